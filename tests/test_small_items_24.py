"""The smaller items of issue 24, each with its regression test: zips with macOS forks or an OBJ's material
library, batch over a folder with compressed files, "wrote …" status lines on stderr."""

import bz2
import gzip
import json
import zipfile

import pytest

from inertia_tool import mass_properties
from inertia_tool.batch.runner import discover_files
from inertia_tool.cli import main
from inertia_tool.errors import MeshReadError
from inertia_tool.mass import shapes


@pytest.fixture
def box_bytes(tmp_path):
    path = tmp_path / "box.stl"
    shapes.write_stl(shapes.box(0.02, 0.03, 0.04), str(path), units="mm")
    return path.read_bytes()


def test_zip_with_macos_forks_and_a_material_library_is_read(tmp_path, box_bytes):
    """Issue 24: 'a zip must hold exactly one mesh file', listing one mesh, for a zip a Mac made or an OBJ
    with its .mtl."""
    path = tmp_path / "part.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("part/box.stl", box_bytes)
        zf.writestr("__MACOSX/part/._box.stl", b"\x00\x05\x16\x07resource fork")
        zf.writestr("part/.DS_Store", b"junk")
        zf.writestr("part/box.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n")
    props = mass_properties(str(path), units="mm", density=1000.0)
    assert props.volume == pytest.approx(0.02 * 0.03 * 0.04, rel=1e-12)


def test_zip_with_two_meshes_is_still_refused(tmp_path, box_bytes):
    path = tmp_path / "two.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("a.stl", box_bytes)
        zf.writestr("b.stl", box_bytes)
    with pytest.raises(MeshReadError, match="exactly one mesh file"):
        mass_properties(str(path), units="mm")


def test_batch_folder_takes_compressed_files(tmp_path, box_bytes, capsys):
    """Issue 24: batch over a folder skipped .zip and .bz2 files without a word."""
    d = tmp_path / "parts"
    d.mkdir()
    (d / "plain.stl").write_bytes(box_bytes)
    (d / "g.stl.gz").write_bytes(gzip.compress(box_bytes))
    (d / "b.stl.bz2").write_bytes(bz2.compress(box_bytes))
    with zipfile.ZipFile(d / "z.zip", "w") as zf:
        zf.writestr("box.stl", box_bytes)
    (d / "notes.txt.gz").write_bytes(gzip.compress(b"not a mesh"))
    found = [p.rsplit("/", 1)[1] for p in discover_files(str(d))]
    assert found == ["b.stl.bz2", "g.stl.gz", "plain.stl", "z.zip"]
    out = tmp_path / "rows.jsonl"
    assert main(["batch", str(d), "--units", "mm", "--density", "1000", "--out", str(out), "--jobs", "1"]) == 0
    rows = [json.loads(line) for line in out.read_text().splitlines() if line.strip()]
    masses = [r["mass"] for r in rows if "mass" in r]
    assert len(masses) == 4 and max(masses) == pytest.approx(min(masses), rel=1e-12)


def test_spin_it_status_lines_go_to_stderr(tmp_path, capsys):
    """Issue 24: "wrote …" went partly to stdout (spin-it's --out), partly to stderr (--report)."""
    pytest.importorskip("manifold3d")
    path = tmp_path / "block.stl"
    shapes.write_stl(shapes.box(0.04, 0.03, 0.02), str(path), units="mm")
    out = tmp_path / "hollow.stl"
    assert main(["spin-it", str(path), "--units", "mm", "--material", "pla", "--axis", "0,0,1", "--wall", "3mm",
                 "--resolution", "16", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "wrote" not in captured.out
    assert f"wrote {out}" in captured.err
    assert out.exists()


def test_batch_units_are_for_files_without_one(tmp_path, box_bytes):
    """Issue 24: `batch --units mm` refused every file that declares its own unit (3MF, glTF) instead of
    honouring it; `analyze` still refuses the contradiction."""
    trimesh = pytest.importorskip("trimesh")
    d = tmp_path / "mixed"
    d.mkdir()
    (d / "plain.stl").write_bytes(box_bytes)                                   # millimetres, no unit in the file
    box = trimesh.creation.box([20.0, 30.0, 40.0])
    box.export(str(d / "declared.3mf"))                                       # 3MF: millimetres declared
    out = tmp_path / "rows.jsonl"
    assert main(["batch", str(d), "--units", "cm", "--density", "1000", "--out", str(out), "--jobs", "1"]) == 0
    rows = {json.loads(line)["path"].rsplit("/", 1)[1]: json.loads(line)
            for line in out.read_text().splitlines() if line.strip()}
    assert rows["declared.3mf"]["status"] == "ok"
    assert rows["declared.3mf"]["volume"] == pytest.approx(24e-6, rel=1e-9)   # its own millimetres
    assert rows["plain.stl"]["volume"] == pytest.approx(24e-6 * 1000, rel=1e-9)  # --units cm on mm numbers
    assert main(["analyze", str(d / "declared.3mf"), "--units", "cm"]) == 2


@pytest.mark.parametrize("command", [["analyze"], ["spin"], ["spin-it", "--axis", "0,0,1", "--wall", "2mm",
                                                              "--resolution", "16"]])
def test_step_weld_warning_is_said_once_with_the_file_name(tmp_path, capsys, command):
    """Issue 24: a STEP printed each weld warning twice, once as `<arrays>`."""
    pytest.importorskip("OCP")
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    shape = BRepAlgoAPI_Fuse(BRepPrimAPI_MakeBox(20, 30, 40).Shape(), BRepPrimAPI_MakeCylinder(5, 60).Shape()).Shape()
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    path = str(tmp_path / "part.step")
    writer.Write(path)
    capsys.readouterr()
    args = [command[0], path, "--material", "steel"] + command[1:]
    if command[0] == "spin-it":
        pytest.importorskip("manifold3d")
    main(args)
    err = capsys.readouterr().err
    assert "<arrays>" not in err
    welds = [line for line in err.splitlines() if "welded" in line]
    assert len(welds) <= 1 and all(path in line for line in welds)


def test_balance_html_text_cells_wrap_and_numbers_stay_whole():
    """Issue 24: the balance HTML report cut its value columns off at 1280 px (long right-aligned text cells
    that could not wrap, e.g. the grades' "typical rotors").  Text cells are now left-aligned and wrap."""
    import re

    from inertia_tool.reports.balance import _html_table
    html = _html_table(["grade", "e·Ω [mm/s]", "typical rotors"],
                       [["G 6.3", "6.3", "general machinery: pump impellers, fans, flywheels, electric motor rotors"]])
    cells = re.findall(r"<td([^>]*)>([^<]*)</td>", html)
    assert cells[0] == (' class="l" style="white-space:nowrap"', "G 6.3")
    assert cells[1] == ("", "6.3")                                   # numbers: right-aligned, one line
    assert cells[2][0] == ' class="l"' and cells[2][1].startswith("general machinery")
