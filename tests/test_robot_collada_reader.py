"""The COLLADA reader without trimesh (:mod:`inertia_tool.mesh.collada`, issue 23 item 4) against trimesh's own
reading of the same documents (independent code: ``trimesh.load`` with pycollada, its scene graph and
``Scene.dump``, as the reader used them before): the same vertices and faces bit for bit, the same declared unit
and float32 rounding, on the COLLADA files of the repository and on generated documents that exercise each rule
(node transforms, mirrors, nearly orthogonal float32 rotations, ``<instance_node>``, ``<polylist>`` and
``<polygons>`` fans, normals and bound texture coordinates in the vertex merge, units, lines, empty scenes)."""

from __future__ import annotations

import glob
import logging
import os
import sys
import warnings

import numpy as np
import pytest

pytest.importorskip("collada")
trimesh = pytest.importorskip("trimesh")

from inertia_tool.errors import MeshReadError  # noqa: E402
from inertia_tool.mesh import read_collada, read_trimesh  # noqa: E402
from inertia_tool.mesh.regular import regular_file_resolver  # noqa: E402
from inertia_tool.mesh.regular import open_regular  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def _through_trimesh(path: str):
    """``(vertices, faces, declared, rounding)`` as the reader computed them through trimesh (before issue 23
    item 4), or None when trimesh finds no triangle mesh."""
    quiet = logging.getLogger("trimesh")
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with open_regular(path) as fh:
                loaded = trimesh.load(fh, file_type="dae", process=False, force=None,
                                      resolver=regular_file_resolver(path))
            if isinstance(loaded, trimesh.Scene) and not loaded.geometry:
                loaded = trimesh.load(read_collada._collada_geometry_only(path), file_type="dae", process=False,
                                      force=None)
    finally:
        quiet.setLevel(level)
    declared = read_trimesh._declared_scale(path, ".dae", loaded)
    rounding = read_trimesh._scene_rounding(loaded)
    if isinstance(loaded, trimesh.Scene):
        geoms = [g for g in loaded.dump() if isinstance(g, trimesh.Trimesh)] if loaded.geometry else []
        if not geoms:
            return None
        loaded = trimesh.util.concatenate(geoms) if len(geoms) > 1 else geoms[0]
    return np.asarray(loaded.vertices, dtype=np.float64), np.asarray(loaded.faces), declared, rounding


def _assert_same(path: str) -> None:
    expected = _through_trimesh(path)
    if expected is None:
        with pytest.raises(MeshReadError, match="contains no triangle mesh"):
            read_collada._read_collada(path)
        return
    v, f, declared, rounding = read_collada._read_collada(path)
    assert v.shape == expected[0].shape and f.shape == expected[1].shape
    assert np.array_equal(v, expected[0])            # bit for bit
    assert np.array_equal(f, expected[1])
    assert declared == expected[2]
    assert rounding == expected[3]


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(HERE, "data", "**", "*.dae"), recursive=True)),
                         ids=os.path.basename)
def test_repository_collada_files_read_as_trimesh_read_them(path):
    _assert_same(path)


# -- generated documents ---------------------------------------------------------------------------------------

_HEAD = ('<?xml version="1.0" encoding="utf-8"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" '
         'version="1.4.1"><asset>{unit}<up_axis>Z_UP</up_axis></asset>')


def _floats(values) -> str:
    return " ".join(repr(float(x)) for x in np.asarray(values, dtype=np.float32).reshape(-1))


def _geometry(gid: str, rng, *, kind: str, normals: bool, uv: bool) -> str:
    """A geometry of a few triangles (or polygons) on points some of which repeat (the merge) and some of which
    differ from another by less than the merge's 1e-8 rounding."""
    n = int(rng.integers(4, 9))
    points = rng.normal(size=(n, 3)) * rng.choice([0.01, 1.0, 300.0])
    points[-1] = points[0] + 3e-9                     # within trimesh's merge rounding of point 0, or not
    sources = [f'<source id="{gid}-pos"><float_array id="{gid}-pos-a" count="{3 * n}">{_floats(points)}'
               f'</float_array><technique_common><accessor source="#{gid}-pos-a" count="{n}" stride="3">'
               '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'
               '</accessor></technique_common></source>']
    inputs = [f'<input semantic="VERTEX" source="#{gid}-vtx" offset="0"/>']
    width = 1
    if normals:
        unit = rng.normal(size=(3, 3))
        unit /= np.linalg.norm(unit, axis=1)[:, None]
        sources.append(f'<source id="{gid}-nrm"><float_array id="{gid}-nrm-a" count="9">{_floats(unit)}'
                       f'</float_array><technique_common><accessor source="#{gid}-nrm-a" count="3" stride="3">'
                       '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" '
                       'type="float"/></accessor></technique_common></source>')
        inputs.append(f'<input semantic="NORMAL" source="#{gid}-nrm" offset="{width}"/>')
        width += 1
    if uv:
        st = rng.random((3, 2))
        sources.append(f'<source id="{gid}-uv"><float_array id="{gid}-uv-a" count="6">{_floats(st)}'
                       f'</float_array><technique_common><accessor source="#{gid}-uv-a" count="3" stride="2">'
                       '<param name="S" type="float"/><param name="T" type="float"/></accessor>'
                       '</technique_common></source>')
        inputs.append(f'<input semantic="TEXCOORD" source="#{gid}-uv" offset="{width}" set="0"/>')
        width += 1

    def corners(count: int) -> list[int]:
        out = []
        for _ in range(count):
            out.append(int(rng.integers(0, n)))
            out.extend(int(rng.integers(0, 3)) for _ in range(width - 1))
        return out

    if kind == "triangles":
        k = int(rng.integers(2, 6))
        body = (f'<triangles material="mat" count="{k}">{"".join(inputs)}<p>'
                f'{" ".join(map(str, corners(3 * k)))}</p></triangles>')
    else:
        counts = [int(c) for c in rng.integers(3, 7, size=int(rng.integers(1, 4)))]
        if kind == "polylist":
            body = (f'<polylist material="mat" count="{len(counts)}">{"".join(inputs)}<vcount>'
                    f'{" ".join(map(str, counts))}</vcount><p>{" ".join(map(str, corners(sum(counts))))}</p>'
                    '</polylist>')
        else:
            body = (f'<polygons material="mat" count="{len(counts)}">{"".join(inputs)}'
                    + "".join(f'<p>{" ".join(map(str, corners(c)))}</p>' for c in counts) + '</polygons>')
    return (f'<geometry id="{gid}" name="{gid}"><mesh>{"".join(sources)}<vertices id="{gid}-vtx">'
            f'<input semantic="POSITION" source="#{gid}-pos"/></vertices>{body}</mesh></geometry>')


def _transform(rng) -> str:
    """One node transform: a matrix (a float32 rotation, possibly mirrored or scaled), a translate, a rotate or
    a scale (possibly negative)."""
    kind = rng.integers(0, 5)
    if kind == 0:
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        q *= rng.choice([1.0, -1.0, 1.7])
        m = np.eye(4)
        m[:3, :3] = q
        m[:3, 3] = rng.normal(size=3)
        return f"<matrix>{_floats(m)}</matrix>"
    if kind == 1:
        return f"<translate>{_floats(rng.normal(size=3))}</translate>"
    if kind == 2:
        axis = rng.normal(size=3)
        return f"<rotate>{_floats(np.r_[axis / np.linalg.norm(axis), rng.uniform(-180, 180)])}</rotate>"
    if kind == 3:
        return f"<scale>{_floats(rng.choice([-1.0, 1.0, 0.5, 2.0], size=3))}</scale>"
    return ""


def _document(seed: int) -> str:
    rng = np.random.default_rng(seed)
    unit = rng.choice(["", '<unit name="meter" meter="1"/>', '<unit name="millimeter" meter="0.001"/>',
                       '<unit name="inch" meter="0.0254"/>', '<unit name="odd" meter="0.37"/>'])
    geometries, nodes, library = [], [], []
    bound = rng.random() < 0.6
    material = ('<library_effects><effect id="fx"><profile_COMMON><technique sid="c"><phong><diffuse>'
                '<color>0.8 0.8 0.8 1</color></diffuse></phong></technique></profile_COMMON></effect>'
                '</library_effects><library_materials><material id="m0" name="m0"><instance_effect url="#fx"/>'
                '</material></library_materials>')
    binding = ('<bind_material><technique_common><instance_material symbol="mat" target="#m0"/>'
               '</technique_common></bind_material>') if bound else ""
    for g in range(int(rng.integers(1, 4))):
        kind = str(rng.choice(["triangles", "polylist", "polygons"]))
        geometries.append(_geometry(f"g{g}", rng, kind=kind, normals=bool(rng.random() < 0.5),
                                    uv=bool(rng.random() < 0.5)))
    lines = ('<geometry id="ln"><mesh><source id="ln-pos"><float_array id="ln-pos-a" count="6">0 0 0 1 1 1'
             '</float_array><technique_common><accessor source="#ln-pos-a" count="2" stride="3"><param name="X" '
             'type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
             '</technique_common></source><vertices id="ln-vtx"><input semantic="POSITION" source="#ln-pos"/>'
             '</vertices><lines count="1"><input semantic="VERTEX" source="#ln-vtx" offset="0"/><p>0 1</p></lines>'
             '</mesh></geometry>')
    geometries.append(lines)

    def node(depth: int, name: str) -> str:
        parts = [_transform(rng) for _ in range(int(rng.integers(0, 3)))]
        for g in range(len(geometries) - 1):
            if rng.random() < 0.5:
                parts.append(f'<instance_geometry url="#g{g}">{binding}</instance_geometry>')
        if rng.random() < 0.2:
            parts.append('<instance_geometry url="#ln"/>')
        if depth < 2:
            for c in range(int(rng.integers(0, 3))):
                parts.append(node(depth + 1, f"{name}_{c}"))
        if library and rng.random() < 0.3:
            parts.append('<instance_node url="#lib0"/>')
        return f'<node id="{name}" name="{name}">{"".join(parts)}</node>'

    library.append(f'<node id="lib0" name="lib0">{_transform(rng)}<instance_geometry url="#g0">{binding}'
                   '</instance_geometry></node>')
    for r in range(int(rng.integers(1, 3))):
        nodes.append(node(0, f"n{r}"))
    return (_HEAD.format(unit=unit) + material + f'<library_geometries>{"".join(geometries)}</library_geometries>'
            f'<library_nodes>{"".join(library)}</library_nodes><library_visual_scenes><visual_scene id="s">'
            f'{"".join(nodes)}</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/>'
            '</scene></COLLADA>')


@pytest.mark.parametrize("seed", range(40))
def test_generated_documents_read_as_trimesh_reads_them(tmp_path, seed):
    path = tmp_path / f"gen{seed}.dae"
    path.write_text(_document(seed))
    _assert_same(str(path))


def test_a_nearly_orthogonal_float32_rotation_is_made_a_rotation_as_trimesh_does(tmp_path):
    """trimesh's scene graph replaces a node matrix whose rotation is orthogonal only to float32 precision by
    the nearest rotation: the points move by ~1e-8 relative, and the reader must move them the same way."""
    angle = np.radians(37.0)
    m = np.eye(4)
    m[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    m[:3, 3] = [0.5, -0.25, 2.0]
    text = _document(3).replace("<library_visual_scenes>", "<library_visual_scenes>", 1)
    text = text.replace('<node id="n0" name="n0">', f'<node id="n0" name="n0"><matrix>{_floats(m)}</matrix>', 1)
    path = tmp_path / "rot.dae"
    path.write_text(text)
    _assert_same(str(path))
    from inertia_tool.mesh.collada import _rigid_repaired
    stored = np.asarray(np.asarray(m, dtype=np.float32), dtype=np.float64)
    fixed = _rigid_repaired(stored)
    assert not np.array_equal(fixed, stored)
    assert np.abs(fixed[:3, :3] @ fixed[:3, :3].T - np.eye(3)).max() < 1e-14


def test_a_mirroring_node_reverses_the_faces(tmp_path):
    """A node with a negative scale keeps the surface's outward winding: a unit tetrahedron mirrored through the
    node encloses +1/6, not −1/6."""
    from inertia_tool.integrals import volume_moments
    pts = "0 0 0 1 0 0 0 1 0 0 0 1"
    tri = "0 2 1 0 1 3 0 3 2 1 2 3"
    doc = (_HEAD.format(unit="") + '<library_geometries><geometry id="t"><mesh><source id="t-p"><float_array '
           f'id="t-a" count="12">{pts}</float_array><technique_common><accessor source="#t-a" count="4" stride="3">'
           '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
           '</technique_common></source><vertices id="t-v"><input semantic="POSITION" source="#t-p"/></vertices>'
           f'<triangles count="4"><input semantic="VERTEX" source="#t-v" offset="0"/><p>{tri}</p></triangles>'
           '</mesh></geometry></library_geometries><library_visual_scenes><visual_scene id="s"><node id="a">'
           '<scale>-1 1 1</scale><instance_geometry url="#t"/></node></visual_scene></library_visual_scenes>'
           '<scene><instance_visual_scene url="#s"/></scene></COLLADA>')
    path = tmp_path / "mirror.dae"
    path.write_text(doc)
    _assert_same(str(path))
    v, f, _, _ = read_collada._read_collada(str(path))
    assert volume_moments(v, f).volume == pytest.approx(1 / 6, rel=1e-12)


def test_reading_collada_does_not_import_trimesh(tmp_path):
    """The point of the reader: a COLLADA file is read without importing trimesh (and scipy.spatial with it)."""
    import subprocess
    path = tmp_path / "gen.dae"
    path.write_text(_document(1))
    code = ("import sys; from inertia_tool.mesh.read import load_mesh; load_mesh(sys.argv[1]); "
            "print('trimesh' in sys.modules, 'scipy.spatial' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, check=True,
                          env={**os.environ, "PYTHONPATH": os.path.dirname(HERE)})
    assert done.stdout.split() == ["False", "False"]


def _unique_rows(keys):
    """``np.unique``'s groups of equal rows (the reference ``collada._equal_rows`` stands in for)."""
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return first, inverse.reshape(-1)


def _colliding_pair(rng, width):
    """Two different rows of ``width`` int64 keys that ``collada._equal_rows`` mixes into the same word."""
    from inertia_tool.mesh.collada import _ROW_MIX
    row = [int(x) for x in rng.integers(-10 ** 9, 10 ** 9, size=width)]
    other = list(row)
    other[1] += 1                  # then a' M0 = a M0 − M1 (mod 2⁶⁴): M0 is odd, so invertible
    m0, m1 = int(_ROW_MIX[0]), int(_ROW_MIX[1])
    shift = (-m1 * pow(m0, -1, 1 << 64)) % (1 << 64)
    other[0] = (row[0] + shift) % (1 << 64)
    other[0] -= (1 << 64) if other[0] >= 1 << 63 else 0
    return np.array([row, other], dtype=np.int64)


@pytest.mark.parametrize("seed", range(30))
def test_equal_rows_are_grouped_as_numpy_unique_groups_them(seed):
    """``_equal_rows`` (a mixed word per row, sorted) groups rows exactly as ``np.unique(axis=0)``: the same
    groups with the same first index, on rows with many repeats, near-equal rows (one key ±1), the widths the
    merge uses (3, 5, 6, 8 keys) and rows built to share a word (then it declines and ``_merged`` sorts the rows
    themselves); the merged vertices and faces are the same either way."""
    from inertia_tool.mesh import collada
    rng = np.random.default_rng(seed)
    width = int(rng.choice([3, 5, 6, 8]))
    distinct = rng.integers(-3, 4, size=(int(rng.integers(1, 40)), width)) * int(rng.choice([1, 10 ** 8, 2 ** 40]))
    keys = distinct[rng.integers(0, len(distinct), size=3 * int(rng.integers(1, 60)))]
    keys[rng.random(len(keys)) < 0.1, 0] += 1                        # neighbours that differ in one key
    collide = seed % 3 == 0
    if collide:
        keys = np.concatenate([keys, _colliding_pair(rng, width)])
        keys = keys[:len(keys) - len(keys) % 3]
    found = collada._equal_rows(keys)
    first, inverse = _unique_rows(keys)
    if collide and len(np.unique(keys, axis=0)) > 1 and found is None:
        pass                                                         # declined: _merged sorts the rows instead
    else:
        assert found is not None
        mine_first, mine_inverse = found
        # the same partition of the rows, each group named by its first row
        np.testing.assert_array_equal(np.sort(mine_first), np.sort(first))
        np.testing.assert_array_equal(mine_first[mine_inverse], first[inverse])
    corners = keys[:, :3].astype(np.float64) * 1e-8
    real = collada._equal_rows
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(collada, "_equal_rows", lambda k: None)           # the rows sorted by np.unique
        reference = collada._merged(corners, None, None)
    merged = collada._merged(corners, None, None)
    assert collada._equal_rows is real
    np.testing.assert_array_equal(merged[0], reference[0])
    np.testing.assert_array_equal(merged[1], reference[1])


def test_rows_that_share_a_word_are_not_taken_for_one_vertex():
    """Two different rows mixed into the same word: ``_equal_rows`` declines (never merges them)."""
    from inertia_tool.mesh import collada
    pair = _colliding_pair(np.random.default_rng(7), 3)
    words = (pair.view(np.uint64) * collada._ROW_MIX[:3]).sum(axis=1, dtype=np.uint64)
    assert words[0] == words[1] and not np.array_equal(pair[0], pair[1])
    assert collada._equal_rows(np.concatenate([pair, pair[:1]])) is None
