"""Corrected descriptions (inertia_tool.robot.write), checked by loading them in MuJoCo and Pinocchio."""

import os
import re

import numpy as np
import pytest
from lxml import etree

from inertia_tool.errors import UsageError
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.write import corrected_document, write_corrected

from conftest import assert_tensor_close
from robot_data import PACKAGES, PANDA, PANDA_MESHES, UR5, UR5_MESHES

ROBOTS = {"ur5": (UR5, UR5_MESHES), "panda": (PANDA, PANDA_MESHES)}


def _corrected(name, tmp_path, **basis):
    path, _ = ROBOTS[name]
    robot = read_robot(path, packages=PACKAGES)
    inertials = link_inertials(robot, **(basis or {"keep_mass": True}))
    out = tmp_path / f"{name}_fixed.urdf"
    write_corrected(robot, inertials, out)
    return robot, {r.name: r.properties for r in inertials if r.properties is not None}, out


def _mujoco_model(urdf, meshes):
    """Load a URDF in MuJoCo: meshes from ``meshes`` (path stripped), no fusing of fixed links, no balancing."""
    mujoco = pytest.importorskip("mujoco")
    text = urdf.read_text()
    compiler = (f'<mujoco><compiler meshdir="{meshes}" strippath="true" fusestatic="false" discardvisual="true" '
                'balanceinertia="false"/></mujoco>')
    text = re.sub(r"(<robot[^>]*>)", lambda m: m.group(1) + compiler, text, count=1)
    return mujoco, mujoco.MjModel.from_xml_string(text)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_written_urdf_loads_in_mujoco_with_the_computed_inertias(name, tmp_path):
    robot, ours, out = _corrected(name, tmp_path)
    mujoco, model = _mujoco_model(out, ROBOTS[name][1])
    assert len(ours) >= 7
    for link, props in ours.items():
        i = model.body(link).id
        assert model.body_mass[i] == pytest.approx(props.mass, rel=1e-12)
        np.testing.assert_allclose(model.body_ipos[i], props.center_of_mass, atol=1e-12)
        # MuJoCo diagonalises: principal moments, and the full tensor rebuilt from body_iquat
        np.testing.assert_allclose(np.sort(model.body_inertia[i]), props.principal.moments, rtol=1e-12)
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        assert_tensor_close(rot @ np.diag(model.body_inertia[i]) @ rot.T, props.inertia, 1e-12)


def test_written_urdf_gives_pinocchio_the_same_inertias(tmp_path):
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip package `pin`) is not installed")
    robot, ours, out = _corrected("ur5", tmp_path)
    model = pin.buildModelFromUrdf(str(out))
    checked = 0
    for link, props in ours.items():
        if not model.existJointName(_joint_of(robot, link)):
            continue
        inertia = model.inertias[model.getJointId(_joint_of(robot, link))]
        assert inertia.mass == pytest.approx(props.mass, rel=1e-12)
        np.testing.assert_allclose(inertia.lever, props.center_of_mass, atol=1e-12)
        assert_tensor_close(inertia.inertia, props.inertia, 1e-12)
        checked += 1
    assert checked == 6          # the six moving links of the UR5 (each the only body of its joint)


def _joint_of(robot, link):
    tree = etree.fromstring(robot.document)
    for joint in tree.findall("joint"):
        if joint.find("child").get("link") == link and joint.get("type") != "fixed":
            return joint.get("name")
    return ""


def _without_inertials(data: bytes) -> bytes:
    tree = etree.fromstring(data)
    for inertial in tree.iter("inertial"):
        inertial.getparent().remove(inertial)
    for comment in tree.xpath("/*/comment()[contains(., 'inertia-tool robot')]"):
        comment.getparent().remove(comment)
    return etree.tostring(tree, method="c14n")


def _outside_inertials(data: bytes) -> bytes:
    """The bytes with every <inertial>…</inertial> and the provenance comment cut out."""
    data = re.sub(rb"[ \t]*<!-- inertia-tool robot:.*?-->\r?\n", b"", data, flags=re.S)
    return re.sub(rb"\r?\n[ \t]*(?:<inertial\b[^>]*/>|<inertial\b.*?</inertial>)", b"", data, flags=re.S)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_every_byte_outside_the_inertials_is_kept(name, tmp_path):
    robot, ours, out = _corrected(name, tmp_path)
    original, written = ROBOTS[name][0].read_bytes(), out.read_bytes()
    assert _outside_inertials(original) == _outside_inertials(written)
    assert _without_inertials(original) == _without_inertials(written)        # and as XML, canonically
    assert len(written.splitlines()) == len(original.splitlines()) + 1        # the provenance comment


def test_missing_inertials_are_inserted_in_the_style_of_the_file(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<?xml version="1.0"?>\n<robot name=\'r\'>\n    <!-- a comment, kept -->\n    <link name=\'a\'>\n'
                    '        <collision>\n            <geometry><box size=\'0.1 0.2 0.3\' /></geometry>\n'
                    '        </collision>\n    </link>\n    <link name="b"/>\n</robot>\n')
    robot = read_robot(urdf)
    inertials = link_inertials(robot, density=1000)
    text = corrected_document(robot, inertials).decode()
    assert "<box size='0.1 0.2 0.3' />" in text and "<!-- a comment, kept -->" in text
    assert "\n        <inertial>\n            <origin" in text
    assert text.endswith("    </link>\n    <link name=\"b\"/>\n</robot>\n")
    declared = read_robot_from_text(tmp_path, text).link("a").declared
    assert declared.mass == pytest.approx(1000 * 0.006)
    mjcf = tmp_path / "m.xml"
    mjcf.write_text('<mujoco>\n  <worldbody>\n    <body name="b">\n      <freejoint/>\n'
                    '      <geom type="sphere" size="0.1"/>\n    </body>\n  </worldbody>\n</mujoco>\n')
    robot = read_robot(mjcf)
    text = corrected_document(robot, link_inertials(robot, density=1000)).decode()
    assert '<body name="b">\n      <inertial pos="0.0 0.0 0.0" mass=' in text
    model = mujoco.MjModel.from_xml_string(text)
    assert model.body_mass[1] == pytest.approx(1000 * 4 / 3 * np.pi * 0.001, rel=1e-14)


def read_robot_from_text(directory, text):
    path = directory / "again.urdf"
    path.write_text(text)
    return read_robot(path)


def test_corrected_values_read_back_as_declared(tmp_path):
    robot, ours, out = _corrected("panda", tmp_path, material="aluminium")
    again = read_robot(out, packages=PACKAGES)
    for link, props in ours.items():
        declared = again.link(link).declared
        assert declared.mass == props.mass
        np.testing.assert_array_equal(declared.rotation, np.eye(3))
        np.testing.assert_allclose(declared.center_of_mass, props.center_of_mass, rtol=0, atol=1e-15)
        assert_tensor_close(declared.inertia, props.inertia, 1e-15)


def test_sdf_and_mjcf_are_corrected_in_their_own_syntax(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    sdf = tmp_path / "m.sdf"
    sdf.write_text('<?xml version="1.0"?>\n<sdf version="1.7"><model name="m"><link name="l">'
                   '<collision name="c"><pose>0.1 0 0 0 0.3 0</pose><geometry><box><size>0.1 0.2 0.3</size></box>'
                   '</geometry></collision></link></model></sdf>\n')
    mjcf = tmp_path / "m.xml"
    mjcf.write_text('<mujoco model="m"><compiler angle="radian"/><worldbody><body name="b"><freejoint/>'
                    '<inertial pos="0 0 0" quat="1 0 0 0" mass="1" diaginertia="1 1 1"/>'
                    '<geom type="box" size="0.05 0.1 0.15" pos="0.1 0 0" euler="0 0.3 0"/></body></worldbody></mujoco>')
    for path in (sdf, mjcf):
        robot = read_robot(path)
        inertials = link_inertials(robot, density=2700)
        out = tmp_path / f"fixed_{path.name}"
        write_corrected(robot, inertials, out)
        props = inertials[0].properties
        declared = read_robot(out).links[0].declared
        assert declared.mass == props.mass
        assert_tensor_close(declared.inertia, props.inertia, 1e-15)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "fixed_m.xml"))
    assert model.body_mass[1] == pytest.approx(props.mass, rel=1e-14)


def test_never_overwrites_without_force_and_leaves_no_temporary_file(tmp_path):
    robot = read_robot(UR5, packages=PACKAGES)
    inertials = link_inertials(robot, keep_mass=True)
    out = tmp_path / "out.urdf"
    out.write_text("keep me")
    with pytest.raises(UsageError, match="exists"):
        write_corrected(robot, inertials, out)
    assert out.read_text() == "keep me"
    write_corrected(robot, inertials, out, force=True)
    assert out.read_bytes() == corrected_document(robot, inertials)
    assert os.listdir(tmp_path) == ["out.urdf"]
    copy = tmp_path / "copy.urdf"
    copy.write_bytes(UR5.read_bytes())
    robot_copy = read_robot(copy, packages=PACKAGES)
    with pytest.raises(UsageError, match="is the input description"):
        write_corrected(robot_copy, inertials, copy)


def test_real_sdf_is_corrected_in_place(tmp_path):
    from robot_data import CASSIE_SDF
    robot = read_robot(CASSIE_SDF)
    inertials = link_inertials(robot, keep_mass=True)
    out = tmp_path / "cassie_fixed.sdf"
    write_corrected(robot, inertials, out)
    assert _outside_inertials(CASSIE_SDF.read_bytes()) == _outside_inertials(out.read_bytes())
    again = read_robot(out)
    for result in inertials:
        if result.properties is None:
            continue
        declared = again.link(result.name).declared
        assert declared.mass == result.properties.mass
        np.testing.assert_allclose(declared.center_of_mass, result.properties.center_of_mass, rtol=0, atol=1e-15)
        assert_tensor_close(declared.inertia, result.properties.inertia, 1e-15)


def test_real_mjcf_gets_inertials_inserted_and_reads_back(tmp_path):
    # Gymnasium's humanoid has no <inertial> (MuJoCo infers them): each body gets one, first, indented
    from robot_data import GYM
    source = GYM / "humanoid.xml"
    robot = read_robot(source)
    inertials = link_inertials(robot, density=1000)
    out = tmp_path / "humanoid.xml"
    write_corrected(robot, inertials, out)
    assert _outside_inertials(source.read_bytes()) == _outside_inertials(out.read_bytes())
    again = read_robot(out)
    for result in inertials:
        declared = again.link(result.name).declared
        assert declared.mass == result.properties.mass
        assert_tensor_close(declared.inertia, result.properties.inertia, 1e-15)
