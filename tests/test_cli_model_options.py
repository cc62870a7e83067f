"""One set of model options for every command (``inertia_tool.cli.model_options``): the same options in the
same order, assemblies and thin-walled models in ``spin``, ``top`` and ``balance``, the model in the HTML
report, files checked before any is written, ``batch`` over several paths."""

import builtins
import json
import os
import shutil

import pytest

from inertia_tool.cli import build_parser, main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOX = os.path.join(ROOT, "meshes", "box.stl")
TOP = os.path.join(ROOT, "meshes", "spinning_top.stl")
WASHER = os.path.join(ROOT, "meshes", "washer.stl")
MODEL_COMMANDS = ("analyze", "spin", "top", "balance")


def _json(capsys, argv):
    assert main(argv) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _option_order(command):
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    return [a.option_strings[0] for a in sub._actions if a.option_strings and a.option_strings[0] != "-h"]


def test_model_options_in_the_same_order_everywhere():
    model = ["--units", "--density", "--material", "--mass", "--material-map", "--model", "--thickness", "--shell",
             "--infill", "--top-bottom", "--top-layers", "--bottom-layers", "--layer-height",
             "--repair", "--assume", "--overlap", "--merge-tolerance", "--max-faces"]
    for command in MODEL_COMMANDS:
        order = _option_order(command)
        assert order[:len(model)] == model, command
    batch = _option_order("batch")
    printed = ("--material-map", "--model", "--thickness", "--shell", "--infill", "--top-bottom", "--top-layers",
               "--bottom-layers", "--layer-height")
    assert batch[:9] == [o for o in model if o not in printed]


@pytest.mark.parametrize("model", [["--model", "shell", "--thickness", "1mm"], ["--shell", "1mm", "--infill", "20%"]])
def test_spin_and_balance_use_the_thin_walled_models(capsys, model, core_moments_memo):
    common = [BOX, "--units", "mm", "--material", "aluminium", *model]
    mass = _json(capsys, ["analyze", *common, "--json"])["mass"]
    spin = _json(capsys, ["spin", *common, "--about", "major", "--json"])
    assert spin["mass"] == pytest.approx(mass, rel=1e-12) and spin["model"]["model"] != "solid"
    bal = _json(capsys, ["balance", *common, "--rpm", "3000", "--planes", "1,9", "--radius", "10",
                         "--axis-point", "15,10,0", "--json"])
    assert bal["mass"] == pytest.approx(mass, rel=1e-12)
    assert bal["model"] == spin["model"]


def test_top_takes_a_printed_part(capsys):
    args = [TOP, "--units", "mm", "--material", "pla", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt",
            "20deg", "--no-simulate", "--json"]
    solid = _json(capsys, ["top", *args])
    printed = _json(capsys, ["top", *args, "--shell", "1.2mm", "--infill", "20%"])
    assert printed["model"]["model"] == "printed" and solid["model"]["model"] == "solid"
    assert printed["top"]["mass"] < solid["top"]["mass"]


def test_spin_takes_an_assembly(capsys):
    parts = [WASHER + ":steel", BOX + ":abs"]
    analyzed = _json(capsys, ["analyze", *parts, "--units", "mm", "--json"])
    spun = _json(capsys, ["spin", *parts, "--units", "mm", "--about", "major", "--json"])
    assert spun["mass"] == pytest.approx(analyzed["mass"], rel=1e-12)
    assert spun["density_source"] == analyzed["density_source"] == "per part"


def test_html_report_shows_the_model_and_says_it_wrote_it(tmp_path, capsys):
    out = tmp_path / "box.html"
    assert main(["analyze", BOX, "--units", "mm", "--material", "aluminium", "--model", "shell", "--thickness",
                 "1mm", "--report", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().err
    page = out.read_text(encoding="utf-8")
    assert "Mass model" in page and "thin shell" in page and "1 mm" in page


def test_missing_matplotlib_refused_before_any_file_is_written(tmp_path, capsys, monkeypatch):
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError("No module named 'matplotlib'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    csv, png = tmp_path / "t.csv", tmp_path / "t.png"
    code = main(["spin", BOX, "--units", "mm", "--about", "major", "--duration", "1s", "--csv", str(csv),
                 "--plot", str(png)])
    assert code == 2 and "needs matplotlib" in capsys.readouterr().err
    assert not csv.exists() and not png.exists()


def test_batch_takes_several_paths_and_says_when_nothing_is_new(tmp_path, capsys):
    for name in ("box.stl", "washer.stl", "cone.stl"):
        shutil.copy(os.path.join(ROOT, "meshes", name), tmp_path / name)
    out = str(tmp_path / "rows.csv")
    files = [str(tmp_path / n) for n in ("box.stl", "washer.stl")]
    assert main(["batch", *files, str(tmp_path / "box.stl"), "--units", "mm", "--out", out, "-q"]) == 0
    first = capsys.readouterr().err
    assert "batch: 2 files: 2 ok, 0 failed in this run" in first
    assert main(["batch", str(tmp_path), "--units", "mm", "--out", out, "-q"]) == 0
    assert "batch: 3 files: 1 ok, 0 failed in this run; 2 done before" in capsys.readouterr().err
    assert main(["batch", str(tmp_path), "--units", "mm", "--out", out, "-q"]) == 0
    assert "batch: 3 files: nothing new; 3 done before" in capsys.readouterr().err


def test_every_help_ends_with_examples(capsys):
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    for name, sub in commands.items():
        text = sub.format_help().rstrip().splitlines()
        start = text.index("examples:")
        examples = [line.strip() for line in text[start + 1:]]
        assert 2 <= len(examples) <= 3, name
        assert all(line.startswith(f"inertia-tool {name} ") for line in examples), name


def test_batch_without_units_says_how_many_files_look_like_millimetres(tmp_path, capsys):
    for name in ("box.stl", "washer.stl"):
        shutil.copy(os.path.join(ROOT, "meshes", name), tmp_path / name)
    assert main(["batch", str(tmp_path), "--out", str(tmp_path / "rows.jsonl"), "-q"]) == 0
    err = capsys.readouterr().err
    assert "batch: warning: 2 file(s) read without --units are implausibly large or small in metres" in err
    rows = [json.loads(line) for line in (tmp_path / "rows.jsonl").read_text().splitlines()]
    assert all("--units mm gives" in row["warnings"] or "`units` mm gives" in row["warnings"] for row in rows)
