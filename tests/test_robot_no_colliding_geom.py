"""Issue 23 (robots17): an MJCF robot whose geoms collide only through a scene's contact pairs says so.

MuJoCo Menagerie's Apptronik Apollo gives its collision class ``contype="0" conaffinity="0"``; only
``scene.xml``, which includes the robot, collides some of them through ``<contact><pair>``.  Read alone, MuJoCo
finds no contact with any of its geoms, and the tool (which takes MuJoCo's collision geoms) computed 0 of 36
links, each "no collision geometry", without saying why or where the pairs are.  It now warns once
(``NoCollidingGeomWarning``, in the JSON ``warnings``), naming the files beside it that include it; audited
through the scene, the paired geoms are computed (a capsule's closed form here).
"""

from __future__ import annotations

import json
import math

import pytest

from inertia_tool.cli import EXIT_INCOMPLETE, main

ROBOT = ('<mujoco model="r"><default><default class="collision"><geom contype="0" conaffinity="0" group="3"/>'
         '</default></default><worldbody>'
         '<body name="pelvis"><inertial pos="0 0 0" mass="5" diaginertia="0.1 0.1 0.1"/>'
         '<geom name="pelvis_capsule" class="collision" type="capsule" size="0.1 0.09"/>'
         '<geom type="sphere" size="0.05" contype="0" conaffinity="0" group="1"/>'
         '<body name="arm" pos="0 0 -0.3"><inertial pos="0 0 0" mass="2" diaginertia="0.1 0.1 0.1"/>'
         '<geom name="arm_box" class="collision" type="box" size="0.1 0.1 0.1"/>'
         '</body></body></worldbody></mujoco>')
SCENE = ('<mujoco model="scene"><include file="robot.xml"/><worldbody><geom name="floor" type="plane" '
         'size="1 1 0.1"/></worldbody><contact><pair geom1="pelvis_capsule" geom2="floor"/></contact></mujoco>')


def test_the_robot_alone_names_the_scene_and_the_scene_computes_the_paired_geom(tmp_path, capsys):
    (tmp_path / "robot.xml").write_text(ROBOT)
    (tmp_path / "scene.xml").write_text(SCENE)
    (tmp_path / "other.xml").write_text('<mujoco><include file="elsewhere.xml"/></mujoco>')   # not this robot
    assert main(["robot", str(tmp_path / "robot.xml"), "--density", "1000", "--json"]) == EXIT_INCOMPLETE
    report = json.loads(capsys.readouterr().out)
    (warning,) = [w for w in report["warnings"] if "no geom collides" in w]
    assert f"{tmp_path / 'scene.xml'} includes it" in warning and "other.xml" not in warning
    assert "all 3 have contype and conaffinity 0" in warning
    assert warning.endswith("--geometry class=collision reads the geoms of its class 'collision', --geometry visual "
                            "all the geoms that do not collide (visual and collision shapes together)")
    assert main(["robot", str(tmp_path / "robot.xml"), "--density", "1000", "--geometry", "class=collision"]) == 0
    assert capsys.readouterr().out.rstrip().endswith("2 links: 2 computed (2 exact)")
    assert [link["mass"] for link in report["links"]] == [None, None]
    assert all(link["problem"].startswith("no collision geometry") for link in report["links"])

    assert main(["robot", str(tmp_path / "scene.xml"), "--density", "1000", "--json"]) == EXIT_INCOMPLETE
    report = json.loads(capsys.readouterr().out)
    assert not [w for w in report["warnings"] if "no geom collides" in w]
    pelvis, arm = report["links"]
    r, h = 0.1, 0.09                       # MuJoCo's capsule: radius, half-length of the cylinder
    assert pelvis["mass"] == pytest.approx(1000 * math.pi * r * r * (2 * h + 4 * r / 3), rel=1e-12)
    assert arm["mass"] is None and arm["problem"].startswith("no collision geometry")


def test_no_warning_where_a_geom_collides(tmp_path, capsys):
    (tmp_path / "robot.xml").write_text(ROBOT.replace('type="box"', 'type="box" contype="1"'))
    assert main(["robot", str(tmp_path / "robot.xml"), "--density", "1000", "--json"]) == EXIT_INCOMPLETE
    report = json.loads(capsys.readouterr().out)
    assert not [w for w in report["warnings"] if "no geom collides" in w]
    assert report["links"][1]["mass"] == pytest.approx(8.0, rel=1e-12)


def test_a_link_with_only_the_other_kind_of_geometry_is_no_frame(tmp_path, capsys):
    """A link with a ``<visual>`` only and no ``<inertial>`` was counted "without geometry or mass (frames)" in
    a collision audit; it has geometry: the summary names it apart, the table says ``none`` and lists why."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="shown"><visual><geometry><box size="1 1 1"/></geometry></visual>'
                    '</link><link name="body"><collision><geometry><box size="1 2 1"/></geometry></collision></link>'
                    '<link name="tool0"/></robot>')
    assert main(["robot", str(urdf), "--density", "1000"]) == 0
    out = capsys.readouterr().out
    assert out.rstrip().endswith("3 links: 1 computed (1 exact); 1 with only visual geometry and no declared mass, "
                                 "not computed: shown; 1 without geometry or mass (frames)")
    assert "\nshown none " in out and "\ntool0 frame " in out
    assert "  shown: no collision geometry; 1 visual element, which --geometry visual reads" in out
    assert main(["robot", str(urdf), "--density", "1000", "--geometry", "visual"]) == 0
    assert "1 with only collision geometry and no declared mass, not computed: body" in capsys.readouterr().out


def test_the_corpus_mode_warns_as_the_single_file_command_does(tmp_path, capsys):
    """The corpus path (several files or a folder) read each model without the single-file command's check, so
    Apollo's "no collision geometry" ×35 came without the warning saying why (robots17's open item)."""
    (tmp_path / "robot.xml").write_text(ROBOT)
    (tmp_path / "scene.xml").write_text(SCENE)
    box = tmp_path / "box.urdf"
    box.write_text('<robot name="b"><link name="b"><collision><geometry><box size="1 1 1"/></geometry></collision>'
                   '</link></robot>')
    argv = ["robot", str(tmp_path / "robot.xml"), str(box), "--density", "1000", "--json"]
    assert main(argv) == EXIT_INCOMPLETE
    report = json.loads(capsys.readouterr().out)
    (warning,) = [w for w in report["warnings"] if "no geom collides" in w]
    assert warning.startswith(f"{tmp_path / 'robot.xml'}: no geom collides (all 3 have contype and conaffinity 0")
    assert f"{tmp_path / 'scene.xml'} includes it" in warning
    # a folder audits the robot through its scene, whose pair collides a geom: no warning there
    assert main(["robot", str(tmp_path), "--density", "1000", "--json"]) == EXIT_INCOMPLETE
    assert not [w for w in json.loads(capsys.readouterr().out)["warnings"] if "no geom collides" in w]
