"""Issue 23 (robots17's open item b): an MJCF ``<attach model>`` whose model file is absent is the reason of the
bodies it would have brought, not of the whole description.

robots17 made an absent mesh file one link's reason in every format, and an absent SDFormat ``<include>`` one
entry ``NAME::*``; an absent ``<asset><model file>`` still refused the MJCF file (exit 3).  With
``read_robot(missing_meshes="per-link")`` (the command line, the corpus) it is now one entry ``PREFIX*`` standing
for the attached bodies (MuJoCo names them all with the prefix), and a body that an attached ``<worldbody>``
would have given geoms says so too; every other body is computed as with the file present (compared exactly
with that run, itself checked against MuJoCo in ``tests/test_robot_mjcf_extras.py``), and the command exits 5.
"""

from __future__ import annotations

import json

import pytest

from inertia_tool.cli import EXIT_INCOMPLETE, main
from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import link_inertials, read_robot

from test_robot_mjcf_extras import attached  # noqa: F401 -- the fixture: a model attaching two others

FULL = ["base", "first", "c_hand", "body 4", "c_finger", "c_g_tip", "last", "w_tip", "w_other"]


@pytest.mark.parametrize("gone, names, unread", [
    (["child.xml"], ["base", "first", "c_*", "last", "w_tip", "w_other"], {"c_*": "child.xml"}),
    (["grand.xml"], ["base", "first", "c_hand", "body 4", "c_finger", "c_g_*", "last", "w_*"],
     {"c_g_*": "grand.xml", "last": "grand.xml", "w_*": "grand.xml"}),
    (["child.xml", "grand.xml"], ["base", "first", "c_*", "last", "w_*"],
     {"c_*": "child.xml", "last": "grand.xml", "w_*": "grand.xml"}),
])
def test_an_absent_attached_model_is_the_reason_of_its_bodies_only(attached, gone, names, unread):  # noqa: F811
    full = {r.name: r for r in link_inertials(read_robot(attached), density="model")}
    assert list(full) == FULL
    for name in gone:
        (attached.parent / "sub" / name).unlink()
    with pytest.raises(RobotDescriptionError, match="the model file .* does not exist"):
        read_robot(attached)                       # the API's default is unchanged
    robot = read_robot(attached, missing_meshes="per-link")
    results = link_inertials(robot, density="model")
    assert [r.name for r in results] == names
    for r in results:
        if r.name in unread:
            assert r.properties is None
            assert r.problem.startswith("attached model not read: <attach model=")
            assert f"the model file {attached.parent / 'sub' / unread[r.name]} does not exist" in r.problem
            assert ("(its geoms would be part of this body)" in r.problem) == (not r.name.endswith("*"))
        else:                                      # computed as with every file present, to the last bit
            mine, theirs = r.properties, full[r.name].properties
            assert (mine.mass, mine.center_of_mass.tolist(), mine.inertia.tolist()) == (
                theirs.mass, theirs.center_of_mass.tolist(), theirs.inertia.tolist())


def test_the_command_computes_the_rest_and_exits_5(attached, capsys):  # noqa: F811
    (attached.parent / "sub" / "child.xml").unlink()
    (attached.parent / "sub" / "Child.xml").write_text("<mujoco/>")          # named as a near match, not read
    code = main(["robot", str(attached), "--density", "model"])
    out = capsys.readouterr().out
    assert code == EXIT_INCOMPLETE
    assert out.rstrip().endswith("6 links: 5 computed (5 exact); 1 without a result: c_*")
    (line,) = [t for t in out.splitlines() if t.startswith("  c_*: ")]
    assert line.startswith(f"  c_*: attached model not read: <attach model='c'> in {attached}: the model file "
                           f"{attached.parent / 'sub' / 'child.xml'} does not exist (near match: "
                           f"{attached.parent / 'sub' / 'Child.xml'}")
    assert main(["robot", str(attached), "--density", "model", "--json"]) == EXIT_INCOMPLETE
    report = json.loads(capsys.readouterr().out)
    assert report["links_without_result"] == ["c_*"]
    assert [link["mass"] is None for link in report["links"]] == [False, False, True, False, False, False]
