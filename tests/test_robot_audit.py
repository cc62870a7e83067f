"""Declared inertials against the geometry (inertia_tool.robot.audit)."""

import numpy as np
import pytest

from inertia_tool.mass import shapes
from inertia_tool.robot import audit_links as audit, link_inertials, read_robot

from robot_data import PACKAGES, UR5

pytestmark = pytest.mark.filterwarnings("ignore::inertia_tool.errors.OverlapWarning")


def _box_urdf(tmp_path, *, mass, xyz="0 0 0", tensor=None, size=(0.1, 0.2, 0.3)):
    a, b, c = size
    exact = shapes.box(a, b, c).exact.with_mass(mass)
    t = (exact.inertia if tensor is None else np.asarray(tensor)).tolist()
    f = tmp_path / "box.urdf"
    f.write_text(f'<robot name="r"><link name="l"><inertial><origin xyz="{xyz}" rpy="0 0 0"/><mass value="{mass!r}"/>'
                 f'<inertia ixx="{t[0][0]!r}" ixy="{t[0][1]!r}" ixz="{t[0][2]!r}" iyy="{t[1][1]!r}" iyz="{t[1][2]!r}" '
                 f'izz="{t[2][2]!r}"/></inertial><collision><geometry><box size="{a} {b} {c}"/></geometry></collision>'
                 '</link></robot>')
    return read_robot(f)


def test_a_correct_declaration_has_no_issue(tmp_path):
    robot = _box_urdf(tmp_path, mass=0.1 * 0.2 * 0.3 * 2700)
    (a,) = audit(robot, link_inertials(robot, material="aluminium"))
    assert a.ok, a.issues
    assert a.mass_ratio == pytest.approx(1, rel=1e-14) and a.com_distance == 0
    assert a.inertia_difference < 1e-14 and a.implied_density == pytest.approx(2700)
    assert a.com_inside_geometry and a.declared_check.ok


def test_a_mass_in_grams_is_an_implausible_density(tmp_path):
    robot = _box_urdf(tmp_path, mass=16200.0)          # 16.2 kg entered as grams
    (a,) = audit(robot, link_inertials(robot, keep_mass=True), keep_mass=True)
    assert a.implied_density == pytest.approx(2.7e6)
    assert a.density_plausible is False
    assert any("implied density" in i for i in a.issues)


def test_triangle_inequality_violation_and_moved_com_are_flagged(tmp_path):
    robot = _box_urdf(tmp_path, mass=1.0, xyz="0.2 0 0", tensor=np.diag([1.0, 1.0, 3.0]))
    (a,) = audit(robot, link_inertials(robot, keep_mass=True), keep_mass=True)
    assert not a.declared_check.triangle and a.declared_check.positive
    assert a.com_in_bounding_box is False and a.com_distance == pytest.approx(0.2)
    text = " ".join(a.issues)
    assert "triangle inequality" in text and "bounding box" in text and "centre of mass is 200.0 mm" in text


def test_com_in_the_box_but_outside_the_material_of_a_ring(tmp_path):
    # a ring of 8 boxes around z: its centre of mass (the origin) is in the bounding box but not in the material
    boxes = "".join(f'<collision><origin xyz="{0.1 * np.cos(t):.17g} {0.1 * np.sin(t):.17g} 0" rpy="0 0 {t:.17g}"/>'
                    '<geometry>'
                    '<box size="0.02 0.08 0.02"/></geometry></collision>' for t in np.arange(8) * np.pi / 4)
    f = tmp_path / "ring.urdf"
    f.write_text(f'<robot name="r"><link name="ring"><inertial><origin xyz="0 0 0"/><mass value="1"/>'
                 f'<inertia ixx="1" iyy="1" izz="1"/></inertial>{boxes}</link></robot>')
    robot = read_robot(f)
    (a,) = audit(robot, link_inertials(robot, keep_mass=True), keep_mass=True)
    assert a.com_in_bounding_box is True and a.com_inside_geometry is False
    assert a.com_distance < 1e-15
    # the ring's own centre of mass is outside its material too: no evidence of a slip, no issue raised
    assert not any("outside the link geometry" in i for i in a.issues), a.issues


def test_a_declared_com_outside_a_solid_link_whose_own_com_is_inside_is_an_issue(tmp_path):
    # one box: the geometry's centre of mass is inside; a declared centre in the box's bounding box but in a
    # notch cut out of an L made of two boxes is outside the material while the L's own centre is inside
    f = tmp_path / "ell.urdf"
    f.write_text('<robot name="r"><link name="ell"><inertial><origin xyz="0.03 -0.03 0"/><mass value="1"/>'
                 '<inertia ixx="1" iyy="1" izz="1"/></inertial>'
                 '<collision><origin xyz="0 0.03 0"/><geometry><box size="0.1 0.04 0.1"/></geometry></collision>'
                 '<collision><origin xyz="-0.03 -0.02 0"/><geometry><box size="0.04 0.06 0.1"/></geometry>'
                 '</collision></link></robot>')
    robot = read_robot(f)
    (a,) = audit(robot, link_inertials(robot, keep_mass=True), keep_mass=True)
    assert a.com_in_bounding_box is True and a.com_inside_geometry is False
    assert any("outside the link geometry (in its bounding box)" in i for i in a.issues), a.issues


def test_ur5_wrist_inertias_are_flagged_and_the_upper_arm_is_not():
    # ur_description's UR5 wrists declare ixx = 0.111 kg·m² for a 1.2 kg link ~10 cm across: a known error of
    # that description (the geometry gives ~1.5e-3); the upper arm's declared tensor is close to its geometry
    robot = read_robot(UR5, packages=PACKAGES)
    audits = {a.name: a for a in audit(robot, link_inertials(robot, keep_mass=True), keep_mass=True)}
    wrist = audits["wrist_1_link"]
    assert wrist.inertia_difference > 50
    assert any("inertia differs" in i for i in wrist.issues)
    assert audits["upper_arm_link"].inertia_difference < 0.1
    assert audits["tool0"].ok and audits["world"].ok           # massless frames are fine
    assert audits["ee_link"].issues == ("declared mass 0 kg is not positive",)
