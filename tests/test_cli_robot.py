"""``inertia-tool robot``: JSON, table, --write, and one-line errors with the documented exit codes."""

import json
import re

import numpy as np
import pytest

from inertia_tool.cli import EXIT_INCOMPLETE, main

from conftest import assert_tensor_close
from robot_data import ERD, PANDA, UR5

PKG = f"example-robot-data={ERD}"


def test_json_lists_every_link_with_declared_and_audit(capsys):
    assert main(["robot", str(UR5), "--package", PKG, "--material", "aluminium", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["format"] == "urdf" and out["geometry"] == "collision"
    links = {link["name"]: link for link in out["links"]}
    upper = links["upper_arm_link"]
    assert upper["density"] == 2700.0 and upper["mass"] == pytest.approx(2700.0 * upper["volume"])
    assert np.asarray(upper["inertia"]).shape == (3, 3)
    assert upper["declared"]["mass"] == 8.393 and upper["declared"]["center_of_mass"] == [0, 0, 0.28]
    assert set(upper["audit"]) >= {"com_distance", "inertia_difference", "declared_positive_definite",
                                   "declared_triangle_inequality", "implied_density", "com_inside_geometry", "issues"}
    assert links["world"]["mass"] is None and links["world"]["declared"] is None


def test_keep_mass_table_and_write(tmp_path, capsys):
    out = tmp_path / "panda_fixed.urdf"
    assert main(["robot", str(PANDA), "--package", PKG, "--keep-mass", "--write", str(out)]) == 0
    captured = capsys.readouterr()
    assert "panda_link1" in captured.out and "declared masses kept" in captured.out
    assert f"wrote {out}" in captured.err
    assert main(["robot", str(out), "--package", PKG, "--keep-mass", "--json"]) == 0
    again = {link["name"]: link for link in json.loads(capsys.readouterr().out)["links"]}
    link = again["panda_link3"]
    assert link["audit"]["com_distance"] < 1e-15 and link["audit"]["inertia_difference"] < 1e-14
    assert_tensor_close(link["declared"]["inertia"], link["inertia"], 1e-14)
    # an existing file is not replaced without --force
    assert main(["robot", str(PANDA), "--package", PKG, "--keep-mass", "--write", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


def test_unresolved_uri_is_one_line_exit_3(capsys, monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    assert main(["robot", str(UR5), "--density", "2700"]) == 3
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "link 'base_link'" in err
    assert "package://example-robot-data/robots/ur_description/meshes/ur5/collision/base.stl" in err


@pytest.mark.parametrize("argv, message", [
    (["--density", "1", "--keep-mass"], "not allowed with"),
    ([], "one of the arguments --density --material --keep-mass is required"),
    (["--density", "1", "--package", "nodir"], "--package expects NAME=DIR"),
    (["--density", "1", "--arg", "x=1"], "--arg expects NAME:=VALUE"),
    (["--density", "1", "--force"], "--force only applies to --write"),
])
def test_usage_errors(argv, message, capsys):
    assert main(["robot", str(UR5), "--package", PKG] + argv) == 2
    assert message in capsys.readouterr().err


def test_xacro_input_writes_the_expanded_urdf(tmp_path, capsys):
    mujoco = pytest.importorskip("mujoco")
    src = tmp_path / "rod.urdf.xacro"
    src.write_text('<?xml version="1.0"?>\n<robot name="rod" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                   '  <xacro:arg name="len" default="0.4"/>\n'
                   '  <link name="rod">\n    <collision><origin xyz="0 0 ${$(arg len)/2}" rpy="0 0 0"/>\n'
                   '      <geometry><cylinder radius="0.02" length="$(arg len)"/></geometry></collision>\n'
                   '  </link>\n</robot>\n')
    out = tmp_path / "rod.urdf"
    assert main(["robot", str(src), "--run-xacro", "--arg", "len:=0.3", "--material", "steel", "--write",
                 str(out)]) == 0
    capsys.readouterr()
    assert "xacro:" not in out.read_text().split("-->", 1)[-1].replace('xmlns:xacro', '')
    text = out.read_text().replace('<robot name="rod"', '<robot name="rod"', 1)
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler fusestatic="false"/></mujoco>', text, count=1)
    model = mujoco.MjModel.from_xml_string(text)              # fusestatic off: a lone link stays a body
    mass = 7850 * np.pi * 0.02 ** 2 * 0.3
    body = model.body("rod").id
    assert model.body_mass[body] == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(model.body_ipos[body], [0, 0, 0.15], atol=1e-15)
    np.testing.assert_allclose(np.sort(model.body_inertia[body]),
                               sorted([mass * 0.02 ** 2 / 2] + [mass * (0.02 ** 2 / 4 + 0.3 ** 2 / 12)] * 2),
                               rtol=1e-12)


def test_an_open_link_mesh_is_reported_with_the_option_that_repairs_it(tmp_path, capsys):
    import trimesh
    from conftest import write_binary_stl
    # a small hole (one of 768 triangles): a bounded estimate exists (a hole as large as a side is refused)
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1)).subdivide().subdivide().subdivide()
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    write_binary_stl(tmp_path / "open.stl", v, f[:-1])
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="holed"><collision><geometry><mesh filename="open.stl"/>'
                    '</geometry></collision></link></robot>')
    assert main(["robot", str(urdf), "--density", "1000"]) == EXIT_INCOMPLETE    # a link without result
    out = capsys.readouterr().out
    assert "holed: mesh needs repair" in out and "--repair" in out and "`" not in out
    assert "holed none " in out and out.rstrip().endswith("1 link: 0 computed; 1 without a result: holed")
    assert main(["robot", str(urdf), "--density", "1000", "--repair", "--json"]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    link = report["links"][0]
    assert link["problem"] is None and link["mass"] > 0 and "repaired" in captured.err
    assert link["method"] == "estimate" and link["uncertainty"]["mass"] >= 0 and link["warnings"]
    assert report["links_without_result"] == [] and "1 estimate" in report["summary"]


def test_one_bad_link_never_stops_the_others_and_names_stay_whole(tmp_path, capsys):
    # a zero-volume mesh (a flat sheet, as UR5e's visual wrist1.dae holds) with --repair: that link has no
    # result and a reason; the long-named link beside it is computed and printed with its full name
    from conftest import box_arrays, write_binary_stl
    v, f = box_arrays((0.1, 0.1, 0.1))
    write_binary_stl(tmp_path / "box.stl", v, f)
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    write_binary_stl(tmp_path / "flat.stl", flat, np.array([[0, 1, 2], [1, 3, 2]]))
    name = "left_shoulder_pitch_link_with_a_long_name"
    urdf = tmp_path / "r.urdf"
    urdf.write_text(f'<robot name="r"><link name="sheet"><inertial><mass value="1"/><inertia ixx="1" iyy="1" '
                    'izz="1" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><mesh filename="flat.stl"/>'
                    f'</geometry></collision></link><link name="{name}"><collision><geometry>'
                    '<mesh filename="box.stl"/></geometry></collision></link><link name="frame"/></robot>')
    for extra in ([], ["--repair"]):
        assert main(["robot", str(urdf), "--density", "1000", *extra]) == EXIT_INCOMPLETE
        out = capsys.readouterr().out
        assert f"\n{name} exact " in out and re.search(r"\nframe +frame ", out)
        assert "1 without a result: sheet; 1 without geometry or mass (frames)" in out
        assert main(["robot", str(urdf), "--density", "1000", "--json", *extra]) == EXIT_INCOMPLETE
        captured = capsys.readouterr()
        report = json.loads(captured.out)
        sheet, long, frame = report["links"]
        assert sheet["mass"] is None and sheet["method"] is None and sheet["problem"]
        assert long["method"] == "exact" and long["uncertainty"] is None and long["mass"] == pytest.approx(1.0)
        assert report["links_without_result"] == ["sheet"] and "without a result: sheet" in captured.err


def test_engine_warnings_about_a_links_mesh_are_in_its_json_warnings(capsys):
    # UR5's wrist3.stl has two overlapping bodies the engine unites: that link says so, the base does not
    assert main(["robot", str(UR5), "--package", PKG, "--density", "2700", "--json"]) == 0
    captured = capsys.readouterr()
    links = {link["name"]: link for link in json.loads(captured.out)["links"]}
    assert any("wrist3.stl: overlapping bodies united" in w for w in links["wrist_3_link"]["warnings"])
    assert links["wrist_3_link"]["method"] == "united" and links["base_link"]["warnings"] == []
    assert "wrist3.stl: overlapping bodies united" in captured.err          # still said on stderr


def test_writing_an_mjcf_that_ignores_inertials_says_so(tmp_path, capsys):
    src = tmp_path / "m.xml"
    src.write_text("<mujoco><compiler inertiafromgeom='true'/><worldbody><body name='b'><freejoint/>"
                   "<geom type='box' size='0.1 0.2 0.3'/></body></worldbody></mujoco>")
    assert main(["robot", str(src), "--density", "1000", "--write", str(tmp_path / "out.xml")]) == 0
    assert 'inertiafromgeom="true"> makes MuJoCo compute the inertias from the geoms' in capsys.readouterr().err


@pytest.mark.parametrize("main_text, part_text, expected", [
    # set in an included file, with spaces around '=': MuJoCo ignores the inertials
    ("<include file='part.xml'/>", "<compiler inertiafromgeom = 'true'/>", "true"),
    # only in a comment, and overridden later in document order: MuJoCo keeps them
    ("<!-- <compiler inertiafromgeom=\"true\"/> --><compiler inertiafromgeom='true'/><include file='part.xml'/>",
     "<compiler inertiafromgeom='auto'/>", "auto"),
    ("<!-- inertiafromgeom=\"true\" -->", "", "auto"),
])
def test_inertiafromgeom_is_read_as_mujoco_reads_it(tmp_path, capsys, main_text, part_text, expected):
    mujoco = pytest.importorskip("mujoco")
    from inertia_tool.robot.mjcf import inertia_from_geometry
    (tmp_path / "part.xml").write_text(f"<mujoco>{part_text}</mujoco>")
    src = tmp_path / "m.xml"
    src.write_text(f"<mujoco>{main_text}<worldbody><body name='b'><freejoint/><inertial pos='0 0 0' mass='5' "
                   "diaginertia='1 1 1'/><geom type='box' size='0.1 0.2 0.3'/></body></worldbody></mujoco>")
    assert inertia_from_geometry(str(src)) == expected
    spec = mujoco.MjSpec.from_file(str(src))                                  # MuJoCo's own reading
    assert spec.compiler.inertiafromgeom == {"true": mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE,
                                             "auto": mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_AUTO}[expected]
    model = spec.compile()
    assert (model.body("b").mass[0] == pytest.approx(5.0)) == (expected != "true")
    assert main(["robot", str(src), "--density", "1000", "--write", str(tmp_path / "out.xml")]) == 0
    said = "makes MuJoCo compute the inertias from the geoms" in capsys.readouterr().err
    assert said == (expected == "true")


def test_links_left_as_they_were_are_named_with_their_reason(tmp_path, capsys):
    src = tmp_path / "m.xml"
    src.write_text("<mujoco><worldbody><body name='solid'><geom type='box' size='0.1 0.2 0.3'/></body>"
                   "<body name='ghost'><geom type='box' size='0.1 0.1 0.1' contype='0' conaffinity='0'/></body>"
                   "<body name='pad'><geom type='box' size='0.1 0.1 0.1' mass='0'/></body></worldbody></mujoco>")
    assert main(["robot", str(src), "--density", "model", "--write", str(tmp_path / "out.xml")]) == EXIT_INCOMPLETE
    err = capsys.readouterr().err
    assert ("<inertial> of 1 link corrected; left as they were: ghost (no collision geometry; 1 visual element, "
            "which --geometry visual reads), pad (every geom is massless in the description (--density RHO or "
            "--material M gives each geom a density))") in err
