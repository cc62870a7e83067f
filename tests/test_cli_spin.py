"""``inertia-tool spin`` and ``inertia-tool top`` on the bundled T-handle and spinning top."""

import importlib.util
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
import trimesh

import inertia_tool as it
from inertia_tool.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
T_HANDLE = os.path.join(ROOT, "meshes", "t_handle.stl")
TOP = os.path.join(ROOT, "meshes", "spinning_top.stl")


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_sample_meshes_are_current_closed_solids(tmp_path):
    spec = importlib.util.spec_from_file_location("make_tops", os.path.join(ROOT, "meshes", "make_tops.py"))
    make_tops = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_tops)
    for name, build in (("t_handle.stl", make_tops.t_handle), ("spinning_top.stl", make_tops.spinning_top)):
        make_tops.write_stl(tmp_path / name, *build(), "check")
        with open(tmp_path / name, "rb") as a, open(os.path.join(ROOT, "meshes", name), "rb") as b:
            assert a.read()[80:] == b.read()[80:], f"meshes/{name} is stale: run python meshes/make_tops.py"
        mesh = trimesh.load(os.path.join(ROOT, "meshes", name))
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.body_count == 1
        props = it.mass_properties(os.path.join(ROOT, "meshes", name), units="mm", density=1000)
        assert props.mesh.watertight and props.mesh.bodies == 1
    # the T-handle's volume is its outline area times its depth: (60·10 + 10·40) mm² × 10 mm
    props = it.mass_properties(T_HANDLE, units="mm", density=1000)
    assert props.volume == pytest.approx((600 + 400) * 10 * 1e-9, rel=1e-6)


@pytest.mark.parametrize("about, kind, period_kind", [("intermediate", "unstable", "flip"),
                                                      ("major", "stable", "wobble"),
                                                      ("minor", "stable", "wobble")])
def test_spin_t_handle_predicted_matches_numerical_simulation(capsys, about, kind, period_kind):
    out = _json(capsys, ["spin", T_HANDLE, "--units", "mm", "--material", "steel", "--about", about,
                         "--rate", "5rev/s", "--duration", "20s", "--method", "numerical", "--json"])
    spin = out["spin"]
    assert spin["kind"] == kind and spin["period_kind"] == period_kind
    assert [s["kind"] for s in out["stability"]] == ["stable", "unstable", "stable"]
    assert spin["simulated"]["method"].startswith("numerical")
    assert spin["simulated"]["events"] >= 2
    assert spin["simulated"]["period"] == pytest.approx(spin["predicted"]["period"], rel=2e-3)
    if kind == "stable":
        # a 1e-3 perturbation is deep in the linear regime: the §4.4.1 period is the exact one
        assert spin["predicted"]["linear_period"] == pytest.approx(spin["predicted"]["period"], rel=1e-5)
        assert spin["simulated"]["max_tilt"] < 0.01
    else:
        assert spin["simulated"]["max_tilt"] == pytest.approx(math.pi, abs=1e-2)     # it turns right over
        # the linear estimate of the time to order one comes before the first flip, within a factor 2
        first = spin["simulated"]["first_flip_time"]
        assert 0.5 * first < spin["predicted"]["time_to_grow"] < first


def test_spin_text_csv_and_plot(tmp_path, capsys):
    csv = tmp_path / "spin.csv"
    png = tmp_path / "spin.png"
    argv = ["spin", T_HANDLE, "--units", "mm", "--density", "7850", "--rate", "300rpm", "--duration", "5s",
            "--samples", "3001", "--csv", str(csv), "--plot", str(png)]
    code = main(argv)
    captured = capsys.readouterr()
    if importlib.util.find_spec("matplotlib") is None:
        assert code == 2 and "matplotlib" in captured.err
        code = main(argv[:-2])
        captured = capsys.readouterr()
    else:
        assert png.stat().st_size > 1000
    assert code == 0
    text = captured.out
    for needle in ("UNSTABLE", "major-axis rule", "flip interval", "Landau–Lifshitz", "simulated"):
        assert needle in text
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert data.shape == (3001, 12)
    assert data[-1, 0] == pytest.approx(5.0)


def test_top_spinning_top_analysis_agrees_with_simulation(capsys):
    out = _json(capsys, ["top", TOP, "--units", "mm", "--material", "steel", "--pivot", "0,0,0",
                         "--spin", "50rev/s", "--tilt", "20deg", "--json"])
    top = out["top"]
    sim = top["simulation"]
    assert top["precession_kind"] == "cusp" and top["sleeping_stable"]
    assert top["theta_min"] == pytest.approx(math.radians(20), abs=1e-12)
    assert top["symmetry_axis"] == pytest.approx([0, 0, 1], abs=1e-12)
    assert sim["theta_min"] >= top["theta_min"] - 1e-7 and sim["theta_max"] <= top["theta_max"] + 1e-7
    assert sim["theta_max"] == pytest.approx(top["theta_max"], abs=1e-4 * (top["theta_max"] - top["theta_min"]) + 1e-9)
    assert sim["nutation_period"] == pytest.approx(top["nutation_period"], rel=1e-4)
    # the l and the pivot moments match the mesh's own mass properties (parallel-axis theorem)
    props = it.mass_properties(TOP, units="mm", material="steel")
    assert top["length"] == pytest.approx(props.center_of_mass[2], rel=1e-12)
    assert top["axial_moment"] == pytest.approx(props.principal.moments[2], rel=1e-9)


def test_top_sleeping_criterion_and_asymmetric_warning(capsys):
    slow = _json(capsys, ["top", TOP, "--units", "mm", "--material", "steel", "--pivot", "0,0,0",
                          "--spin", "3rev/s", "--no-simulate", "--json"])["top"]
    assert not slow["sleeping_stable"]
    assert slow["critical_sleeping_spin"] / (2 * math.pi) == pytest.approx(6.35, rel=2e-3)
    assert main(["top", T_HANDLE, "--units", "mm", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt", "10",
                 "--no-simulate"]) == 0
    err = capsys.readouterr().err
    assert "not a symmetric top" in err


@pytest.mark.parametrize("argv, code, message", [
    (["spin", T_HANDLE, "--rate", "5 furlong/s"], 2, "angular-rate unit"),
    (["spin", T_HANDLE, "--perturbation", "0"], 2, "perturbation"),
    (["top", TOP, "--units", "mm", "--pivot", "1,2", "--spin", "5rev/s"], 2, "three comma-separated"),
    (["top", T_HANDLE, "--units", "mm", "--pivot", "0,0,35", "--spin", "5rev/s"], 4, "centre of mass"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--tilt", "200deg"], 2,
     "--tilt must be between 0 and 180 deg"),
])
def test_bad_input_exit_codes(capsys, argv, code, message):
    assert main(argv) == code
    assert message in capsys.readouterr().err


def test_end_to_end_subprocess():
    env = {**os.environ, "PYTHONPATH": ROOT}
    run = subprocess.run([sys.executable, "-m", "inertia_tool.cli", "spin", T_HANDLE, "--units", "mm",
                          "--material", "aluminium", "--about", "intermediate", "--duration", "10s"],
                         capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "flip interval" in run.stdout and "Traceback" not in run.stderr


def test_analyze_reports_stability_section_for_the_octahedron(tmp_path, capsys):
    """``analyze`` carries the stability section: exercise 4.9(b) for the octahedron with h > b > a."""
    from conftest import write_binary_stl
    from test_stability import _octahedron

    path = tmp_path / "octahedron.stl"
    write_binary_stl(path, *_octahedron(20.0, 30.0, 50.0))
    out = _json(capsys, ["analyze", str(path), "--units", "mm", "--material", "aluminium", "--json"])
    stab = out["stability"]
    assert [s["kind"] for s in stab] == ["stable", "unstable", "stable"]
    assert [s["moment"] for s in stab] == pytest.approx(out["principal_moments"], rel=1e-12)
    for s, expected in zip(stab, ([0, 0, 1], [0, 1, 0], [1, 0, 0])):
        assert np.abs(s["axis"]) == pytest.approx(expected, abs=1e-9)
    assert [s["dissipation_stable"] for s in stab] == [False, False, True]
    assert main(["analyze", str(path), "--units", "mm"]) == 0
    assert "major-axis rule" in capsys.readouterr().out


# -- sampling, option ranges and wording (reviewer's UX findings) ----------------------------------------------

BOX = os.path.join(ROOT, "meshes", "box.stl")


def test_spin_refuses_an_undersampled_simulation(capsys):
    # 400001 samples over 1e6 s are 0.45 per predicted flip interval (1.1185 s): the "measured" 10.6 s was an alias
    assert main(["spin", BOX, "--units", "mm", "--duration", "1e6s"]) == 2
    err = capsys.readouterr().err
    assert "Undersampled" in err and "duration" in err and "samples" in err and err.count("\n") == 1
    assert main(["spin", BOX, "--units", "mm", "--duration", "30s", "--samples", "10"]) == 2
    assert "at least 431 samples" in capsys.readouterr().err


def test_spin_engine_sampling_bound_and_well_sampled_measurement():
    props = it.mass_properties(BOX, units="mm")
    with pytest.raises(it.errors.UsageError, match="Undersampled"):
        it.dynamics.spin_experiment(props, "intermediate", 10 * math.pi, duration=1e6)
    # just above the bound (16 per flip interval) the measured interval still matches the prediction
    e = it.dynamics.spin_experiment(props, "intermediate", 10 * math.pi, duration=60.0,
                                    samples=int(60 / 1.11851 * 17) + 1)
    assert e.measured_period == pytest.approx(e.predicted_period, rel=5e-3)


@pytest.mark.parametrize("argv, message", [
    (["spin", BOX, "--perturbation", "2"], "--perturbation must be between 0 and 1 (exclusive), got 2"),
    (["spin", BOX, "--perturbation", "1"], "--perturbation must be between 0 and 1"),
    (["spin", BOX, "--perturbation", "nan"], "--perturbation must be"),
    (["spin", BOX, "--rtol", "-1"], "--rtol must be >= 0 and < 1, got -1"),
    (["spin", BOX, "--rate", "-5rev/s"],
     "--rate must be between 1.0472e-05 and 1.0472e+06 rad/s (1e-4 to 1e7 rpm), got -5rev/s"),
    (["spin", BOX, "--duration", "0s"], "--duration must be between 1e-06 and 1e+06 s, got 0s"),
    (["spin", BOX, "--samples", "1"], "--samples must be between 2 and 400001"),
    (["spin", BOX, "--merge-tolerance", "-1"], "--merge-tolerance must be"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--symmetry-rtol", "-1"],
     "--symmetry-rtol must be >= 0 and < 1, got -1"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--gravity", "0"],
     "--gravity must be between 1e-06 and 10000 m/s²"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--tilt", "200deg"],
     "--tilt must be between 0 and 180 deg (0 and π rad) from the vertical, got 200deg"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--tilt", "-0.1rad"],
     "--tilt must be between 0 and 180 deg"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "5rev/s", "--samples", "100000000"],
     "--samples must be between 2 and 400001"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt", "20", "--duration", "1e6s"],
     "Undersampled"),
])
def test_numeric_options_are_checked_with_their_names(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_spin_rtol_default_is_the_library_default():
    from inertia_tool.cli import build_parser
    from inertia_tool.mass.principal import DEFAULT_EQUAL_RTOL
    assert build_parser().parse_args(["spin", BOX]).rtol == DEFAULT_EQUAL_RTOL


def test_spin_report_without_flips_says_so(capsys):
    assert main(["spin", BOX, "--units", "mm", "--duration", "0.5s"]) == 0     # first flip at 0.63 s
    out = capsys.readouterr().out
    assert "no flip within the simulated time" in out
    assert "nan" not in out and "never s" not in out
    assert main(["spin", BOX, "--units", "mm", "--duration", "0.9s", "--samples", "2000"]) == 0
    out = capsys.readouterr().out
    assert "one flip only" in out and "nan" not in out


def test_top_report_without_nutation_says_so(capsys):
    import dataclasses
    from inertia_tool.reports.stability import format_heavy_top
    assert main(["top", TOP, "--units", "mm", "--material", "steel", "--pivot", "0,0,0", "--spin", "50rev/s",
                 "--tilt", "0"]) == 0
    out = capsys.readouterr().out
    assert "no nutation period seen within the simulated time" in out and "nan" not in out
    props = it.mass_properties(TOP, units="mm", material="steel")
    top = it.dynamics.heavy_top_on_pivot(props, [0, 0, 0], theta0=0.3, omega3=300.0)
    text = format_heavy_top(dataclasses.replace(top, nutation_period=math.inf))
    assert "no nutation period (θ never returns)" in text and "never s" not in text
