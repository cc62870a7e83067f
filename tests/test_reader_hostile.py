"""Readers against hostile files: no silent wrong number, no internal error, no unbounded allocation.

Regression tests of issue 22 ("Untrusted files ..."): non-finite coordinates (pycollada turned NaN into 0),
float32 storage far from the origin (a box 1e6 m out came back 30 % heavy without a word), numbers that only
Python's ``float()`` accepts in robot files, and the reader inputs that ended in an internal error.
"""

import io
import json
import math
import struct
import warnings
import zipfile
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import MeshReadError, RobotDescriptionError, StoragePrecisionWarning
from inertia_tool.mesh.precision import float32_rounding, volume_rounding_bound
from inertia_tool.mesh.read import load_mesh
from inertia_tool.robot.description import parse_decimal, read_robot

from conftest import box_arrays, write_binary_stl


def run_cli(*argv):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


# -- non-finite coordinates ------------------------------------------------------------------------------------

def _box_dae(tmp_path, replace=None):
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("collada")
    text = trimesh.exchange.dae.export_collada(trimesh.creation.box(extents=(1.0, 2.0, 4.0))).decode()
    if replace is not None:
        start = text.index(">", text.index("<float_array")) + 1
        first = text[start:].split()[0]
        text = text[:start] + replace + text[start + len(first):]
    path = tmp_path / "box.dae"
    path.write_text(text)
    return path


def test_collada_box_reads_exactly(tmp_path):
    props = mass_properties(_box_dae(tmp_path), density=1000.0)
    assert props.mass == pytest.approx(8000.0, rel=1e-12)


@pytest.mark.parametrize("token", ["nan", "NaN", "-nan", "inf", "-Infinity", "1e999", "0x1p3", "&#110;an"])
def test_collada_non_finite_coordinate_is_refused_not_zeroed(tmp_path, token):
    # pycollada sets NaN to 0: the box would come out at 7,333 kg instead of 8,000 with exit 0
    path = _box_dae(tmp_path, token)
    with pytest.raises(MeshReadError, match="box.dae"):
        load_mesh(path)
    code, out, err = run_cli("analyze", path, "--density", "1000")
    assert code == 3 and out == "" and "Traceback" not in err


@pytest.mark.parametrize("suffix", ["glb", "ply", "3mf", "off", "obj", "stl"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_vertex_is_refused_in_every_format(tmp_path, suffix, bad):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box()
    vertices = box.vertices.copy()
    vertices[3, 1] = bad
    path = tmp_path / f"bad.{suffix}"
    trimesh.Trimesh(vertices, box.faces, process=False).export(path)
    with pytest.raises(MeshReadError, match="NaN or infinite"):
        load_mesh(path)


def test_collada_instances_count_against_the_face_limit(tmp_path):
    from inertia_tool.mesh.read import GLTF_INSTANCE_FACES
    path = _box_dae(tmp_path)
    text = path.read_text()
    node = text[text.index("<node"):text.index("</node>") + len("</node>")]
    path.write_text(text.replace(node, node * 50))
    assert len(load_mesh(path, max_faces=50 * (GLTF_INSTANCE_FACES + 12)).faces) == 50 * 12
    trimesh = pytest.importorskip("trimesh")
    load = trimesh.load
    trimesh.load = lambda *a, **k: pytest.fail("parsed before the refusal")
    try:
        with pytest.raises(MeshReadError, match="50 geometry and node instances"):
            load_mesh(path, max_faces=50 * GLTF_INSTANCE_FACES - 1)
    finally:
        trimesh.load = load


def test_collada_nan_hidden_in_cdata_is_refused(tmp_path):
    path = _box_dae(tmp_path, "<![CDATA[nan]]>")
    with pytest.raises(MeshReadError, match="float_array"):
        load_mesh(path)


def test_zipped_collada_nan_is_refused(tmp_path):
    dae = _box_dae(tmp_path, "nan")
    zae = tmp_path / "box.zae"
    with zipfile.ZipFile(zae, "w") as zf:
        zf.write(dae, "box.dae")
    with pytest.raises(MeshReadError, match="float_array"):
        load_mesh(zae)


def test_step_tessellation_without_bounding_box_is_a_clear_error(tmp_path):
    pytest.importorskip("OCP")
    from OCP.BRep import BRep_Builder
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound
    compound = TopoDS_Compound()
    BRep_Builder().MakeCompound(compound)
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    path = tmp_path / "empty.step"
    writer.Write(str(path))
    code, out, err = run_cli("analyze", path)
    assert code == 3 and "bounding box" in err and "internal error" not in err


def _encrypted(path, inner_name, data):
    """A zip whose one member has the 'encrypted' flag set (zipfile cannot write encryption itself)."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr(inner_name, data)
    raw = bytearray(path.read_bytes())
    for magic, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        at = raw.find(magic)
        flags = struct.unpack_from("<H", raw, at + offset)[0]
        struct.pack_into("<H", raw, at + offset, flags | 1)
    path.write_bytes(bytes(raw))


@pytest.mark.parametrize("name,inner", [("part.zip", "part.stl"), ("part.3mf", "3D/3dmodel.model"),
                                        ("part.zae", "part.dae")])
def test_encrypted_zip_member_is_refused(tmp_path, name, inner):
    path = tmp_path / name
    _encrypted(path, inner, b"solid x\nendsolid x\n")
    with pytest.raises(MeshReadError, match="encrypted"):
        load_mesh(path)
    code, _, err = run_cli("analyze", path)
    assert code == 3 and "encrypted" in err and "internal error" not in err


# -- float32 storage far from the origin ------------------------------------------------------------------------

def _float32_box(path, center, side):
    v, f = box_arrays((side, side, side), center)
    write_binary_stl(path, v, f)
    return v


def test_far_float32_box_warns_with_a_bound_that_holds(tmp_path):
    # the case: a box a million metres out; its float32 corners are not the drawn ones
    side = 0.3
    path = tmp_path / "far.stl"
    _float32_box(path, (1e6 + 0.01, 1e6 - 0.02, 1e6 + 0.03), side)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = mass_properties(path, density=1.0)
    actual = abs(props.volume - side ** 3)
    assert actual / side ** 3 > 0.1                     # the file itself lost that much
    messages = [str(w.message) for w in caught if issubclass(w.category, StoragePrecisionWarning)]
    assert len(messages) == 1 and "float32" in messages[0]
    raw = load_mesh(path)
    assert raw.storage_rounding == float32_rounding(1e6 + 0.03 + side / 2) == 2.0 ** -5
    assert volume_rounding_bound(raw.vertices, raw.faces, raw.storage_rounding) >= actual
    code, _, err = run_cli("analyze", path)
    assert code == 0 and "float32" in err


def test_float32_part_near_the_origin_does_not_warn(tmp_path):
    path = tmp_path / "near.stl"
    _float32_box(path, (0.01, 0.02, -0.03), 0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", StoragePrecisionWarning)
        props = mass_properties(path, density=1.0)
    assert props.volume == pytest.approx(1e-3, rel=1e-6)


def test_ascii_stl_and_arrays_have_no_storage_rounding(tmp_path):
    from conftest import write_ascii_stl
    v, f = box_arrays((0.3, 0.3, 0.3), (1e6, 1e6, 1e6))
    write_ascii_stl(tmp_path / "far.stl", v, f)
    assert load_mesh(tmp_path / "far.stl").storage_rounding == 0.0
    assert load_mesh((v, f)).storage_rounding == 0.0


@settings(max_examples=60, deadline=None)
@given(offset=st.floats(-1e7, 1e7), side=st.floats(1e-3, 10.0), shift=st.floats(0.0, 1.0),
       exponent=st.integers(-2, 2))
def test_storage_rounding_bound_contains_the_error_of_rounded_boxes(offset, side, shift, exponent):
    # the drawn box (float64) against the same box rounded to float32, as an exporter writes it
    scale = 10.0 ** exponent
    v, f = box_arrays((side, side * (1 + shift), side * (2 - shift)), (offset, -0.5 * offset, offset * shift))
    v, side = v * scale, side * scale
    drawn = side ** 3 * (1 + shift) * (2 - shift)
    stored = v.astype(np.float32).astype(np.float64)
    delta = float32_rounding(float(np.max(np.abs(stored))))
    assert np.max(np.abs(stored - v)) <= delta
    signed = np.einsum("ij,ij->i", stored[f[:, 0]], np.cross(stored[f[:, 1]], stored[f[:, 2]])).sum() / 6.0
    assert abs(signed - drawn) <= volume_rounding_bound(stored, f, delta)


def test_float32_rounding_is_half_the_spacing():
    assert float32_rounding(1.0) == 2.0 ** -24
    assert float32_rounding(1e6) == 2.0 ** -5             # 2^19 ≤ 1e6 < 2^20: spacing 2^-4
    assert float32_rounding(0.0) > 0


def test_far_ply_float_glb_and_collada_warn(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.creation.box(extents=(0.3, 0.3, 0.3))
    mesh.apply_translation((1e6 + 0.01, 1e6, 1e6))
    for name in ("far.ply", "far.glb", "far.dae"):
        mesh.export(tmp_path / name)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mass_properties(tmp_path / name, density=1.0)
        assert any(issubclass(w.category, StoragePrecisionWarning) for w in caught), name


# -- robot numbers --------------------------------------------------------------------------------------------

_URDF = '<robot name="r"><link name="a"><collision><geometry><box size="{} 1 1"/></geometry></collision></link></robot>'


@pytest.mark.parametrize("token", ["1", "2.5", "+.5", "5.", "-0.0e0", "1e-3", "1E+2", "007"])
def test_decimal_grammar_accepts_xml_schema_decimals(token):
    assert parse_decimal(token) == float(token)


@pytest.mark.parametrize("token", ["1_000", "١٢", "１", "inf", "INF", "nan", "NaN", "Infinity", "0x10", "1e", ".",
                                   "+-1", "1.0f", "", "1 2", "٣.٥", "1e1_0"])
def test_decimal_grammar_refuses_what_only_python_float_accepts(token):
    with pytest.raises(ValueError):
        parse_decimal(token)


@pytest.mark.parametrize("size", ["1_000", "١", "inf", "nan"])
def test_urdf_number_python_accepts_is_refused(tmp_path, size):
    path = tmp_path / "r.urdf"
    path.write_text(_URDF.format(size), encoding="utf-8")
    with pytest.raises(RobotDescriptionError, match="box size"):
        read_robot(path)
    code, out, err = run_cli("robot", path, "--material", "steel")
    assert code == 3 and out == "" and "Traceback" not in err


@pytest.mark.parametrize("shape", ['<sphere radius="1e300"/>', '<cylinder radius="1e-300" length="1"/>',
                                   '<box size="1e-200 1e-200 1e-200"/>', '<cylinder radius="1" length="1e300"/>',
                                   '<mesh filename="x.stl" scale="1e-300 1 1"/>'])
def test_urdf_sizes_outside_float64_range_are_refused(tmp_path, shape):
    (tmp_path / "x.stl").write_bytes(b"")
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r"><link name="a"><collision><origin xyz="0 0 0"/><geometry>{shape}</geometry>'
                    "</collision></link></robot>")
    code, out, err = run_cli("robot", path, "--material", "steel")
    assert code == 3 and "internal error" not in err and "between" in err, err


def test_urdf_origin_far_beyond_any_robot_is_refused(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text('<robot name="r"><link name="a"><collision><origin xyz="1e300 0 0"/><geometry>'
                    '<sphere radius="1"/></geometry></collision></link></robot>')
    with pytest.raises(RobotDescriptionError, match="origin xyz"):
        read_robot(path)


def _mjcf(tmp_path, compiler, geom='type="box" size="0.1 0.2 0.3" euler="10 20 30"'):
    path = tmp_path / "m.xml"
    path.write_text(f'<mujoco><compiler {compiler}/><worldbody><body name="b"><geom {geom}/></body></worldbody>'
                    "</mujoco>")
    return path


@pytest.mark.parametrize("seq", ["qqq", "xy", "xyzx", "x1z", ""])
def test_mjcf_bad_eulerseq_is_refused(tmp_path, seq):
    path = _mjcf(tmp_path, f'eulerseq="{seq}"')
    with pytest.raises(RobotDescriptionError, match="eulerseq"):
        read_robot(path)
    code, _, err = run_cli("robot", path, "--material", "steel")
    assert code == 3 and "internal error" not in err


@pytest.mark.parametrize("seq", ["xyz", "XYZ", "zyx", "xYz", "ZyX", "xyx", "zXz"])
def test_mjcf_euler_sequences_match_mujoco(tmp_path, seq):
    mujoco = pytest.importorskip("mujoco")
    path = _mjcf(tmp_path, f'eulerseq="{seq}"')
    robot = read_robot(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, model.geom_quat[0])
    np.testing.assert_allclose(robot.links[0].elements[0].rotation, matrix.reshape(3, 3), atol=1e-12)


def test_mjcf_non_integer_contype_is_refused(tmp_path):
    path = _mjcf(tmp_path, 'angle="radian"', 'type="sphere" size="1" contype="1.5"')
    with pytest.raises(RobotDescriptionError, match="contype"):
        read_robot(path)


def test_mjcf_size_with_python_only_number_is_refused(tmp_path):
    path = _mjcf(tmp_path, 'angle="radian"', 'type="sphere" size="1_0"')
    with pytest.raises(RobotDescriptionError, match="size"):
        read_robot(path)


def test_sdf_number_python_accepts_is_refused(tmp_path):
    path = tmp_path / "r.sdf"
    path.write_text('<sdf version="1.7"><model name="m"><link name="a"><collision name="c"><geometry><sphere>'
                    "<radius>1_0</radius></sphere></geometry></collision></link></model></sdf>")
    with pytest.raises(RobotDescriptionError, match="radius"):
        read_robot(path)
    assert math.isfinite(parse_decimal("1e308"))


# -- the streaming 3MF reader -----------------------------------------------------------------------------------

_NS = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
_BOX_MESH = ("<mesh><vertices>" + "".join(f'<vertex x="{x}" y="{y}" z="{z}"/>' for x in (0, 1) for y in (0, 2)
                                          for z in (0, 3)) + "</vertices><triangles>"
             + "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in
                       ((0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                        (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3))) + "</triangles></mesh>")


def _write_3mf(path, resources, build, unit="millimeter", extra_parts=()):
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="{unit}" xmlns="{_NS}"><resources>{resources}'
             f"</resources><build>{build}</build></model>")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("[Content_Types].xml", "<Types/>")
        zf.writestr("3D/3dmodel.model", model)
        for name, data in extra_parts:
            zf.writestr(name, data)
    return path


def test_3mf_components_and_transforms_place_every_instance(tmp_path):
    # box 1 x 2 x 3 mm (6 mm³, outward); object 2 = the box three times: shifted, scaled by 2, mirrored in x
    resources = (f'<object id="1" type="model">{_BOX_MESH}</object><object id="2" type="model"><components>'
                 '<component objectid="1" transform="1 0 0 0 1 0 0 0 1 10 0 0"/>'
                 '<component objectid="1" transform="2 0 0 0 2 0 0 0 2 20 0 0"/>'
                 '<component objectid="1" transform="-1 0 0 0 1 0 0 0 1 -10 0 0"/></components></object>')
    path = _write_3mf(tmp_path / "parts.3mf", resources,
                      '<item objectid="2" transform="0 1 0 -1 0 0 0 0 1 0 0 100"/><item objectid="1"/>')
    props = mass_properties(path, density=1.0)
    assert props.volume == pytest.approx((6 + 48 + 6 + 6) * 1e-9, rel=1e-12)   # 3MF unit: millimetre
    raw = load_mesh(path)
    assert len(raw.faces) == 4 * 12
    assert raw.vertices[:, 2].max() == pytest.approx(0.106)                     # item shifted by 100 mm in z


def test_3mf_reader_agrees_with_trimesh_on_an_exported_scene(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    scene = trimesh.Scene()
    rotation = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])
    scene.add_geometry(trimesh.creation.box(extents=(10, 20, 30)), transform=rotation)
    scene.add_geometry(trimesh.creation.icosphere(subdivisions=2, radius=5),
                       transform=trimesh.transformations.translation_matrix([40, 0, 0]))
    path = tmp_path / "scene.3mf"
    scene.export(path)
    ours = load_mesh(path)
    theirs = trimesh.load(path, force="mesh")
    assert len(ours.faces) == len(theirs.faces)
    np.testing.assert_allclose(np.sort(ours.vertices, axis=0), np.sort(theirs.vertices * 1e-3, axis=0), atol=1e-12)
    assert mass_properties(path).volume == pytest.approx(theirs.volume * 1e-9, rel=1e-9)


def test_3mf_instance_bomb_is_refused_before_placing(tmp_path, no_parser):
    # 12 triangles, 10 copies per level, 6 levels: 12 million placed triangles from a few kB
    resources = f'<object id="1">{_BOX_MESH}</object>'
    for level in range(2, 8):
        copies = "".join(f'<component objectid="{level - 1}" transform="1 0 0 0 1 0 0 0 1 {k} 0 0"/>'
                         for k in range(10))
        resources += f'<object id="{level}"><components>{copies}</components></object>'
    path = _write_3mf(tmp_path / "bomb.3mf", resources, '<item objectid="7"/>')
    with pytest.raises(MeshReadError, match="places at least 1,0[0-9,]+ triangles"):
        load_mesh(path, max_faces=1_000_000)


def test_3mf_component_cycle_is_refused(tmp_path):
    resources = f'<object id="1">{_BOX_MESH}<components><component objectid="2"/></components></object>' \
                '<object id="2"><components><component objectid="1"/></components></object>'
    with pytest.raises(MeshReadError, match="nested deeper"):
        load_mesh(_write_3mf(tmp_path / "cycle.3mf", resources, '<item objectid="1"/>'))


def test_3mf_too_many_vertices_refused_while_streaming(tmp_path):
    many = "".join(f'<vertex x="{k}" y="0" z="0"/>' for k in range(100))
    resources = f'<object id="1"><mesh><vertices>{many}</vertices><triangles/></mesh></object>'
    with pytest.raises(MeshReadError, match="more vertices than"):
        load_mesh(_write_3mf(tmp_path / "v.3mf", resources, '<item objectid="1"/>'), max_faces=10)


@pytest.mark.parametrize("resources,build,match", [
    (f'<object id="1">{_BOX_MESH}</object>', '<item objectid="9"/>', "object '9'"),
    (f'<object id="1">{_BOX_MESH}</object>', '<item objectid="1" transform="1 0 0"/>', "twelve finite"),
    ('<object id="1"><mesh><vertices><vertex x="0" y="0" z="0"/></vertices><triangles>'
     '<triangle v1="0" v2="0" v3="5"/></triangles></mesh></object>', '<item objectid="1"/>', "triangle index"),
    ('<object id="1"><mesh><vertices><vertex x="nan" y="0" z="0"/><vertex x="1" y="0" z="0"/>'
     '<vertex x="0" y="1" z="0"/></vertices><triangles><triangle v1="0" v2="1" v3="2"/></triangles></mesh>'
     "</object>", '<item objectid="1"/>', "NaN"),
    (f'<object id="1">{_BOX_MESH}</object>', "", "no build item"),
    ('<object id="1"><components><component objectid="1" p:path="/3D/missing.model" '
     'xmlns:p="http://schemas.microsoft.com/3dmanufacturing/production/2015/06"/></components></object>',
     '<item objectid="1"/>', "missing.model"),
])
def test_3mf_malformed_models_are_refused(tmp_path, resources, build, match):
    with pytest.raises(MeshReadError, match=match):
        load_mesh(_write_3mf(tmp_path / "bad.3mf", resources, build))


def test_3mf_objects_in_other_model_parts_are_placed(tmp_path):
    production = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
    other = (f'<model unit="millimeter" xmlns="{_NS}"><resources><object id="5">{_BOX_MESH}</object></resources>'
             "<build/></model>")
    resources = (f'<object id="1"><components><component objectid="5" p:path="/3D/other.model" '
                 f'xmlns:p="{production}"/></components></object>')
    build = f'<item objectid="1"/><item objectid="5" p:path="/3D/other.model" xmlns:p="{production}" ' \
            'transform="1 0 0 0 1 0 0 0 1 50 0 0"/>'
    path = _write_3mf(tmp_path / "production.3mf", resources, build, extra_parts=[("3D/other.model", other)])
    assert mass_properties(path, density=1.0).volume == pytest.approx(12e-9, rel=1e-12)


def test_3mf_junk_model_parts_are_never_parsed(tmp_path):
    # the 5 MB 3MF of 3,000 junk .model parts took 6.3 GB: unreferenced parts are not read now
    junk = [(f"3D/junk{k}.model", "<model>" + "<x/>" * 1000 + "</model>") for k in range(300)]
    path = _write_3mf(tmp_path / "junk.3mf", f'<object id="1">{_BOX_MESH}</object>', '<item objectid="1"/>',
                      extra_parts=junk)
    assert len(load_mesh(path).faces) == 12


# -- memory: counts checked before anything is allocated -----------------------------------------------------

def _polygon_ply(path, corners, polygons):
    header = (b"ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              b"property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
              % (corners, polygons))
    angle = np.linspace(0, 2 * np.pi, corners, endpoint=False)
    vertices = np.c_[np.cos(angle), np.sin(angle), np.zeros(corners)].astype("<f4").tobytes()
    face = bytes([corners]) + np.arange(corners, dtype="<i4").tobytes()
    path.write_bytes(header + vertices + face * polygons)


@pytest.fixture
def no_parser(monkeypatch):
    """Make trimesh's loader fail the test if called: a refusal must come before any parser allocates."""
    trimesh = pytest.importorskip("trimesh")

    def refuse(*args, **kwargs):
        raise AssertionError("the parser ran: the file should have been refused from its counts")
    monkeypatch.setattr(trimesh, "load", refuse)


def test_ply_of_255_corner_polygons_is_bounded_by_the_face_limit(tmp_path, monkeypatch):
    # the 204 MB PLY of 255-corner faces took 4.6 GB: 200 faces are 50,600 triangles, counted exactly
    path = tmp_path / "polygons.ply"
    _polygon_ply(path, 255, 200)
    with monkeypatch.context() as patch:
        trimesh = pytest.importorskip("trimesh")
        patch.setattr(trimesh, "load", lambda *a, **k: pytest.fail("parsed before the refusal"))
        with pytest.raises(MeshReadError, match="up to 50,600 triangles"):
            load_mesh(path, max_faces=50_599)
    assert len(load_mesh(path, max_faces=50_600).faces) == 50_600


def test_ply_header_claiming_a_billion_faces_is_refused_from_the_header(tmp_path, no_parser):
    path = tmp_path / "lying.ply"
    path.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     b"property float z\nelement face 1000000000\nproperty list uchar int vertex_indices\n"
                     b"end_header\n" + bytes(36))
    with pytest.raises(MeshReadError, match="1,000,000,000"):
        load_mesh(path)


def _instanced_glb(path, instances):
    """A GLB of one 12-triangle box placed ``instances`` times (one node each): a few bytes per instance."""
    import json
    box_v = np.array(box_arrays((1.0, 1.0, 1.0))[0], dtype="<f4")
    box_f = np.array(box_arrays((1.0, 1.0, 1.0))[1], dtype="<u4")
    binary = box_v.tobytes() + box_f.tobytes()
    doc = {"asset": {"version": "2.0"}, "scene": 0,
           "scenes": [{"nodes": list(range(instances))}],
           "nodes": [{"mesh": 0, "translation": [2.0 * k, 0.0, 0.0]} for k in range(instances)],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "buffers": [{"byteLength": len(binary)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": box_v.nbytes},
                           {"buffer": 0, "byteOffset": box_v.nbytes, "byteLength": box_f.nbytes}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(box_v), "type": "VEC3",
                          "min": box_v.min(axis=0).tolist(), "max": box_v.max(axis=0).tolist()},
                         {"bufferView": 1, "componentType": 5125, "count": box_f.size, "type": "SCALAR"}]}
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


def test_glb_instances_count_against_the_face_limit(tmp_path):
    from inertia_tool.mesh.read import GLTF_INSTANCE_FACES
    path = tmp_path / "few.glb"
    _instanced_glb(path, 3)
    props = mass_properties(path, density=1.0)
    assert props.volume == pytest.approx(3.0, rel=1e-12)
    per_instance = 12 + GLTF_INSTANCE_FACES
    assert len(load_mesh(path, max_faces=3 * per_instance).faces) == 36
    with pytest.raises(MeshReadError, match="places at least"):
        load_mesh(path, max_faces=3 * per_instance - 1)


def test_glb_of_many_instances_is_refused_before_loading(tmp_path, no_parser):
    # the 10 MB GLB of 200k instances took 1.7 GB in trimesh; here 20,000 instances and a small limit
    path = tmp_path / "many.glb"
    _instanced_glb(path, 20_000)
    with pytest.raises(MeshReadError, match="places at least"):
        load_mesh(path, max_faces=100_000)


def test_gltf_node_cycle_is_refused(tmp_path, no_parser):
    import json
    path = tmp_path / "cycle.gltf"
    path.write_text(json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
                                "nodes": [{"children": [1]}, {"children": [0]}]}))
    with pytest.raises(MeshReadError, match="deeper than 64"):
        load_mesh(path)


def test_urdf_with_too_many_links_is_refused(tmp_path):
    from inertia_tool.robot.description import MAX_ROBOT_LINKS
    path = tmp_path / "many.urdf"
    path.write_text('<robot name="r">' + '<link name="l"/>' * (MAX_ROBOT_LINKS + 1) + "</robot>")
    with pytest.raises(RobotDescriptionError, match="10,001 links .*more than the 10,000 allowed"):
        read_robot(path)
    # at the limit, links of distinct names (two links of one name are refused on their own)
    path.write_text('<robot name="r">' + "".join(f'<link name="l{i}"/>' for i in range(MAX_ROBOT_LINKS))
                    + "</robot>")
    assert len(read_robot(path).links) == MAX_ROBOT_LINKS


def test_robot_max_faces_is_a_total_over_the_meshes(tmp_path):
    v, f = box_arrays((0.1, 0.1, 0.1))
    for name in ("a", "b"):
        write_binary_stl(tmp_path / f"{name}.stl", v, f)
    links = "".join(f'<link name="{n}"><collision><geometry><mesh filename="{n}.stl"/></geometry></collision>'
                    "</link>" for n in ("a", "b"))
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r">{links}</robot>')
    code, out, err = run_cli("robot", path, "--density", "1000", "--max-faces", "24", "--json")
    assert code == 0 and [link["mass"] for link in json.loads(out)["links"]] == pytest.approx([1.0, 1.0])
    code, out, err = run_cli("robot", path, "--density", "1000", "--max-faces", "20")
    assert code == 5 and "Traceback" not in err          # link b has no result: exit 5 (issue 23 item 2)
    assert "b.stl: holds 12 triangles, more than --max-faces (8) allows: the limit counts all the robot's " \
           "meshes together (20), and the meshes read before this one left 8" in out
    code, _, err = run_cli("robot", path, "--density", "1000", "--max-faces", "0")
    assert code == 2 and "--max-faces" in err


def test_3mf_nested_empty_objects_are_refused_by_instance_count(tmp_path):
    # each level holds two copies of the next and no triangle: 2^13 instances from a few hundred bytes
    resources = '<object id="1"><mesh><vertices><vertex x="0" y="0" z="0"/></vertices><triangles/></mesh></object>'
    for level in range(2, 14):
        twice = f'<component objectid="{level - 1}"/>' * 2
        resources += f'<object id="{level}"><components>{twice}</components></object>'
    resources += f'<object id="99">{_BOX_MESH}</object>'
    path = _write_3mf(tmp_path / "empty.3mf", resources, '<item objectid="13"/><item objectid="99"/>')
    with pytest.raises(MeshReadError, match=r"empty\.3mf.*places at least 2,001 object instances"):
        load_mesh(path, max_faces=2000)
    # within the limit the empty tree adds nothing and is not walked when placing
    mesh = load_mesh(path, max_faces=10_000)
    assert len(mesh.faces) == 12 and len(mesh.vertices) == 8


def test_3mf_vertices_placed_by_many_items_are_refused(tmp_path):
    # 4 vertices and no triangle, placed by 5,000 build items: 20,000 vertices past max_faces = 10
    four = "".join(f'<vertex x="{k}" y="0" z="0"/>' for k in range(4))
    resources = (f'<object id="1"><mesh><vertices>{four}</vertices><triangles/></mesh></object>'
                 f'<object id="2">{_BOX_MESH.replace("<triangle v1", "<x v1", 11)}</object>')
    build = '<item objectid="1"/>' * 5000 + '<item objectid="2"/>'
    with pytest.raises(MeshReadError, match=r"places at least 3[0-9,]+ vertices"):
        load_mesh(_write_3mf(tmp_path / "v.3mf", resources, build), max_faces=10)


@pytest.mark.parametrize("attribute", ['x="1_0"', 'x="\u0661\u0660"', 'x="1\u00a0"'])
def test_3mf_vertex_numbers_outside_the_grammar_are_refused(tmp_path, attribute):
    mesh = _BOX_MESH.replace('x="1"', attribute, 1)
    with pytest.raises(MeshReadError, match=r"bad\.3mf.*<vertex> without three numbers"):
        load_mesh(_write_3mf(tmp_path / "bad.3mf", f'<object id="1">{mesh}</object>', '<item objectid="1"/>'))


@pytest.mark.parametrize("text", ["1_0", "\u0661\u0660"])
def test_3mf_triangle_indices_and_transforms_outside_the_grammar_are_refused(tmp_path, text):
    mesh = _BOX_MESH.replace('v3="3"', f'v3="{text}"', 1)
    with pytest.raises(MeshReadError, match="<triangle> without three numbers"):
        load_mesh(_write_3mf(tmp_path / "t.3mf", f'<object id="1">{mesh}</object>', '<item objectid="1"/>'))
    build = f'<item objectid="1" transform="1 0 0 0 1 0 0 0 1 {text} 0 0"/>'
    with pytest.raises(MeshReadError, match="twelve finite"):
        load_mesh(_write_3mf(tmp_path / "m.3mf", f'<object id="1">{_BOX_MESH}</object>', build))


# -- numbers outside the one grammar (Python's float() reads 1_0 as 10) ---------------------------------------

_ODD_NUMBERS = ["1_0", "\u0661\u0660", "\uff11"]          # underscore, Arabic-Indic digits, a full-width digit


def _stl_text(x):
    return ("solid my_part\nfacet normal 0 0 1\nouter loop\n"
            f"vertex 0 0 0\nvertex {x} 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid my_part\n")


@pytest.mark.parametrize("text", _ODD_NUMBERS)
def test_ascii_stl_coordinate_outside_the_grammar_is_refused(tmp_path, text):
    path = tmp_path / "odd.stl"
    path.write_bytes(_stl_text(text).encode())
    with pytest.raises(MeshReadError, match=r"odd\.stl.*line 5: vertex coordinate is not a decimal number"):
        load_mesh(path)


def test_ascii_stl_names_with_underscores_still_read(tmp_path):
    path = tmp_path / "named_part.stl"
    path.write_bytes(_stl_text("1").encode())
    mesh = load_mesh(path, units="m")
    assert sorted(mesh.vertices[:, 0]) == [0.0, 0.0, 1.0]


def _obj_text(x, index="3"):
    return f"# my_part\no my_part\nusemtl steel_1\nv 0 0 0\nv {x} 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 {index}\n"


@pytest.mark.parametrize("text", _ODD_NUMBERS)
def test_obj_coordinate_and_index_outside_the_grammar_are_refused(tmp_path, text):
    path = tmp_path / "odd.obj"
    path.write_bytes(_obj_text(text).encode())
    with pytest.raises(MeshReadError, match=r"odd\.obj.*line 5: vertex coordinate .* is not a decimal number"):
        load_mesh(path)
    index = "0_3" if "_" in text else text                 # "0_3" was read as index 3: a wrong face, silently
    path.write_bytes(_obj_text("1", index=index).encode())
    with pytest.raises(MeshReadError, match=r"odd\.obj.*line 8: face index .* is not an integer"):
        load_mesh(path)


def test_obj_names_with_underscores_still_read(tmp_path):
    path = tmp_path / "odd.obj"
    path.write_bytes(_obj_text("1").encode())
    assert len(load_mesh(path).faces) == 1


# -- issue 25: an OBJ coordinate that is not a number is reported on its own line --------------------------

_OBJ_FILLER = {"comment": "# a comment", "blank": "", "normal": "vn 0 0 1", "vertex": "v 0.5 0.25 0.125",
               "continued": "v 1 \\\n2 3"}         # one statement on two lines


@pytest.mark.parametrize("bad_line", [3, 9])
def test_obj_bad_coordinate_names_its_line(tmp_path, bad_line):
    lines = ["v 0 0 0", "v 1 0 0", "v 0 1 0", "v 0 0 1", "f 1 2 3", "f 1 3 4", "f 1 4 2", "f 2 4 3", "v 1 1 1"]
    lines[bad_line - 1] = "v 0 1 abc" if bad_line == 3 else "v 1 2 x"
    path = tmp_path / "bad.obj"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(MeshReadError, match=rf"bad\.obj: line {bad_line}: vertex coordinate '(abc|x)' is not a number"):
        load_mesh(path)
    err = io.StringIO()
    with redirect_stderr(err):
        assert main(["analyze", str(path)]) == 3
    assert f"line {bad_line}:" in err.getvalue() and "after line" not in err.getvalue()


@settings(max_examples=40, deadline=None)
@given(before=st.lists(st.sampled_from(sorted(_OBJ_FILLER)), max_size=30),
       after=st.lists(st.sampled_from(sorted(_OBJ_FILLER)), max_size=10),
       column=st.integers(0, 2))
def test_obj_bad_coordinate_line_is_counted_past_comments_and_continuations(tmp_path_factory, before, after, column):
    text = "".join(_OBJ_FILLER[k] + "\n" for k in before)
    expected = text.count("\n") + 1                     # the physical line the bad statement starts on
    coords = ["1", "2", "3"]
    coords[column] = "1.0e"
    text += "v " + " ".join(coords) + "\n" + "".join(_OBJ_FILLER[k] + "\n" for k in after)
    text += "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -3\n"
    path = tmp_path_factory.mktemp("obj") / "bad.obj"
    path.write_text(text)
    with pytest.raises(MeshReadError, match=rf": line {expected}: vertex coordinate '1\.0e' is not a number"):
        load_mesh(path)
