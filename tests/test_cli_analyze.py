import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import box_arrays, write_binary_stl
from inertia_tool.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture
def box_stl(tmp_path):
    p = tmp_path / "box.stl"
    write_binary_stl(p, *box_arrays((10.0, 20.0, 30.0), center=(5.0, 0.0, 0.0)))
    return str(p)


def test_json_has_the_documented_keys_in_si(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--material", "aluminium", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("mass", "volume", "center_of_mass", "inertia", "principal_moments", "principal_axes", "units", "mesh"):
        assert key in out
    m = 2700 * 6e-6
    assert out["mass"] == pytest.approx(m, rel=1e-6)
    assert out["volume"] == pytest.approx(6e-6, rel=1e-6)
    np.testing.assert_allclose(out["center_of_mass"], [0.005, 0, 0], atol=1e-9)
    np.testing.assert_allclose(np.diag(out["inertia"]), m * np.array([0.02**2 + 0.03**2, 0.01**2 + 0.03**2,
                                                                       0.01**2 + 0.02**2]) / 12, rtol=1e-6)
    assert out["principal_moments"] == sorted(out["principal_moments"])
    axes = np.array(out["principal_axes"])
    assert np.linalg.det(axes.T) == pytest.approx(1.0)
    assert out["mesh"]["watertight"] is True and out["mesh"]["bodies"] == 1


def test_text_report_states_units_and_sections(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--density", "1000"]) == 0
    text = capsys.readouterr().out
    for needle in ("units: SI", "centre of mass", "about the mesh origin", "principal moments", "radius of gyration",
                   "watertight"):
        assert needle in text


def test_assembly_with_part_materials(tmp_path, capsys):
    a, b = tmp_path / "a.stl", tmp_path / "b.stl"
    write_binary_stl(a, *box_arrays((1.0, 1.0, 1.0)))
    write_binary_stl(b, *box_arrays((1.0, 1.0, 1.0), center=(2.0, 0, 0)))
    assert main(["analyze", f"{a}:steel", f"{b}:1000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mass"] == pytest.approx(8850.0)
    assert len(out["bodies"]) == 2


@pytest.mark.parametrize("argv, code, message", [
    (["analyze", "/definitely/missing.stl"], 3, "no such file"),
    (["analyze", "BOX", "--units", "furlong"], 2, "length unit"),
    (["analyze", "BOX", "--material", "unobtainium"], 2, "Unknown material"),
    (["analyze", "BOX", "--density", "-5"], 2, "--density must be between 0.1 and 100000 kg/m³, got -5"),
    (["analyze"], 2, "required"),
])
def test_errors_are_one_line_with_documented_exit_codes(box_stl, capsys, argv, code, message):
    argv = [box_stl if a == "BOX" else a for a in argv]
    assert main(argv) == code
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err


def test_open_mesh_exit_3_and_no_traceback_end_to_end(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "open.stl"
    write_binary_stl(p, v, f[1:])
    r = subprocess.run([sys.executable, "-m", "inertia_tool.cli", "analyze", str(p)], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": ROOT})
    assert r.returncode == 3
    assert "boundary edges" in r.stderr and str(p) in r.stderr
    assert "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_warnings_go_to_stderr_and_json(tmp_path, capsys):
    v, f = box_arrays()
    p = tmp_path / "inv.stl"
    write_binary_stl(p, v, f[:, ::-1])
    assert main(["analyze", str(p), "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["volume"] == pytest.approx(6.0)
    assert any("inside out" in w for w in out["warnings"])
    assert "inside out" in cap.err


# -- reviewer's UX findings ------------------------------------------------------------------------------------

def _mass(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)["mass"]


def test_file_density_with_a_slash_unit(box_stl, capsys):
    # 10 x 20 x 30 mm box = 6 cm³; 1.24 g/cm³ -> 7.44 g, as with --density
    spec = _mass(capsys, ["analyze", f"{box_stl}:1.24g/cm3", "--units", "mm"])
    assert spec == pytest.approx(1.24e-3 * 6.0, rel=1e-12)
    assert _mass(capsys, ["analyze", f"{box_stl}:1240 kg/m³", "--units", "mm"]) == pytest.approx(spec, rel=1e-12)
    assert _mass(capsys, ["analyze", box_stl, "--units", "mm", "--density", "1.24g/cm3"]) == pytest.approx(spec)


def test_file_density_text_report_names_the_density(box_stl, capsys):
    assert main(["analyze", f"{box_stl}:1.24g/cm3", "--units", "mm"]) == 0
    assert "1240 kg/m³" in capsys.readouterr().out


def test_split_part_spec_rules(tmp_path, monkeypatch):
    from inertia_tool.cli.model_options import split_part_spec
    monkeypatch.chdir(tmp_path)
    (tmp_path / "odd:name.stl").write_bytes(b"")
    assert split_part_spec("odd:name.stl") == ("odd:name.stl", None)            # exists as given
    assert split_part_spec("odd:name.stl:steel") == ("odd:name.stl", "steel")
    assert split_part_spec("a.stl:1.24g/cm3") == ("a.stl", "1.24g/cm3")
    assert split_part_spec("a.stl:lb/ft3") == ("a.stl", "lb/ft3")
    assert split_part_spec(r"C:\parts\a.stl") == (r"C:\parts\a.stl", None)       # a Windows path
    assert split_part_spec("C:/parts/a.stl") == ("C:/parts/a.stl", None)
    assert split_part_spec(r"C:\parts\a.stl:abs") == (r"C:\parts\a.stl", "abs")
    assert split_part_spec("a.stl:") == ("a.stl:", None)


def test_global_density_with_every_part_having_its_own_is_refused(tmp_path, capsys):
    a, b = tmp_path / "a.stl", tmp_path / "b.stl"
    write_binary_stl(a, *box_arrays((1.0, 1.0, 1.0)))
    write_binary_stl(b, *box_arrays((1.0, 1.0, 1.0), center=(2.0, 0, 0)))
    assert main(["analyze", f"{a}:steel", f"{b}:abs", "--density", "1000"]) == 2
    assert "--density 1000 would apply to no part" in capsys.readouterr().err
    assert main(["analyze", f"{a}:steel", f"{b}:abs", "--material", "pla"]) == 2
    # with a part without its own, the global one is that part's default, and the report says so
    assert main(["analyze", f"{a}:steel", str(b), "--density", "500", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mass"] == pytest.approx(7850.0 + 500.0)
    assert "500 kg/m³ for the parts without their own" in out["density_source"]


@pytest.mark.parametrize("extra, message", [
    (["--frame", "mesh"], "--frame applies to --format urdf"),
    (["--frame", "mesh", "--json"], "--frame applies"),
    (["--cad-units", "g-mm"], "--cad-units applies to --format cad only"),
    (["--cad-units", "g-mm", "--format", "urdf"], "--cad-units applies"),
    (["--merge-tolerance", "-1"], "--merge-tolerance must be at least 0 and below 0.1"),
    (["--merge-tolerance", "nan"], "--merge-tolerance must be at least 0 and below 0.1"),
    (["--merge-tolerance", "inf"], "--merge-tolerance must be"),
    (["--max-faces", "0"], "--max-faces must be between 1 and 715,827,882 triangles, got 0"),
    (["--report", "r.md"], "--report writes HTML: expected a file name ending in .html or .htm"),
    (["--report", "r"], "--report writes HTML"),
])
def test_contradictory_or_nonsensical_options_exit_2(box_stl, capsys, tmp_path, monkeypatch, extra, message):
    monkeypatch.chdir(tmp_path)
    assert main(["analyze", box_stl, "--units", "mm", *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "r.md").exists()


def test_frame_and_cad_units_accepted_with_their_format(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--format", "urdf", "--frame", "mesh"]) == 0
    assert "axes parallel to the mesh (link) axes" in capsys.readouterr().out
    assert main(["analyze", box_stl, "--units", "mm", "--format", "cad", "--cad-units", "g-mm"]) == 0
    assert "Mass = 6 grams" in capsys.readouterr().out         # 6 cm³ of the default 1000 kg/m³


def test_merge_tolerance_zero_means_off(box_stl, capsys):
    assert main(["analyze", box_stl, "--units", "mm", "--merge-tolerance", "0"]) == 0
