"""Printed-part model (thinwall.printed_part): solid skin plus partially filled core, first order in the skin."""

import numpy as np
import pytest
import trimesh

from inertia_tool import mass_properties
from inertia_tool.errors import PhysicsError, UsageError
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


def test_exact_hollow_box_mass_error_matches_the_stated_estimate(block):
    """The first-order skin volume A·s over-counts the exact skin by K s² − 8 s³ with K = 4(a+b+c):
    the reported estimate (1 − f) K s² / V_material must match the true relative mass error to O(s³)."""
    for skin, infill in ((0.0012, 0.2), (0.0008, 0.0), (0.002, 0.5)):
        part = printed_part(block, skin=skin, infill=infill, density=RHO)
        mass, _ = _exact_printed_box(skin, infill)
        true_error = part.properties.mass / mass - 1
        assert true_error > 0
        assert part.mass_error_estimate == pytest.approx(true_error, rel=0.15)
        assert part.offset_coefficient == pytest.approx(4 * (A + B + C), rel=1e-12)


def test_exact_hollow_box_inertia_error_is_second_order_with_infill(block):
    """With infill the relative inertia error falls towards 4× per halving of the skin (second order in s/L);
    it is dominated by the corners the first-order skin counts twice (a 1 mm skin on this 30 mm block: ~4 %)."""
    errors = []
    for skin in (0.001, 0.0005, 0.00025):
        part = printed_part(block, skin=skin, infill=0.2, density=RHO)
        _, inertia = _exact_printed_box(skin, 0.2)
        errors.append(np.max(np.abs(np.diag(part.properties.inertia) / np.diag(inertia) - 1)))
        np.testing.assert_allclose(part.properties.center_of_mass, [0.01, -0.02, 0.005], atol=1e-15)
    assert errors[0] < 0.05
    assert 2.8 < errors[0] / errors[1] < errors[1] / errors[2] < 4.2
    assert part.inertia_error_order == "(s/L)^2"


def test_empty_skin_inertia_error_is_first_order(block):
    """With infill 0 the part is only skin: the error is first order (~2× per halving), as stated."""
    errors = []
    for skin in (0.002, 0.001, 0.0005):
        part = printed_part(block, skin=skin, infill=0.0, density=RHO)
        _, inertia = _exact_printed_box(skin, 0.0)
        errors.append(np.max(np.abs(np.diag(part.properties.inertia) / np.diag(inertia) - 1)))
    assert 1.7 < errors[0] / errors[1] < 2.3 and 1.7 < errors[1] / errors[2] < 2.3
    assert part.inertia_error_order == "s/L"


def test_full_infill_is_the_solid(block):
    part = printed_part(block, skin=0.001, infill=1.0, density=RHO)
    solid = mass_properties(block, density=RHO)
    assert part.properties.mass == pytest.approx(solid.mass, rel=1e-13)
    np.testing.assert_allclose(part.properties.inertia, solid.inertia, rtol=1e-12,
                               atol=1e-12 * np.abs(solid.inertia).max())
    assert part.mass_error_estimate == 0.0


def test_weighed_print_scales_density(block):
    part = printed_part(block, skin=0.0012, infill=0.15, mass=0.05)
    assert part.properties.mass == pytest.approx(0.05)
    ref = printed_part(block, skin=0.0012, infill=0.15, density=RHO)
    assert_tensor_close(part.properties.inertia, ref.properties.inertia * 0.05 / ref.properties.mass, rtol=1e-12)


def test_skin_thicker_than_the_part_is_refused(block):
    with pytest.raises(PhysicsError, match="all skin"):
        printed_part(block, skin=0.02, infill=0.2, density=RHO)


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


def test_cli_printed_json_states_the_model(block_stl, capsys):
    import json
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", "--material", "pla", "--shell", "1.2mm", "--infill", "20%",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = printed_part(trimesh.creation.box([A, B, C]), skin=0.0012, infill=0.2, density=RHO)
    assert out["mass"] == pytest.approx(ref.properties.mass, rel=1e-6)
    assert out["model"]["model"] == "printed" and out["model"]["infill"] == pytest.approx(0.2)
    assert out["model"]["mass_error_estimate"] == pytest.approx(ref.mass_error_estimate, rel=1e-6)


def test_cli_printed_text_states_the_error(block_stl, capsys):
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", "--material", "pla", "--shell", "1.2", "--infill", "0.2"]) == 0
    text = capsys.readouterr().out
    assert "model: printed part, skin 1.2 mm, infill 20%" in text and "estimated error" in text


@pytest.mark.parametrize("args", [["--shell", "1mm"], ["--infill", "20%"], ["--thickness", "2mm"],
                                  ["--model", "shell"], ["--model", "shell", "--thickness", "1mm", "--shell", "1mm",
                                                         "--infill", "20%"],
                                  ["--shell", "1mm", "--infill", "120%"], ["--shell", "1 furlong", "--infill", "20%"]])
def test_cli_contradictory_model_options_exit_2(block_stl, args, capsys):
    from inertia_tool.cli import main
    assert main(["analyze", block_stl, "--units", "mm", *args]) == 2
    assert "error" in capsys.readouterr().err
