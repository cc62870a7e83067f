"""SolidWorks-style mass properties report (reports/cad.py) and --format cad."""

import re

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from conftest import write_binary_stl
from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import UsageError
from inertia_tool.robot.inertial import positive_tensor_notation
from inertia_tool.reports.cad import format_cad_report
from conftest import assert_tensor_close


@pytest.fixture(scope="module")
def mesh():
    box = trimesh.creation.box([0.04, 0.02, 0.01])
    rot = Rotation.from_euler("zyx", [30, 20, 10], degrees=True).as_matrix()
    box.apply_transform(np.vstack([np.hstack([rot, [[0.1], [-0.05], [0.02]]]), [0, 0, 0, 1]]))
    return box


@pytest.fixture(scope="module")
def props(mesh):
    return mass_properties((mesh.vertices, mesh.faces), material="aluminium", name="block")


def _value(text, label):
    m = re.search(rf"(?m)(?:^|\s){re.escape(label)} = ([-+]?[0-9][-+0-9.eE]*)", text)
    assert m, f"{label} not in report"
    return float(m.group(1))


def _tensor(text, prefix, heading):
    block = text.split(heading, 1)[1]
    return np.array([[_value(block, f"{prefix}{a}{b}") for b in "xyz"] for a in "xyz"])


def test_positive_tensor_notation_against_trimesh(mesh, props):
    """Lxy = +∫xy dm: the negative of the tensor element, here cross-checked with trimesh's tensor."""
    text = format_cad_report(props)
    assert "positive tensor notation" in text
    central = _tensor(text, "L", "Taken at the center of mass and aligned")
    mesh.density = 2700.0
    ref = np.array(mesh.moment_inertia)          # trimesh: tensor convention, about the centre of mass
    expected = np.where(np.eye(3, dtype=bool), ref, -ref)
    np.testing.assert_allclose(central, expected, rtol=1e-7, atol=1e-7 * np.abs(ref).max())
    assert central[0, 1] == pytest.approx(-props.inertia[0, 1], rel=1e-7)
    assert abs(central[0, 1]) > 1e-3 * central[0, 0]


def test_values_and_output_coordinate_system(props):
    text = format_cad_report(props)
    assert _value(text, "Mass") == pytest.approx(props.mass, rel=1e-7)
    assert _value(text, "Volume") == pytest.approx(8e-6, rel=1e-7)
    assert _value(text, "Surface area") == pytest.approx(2 * (8e-4 + 4e-4 + 2e-4), rel=1e-7)
    np.testing.assert_allclose([_value(text, c) for c in "XYZ"], [0.1, -0.05, 0.02], rtol=1e-7)
    about = _tensor(text, "I", "Taken at the output coordinate system")
    assert_tensor_close(about, positive_tensor_notation(np.asarray(props.inertia_about(np.zeros(3)))), rtol=1e-7)
    moments = [_value(text, f"P{c}") for c in "xyz"]
    np.testing.assert_allclose(moments, props.principal.moments, rtol=1e-7)
    assert moments == sorted(moments)


def test_gram_millimetre_units(props):
    """g·mm (SolidWorks' default): mass × 1e3, lengths × 1e3, inertia × 1e9, density in g/mm³."""
    text = format_cad_report(props, units="g-mm")
    assert "grams * square millimeters" in text
    assert _value(text, "Mass") == pytest.approx(props.mass * 1e3, rel=1e-7)
    assert _value(text, "Density") == pytest.approx(0.0027, rel=1e-7)
    assert _value(text, "Volume") == pytest.approx(8000.0, rel=1e-7)
    assert _value(text, "X") == pytest.approx(100.0, rel=1e-7)
    central = _tensor(text, "L", "Taken at the center of mass and aligned")
    assert_tensor_close(central, positive_tensor_notation(props.inertia) * 1e9, rtol=1e-7)


def test_positive_tensor_notation_only_flips_products():
    t = np.array([[3.0, -0.2, 0.1], [-0.2, 4.0, -0.3], [0.1, -0.3, 5.0]])
    p = positive_tensor_notation(t)
    np.testing.assert_array_equal(np.diag(p), np.diag(t))
    np.testing.assert_array_equal(p - np.diag(np.diag(p)), -(t - np.diag(np.diag(t))))


def test_unknown_units_refused(props):
    with pytest.raises(UsageError):
        format_cad_report(props, units="slug-ft")


def test_cli_cad_format(tmp_path, mesh, capsys):
    p = tmp_path / "block.stl"
    write_binary_stl(p, mesh.vertices * 1000, mesh.faces)
    assert main(["analyze", str(p), "--units", "mm", "--material", "aluminium", "--format", "cad",
                 "--cad-units", "g-mm"]) == 0
    text = capsys.readouterr().out
    assert _value(text, "Mass") == pytest.approx(21.6, rel=1e-5)
    assert "Using positive tensor notation" in text
