"""Issue 23 (robots17's open item a): MJCF geoms chosen by MuJoCo ``group`` or default class.

``--geometry`` took collision geoms (those that can collide), visual ones (the others) or ``all`` (every geom in
``<compiler inertiagrouprange>``).  A Menagerie model puts its visual meshes in class ``visual`` (group 2) and
its collision shapes in class ``collision`` (group 3); a user may want exactly one of them, or what MuJoCo's
inertia from geometry counts for another range.  ``geometry="group=LIST"`` takes the geoms of those groups and
``geometry="class=LIST"`` those whose default class (or a class it is nested in) is named.

The reference is MuJoCo's compiler (``mujoco`` 4.0, ``inertiafromgeom="true"``): ``group=A-B`` must equal
``<compiler inertiagrouprange="A B">``, and ``class=C`` must equal MuJoCo with every geom outside ``C`` made
massless, the classes read from ``MjsGeom.classname`` and the nesting from the XML by this test's own walk.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from inertia_tool.cli import main
from inertia_tool.errors import UsageError
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.description import parse_geometry
from inertia_tool.robot.mjspec import compare_with_mujoco

from conftest import assert_tensor_close

mujoco = pytest.importorskip("mujoco")

# a body left without mass compiles with boundmass 1e-15, which MuJoCo's compiler notes as near singular
pytestmark = pytest.mark.filterwarnings("ignore:Inertia matrix is too close to singular:UserWarning")

DEFAULTS = ('<default><geom density="700"/>'
            '<default class="visual"><geom group="2" contype="0" conaffinity="0" density="300"/></default>'
            '<default class="collision"><geom group="3" density="1200"/>'
            '<default class="foot"><geom density="2500" group="4"/></default></default></default>')
SHAPES = ('type="box" size="0.05 0.1 0.02"', 'type="sphere" size="0.04"', 'type="capsule" size="0.02 0.06"',
          'type="cylinder" size="0.03 0.05"', 'type="ellipsoid" size="0.02 0.05 0.03"')


def _geom(shape: int, cls: str, group: int | None, k: int) -> str:
    attrs = SHAPES[shape] + f' pos="{0.01 * k} {0.02 * (k % 3)} {-0.01 * k}" euler="{7 * k} {11 * k} 0"'
    if cls:
        attrs += f' class="{cls}"'
    if group is not None:
        attrs += f' group="{group}"'
    return f"<geom {attrs}/>"


def _model(bodies, group_range: str = "0 5") -> str:
    """``bodies``: per body a list of (shape, class, explicit group or None); the second body is nested in the
    first with childclass collision (its class-less geoms are the collision class's)."""
    text = []
    for index, geoms in enumerate(bodies):
        child = ' childclass="collision"' if index == 1 else ""
        text.append(f'<body name="b{index}" pos="0 0 {-0.3 * index}"{child}><joint type="hinge"/>'
                    + "".join(_geom(*g, k=10 * index + j) for j, g in enumerate(geoms)))
    inner = "".join(text) + "</body>" * len(bodies)
    return (f'<mujoco model="sel"><compiler angle="degree" inertiafromgeom="true" inertiagrouprange="{group_range}" '
            f'boundmass="1e-15" boundinertia="1e-15"/>{DEFAULTS}<worldbody>{inner}</worldbody></mujoco>')


def _mujoco_bodies(spec) -> dict:
    model = spec.compile()
    out = {}
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out[model.body(i).name] = (float(model.body_mass[i]), model.body_ipos[i].copy(),
                                   rot @ np.diag(model.body_inertia[i]) @ rot.T)
    return out


def _assert_equal(results, reference, selected: dict):
    """Each body with a selected geom equals MuJoCo's; the others have no result and say which geoms."""
    assert [r.name for r in results] == list(reference)
    for r in results:
        if not selected[r.name]:
            assert r.properties is None and r.problem.startswith("no geom ")
            continue
        mass, com, tensor = reference[r.name]
        p = r.properties
        assert p.mass == pytest.approx(mass, rel=1e-9), r.name
        np.testing.assert_allclose(p.center_of_mass, com, atol=1e-10, err_msg=r.name)
        assert_tensor_close(p.inertia, tensor, 1e-9)


def _classes_by_nesting(xml: str) -> dict:
    """class → the classes it is nested in (this test's own walk of the XML)."""
    parents = {}

    def walk(element, above):
        for child in element.findall("default"):
            name = child.get("class", "main")
            if above is not None:
                parents[name] = above
            walk(child, name)
    walk(ET.fromstring(xml), None)
    return parents


def _lineage(name: str, parents: dict) -> set:
    out = {name, "main"}
    while name in parents:
        name = parents[name]
        out.add(name)
    return out


GEOMS = st.lists(st.tuples(st.integers(0, len(SHAPES) - 1), st.sampled_from(["", "visual", "collision", "foot"]),
                           st.one_of(st.none(), st.integers(0, 5))), min_size=1, max_size=3)


@settings(max_examples=25, deadline=None)
@given(bodies=st.lists(GEOMS, min_size=2, max_size=3), low=st.integers(0, 5), span=st.integers(0, 2))
def test_group_selection_equals_mujocos_inertiagrouprange(tmp_path_factory, bodies, low, span):
    high = low + span
    path = tmp_path_factory.mktemp("g") / "m.xml"
    path.write_text(_model(bodies, f"{low} {high}"))
    spec = mujoco.MjSpec.from_file(str(path))
    reference = _mujoco_bodies(spec)
    spec = mujoco.MjSpec.from_file(str(path))
    selected = {b.name: any(low <= g.group <= high for g in b.geoms) for b in spec.bodies[1:]}
    chosen = f"group={low}" + (f"-{high}" if span else "")
    robot = read_robot(path, geometry=chosen)
    _assert_equal(link_inertials(robot, density="model"), reference, selected)
    assert compare_with_mujoco(robot) == ()
    # the same geoms listed one by one, and as the file's own range ("all")
    listed = read_robot(path, geometry="group=" + ",".join(str(g) for g in range(high, low - 1, -1)))
    assert [link.elements for link in listed.links] == [link.elements for link in robot.links]
    assert [link.elements for link in read_robot(path, geometry="all").links] == [link.elements for link in robot.links]


@settings(max_examples=25, deadline=None)
@given(bodies=st.lists(GEOMS, min_size=2, max_size=3), wanted=st.sampled_from(["visual", "collision", "foot",
                                                                               "visual,foot", "main"]))
def test_class_selection_equals_mujoco_with_the_other_geoms_massless(tmp_path_factory, bodies, wanted):
    xml = _model(bodies)
    path = tmp_path_factory.mktemp("c") / "m.xml"
    path.write_text(xml)
    parents = _classes_by_nesting(xml)
    names = set(wanted.split(","))
    spec = mujoco.MjSpec.from_file(str(path))
    selected = {}
    for body in spec.bodies[1:]:
        selected[body.name] = False
        for geom in body.geoms:
            if names & _lineage(geom.classname.name, parents):
                selected[body.name] = True
            else:
                geom.mass, geom.density = 0.0, 0.0
    robot = read_robot(path, geometry=f"class={wanted}")
    _assert_equal(link_inertials(robot, density="model"), _mujoco_bodies(spec), selected)
    assert compare_with_mujoco(robot) == ()


def test_menagerie_style_classes_and_groups_pick_the_same_geoms(tmp_path):
    # the class-less geom of the childclass="collision" body is the collision class's, group 3 like the others
    path = tmp_path / "m.xml"
    path.write_text(_model([[(0, "visual", None), (1, "collision", None)], [(2, "", None), (3, "visual", None)]]))
    by_class = read_robot(path, geometry="class=collision")
    by_group = read_robot(path, geometry="group=3")
    assert [len(link.elements) for link in by_class.links] == [1, 1]
    assert [link.elements for link in by_class.links] == [link.elements for link in by_group.links]
    visual = read_robot(path, geometry="class=visual")
    assert [len(link.elements) for link in visual.links] == [1, 1]
    by_contact = read_robot(path, geometry="visual")
    assert [link.elements for link in visual.links] == [link.elements for link in by_contact.links]


@pytest.mark.parametrize("text, expected", [
    ("collision", ("collision", ())), ("all", ("all", ())), ("group=3", ("group", (3,))),
    ("group=5,0-2,1", ("group", (0, 1, 2, 5))), ("class=collision", ("class", ("collision",))),
    ("class=a,b,a", ("class", ("a", "b"))),
])
def test_parse_geometry(text, expected):
    assert parse_geometry(text) == expected


@pytest.mark.parametrize("text", ["", "visuals", "group=", "group=a", "group=3-1", "group=-1", "group=1,,2",
                                  "group=0-5000", "class=", "class=a, b", "class=a,", "colour=red", "group 3"])
def test_malformed_selections_are_one_sentence(text):
    with pytest.raises(UsageError, match="Expected `geometry` to be one of") as caught:
        parse_geometry(text)
    assert "\n" not in str(caught.value)


def test_the_command_line_names_the_problem(tmp_path, capsys):
    path = tmp_path / "m.xml"
    path.write_text(_model([[(0, "visual", None)], [(1, "", None)]]))
    assert main(["robot", str(path), "--density", "model", "--geometry", "class=colision"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"inertia-tool: error: {path} has no <default class='colision'> for --geometry 'class=colision' "
                   "(its classes: collision, foot, main, visual)")
    assert main(["robot", str(path), "--density", "model", "--geometry", "group=x"]) == 2
    assert capsys.readouterr().err.startswith("inertia-tool: error: Expected --geometry to be one of collision, "
                                              "visual, all, group=LIST")
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><collision><geometry><box size="1 1 1"/></geometry></collision>'
                    '</link></robot>')
    assert main(["robot", str(urdf), "--density", "1000", "--geometry", "group=3"]) == 2
    assert "got 'group=3' (MJCF only)" in capsys.readouterr().err
    # a body whose geoms all lie outside the selection is named apart and does not change the exit code, as a
    # URDF link with only a <visual> in a collision audit (robots17)
    assert main(["robot", str(path), "--density", "model", "--geometry", "group=2", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"geometry": "group=2"' in out and '"problem": "no geom in group 2"' in out
    assert '"summary": "2 links: 1 computed (1 exact); 1 with only geoms outside the selection and no declared mass, ' \
           'not computed: b1"' in out
