import os

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import box_arrays, write_ascii_stl, write_binary_stl
from inertia_tool.errors import MeshReadError, TrailingDataWarning, UsageError
from inertia_tool.mesh.read import load_mesh


# every test runs on the C extension (when built) and on the pure-numpy path
pytestmark = pytest.mark.usefixtures("engine_path")


def _same_triangles(raw, vertices, faces, scale=1.0):
    got = np.sort(np.sort(raw.vertices[raw.faces].reshape(-1, 9), axis=1), axis=0)
    want = np.sort(np.sort(np.asarray(vertices, dtype=np.float32).astype(float)[faces].reshape(-1, 9) * scale,
                           axis=1), axis=0)
    np.testing.assert_allclose(got, want, rtol=1e-15, atol=0)


def test_binary_stl_matches_source_and_welds(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f)
    raw = load_mesh(p)
    assert len(raw.vertices) == 8 and len(raw.faces) == 12 and raw.file_faces == 12
    _same_triangles(raw, v, f)


def test_binary_stl_with_solid_header_is_read_as_binary(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f, header=b"solid exported by a CAD tool")
    raw = load_mesh(p)
    assert len(raw.faces) == 12


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_ascii_stl_any_line_ending(tmp_path, newline):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_ascii_stl(p, v, f, newline=newline)
    raw = load_mesh(p)
    assert len(raw.faces) == 12 and len(raw.vertices) == 8


def test_units_scale_coordinates(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f)
    raw = load_mesh(p, units="mm")
    _same_triangles(raw, v, f, scale=1e-3)


def test_trailing_bytes_are_accepted_with_a_warning(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f, extra=b"\x00" * 17)
    with pytest.warns(TrailingDataWarning, match="17 bytes"):
        raw = load_mesh(p)
    assert len(raw.faces) == 12


def test_header_claiming_too_many_triangles_is_refused_before_allocation(tmp_path):
    p = tmp_path / "liar.stl"
    with open(p, "wb") as fh:
        fh.write(b"\0" * 80 + np.uint32(10**9).tobytes() + b"\0" * 500)
    with pytest.raises(MeshReadError, match="announces 1,000,000,000 triangles"):
        load_mesh(p)


def test_truncated_binary_is_refused(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f)
    data = open(p, "rb").read()
    open(p, "wb").write(data[:-30])
    with pytest.raises(MeshReadError, match=str(p)):
        load_mesh(p)


@pytest.mark.parametrize("content, message", [(b"", "empty file"), (b"solid x\nendsolid x\n", "without any 'vertex'")])
def test_empty_inputs(tmp_path, content, message):
    p = tmp_path / "e.stl"
    p.write_bytes(content)
    with pytest.raises(MeshReadError, match=message):
        load_mesh(p)


def test_nan_coordinates_are_refused(tmp_path):
    v, f = box_arrays()
    v = v.copy()
    v[0, 0] = np.nan
    p = tmp_path / "nan.stl"
    write_ascii_stl(p, v, f)
    with pytest.raises(MeshReadError, match="NaN"):
        load_mesh(p)


def test_directory_and_missing_file(tmp_path):
    with pytest.raises(MeshReadError, match="directory"):
        load_mesh(tmp_path)
    with pytest.raises(MeshReadError, match="no such file"):
        load_mesh(tmp_path / "nope.stl")


def test_max_faces_guard(tmp_path):
    v, f = box_arrays()
    p = tmp_path / "box.stl"
    write_binary_stl(p, v, f)
    with pytest.raises(MeshReadError, match="`max_faces`"):
        load_mesh(p, max_faces=5)


def test_obj_through_trimesh(tmp_path):
    m = trimesh.creation.box([1, 2, 3])
    p = tmp_path / "box.obj"
    m.export(p)
    raw = load_mesh(p, units="cm")
    assert len(raw.faces) == 12
    np.testing.assert_allclose(raw.vertices.max(axis=0), [0.005, 0.01, 0.015])


def test_arrays_and_trimesh_objects(box_mesh):
    raw = load_mesh(box_mesh)
    assert len(raw.faces) == 12
    raw = load_mesh((box_mesh.vertices, box_mesh.faces), units="mm")
    np.testing.assert_allclose(raw.vertices, box_mesh.vertices * 1e-3)
    with pytest.raises(UsageError, match="shape"):
        load_mesh((np.zeros((3, 2)), np.zeros((1, 3), dtype=int)))
    with pytest.raises(UsageError, match="face indices"):
        load_mesh((np.zeros((3, 3)), np.array([[0, 1, 5]])))


def test_unknown_suffix(tmp_path):
    p = tmp_path / "mesh.xyz"
    p.write_text("1 2 3\n")
    with pytest.raises(MeshReadError, match="unsupported file type"):
        load_mesh(p)


def test_png_renamed_stl_is_refused(tmp_path):
    p = tmp_path / "picture.stl"
    p.write_bytes(b"\x89PNG\r\n\x1a\n" + os.urandom(300))
    with pytest.raises(MeshReadError):
        load_mesh(p)


def test_binary_stl_negative_zero_corner_welds_with_positive_zero(tmp_path):
    v, f = box_arrays((2.0, 2.0, 2.0), center=(1.0, 1.0, 1.0))   # corners on the coordinate planes
    tri = v[f].astype(np.float32)
    tri[tri == 0] = np.float32(-0.0) * (np.arange(tri.size).reshape(tri.shape)[tri == 0] % 2)  # mix -0.0 and 0.0
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    p = tmp_path / "signed_zero.stl"
    p.write_bytes(b" " * 80 + np.uint32(len(tri)).tobytes() + rec.tobytes())
    assert np.signbit(tri).any()
    raw = load_mesh(p)
    assert len(raw.vertices) == 8


def test_3mf_through_trimesh(tmp_path):
    m = trimesh.creation.box([10.0, 20.0, 30.0])
    p = tmp_path / "box.3mf"
    m.export(p)
    raw = load_mesh(p, units="mm")
    assert len(raw.faces) == 12
    np.testing.assert_allclose(np.ptp(raw.vertices, axis=0), [0.01, 0.02, 0.03], rtol=1e-12)


@pytest.mark.skipif(not hasattr(os, "symlink"), reason="needs symbolic links")
def test_symlink_loop_broken_link_and_not_a_directory_say_why(tmp_path):
    """Before: a symbolic link loop was reported as "no such file"."""
    loop = tmp_path / "loop.stl"
    os.symlink(loop, loop)
    with pytest.raises(MeshReadError, match=r"loop\.stl: symbolic link loop"):
        load_mesh(loop)
    broken = tmp_path / "broken.stl"
    os.symlink(tmp_path / "missing.stl", broken)
    with pytest.raises(MeshReadError, match=r"broken\.stl: broken symbolic link"):
        load_mesh(broken)
    with pytest.raises(MeshReadError, match=r"missing\.stl: no such file"):
        load_mesh(tmp_path / "missing.stl")
    (tmp_path / "plain").write_text("x")
    with pytest.raises(MeshReadError, match="a component of the path is not a directory"):
        load_mesh(tmp_path / "plain" / "a.stl")


@pytest.mark.skipif(not hasattr(os, "symlink"), reason="needs symbolic links")
def test_batch_reports_a_symlink_loop_as_a_file_error_not_an_internal_one(tmp_path):
    from inertia_tool.batch.runner import BatchOptions, analyze_file
    loop = tmp_path / "loop.stl"
    os.symlink(loop, loop)
    row = analyze_file(str(loop), BatchOptions())
    assert row["status"] == "error" and "symbolic link loop" in row["error"]


def _3mf_with_junk(path, members, member_bytes=1 << 20, model_name="3D/3dmodel.model"):
    """A valid box 3MF plus ``members`` unreferenced members of ``member_bytes`` zeros each (deflated once)."""
    import io as _io
    import zipfile
    import zlib

    from corpus.make_corpus import _zeros_bomb, _zip
    box = trimesh.creation.box([10.0, 20.0, 30.0])
    parts = []
    with zipfile.ZipFile(_io.BytesIO(trimesh.exchange.threemf.export_3MF(box))) as zf:
        for info in zf.infolist():
            data = zf.read(info)
            name = model_name if info.filename == "3D/3dmodel.model" else info.filename
            c = zlib.compressobj(9, zlib.DEFLATED, -15)
            parts.append((name, c.compress(data) + c.flush(), len(data), zlib.crc32(data)))
    deflated, crc, size = _zeros_bomb(member_bytes)
    parts += [(f"Metadata/junk{k:05d}.bin", deflated, size, crc) for k in range(members)]
    _zip(path, parts)


def test_3mf_members_the_model_does_not_reference_are_never_inflated(tmp_path):
    """Before: trimesh inflated every member (5,000 small compressible members: 68 s, 5.2 GB); the ratio check
    only looked at members over 1 MiB.  Now only the model parts are read: peak Python memory stays far
    below the junk's inflated size."""
    import tracemalloc
    p = tmp_path / "junk.3mf"
    _3mf_with_junk(p, 400)                                         # 400 MiB of zeros in ~0.4 MB of zip
    assert p.stat().st_size < 2 << 20
    tracemalloc.start()
    try:
        raw = load_mesh(p, units="mm")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(raw.faces) == 12
    np.testing.assert_allclose(np.ptp(raw.vertices, axis=0), [0.01, 0.02, 0.03], rtol=1e-12)
    assert peak < 32 << 20, f"peak {peak:,} bytes"


def test_3mf_model_parts_are_bounded_by_the_face_limit(tmp_path):
    from inertia_tool.mesh.read import zip_inflate_limit
    p = tmp_path / "models.3mf"
    _3mf_with_junk(p, 0)
    import zipfile
    with zipfile.ZipFile(p, "a") as zf:                             # a second model part of 16 MiB
        zf.writestr("3D/Objects/part.model", os.urandom(8 << 20).hex(), compress_type=zipfile.ZIP_DEFLATED)
    with pytest.raises(MeshReadError, match=r"model parts would inflate to [\d,]+ bytes, more than the "
                                            r"[\d,]+ allowed for `max_faces` \(1\)"):
        load_mesh(p, max_faces=1)
    assert zip_inflate_limit(1000) == 256 * 1000 + (16 << 20)
    assert len(load_mesh(p, max_faces=1_000_000).faces) == 12


def test_3mf_without_a_model_part_is_refused(tmp_path):
    import zipfile
    p = tmp_path / "empty.3mf"
    with zipfile.ZipFile(p, "w") as zf:
        zf.writestr("Metadata/thumbnail.png", b"png")
    with pytest.raises(MeshReadError, match="without a 3D/3dmodel.model part"):
        load_mesh(p)


def test_units_never_scale_the_callers_arrays(box_mesh, tmp_path):
    """A file's vertices are scaled in place (no second copy of a large mesh); arrays a caller passed are not."""
    v = np.array(box_mesh.vertices, dtype=np.float64)
    before = v.copy()
    raw = load_mesh((v, np.asarray(box_mesh.faces)), units="mm")
    np.testing.assert_array_equal(v, before)
    np.testing.assert_allclose(raw.vertices, before * 1e-3, rtol=0, atol=0)


def _cube_with_raised_corner(height: float, order: int) -> str:
    """OBJ of the unit cube whose top corner (1, 1, 1) is raised by ``height``: the top quad is not planar.
    ``order`` rotates the top quad's corner list, so that its first corner is any of the four."""
    vertices = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1 + height), (0, 1, 1)]
    top = [5, 6, 7, 8][order:] + [5, 6, 7, 8][:order]
    quads = [[1, 4, 3, 2], top, [1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7], [4, 1, 5, 8]]
    return "".join(f"v {x} {y} {z}\n" for x, y, z in vertices) + "".join(
        "f " + " ".join(map(str, q)) + "\n" for q in quads)


@pytest.mark.parametrize("order", range(4))
def test_a_non_planar_quad_is_split_along_its_shorter_diagonal(tmp_path, order):
    # top corners a=(0,0,1) b=(1,0,1) c=(1,1,1+h) d=(0,1,1): |bd| = √2 < |ac| = √(2 + h²), so the top is
    # abd (flat) and bcd (a tetrahedron of volume h/6 above the cube); the other split, abc and acd, would
    # add h/3 (MuJoCo's OBJ loader splits along the shorter diagonal too: Menagerie's trossen_wxai meshes)
    from inertia_tool import mass_properties
    height = 0.5
    path = tmp_path / "raised.obj"
    path.write_text(_cube_with_raised_corner(height, order))
    raw = load_mesh(str(path), units="m")
    assert len(raw.faces) == 12
    assert mass_properties(raw, density=1.0).volume == pytest.approx(1 + height / 6, rel=1e-14)
    assert not any(4 in f and 6 in f for f in raw.faces.tolist())    # no triangle holds the long diagonal a–c


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(height=st.floats(1e-6, 3.0), order=st.integers(0, 3))
def test_non_planar_quads_are_named_with_what_the_other_split_could_change(tmp_path, height, order):
    """The warning's fraction bounds the volume the first-corner split (trimesh's) gives instead."""
    import re

    import trimesh

    from inertia_tool.errors import NonPlanarPolygonWarning
    path = tmp_path / "raised.obj"
    path.write_text(_cube_with_raised_corner(height, order))
    with pytest.warns(NonPlanarPolygonWarning, match="1 of 6 quadrilaterals are not planar") as caught:
        raw = load_mesh(str(path), units="m")
    stated = float(re.search(r"up to ([0-9.e+-]+) %", str(caught[0].message)).group(1)) / 100
    ours = abs(float(np.linalg.det(raw.vertices[raw.faces]).sum()) / 6)
    other = trimesh.load(str(path), process=False).volume
    tetra = height / 6                                                 # the tetrahedron of the top quad's corners
    assert tetra / ours <= stated <= 1.1 * tetra / ours              # two digits, rounded up: still a bound
    assert abs(other - ours) / ours <= stated
    if order in (0, 2):     # trimesh splits from corner a or c: along ac, the longer diagonal, so not ours
        assert abs(other - ours) == pytest.approx(tetra, rel=1e-6)


def test_planar_quads_split_without_a_word(tmp_path):
    import warnings as _warnings
    path = tmp_path / "cube.obj"
    path.write_text(_cube_with_raised_corner(0.0, 1))
    with _warnings.catch_warnings():
        _warnings.simplefilter("error")
        load_mesh(str(path), units="m")
