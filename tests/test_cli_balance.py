"""Tests of ``inertia-tool balance``: JSON against the Python API, reports, overwrite guard, errors."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import inertia_tool as it
from inertia_tool.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WHEEL = os.path.join(ROOT, "meshes", "unbalanced_wheel.stl")
BASE = ["balance", WHEEL, "--units", "mm", "--material", "steel", "--axis-point", "0,0,0",
        "--axis-direction", "0,0,1", "--rpm", "3000", "--planes", "-40,40", "--radius", "180"]


@pytest.fixture(scope="module")
def wheel():
    return it.mass_properties(WHEEL, units="mm", material="steel")


def _json(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_matches_the_python_api_and_balances_the_wheel(wheel, capsys):
    out = _json(capsys, BASE + ["--grade", "G6.3", "--bearings", "-120,120"])
    rep = it.balance(wheel, axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000, planes=(-0.04, 0.04),
                     radius=0.18, grade="G6.3", bearings=(-0.12, 0.12))
    assert out["initial"]["kind"] == rep.initial.kind == "dynamic"
    assert [c["mass"] for c in out["corrections"]] == pytest.approx([c.mass for c in rep.corrections], rel=1e-12)
    np.testing.assert_allclose(out["support_torque_about_axis_point"], rep.torque, rtol=1e-12)
    # the wheel was made with a 0.2° tilt: the nearest principal axis is tilted by about that much
    assert np.degrees(out["initial"]["tilt"]) == pytest.approx(0.2, abs=0.01)
    # apply the JSON corrections ourselves: static and couple unbalance vanish to round-off
    fixed = it.mass.combine([wheel] + [it.mass.point_mass(c["mass"], c["position"]) for c in out["corrections"]])
    u0 = out["initial"]["static_unbalance_magnitude"]
    assert np.linalg.norm(fixed.mass * fixed.center_of_mass[:2]) < 1e-10 * u0
    j = np.asarray(fixed.inertia_about([0, 0, 0]))
    assert max(abs(j[0, 2]), abs(j[1, 2])) < 1e-10 * np.linalg.norm(out["initial"]["moment_unbalance_about_axis_point"])
    assert out["verification"]["kind"] == "balanced"
    assert out["grade"]["name"] == "G 6.3"
    assert out["permissible_unbalance"] == pytest.approx(6.3e-3 * wheel.mass / (100 * np.pi), rel=1e-12)


def test_lengths_follow_units_or_carry_their_own(capsys):
    a = _json(capsys, BASE)
    b = _json(capsys, BASE[:-4] + ["--planes=-0.04m,4cm", "--radius", "0.18m"])
    assert [c["mass"] for c in a["corrections"]] == pytest.approx([c["mass"] for c in b["corrections"]], rel=1e-12)


def test_single_plane(capsys):
    out = _json(capsys, BASE[:-4] + ["--single-plane", "--radius", "180"])
    assert out["single_plane"] and len(out["corrections"]) == 1
    assert out["verification"]["static_unbalance_magnitude"] < 1e-12
    assert out["verification"]["kind"] == "couple"      # the tilt is left


def test_text_report(capsys):
    assert main(BASE + ["--grade", "G6.3", "--bearings", "-120,120"]) == 0
    text = capsys.readouterr().out
    for needle in ("static unbalance", "couple unbalance", "ISO 21940-2", "U_per", "G 6.3", "bearing A",
                   "Eq. (4.26)", "Two-plane correction", "Verification", "or remove at"):
        assert needle in text


def test_html_report_and_overwrite_guard(tmp_path, capsys):
    path = tmp_path / "wheel-balance.html"
    assert main(BASE + ["--grade", "G6.3", "--report", str(path)]) == 0
    page = path.read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>") and "<script" not in page
    svgs = page.count("<svg")
    assert svgs == 2
    start = page.index("<svg")
    ET.fromstring(page[start:page.index("</svg>") + 6])       # well-formed SVG
    capsys.readouterr()
    assert main(BASE + ["--report", str(path)]) == 2
    assert "--force" in capsys.readouterr().err
    assert main(BASE + ["--report", str(path), "--force"]) == 0


def test_markdown_report_writes_polar_plots(tmp_path):
    path = tmp_path / "wheel.md"
    assert main(BASE + ["--report", str(path)]) == 0
    text = path.read_text(encoding="utf-8")
    assert "| plane |" in text and "wheel-plane1.svg" in text
    for k in (1, 2):
        ET.parse(tmp_path / f"wheel-plane{k}.svg")


@pytest.mark.parametrize("change, message", [
    (["--radius", "0"], "radius"),
    (["--rpm", "0"], "rpm"),
    (["--rpm", "-3000"], "rpm"),
    (["--planes", "40,40"], "coincide"),
    (["--axis-point", "1000,0,0"], "axis"),
    (["--grade", "G7"], "grade"),
    (["--report", "out.txt"], ".html or .md"),
    (["--planes", "1,2,3"], "planes"),
])
def test_errors_exit_2_with_one_line(change, message, capsys):
    argv = list(BASE)
    key = change[0]
    if key in argv:
        i = argv.index(key)
        argv[i:i + 2] = change
    else:
        argv += change
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_end_to_end_subprocess(wheel):
    proc = subprocess.run([sys.executable, "-m", "inertia_tool.cli"] + BASE + ["--grade", "G6.3", "--json"],
                          capture_output=True, text=True, env={**os.environ, "PYTHONPATH": ROOT}, timeout=120)
    assert proc.returncode == 0, proc.stderr
    rep = it.balance(wheel, axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000, planes=(-0.04, 0.04),
                     radius=0.18, grade="G6.3")
    out = json.loads(proc.stdout)
    assert out["achieved_grade"] == rep.achieved_grade.name
    assert out["achieved_value"] == pytest.approx(rep.achieved_value, rel=1e-12)


def test_wheel_sample_matches_its_generator(wheel):
    sys.path.insert(0, os.path.join(ROOT, "meshes"))
    try:
        from make_wheel import LUMP_SIZE, make_wheel
    finally:
        sys.path.pop(0)
    fresh = it.mass_properties(make_wheel(), units="mm", material="steel")
    assert fresh.mass == pytest.approx(wheel.mass, rel=1e-6)          # the STL stores float32 coordinates
    np.testing.assert_allclose(fresh.center_of_mass, wheel.center_of_mass, atol=1e-8)
    assert wheel.mesh.bodies == 2
    lump = 7850 * np.prod(LUMP_SIZE) * 1e-9
    assert lump == pytest.approx(0.0374, abs=1e-4)                   # the README's "37 g lump"


# -- one plane needs --single-plane; a single-plane correction says the couple is left ------------------------

SHAFT = ["balance", WHEEL, "--units", "mm", "--material", "steel", "--rpm", "3000", "--radius", "150",
         "--grade", "G6.3"]


def test_one_plane_without_single_plane_is_a_usage_error(capsys):
    assert main(SHAFT + ["--planes", "-40mm"]) == 2
    err = capsys.readouterr().err
    assert "--single-plane" in err and "two" in err and err.count("\n") == 1
    assert main(SHAFT + ["--planes", "-40,0,40"]) == 2
    assert "2 comma-separated" in capsys.readouterr().err


def test_single_plane_verification_says_couple_not_corrected(wheel, capsys):
    out = _json(capsys, SHAFT + ["--single-plane"])
    v = out["verification"]
    assert v["kind"] in ("couple", "quasi-static", "dynamic")          # the wheel's 0.2° tilt stays
    assert v["couple_corrected"] is False and "couple not corrected" in v["summary"]
    assert v["static_unbalance_magnitude"] < 1e-9 * out["initial"]["static_unbalance_magnitude"]
    assert main(SHAFT + ["--single-plane"]) == 0
    text = capsys.readouterr().out
    line = text.split("Verification")[1].splitlines()[1]
    assert "couple not corrected" in line and "meets" not in line
    # with bearings the tolerance includes the couple, so the grade there is quoted, and is poor
    out = _json(capsys, SHAFT + ["--single-plane", "--bearings", "-120mm,120mm"])
    assert "couple not corrected" in out["verification"]["summary"]
    assert "at the bearings it meets" in out["verification"]["summary"]
    assert out["verification"]["achieved_value"] > 6.3


def test_two_plane_verification_quotes_the_grade(capsys):
    out = _json(capsys, SHAFT + ["--planes", "-40mm,40mm"])
    assert out["verification"]["couple_corrected"] is True
    assert "meets G 0.4" in out["verification"]["summary"]


def test_radius_checked_with_the_option_name(capsys):
    assert main(SHAFT[:-4] + ["--radius", "-5mm", "--grade", "G6.3", "--planes", "-40,40"]) == 2
    assert "--radius must be between 1e-09 and 1e+06 m, got -5mm" in capsys.readouterr().err


def test_hostile_file_name_is_escaped_in_markdown_and_html(tmp_path):
    """Before: the name went raw into the Markdown report (a live <script>, a '|' that split the table)."""
    import shutil
    name = "<script>alert(1)|x_*y*.stl"
    part = tmp_path / name
    shutil.copy(WHEEL, part)
    argv = [a if a != WHEEL else str(part) for a in BASE]
    md, page = tmp_path / "r.md", tmp_path / "r.html"
    assert main(argv + ["--report", str(md)]) == 0
    assert main(argv + ["--report", str(page)]) == 0
    text = md.read_text(encoding="utf-8")
    assert "<script" not in text and "&lt;script&gt;" in text
    assert r"\|x\_\*y\*.stl" in text
    row = next(line for line in text.splitlines() if line.startswith("| part |"))
    assert row.replace(r"\|", "").count("|") == 3                     # still one row of two cells
    html_text = page.read_text(encoding="utf-8")
    assert "<script" not in html_text and "&lt;script&gt;alert(1)|x_*y*.stl" in html_text


def test_markdown_escaping_helper():
    from inertia_tool.reports.escape import escape_markdown
    assert escape_markdown("a|b\nc <d> & [e](f) `g`") == r"a\|b c &lt;d&gt; &amp; \[e\](f) \`g\`"
