"""Inertia about any point, in any coordinate system (mass/frame.py, analyze --about/--axes; issue 24)."""

import json
import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import ImplausiblePointWarning, UsageError
from inertia_tool.mass import shapes
from inertia_tool.mass.frame import inertia_in_frame

A, B, C, RHO = 0.02, 0.03, 0.04, 7850.0


def _box_props():
    s = shapes.box(A, B, C)
    return mass_properties((s.vertices, s.faces), density=RHO, units="m")


def _brute_inertia(props, point, rotation):
    """Independent: the box's mass as 40³ point masses, summed about ``point`` in the rotated axes."""
    n = 40
    g = [(np.arange(n) + 0.5) / n - 0.5 for _ in range(3)]
    x, y, z = np.meshgrid(g[0] * A, g[1] * B, g[2] * C, indexing="ij")
    pts = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1) + props.center_of_mass
    m = props.mass / len(pts)
    local = (pts - point) @ rotation                 # coordinates in the system's axes
    r2 = np.einsum("ij,ij->i", local, local)
    return m * (r2.sum() * np.eye(3) - local.T @ local)


@settings(max_examples=20, deadline=None)
@given(point=st.tuples(*[st.floats(-0.2, 0.2)] * 3), rotvec=st.tuples(*[st.floats(-3.0, 3.0)] * 3))
def test_inertia_in_frame_matches_point_masses(point, rotvec):
    props = _box_props()
    rot = Rotation.from_rotvec(rotvec).as_matrix()
    frame = inertia_in_frame(props, point, rot)
    brute = _brute_inertia(props, np.asarray(point), rot)
    scale = np.abs(brute).max()
    np.testing.assert_allclose(frame.inertia, brute, atol=2e-3 * scale)
    np.testing.assert_allclose(frame.center_of_mass, rot.T @ (props.center_of_mass - point), atol=1e-15)
    # the central tensor rotates; the trace (sum of moments) is invariant
    assert np.trace(frame.central_inertia) == pytest.approx(np.trace(props.inertia), rel=1e-12)


def test_frame_refuses_an_improper_rotation():
    with pytest.raises(UsageError, match="proper rotation"):
        inertia_in_frame(_box_props(), [0, 0, 0], np.diag([1.0, 1.0, -1.0]))


def test_inertia_about_a_millimetre_point_read_as_metres_warns():
    """Issue 24: `inertia_about([101.6, 152.4, 0])` after units="mm" silently took metres (4.8e4 kg·m²)."""
    props = _box_props()
    with pytest.warns(ImplausiblePointWarning, match="millimetres read as metres"):
        props.inertia_about([101.6, 152.4, 0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        props.inertia_about([0.1016, 0.1524, 0])            # 3 part sizes away: plausible, no warning
        props.inertia_about([101.6, 152.4, 0], far_point_ratio=None)


def test_warning_points_at_the_caller():
    props = _box_props()
    with pytest.warns(ImplausiblePointWarning) as record:
        props.inertia_about([500.0, 0, 0])
    assert record[0].filename == __file__


@pytest.fixture
def box_stl(tmp_path):
    path = tmp_path / "box.stl"
    shapes.write_stl(shapes.box(A, B, C), str(path), units="mm")
    return str(path)


def test_cli_about_in_millimetres_json(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--density", "7850", "--about", "101.6mm,152.4mm,0",
                 "--axes", "axis-angle:0,0,1,90deg", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    system = out["coordinate_system"]
    props = _box_props()
    rot = Rotation.from_rotvec([0, 0, np.pi / 2]).as_matrix()
    np.testing.assert_allclose(system["origin"], [0.1016, 0.1524, 0], atol=1e-12)
    np.testing.assert_allclose(system["axes"][0], [0, 1, 0], atol=1e-12)
    brute = _brute_inertia(props, np.array([0.1016, 0.1524, 0]), rot)
    np.testing.assert_allclose(system["inertia_about_origin"], brute, rtol=2e-3, atol=1e-9)
    assert not any("part sizes" in w for w in out["warnings"])


def test_cli_about_plain_numbers_are_in_units_and_a_far_point_is_warned(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--density", "7850", "--about", "101.6,152.4,0"]) == 0
    captured = capsys.readouterr()
    assert "in the coordinate system at ( 0.1016,  0.1524,  0) m" in captured.out
    assert main(["analyze", box_stl, "--units", "mm", "--density", "7850", "--about", "101.6m,152.4m,0"]) == 0
    assert "part sizes" in capsys.readouterr().out           # among the report's warnings


def test_cli_about_in_cad_and_html(box_stl, capsys, tmp_path):
    report = tmp_path / "r.html"
    assert main(["analyze", box_stl, "--units", "mm", "--density", "7850", "--about", "10mm,0,0", "--format", "cad",
                 "--cad-units", "g-mm", "--report", str(report)]) == 0
    text = capsys.readouterr().out
    assert "Coordinate system: -- origin (0.01, 0, 0) m" in text
    assert "\tX = -10" in text                               # the centre of mass relative to the new origin
    html = report.read_text()
    assert "Chosen coordinate system" in html


@pytest.mark.parametrize("args, message", [
    (["--axes", "axis-angle:0,0,1,90deg"], "--axes needs --about"),
    (["--about", "0,0,0", "--axes", "euler:1,2,3"], "--axes takes"),
    (["--about", "0,0,0", "--axes", "matrix:1,0,0,0,1,0,0,0,-1"], "proper rotation"),
    (["--about", "0,0,0", "--format", "urdf"], "--about applies to"),
])
def test_cli_about_refusals(box_stl, capsys, args, message):
    assert main(["analyze", box_stl, "--units", "mm", "--density", "7850"] + args) == 2
    assert message in capsys.readouterr().err
