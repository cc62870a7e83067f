"""reports/spin_it.py's HTML report (``spin-it --report``): written through the one output writer, parses, shows
the exact re-analyses of the JSON output and the simulated spin before and after as inline SVG."""

import json
import math
import re
from html.parser import HTMLParser

import pytest

pytest.importorskip("manifold3d")
trimesh = pytest.importorskip("trimesh")

from inertia_tool.cli import main  # noqa: E402
from test_design_spin_it import asymmetric_top, lopsided_yoyo  # noqa: E402


class _Page(HTMLParser):
    """Tables (rows of cell texts), number of ``<svg>`` and ``<polyline>`` elements, figure captions, title."""

    def __init__(self):
        super().__init__()
        self.tables, self.captions, self.svgs, self.lines, self.title = [], [], 0, 0, ""
        self._cell = self._where = None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []
        elif tag == "svg":
            self.svgs += 1
        elif tag == "polyline":
            self.lines += 1
        elif tag in ("figcaption", "title"):
            self._where = tag
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None
        elif tag == "figcaption" and self._where == "figcaption":
            self.captions.append("".join(self._cell))
            self._cell = self._where = None
        elif tag == "title" and self._where == "title":
            self.title = "".join(self._cell)
            self._cell = self._where = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def _parse(path):
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    page.close()
    return page


def _value(cell: str) -> float:
    return float(re.match(r"-?[0-9.]+(e[-+]?[0-9]+)?", cell).group(0))


def _spans(caption: str) -> list[float]:
    """Widths (max − min) of the ranges ``label: lo to hi`` of a caption."""
    return [float(hi) - float(lo) for lo, hi in re.findall(r": (-?[0-9.e+-]+) to (-?[0-9.e+-]+)", caption)]


def test_cli_spin_it_report_of_a_yoyo(tmp_path, capsys):
    v, f = lopsided_yoyo()
    src = tmp_path / "yo<yo>&.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(src)
    report = tmp_path / "r.html"
    args = ["spin-it", str(src), "--units", "mm", "--material", "PLA", "--axis", "0,0,1", "--through", "0,0,0",
            "--wall", "2mm", "--resolution", "24", "--report", str(report)]
    assert main(args + ["--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert f"wrote {report}" in captured.err
    text = report.read_text(encoding="utf-8")
    assert "yo&lt;yo&gt;&amp;.stl" in text and "yo<yo>" not in text
    page = _parse(report)
    assert page.title == f"spin-it: {src}"
    table = next(t for t in page.tables if t[0] == ["quantity", "before", "after"])
    rows = {r[0]: r[1:] for r in table[1:]}
    for side, column in (("before", 0), ("after", 1)):
        metrics = data[side]["metrics"]
        mass = data[side]["mass_properties"]["mass"]
        assert _value(rows["mass"][column]) == pytest.approx(mass * 1e3, rel=1e-3)
        assert _value(rows["I_axis (about the COM) kg·m²"][column]) == pytest.approx(metrics["axis_moment"],
                                                                                    rel=1e-4)
        assert _value(rows["I_axis / I_next"][column]) == pytest.approx(metrics["moment_ratio"], abs=1e-4)
        assert _value(rows["COM offset from the axis"][column]) == pytest.approx(metrics["axis_offset"] * 1e3,
                                                                                abs=1e-3)
        assert _value(rows["axis to nearest principal axis"][column]) == pytest.approx(
            math.degrees(metrics["axis_tilt"]), abs=1e-3)
    # two panels (before, after), each with the two transverse components of ω; the wobble shrinks
    assert page.svgs == 2 and page.lines == 4
    before, after = (_spans(c) for c in page.captions)
    assert len(before) == len(after) == 2
    assert max(after) < 0.8 * max(before)              # coarse grid (24): 3.8 → 2.3 rad/s; at 40, 3.8 → 0.6
    # refuses to overwrite without --force (before any work), replaces it with --force
    report.write_text("keep", encoding="utf-8")
    assert main(args) == 2
    assert "--report" in capsys.readouterr().err and report.read_text(encoding="utf-8") == "keep"
    assert main(args + ["--force"]) == 0
    assert report.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_cli_spin_it_report_of_a_top(tmp_path, capsys):
    v, f = asymmetric_top()
    src = tmp_path / "top.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(src)
    report = tmp_path / "top.html"
    assert main(["spin-it", str(src), "--units", "mm", "--material", "PLA", "--mode", "top", "--axis", "0,0,1",
                 "--pivot", "0,0,0", "--wall", "1.5mm", "--resolution", "24", "--report", str(report),
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    page = _parse(report)
    table = next(t for t in page.tables if t[0] == ["quantity", "before", "after"])
    rows = {r[0]: r[1:] for r in table[1:]}
    for side, column in (("before", 0), ("after", 1)):
        threshold = data[side]["metrics"]["sleeping_threshold"]
        assert _value(rows["sleeping-top threshold √(4 I1 M g l)/I3"][column]) == pytest.approx(threshold,
                                                                                               rel=1e-3)
    # θ(t) before and after: released at 0.05 rad, nutating above it and staying upright (spun above threshold)
    assert page.svgs == 2 and page.lines == 2
    for caption in page.captions:
        lo, hi = (float(x) for x in re.search(r"θ: ([0-9.]+) to ([0-9.]+)", caption).groups())
        assert lo == pytest.approx(math.degrees(0.05), rel=1e-2)
        assert math.degrees(0.05) < hi < 30
