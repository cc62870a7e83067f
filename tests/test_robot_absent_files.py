"""Issue 23: a robot as shipped with a file left out still gets every link it can.

"Every link gets an answer or a reason, visibly ... a non-zero exit code (with a summary line) when any link has
no result.  A link's failure never aborts the robot."  MuJoCo Menagerie's RealSense D435i names
``assets/d435i_8.obj``, which that fork lacks; osrf gazebo_models' ``iris_with_standoffs_demo`` includes two models
that are not in the collection.  ``inertia-tool robot`` reads every description with
``read_robot(missing_meshes="per-link")``: a link whose mesh file is absent says which file (and a near match, if
one exists; nothing is read in its place), an SDFormat ``<include>`` whose model is absent becomes one entry
``NAME::*`` with the reason, every other link is computed, and the command exits with ``EXIT_INCOMPLETE`` (5)
after the summary line.  Before, the command refused the whole description (exit 3).  The API's default is still
to refuse, as MuJoCo, urdfdom and SDFormat do.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from inertia_tool.cli import EXIT_INCOMPLETE, EXIT_OK, main
from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import read_robot

from conftest import write_binary_stl

#: The corner tetrahedron of edge 0.125 m (exact in an STL's float32): volume 0.125³ / 6, wound outwards.
TETRA = 0.125 * np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
TETRA_VOLUME = 0.125 ** 3 / 6


def _link(name: str, geometry: str) -> str:
    return f'<link name="{name}"><collision><geometry>{geometry}</geometry></collision></link>'


def _run(argv, capsys) -> tuple[int, str, str]:
    code = main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_urdf_an_absent_mesh_is_its_links_reason_and_the_others_compute(tmp_path, capsys):
    (tmp_path / "meshes").mkdir()
    write_binary_stl(tmp_path / "meshes" / "tetra.stl", TETRA, TETRA_FACES)
    (tmp_path / "meshes" / "gone.obj").write_text("v 0 0 0\n")                     # the near match named
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + _link("box", '<box size="0.1 0.2 0.3"/>')
                    + _link("gone", '<mesh filename="meshes/gone.stl"/>')
                    + _link("tetra", '<mesh filename="meshes/tetra.stl"/>') + "</robot>")
    with pytest.raises(RobotDescriptionError, match="gone.stl, which does not exist"):
        read_robot(str(urdf))                   # the API's default is unchanged
    code, out, err = _run(["robot", str(urdf), "--density", "1000"], capsys)
    assert code == EXIT_INCOMPLETE
    absent = tmp_path / "meshes" / "gone.stl"
    assert f"gone: mesh file missing: {absent} (near match: {tmp_path / 'meshes' / 'gone.obj'} " in out
    assert out.rstrip().endswith("3 links: 2 computed (2 exact); 1 without a result: gone")
    code, out, err = _run(["robot", str(urdf), "--density", "1000", "--json"], capsys)
    assert code == EXIT_INCOMPLETE
    report = json.loads(out)
    box, gone, tetra = report["links"]
    assert box["mass"] == pytest.approx(1000 * 0.1 * 0.2 * 0.3, rel=1e-12) and box["method"] == "exact"
    assert tetra["mass"] == pytest.approx(1000 * TETRA_VOLUME, rel=1e-12) and tetra["method"] == "exact"
    assert gone["mass"] is None and gone["method"] is None and str(absent) in gone["problem"]
    assert report["links_without_result"] == ["gone"]
    assert "inertia-tool robot: 3 links: 2 computed (2 exact); 1 without a result: gone\n" in err


def test_urdf_write_corrects_the_computed_links_and_names_the_absent_one(tmp_path, capsys):
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">' + _link("box", '<box size="0.1 0.2 0.3"/>')
                    + _link("gone", '<mesh filename="gone.stl"/>') + "</robot>")
    out_file = tmp_path / "out.urdf"
    code, out, err = _run(["robot", str(urdf), "--density", "1000", "--write", str(out_file)], capsys)
    assert code == EXIT_INCOMPLETE
    assert "<inertial> of 1 link corrected; left as they were: gone (mesh file missing: " in err
    written = read_robot(str(out_file), missing_meshes="per-link")
    assert written.link("box").declared.mass == pytest.approx(6.0, rel=1e-12)
    assert written.link("gone").declared is None


def test_sdf_an_absent_included_model_is_one_entry_with_its_reason(tmp_path, capsys):
    sdf = tmp_path / "model.sdf"
    sdf.write_text('<sdf version="1.6"><model name="m"><link name="body"><collision name="c"><geometry><box>'
                   '<size>0.1 0.2 0.3</size></box></geometry></collision></link>'
                   '<include><uri>model://nowhere_here</uri></include>'
                   '<include><uri>model://nowhere_else</uri><name>cam</name></include></model></sdf>')
    with pytest.raises(RobotDescriptionError, match="cannot find model 'nowhere_here'"):
        read_robot(str(sdf))
    code, out, err = _run(["robot", str(sdf), "--density", "1000", "--json"], capsys)
    assert code == EXIT_INCOMPLETE
    report = json.loads(out)
    body, here, cam = report["links"]
    assert body["mass"] == pytest.approx(6.0, rel=1e-12)
    assert here["name"] == "nowhere_here::*" and "cannot find model 'nowhere_here'" in here["problem"]
    assert cam["name"] == "cam::*" and "cannot find model 'nowhere_else'" in cam["problem"]
    assert report["links_without_result"] == ["nowhere_here::*", "cam::*"]
    # an include that is malformed (not absent) still refuses the description
    sdf.write_text('<sdf version="1.6"><model name="m"><include><uri>ftp://x/y</uri></include></model></sdf>')
    code, out, err = _run(["robot", str(sdf), "--density", "1000"], capsys)
    assert code == 3 and "unsupported URI scheme 'ftp'" in err


def test_mjcf_a_primitive_fitted_to_an_absent_mesh_is_named(tmp_path, capsys):
    """RealSense D435i: the collision capsule is fitted to ``d435i_8.obj``, which is absent."""
    (tmp_path / "assets").mkdir()
    write_binary_stl(tmp_path / "assets" / "tetra.stl", TETRA, TETRA_FACES)
    xml = tmp_path / "m.xml"
    xml.write_text('<mujoco><compiler meshdir="assets"/><asset><mesh file="tetra.stl"/><mesh file="gone.obj"/>'
                   '</asset><worldbody><body name="cam"><geom type="capsule" mesh="gone"/></body>'
                   '<body name="part"><geom type="mesh" mesh="tetra"/></body></worldbody></mujoco>')
    code, out, err = _run(["robot", str(xml), "--density", "1000", "--json"], capsys)
    assert code == EXIT_INCOMPLETE
    cam, part = json.loads(out)["links"]
    assert f"mesh file missing: {tmp_path / 'assets' / 'gone.obj'}" == cam["problem"]
    assert part["mass"] == pytest.approx(1000 * TETRA_VOLUME, rel=1e-12)


@settings(max_examples=12, deadline=None)
@given(sizes=st.lists(st.tuples(*[st.floats(0.01, 2.0)] * 3), min_size=1, max_size=5),
       absent=st.lists(st.booleans(), min_size=5, max_size=5), density=st.floats(10.0, 20000.0))
def test_every_link_present_is_computed_whichever_are_absent(tmp_path_factory, sizes, absent, density):
    """Any subset of the links' meshes absent: exactly those links have no result, named in the summary; the
    others have their closed-form mass; the exit code is 5 if any is absent, else 0."""
    from conftest import box_arrays
    folder = tmp_path_factory.mktemp("r")
    links = []
    for k, size in enumerate(sizes):
        if not absent[k]:
            vertices, faces = box_arrays(size)
            write_binary_stl(folder / f"l{k}.stl", vertices, faces)
        links.append(_link(f"l{k}", f'<mesh filename="l{k}.stl"/>'))
    urdf = folder / "r.urdf"
    urdf.write_text('<robot name="r">' + "".join(links) + "</robot>")
    import contextlib
    import io
    with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()):
        code = main(["robot", str(urdf), "--density", repr(density), "--json"])
    report = json.loads(out.getvalue())
    gone = [f"l{k}" for k in range(len(sizes)) if absent[k]]
    assert code == (EXIT_INCOMPLETE if gone else EXIT_OK)
    assert report["links_without_result"] == gone
    for k, (link, size) in enumerate(zip(report["links"], sizes)):
        if absent[k]:
            assert link["mass"] is None and str(folder / f"l{k}.stl") in link["problem"]
        else:
            edges = 2 * np.float32(np.asarray(size) / 2).astype(float)       # the STL's float32 corners
            assert link["mass"] == pytest.approx(density * float(np.prod(edges)), rel=1e-12)
