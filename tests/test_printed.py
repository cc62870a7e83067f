"""Printed-part model (thinwall.printed_part): the skin is the part less its inward offset, the core filled."""

import numpy as np
import pytest
import trimesh

from inertia_tool import mass_properties
from hypothesis import given, settings, strategies as st

from inertia_tool.errors import UsageError
from inertia_tool.mass.thinwall import printed_part
from conftest import assert_tensor_close

A, B, C, RHO = 0.08, 0.05, 0.03, 1240.0   # a PLA block, m and kg/m³


def _box_inertia(mass, a, b, c):
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _exact_printed_box(skin, infill):
    """The exact printed box: the outer box minus (1 − f) of the inner box offset inward by the skin."""
    ai, bi, ci = A - 2 * skin, B - 2 * skin, C - 2 * skin
    m_out, m_in = RHO * A * B * C, RHO * ai * bi * ci
    mass = m_out - (1 - infill) * m_in
    inertia = _box_inertia(m_out, A, B, C) - (1 - infill) * _box_inertia(m_in, ai, bi, ci)
    return mass, inertia


@pytest.fixture
def block():
    box = trimesh.creation.box([A, B, C])
    box.apply_translation([0.01, -0.02, 0.005])
    return box.vertices, box.faces


def _vf(solid):
    return solid.vertices, solid.faces


def _rotation(angles):
    from scipy.spatial.transform import Rotation
    return Rotation.from_euler("xyz", angles).as_matrix()


def _assert_within_bounds(part, mass, com, inertia):
    """The closed-form values lie inside the bounds the part states (each bound must hold)."""
    p = part.properties
    assert abs(p.mass / mass - 1) <= part.mass_error_bound * (1 + 1e-9)
    assert np.linalg.norm(p.center_of_mass - com) <= part.center_of_mass_error_bound + 1e-15
    top = np.max(np.linalg.eigvalsh(p.inertia))
    assert np.linalg.norm(p.inertia - inertia, 2) <= part.inertia_error_bound * top * (1 + 1e-9)


def test_printed_20mm_cube_is_the_cube_less_its_inward_offset():
    """Issue 24: --shell 1.2mm --infill 20% on the 20 mm cube gave 4.944 g ("over-counted by about 6.58 %").
    The exact skin is the cube less the 17.6 mm cube: M = ρ[a³ − (1 − f)(a − 2s)³] = 4.5118 g of PLA."""
    a, s, f = 0.02, 0.0012, 0.2
    part = printed_part(trimesh.creation.box([a, a, a]), skin=s, infill=f, density=RHO)
    mass = RHO * (a ** 3 - (1 - f) * (a - 2 * s) ** 3)
    inertia = (_box_inertia(RHO * a ** 3, a, a, a)
               - (1 - f) * _box_inertia(RHO * (a - 2 * s) ** 3, a - 2 * s, a - 2 * s, a - 2 * s))
    assert part.properties.mass == pytest.approx(mass, rel=1e-3)
    assert mass == pytest.approx(4.5118e-3, rel=1e-4)
    assert_tensor_close(part.properties.inertia, inertia, rtol=1e-3)
    assert part.core_volume == pytest.approx((a - 2 * s) ** 3, rel=1e-3)
    _assert_within_bounds(part, mass, np.zeros(3), inertia)
    assert 0 < part.mass_error_bound < 0.05 and part.inertia_error_bound < 0.1


def test_printed_sphere_cylinder_and_torus_match_their_closed_forms():
    """The inward offset of a sphere, a cylinder and a torus is known: radius r − s (and height h − 2s).  The
    meshes are fine tessellations (their own volume within ~0.1 % of the smooth solid), so 1 % is the test."""
    s, f = 0.0012, 0.2
    from inertia_tool.mass import shapes
    r, h, big = 0.01, 0.03, 0.02
    cases = [(trimesh.creation.icosphere(5, radius=r), 4 / 3 * np.pi * r ** 3, 4 / 3 * np.pi * (r - s) ** 3),
             (trimesh.creation.cylinder(radius=r, height=h, sections=256), np.pi * r * r * h,
              np.pi * (r - s) ** 2 * (h - 2 * s)),
             (_vf(shapes.torus(big, r, segments=192, rings=96)), 2 * np.pi ** 2 * big * r * r,
              2 * np.pi ** 2 * big * (r - s) ** 2)]
    for mesh, volume, core in cases:
        part = printed_part(mesh, skin=s, infill=f, density=RHO, band_cells=30_000)
        assert part.properties.mass == pytest.approx(RHO * (volume - (1 - f) * core), rel=0.01)
        assert part.core_volume == pytest.approx(core, rel=0.01)
        assert np.isfinite(part.mass_error_bound) and part.mass_error_bound < 0.1


def test_printed_hollow_sphere_core_lies_between_both_offsets():
    """A spherical shell r_i ≤ |x| ≤ r_o (a cavity: a non-convex solid): its core is the shell
    r_i + s ≤ |x| ≤ r_o − s."""
    from inertia_tool.mass import shapes
    r_o, r_i, s = 0.02, 0.012, 0.0015
    mesh = _vf(shapes.hollow_sphere(r_o, r_i))
    part = printed_part(mesh, skin=s, infill=0.0, density=RHO, band_cells=30_000)
    core = 4 / 3 * np.pi * ((r_o - s) ** 3 - (r_i + s) ** 3)
    assert part.core_volume == pytest.approx(core, rel=0.01)


@settings(max_examples=6, deadline=None)
@given(dims=st.tuples(*[st.floats(0.01, 0.05)] * 3), skin=st.floats(0.0005, 0.003), infill=st.floats(0.0, 0.9),
       angles=st.tuples(*[st.floats(0.0, 3.0)] * 3), shift=st.tuples(*[st.floats(-0.05, 0.05)] * 3))
def test_printed_box_bounds_hold_at_any_pose(dims, skin, infill, angles, shift):
    """A box at a random rotation and position (never aligned with the integration grid): the exact mass,
    centre of mass and inertia lie within the stated bounds, on cases nobody tuned on."""
    a, b, c = dims
    box = trimesh.creation.box([a, b, c])
    rot = _rotation(angles)
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = rot, shift
    box.apply_transform(transform)
    part = printed_part(box, skin=skin, infill=infill, density=RHO, band_cells=5_000)
    inner = [max(x - 2 * skin, 0.0) for x in (a, b, c)]
    m_out, m_in = RHO * a * b * c, RHO * float(np.prod(inner))
    mass = m_out - (1 - infill) * m_in
    local = _box_inertia(m_out, a, b, c) - (1 - infill) * _box_inertia(m_in, *inner)
    _assert_within_bounds(part, mass, np.asarray(shift), rot @ local @ rot.T)
    assert part.properties.mass == pytest.approx(mass, rel=0.01)


def test_full_infill_is_the_solid(block):
    part = printed_part(block, skin=0.001, infill=1.0, density=RHO)
    solid = mass_properties(block, density=RHO)
    assert part.properties.mass == pytest.approx(solid.mass, rel=1e-13)
    np.testing.assert_allclose(part.properties.inertia, solid.inertia, rtol=1e-12,
                               atol=1e-12 * np.abs(solid.inertia).max())
    assert part.mass_error_bound == 0.0 and part.properties.mesh.exact


def test_weighed_print_scales_density(block):
    part = printed_part(block, skin=0.0012, infill=0.15, mass=0.05, band_cells=5_000)
    assert part.properties.mass == pytest.approx(0.05)
    ref = printed_part(block, skin=0.0012, infill=0.15, density=RHO, band_cells=5_000)
    assert_tensor_close(part.properties.inertia, ref.properties.inertia * 0.05 / ref.properties.mass, rtol=1e-12)


def test_skin_past_the_middle_leaves_a_solid_part(block):
    """A skin at least half the thinnest dimension leaves no core: the part prints solid, exactly."""
    part = printed_part(block, skin=0.02, infill=0.2, density=RHO)
    solid = mass_properties(block, density=RHO)
    assert part.properties.mass == pytest.approx(solid.mass, rel=1e-13)
    assert part.core_volume == 0.0 and part.mass_error_bound == 0.0


@pytest.mark.parametrize("skin, infill", [(0.0, 0.2), (-1e-3, 0.2), (1e-3, 1.2), (1e-3, -0.1)])
def test_bad_parameters(block, skin, infill):
    with pytest.raises(UsageError):
        printed_part(block, skin=skin, infill=infill, density=RHO)


# -- command line ----------------------------------------------------------------------------------------------

@pytest.fixture
def block_stl(tmp_path):
    from conftest import write_binary_stl
    box = trimesh.creation.box([A * 1000, B * 1000, C * 1000])
    p = tmp_path / "block.stl"
    write_binary_stl(p, box.vertices, box.faces)
    return str(p)


def test_cli_printed_json_states_the_model(block_stl, capsys, core_moments_memo):
    import json
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", "--material", "pla", "--shell", "1.2mm", "--infill", "20%",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = printed_part(trimesh.creation.box([A, B, C]), skin=0.0012, infill=0.2, density=RHO)
    assert out["mass"] == pytest.approx(ref.properties.mass, rel=1e-6)
    assert out["model"]["model"] == "printed" and out["model"]["infill"] == pytest.approx(0.2)
    assert out["model"]["mass_error_bound"] == pytest.approx(ref.mass_error_bound, rel=1e-6)
    assert 0 < out["model"]["mass_error_bound"] < 0.05


def test_cli_printed_text_states_the_error(block_stl, capsys, core_moments_memo):
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", "--material", "pla", "--shell", "1.2", "--infill", "0.2"]) == 0
    text = capsys.readouterr().out
    assert "model: printed part, skin 1.2 mm, infill 20%" in text and "bounds that hold" in text
    assert "over-counted" not in text and "ESTIMATE" in text


@pytest.mark.parametrize("args", [["--shell", "1mm"], ["--infill", "20%"], ["--thickness", "2mm"],
                                  ["--model", "shell"], ["--model", "shell", "--thickness", "1mm", "--shell", "1mm",
                                                         "--infill", "20%"],
                                  ["--shell", "1mm", "--infill", "120%"], ["--shell", "1 furlong", "--infill", "20%"]])
def test_cli_contradictory_model_options_exit_2(block_stl, args, capsys):
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", *args]) == 2
    assert "error" in capsys.readouterr().err


# -- top and bottom layers as a slicer makes them --------------------------------------------------------------
def _slab_box_inertia(mass, a, b, c):
    return _box_inertia(mass, a, b, c)


@pytest.mark.parametrize("layers, height", [(6, 0.0002), (8, 0.00025)])
def test_printed_cube_with_top_and_bottom_layers_closed_form(layers, height):
    """20 mm cube, walls 0.8 mm (two 0.4 mm perimeters), N top and bottom layers of height H, 20 % infill: the
    infill is the core [t, a − t]² × [T, a − T] with T = N H > t (closed form: walls + slabs + infilled core);
    the mass and inertia within 1 %, and inside the stated bounds."""
    a, s, f = 0.02, 0.0008, 0.2
    thickness = layers * height
    part = printed_part(trimesh.creation.box([a, a, a]), skin=s, infill=f, density=RHO, top=thickness,
                        bottom=thickness, band_cells=30_000)
    ci, hi = a - 2 * s, a - 2 * thickness
    mass = RHO * (a ** 3 - (1 - f) * ci * ci * hi)
    inertia = _box_inertia(RHO * a ** 3, a, a, a) - (1 - f) * _box_inertia(RHO * ci * ci * hi, ci, ci, hi)
    assert part.properties.mass == pytest.approx(mass, rel=0.01)
    assert_tensor_close(part.properties.inertia, inertia, rtol=0.01)
    without = RHO * (a ** 3 - (1 - f) * ci ** 3)
    assert abs(part.properties.mass - mass) < 0.1 * abs(without - mass)      # the layers are really counted
    _assert_within_bounds(part, mass, np.zeros(3), inertia)
    assert part.top == part.bottom == thickness


def test_printed_cylinder_with_top_and_bottom_layers_closed_form():
    """A 128-gon prism (apothem a, height h), walls s, top/bottom T: the infill is the prism of apothem a − s
    over [T, h − T] (closed form from the polygon's area n a² tan(π/n)), within 1 %."""
    n, radius, h, s, thickness, f = 128, 0.01, 0.02, 0.0008, 0.0016, 0.15
    from inertia_tool.mass import shapes
    solid = shapes.cylinder(radius, h, segments=n)
    apothem = radius * np.cos(np.pi / n)
    area = n * (apothem - s) ** 2 * np.tan(np.pi / n)
    volume = solid.mesh_exact.volume
    mass = RHO * (volume - (1 - f) * area * (h - 2 * thickness))
    part = printed_part(_vf(solid), skin=s, infill=f, density=RHO, top=thickness, bottom=thickness,
                        band_cells=30_000)
    assert part.properties.mass == pytest.approx(mass, rel=0.01)
    assert part.mass_error_bound >= abs(part.properties.mass / mass - 1)


def test_layers_thinner_than_the_wall_change_nothing(block):
    plain = printed_part(block, skin=0.002, infill=0.2, density=RHO, band_cells=5_000)
    thin = printed_part(block, skin=0.002, infill=0.2, density=RHO, top=0.0015, bottom=0.001, band_cells=5_000)
    assert thin.properties.mass == plain.properties.mass


@pytest.mark.slow
def test_cli_top_bottom_layers(block_stl, capsys, core_moments_memo):
    from inertia_tool.cli import main
    import json
    base = ["analyze", str(block_stl), "--units", "mm", "--material", "pla", "--shell", "0.8mm", "--infill", "20%",
            "--json"]
    assert main(base) == 0
    plain = json.loads(capsys.readouterr().out)["mass"]
    assert main(base + ["--top-layers", "6", "--bottom-layers", "6", "--layer-height", "0.3mm"]) == 0
    layered = json.loads(capsys.readouterr().out)["mass"]
    assert main(base + ["--top-bottom", "1.8mm"]) == 0
    same = json.loads(capsys.readouterr().out)["mass"]
    assert layered > plain and same == pytest.approx(layered, rel=1e-12)
    assert main(base + ["--top-layers", "6"]) == 2                      # needs --layer-height
    assert main(base + ["--top-bottom", "1mm", "--top-layers", "3", "--layer-height", "0.2mm"]) == 2
