"""The heavy top on an estimated part (issue 21, notes19): the repaired part's bounds carried to the top's inputs
and results (:mod:`inertia_tool.dynamics.top_bounds`), checked against the closed part, and the text of ``top
--repair`` saying which results they leave in doubt.  Before, ``top --repair`` printed the repair warning only.

The part: a ball (icosphere, radius 30 mm) on a pivot at its surface, a few faces lost at its equator; the
repair's patch crosses a curved region, so the estimate differs from the closed ball (by ~1e-9 kg·m²)."""

import math
import warnings

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.cli import main  # noqa: E402
from inertia_tool.dynamics.top import heavy_top_on_pivot  # noqa: E402
from inertia_tool.dynamics.top_bounds import heavy_top_bounds  # noqa: E402
from inertia_tool.reports.stability import format_top_estimate  # noqa: E402

PIVOT = [0.0, 0.0, -0.03]
TILT = 0.3


def _ball(subdivisions: int, lost: int):
    """The closed ball and the ball with its ``lost`` faces furthest along +x taken out."""
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.03)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    c = m.triangles_center
    gone = np.zeros(len(f), dtype=bool)
    gone[np.argsort(-(c[:, 0] + 1e-3 * c[:, 1] + 1e-6 * c[:, 2]))[:lost]] = True
    return (v, f), (v, f[~gone])


def _tops(subdivisions, lost, spin):
    closed, damaged = _ball(subdivisions, lost)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        truth = mass_properties(closed, density=1000.0)
        est = mass_properties(damaged, density=1000.0, repair=True)
        true_top = heavy_top_on_pivot(truth, PIVOT, theta0=TILT, omega3=spin)
        top = heavy_top_on_pivot(est, PIVOT, theta0=TILT, omega3=spin)
    u = est.mesh.uncertainty
    assert u is not None
    bounds = heavy_top_bounds(top, inertia_com=np.asarray(est.inertia),
                              inertia_pivot=np.asarray(est.inertia_about(PIVOT).tensor), mass=est.mass,
                              mass_rtol=u.mass, com_bound=u.center_of_mass, inertia_rtol=u.inertia)
    return true_top, top, bounds


def _within(x, r):
    return r[0] <= x <= r[1]


# spins (rev/s): fast (every verdict holds), near the sleeping limit (its verdict in doubt), near the limit of
# steady precession at θ0 = 0.3 rad (its existence in doubt: ω = ω_sleep √cos θ0)
@pytest.mark.parametrize("subdivisions, lost, spin, sleeping_holds, steady",
                         [(3, 4, 40.0, True, True), (4, 6, 40.0, True, True),
                          (3, 4, 17.115, False, True), (3, 4, 16.728, True, None)])
def test_bounds_hold_against_the_closed_ball(subdivisions, lost, spin, sleeping_holds, steady):
    true_top, top, b = _tops(subdivisions, lost, 2 * math.pi * spin)
    assert b is not None and b.moment > 0
    assert top.transverse_moment != true_top.transverse_moment          # the estimate is not the closed part
    assert abs(top.transverse_moment - true_top.transverse_moment) <= b.moment
    assert abs(top.axial_moment - true_top.axial_moment) <= b.moment
    assert abs(top.length - true_top.length) <= b.length
    assert _within(true_top.mass * true_top.gravity * true_top.length, b.gravity_torque)
    assert _within(true_top.sleeping_margin, b.sleeping_margin)
    assert _within(true_top.transverse_asymmetry, (0.0, b.asymmetry[1]))
    assert b.steady_possible is steady
    if steady:
        assert _within(true_top.precession_rate_slow, b.precession_rate_slow)
        assert _within(true_top.precession_rate_fast, b.precession_rate_fast)
    lines = format_top_estimate(top, b)
    said = "\n".join(lines)
    assert "the part is an estimate" in lines[0]
    doubt = lines[-1]
    assert doubt.startswith("    in doubt:") and "nutation limits" in doubt
    assert ("sleeping-top verdict" in doubt) is (not sleeping_holds)
    assert ("whether steady precession exists" in doubt) is (steady is None)
    assert ("the verdict holds" in said) is sleeping_holds


def test_bounds_wider_than_the_part_give_no_numbers():
    """A corner of a coarse disc lost (inertia ±135 %): no bound follows, and the text says nothing is proven."""
    m = trimesh.creation.cylinder(radius=0.04, height=0.016, sections=16).subdivide()
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    c = m.triangles_center
    lost = (c[:, 0] > 0.024) & (c[:, 2] > 0.0) & (np.abs(c[:, 1]) < 0.012)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = mass_properties((v, f[~lost]), density=1000.0, repair=True)
        top = heavy_top_on_pivot(est, PIVOT, theta0=TILT, omega3=2 * math.pi * 30)
    u = est.mesh.uncertainty
    b = heavy_top_bounds(top, inertia_com=np.asarray(est.inertia),
                         inertia_pivot=np.asarray(est.inertia_about(PIVOT).tensor), mass=est.mass,
                         mass_rtol=u.mass, com_bound=u.center_of_mass, inertia_rtol=u.inertia)
    assert b is None
    assert "not bounded" in format_top_estimate(top, None)[0]


def test_top_cli_text_says_what_is_in_doubt(tmp_path, capsys):
    _, damaged = _ball(3, 4)
    path = tmp_path / "ball_hole.stl"
    trimesh.Trimesh(*damaged, process=False).export(path)
    argv = ["top", str(path), "--pivot", "0,0,-0.03", "--spin", "17.115rev/s", "--tilt", "0.3rad", "--no-simulate"]
    assert main([*argv, "--repair"]) == 0
    out = capsys.readouterr().out
    assert "the part is an estimate: about the pivot I1 and I3" in out
    assert "in doubt: the symmetric-top reading; the sleeping-top verdict" in out
    closed, _ = _ball(3, 4)
    whole = tmp_path / "ball.stl"
    trimesh.Trimesh(*closed, process=False).export(whole)
    assert main(["top", str(whole), *argv[2:]]) == 0
    assert "estimate" not in capsys.readouterr().out                   # an exact part: no caveat, as before


def test_top_json_carries_the_bounds_and_validates(tmp_path, capsys):
    """``top --json --repair``: ``top_bounds`` with the bounds and the keys of the results in doubt, valid against
    the shipped schema; ``null`` for an exact part."""
    import json

    jsonschema = pytest.importorskip("jsonschema")
    from inertia_tool.reports.serialize import output_schema

    closed, damaged = _ball(3, 4)
    validator = jsonschema.Draft202012Validator(output_schema())
    for faces, name, repair in ((damaged, "ball_hole.stl", ["--repair"]), (closed, "ball.stl", [])):
        path = tmp_path / name
        trimesh.Trimesh(*faces, process=False).export(path)
        assert main(["top", str(path), "--pivot", "0,0,-0.03", "--spin", "17.115rev/s", "--tilt", "0.3rad",
                     "--no-simulate", "--json", *repair]) == 0
        out = json.loads(capsys.readouterr().out)
        validator.validate(out)
        if repair:
            b = out["top_bounds"]
            assert b["bounded"] and b["moment"] > 0
            assert b["in_doubt"][:2] == ["symmetric_top", "sleeping_top"]
            assert b["sleeping_margin"][0] <= out["top"]["sleeping_margin"] <= b["sleeping_margin"][1]
        else:
            assert out["top_bounds"] is None and out["method"] == "exact"
