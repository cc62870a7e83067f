"""Every subcommand on hostile inputs: a result or a one-line error with a documented exit code, never exit 1.

Regression test of issue 22's "Internal errors (exit 1)" list: each input below once ended in an internal
error, a traceback, or NaN printed into JSON with exit 0.  The contract checked for every (command, input):
exit code other than 1, no "Traceback" and no "internal error" on stderr, no terminal control character on
either stream, and JSON output (where asked for) that parses with finite numbers only.
"""

import io
import json
import math
import re
import struct
import zipfile
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

from inertia_tool.cli import main

from conftest import box_arrays, write_binary_stl

_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def _finite(value) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    return True


def check_contract(argv, code, out, err):
    shown = " ".join(map(str, argv))
    assert code != 1, f"{shown}: exit 1\n{err}"
    assert "Traceback" not in err and "internal error" not in err, f"{shown}\n{err}"
    assert not _CONTROL.search(err) and not _CONTROL.search(out), f"{shown}: control character printed"
    if code in (0, 5) and "--json" in argv:      # 5: robot, a link without a result (the report is complete)
        assert _finite(json.loads(out)), f"{shown}: non-finite number in JSON"


_HOSTILE_NAME = "e\x1b]0;owned\x07\x1b[31m\x9b2J--x-->.stl"


def _dae(path, token):
    trimesh = pytest.importorskip("trimesh")
    text = trimesh.exchange.dae.export_collada(trimesh.creation.box(extents=(0.1, 0.2, 0.4))).decode()
    start = text.index(">", text.index("<float_array")) + 1
    first = text[start:].split()[0]
    path.write_text(text[:start] + token + text[start + len(first):])


def _encrypted_zip(path):
    v, f = box_arrays((0.1, 0.1, 0.1))
    inner = path.parent / "inner.stl"
    write_binary_stl(inner, v, f)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.write(inner, "part.stl")
    raw = bytearray(path.read_bytes())
    for magic, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        at = raw.find(magic)
        struct.pack_into("<H", raw, at + offset, struct.unpack_from("<H", raw, at + offset)[0] | 1)
    path.write_bytes(bytes(raw))


def _empty_step(path):
    pytest.importorskip("OCP")
    from OCP.BRep import BRep_Builder
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound
    compound = TopoDS_Compound()
    BRep_Builder().MakeCompound(compound)
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    writer.Write(str(path))


def _ply_claiming(path, faces):
    path.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     b"property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % faces
                     + bytes(36))


def _mesh_inputs(tmp):
    """name → path of hostile mesh files (and one good box, for the hostile option values)."""
    files = {}
    v, f = box_arrays((0.1, 0.2, 0.3))
    write_binary_stl(tmp / "good.stl", v, f)
    files["good"] = tmp / "good.stl"
    write_binary_stl(tmp / _HOSTILE_NAME, v, f)
    files["escape-name"] = tmp / _HOSTILE_NAME
    write_binary_stl(tmp / "far.stl", v + 1e6 + 0.01, f)
    files["far-float32"] = tmp / "far.stl"
    write_binary_stl(tmp / "huge.stl", v * 1e37, f)
    files["huge-coordinates"] = tmp / "huge.stl"
    write_binary_stl(tmp / "tiny.stl", v * 1e-36, f)
    files["tiny-coordinates"] = tmp / "tiny.stl"
    for name, token in (("nan", "nan"), ("inf", "inf"), ("overflow", "1e999")):
        _dae(tmp / f"{name}.dae", token)
        files[f"dae-{name}"] = tmp / f"{name}.dae"
    _encrypted_zip(tmp / "enc.zip")
    files["encrypted-zip"] = tmp / "enc.zip"
    _ply_claiming(tmp / "lying.ply", 10 ** 9)
    files["ply-1e9-faces"] = tmp / "lying.ply"
    try:
        _empty_step(tmp / "empty.step")
        files["step-no-bbox"] = tmp / "empty.step"
    except pytest.skip.Exception:
        pass
    return files


def _robot_inputs(tmp):
    def urdf(name, body):
        path = tmp / f"{name}.urdf"
        path.write_text(f'<robot name="r"><link name="a">{body}</link></robot>', encoding="utf-8")
        return path

    def geometry(shape):
        return f"<collision><geometry>{shape}</geometry></collision>"

    files = {
        "sphere-1e300": urdf("s", geometry('<sphere radius="1e300"/>')),
        "cylinder-1e-300": urdf("c", geometry('<cylinder radius="1e-300" length="1"/>')),
        "box-1e-200": urdf("b", geometry('<box size="1e-200 1e-200 1e-200"/>')),
        "underscore": urdf("u", geometry('<box size="1_000 1 1"/>')),
        "arabic-indic": urdf("a", geometry('<box size="١ 1 1"/>')),
        "inertial-1e300": urdf("i", geometry('<box size="1 1 1"/>') + '<inertial><mass value="1e300"/><inertia '
                               'ixx="1e300" iyy="1e300" izz="1e300" ixy="0" ixz="0" iyz="0"/></inertial>'),
        "inertial-tiny": urdf("t", geometry('<box size="1 1 1"/>') + '<inertial><mass value="1e-300"/><inertia '
                              'ixx="1e-300" iyy="1e-300" izz="1e-300" ixy="0" ixz="0" iyz="0"/></inertial>'),
        "origin-1e300": urdf("o", '<collision><origin xyz="1e300 0 0"/><geometry><sphere radius="1"/></geometry>'
                                  "</collision>"),
    }
    mjcf = tmp / "q.xml"
    mjcf.write_text('<mujoco><compiler eulerseq="qqq"/><worldbody><body><geom type="sphere" size="1" '
                    'euler="1 2 3"/></body></worldbody></mujoco>')
    files["eulerseq-qqq"] = mjcf
    return files


_MESH_COMMANDS = {
    "analyze": ["--json"],
    "spin": ["--json"],
    "top": ["--pivot", "0,0,0", "--spin", "100", "--json"],
    "balance": ["--rpm", "1000", "--radius", "0.01", "--json"],
    "spin-it": ["--axis", "0,0,1", "--wall", "1mm", "--resolution", "12", "--json"],
}

_HOSTILE_OPTIONS = [
    ["spin-it", "--axis", "0,0,1", "--wall", "1mm", "--through", "1e300,0,0", "--json"],
    ["spin-it", "--axis", "0,0,1", "--wall", "1e300", "--json"],
    ["spin-it", "--axis", "0,0,1", "--wall", "1mm", "--density", "1e300", "--json"],
    ["spin-it", "--axis", "0,0,1", "--wall", "1mm", "--mass", "1e-300", "--json"],
    ["spin-it", "--axis", "0,0,1", "--wall", "1mm", "--insert", "1e300", "--json"],
    ["spin-it", "--axis", "nan,0,1", "--wall", "1mm", "--json"],
    ["spin-it", "--mode", "top", "--pivot", "0,0,1e300", "--axis", "0,0,1", "--wall", "1mm", "--json"],
    ["spin", "--rate", "1e300", "--json"],
    ["top", "--pivot", "0,0,0", "--spin", "1e300", "--json"],
    ["balance", "--rpm", "1e300", "--radius", "1e300", "--json"],
    ["analyze", "--density", "1e-300", "--json"],
    ["analyze", "--max-faces", "0", "--json"],
]


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hostile")
    return _mesh_inputs(tmp), _robot_inputs(tmp), tmp


@pytest.mark.parametrize("command", sorted(_MESH_COMMANDS))
def test_every_mesh_command_on_every_hostile_file(hostile, command):
    meshes, _, _ = hostile
    for name, path in meshes.items():
        if name == "good":
            continue
        argv = [command, path, *_MESH_COMMANDS[command]]
        check_contract(argv, *run_cli(argv))


def test_batch_on_the_hostile_files(hostile):
    meshes, _, tmp = hostile
    argv = ["batch", *[p for n, p in meshes.items() if n != "good"], "--out", tmp / "rows.csv", "--jobs", "1",
            "--quiet"]
    code, out, err = run_cli(argv)
    check_contract(argv, code, out, err)


@pytest.mark.parametrize("options", _HOSTILE_OPTIONS, ids=lambda o: " ".join(o[:1] + o[-3:-1]))
def test_hostile_option_values(hostile, options):
    meshes, _, _ = hostile
    argv = [options[0], meshes["good"], *options[1:]]
    code, out, err = run_cli(argv)
    check_contract(argv, code, out, err)
    assert code == 2, f"{argv}: {err}"


@pytest.mark.parametrize("name", ["sphere-1e300", "cylinder-1e-300", "box-1e-200", "underscore", "arabic-indic",
                                  "inertial-1e300", "inertial-tiny", "origin-1e300", "eulerseq-qqq"])
@pytest.mark.parametrize("extra", [["--material", "steel"], ["--keep-mass"], ["--density", "1000", "--json"]])
def test_robot_on_hostile_descriptions(hostile, name, extra):
    _, robots, _ = hostile
    argv = ["robot", robots[name], *extra]
    check_contract(argv, *run_cli(argv))


@pytest.mark.parametrize("fmt", ["urdf", "sdf", "mjcf"])
def test_escape_sequences_in_a_file_name_keep_the_snippet_valid_xml(hostile, fmt):
    from lxml import etree
    meshes, _, _ = hostile
    argv = ["analyze", meshes["escape-name"], "--format", fmt]
    code, out, err = run_cli(argv)
    check_contract(argv, code, out, err)
    assert code == 0
    etree.fromstring(f"<r>{out}</r>".encode())        # well-formed: no control character, no "--" in the comment
    assert "\\u001b]0;owned" in out


def test_escaped_name_in_json_decodes_to_the_real_name(hostile):
    meshes, _, _ = hostile
    code, out, err = run_cli(["analyze", meshes["escape-name"], "--json"])
    assert code == 0 and "\x1b" not in out
    assert json.loads(out)["name"].endswith(_HOSTILE_NAME)


def test_a_direction_near_the_float64_limit_is_a_direction(hostile):
    meshes, _, _ = hostile
    argv = ["spin-it", meshes["good"], "--axis", "1e308,1e308,0", "--wall", "1mm", "--resolution", "12", "--json"]
    code, out, err = run_cli(argv)
    check_contract(argv, code, out, err)
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["axis"], [math.sqrt(0.5), math.sqrt(0.5), 0.0], atol=1e-12)


def test_escape_sequences_in_error_lines_are_escaped(tmp_path):
    path = tmp_path / "a\x1b[2Jb.stl"
    path.write_bytes(b"")
    code, out, err = run_cli(["analyze", path])
    assert code == 3 and "\x1b" not in err and "a\\u001b[2Jb.stl" in err


def test_float32_far_box_is_not_silently_exact(hostile):
    meshes, _, _ = hostile
    code, out, err = run_cli(["analyze", meshes["far-float32"], "--json"])
    assert code == 0 and "float32" in err
    volume = json.loads(out)["volume"]
    assert not np.isclose(volume, 0.1 * 0.2 * 0.3, rtol=1e-3)     # the file's corners really moved


# -- hypothesis: any number in a robot file or on the spin-it command line -------------------------------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_EXTREMES = st.sampled_from([0.0, -0.0, 5e-324, 1e-300, 1e-200, 1e-10, 1e10, 1e200, 1e300, 1.7976931348623157e308,
                             float("nan"), float("inf"), -float("inf")])
_NUMBERS = st.one_of(_EXTREMES, st.floats(allow_nan=True, allow_infinity=True), _EXTREMES.map(lambda x: -x))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=st.sampled_from(["sphere", "cylinder", "box", "capsule"]), size=_NUMBERS, other=_NUMBERS,
       offset=_NUMBERS, mass=_NUMBERS)
def test_any_number_in_a_urdf_is_a_result_or_a_clear_error(tmp_path_factory, shape, size, other, offset, mass):
    tmp = tmp_path_factory.mktemp("urdf")
    attrs = {"sphere": f'radius="{size!r}"', "cylinder": f'radius="{size!r}" length="{other!r}"',
             "capsule": f'radius="{size!r}" length="{other!r}"',
             "box": f'size="{size!r} {other!r} {abs(other)!r}"'}[shape]
    path = tmp / "r.urdf"
    path.write_text(f'<robot name="r"><link name="a"><inertial><origin xyz="{offset!r} 0 0"/><mass value="{mass!r}"/>'
                    f'<inertia ixx="{mass!r}" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial><collision>'
                    f'<origin xyz="0 {offset!r} 0"/><geometry><{shape} {attrs}/></geometry></collision></link>'
                    "</robot>")
    for extra in (["--material", "steel", "--json"], ["--keep-mass", "--json"]):
        argv = ["robot", path, *extra]
        code, out, err = run_cli(argv)
        check_contract(argv, code, out, err)
        assert code in (0, 3, 5), err              # 5: e.g. --keep-mass with a declared mass of 0


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(option=st.sampled_from(["--through", "--wall", "--density", "--mass", "--insert", "--axis"]), value=_NUMBERS)
def test_any_number_on_the_spin_it_command_line_is_a_result_or_a_clear_error(hostile, option, value):
    meshes, _, _ = hostile
    text = f"{value!r},0,1" if option in ("--through", "--axis") else repr(value)
    # the option under test comes last: argparse keeps the last value of an option given twice
    argv = ["spin-it", meshes["good"], "--axis", "0,0,1", "--wall", "1mm", "--resolution", "12", "--json",
            option, text]
    code, out, err = run_cli(argv)
    check_contract(argv, code, out, err)


def test_escape_terminal_escapes_every_control_but_keeps_report_lines():
    from inertia_tool.reports.escape import escape_terminal
    assert escape_terminal("a\x1b[2Jb") == "a\\u001b[2Jb"
    assert escape_terminal("x\x9b1m\x7f\x00") == "x\\u009b1m\\u007f\\u0000"
    assert escape_terminal("abc\u202edcba\u2066") == "abc\\u202edcba\\u2066"        # bidirectional overrides
    assert escape_terminal("one\ntwo\tthree\r") == "one\\u000atwo\\u0009three\\u000d"
    assert escape_terminal("one\ntwo\tthree\r", lines=True) == "one\ntwo\tthree\\u000d"
    assert escape_terminal("café ünïcode ✓") == "café ünïcode ✓"
    name = "p\x1b]0;t\x07\u2028.stl"
    assert json.loads(f'"{escape_terminal(name)}"') == name                       # a JSON escape of the same text
