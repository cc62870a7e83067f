"""The stage benchmark's accounting (benchmarks/bench_stages.py, issue 25): every stage it names exists in the
package, its rows add up to the whole analysis, and the time of each stage lands in its own row, not in its
caller's (driven by a clock the test advances, so no assertion depends on how fast anything runs)."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks"))

from bench_stages import OTHER, STAGES, StageClock, _stage_codes, _write_stl, torus  # noqa: E402

import inertia_tool.mass.pipeline as pipeline  # noqa: E402
import inertia_tool.mesh.checks as checks  # noqa: E402
import inertia_tool.mesh.read_stl as read  # noqa: E402


def test_every_stage_names_a_function_of_the_package():
    # a renamed function would otherwise drop its time into "other" without a word
    codes = _stage_codes()
    assert sorted(set(codes.values())) == sorted(STAGES)
    assert len(codes) == sum(len(names) for names in STAGES.values())


@pytest.fixture
def torus_stl(tmp_path, monkeypatch):
    monkeypatch.setattr("bench_stages.OUT", str(tmp_path))
    return torus(60, 30)                # 3,600 faces: a closed, exact solid


class Clock:
    """A clock that moves only when told."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_each_stage_is_charged_to_its_row_and_the_rows_add_up(torus_stl, monkeypatch):
    # the census takes "1 s", the weld "2 s" before it reads the file (whose chunks take "8 s" each, charged to
    # "read" though the weld calls them), a pipeline check "4 s": each lands in its row, and the rows sum to
    # the clock's whole advance
    clock = Clock()
    stage = StageClock(cpu_clock=clock, wall_clock=clock,     # before the stand-ins: it finds the real stages
                       kernel_clock=lambda: (clock.now / 2, int(clock.now) * 10))
    real_census, real_weld, real_size = checks.census_and_shells, read.weld_exact_stream, pipeline.warn_implausible_size

    def census(*args, **kwargs):        # one function each: the hook tells them apart by their code
        clock.now += 1.0
        return real_census(*args, **kwargs)

    def weld(*args, **kwargs):
        clock.now += 2.0
        return real_weld(*args, **kwargs)

    def size(*args, **kwargs):
        clock.now += 4.0
        return real_size(*args, **kwargs)

    real_chunks = read._binary_stl_chunks
    reads = []

    def chunks(*args, **kwargs):
        views = real_chunks(*args, **kwargs)

        def timed():
            for v in views():
                clock.now += 8.0
                reads.append(len(v))
                yield v
        return timed

    stand_ins = {"census_and_shells": (real_census, census), "weld_exact_stream": (real_weld, weld),
                 "warn_implausible_size": (real_size, size)}
    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("inertia_tool"):
            for name, (real, stand_in) in stand_ins.items():
                if getattr(module, name, None) is real:
                    monkeypatch.setattr(module, name, stand_in)
    monkeypatch.setattr(read, "_binary_stl_chunks", chunks)
    # the stand-ins are recognised as the stages they wrap (the warning check is in no stage)
    stage.codes[census.__code__] = "census+shells"
    stage.codes[weld.__code__] = "weld"
    stage.codes[next(c for c in chunks.__code__.co_consts if getattr(c, "co_name", "") == "timed")] = "read"
    cpu, wall, other = stage.run(lambda: pipeline.mass_properties(torus_stl, density=1000.0))
    assert reads, "the file was read through the stand-in"
    assert cpu == wall
    assert cpu["census+shells"] == 1.0
    assert cpu["weld"] == 2.0
    assert cpu["read"] == 8.0 * len(reads)
    assert cpu[OTHER] == 4.0
    assert sum(cpu.values()) == clock.now
    assert stage.sys == {row: t / 2 for row, t in cpu.items()}
    assert stage.faults == {row: int(t) * 10 for row, t in cpu.items()}
    charged = {name: t for name, t in other.items() if t}
    assert list(charged.values()) == [4.0] and next(iter(charged)).endswith(".<locals>.size")
    assert stage.events > 100


def test_real_clocks_give_every_row_that_runs_some_time(torus_stl):
    stage = StageClock()
    pipeline.mass_properties(torus_stl, density=1000.0)
    cpu, wall, other = stage.run(lambda: pipeline.mass_properties(torus_stl, density=1000.0))
    assert set(cpu) == set(wall) == {*STAGES, OTHER}
    assert all(v >= 0 for v in (*cpu.values(), *wall.values()))
    for row in ("read", "weld", "census+shells", "integrate", OTHER):
        assert wall[row] > 0, row
    assert sum(other.values()) == pytest.approx(cpu[OTHER], rel=1e-9, abs=1e-12)


def test_write_stl_writes_the_records_it_is_given(tmp_path):
    tri = np.arange(27, dtype=np.float32).reshape(3, 3, 3) + 0.5
    path = str(tmp_path / "three.stl")
    _write_stl(path, tri)
    raw = np.fromfile(path, dtype=np.uint8)
    assert len(raw) == 84 + 3 * 50
    assert int(np.frombuffer(raw[80:84].tobytes(), dtype="<u4")[0]) == 3
    rec = np.frombuffer(raw[84:].tobytes(), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    assert np.array_equal(rec["v"], tri)
