"""HTML report (inertia_tool.reports.html) and ``analyze --report``."""

import math
import os
import re
import sys
from html.parser import HTMLParser

import numpy as np
import pytest
import trimesh

from conftest import write_binary_stl
from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.reports.html import HtmlSection, html_report, svg_views

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class _Collect(HTMLParser):
    """Elements (tag, attrs) in order, text per heading, all text."""

    def __init__(self):
        super().__init__()
        self.elements = []
        self.text = []
        self.headings = []
        self._in_h = None

    def handle_starttag(self, tag, attrs):
        self.elements.append((tag, dict(attrs)))
        if tag in ("h1", "h2"):
            self._in_h = tag
            self.headings.append("")

    def handle_endtag(self, tag):
        if tag == self._in_h:
            self._in_h = None

    def handle_data(self, data):
        self.text.append(data)
        if self._in_h:
            self.headings[-1] += data


def _parse(doc):
    p = _Collect()
    p.feed(doc)
    p.close()
    return p


def _tags(p, tag, cls=None):
    return [a for t, a in p.elements if t == tag and (cls is None or a.get("class") == cls)]


def _t_handle():
    v2 = np.array([(-40, 0), (40, 0), (40, 12), (6, 12), (6, 70), (-6, 70), (-6, 12), (-40, 12)], float)
    f2 = np.array([(0, 1, 2), (0, 2, 3), (0, 3, 6), (0, 6, 7), (6, 3, 4), (6, 4, 5)])
    m = trimesh.creation.extrude_triangulation(v2, f2, 12.0)
    m.apply_translation([0, 0, -6])
    return m


def _path_points(d):
    nums = np.array([float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", d)])
    return nums.reshape(-1, 2)


def test_report_has_three_views_with_com_axes_and_ellipsoid(tmp_path):
    box = trimesh.creation.box([0.04, 0.02, 0.01])
    box.apply_translation([0.1, -0.05, 0.02])
    props = mass_properties(box, density=2700.0, name="box")
    doc = html_report(props, meshes=[(box.vertices, box.faces)], generated="fixed")
    p = _parse(doc)
    svgs = _tags(p, "svg")
    assert len(svgs) == 3
    assert len(_tags(p, "ellipse", "ellipsoid")) == 3
    assert len(_tags(p, "circle", "com")) == 3
    for k in (1, 2, 3):           # each axis lies in two of the three views, out of the page in the third
        assert len(_tags(p, "line", f"axis{k}")) == 2
    text = " ".join(p.text)
    assert f"{props.mass:.6g}" in text and "2700" in text
    for k in range(3):
        assert f"{props.principal.moments[k]:.6e}" in text
    # no external resources, no scripts
    assert not _tags(p, "script") and not _tags(p, "link") and "http://" not in doc.replace(
        'xmlns="http://www.w3.org/2000/svg"', "")


def test_drawing_geometry_com_and_ellipse_to_scale():
    # a box 40 x 20 x 10 mm off the origin: in the top view the COM sits at the middle of the outline and the
    # ellipse's semi-axes are the sides times sqrt(5/12) (the equivalent ellipsoid of a box), to the same scale
    box = trimesh.creation.box([0.04, 0.02, 0.01])
    box.apply_translation([0.1, -0.05, 0.02])
    props = mass_properties(box)
    top = _parse(svg_views(props, [(box.vertices, box.faces)])[0])
    fill = _points = _path_points(_tags(top, "path", "fill")[0]["d"])
    (x0, y0), (x1, y1) = fill.min(axis=0), fill.max(axis=0)
    com = _tags(top, "circle", "com")[0]
    assert float(com["cx"]) == pytest.approx((x0 + x1) / 2, abs=0.15)
    assert float(com["cy"]) == pytest.approx((y0 + y1) / 2, abs=0.15)
    scale = (x1 - x0) / 0.04                      # px per metre
    assert (y1 - y0) / 0.02 == pytest.approx(scale, rel=0.02)
    ell = _tags(top, "ellipse", "ellipsoid")[0]
    assert float(ell["rx"]) == pytest.approx(0.04 * math.sqrt(5 / 12) * scale, rel=0.01)
    assert float(ell["ry"]) == pytest.approx(0.02 * math.sqrt(5 / 12) * scale, rel=0.01)
    del _points


def test_rotated_part_tilts_the_ellipse():
    box = trimesh.creation.box([0.04, 0.01, 0.01])
    box.apply_transform(trimesh.transformations.rotation_matrix(math.radians(30), [0, 0, 1]))
    props = mass_properties(box)
    ell = _tags(_parse(svg_views(props, [(box.vertices, box.faces)])[0]), "ellipse", "ellipsoid")[0]
    angle = float(re.match(r"rotate\((-?[\d.]+)", ell["transform"]).group(1))
    assert (angle + 30) % 180 == pytest.approx(0, abs=1e-6) or (angle + 30) % 180 == pytest.approx(180, abs=1e-6)


def test_text_is_escaped():
    box = trimesh.creation.box([1, 1, 1])
    name = 'evil <script>alert("x")</script> & "quotes".stl'
    props = mass_properties(box, name=name)
    doc = html_report(props, meshes=[(box.vertices, box.faces)], warnings=["<b>bold</b> warning"],
                      density_source="<i>x</i>")
    p = _parse(doc)
    assert not _tags(p, "script") and not _tags(p, "b") and not _tags(p, "i")
    assert p.headings[0] == f"Mass properties of {name}"
    assert "<b>bold</b> warning" in " ".join(p.text)


def test_edge_count_is_bounded_for_large_meshes():
    s = trimesh.creation.icosphere(subdivisions=5)          # 20,480 triangles
    props = mass_properties(s)
    views = svg_views(props, [(s.vertices, s.faces)], max_edges=100)
    for v in views:
        edges = _tags(_parse(v), "path", "edges")
        assert len(edges) == 1 and edges[0]["d"].count("M") <= 100
        assert _tags(_parse(v), "polygon", "hull")         # too many front faces: hull outline
    assert sum(len(v) for v in views) < 60_000


def test_report_computes_nothing_it_is_not_given(monkeypatch):
    # formatting only: without a stability verdict there is no stability section, and the writer never
    # imports the stability engine to make one
    monkeypatch.setitem(sys.modules, "inertia_tool.dynamics.spin_stability", None)   # importing it would raise
    m = _t_handle()
    doc = html_report(mass_properties(m), meshes=[(m.vertices, m.faces)])
    assert "Spin stability" not in _parse(doc).headings


def test_stability_section_prints_the_verdict_it_is_given():
    from inertia_tool import stability
    m = _t_handle()
    props = mass_properties(m)
    verdict = stability(props)
    p = _parse(html_report(props, meshes=[(m.vertices, m.faces)], stability=verdict))
    assert "Spin stability" in p.headings
    kinds = [t for t in p.text if t in ("stable", "unstable", "marginal", "neutral")]
    assert kinds == list(verdict.kinds) == ["stable", "unstable", "stable"]
    undefined = _parse(html_report(props, stability="undefined <for a point mass>"))
    assert "undefined <for a point mass>" in undefined.text


def test_extra_sections_plug_in_and_are_escaped():
    box = trimesh.creation.box([1, 2, 3])
    props = mass_properties(box)
    section = HtmlSection(f"Balance <{props.mass:.3g} kg>", "<p>corrections here</p>", "bal ance")
    doc = html_report(props, extra_sections=[section])
    p = _parse(doc)
    assert "Balance <6e+03 kg>" in p.headings and 'id="balance"' in doc


def test_cli_report_refuses_to_overwrite_without_force(tmp_path, capsys):
    m = _t_handle()
    stl = tmp_path / "t <handle>.stl"
    write_binary_stl(stl, m.vertices, m.faces)
    out = tmp_path / "t.html"
    assert main(["analyze", str(stl), "--units", "mm", "--material", "pla", "--report", str(out)]) == 0
    first = out.read_text(encoding="utf-8")
    p = _parse(first)
    assert len(_tags(p, "svg")) == 3 and "t <handle>.stl" in p.headings[0]
    assert "1240" in first
    capsys.readouterr()
    assert main(["analyze", str(stl), "--units", "mm", "--report", str(out)]) == 2
    assert "--force" in capsys.readouterr().err and out.read_text(encoding="utf-8") == first
    assert main(["analyze", str(stl), "--units", "mm", "--report", str(out), "--force", "--json"]) == 0
    assert "1000 kg/m³" in out.read_text(encoding="utf-8")


def test_renders_in_headless_chromium(tmp_path):
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    try:
        import screenshot_report
    finally:
        sys.path.pop(0)
    if screenshot_report.find_chromium() is None:
        pytest.skip("no Chromium on this machine (apt-get install -y chromium)")
    Image = pytest.importorskip("PIL.Image")
    m = _t_handle()
    page = tmp_path / "r.html"
    page.write_text(html_report(mass_properties(m), meshes=[(m.vertices, m.faces)]), encoding="utf-8")
    png = tmp_path / "r.png"
    screenshot_report.screenshot(str(page), str(png), width=1000, height=700)
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert img.shape[:2] == (700, 1000)
    # the views drew coloured pixels: the red, green and blue axes and the orange ellipse
    for colour in [(214, 39, 40), (44, 160, 44), (31, 119, 180), (255, 127, 14)]:
        assert np.any(np.all(np.abs(img - colour) <= 40, axis=-1)), colour
