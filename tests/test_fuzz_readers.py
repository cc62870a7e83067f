"""The readers fuzzer (fuzz/fuzz_readers.py) in CI: its committed seed corpus, a replay of the corpus with
hypothesis-generated mutations (no fuzzing engine needed), the regressions it found, and — when atheris is
installed — a short coverage-guided run with a fixed budget.

The invariant, checked by ``fuzz_readers.check_one`` for every input: a result with finite numbers, or one of the
project's named errors (an ``InertiaToolError`` subclass); never another exception, never a non-finite number
accepted, never more than ``TIME_LIMIT`` seconds on one input.
"""

import os
import re
import signal
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FUZZ = os.path.join(ROOT, "fuzz")
sys.path.insert(0, FUZZ)

import fuzz_readers  # noqa: E402
from fuzz_readers import FORMATS, Finding, check_one, seeds  # noqa: E402
from instrumented import import_readers  # noqa: E402

REGRESSIONS = os.path.join(ROOT, "tests", "regressions")
SEEDS = seeds()

#: Byte strings that sit on the edges of what the readers parse: numbers a grammar may half-accept, counts
#: past any limit, markup that opens and never closes.
_TOKENS = (b"nan", b"inf", b"-inf", b"1e308", b"1e-320", b"-0", b"0", b"-1", b"4294967296", b"99999999999999999999",
           b"1_000", b"\xd9\xa1", b"0x10", b" ", b"\n", b"\x00", b"<", b">", b"\"", b"&amp;", b"<!--", b"]]>",
           b"<link name=\"a\">", b"<body>", b"facet normal", b"vertex 1 1 1", b"f 1 2 3", b"element face 1000000000")


def test_the_corpus_has_a_small_seed_of_every_format():
    suffixes = {s for s, _ in SEEDS}
    assert suffixes == set(FORMATS)
    assert all(len(data) <= 8192 for _, data in SEEDS)
    stl = [data for s, data in SEEDS if s == ".stl"]
    assert any(d.startswith(b"solid") for d in stl) and any(not d.startswith(b"solid") for d in stl)  # both STLs


@pytest.mark.parametrize("k", range(len(SEEDS)), ids=[f"{s}-{k}" for k, (s, _) in enumerate(SEEDS)])
def test_every_seed_reads_to_a_result(k):
    suffix, data = SEEDS[k]
    assert check_one(data, suffix) == "result"


def test_every_reader_and_robot_parser_is_imported_for_instrumentation():
    names = set(import_readers())
    for module in ("inertia_tool.mesh.read", "inertia_tool.mesh.decompress", "inertia_tool.mesh.prepare",
                   "inertia_tool.robot.description", "inertia_tool.robot.mjcf", "inertia_tool.robot.resolve",
                   "inertia_tool.robot.geometry", "trimesh.exchange.threemf", "trimesh.exchange.gltf",
                   "trimesh.exchange.ply", "trimesh.exchange.dae"):
        assert module in names


def test_the_invariant_catches_what_it_should(monkeypatch):
    """check_one itself: a stray exception, a bare InertiaToolError and a hang are findings; a named error is
    not."""
    from inertia_tool.errors import InertiaToolError, MeshReadError

    def raising(exc):
        def f(path):
            raise exc
        return f
    suffix, data = SEEDS[0]
    for exc, finding in ((IndexError("x"), True), (InertiaToolError("x"), True), (MeshReadError("x"), False)):
        monkeypatch.setattr(fuzz_readers, "_check_mesh", raising(exc))
        monkeypatch.setattr(fuzz_readers, "_check_robot", raising(exc))
        if finding:
            with pytest.raises(Finding):
                check_one(data, suffix)
        else:
            assert check_one(data, suffix) == "refused: MeshReadError"

    def forever(path):
        while True:
            pass
    monkeypatch.setattr(fuzz_readers, "_check_mesh", forever)
    with pytest.raises(Finding, match="no answer within"):
        check_one(data, ".stl", time_limit=0.2)


def _mutate(data: bytes, ops) -> bytes:
    b = bytearray(data)
    for kind, pos, arg in ops:
        at = pos % (len(b) + 1)
        if kind == "flip" and b:
            b[at % len(b)] ^= 1 << (arg % 8)
        elif kind == "cut":
            del b[at:at + 1 + arg % 64]
        elif kind == "token":
            b[at:at] = _TOKENS[arg % len(_TOKENS)]
        elif kind == "replace_number":
            m = re.search(rb"-?\d+(\.\d+)?(e-?\d+)?", bytes(b[at:]))
            if m:
                b[at + m.start():at + m.end()] = _TOKENS[arg % len(_TOKENS)]
        elif kind == "duplicate" and b:
            chunk = b[at:at + 1 + arg % 256]
            b[at:at] = chunk * (1 + arg % 3)
        elif kind == "truncate":
            del b[at:]
    return bytes(b)


_OPS = st.lists(st.tuples(st.sampled_from(["flip", "cut", "token", "replace_number", "duplicate", "truncate"]),
                          st.integers(0, 1 << 16), st.integers(0, 1 << 16)), min_size=1, max_size=4)


@settings(max_examples=250, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(k=st.integers(0, len(SEEDS) - 1), ops=_OPS)
def test_mutated_seeds_give_a_result_or_a_named_error(k, ops):
    suffix, data = SEEDS[k]
    check_one(_mutate(data, ops), suffix)            # raises Finding on anything else


REGRESSION_FILES = sorted(n for n in os.listdir(REGRESSIONS)
                          if os.path.splitext(n)[1].lower() in FORMATS) if os.path.isdir(REGRESSIONS) else []


@pytest.mark.parametrize("name", REGRESSION_FILES)
def test_regressions_replay_cleanly(name):
    with open(os.path.join(REGRESSIONS, name), "rb") as fh:
        check_one(fh.read(), os.path.splitext(name)[1].lower())


@pytest.mark.slow
def test_a_fixed_budget_of_coverage_guided_fuzzing(tmp_path):
    """libFuzzer through atheris for at most 3,000 inputs or 15 s (plus the ~40 s of instrumenting every reader
    at start): no finding, and the coverage of the seeds alone is far above the 58 edges the old harness saw."""
    pytest.importorskip("atheris")
    env = {**os.environ, "PYTHONPATH": ROOT + os.pathsep + os.environ.get("PYTHONPATH", "")}
    proc = subprocess.run([sys.executable, os.path.join(FUZZ, "fuzz_readers.py"), "-atheris_runs=3000",
                           "-max_total_time=15", "-timeout=10", "-rss_limit_mb=3072", "-seed=1",
                           f"-artifact_prefix={tmp_path}/", str(tmp_path / "work")],
                          capture_output=True, text=True, env=env, timeout=300)
    log = proc.stdout + proc.stderr
    assert "ERROR: libFuzzer" not in log and "Uncaught Python exception" not in log, log[-3000:]
    done = re.search(r"^Done (\d+) (?:runs )?in", log, re.MULTILINE)       # libFuzzer: "Done 3000 runs in 12 s"
    assert done, log[-3000:]
    # libFuzzer's -timeout alarm stays armed while the interpreter shuts down after "Done": a SIGALRM then is
    # the end of a finished run, not a finding (a timeout during the run prints "ERROR: libFuzzer: timeout")
    assert proc.returncode in (0, -signal.SIGALRM), log[-3000:]
    inited = re.search(r"INITED cov: (\d+)", log)
    assert inited and int(inited.group(1)) > 941, log[-2000:]


@pytest.mark.parametrize("command, name, problem", [
    ("robot", "mjcf-geom-size-not-a-number.xml", "size"),
    ("robot", "mjcf-contype-nan.xml", "contype"),
    ("analyze", "gltf-position-scalar-accessor.gltf", "vertices are not points in 3-D"),
])
def test_fuzzer_findings_are_one_line_errors(command, name, problem, capsys):
    """Found by the fuzzer: an MJCF geom ``size="0x10 ..."`` or ``contype="nan"`` (the corpus replay), and a
    glTF whose POSITION names the SCALAR index accessor (atheris, 2026-11-25) were internal errors (a ValueError
    from ``float``/``int`` or from the integration kernel, exit 1); they are refused, naming the file and the
    problem."""
    from inertia_tool.cli import main
    path = os.path.join(REGRESSIONS, name)
    assert main([command, path, *(["--density", "1000"] if command == "robot" else [])]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and path in err[0] and problem in err[0] and "internal error" not in err[0]
