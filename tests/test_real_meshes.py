"""Real robot meshes from registry packages (``tests/data/``, provenance in ``tests/data/README.md``).

What ``mass_properties`` and ``analyze`` give on each, checked against independent computations: trimesh's
``mass_properties`` on the same triangles welded by exact vertex bit patterns (and manifold3d's volume where
it accepts the mesh), to 1e-9 relative; manifold3d's boolean union for overlapping bodies; the COLLADA files'
units and node matrices read with ElementTree.  The damaged files are refused with one line naming the file
unless ``repair=True``, which must then state its method and bounds.
"""

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import inertia_tool as it
from conftest import assert_tensor_close
from inertia_tool.cli import main
from inertia_tool.errors import InsideOutWarning, InvalidMeshError, NearlyEqualMomentsWarning, OverlapWarning

trimesh = pytest.importorskip("trimesh")

DATA = Path(__file__).parent / "data"
_ERD = "robots/example-robot-data/robots/"
#: Files shared with the robot-description tests (listed in the first table of tests/data/README.md).
SHARED = {
    "ur5_collision_base.stl": _ERD + "ur_description/meshes/ur5/collision/base.stl",
    "ur5_collision_wrist1.stl": _ERD + "ur_description/meshes/ur5/collision/wrist1.stl",
    "ur5_collision_shoulder.stl": _ERD + "ur_description/meshes/ur5/collision/shoulder.stl",
    "ur5_collision_forearm.stl": _ERD + "ur_description/meshes/ur5/collision/forearm.stl",
    "panda_collision_link1.stl": _ERD + "panda_description/meshes/collision/link1.stl",
    "panda_collision_hand.stl": _ERD + "panda_description/meshes/collision/hand.stl",
}


def data(name):
    """Path of a test mesh: a file of this directory, or one shared with the robot-description tests."""
    return DATA / SHARED.get(name, name)
RTOL = 1e-9

#: Closed files the plain call accepts: name -> (bodies, warning expected or None).
CLOSED = {
    "ur5_collision_base.stl": (1, None),
    "ur5_collision_wrist1.stl": (2, None),                     # two separate bodies, no overlap
    "panda_collision_link1.stl": (1, None),
    "panda_collision_hand.stl": (1, None),
    "solo12_base.stl": (1, None),                              # 5,472 faces
    "tiago_pro_arm_7_link_collision.stl": (1, InsideOutWarning),   # wound inside out in the package
    "finger_edu_base_front.stl": (1, None),                    # closed only after welding within 1e-6 of its size
}
#: Closed files whose bodies overlap (named in a warning; united by default since issue 10).
OVERLAPPING = ["ur5_collision_shoulder.stl", "ur5_collision_forearm.stl", "pybullet_tray_textured2.obj"]
#: Files that are not closed solids: refused by the plain call.
DAMAGED = {"ur10_collision_forearm.stl": "boundary edges", "pr2_wrist_flex.stl": "boundary edges"}
#: COLLADA files: inch units; node transforms with non-uniform scale.
COLLADA = ["pybullet_racecar_cone.dae", "pybullet_racecar_parking_1.dae"]


def exact_welded(path):
    """Vertices and faces of ``path`` as trimesh reads them unprocessed, welded by exact coordinates."""
    mesh = trimesh.load(str(path), process=False, force="mesh")
    unique, inverse = np.unique(np.asarray(mesh.vertices, dtype=np.float64), axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[np.asarray(mesh.faces)]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    return unique, faces[keep]


def trimesh_reference(path):
    """(volume, centre of mass, central inertia) at unit density from trimesh, outward orientation."""
    vertices, faces = exact_welded(path)
    props = trimesh.Trimesh(vertices=vertices, faces=faces, process=False).mass_properties
    sign = np.sign(props.volume)           # an inside-out file integrates to minus the solid
    return sign * props.volume, np.asarray(props.center_mass), sign * np.asarray(props.inertia), vertices


def quiet_mass_properties(path, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = it.mass_properties(path, **kwargs)
    return props, [w for w in caught if not issubclass(w.category, NearlyEqualMomentsWarning)]


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_closed_real_mesh_matches_trimesh_on_the_same_triangles(name):
    bodies, expected_warning = CLOSED[name]
    props, caught = quiet_mass_properties(data(name), density=1.0)
    shape_warnings = {w.category for w in caught} & {InsideOutWarning, OverlapWarning}
    assert shape_warnings == ({expected_warning} if expected_warning else set())
    assert props.mesh.bodies == bodies
    volume, center, inertia, vertices = trimesh_reference(data(name))
    diagonal = np.linalg.norm(np.ptp(vertices, axis=0))
    assert props.volume == pytest.approx(volume, rel=RTOL)
    assert props.mass == pytest.approx(volume, rel=RTOL)
    np.testing.assert_allclose(props.center_of_mass, center, rtol=0, atol=RTOL * diagonal)
    assert_tensor_close(props.inertia, inertia, rtol=RTOL)


@pytest.mark.parametrize("name", sorted(set(CLOSED) - {"finger_edu_base_front.stl"}))
def test_closed_real_mesh_volume_matches_manifold3d(name):
    m3d = pytest.importorskip("manifold3d")
    vertices, faces = exact_welded(data(name))
    solid = m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(vertices),
                                    tri_verts=np.ascontiguousarray(faces, dtype=np.uint64)))
    assert solid.status() == m3d.Error.NoError
    props, _ = quiet_mass_properties(data(name), density=1.0)
    assert props.volume == pytest.approx(abs(solid.volume()), rel=RTOL)


def test_finger_edu_base_front_is_closed_only_by_tolerance_welding():
    props, _ = quiet_mass_properties(data("finger_edu_base_front.stl"))
    diagonal = np.linalg.norm(props.mesh.bbox_max - props.mesh.bbox_min)
    assert props.mesh.welded_tolerance is not None
    assert props.mesh.welded_tolerance == pytest.approx(1e-6 * diagonal)
    with pytest.raises(InvalidMeshError, match="boundary edges"):
        it.mass_properties(data("finger_edu_base_front.stl"), merge_tolerance=0)


@pytest.mark.parametrize("name", ["ur5_collision_base.stl", "solo12_base.stl"])
def test_analyze_json_on_real_mesh_matches_the_api(name, capsys):
    assert main(["analyze", str(data(name)), "--density", "1000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    props, _ = quiet_mass_properties(data(name), density=1000.0)
    assert out["mass"] == pytest.approx(props.mass, rel=RTOL)
    np.testing.assert_allclose(out["center_of_mass"], props.center_of_mass, rtol=RTOL, atol=0)
    assert_tensor_close(out["inertia"], props.inertia, rtol=RTOL)


def _sum_of_bodies_options():
    """Options asking for the plain sum of overlapping bodies: the default before issue 10, which adds a
    ``LoadOptions.overlap`` field ("union" by default, "sum" keeps the double count)."""
    names = {f.name for f in dataclasses.fields(it.LoadOptions)}
    return {"overlap": "sum"} if "overlap" in names else {}


@pytest.mark.parametrize("name", OVERLAPPING)
def test_overlapping_bodies_are_named_in_a_warning(name):
    _, caught = quiet_mass_properties(data(name), density=1.0)
    assert OverlapWarning in [w.category for w in caught]


@pytest.mark.parametrize("name", OVERLAPPING)
def test_sum_of_overlapping_bodies_matches_trimesh(name):
    props, _ = quiet_mass_properties(data(name), density=1.0, **_sum_of_bodies_options())
    volume, center, inertia, vertices = trimesh_reference(data(name))    # trimesh sums the shells
    assert props.volume == pytest.approx(volume, rel=RTOL)
    np.testing.assert_allclose(props.center_of_mass, center, rtol=0,
                               atol=RTOL * np.linalg.norm(np.ptp(vertices, axis=0)))
    assert_tensor_close(props.inertia, inertia, rtol=RTOL)


def _manifold_union_volume(path):
    m3d = pytest.importorskip("manifold3d")
    vertices, faces = exact_welded(path)
    whole = m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(vertices),
                                    tri_verts=np.ascontiguousarray(faces, dtype=np.uint64)))
    return m3d.Manifold.batch_boolean(whole.decompose(), m3d.OpType.Add).volume()


@pytest.mark.parametrize("name", ["ur5_collision_shoulder.stl", "pybullet_tray_textured2.obj"])
def test_repair_gives_the_union_of_overlapping_bodies(name):
    # shoulder: the bodies overlap by 6e-6 of the volume; tray: by 1.1 %; manifold3d's union is the truth
    union = _manifold_union_volume(data(name))
    props, _ = quiet_mass_properties(data(name), density=1.0, repair=True)
    assert props.volume == pytest.approx(union, rel=1e-7)


@pytest.mark.parametrize("name", sorted(DAMAGED))
def test_damaged_real_mesh_is_refused_in_one_line_naming_the_file(name):
    with pytest.raises(InvalidMeshError) as info:
        it.mass_properties(data(name))
    message = str(info.value)
    assert "\n" not in message
    assert name in message
    assert DAMAGED[name] in message


@pytest.mark.parametrize("name", sorted(DAMAGED))
def test_analyze_refuses_damaged_real_mesh_with_exit_code_3(name, capsys):
    assert main(["analyze", str(data(name))]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and name in err[0]


@pytest.mark.parametrize("name", sorted(DAMAGED))
def test_repair_of_damaged_real_mesh_states_method_and_bounds(name):
    # no truth is known for these files: the estimate must say how it was made and how far it may be off,
    # and lie between nothing and the convex hull of the vertices
    props, _ = quiet_mass_properties(data(name), density=1.0, repair=True)
    report = getattr(props, "mesh_report", None) or props.mesh
    assert getattr(report, "method", None)
    assert getattr(report, "uncertainty", None) is not None
    vertices, faces = exact_welded(data(name))
    hull = trimesh.Trimesh(vertices=vertices, faces=faces).convex_hull.volume
    assert 0 < props.volume <= hull * (1 + RTOL)


def collada_instances(path):
    """(unit in m, [(4×4 node matrix, (k, 3) positions)]) of every geometry instance, read with ElementTree.

    Nested node matrices are composed from the root down; positions are the geometry's first float array.
    """
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    ns = {"c": root.tag[1:root.tag.index("}")]}
    unit = root.find("c:asset/c:unit", ns)
    meter = float(unit.get("meter")) if unit is not None else 1.0
    positions = {g.get("id"): np.array(g.find(".//c:float_array", ns).text.split(), dtype=float).reshape(-1, 3)
                 for g in root.iter(f"{{{ns['c']}}}geometry")}
    found = []

    def walk(node, matrix):
        m = node.find("c:matrix", ns)
        if m is not None:
            matrix = matrix @ np.array(m.text.split(), dtype=float).reshape(4, 4)
        for inst in node.findall("c:instance_geometry", ns):
            found.append((matrix, positions[inst.get("url")[1:]]))
        for child in node.findall("c:node", ns):
            walk(child, matrix)

    for scene in root.iter(f"{{{ns['c']}}}visual_scene"):
        for node in scene.findall("c:node", ns):
            walk(node, np.eye(4))
    return meter, found


@pytest.mark.parametrize("name", COLLADA)
def test_collada_unit_and_node_transforms_place_the_vertices(name):
    # the bounding box of the result is that of the file's positions, moved by their nodes' matrices and
    # scaled by <unit meter>: cone.dae is in inches, parking_1.dae places boxes with non-uniform scales
    meter, instances = collada_instances(DATA / name)
    placed = np.vstack([(pos @ m[:3, :3].T + m[:3, 3]) * meter for m, pos in instances])
    props, _ = quiet_mass_properties(DATA / name, density=1.0)
    size = np.linalg.norm(np.ptp(placed, axis=0))
    np.testing.assert_allclose(props.mesh.bbox_min, placed.min(axis=0), rtol=0, atol=1e-6 * size)
    np.testing.assert_allclose(props.mesh.bbox_max, placed.max(axis=0), rtol=0, atol=1e-6 * size)


def test_collada_parking_volume_is_the_sum_of_its_scaled_boxes():
    # four axis-aligned box geometries, each mapped by a linear part of determinant det: V = Σ |det|·V_box
    meter, instances = collada_instances(DATA / "pybullet_racecar_parking_1.dae")
    expected = 0.0
    for matrix, pos in instances:
        assert all(len(np.unique(pos[:, k])) == 2 for k in range(3))    # a box in its own axes
        expected += abs(np.linalg.det(matrix[:3, :3])) * np.prod(np.ptp(pos, axis=0)) * meter ** 3
    props, _ = quiet_mass_properties(DATA / "pybullet_racecar_parking_1.dae", density=1.0)
    assert props.volume == pytest.approx(expected, rel=1e-6)


def test_every_data_file_has_its_provenance_in_the_readme():
    # each file committed under tests/data must name its package, version, original path and licence
    rows = {}
    for line in (DATA / "README.md").read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[0].startswith("`"):
            rows[cells[0].strip("`")] = cells[1:]
    files = sorted(p.name for p in DATA.iterdir() if p.is_file() and p.name != "README.md")
    assert files == sorted(rows)
    for name, (package, original, licence, _) in rows.items():
        assert package.split()[-1][0].isdigit(), f"{name}: no package version"
        assert original.startswith("`") and licence, f"{name}: no original path or licence"
