"""spin-it never hands back a worse part without saying so (design/verify.py; issue 24): the verdict's rules,
the retry on a finer grid, exit code 6, the thin-part message and --repair."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

manifold3d = pytest.importorskip("manifold3d")

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.cli import EXIT_DESIGN, EXIT_PHYSICS, main  # noqa: E402
from inertia_tool.design import verify  # noqa: E402
from inertia_tool.design.hollow import SpinDesignMetrics, spin_it  # noqa: E402
from inertia_tool.errors import DesignRejectedError, NoRoomError  # noqa: E402
from inertia_tool.mass import shapes  # noqa: E402


def _box(a, b, c):
    s = shapes.box(a, b, c)
    return s.vertices, s.faces


def _metrics(tilt_deg):
    return SpinDesignMetrics(mass=1.0, axis_moment=2.0, next_moment=1.0, moment_ratio=2.0,
                             axis_tilt=math.radians(tilt_deg), axis_offset=None, nearest_principal="major",
                             epsilon_coefficient=-0.5)


def _result(tilt_before, tilt_after, objective_before, objective_after, before=None, after=None, axis=(0, 0, 1)):
    body = mass_properties(_box(0.04, 0.03, 0.01), density=1000.0)
    return SimpleNamespace(mode="yoyo", axis=np.asarray(axis, float), before=before or body, after=after or body,
                           metrics_before=_metrics(tilt_before), metrics_after=_metrics(tilt_after),
                           objective_before=objective_before, objective_after=objective_after)


def test_wobble_is_small_about_the_major_axis_and_large_about_the_intermediate():
    """Chapter 4 §4.4.1: a knock of 0.1° stays ~0.1° (about 2e-3 rad/rad) about the major axis and grows to
    order 1 about the intermediate axis (the tennis-racket flip) — an independent check of the simulation the
    verdict uses."""
    body = mass_properties(_box(0.04, 0.03, 0.01), density=1000.0)     # major axis z, intermediate y
    major = verify._wobble(body, np.array([0.0, 0.0, 1.0]))
    middle = verify._wobble(body, np.array([0.0, 1.0, 0.0]))
    assert major < 5 * math.radians(0.1)
    assert middle > 0.5


def test_verdict_rejects_an_axis_that_ends_farther_off_principal():
    """Issue 24: the quadknot yo-yo's axis ended 10° off every principal axis with exit 0."""
    v = verify.verify_spin_design(_result(0.0, 10.0, 1.0, 0.9), 48)
    assert not v.ok and "10° from a principal axis" in v.reasons[0]


def test_verdict_rejects_a_worse_objective_and_passes_an_equal_one():
    assert not verify.verify_spin_design(_result(0.0, 0.0, 1.0, 1.01), 48).ok
    assert verify.verify_spin_design(_result(0.0, 0.0, 1.0, 1.0), 48).ok


def test_verdict_rejects_a_larger_simulated_wobble():
    """The same moments turned so that the axis is the intermediate one: the simulated spin flips."""
    good = mass_properties(_box(0.04, 0.03, 0.01), density=1000.0)
    bad = mass_properties(_box(0.04, 0.01, 0.03), density=1000.0)
    v = verify.verify_spin_design(_result(0.0, 0.0, 1.0, 1.0, before=good, after=bad), 48)
    assert not v.ok and "wobbles more" in v.reasons[0]
    assert v.wobble_after > 10 * v.wobble_before


def test_verdict_passes_a_closer_axis_with_a_note():
    v = verify.verify_spin_design(_result(2.8, 2.3, 4.9, 2.1), 48)
    assert v.ok and v.notes and "still 2.3°" in v.notes[0]


def test_failed_designs_are_retried_finer_then_refused(monkeypatch):
    seen = []

    def fake(source, *, resolution, **options):
        seen.append(resolution)
        return _result(0.0, 5.0, 1.0, 0.5)

    monkeypatch.setattr("inertia_tool.design.hollow.spin_it", fake)
    with pytest.raises(DesignRejectedError, match="resolution 48: the spin axis ends 5°"):
        verify.spin_it_verified("part.stl", resolution=48, axis=[0, 0, 1], wall=0.002)
    assert seen == [48, 72, 108]


def test_retry_stops_at_the_first_design_that_passes(monkeypatch):
    outcomes = iter([_result(0.0, 5.0, 1.0, 0.5), _result(0.0, 0.2, 1.0, 0.5)])
    monkeypatch.setattr("inertia_tool.design.hollow.spin_it", lambda source, *, resolution, **o: next(outcomes))
    result, verdicts = verify.spin_it_verified("part.stl", resolution=100, axis=[0, 0, 1], wall=0.002)
    assert [v.ok for v in verdicts] == [False, True] and [v.resolution for v in verdicts] == [100, 128]


def test_cli_exits_6_when_every_design_is_worse(tmp_path, monkeypatch, capsys):
    path = tmp_path / "block.stl"
    shapes.write_stl(shapes.box(0.04, 0.03, 0.02), str(path), units="mm")
    monkeypatch.setattr("inertia_tool.design.hollow.spin_it",
                        lambda source, *, resolution, **o: _result(0.0, 5.0, 1.0, 0.5))
    out = tmp_path / "out.stl"
    code = main(["spin-it", str(path), "--units", "mm", "--axis", "0,0,1", "--wall", "2mm", "--out", str(out)])
    assert code == EXIT_DESIGN == 6
    err = capsys.readouterr().err
    assert "found no design better" in err and "nothing was written" in err and "Traceback" not in err
    assert not out.exists()


def test_thin_part_says_so_and_a_finer_resolution_is_found():
    """Issue 24: a thin part found no cavity at the default resolution and said nothing.  A 40 × 40 × 4 mm
    plate with a 1.5 mm wall has no room at 48 cells: the design stage says so (NoRoomError, naming the
    resolution), and the verified design tries a few finer ones and says which one it used."""
    v, f = _box(0.04, 0.04, 0.004)
    with pytest.raises(NoRoomError, match=r"no room for a cavity at resolution 48"):
        spin_it((v, f), axis=[0, 0, 1], wall=0.0015, material="PLA", resolution=48)
    result, verdicts = verify.spin_it_verified((v, f), axis=[0, 0, 1], wall=0.0015, material="PLA", resolution=48)
    assert result.cavity_volume > 0 and verdicts[-1].resolution > 48
    assert "resolution 48 left no room" in verdicts[-1].notes[0]


def test_part_thinner_than_the_wall_says_no_resolution_helps(capsys, tmp_path):
    v, f = _box(0.04, 0.04, 0.002)
    with pytest.raises(NoRoomError, match="nowhere deeper than the wall"):
        spin_it((v, f), axis=[0, 0, 1], wall=0.002, material="PLA", resolution=48)
    path = tmp_path / "plate.stl"
    shapes.write_stl(shapes.box(0.04, 0.04, 0.002), str(path), units="mm")
    code = main(["spin-it", str(path), "--units", "mm", "--material", "pla", "--axis", "0,0,1", "--wall", "2mm"])
    assert code == EXIT_PHYSICS
    err = capsys.readouterr().err
    assert "a thinner --wall is the only way" in err and "Traceback" not in err


def test_cli_spin_it_repair_reads_a_cracked_part(tmp_path, capsys):
    """Its refusal recommended --repair, which spin-it did not have: now it does."""
    import trimesh
    box = trimesh.creation.box([40, 30, 20]).subdivide().subdivide().subdivide().subdivide()
    cracked = trimesh.Trimesh(box.vertices, box.faces[1:], process=False)     # one small triangle missing
    path = tmp_path / "cracked.stl"
    cracked.export(path)
    args = ["spin-it", str(path), "--units", "mm", "--material", "pla", "--axis", "0,0,1", "--wall", "3mm",
            "--resolution", "16"]
    assert main(args) == 3
    assert "--repair" in capsys.readouterr().err
    assert main(args + ["--repair"]) == 0
    out = capsys.readouterr().out
    assert "verified against the input" in out
