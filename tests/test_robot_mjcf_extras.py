"""MJCF constructs MuJoCo models ship with that the reader once refused (issue 23): height fields in a body
(MuJoCo's inertia box), inline meshes (``<mesh vertex face>``, and ``vertex`` alone: the convex hull),
``<attach>`` of a model asset.  The independent reference is MuJoCo's own compiler (``mujoco`` 4.0): body
masses, centres and inertias."""

import numpy as np
import pytest

from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.mjspec import compare_with_mujoco

from conftest import assert_tensor_close

mujoco = pytest.importorskip("mujoco")


def _mujoco_bodies(path):
    """name → (mass, centre, tensor in body axes) of every body but the world, from MuJoCo's compiler."""
    model = mujoco.MjModel.from_xml_path(str(path))
    out = {}
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out[model.body(i).name] = (model.body_mass[i], model.body_ipos[i].copy(),
                                   rot @ np.diag(model.body_inertia[i]) @ rot.T)
    return out


def _assert_like_mujoco(path, results, *, rtol=1e-9):
    reference = _mujoco_bodies(path)
    ours = {r.name: r for r in results}
    assert set(ours) == set(reference)
    for name, (mass, com, tensor) in reference.items():
        props = ours[name].properties
        assert props is not None, (name, ours[name].problem)
        assert props.mass == pytest.approx(mass, rel=rtol), name
        scale = max(np.linalg.norm(com), np.sqrt(np.trace(tensor) / mass))
        np.testing.assert_allclose(props.center_of_mass, com, atol=rtol * scale, err_msg=name)
        assert_tensor_close(props.inertia, tensor, rtol)


# -- height fields ------------------------------------------------------------------------------------------

HFIELD = """<mujoco><compiler inertiafromgeom="true"/>
<asset><hfield name="terrain" nrow="3" ncol="4" size="1 2 0.5 0.1" elevation="0 1 0 1 1 1 0 0 0 1 1 1"/>
<hfield name="bump" nrow="2" ncol="2" size="0.3 0.2 0.04 0.02"/></asset>
<worldbody><geom type="hfield" hfield="terrain"/>
<body name="a" pos="0 0 1"><freejoint/>
<geom type="hfield" hfield="bump" pos="0.3 0.2 0.1" euler="10 20 30" density="7"/>
<geom type="sphere" size="0.1" pos="0 0 -0.2"/></body>
</worldbody></mujoco>"""


def test_terrain_in_the_world_is_skipped_and_a_body_height_field_is_mujocos_box(tmp_path):
    path = tmp_path / "hfield.xml"
    path.write_text(HFIELD)
    robot = read_robot(path)
    results = link_inertials(robot, density="model")
    _assert_like_mujoco(path, results, rtol=1e-12)
    (a,) = results
    assert any("height field 'bump'" in w and "0.6 x 0.4 x 0.04 m" in w for w in a.warnings), a.warnings
    assert compare_with_mujoco(robot) == ()


def test_the_height_field_box_is_the_closed_form(tmp_path):
    # independent of MuJoCo: half-sizes (rx, ry, elevation/4 + base/2) at the geom's frame, one density
    path = tmp_path / "hfield.xml"
    path.write_text(HFIELD)
    props = link_inertials(read_robot(path), density=1000)[0].properties
    a, b, c = 0.6, 0.4, 2 * (0.04 / 4 + 0.02 / 2)
    box_mass = 1000 * a * b * c
    sphere_mass = 1000 * 4 / 3 * np.pi * 0.1 ** 3
    assert props.mass == pytest.approx(box_mass + sphere_mass, rel=1e-13)


def test_an_undefined_height_field_is_named(tmp_path):
    path = tmp_path / "h.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom type="hfield" hfield="nowhere"/></body>'
                    '</worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="height field 'nowhere' is not defined"):
        read_robot(path)
