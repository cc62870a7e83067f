"""Mesh formats robots and CAD use: COLLADA units and node transforms, glTF node transforms, 3MF units,
OBJ groups, compressed single-mesh files with bounded decompression."""

import bz2
import contextlib
import gzip
import os
import warnings
import zipfile

import numpy as np
import pytest
import trimesh

import inertia_tool as it
from inertia_tool.mass import shapes
from inertia_tool.errors import MeshReadError, UsageError
from inertia_tool.mesh.read import load_mesh

from conftest import assert_tensor_close
from robot_data import ERD, UR5_MESHES

DAE = ERD / "robots" / "ur_description" / "meshes" / "ur5" / "visual" / "wrist3.dae"
OBJ = ERD / "robots" / "alexander_description" / "meshes" / "AnklePitchLink.obj"
STL = UR5_MESHES / "wrist3.stl"

pytestmark = pytest.mark.filterwarnings("ignore::inertia_tool.errors.OverlapWarning")


def _collada_triangles(path):
    """Independent reader: pycollada's bound geometry (node transforms applied), file units."""
    collada = pytest.importorskip("collada")
    doc = collada.Collada(str(path))
    tris = [np.asarray(prim.vertex)[np.asarray(prim.vertex_index)]
            for geom in doc.scene.objects("geometry") for prim in geom.primitives()
            if isinstance(prim, collada.triangleset.BoundTriangleSet)]
    return np.concatenate(tris), doc.assetInfo.unitmeter


def test_collada_real_file_matches_pycollada_with_node_transforms():
    raw = load_mesh(DAE)
    tris, unit = _collada_triangles(DAE)
    assert unit == 1.0 and raw.units == "m"
    ours = raw.vertices[raw.faces]
    assert len(ours) == len(tris)
    np.testing.assert_allclose(np.sort(ours.reshape(-1, 3), axis=0), np.sort(tris.reshape(-1, 3), axis=0), atol=1e-12)


def test_collada_unit_is_honoured_and_a_contradicting_unit_refused(tmp_path):
    text = DAE.read_text()
    assert '<unit name="meter" meter="1"/>' in text
    mm = tmp_path / "wrist3_mm.dae"
    mm.write_text(text.replace('<unit name="meter" meter="1"/>', '<unit name="millimeter" meter="0.001"/>'))
    metres, millimetres = load_mesh(DAE), load_mesh(mm)
    assert millimetres.units == "mm"
    np.testing.assert_allclose(millimetres.vertices, 1e-3 * metres.vertices, rtol=1e-15)
    assert load_mesh(mm, units="mm").units == "mm"            # agreeing explicit unit: applied once
    with pytest.raises(UsageError, match="declares its length unit as mm"):
        load_mesh(mm, units="in")


def test_visual_collada_and_collision_stl_of_the_same_link_agree():
    # the UR5 wrist 3 as drawn (COLLADA, two pieces, closed after tolerance welding) and as collided (STL)
    visual, collision = it.mass_properties(DAE), it.mass_properties(STL)
    assert visual.mesh.welded_tolerance > 0
    assert visual.volume == pytest.approx(collision.volume, rel=0.01)
    np.testing.assert_allclose(visual.center_of_mass, collision.center_of_mass, atol=1e-3)


def test_gltf_node_transform_and_scale(tmp_path):
    mesh = trimesh.load(STL)
    transform = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])
    transform[:3, :3] *= 2.0
    transform[:3, 3] = [0.1, 0.2, 0.3]
    scene = trimesh.Scene()
    scene.add_geometry(mesh, transform=transform)
    glb = tmp_path / "wrist3.glb"
    scene.export(glb)
    ref = it.mass_properties(STL, density=1000)
    props = it.mass_properties(glb, density=1000)
    rotation = transform[:3, :3] / 2.0
    assert props.volume == pytest.approx(8 * ref.volume, rel=1e-6)           # float32 in the GLB
    np.testing.assert_allclose(props.center_of_mass, rotation @ (2 * ref.center_of_mass) + [0.1, 0.2, 0.3],
                               atol=1e-7)
    assert_tensor_close(props.inertia, 32 * rotation @ ref.inertia @ rotation.T, 1e-5)   # mass ×8, length² ×4


def _threemf(tmp_path, unit):
    box = trimesh.creation.box([10.0, 20.0, 30.0])
    path = tmp_path / f"box_{unit}.3mf"
    box.export(path)                                   # trimesh writes unit="millimeter"
    with zipfile.ZipFile(path) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    model = members["3D/3dmodel.model"].decode()
    assert 'unit="millimeter"' in model
    if unit is None:
        model = model.replace(' unit="millimeter"', "")
    else:
        model = model.replace('unit="millimeter"', f'unit="{unit}"')
    members["3D/3dmodel.model"] = model.encode()
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    return path


@pytest.mark.parametrize("unit, metres", [("millimeter", 1e-3), (None, 1e-3), ("inch", 0.0254), ("meter", 1.0),
                                          ("micron", 1e-6)])
def test_3mf_unit_attribute_is_honoured(tmp_path, unit, metres):
    # 3MF: <model unit="..."> with millimetre the default of the specification
    props = it.mass_properties(_threemf(tmp_path, unit), density=1000)
    assert props.volume == pytest.approx(6000 * metres ** 3, rel=1e-12)
    assert props.mass == pytest.approx(1000 * 6000 * metres ** 3, rel=1e-12)


def test_3mf_contradicting_units_refused_agreeing_accepted(tmp_path):
    path = _threemf(tmp_path, "millimeter")
    assert it.mass_properties(path, units="mm").volume == pytest.approx(6e-6)
    with pytest.raises(UsageError, match="declares its length unit as mm"):
        it.mass_properties(path, units="cm")


def test_obj_real_file_and_groups_read_as_one_part(tmp_path):
    ankle = it.mass_properties(OBJ, density=1000)
    assert ankle.volume > 0 and not ankle.parts
    # two groups (g/o) in one OBJ: all groups are one part, each closed group a body
    a, b = shapes.box(1, 1, 1), shapes.box(1, 1, 1, center=(3, 0, 0))
    lines = ["o first", "g first"] + [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in a.vertices]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in a.faces]
    lines += ["o second", "g second"] + [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in b.vertices]
    lines += [f"f {i + 9} {j + 9} {k + 9}" for i, j, k in b.faces]
    obj = tmp_path / "two.obj"
    obj.write_text("\n".join(lines) + "\n")
    props = it.mass_properties(obj)
    assert props.volume == pytest.approx(2.0) and len(props.parts) == 2
    np.testing.assert_allclose(props.center_of_mass, [1.5, 0, 0], atol=1e-15)


@pytest.mark.parametrize("kind", ["gz", "bz2", "zip"])
def test_compressed_single_mesh_files(tmp_path, kind):
    data = STL.read_bytes()
    if kind == "zip":
        path = tmp_path / "wrist3.zip"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr("meshes/wrist3.stl", data)
    else:
        path = tmp_path / f"wrist3.stl.{kind}"
        path.write_bytes(gzip.compress(data) if kind == "gz" else bz2.compress(data))
    ref = it.mass_properties(STL, density=1000)
    props = it.mass_properties(path, density=1000)
    assert props.mass == ref.mass and props.name == str(path)
    assert_tensor_close(props.inertia, ref.inertia, 1e-15)


def test_compressed_bombs_and_ambiguous_archives_are_refused(tmp_path):
    bomb = tmp_path / "bomb.stl.gz"
    bomb.write_bytes(gzip.compress(b"\0" * (200 << 20)))          # 200 MiB of zeros, ~200 KB compressed
    with pytest.raises(MeshReadError, match="decompression bomb"):
        load_mesh(bomb)
    zbomb = tmp_path / "bomb.zip"
    with zipfile.ZipFile(zbomb, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("a.stl", b"\0" * (50 << 20))
    with pytest.raises(MeshReadError, match="decompression bomb before inflating"):
        load_mesh(zbomb)
    two = tmp_path / "two.zip"
    with zipfile.ZipFile(two, "w") as zf:
        zf.writestr("a.stl", STL.read_bytes())
        zf.writestr("b.stl", STL.read_bytes())
    with pytest.raises(MeshReadError, match="exactly one mesh"):
        load_mesh(two)
    nested = tmp_path / "w.stl.gz.gz"
    nested.write_bytes(gzip.compress(gzip.compress(STL.read_bytes())))
    with pytest.raises(MeshReadError, match="not a mesh with a known suffix"):
        load_mesh(nested)
    corrupt = tmp_path / "c.stl.gz"
    corrupt.write_bytes(b"\x1f\x8b\x08\x00garbage")
    with pytest.raises(MeshReadError, match="cannot be decompressed"):
        load_mesh(corrupt)


def test_error_inside_an_archive_names_the_archive_and_member(tmp_path):
    path = tmp_path / "t.stl.gz"
    path.write_bytes(gzip.compress(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nendloop\nendfacet\n"))
    with pytest.raises(MeshReadError) as exc:
        load_mesh(path)
    assert str(exc.value).startswith(f"{path}:t.stl")


def test_zipped_collada_zae(tmp_path):
    # .zae: a zip holding the .dae and a manifest naming it (COLLADA 1.5)
    zae = tmp_path / "wrist3.zae"
    with zipfile.ZipFile(zae, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.write(DAE, "wrist3.dae")
        zf.writestr("manifest.xml", "<?xml version='1.0'?><dae_root>./wrist3.dae</dae_root>")
    zipped, plain = load_mesh(zae), load_mesh(DAE)
    assert zipped.units == "m" and len(zipped.faces) == len(plain.faces)
    np.testing.assert_array_equal(np.sort(zipped.vertices, axis=0), np.sort(plain.vertices, axis=0))


def test_glb_textures_are_not_decoded(tmp_path, monkeypatch):
    """A textured GLB is read for its geometry only: its images are never decoded (they took most of the time
    of a textured asset), and the mass properties equal those of the untextured mesh."""
    from PIL import Image

    m = trimesh.creation.icosphere(subdivisions=3, radius=0.05)
    uv = np.c_[0.5 + 0.5 * m.vertices[:, 0] / 0.05, 0.5 + 0.5 * m.vertices[:, 1] / 0.05]
    m.visual = trimesh.visual.TextureVisuals(uv=uv, image=Image.new("RGB", (256, 256), (200, 30, 30)))
    glb = tmp_path / "textured.glb"
    m.export(glb)
    assert b"image/png" in glb.read_bytes()      # the texture is in the file

    opened = []
    real_open = Image.open

    def spy(*args, **kwargs):        # trimesh catches a reader's errors, so the calls are counted instead
        opened.append(args)
        return real_open(*args, **kwargs)
    monkeypatch.setattr(Image, "open", spy)
    props = it.mass_properties(glb, density=1000, units="m")
    assert opened == []
    ref = it.mass_properties((np.asarray(m.vertices), np.asarray(m.faces)), density=1000, units="m")
    assert props.mass == pytest.approx(ref.mass, rel=1e-6)       # float32 in the GLB
    np.testing.assert_allclose(props.inertia, ref.inertia, rtol=1e-5, atol=1e-12)


@pytest.mark.parametrize("fail", [False, True])
def test_decompressed_temporary_directory_is_removed_once_after_use(tmp_path, fail):
    # the review found a second rmtree inside the TemporaryDirectory: one cleanup, after success and failure
    from inertia_tool.mesh.decompress import decompressed
    path = tmp_path / "t.stl.gz"
    path.write_bytes(gzip.compress(b"solid t\nendsolid t\n"))
    seen = []
    with pytest.raises(RuntimeError) if fail else contextlib.nullcontext():
        with decompressed(str(path), max_bytes=1 << 20, max_ratio=100, min_ratio_bytes=1 << 20,
                          suffixes=(".stl",)) as (inner, member):
            seen.append(inner)
            assert member == "t.stl" and os.path.isfile(inner)
            if fail:
                raise RuntimeError("the caller failed")
    assert seen and not os.path.exists(os.path.dirname(seen[0]))


@pytest.mark.parametrize("n_faces", [1, 80, 81, 200])
def test_small_binary_stl_read_once_equals_chunked_read(tmp_path, n_faces):
    """A binary STL that fits in the first read (at most 80 triangles: 84 + 50·80 ≤ 4096 bytes) is welded from
    those bytes instead of being opened again: the vertices and faces are the ones the chunked file read gives,
    and a trailing byte after the triangles changes nothing."""
    from inertia_tool.mesh.read import load_mesh
    from inertia_tool.mesh.read_stl import _binary_stl_chunks
    from inertia_tool.mesh.weld import weld_exact_stream

    rng = np.random.default_rng(n_faces)
    tri = rng.integers(-4, 5, size=(n_faces, 3, 3)).astype(np.float32) / 4    # shared corners, exact in float32
    rec = np.zeros(n_faces, dtype=[("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["v"] = tri
    for extra in (b"", b"\x00"):
        path = tmp_path / f"t{len(extra)}.stl"
        path.write_bytes(b"\x00" * 80 + np.uint32(n_faces).tobytes() + rec.tobytes() + extra)
        chunked = weld_exact_stream(_binary_stl_chunks(str(path), n_faces, padded=False), 3 * n_faces)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            raw = load_mesh(str(path), units="m")
        np.testing.assert_array_equal(raw.faces, chunked[1])
        np.testing.assert_array_equal(raw.vertices, chunked[0])
        np.testing.assert_array_equal(raw.vertices[raw.faces], tri.astype(np.float64))
