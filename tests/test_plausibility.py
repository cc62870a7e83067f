"""Units and plausibility (``inertia_tool.mesh.plausibility``, ``inertia_tool.units``): a part read in the wrong
unit, a mass that implies no material, a balancing correction outside the part — warned about, never guessed."""

import json
import os
import warnings

import numpy as np
import pytest

import inertia_tool as it
from inertia_tool.cli import main
from inertia_tool.errors import (ImplausibleCorrectionWarning, ImplausibleDensityWarning, ImplausibleSizeWarning,
                                 InertiaToolWarning)
from inertia_tool.mass import shapes
from inertia_tool.units import PLAUSIBLE_DENSITY, PLAUSIBLE_EXTENT, implausible_density, implausible_extent

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
T_HANDLE = os.path.join(ROOT, "meshes", "t_handle.stl")     # 60 x 10 x 50 mm
WHEEL = os.path.join(ROOT, "meshes", "unbalanced_wheel.stl")


def _caught(fn, *args, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        result = fn(*args, **kwargs)
    return result, [w for w in caught if issubclass(w.category, InertiaToolWarning)]


# -- the rules -----------------------------------------------------------------------------------------------

def test_extent_rule_names_the_unit_that_fits():
    assert implausible_extent(1.0) is None and implausible_extent(PLAUSIBLE_EXTENT[1]) is None
    assert implausible_extent(PLAUSIBLE_EXTENT[0]) is None
    why = implausible_extent(150.0)                 # a 150 mm part read as metres
    assert "150 m" in why and "if the file is in mm" in why and "0.15 m" in why
    assert "um" in implausible_extent(2e5)          # 200 km: only micrometres make it a part (0.2 m)
    assert "if the file is in" not in implausible_extent(5e-5)   # 50 µm: no unit of the table enlarges it


def test_density_rule_spans_foams_to_osmium():
    low, high = PLAUSIBLE_DENSITY
    assert low <= min(it.units.MATERIALS.values()) and max(it.units.MATERIALS.values()) <= high
    assert implausible_density(22_590.0) is None and implausible_density(150.0) is None
    assert "above" in implausible_density(6.9e4) and "below" in implausible_density(8.3e-6)


# -- the engine --------------------------------------------------------------------------------------------

def test_millimetre_part_without_units_warns_and_keeps_the_numbers():
    props, caught = _caught(it.mass_properties, T_HANDLE, material="aluminium")
    sizes = [w for w in caught if issubclass(w.category, ImplausibleSizeWarning)]
    assert len(sizes) == 1 and "`units` mm gives 60 mm" in str(sizes[0].message)
    in_mm = it.mass_properties(T_HANDLE, units="mm", material="aluminium")
    assert props.mass == pytest.approx(in_mm.mass * 1e9, rel=1e-12)          # never rescaled silently


@pytest.mark.parametrize("units", ["mm", "m"])
def test_explicit_units_silence_the_size_check(units):
    _, caught = _caught(it.mass_properties, T_HANDLE, units=units, material="aluminium")
    assert not [w for w in caught if issubclass(w.category, ImplausibleSizeWarning)]


def test_size_check_applies_to_arrays_and_thin_shells():
    box = shapes.box(30.0, 20.0, 10.0)              # a 30 mm box given in "metres"
    _, caught = _caught(it.mass_properties, (box.vertices, box.faces))
    assert any(issubclass(w.category, ImplausibleSizeWarning) for w in caught)
    from inertia_tool.mass.thinwall import shell_mass_properties
    _, caught = _caught(shell_mass_properties, (box.vertices, box.faces), thickness=0.001)
    assert any(issubclass(w.category, ImplausibleSizeWarning) for w in caught)


def test_mass_implying_no_material_warns():
    _, caught = _caught(it.mass_properties, T_HANDLE, units="mm", mass=100.0)   # 100 kg in 10 cm³
    dens = [w for w in caught if issubclass(w.category, ImplausibleDensityWarning)]
    assert len(dens) == 1 and "1e+07 kg/m³" in str(dens[0].message)
    _, caught = _caught(it.mass_properties, T_HANDLE, units="mm", mass=0.027)   # aluminium
    assert not [w for w in caught if issubclass(w.category, ImplausibleDensityWarning)]


def test_reference_solid_transformed_matches_its_mesh():
    from scipy.spatial.transform import Rotation
    turn = Rotation.from_euler("zyx", [30, 20, -10], degrees=True).as_matrix()
    solid = shapes.box(0.04, 0.02, 0.01).transformed(turn, [0.1, -0.2, 0.3])
    props = it.mass_properties((solid.vertices, solid.faces), units="m", density=1.0)
    from conftest import assert_tensor_close
    assert np.allclose(props.center_of_mass, [0.1, -0.2, 0.3], atol=1e-15)
    assert_tensor_close(props.inertia, solid.exact.inertia, rtol=1e-12)
    assert_tensor_close(solid.exact.inertia, turn @ shapes.box(0.04, 0.02, 0.01).exact.inertia @ turn.T, rtol=1e-14)


# -- balancing -----------------------------------------------------------------------------------------------

def _wheel():
    return it.mass_properties(WHEEL, units="mm", material="steel")


def test_correction_outside_the_part_is_noted_and_warned():
    report, caught = _caught(it.balance, _wheel(), axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000,
                             planes=(-0.03, 0.03), radius=0.4)
    assert any("`radius` 0.4 m lies outside the part" in n for n in report.notes)
    assert any(issubclass(w.category, ImplausibleCorrectionWarning) for w in caught)
    report, caught = _caught(it.balance, _wheel(), axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000,
                             planes=(-0.05, 0.03), radius=0.18)
    assert any("`planes` at -0.05 m lie outside" in n for n in report.notes)
    report, caught = _caught(it.balance, _wheel(), axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000,
                             planes=(-0.03, 0.03), radius=0.18)
    assert not report.notes or not any("outside the part" in n for n in report.notes)
    assert not [w for w in caught if issubclass(w.category, ImplausibleCorrectionWarning)]


def test_heavy_correction_is_noted():
    # planes 2 mm apart must cancel the wheel's couple with large opposite masses: 2.3 kg each at 40 mm
    report, _ = _caught(it.balance, _wheel(), axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000,
                        planes=(-0.001, 0.001), radius=0.04)
    added = sum(c.mass for c in report.corrections)
    assert added > 0.1 * report.mass
    assert any(f"{100 * added / report.mass:.3g} %" in n for n in report.notes)


# -- the command line ----------------------------------------------------------------------------------------

def test_cli_warns_in_the_text_report_json_and_stderr(capsys):
    assert main(["analyze", T_HANDLE, "--material", "aluminium"]) == 0
    out, err = capsys.readouterr()
    second = out.splitlines()[1]
    assert second.startswith("  WARNING:") and "--units mm gives 60 mm" in second
    assert "--units mm gives 60 mm" in err
    assert main(["analyze", T_HANDLE, "--material", "aluminium", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert any("--units mm gives 60 mm" in w for w in data["warnings"])
    assert main(["analyze", T_HANDLE, "--units", "mm", "--material", "aluminium", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"] == []


def test_cli_mass_prints_the_implied_density(capsys):
    assert main(["analyze", T_HANDLE, "--units", "mm", "--mass", "27g", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["density_source"] == "scaled to a total mass of 0.027 kg: implied density 2700 kg/m³"


@pytest.mark.parametrize("command", [["spin", "--about", "major"], ["balance", "--rpm", "3000", "--planes", "0,50",
                                                                   "--radius", "30"]])
def test_cli_spin_and_balance_carry_the_warning(capsys, command):
    assert main([command[0], T_HANDLE, "--material", "aluminium", "--json", *command[1:]]) == 0
    data = json.loads(capsys.readouterr().out)
    assert any("metres assumed" in w for w in data["warnings"])


def test_cli_notes_metres_taken_when_the_size_is_plausible(tmp_path, capsys):
    """A 15 mm part exported in millimetres reads as 15 m: no warning (within 0.1 mm..20 m), but the report
    says the unit was taken, not given, and JSON has units_assumed."""
    path = tmp_path / "bolt.stl"
    shapes.write_stl(shapes.box(15.0, 8.0, 5.0), path, units="m")
    assert main(["analyze", str(path), "--material", "steel"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1].startswith("  note: no --units given: coordinates taken as metres (largest extent 15 m)")
    assert main(["analyze", str(path), "--material", "steel", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["units_assumed"] is True and data["warnings"] == []
    assert main(["analyze", str(path), "--units", "m", "--material", "steel", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["units_assumed"] is False
