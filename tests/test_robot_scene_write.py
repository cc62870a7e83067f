"""Issue 23: ``robot scene.xml --write`` on a Menagerie-style scene (a main file that only includes the robot's
file) says where the bodies it did not correct are, and which file to write instead; it listed every body as
"no element of its own in the file"."""

from __future__ import annotations

from inertia_tool.cli import EXIT_OK, main
from inertia_tool.robot import read_robot
from inertia_tool.robot.write import included_files

ROBOT = """<mujoco model="arm">
  <worldbody>
    <body name="base"><geom type="box" size="0.1 0.2 0.3"/>
      <inertial pos="0 0 0" mass="2" diaginertia="1 1 1"/>
      <body name="tip" pos="0 0 0.5"><geom type="sphere" size="0.05"/></body>
    </body>
  </worldbody>
</mujoco>
"""


def _scene(tmp_path):
    (tmp_path / "arm.xml").write_text(ROBOT)
    (tmp_path / "scene.xml").write_text('<mujoco model="scene">\n  <include file="arm.xml"/>\n  <worldbody>\n'
                                        '    <geom name="floor" type="plane" size="0 0 0.05"/>\n  </worldbody>\n'
                                        '</mujoco>\n')
    return str(tmp_path / "scene.xml")


def test_a_scene_names_the_included_file_to_write(tmp_path, capsys):
    scene = _scene(tmp_path)
    out = tmp_path / "out" / "scene.xml"
    out.parent.mkdir()
    assert main(["robot", scene, "--density", "1000", "--write", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    (line,) = [x for x in err.splitlines() if x.startswith("wrote ")]
    assert line == (f"wrote {out}: <inertial> of 0 links corrected; left as they were: 2 computed bodies of arm.xml, "
                    "which this file includes (only the main file is written: run --write on arm.xml to correct "
                    "them): base, tip")
    assert "no element of its own" not in err


def test_a_file_with_bodies_of_its_own_names_no_included_file(tmp_path):
    _scene(tmp_path)
    assert included_files(read_robot(str(tmp_path / "arm.xml"))) == ()
    assert included_files(read_robot(str(tmp_path / "scene.xml"))) == ("arm.xml",)
