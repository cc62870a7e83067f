"""The command line's shared rules (``inertia_tool.cli`` and its option helpers): one-line errors, negative
values with units, and the file-writing rules common to every subcommand."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from inertia_tool.cli import _NEGATIVE_VALUE, build_parser, main
from robot_data import ERD, UR5

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(ROOT, "meshes")
TOP = os.path.join(MESHES, "spinning_top.stl")
T_HANDLE = os.path.join(MESHES, "t_handle.stl")
WHEEL = os.path.join(MESHES, "unbalanced_wheel.stl")
BOX = os.path.join(MESHES, "box.stl")


def _run(*argv):
    env = {**os.environ, "PYTHONPATH": ROOT}
    return subprocess.run([sys.executable, "-m", "inertia_tool.cli", *argv], capture_output=True, text=True,
                          env=env, cwd=ROOT, timeout=120)


# -- negative values ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("text", ["-5", "-.5", "-0.5", "-1e-3", "-20deg", "-40,40", "-5,0,0", "-2mm,0,0",
                                  "-40mm,40mm", "-120mm,120mm", "-5,0,-2mm", "-0.5rev/s", "-1.5e2mm,+3mm"])
def test_negative_values_with_units_are_values(text):
    assert _NEGATIVE_VALUE.match(text)


@pytest.mark.parametrize("text", ["-j", "-q", "-h", "--force", "--units", "-x1", "-", "-2 mm", "-mm"])
def test_options_are_still_options(text):
    assert not _NEGATIVE_VALUE.match(text)


def test_short_options_still_parse_next_to_negative_values():
    args = build_parser().parse_args(["batch", "dir", "--out", "r.jsonl", "-j", "2", "-q"])
    assert args.jobs == 2 and args.quiet


def _top_json(capsys, pivot):
    assert main(["top", TOP, "--units", "mm", "--material", "steel", pivot[0], *pivot[1:], "--spin", "50rev/s",
                 "--tilt", "20deg", "--no-simulate", "--json"]) == 0
    return json.loads(capsys.readouterr().out)["top"]


def test_top_pivot_with_a_negative_unit_value_equals_the_equals_form(capsys):
    spaced = _top_json(capsys, ["--pivot", "-2mm,0,0"])
    joined = _top_json(capsys, ["--pivot=-0.2cm,0,0"])    # the '=' form never went through the matcher
    assert spaced["length"] == pytest.approx(joined["length"], rel=1e-12)
    assert spaced["nutation_period"] == pytest.approx(joined["nutation_period"], rel=1e-12)
    assert _top_json(capsys, ["--pivot", "0,0,0"])["length"] != pytest.approx(spaced["length"], rel=1e-6)


def test_balance_planes_and_bearings_with_negative_unit_values(capsys):
    base = ["balance", WHEEL, "--units", "mm", "--material", "steel", "--rpm", "3000", "--radius", "150",
            "--grade", "G6.3", "--json"]
    assert main(base + ["--planes", "-40mm,40mm", "--bearings", "-120mm,120mm"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(base + ["--planes=-4cm,4cm", "--bearings=-12cm,12cm"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert [p["position"] for p in a["correction_planes"]] == pytest.approx([-0.04, 0.04], rel=1e-12)
    assert [p["position"] for p in a["tolerance_planes"]] == pytest.approx([-0.12, 0.12], rel=1e-12)
    np.testing.assert_allclose([c["mass"] for c in a["corrections"]], [c["mass"] for c in b["corrections"]],
                               rtol=1e-12)


# -- one-line errors -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv, cmd", [
    (["analyze", BOX, "--bogus"], "analyze"),
    (["analyze"], "analyze"),
    (["top", TOP, "--pivot"], "top"),
    (["spin", BOX, "--about", "sideways"], "spin"),
    ([], None),
])
def test_argparse_errors_are_one_line_naming_the_command(argv, cmd):
    r = _run(*argv)
    assert r.returncode == 2
    lines = r.stderr.splitlines()
    assert len(lines) == 1, r.stderr
    prog = "inertia-tool" + (f" {cmd}" if cmd else "")
    assert lines[0].startswith(f"{prog}: error: ") and lines[0].endswith(f"(see {prog} --help)")
    assert "usage:" not in r.stderr


def test_in_process_usage_error_returns_2(capsys):
    assert main(["analyze", BOX, "--bogus"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_no_warning_after_an_error_line():
    # the T-handle warns (two equal-ish moments / asymmetric top) before the pivot at its centre of mass fails
    r = _run("top", T_HANDLE, "--units", "mm", "--pivot", "0,0,35", "--spin", "5rev/s")
    assert r.returncode == 4
    assert r.stderr.splitlines() == [r.stderr.strip()] and r.stderr.startswith("inertia-tool: error:")


def test_warnings_still_printed_on_success():
    r = _run("top", T_HANDLE, "--units", "mm", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt", "10",
             "--no-simulate")
    assert r.returncode == 0
    assert "inertia-tool: warning: not a symmetric top" in r.stderr


# -- files that are written ----------------------------------------------------------------------------------

WRITERS = [
    (["spin", BOX, "--units", "mm", "--duration", "3s"], "--csv", "t.csv"),
    (["top", TOP, "--units", "mm", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt", "20"], "--csv", "t.csv"),
    (["analyze", BOX, "--units", "mm"], "--report", "r.html"),
    (["balance", WHEEL, "--units", "mm", "--rpm", "3000", "--radius", "150", "--planes", "-40,40"],
     "--report", "r.html"),
    (["balance", WHEEL, "--units", "mm", "--rpm", "3000", "--radius", "150", "--planes", "-40,40"],
     "--report", "r.md"),
    (["robot", str(UR5), "--package", f"example-robot-data={ERD}", "--density", "2700"], "--write", "r.urdf"),
]


@pytest.mark.parametrize("argv, option, name", WRITERS)
def test_every_writer_refuses_to_overwrite_without_force(tmp_path, capsys, argv, option, name):
    path = tmp_path / name
    path.write_text("precious")
    assert main(argv + [option, str(path)]) == 2
    err = capsys.readouterr().err
    assert "exists" in err and "--force" in err and err.count("\n") == 1
    assert path.read_text() == "precious"
    assert main(argv + [option, str(path), "--force"]) == 0
    assert path.read_text() != "precious"


@pytest.mark.parametrize("argv, option, name", WRITERS + [
    (["batch", MESHES, "-q"], "--out", "d.jsonl"),
    (["batch", MESHES, "-q"], "--out", "d.csv"),
])
def test_every_writer_reports_a_missing_directory_as_usage_error(tmp_path, capsys, argv, option, name):
    target = tmp_path / "missing" / name
    assert main(argv + [option, str(target)]) == 2
    err = capsys.readouterr().err
    assert str(target) in err and ("No such file" in err or "no such directory" in err)
    assert "internal error" not in err and err.count("\n") == 1


@pytest.mark.parametrize("option", ["--csv", "--plot"])
def test_top_and_spin_writers_refuse_a_directory(tmp_path, capsys, option):
    assert main(["spin", BOX, "--units", "mm", option, str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_batch_out_unwritable_subprocess(tmp_path):
    r = _run("batch", MESHES, "--out", "/nonexistent/d.jsonl", "-q")
    assert r.returncode == 2
    assert r.stderr.strip() == ("inertia-tool: error: /nonexistent/d.jsonl: cannot write the results file "
                                "(No such file or directory)")


def test_engine_messages_name_parameters_and_the_cli_names_options():
    from inertia_tool.cli import build_parser, speak_options
    from inertia_tool.mass.pipeline import mass_properties
    from inertia_tool.errors import MeshReadError
    import numpy as np
    import trimesh
    box = trimesh.creation.box([1.0, 1.0, 1.0])
    with pytest.raises(MeshReadError) as info:
        mass_properties((np.asarray(box.vertices), np.asarray(box.faces)), max_faces=3)
    assert "`max_faces`" in str(info.value) and "--" not in str(info.value)
    analyze = build_parser()._defaults["_subparsers"]["analyze"]
    assert "--max-faces" in speak_options(str(info.value), analyze)
    assert speak_options("use `repair=True` or `nothing_known`", analyze) == "use --repair or nothing_known"


@pytest.mark.parametrize("exc, code", [("UsageError", 2), ("UnitsError", 2), ("MaterialError", 2), ("MeshReadError", 3),
                                       ("InvalidMeshError", 3), ("PhysicsError", 4), ("InertiaToolError", 1)])
def test_exit_codes_come_from_one_table_by_exception_type(exc, code):
    from inertia_tool import errors
    from inertia_tool.cli import exit_code
    assert exit_code(getattr(errors, exc)("x")) == code
    assert not hasattr(getattr(errors, exc), "exit_code")
