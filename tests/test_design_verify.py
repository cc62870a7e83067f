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


def test_top_whose_sleeping_spin_rises_passes_with_a_note():
    """meshes/t_handle.stl as a top: the objective improves through the symmetry terms while the sleeping
    threshold rises (239 → 249 rad/s at resolution 48); not a failure of the stated rule, but said."""
    from dataclasses import replace
    result = _result(0.0, 0.0, 8337.0, 8108.0)
    result.mode = "top"
    result.metrics_before = replace(result.metrics_before, sleeping_threshold=239.1)
    result.metrics_after = replace(result.metrics_after, sleeping_threshold=248.7)
    v = verify.verify_spin_design(result, 48)
    assert v.ok and any("sleeping-top spin rises (239.1 → 248.7 rad/s)" in n for n in v.notes)


def test_failed_designs_are_retried_finer_then_refused(monkeypatch):
    seen = []

    def fake(source, *, resolution, **options):
        seen.append(resolution)
        return _result(0.0, 5.0, 1.0, 0.5)

    monkeypatch.setattr("inertia_tool.design.hollow.spin_it", fake)
    with pytest.raises(DesignRejectedError, match=r"resolution 48, 72, 108, 5 attempts\): the spin axis ends 5°"):
        verify.spin_it_verified("part.stl", resolution=48, axis=[0, 0, 1], wall=0.002)
    # off principal: the same grid twice more with a stiffer product penalty, then finer
    assert seen == [48, 48, 48, 72, 108]


def test_retry_stops_at_the_first_design_that_passes(monkeypatch):
    outcomes = iter([_result(0.0, 5.0, 1.0, 0.5), _result(0.0, 0.2, 1.0, 0.5)])
    monkeypatch.setattr("inertia_tool.design.hollow.spin_it", lambda source, *, resolution, **o: next(outcomes))
    result, verdicts = verify.spin_it_verified("part.stl", resolution=100, axis=[0, 0, 1], wall=0.002)
    assert [v.ok for v in verdicts] == [False, True] and [v.resolution for v in verdicts] == [100, 100]
    assert [v.product_weight for v in verdicts] == [1e4, 1e5]


def test_a_worse_objective_is_retried_finer_not_stiffer(monkeypatch):
    seen = []

    def fake(source, *, resolution, **options):
        seen.append((resolution, options.get("product_weight")))
        return _result(0.0, 0.0, 1.0, 1.5)

    monkeypatch.setattr("inertia_tool.design.hollow.spin_it", fake)
    with pytest.raises(DesignRejectedError, match="objective is worse") as info:
        verify.spin_it_verified("part.stl", resolution=100, axis=[0, 0, 1], wall=0.002)
    assert seen == [(100, None), (128, None)]
    assert "resolution is at its maximum" in str(info.value) and "\n" not in str(info.value)


def test_cli_exits_6_when_every_design_is_worse(tmp_path, monkeypatch, capsys):
    path = tmp_path / "block.stl"
    shapes.write_stl(shapes.box(0.04, 0.03, 0.02), str(path), units="mm")
    monkeypatch.setattr("inertia_tool.design.hollow.spin_it",
                        lambda source, *, resolution, **o: _result(0.0, 5.0, 1.0, 0.5))
    out = tmp_path / "out.stl"
    code = main(["spin-it", str(path), "--units", "mm", "--axis", "0,0,1", "--wall", "2mm", "--out", str(out)])
    assert code == EXIT_DESIGN == 6
    err = capsys.readouterr().err
    assert "rejected every design" in err and "nothing was written" in err and "Traceback" not in err
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


# --- the principal-axis rule on degenerate eigenspaces (design.hollow.principal_tilt) -----------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from inertia_tool.design.hollow import design_metrics, principal_tilt  # noqa: E402
from inertia_tool.tolerances import EQUAL_MOMENTS_RTOL  # noqa: E402


def _cylinder_tensor(mass=1.0, radius=0.02, height=0.05):
    """Closed form (Chapter 4, "Rigid Body Motion", table of moments): M R²/2 about the axis z and
    M (R²/4 + h²/12) about every transverse axis — the transverse principal axes are arbitrary."""
    transverse = mass * (radius ** 2 / 4 + height ** 2 / 12)
    return np.diag([transverse, transverse, mass * radius ** 2 / 2])


@settings(max_examples=60, deadline=None)
@given(quaternion=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1),
       phi=st.floats(0, 2 * math.pi), theta=st.floats(0, math.pi / 2))
def test_cylinder_every_transverse_axis_is_principal(quaternion, phi, theta):
    """A cylinder turned anywhere: every direction ⟂ its axis lies in the degenerate transverse eigenspace
    (tilt 0, whatever basis eigh picks in it); a direction θ from the axis is min(θ, 90° − θ) from an
    eigenspace (the axis, or the transverse plane)."""
    r = Rotation.from_quat(quaternion).as_matrix()
    tensor = r @ _cylinder_tensor() @ r.T
    transverse = r @ np.array([math.cos(phi), math.sin(phi), 0.0])
    tilt, index = principal_tilt(tensor, transverse)
    assert tilt < 1e-12 and index in (1, 2)          # R²/4 + h²/12 > R²/2: the transverse pair is the larger
    oblique = r @ np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])
    tilt, _ = principal_tilt(tensor, oblique)
    assert tilt == pytest.approx(min(theta, math.pi / 2 - theta), abs=1e-7)


@pytest.mark.parametrize("gap", [10 * EQUAL_MOMENTS_RTOL, 1e-3, 0.3])
def test_distinct_moments_keep_the_one_degree_rule(gap):
    """Moments farther apart than the tolerance of equal moments are distinct: a direction 30° from both
    transverse axes in their plane is 30° off principal, as before (the rule is not loosened)."""
    tensor = np.diag([1.0, 1.0 + gap * 2.0, 2.0])
    tilt, index = principal_tilt(tensor, [math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0])
    assert tilt == pytest.approx(math.radians(30), abs=1e-9) and index == 0


def test_cylinder_mesh_spun_across_its_axis_is_on_principal():
    """The faceted cylinder's transverse moments are equal to round-off; spun about a transverse direction
    30° from the mesh x axis, the old rule (nearest of the deterministic basis vectors) read it 30° off
    principal; it is on principal (tilt 0) and its moment is the transverse one."""
    solid = shapes.cylinder(0.02, 0.05)
    props = mass_properties((solid.vertices, solid.faces), density=1000.0)
    axis = [math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0]
    metrics = design_metrics(props, "yoyo", axis)
    assert metrics.axis_tilt < 1e-6
    expected = _cylinder_tensor(props.mass, 0.02, 0.05)[0, 0]
    assert metrics.axis_moment == pytest.approx(expected, rel=5e-3)         # faceting: 128 segments
    assert metrics.nearest_principal in ("major", "intermediate")           # h²/12 + R²/4 > R²/2 here


# --- the two bundled-mesh rejections of issue 24 --------------------------------------------------------------

@pytest.mark.slow
def test_t_handle_yoyo_about_its_minor_axis_is_refused_with_the_axis_to_use(tmp_path, capsys):
    """meshes/t_handle.stl about z: z is its minor principal axis (I_axis/I_next 0.489); a cavity lowers the
    transverse moment towards it and the spin tumbles (a real failure, rightly refused).  The refusal is one
    line: what failed, and the major axis to spin about instead; exit 6, nothing written."""
    out = tmp_path / "t.stl"
    code = main(["spin-it", "meshes/t_handle.stl", "--units", "mm", "--material", "pla", "--axis", "0,0,1",
                 "--wall", "2mm", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == EXIT_DESIGN and not out.exists() and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert "minor principal axis" in err and "--axis 0,1,0" in err and "wobbles more after" in err
    # the axis the refusal names is one spin-it can design for
    assert main(["spin-it", "meshes/t_handle.stl", "--units", "mm", "--material", "pla", "--axis", "0,1,0",
                 "--wall", "2mm"]) == 0
    assert "major" in capsys.readouterr().out


@pytest.mark.slow
def test_cone_at_resolution_96_is_brought_onto_principal(capsys):
    """meshes/cone.stl at resolution 96 ended 1.18° off principal and was refused (and 128, the maximum, could
    not be retried finer): the product penalty, relative to I33², tolerated a tilt |I13|/(I33 − I11) that
    grew as the transverse moments were drawn towards the axial one.  The retry with it ten times stiffer
    passes on the same grid, the exact objective better than the part's."""
    result, verdicts = verify.spin_it_verified("meshes/cone.stl", units="mm", material="PLA", axis=[0, 0, 1],
                                               mode="yoyo", wall=0.002, resolution=96)
    assert verdicts[-1].ok and verdicts[-1].resolution == 96
    assert result.metrics_after.axis_tilt < math.radians(1.0)
    assert result.objective_after < result.objective_before
    assert [v.product_weight for v in verdicts][-1] > verify.DEFAULT_PRODUCT_WEIGHT
