"""Issue 23 (scenes19): a Menagerie-style scene, the file people open, read as MuJoCo compiles it.

A scene ``<include>``s the model file and adds what a simulation needs around the robot: ``<statistic>``,
``<visual>``, textures and materials, and in ``<worldbody>`` lights, cameras, a floor plane, sometimes static
world geoms (a table, walls: a box or a mesh), world sites, geoms in a world ``<frame>``, and free objects or
mocap bodies.  MuJoCo gives a plane no mass; a geom directly in ``<worldbody>`` (or in a world frame) belongs to
the world body, which is not a link of the robot; an object with its own ``<body>`` is a body like the robot's.
Checked against MuJoCo's own compile (``tests/mujoco_reference.py``), body by body.
"""

from __future__ import annotations

import pytest

from inertia_tool.cli import main
from inertia_tool.mass import shapes
from inertia_tool.robot import link_inertials, read_robot

from mujoco_reference import assert_like_mujoco

pytest.importorskip("mujoco")

ROBOT = """<mujoco model="arm">
  <compiler angle="radian" meshdir="assets"/>
  <asset><mesh name="cone" file="cone.stl" scale="0.001 0.001 0.001"/></asset>
  <worldbody>
    <body name="base" pos="0 0 0.1">
      <geom type="cylinder" size="0.05 0.02" density="2700"/>
      <body name="link" pos="0 0 0.05">
        <joint type="hinge" axis="0 0 1"/>
        <geom type="box" size="0.02 0.03 0.1" pos="0 0 0.1" euler="0.1 0.2 0.3"/>
        <geom type="mesh" mesh="cone" pos="0 0 0.2"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

SCENE = """<mujoco model="arm scene">
  <include file="arm.xml"/>
  <statistic center="0 0 0.3" extent="0.8"/>
  <visual><headlight diffuse="0.6 0.6 0.6"/><global azimuth="120" elevation="-20"/></visual>
  <asset>
    <texture type="2d" name="grid" builtin="checker" rgb1="0.2 0.3 0.4" rgb2="0.1 0.2 0.3" width="300" height="300"/>
    <material name="grid" texture="grid" texrepeat="5 5" reflectance="0.2"/>
    <mesh name="table_top" file="cone.stl" scale="0.01 0.01 0.001"/>
  </asset>
  <worldbody>
    <light pos="0 0 1.5" dir="0 0 -1" directional="true"/>
    <camera name="front" pos="1 0 0.5" xyaxes="0 1 0 -0.4 0 1"/>
    <geom name="floor" size="0 0 0.05" type="plane" material="grid"/>
    <geom name="wall" type="box" size="0.01 1 0.5" pos="-1 0 0.5"/>
    <geom name="table" type="mesh" mesh="table_top" pos="0.5 0 0"/>
    <site name="target" pos="0.3 0 0.3" size="0.01"/>
    <frame pos="0 1 0"><geom type="sphere" size="0.1"/></frame>
    <body name="object" pos="0.4 0 0.05">
      <freejoint/>
      <geom type="box" size="0.02 0.02 0.02" density="500"/>
    </body>
    <body name="shelf" pos="0 -0.5 0.2">
      <geom type="box" size="0.1 0.1 0.01" density="800"/>
      <geom type="plane" size="0.1 0.1 0.1" pos="0 0 0.011"/>
    </body>
    <body name="goal" mocap="true" pos="0.3 0.1 0.3">
      <geom type="sphere" size="0.03" contype="0" conaffinity="0" rgba="0 1 0 0.3"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def scene(tmp_path):
    (tmp_path / "assets").mkdir()
    shapes.write_stl(shapes.cone(20.0, 50.0, segments=24), tmp_path / "assets" / "cone.stl")
    (tmp_path / "arm.xml").write_text(ROBOT)
    (tmp_path / "scene.xml").write_text(SCENE)
    return tmp_path / "scene.xml"


def test_a_scene_has_the_bodies_mujoco_compiles_and_their_inertia(scene):
    # the floor, the wall, the table, the world frame's sphere: world geoms, no link; the shelf's plane adds
    # nothing (MuJoCo gives a plane no mass, and allows one only in a body fixed to the world); every geom
    # counts (MuJoCo's inertia from geometry)
    robot = read_robot(scene, geometry="all")
    assert [link.name for link in robot.links] == ["base", "link", "object", "shelf", "goal"]
    results = link_inertials(robot, density="model")
    assert [r.method for r in results] == ["exact"] * 5
    assert_like_mujoco(scene, results, rtol=1e-9)
    shelf = results[3].properties
    assert shelf.mass == pytest.approx(800 * 0.2 * 0.2 * 0.02, rel=1e-12)    # the plane weighs nothing
    assert shelf.center_of_mass == pytest.approx([0, 0, 0], abs=1e-15)


def test_the_scene_and_its_model_give_the_robot_the_same_numbers(scene):
    # what the scene adds changes no body of the robot, to the last bit (collision geometry, as the command)
    alone = {r.name: r.properties for r in link_inertials(read_robot(scene.parent / "arm.xml"), density="model")}
    in_scene = {r.name: r.properties for r in link_inertials(read_robot(scene), density="model")}
    assert set(in_scene) == {"base", "link", "object", "shelf", "goal"}
    for name in alone:
        a, b = alone[name], in_scene[name]
        assert (a.mass, a.center_of_mass.tolist(), a.inertia.tolist()) == (
            b.mass, b.center_of_mass.tolist(), b.inertia.tolist())
    assert in_scene["goal"] is None                # its only geom does not collide


def test_the_command_lists_no_world_link(scene, capsys):
    code = main(["robot", str(scene), "--density", "model"])
    out = capsys.readouterr().out
    assert code == 0                          # goal: no collision geometry and no mass, a frame, as MuJoCo's
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("-----")) + 1
    table = lines[start:lines.index("", start)]
    assert [line.split()[0] for line in table] == ["base", "link", "object", "shelf", "goal"]
    assert "goal: no collision geometry" in out


def test_a_scene_of_world_geoms_only_is_refused_in_one_line(tmp_path):
    # terrain without a body: nothing to compute, said rather than an empty table
    path = tmp_path / "terrain.xml"
    path.write_text('<mujoco><worldbody><geom type="plane" size="1 1 0.1"/><geom type="box" size="1 1 0.1"/>'
                    '</worldbody></mujoco>')
    from inertia_tool.errors import RobotDescriptionError
    with pytest.raises(RobotDescriptionError, match="no bodies: every geom is in <worldbody>"):
        read_robot(path)
