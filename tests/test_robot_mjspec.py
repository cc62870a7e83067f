"""The built-in MJCF reader against MuJoCo's own reading (inertia_tool.robot.mjspec): bodies, the geoms each
geometry selects, primitive sizes and placements, mesh files — on real models (Menagerie's 2F-85 linkage,
Gymnasium's humanoid and walker) and on constructed ones that exercise classes, frames, replicate, fromto,
eulerseq and contact pairs; and the comparison itself must see a difference when there is one."""

from pathlib import Path

import pytest

from inertia_tool.robot import read_robot
from inertia_tool.robot.mjspec import compare_with_mujoco

pytest.importorskip("mujoco")

DATA = Path(__file__).parent / "data" / "robots"

SCENE = """<mujoco><compiler angle="radian" eulerseq="zyx"/>
<default><geom contype="0" conaffinity="0"/><default class="limb"><geom type="capsule" size="0.03"/></default>
<default class="slab"><geom type="box" size="0.1 0.2 0.3" euler="0.3 0.2 0.1"/></default></default>
<worldbody><body name="torso" childclass="limb"><geom name="t" fromto="0 0 0 0.1 0.2 0.3"/>
<frame pos="0.1 0 0" euler="0 0.5 0"><geom name="s" class="slab" size="0.05" quat="0.9 0.1 0.2 0.3"/></frame>
<replicate count="3" sep="-" offset="0.2 0 0"><body name="finger"><geom name="f" zaxis="1 1 0" size="0.02 0.1"/>
</body></replicate>
<body><geom name="e" type="ellipsoid" size="0.1 0.2 0.05" xyaxes="1 1 0 -1 1 1"/></body></body>
<body name="foot"><geom name="sole" type="cylinder" size="0.05 0.02" axisangle="1 0 0 0.4"/></body>
</worldbody><contact><pair geom1="sole" geom2="t"/></contact></mujoco>"""


@pytest.mark.parametrize("path", [DATA / "menagerie_2f85" / "2f85_right_finger.xml",
                                  DATA / "gymnasium" / "humanoid.xml", DATA / "gymnasium" / "walker2d.xml"],
                         ids=lambda p: p.name)
@pytest.mark.parametrize("geometry", ["collision", "visual", "all"])
def test_real_models_are_read_as_mujoco_reads_them(path, geometry):
    assert compare_with_mujoco(read_robot(path, geometry=geometry)) == ()


@pytest.mark.parametrize("geometry", ["collision", "visual", "all"])
def test_classes_frames_replicate_fromto_and_pairs_are_read_as_mujoco_reads_them(tmp_path, geometry):
    path = tmp_path / "scene.xml"
    path.write_text(SCENE)
    robot = read_robot(path, geometry=geometry)
    assert len(robot.links) == 6 and compare_with_mujoco(robot) == ()


def test_a_different_reading_is_seen(tmp_path):
    # the reader's description of one file compared with MuJoCo's reading of a slightly different one
    path = tmp_path / "scene.xml"
    path.write_text(SCENE)
    robot = read_robot(path, geometry="all")
    for change, expected in [('size="0.05"', "size and orientation differ"),
                             ('pos="0.1 0 0" euler', "puts its centre at"),
                             ('axisangle="1 0 0 0.4"', "size and orientation differ"),
                             ('<body name="foot">', "MuJoCo has 7 bodies"),
                             ('name="sole" type="cylinder"', "reads a sphere")]:
        replacement = {'size="0.05"': 'size="0.06"', 'pos="0.1 0 0" euler': 'pos="0.1 0 1e-3" euler',
                       'axisangle="1 0 0 0.4"': 'axisangle="1 0 0 0.41"',
                       '<body name="foot">': '<body name="extra"/><body name="foot">',
                       'name="sole" type="cylinder"': 'name="sole" type="sphere"'}[change]
        path.write_text(SCENE.replace(change, replacement, 1))
        found = compare_with_mujoco(robot)
        assert found and expected in found[0], (change, found)
    path.write_text("<mujoco><worldbody><body><geom type='box' size='0 1 1'/></body></worldbody></mujoco>")
    assert compare_with_mujoco(robot)[0].startswith("MuJoCo refuses the model")
