"""URDF / SDFormat / MuJoCo <inertial> blocks (inertial.py, reports/robot.py) and the simulators' checks."""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from conftest import write_binary_stl
from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import PhysicsError, UsageError
from inertia_tool.robot.inertial import (GAZEBO_TOLERANCE, check_moments, inertial_frame, quaternion_from_matrix,
                                   rpy_from_matrix)
from inertia_tool.mass.properties import MassProperties
from inertia_tool.robot.formats import format_inertial, format_mjcf, format_sdf, format_urdf


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _quat_matrix(w, x, y, z):
    """Active rotation of a unit quaternion (w, x, y, z), written out (independent of scipy)."""
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@pytest.fixture(scope="module")
def tilted():
    """A 40 × 20 × 10 mm aluminium block turned by 30° about z, then tipped, off the origin: all products non-zero."""
    box = trimesh.creation.box([0.04, 0.02, 0.01])
    rot = Rotation.from_euler("zyx", [30, 20, 10], degrees=True).as_matrix()
    v = box.vertices @ rot.T + [0.1, -0.05, 0.02]
    return mass_properties((v, box.faces), material="aluminium", name="tilted block")


def _floats(text):
    return np.array([float(x) for x in text.split()])


def _urdf_numbers(xml):
    el = ET.fromstring(xml)
    origin, mass, inertia = el.find("origin"), el.find("mass"), el.find("inertia")
    t = {k: float(v) for k, v in inertia.attrib.items()}
    tensor = np.array([[t["ixx"], t["ixy"], t["ixz"]], [t["ixy"], t["iyy"], t["iyz"]], [t["ixz"], t["iyz"], t["izz"]]])
    return _floats(origin.get("xyz")), _floats(origin.get("rpy")), float(mass.get("value")), tensor


@pytest.mark.parametrize("frame", ["principal", "mesh"])
def test_urdf_block_reproduces_the_engine(tilted, frame):
    xyz, rpy, mass, tensor = _urdf_numbers(format_urdf(inertial_frame(tilted, frame)))
    rot = _rz(rpy[2]) @ _ry(rpy[1]) @ _rx(rpy[0])          # URDF: fixed-axis roll, pitch, yaw
    scale = np.abs(tilted.inertia).max()
    np.testing.assert_allclose(rot @ tensor @ rot.T, tilted.inertia, atol=1e-10 * scale)
    np.testing.assert_allclose(xyz, tilted.center_of_mass, rtol=1e-11)
    assert mass == pytest.approx(tilted.mass, rel=1e-11)
    if frame == "principal":
        np.testing.assert_allclose(np.sort(np.diag(tensor)), tilted.principal.moments, rtol=1e-11)
        assert np.count_nonzero(tensor - np.diag(np.diag(tensor))) == 0
    else:
        np.testing.assert_allclose(rpy, 0.0)


def test_urdf_products_use_the_tensor_sign():
    """A box lying along x = y has ∫xy dm > 0 about its centre, so the URDF ixy (tensor element) is negative."""
    box = trimesh.creation.box([0.3, 0.05, 0.05])
    props = mass_properties((box.vertices @ _rz(np.pi / 4).T, box.faces), density=1000)
    _, _, _, tensor = _urdf_numbers(format_urdf(inertial_frame(props, "mesh")))
    m = props.mass
    ixy_integral = m * (0.3 ** 2 - 0.05 ** 2) / 12 * 0.5     # ∫xy dm for the rotated box, closed form
    assert tensor[0, 1] == pytest.approx(-ixy_integral, rel=1e-9)


@pytest.mark.parametrize("frame", ["principal", "mesh"])
def test_sdf_block_reproduces_the_engine(tilted, frame):
    el = ET.fromstring(format_sdf(inertial_frame(tilted, frame)))
    pose = _floats(el.find("pose").text)
    t = {c.tag: float(c.text) for c in el.find("inertia")}
    tensor = np.array([[t["ixx"], t["ixy"], t["ixz"]], [t["ixy"], t["iyy"], t["iyz"]], [t["ixz"], t["iyz"], t["izz"]]])
    rot = _rz(pose[5]) @ _ry(pose[4]) @ _rx(pose[3])
    np.testing.assert_allclose(rot @ tensor @ rot.T, tilted.inertia, atol=1e-10 * np.abs(tilted.inertia).max())
    np.testing.assert_allclose(pose[:3], tilted.center_of_mass, rtol=1e-11)
    assert float(el.find("mass").text) == pytest.approx(tilted.mass, rel=1e-11)


@pytest.mark.parametrize("frame", ["principal", "mesh"])
def test_mjcf_round_trip_through_mujoco(tilted, frame):
    """Load the block into MuJoCo's compiler; its body_ipos/body_iquat/body_inertia must give the engine's tensor."""
    mujoco = pytest.importorskip("mujoco")
    block = format_mjcf(inertial_frame(tilted, frame))
    model = mujoco.MjModel.from_xml_string(
        f"<mujoco><worldbody><body name='part'><freejoint/>{block}</body></worldbody></mujoco>")
    body = model.body("part").id
    rot = _quat_matrix(*model.body_iquat[body])
    inertia = rot @ np.diag(model.body_inertia[body]) @ rot.T
    np.testing.assert_allclose(inertia, tilted.inertia, atol=1e-10 * np.abs(tilted.inertia).max())
    np.testing.assert_allclose(model.body_ipos[body], tilted.center_of_mass, rtol=1e-11)
    assert model.body_mass[body] == pytest.approx(tilted.mass, rel=1e-11)
    np.testing.assert_allclose(np.sort(model.body_inertia[body]), tilted.principal.moments, rtol=1e-10)


def test_mjcf_fullinertia_order(tilted):
    el = ET.fromstring(format_mjcf(inertial_frame(tilted, "mesh")).split("-->")[-1])
    full = _floats(el.get("fullinertia"))
    t = tilted.inertia
    np.testing.assert_allclose(full, [t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]], rtol=1e-11)
    assert el.get("quat") is None


def test_thin_plate_shell_is_accepted_by_mujoco():
    """A flat plate sits on the triangle-inequality boundary; with the t²/12 term it is inside, and MuJoCo agrees."""
    mujoco = pytest.importorskip("mujoco")
    from inertia_tool.mass.thinwall import shell_mass_properties
    v = np.array([[0, 0, 0], [0.2, 0, 0], [0.2, 0.1, 0], [0, 0.1, 0]], dtype=float)
    plate = shell_mass_properties((v, np.array([[0, 1, 2], [0, 2, 3]])), thickness=0.001, material="steel")
    frame = inertial_frame(plate)
    assert frame.check.triangle_margin == pytest.approx(plate.mass * 0.001 ** 2 / 6, rel=1e-6)
    mujoco.MjModel.from_xml_string(f"<mujoco><worldbody><body><freejoint/>{format_mjcf(frame)}</body></worldbody>"
                                   "</mujoco>")


def _fake(moments, rotation=None):
    rotation = np.eye(3) if rotation is None else rotation
    return MassProperties(mass=1.0, volume=1e-3, center_of_mass=[0, 0, 0],
                          inertia=rotation @ np.diag(moments) @ rotation.T, name="fake")


def test_triangle_inequality_violation_is_refused_with_the_numbers():
    with pytest.raises(PhysicsError, match=r"1, 1, 3 kg·m².*triangle inequality"):
        inertial_frame(_fake([1.0, 1.0, 3.0]))


def test_zero_moment_is_refused():
    """A needle (a wire along x): I1 = 0; MuJoCo refuses moments ≤ mjMINVAL, so do we, whatever the frame."""
    for frame in ("principal", "mesh"):
        with pytest.raises(PhysicsError, match="positive"):
            inertial_frame(_fake([0.0, 1.0, 1.0]), frame)


def test_gazebo_tolerance_boundary():
    """gz-math ValidMoments: I1 + I2 + ε ≥ I3 with ε = 10 · DBL_EPSILON · ½ ΣI."""
    eps = GAZEBO_TOLERANCE * np.finfo(float).eps * 0.5 * 4.0
    assert check_moments([1.0, 1.0, 2.0 + 0.5 * eps]).ok
    assert not check_moments([1.0, 1.0, 2.0 + 4 * eps]).ok
    assert check_moments([1.0, 1.0, 2.0 + 0.5 * eps]).epsilon == pytest.approx(eps)


def test_mujoco_agrees_with_the_triangle_check():
    mujoco = pytest.importorskip("mujoco")
    for moments, ok in (([1.0, 1.5, 2.0], True), ([1.0, 1.0, 2.1], False)):
        assert check_moments(moments).ok is ok
        xml = (f"<mujoco><worldbody><body><freejoint/><inertial pos='0 0 0' mass='1' "
               f"diaginertia='{' '.join(map(str, moments))}'/></body></worldbody></mujoco>")
        if ok:
            mujoco.MjModel.from_xml_string(xml)
        else:
            with pytest.raises(ValueError, match="A \\+ B >= C"):
                mujoco.MjModel.from_xml_string(xml)


@pytest.mark.parametrize("angles", [(0.3, -0.4, 1.2), (2.5, 1.1, -2.9), (0.0, np.pi / 2 - 1e-3, 0.7)])
def test_rpy_and_quaternion_conventions(angles):
    roll, pitch, yaw = angles
    rot = _rz(yaw) @ _ry(pitch) @ _rx(roll)
    np.testing.assert_allclose(rpy_from_matrix(rot), angles, atol=1e-9)
    q = quaternion_from_matrix(rot)
    assert q[0] >= 0 and np.linalg.norm(q) == pytest.approx(1.0)
    np.testing.assert_allclose(_quat_matrix(*q), rot, atol=1e-12)


def test_bad_frame_and_format(tilted):
    with pytest.raises(UsageError):
        inertial_frame(tilted, "body")
    with pytest.raises(UsageError):
        format_inertial(inertial_frame(tilted), "usd")


def test_comment_is_valid_xml_even_for_odd_names():
    props = MassProperties(mass=1.0, volume=1e-3, center_of_mass=[0, 0, 0], inertia=np.diag([1.0, 2.0, 2.5]),
                           name="part--v2 <final>.stl")
    text = format_urdf(inertial_frame(props), source=props.name)
    ET.fromstring(f"<root>{text}</root>")


# -- command line ----------------------------------------------------------------------------------------------

@pytest.fixture
def block_stl(tmp_path):
    box = trimesh.creation.box([40.0, 20.0, 10.0])
    rot = Rotation.from_euler("z", 30, degrees=True).as_matrix()
    p = tmp_path / "block.stl"
    write_binary_stl(p, box.vertices @ rot.T + [5, 0, 0], box.faces)
    return str(p)


@pytest.mark.parametrize("fmt", ["urdf", "sdf", "mjcf"])
def test_cli_prints_a_block(block_stl, fmt, capsys):
    assert main(["analyze", block_stl, "--units", "mm", "--material", "aluminium", "--format", fmt]) == 0
    out = capsys.readouterr().out
    root = ET.fromstring(f"<root>{out}</root>")
    assert root.find("inertial") is not None
    assert "tensor convention" in out


def test_cli_json_alias(block_stl, capsys):
    assert main(["analyze", block_stl, "--units", "mm", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(["analyze", block_stl, "--units", "mm", "--format", "json"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert a == b
    assert main(["analyze", block_stl, "--json", "--format", "urdf"]) == 2


def test_cli_refuses_a_needle_with_exit_code_4(tmp_path, capsys):
    """A 1 m × 1 nm steel strip 1 µm thick is a needle: I1 ≈ 7e-22 kg·m², below MuJoCo's mjMINVAL."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1e-9, 0], [0, 1e-9, 0]], dtype=float)
    p = tmp_path / "needle.stl"
    write_binary_stl(p, v, np.array([[0, 1, 2], [0, 2, 3]]))
    code = main(["analyze", str(p), "--model", "shell", "--thickness", "1um", "--density", "7850",
                 "--format", "mjcf"])
    err = capsys.readouterr().err
    assert code == 4 and "principal moments" in err


# -- the principal frame nearest the link frame (docs/conventions.md) -------------------------------------

from hypothesis import given, settings, strategies as st   # noqa: E402

from inertia_tool.robot.inertial import _SIGNED_PERMUTATIONS, principal_frame_nearest   # noqa: E402
from inertia_tool.mass.principal import principal_axes            # noqa: E402


def test_aligned_box_keeps_the_link_axes_not_the_ascending_order():
    # a 0.1 × 0.3 × 0.2 box along the link axes: ascending order would be (y, z, x) — rpy of ±90° for no reason
    box = trimesh.creation.box([0.1, 0.3, 0.2])
    props = mass_properties((box.vertices, box.faces), density=1000)
    assert not np.allclose(np.abs(props.principal.axes), np.eye(3))          # the sorted frame is permuted
    frame = inertial_frame(props, "principal")
    np.testing.assert_allclose(frame.rotation, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(frame.rpy, 0.0, atol=1e-12)
    np.testing.assert_allclose(np.diag(frame.inertia), np.diag(props.inertia), rtol=1e-12)


def test_slightly_turned_link_gets_the_small_rotation():
    box = trimesh.creation.box([0.1, 0.3, 0.2])
    turn = Rotation.from_euler("xyz", [0.05, -0.03, 0.08]).as_matrix()
    props = mass_properties((box.vertices @ turn.T, box.faces), density=1000)
    frame = inertial_frame(props, "principal")
    np.testing.assert_allclose(frame.rotation, turn, atol=1e-9)
    np.testing.assert_allclose(frame.rpy, [0.05, -0.03, 0.08], atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.5, 3.0), min_size=3, max_size=3, unique=True),
       st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1))
def test_nearest_frame_is_the_largest_trace_of_all_24(moments, quat):
    rot = Rotation.from_quat(quat).as_matrix()
    tensor = rot @ np.diag(sorted(moments)) @ rot.T
    pa = principal_axes(tensor)
    if pa.equal_pairs:
        return
    r = principal_frame_nearest(pa)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)
    diag = r.T @ tensor @ r
    np.testing.assert_allclose(diag - np.diag(np.diag(diag)), 0.0, atol=1e-12 * max(moments))
    assert np.trace(r) >= max(np.trace(pa.axes @ p) for p in _SIGNED_PERMUTATIONS) - 1e-12


def test_axisymmetric_and_spherical_links_keep_the_link_axes():
    cylinder = trimesh.creation.cylinder(radius=0.05, height=0.3, sections=64)
    props = mass_properties((cylinder.vertices, cylinder.faces), density=1000)
    assert props.principal.equal_pairs                                   # I_xx = I_yy
    np.testing.assert_allclose(inertial_frame(props, "principal").rotation, np.eye(3), atol=1e-12)
    # tilted by 0.1 rad about x: the unique axis follows the tilt; the plane keeps x
    tilt = Rotation.from_euler("x", 0.1).as_matrix()
    tilted = mass_properties((cylinder.vertices @ tilt.T, cylinder.faces), density=1000)
    r = inertial_frame(tilted, "principal").rotation
    np.testing.assert_allclose(r, tilt, atol=1e-9)
    cube = trimesh.creation.box([0.2, 0.2, 0.2])
    turned = Rotation.from_euler("xyz", [0.3, 0.2, 0.1]).as_matrix()
    props = mass_properties((cube.vertices @ turned.T, cube.faces), density=1000)
    np.testing.assert_allclose(inertial_frame(props, "principal").rotation, np.eye(3))
