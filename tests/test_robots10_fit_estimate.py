"""robot: a primitive fitted to a mesh that only ``--repair`` integrates is ``unverified`` with no uncertainty,
and the text table and ``--json`` say so with the same method and the same reason (robots10; robots7 saw arx_l5's
``link2`` "repaired (patched, an estimate)" in the warnings beside ``unverified`` and no bound)."""

import json
import re

import numpy as np

from inertia_tool.cli import main


def _holed_box(path):
    """A 0.1 m box, each side split 8 × 8, one of its 768 triangles missing: a bounded patched estimate."""
    import trimesh
    from conftest import write_binary_stl
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1)).subdivide().subdivide().subdivide()
    write_binary_stl(path, np.asarray(box.vertices), np.asarray(box.faces)[:-1])


def _table_methods(text):
    """link name → the method column of the text table."""
    rows = text.split("\n---")[1].split("\n\n")[0].strip().splitlines()[1:] if "\n---" in text else []
    head = text.split("\n---")[0].splitlines()[-1]
    assert head.startswith("link")
    return {row.split()[0]: row.split()[1] for row in rows if row.strip()}


def test_fitted_primitive_on_an_estimate_says_the_same_in_table_and_json(tmp_path, capsys):
    _holed_box(tmp_path / "open.stl")
    xml = tmp_path / "robot.xml"
    xml.write_text('<mujoco><asset><mesh name="m" file="open.stl"/></asset><worldbody>'
                   '<body name="fitted"><geom type="capsule" mesh="m"/></body>'
                   '<body name="plain"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    argv = ["robot", str(xml), "--density", "model", "--repair"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert main([*argv, "--json"]) == 0
    links = {link["name"]: link for link in json.loads(capsys.readouterr().out)["links"]}
    table = _table_methods(text)
    assert table == {name: link["method"] for name, link in links.items()}
    assert links["plain"]["method"] == "estimate" and links["plain"]["uncertainty"]["mass"] > 0
    fitted = links["fitted"]
    assert fitted["method"] == "unverified" and fitted["uncertainty"] is None
    notes = [w for w in fitted["warnings"] if "is fitted to open.stl" in w]
    assert len(notes) == 1 and "no bound on it is derived" in notes[0]
    assert re.search(r"volume ±[0-9.e+-]+ %, inertia ±[0-9.e+-]+ %", notes[0])
    assert f"fitted: {notes[0]}" in " ".join(text.split())      # the same sentence in the text warnings
    assert not any("is fitted to" in w for w in links["plain"]["warnings"])
