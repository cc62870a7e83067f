"""Balancing by drilling (inertia_tool.balancing.drilling): depths that cancel U and W exactly, the removed
cylinders against a real boolean of the mesh, and holes that would leave the part."""

import math

import numpy as np
import pytest

from conftest import assert_tensor_close
from inertia_tool.balancing.drilling import DrilledHole, remove_cylinders
from inertia_tool.balancing.rotor import balance, shaft_frame, unbalance_state
from inertia_tool.errors import PhysicsError
from inertia_tool.mass import shapes
from inertia_tool.mass.pipeline import mass_properties

STEEL = 7850.0


@pytest.fixture(scope="module")
def rotor():
    """A steel disc (R 100 mm, 40 mm thick) with a 16 mm boss fused off-centre on one face: static and couple
    unbalance about the z axis."""
    manifold3d = pytest.importorskip("manifold3d")
    disc = manifold3d.Manifold.cylinder(0.04, 0.1, 0.1, 128).translate([0, 0, -0.02])
    boss = manifold3d.Manifold.cylinder(0.008, 0.008, 0.008, 64).translate([0.05, 0.02, 0.02])
    mesh = (disc + boss).to_mesh64()
    v, f = np.asarray(mesh.vert_properties)[:, :3].copy(), np.asarray(mesh.tri_verts).astype(np.int64)
    return mass_properties((v, f), density=STEEL), (v, f)


def _report(rotor, **kw):
    props, mesh = rotor
    args = dict(axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000, planes=(-0.02, 0.02), radius=0.07,
                drill_diameter=0.012, part_mesh=mesh)
    args.update(kw)
    return balance(props, **args)


def test_drilling_cancels_static_and_moment_unbalance(rotor):
    report = _report(rotor)
    u0 = np.linalg.norm(report.initial.static_unbalance)
    w0 = np.linalg.norm(report.initial.moment_unbalance)
    assert np.linalg.norm(report.drilled.static_unbalance) < 1e-10 * u0
    assert np.linalg.norm(report.drilled.moment_unbalance) < 1e-10 * w0
    assert len(report.drillings) == 2 and all(h.inside_checked for h in report.drillings)
    for hole, corr in zip(report.drillings, report.corrections):
        # removal at the opposite angle of the added mass, drilled towards the other plane
        assert hole.angle == pytest.approx(corr.removal_angle, abs=0.05)
        assert hole.mass == pytest.approx(STEEL * math.pi * 0.006 ** 2 * hole.depth)
    assert [h.direction for h in report.drillings] == [1, -1]


def test_removed_cylinders_match_a_boolean_of_the_mesh(rotor):
    """The closed-form removal equals the exact analysis of the part with 256-gon prisms cut out, to the
    prisms' O(1/n²) difference from the cylinders."""
    manifold3d = pytest.importorskip("manifold3d")
    props, (v, f) = rotor
    report = _report(rotor)
    part = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.array(v), tri_verts=f.astype(np.uint64)))
    frame = shaft_frame([0, 0, 0], [0, 0, 1])
    for h in report.drillings:
        z0 = min(h.plane, h.plane + h.direction * h.depth)
        centre = frame.to_mesh([h.radius * math.cos(h.angle), h.radius * math.sin(h.angle), z0])
        part = part - manifold3d.Manifold.cylinder(h.depth, h.diameter / 2, h.diameter / 2, 256).translate(centre)
    mesh = part.to_mesh64()
    cut = mass_properties((np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts)), density=STEEL)
    closed = remove_cylinders(props, report.drillings)
    removed = props.mass - closed.mass
    assert props.mass - cut.mass == pytest.approx(removed, rel=1e-3)
    np.testing.assert_allclose(cut.center_of_mass, closed.center_of_mass, atol=1e-4 * removed / props.mass)
    assert_tensor_close(cut.inertia, closed.inertia, rtol=1e-6)
    state = unbalance_state(cut, frame)
    assert np.linalg.norm(state.static_unbalance) < 2e-3 * np.linalg.norm(report.initial.static_unbalance)


def test_remove_cylinders_of_a_box_hole_in_closed_form():
    """A cylinder removed from the middle of a block: mass, centre and inertia by hand."""
    block = shapes.box(0.1, 0.1, 0.1).exact
    props = block.with_mass(block.volume * 1000.0)
    d, depth = 0.02, 0.1
    m = 1000.0 * math.pi * d * d / 4 * depth
    hole = DrilledHole(plane=-0.05, angle=0.0, radius=0.0, diameter=d, depth=depth, direction=1, mass=m,
                       entry=np.array([0.0, 0.0, -0.05]), axis=np.array([0.0, 0.0, 1.0]),
                       centroid=np.zeros(3), inside_checked=False)
    out = remove_cylinders(props, [hole])
    assert out.mass == pytest.approx(props.mass - m)
    np.testing.assert_allclose(out.center_of_mass, 0.0, atol=1e-15)
    izz = props.inertia[2, 2] - m * (d / 2) ** 2 / 2
    ixx = props.inertia[0, 0] - m * (3 * (d / 2) ** 2 + depth ** 2) / 12
    np.testing.assert_allclose(np.diag(out.inertia), [ixx, ixx, izz], rtol=1e-12)


def test_hole_that_leaves_the_part_is_refused(rotor):
    with pytest.raises(PhysicsError, match="leaves the part"):
        _report(rotor, radius=0.099)           # a 12 mm drill 1 mm inside the rim breaks out


def test_without_the_mesh_the_report_says_the_holes_were_not_checked(rotor):
    report = _report(rotor, part_mesh=None)
    assert not any(h.inside_checked for h in report.drillings)
    assert any("not checked" in n for n in report.notes)


def test_cli_balance_drill(rotor, tmp_path, capsys):
    import json

    import trimesh

    from inertia_tool.cli import main
    _, (v, f) = rotor
    path = tmp_path / "rotor.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(path)
    code = main(["balance", str(path), "--units", "mm", "--density", "7850", "--rpm", "3000", "--planes",
                 "-20,20", "--radius", "70", "--drill", "12mm", "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["drillings"]) == 2 and all(h["inside_checked"] for h in data["drillings"])
    assert data["drilled_verification"]["kind"] in ("balanced", "static", "couple", "quasi-static", "dynamic")
    assert main(["balance", str(path), "--units", "mm", "--density", "7850", "--rpm", "3000", "--planes",
                 "-20,20", "--radius", "70", "--drill", "12mm"]) == 0
    assert "drill parallel to the shaft" in capsys.readouterr().out
