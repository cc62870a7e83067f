"""A link without geometry of the chosen kind says which kind it has (example-robot-data's Cassie: 26 of its
35 SDFormat links have only a <visual>, so `--geometry collision` computed 9)."""

import pytest

from inertia_tool.robot import link_inertials, read_robot

URDF = """<robot name="r">
  <link name="both"><collision><geometry><box size="1 1 1"/></geometry></collision>
    <visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <link name="seen"><visual><geometry><sphere radius="0.1"/></geometry></visual>
    <visual><geometry><sphere radius="0.2"/></geometry></visual></link>
  <link name="frame"/>
</robot>"""

SDF = """<sdf version="1.6"><model name="m">
  <link name="seen"><visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link>
</model></sdf>"""

MJCF = """<mujoco><worldbody><body name="seen"><geom type="box" size="1 1 1" contype="0" conaffinity="0"/>
</body></worldbody></mujoco>"""


@pytest.mark.parametrize("name, text, count", [("r.urdf", URDF, 2), ("m.sdf", SDF, 1), ("m.xml", MJCF, 1)])
def test_a_link_with_visual_geometry_only_says_so(tmp_path, name, text, count):
    path = tmp_path / name
    path.write_text(text)
    results = {r.name: r for r in link_inertials(read_robot(str(path)), density=1000.0)}
    seen = results["seen"]
    element = "elements" if count > 1 else "element"
    assert seen.problem == f"no collision geometry; {count} visual {element}, which --geometry visual reads"
    visual = {r.name: r for r in link_inertials(read_robot(str(path), geometry="visual"), density=1000.0)}
    assert visual["seen"].properties is not None
    if "frame" in results:
        assert results["frame"].problem == "no collision geometry"
