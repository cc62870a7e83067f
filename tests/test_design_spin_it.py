"""spin-it (inertia_tool.design): voxel grid, moment vectors, and the yo-yo and top designs verified by exact
re-analysis and by simulating the spin (Chapter 4 §4.4.1 and §4.4.3)."""

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

manifold3d = pytest.importorskip("manifold3d")

from conftest import assert_tensor_close  # noqa: E402
from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.cli import main  # noqa: E402
from inertia_tool.design import spin_it  # noqa: E402
from inertia_tool.design.grid import interior_grid, surface_distance  # noqa: E402
from inertia_tool.design.hollow import design_frame  # noqa: E402
from inertia_tool.design.moments import cell_moment_rows, frame_quantities, moment_vector  # noqa: E402
from inertia_tool.dynamics.simulation import simulate  # noqa: E402
from inertia_tool.dynamics.top import heavy_top, heavy_top_on_pivot  # noqa: E402
from inertia_tool.errors import AsymmetricTopWarning, InvalidMeshError, UsageError  # noqa: E402
from inertia_tool.mass import shapes  # noqa: E402
from inertia_tool.rotations import quaternion_to_matrix  # noqa: E402


def _arrays(solid):
    mesh = solid.to_mesh64()
    return np.asarray(mesh.vert_properties)[:, :3].copy(), np.asarray(mesh.tri_verts).astype(np.int64)


def lopsided_yoyo():
    """A 60 mm disc, 12 mm thick, with an off-centre 18 mm bump (Spin-It's lopsided yo-yo), m."""
    disc = manifold3d.Manifold.cylinder(0.012, 0.03, 0.03, 96).translate([0, 0, -0.006])
    bump = manifold3d.Manifold.sphere(0.009, 48).translate([0.016, 0.004, 0.006])
    return _arrays(disc + bump)


def asymmetric_top():
    """A tilted ellipsoid on a conical tip with an off-axis handle; tip at the origin, axis +z, m."""
    body = manifold3d.Manifold.sphere(1.0, 64).scale([0.025, 0.018, 0.012]).rotate([20, 0, 0]).translate(
        [0.002, 0, 0.016])
    tip = manifold3d.Manifold.cylinder(0.008, 0.0005, 0.007, 48)
    handle = manifold3d.Manifold.cylinder(0.02, 0.003, 0.003, 32).translate([0.004, 0.002, 0.022])
    return _arrays(body + tip + handle)


@pytest.fixture(scope="module")
def yoyo():
    v, f = lopsided_yoyo()
    return spin_it((v, f), axis=[0, 0, 1], through=[0, 0, 0], mode="yoyo", wall=0.002, material="PLA",
                   resolution=40)


@pytest.fixture(scope="module")
def top():
    v, f = asymmetric_top()
    return spin_it((v, f), axis=[0, 0, 1], pivot=[0, 0, 0], mode="top", wall=0.0015, material="PLA",
                   resolution=40)


# -- the grid -------------------------------------------------------------------------------------------
def test_grid_inside_matches_the_volume_and_skips_a_cavity():
    solid = shapes.hollow_sphere(0.03, 0.015, segments=48)
    grid = interior_grid(solid.vertices, solid.faces, spacing=0.001)
    volume = grid.inside.sum() * grid.spacing ** 3
    assert volume == pytest.approx(solid.mesh_exact.volume, rel=0.02)
    centres = grid.centers(np.nonzero(grid.inside))
    radius = np.linalg.norm(centres, axis=1)
    assert radius.min() > 0.0145 and radius.max() < 0.0301       # nothing inside the cavity


def test_surface_distance_is_the_distance_to_a_box():
    """Inside a box the distance to the surface is the smallest distance to its six faces (closed form)."""
    box = shapes.box(0.04, 0.03, 0.02)
    rng = np.random.default_rng(3)
    points = rng.uniform(-1, 1, size=(3000, 3)) * [0.02, 0.015, 0.01]
    exact = np.min(np.column_stack([0.02 - abs(points[:, 0]), 0.015 - abs(points[:, 1]),
                                    0.01 - abs(points[:, 2])]), axis=1)
    cutoff = 0.006
    measured = surface_distance(points, box.vertices, box.faces, cutoff=cutoff)
    np.testing.assert_allclose(measured, np.minimum(exact, cutoff), atol=1e-15)


def test_grid_depth_is_within_a_cell_of_the_true_depth():
    box = shapes.box(0.04, 0.03, 0.02)
    grid = interior_grid(box.vertices, box.faces, spacing=0.001)
    index = np.nonzero(grid.inside)
    c = grid.centers(index)
    exact = np.min(np.column_stack([0.02 - abs(c[:, 0]), 0.015 - abs(c[:, 1]), 0.01 - abs(c[:, 2])]), axis=1)
    error = grid.signed_distance[index] - exact
    # stored as float32: the depth may read low by its rounding (2⁻²⁴ relative)
    assert error.min() >= -2.0 ** -24 * exact.max() and error.max() <= math.sqrt(3) * grid.spacing


# -- moment vectors ----------------------------------------------------------------------------------------
def test_moment_vector_round_trip_in_a_rotated_frame():
    solid = shapes.octahedron(0.02, 0.03, 0.05, center=[0.01, -0.02, 0.03])
    props = solid.exact
    axis = np.array([0.3, -0.5, 0.8])
    frame = design_frame(axis / np.linalg.norm(axis))
    origin = np.array([0.002, 0.001, -0.004])
    m, c, i_origin, i_center = frame_quantities(moment_vector(props, origin, frame))
    assert m == pytest.approx(props.mass)
    np.testing.assert_allclose(frame @ c + origin, props.center_of_mass, atol=1e-15)
    assert_tensor_close(frame @ i_center @ frame.T, props.inertia, rtol=1e-12)
    assert_tensor_close(frame @ i_origin @ frame.T, props.inertia_about(origin).tensor, rtol=1e-12)


def test_cells_of_a_block_sum_to_the_exact_box():
    """Cells tile a box exactly, so their moment rows add up to its closed-form moments."""
    h = 0.002
    idx = np.stack(np.meshgrid(np.arange(3), np.arange(4), np.arange(5), indexing="ij"), -1).reshape(-1, 3)
    centres = (idx + 0.5) * h + np.array([0.01, 0.02, -0.005])
    total = cell_moment_rows(centres, h).sum(axis=0)
    box = shapes.box(3 * h, 4 * h, 5 * h, center=[0.01 + 1.5 * h, 0.02 + 2 * h, -0.005 + 2.5 * h])
    expected = moment_vector(box.exact, np.zeros(3), np.eye(3))
    np.testing.assert_allclose(total, expected, rtol=1e-12, atol=1e-12 * abs(expected).max())


# -- yo-yo ------------------------------------------------------------------------------------------------
def test_yoyo_design_is_verified_by_reanalysis(yoyo):
    again = mass_properties((yoyo.vertices, yoyo.faces), density=yoyo.before.density)
    assert again.mass == pytest.approx(yoyo.after.mass, rel=1e-12)
    assert_tensor_close(again.inertia, yoyo.after.inertia, rtol=1e-12)
    assert again.mesh.bodies == 1 if hasattr(again.mesh, "bodies") else True
    assert yoyo.after.mass < yoyo.before.mass
    assert yoyo.cavity_volume == pytest.approx(yoyo.before.volume - yoyo.after.volume)
    assert yoyo.measured_wall >= yoyo.wall


def test_yoyo_centre_of_mass_moves_onto_the_axis_and_the_axis_becomes_principal(yoyo):
    b, a = yoyo.metrics_before, yoyo.metrics_after
    assert a.axis_offset < b.axis_offset / 5            # 0.70 mm → ~0.1 mm
    assert a.axis_tilt < b.axis_tilt / 5                # 1.7° → a few hundredths of a degree
    assert a.nearest_principal == "major" and a.epsilon_coefficient < 0
    assert a.moment_ratio > 1.7


def _wobble(props, axis, rate=60.0, turns=20):
    """Largest angle between the body's requested axis (carried into space) and the fixed angular momentum
    when the body is set spinning about that axis (torque-free, Eqs. 4.27)."""
    t = np.linspace(0, turns * 2 * math.pi / rate, 40 * turns + 1)
    traj = simulate(props, rate * np.asarray(axis, float), t)
    rotations = quaternion_to_matrix(traj.orientation)
    carried = rotations @ np.asarray(axis, float)
    momentum = traj.angular_momentum[0] / np.linalg.norm(traj.angular_momentum[0])
    return float(np.max(np.arccos(np.clip(carried @ momentum, -1, 1))))


def test_yoyo_spins_without_wobble_after_hollowing(yoyo):
    """Simulated free spin about the requested axis: the wobble follows the axis tilt, and shrinks with it."""
    before = _wobble(yoyo.before, yoyo.axis)
    after = _wobble(yoyo.after, yoyo.axis)
    assert after < before / 5
    assert before > yoyo.metrics_before.axis_tilt     # the axis circles the momentum at more than its tilt


# -- top --------------------------------------------------------------------------------------------------
def test_top_metrics_are_the_heavy_top_analysis_of_the_reanalysed_part(top):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AsymmetricTopWarning)
        report = heavy_top_on_pivot(top.after, [0, 0, 0], theta0=0.0, omega3=1.0)
    assert top.metrics_after.sleeping_threshold == pytest.approx(report.critical_sleeping_spin, rel=1e-12)
    assert top.metrics_after.transverse_asymmetry == pytest.approx(report.transverse_asymmetry, rel=1e-12)
    assert top.measured_wall >= top.wall


def test_top_becomes_more_symmetric_with_its_centre_of_mass_on_the_axis(top):
    b, a = top.metrics_before, top.metrics_after
    assert a.axis_offset < b.axis_offset / 2
    assert a.transverse_asymmetry < b.transverse_asymmetry / 1.5
    assert a.axis_tilt < b.axis_tilt / 2
    assert a.height > 0
    # the sleeping threshold moves by little here: the penalties for symmetry dominate (docs/spin-it.md)
    assert a.sleeping_threshold == pytest.approx(b.sleeping_threshold, rel=0.05)


def test_top_sleeps_above_its_threshold_in_simulation(top):
    """The hollowed top, as the heavy symmetric top of §4.4.3, spun 20 % above its sleeping threshold from a
    tilt of 0.02 rad stays upright; 20 % below it falls away from the vertical (simulated, heavy_top)."""
    a = top.metrics_after
    for factor, stays in ((1.2, True), (0.8, False)):
        t = heavy_top(a.next_moment, a.axis_moment, a.mass, a.height, theta0=0.02,
                      omega3=factor * a.sleeping_threshold)
        period = t.nutation_period if math.isfinite(t.nutation_period) else 1.0
        traj = t.simulate(min(3 * period, 2.0), samples=3001)
        assert bool(traj.theta.max() < 0.1) is stays
        assert traj.theta.max() == pytest.approx(t.theta_max, rel=1e-3)


# -- command line ------------------------------------------------------------------------------------------
def test_cli_spin_it_writes_a_hollow_part_and_json(tmp_path, capsys):
    import trimesh
    v, f = lopsided_yoyo()
    src = tmp_path / "yoyo.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(src)
    out = tmp_path / "hollow.stl"
    code = main(["spin-it", str(src), "--units", "mm", "--material", "PLA", "--axis", "0,0,1", "--through",
                 "0,0,0", "--wall", "2mm", "--resolution", "24", "--out", str(out), "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    if data["after"]["mass_properties"]["certificate"]["kind"] == "exact":
        written = mass_properties(str(out), units="mm", material="PLA")
        assert written.mass == pytest.approx(data["after"]["mass_properties"]["mass"], rel=1e-6)
    else:   # manifold3d's boolean left the surface passing through itself: said in "verified", refused on reading
        assert "passes through itself" in data["verified"]
        with pytest.raises(InvalidMeshError, match="passes through itself"):
            mass_properties(str(out), units="mm", material="PLA")
    assert data["after"]["metrics"]["axis_offset"] < data["before"]["metrics"]["axis_offset"]
    # refuses to replace the output, and --mode top without --pivot
    assert main(["spin-it", str(src), "--units", "mm", "--axis", "0,0,1", "--wall", "2", "--out", str(out)]) == 2
    assert main(["spin-it", str(src), "--units", "mm", "--axis", "0,0,1", "--wall", "2", "--mode", "top"]) == 2
    assert "--pivot" in capsys.readouterr().err
    pytest.importorskip("matplotlib")
    png = tmp_path / "sections.png"
    assert main(["spin-it", str(src), "--units", "mm", "--axis", "0,0,1", "--wall", "2mm", "--resolution", "24",
                 "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"


def test_bad_parameters_are_refused():
    v, f = lopsided_yoyo()
    with pytest.raises(UsageError, match="mode"):
        spin_it((v, f), axis=[0, 0, 1], mode="gyro", wall=0.002)
    with pytest.raises(UsageError, match="pivot"):
        spin_it((v, f), axis=[0, 0, 1], mode="top", wall=0.002)
    with pytest.raises(UsageError, match="axis"):
        spin_it((v, f), axis=[0, 0, 0], wall=0.002)
    with pytest.raises(UsageError, match="wall"):
        spin_it((v, f), axis=[0, 0, 1], wall=-1.0)


# -- dense insert (two quadrics) ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def top_with_insert():
    v, f = asymmetric_top()
    return spin_it((v, f), axis=[0, 0, 1], pivot=[0, 0, 0], mode="top", wall=0.0015, material="PLA",
                   resolution=32, insert_density=7850.0)


@pytest.mark.slow
def test_steel_insert_makes_the_top_symmetric_and_lowers_its_sleeping_spin(top, top_with_insert):
    b, a, hollow_only = top_with_insert.metrics_before, top_with_insert.metrics_after, top.metrics_after
    assert top_with_insert.insert is not None
    assert a.transverse_asymmetry < b.transverse_asymmetry / 4            # 0.19 → ~0.02
    assert a.transverse_asymmetry < hollow_only.transverse_asymmetry / 2
    assert a.axis_offset < b.axis_offset / 4
    assert a.sleeping_threshold < 0.95 * b.sleeping_threshold             # 89 → ~77 rad/s
    assert top_with_insert.objective_after < top.objective_after


@pytest.mark.slow
def test_insert_is_verified_as_two_bodies_inside_the_wall(top_with_insert):
    r = top_with_insert
    shell = mass_properties((r.vertices, r.faces), density=r.before.density)
    insert = mass_properties((r.insert_vertices, r.insert_faces), density=7850.0)
    assert r.after.mass == pytest.approx(shell.mass + insert.mass, rel=1e-12)
    np.testing.assert_allclose(r.after.center_of_mass,
                               (shell.mass * shell.center_of_mass + insert.mass * insert.center_of_mass)
                               / (shell.mass + insert.mass), atol=1e-12)
    # the insert fills part of the pocket: shell and insert together are no more than the solid part
    assert shell.volume + insert.volume <= r.before.volume * (1 + 1e-9)
    v, f = asymmetric_top()
    assert surface_distance(r.insert_vertices, v, f, cutoff=0.01).min() >= r.wall


@pytest.mark.slow
def test_cli_insert_writes_a_two_material_3mf(tmp_path, capsys):
    import trimesh
    v, f = asymmetric_top()
    src = tmp_path / "top.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(src)
    out = tmp_path / "top.3mf"
    args = ["spin-it", str(src), "--units", "mm", "--material", "PLA", "--axis", "0,0,1", "--mode", "top",
            "--pivot", "0,0,0", "--wall", "1.5mm", "--resolution", "24", "--insert", "steel"]
    assert main(args + ["--out", str(tmp_path / "top.stl.out.stl")]) == 2      # two materials need 3MF
    assert main(args + ["--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    scene = trimesh.load(out)
    volumes = sorted(g.volume for g in scene.geometry.values())                 # mm³
    assert len(volumes) == 2 and all(g.is_watertight for g in scene.geometry.values())
    assert volumes[0] * 1e-9 == pytest.approx(data["insert"]["volume_m3"], rel=1e-6)


# -- the written file is what was reported (issue: the hollowed part crossed itself by rounding) ------------
def _round_trip(tmp_path, capsys, source, options):
    out = tmp_path / "out.stl"
    assert main(["spin-it", str(source), "--units", "mm", "--material", "PLA", "--out", str(out), "--json",
                 *options]) == 0
    reported = json.loads(capsys.readouterr().out)
    assert main(["analyze", str(out), "--units", "mm", "--material", "PLA", "--json"]) == 0
    analysed = json.loads(capsys.readouterr().out)
    return reported, analysed


@pytest.mark.slow
@pytest.mark.parametrize("name, options", [
    ("box.stl", ["--axis", "0,0,1", "--wall", "2mm", "--resolution", "96"]),          # crossed at 4 face pairs
    ("unbalanced_wheel.stl", ["--axis", "0,0,1", "--wall", "3mm", "--resolution", "96"]),   # crossed at 40
    ("spinning_top.stl", ["--mode", "top", "--pivot", "0,0,0", "--axis", "0,0,1", "--wall", "2mm"]),
    ("octahedron.stl", ["--axis", "0,0,1", "--wall", "2mm"]),
])
def test_written_part_analyses_exact_to_the_reported_mass(tmp_path, capsys, name, options):
    from pathlib import Path
    reported, analysed = _round_trip(tmp_path, capsys, Path(__file__).parents[1] / "meshes" / name, options)
    assert reported["removed_cells"] > 0
    assert analysed["certificate"]["kind"] == "exact"
    assert analysed["mass"] == pytest.approx(reported["after"]["mass_properties"]["mass"], rel=1e-9, abs=0)


@pytest.mark.slow
@settings(max_examples=4, deadline=None)
@given(st.lists(st.tuples(st.floats(-8, 8), st.floats(-8, 8), st.floats(-3, 3), st.floats(6, 14)),
                min_size=1, max_size=3), st.floats(0, 90), st.sampled_from([32, 48, 64]))
def test_written_generated_parts_analyse_exact(tmp_path_factory, blobs, tilt, resolution):
    """Unions of rounded boxes and balls (mm), tilted: the file spin-it writes is certified exact by analyze and
    holds the reported mass."""
    import trimesh
    from hypothesis import assume
    body = manifold3d.Manifold.cube([40, 30, 12], center=True)
    for x, y, z, r in blobs:
        body = body + manifold3d.Manifold.sphere(r, 40).translate([x, y, z])
    v, f = _arrays(body.rotate([tilt, 0, 0]))
    tmp = tmp_path_factory.mktemp("generated")
    source = tmp / "part.stl"
    trimesh.Trimesh(v, f, process=False).export(source)
    out = tmp / "out.stl"
    import contextlib
    import io
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        code = main(["spin-it", str(source), "--units", "mm", "--material", "PLA", "--axis", "0,0,1", "--wall",
                     "2mm", "--resolution", str(resolution), "--out", str(out), "--json"])
    assume(code == 0)                        # a design may be rejected (exit 6): nothing written to check
    reported = json.loads(buffer.getvalue())
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["analyze", str(out), "--units", "mm", "--material", "PLA", "--json"]) == 0
    analysed = json.loads(buffer.getvalue())
    assert analysed["certificate"]["kind"] == "exact"
    assert analysed["mass"] == pytest.approx(reported["after"]["mass_properties"]["mass"], rel=1e-9, abs=0)


# -- ring insert -------------------------------------------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(st.floats(0.001, 0.05), st.floats(-0.01, 0.01), st.floats(-0.01, 0.01), st.floats(0.005, 0.05))
def test_ring_quadric_is_negative_exactly_beyond_its_radius(radius, cx, cy, half):
    """``ring_coefficients``: q(x̂) < 0 ⇔ x² + y² > ρ² for frame points x = centre + half x̂ (independent: the
    radius computed from the points)."""
    from inertia_tool.design.insert import ring_coefficients
    from inertia_tool.design.optimize import quadric_values
    centre = np.array([cx, cy, 0.003])
    rng = np.random.default_rng(int(radius * 1e6))
    points = rng.uniform(-0.06, 0.06, size=(500, 3))
    q = quadric_values(ring_coefficients(radius, centre, half), (points - centre) / half)
    r2 = points[:, 0] ** 2 + points[:, 1] ** 2
    clear = np.abs(r2 - radius ** 2) > 1e-9 * max(radius ** 2, 1e-6)
    np.testing.assert_array_equal((q < 0)[clear], (r2 > radius ** 2)[clear])


@pytest.mark.slow
def test_insert_is_the_best_exact_objective_of_its_shapes():
    """With an insert allowed, spin-it meshes the quadric insert, the ring (a rim about the axis) and the cavity
    alone and keeps the best exact objective: never worse than the cavity-only design at the same grid."""
    from pathlib import Path
    top = Path(__file__).parents[1] / "meshes" / "spinning_top.stl"
    spec = dict(units="mm", material="PLA", mode="top", pivot=[0, 0, 0], axis=[0, 0, 1], wall=0.002,
                resolution=32)
    alone = spin_it(str(top), **spec)
    with_insert = spin_it(str(top), insert_density=7850.0, **spec)
    assert with_insert.objective_after <= alone.objective_after * (1 + 1e-9)
    assert with_insert.insert_shape in ("quadric", "ring", None)
    assert (with_insert.insert is None) == (with_insert.insert_shape is None)


# -- a top's pivot in empty space (issue 24 item 3) ----------------------------------------------------------
@pytest.mark.parametrize("pivot, warned", [
    ((0.0, 0.0, 0.0), False),             # the centre: inside the material
    ((0.0, 0.0, -0.5), False),            # on the bottom face
    ((0.5, 0.5, -0.5), False),            # a corner
    ((0.0, 0.0, -0.515), False),          # 1.5 % of the extent below: within PIVOT_GAP_RTOL
    ((0.0, 0.0, -0.53), True),            # 3 % below the bottom face
    ((0.0, 0.0, -30.0), True),            # a millimetre pivot read as metres
    ((0.7, 0.7, 0.0), True),              # beside the part
])
def test_a_pivot_outside_the_part_is_warned_about(pivot, warned):
    from inertia_tool.design.grid import SurfaceTree
    from inertia_tool.design.hollow import _warn_pivot_off_part
    from inertia_tool.errors import PivotOffPartWarning
    from inertia_tool.tolerances import PIVOT_GAP_RTOL

    cube = shapes.box(1.0, 1.0, 1.0)                 # unit cube about the origin, extent 1 m
    v, f = cube.vertices, cube.faces
    assert PIVOT_GAP_RTOL == pytest.approx(0.02)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _warn_pivot_off_part("cube", np.array(pivot), v, f, SurfaceTree(v, f), 1.0)
    found = [w for w in caught if issubclass(w.category, PivotOffPartWarning)]
    assert bool(found) is warned
    if warned:
        assert "empty space" in str(found[0].message) and "--pivot" in str(found[0].message)


def test_spin_it_top_warns_about_a_pivot_below_its_tip_and_not_at_it():
    from inertia_tool.errors import PivotOffPartWarning

    v, f = asymmetric_top()
    for pivot, warned in (([0, 0, 0], False), ([0, 0, -0.01], True)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = spin_it((v, f), axis=[0, 0, 1], pivot=pivot, mode="top", wall=0.0015, material="PLA",
                             resolution=16)
        assert np.allclose(result.origin, pivot)             # designed as asked
        assert any(issubclass(w.category, PivotOffPartWarning) for w in caught) is warned


@pytest.mark.parametrize("named, expected", [("z", (0, 0, 1)), ("X", (1, 0, 0)), ("-y", (0, -1, 0)),
                                             ("+z", (0, 0, 1)), ("0,0,2", (0, 0, 1))])
def test_the_spin_axis_can_be_named(named, expected):
    from inertia_tool.cli.spin_it import _direction
    np.testing.assert_array_equal(_direction(named), expected)


@pytest.mark.parametrize("bad", ["w", "zz", "0,0,0", "1,2", "nan,0,1", "--z"])
def test_a_bad_spin_axis_is_a_usage_error(bad):
    from inertia_tool.cli.spin_it import _direction
    from inertia_tool.errors import UsageError
    with pytest.raises(UsageError, match="--axis must be"):
        _direction(bad)
