"""glTF scenes read per node (mesh/parts.py ``scene_parts``): node names, their materials' names mapped to
densities, against the closed form of boxes (tests/test_assembly_3mf.py ``box_truth``)."""

from __future__ import annotations

import json

import pytest
import trimesh

from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import MaterialError
from test_assembly_3mf import _check, box_truth


def scene(path, boxes):
    """``boxes``: (node name, lo m, hi m, material name), each a node placing a box mesh by a translation."""
    s = trimesh.Scene()
    for name, lo, hi, material in boxes:
        size = [h - lo_ for h, lo_ in zip(hi, lo)]
        mesh = trimesh.creation.box(size)
        mesh.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(name=material))
        centre = [(h + lo_) / 2 for h, lo_ in zip(hi, lo)]
        s.add_geometry(mesh, node_name=name, geom_name=f"{name}-mesh",
                       transform=trimesh.transformations.translation_matrix(centre))
    s.export(path)
    return path


def test_nodes_with_named_materials_against_closed_form(tmp_path):
    path = scene(tmp_path / "s.glb", [("bolt", (0.03, 0, 0), (0.04, 0.01, 0.01), "steel"),
                                       ("body", (0, 0, 0), (0.01, 0.02, 0.01), "PLA")])
    props = mass_properties(path)
    _check(props, box_truth([((0.03, 0, 0), (0.04, 0.01, 0.01), 7850.0), ((0, 0, 0), (0.01, 0.02, 0.01), 1240.0)]),
           rtol=1e-6)     # glTF stores float32 coordinates
    assert sorted((b.name, b.material) for b in props.parts) == [("body", "PLA"), ("bolt", "steel")]


def test_an_appearance_name_needs_a_default_or_a_map(tmp_path, capsys):
    path = scene(tmp_path / "a.glb", [("a", (0, 0, 0), (0.01, 0.01, 0.01), "Material.001"),
                                       ("b", (0.02, 0, 0), (0.03, 0.01, 0.01), "steel")])
    with pytest.raises(MaterialError, match="Material.001"):
        mass_properties(path)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert "--material-map" in err and "or one for every part with --density or --material" in err
    assert main(["analyze", str(path), "--material", "abs", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert sorted(b["density"] for b in data["bodies"]) == [1040.0, 7850.0]


def _one_mesh_two_primitives(path, boxes):
    """Boxes (as :func:`scene`'s, placed in their vertices) as the two primitives of one mesh in one node, as CAD
    exporters write a part of two materials.  trimesh names the frames of such primitives ``{node}_{6 random hex
    digits}``, new on every load."""
    import struct
    s = trimesh.Scene()
    for name, lo, hi, material in boxes:
        mesh = trimesh.creation.box([h - lo_ for h, lo_ in zip(hi, lo)])
        mesh.apply_translation([(h + lo_) / 2 for h, lo_ in zip(hi, lo)])
        mesh.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(name=material))
        s.add_geometry(mesh, node_name=name, geom_name=f"{name}-mesh")
    s.export(path)
    data = path.read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    binary = data[20 + length:]
    first, second = doc["nodes"][0], doc["nodes"][1]
    doc["meshes"][first["mesh"]]["primitives"] += doc["meshes"][second["mesh"]]["primitives"]
    doc["scenes"][0]["nodes"] = [i for i in doc["scenes"][0]["nodes"] if doc["nodes"][i] is not second]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    header = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + len(binary))
    path.write_bytes(header + struct.pack("<II", len(text), 0x4E4F534A) + text + binary)
    return path


def test_primitive_part_names_are_the_same_on_every_load(tmp_path, capsys):
    """A mesh of two primitives: trimesh's frame names are random, the part names are ``{node} primitive k``, the
    same on every load, and the one a message names can be given back in ``--material-map``."""
    boxes = [("bolt", (0.03, 0, 0), (0.04, 0.01, 0.01), "steel"), ("body", (0, 0, 0), (0.01, 0.02, 0.01), "PLA")]
    path = _one_mesh_two_primitives(tmp_path / "p.glb", boxes)
    names = [sorted((b.name, b.material) for b in mass_properties(path).parts) for _ in range(3)]
    assert names[0] == names[1] == names[2] == [("bolt primitive 1", "steel"), ("bolt primitive 2", "PLA")]
    assert main(["analyze", str(path), "--material-map", "bolt primitive 2=1g/cm3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert sorted(b["density"] for b in data["bodies"]) == [1000.0, 7850.0]
    props = mass_properties(path, material_map={"bolt primitive 2": 1000.0})
    _check(props, box_truth([((0.03, 0, 0), (0.04, 0.01, 0.01), 7850.0), ((0, 0, 0), (0.01, 0.02, 0.01), 1000.0)]),
           rtol=1e-6)
