"""Gazebo model folders and ROS packages as they are shipped (issue 23 item 4): model:// and package:// found
around the description without environment variables, SDFormat <include> and nested models, a licence comment
before the XML declaration, COLLADA files whose <image> has no path and whose triangles are in <polylist>."""

import json
import re

import numpy as np
import pytest

from inertia_tool.errors import RobotDescriptionError, SkippedModelWarning
from inertia_tool.mass import shapes
from inertia_tool.mesh.read import load_mesh
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.write import write_corrected
from inertia_tool.reports.robot_audit import links_without_result

LICENCE = b"<!--\n  Copyright (c) a robot maker. Licensed under the Apache License, Version 2.0.\n-->\n"


def _box_model(folder, name, link, size, *, extra="", licence=False):
    (folder / "meshes").mkdir(parents=True)
    shapes.write_stl(shapes.box(*size), folder / "meshes" / f"{link}.stl")
    (folder / "model.config").write_text(f"<?xml version='1.0'?>\n<model><name>{name}</name>"
                                         "<sdf version='1.6'>robot.sdf</sdf></model>\n")
    text = (f'<?xml version="1.0" encoding="UTF-8"?>\n<sdf version="1.6">\n  <model name="{name}">\n'
            f'    <link name="{link}">\n      <collision name="c">\n        <geometry><mesh>'
            f'<uri>model://{name}/meshes/{link}.stl</uri></mesh></geometry>\n      </collision>\n    </link>\n'
            f'{extra}  </model>\n</sdf>\n').encode()
    (folder / "robot.sdf").write_bytes((LICENCE if licence else b"") + text)
    return folder / "robot.sdf"


@pytest.fixture
def gazebo_models(tmp_path, monkeypatch):
    for var in ("GZ_SIM_RESOURCE_PATH", "GAZEBO_MODEL_PATH", "ROS_PACKAGE_PATH"):
        monkeypatch.delenv(var, raising=False)
    models = tmp_path / "models"
    _box_model(models / "gripper", "gripper", "finger", (0.01, 0.02, 0.03))
    nested = ('    <model name="inner">\n      <link name="part">\n        <collision name="c"><geometry><box>'
              '<size>0.1 0.1 0.1</size></box></geometry></collision>\n      </link>\n    </model>\n'
              '    <include>\n      <uri>model://gripper</uri>\n      <name>hand</name>\n    </include>\n')
    arm = _box_model(models / "arm", "arm", "base", (0.2, 0.2, 0.1), extra=nested, licence=True)
    return arm


def test_a_gazebo_model_folder_reads_without_environment_variables(gazebo_models):
    # osrf mpl_right_arm/model.sdf: a licence comment before the declaration; model:// of the model itself and
    # of a sibling model folder; an <include> of the sibling (model.config names its file) and a nested model
    robot = read_robot(gazebo_models)
    assert [link.name for link in robot.links] == ["base", "inner::part", "hand::finger"]
    masses = {r.name: r.properties.mass for r in link_inertials(robot, density=1000)}
    assert masses["base"] == pytest.approx(4.0, rel=1e-6)
    assert masses["inner::part"] == pytest.approx(1.0, rel=1e-14)
    assert masses["hand::finger"] == pytest.approx(0.006, rel=1e-6)


def test_a_corrected_copy_of_a_gazebo_model_keeps_the_licence_and_reads_back(gazebo_models, tmp_path):
    robot = read_robot(gazebo_models)
    out = gazebo_models.parent / "robot_fixed.sdf"
    changed = write_corrected(robot, link_inertials(robot, density=1000), out)
    assert set(changed) == {"base", "inner::part"}            # hand::finger is in the included file
    data = out.read_bytes()
    assert data.startswith(LICENCE)
    again = {link.name: link.declared for link in read_robot(out).links}
    assert again["base"].mass == pytest.approx(4.0, rel=1e-6)
    assert again["inner::part"].mass == pytest.approx(1.0, rel=1e-14)
    assert again["hand::finger"] is None                # in the included file: left as it was


def test_a_world_with_a_light_include_and_a_missing_model(tmp_path, gazebo_models, monkeypatch):
    sun = tmp_path / "models" / "sun"
    sun.mkdir()
    (sun / "model.sdf").write_text('<sdf version="1.6"><light name="sun" type="directional"/></sdf>')
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://sun</uri></include>'
                     '<include><uri>model://gripper</uri></include></world></sdf>')
    assert [link.name for link in read_robot(world).links] == ["gripper::finger"]
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://nowhere</uri></include></world></sdf>')
    with pytest.raises(RobotDescriptionError, match="cannot find model 'nowhere'"):
        read_robot(world)
    (tmp_path / "models" / "loop.sdf").write_text('<sdf version="1.6"><model name="loop"><include><uri>loop.sdf'
                                                   '</uri></include></model></sdf>')
    with pytest.raises(RobotDescriptionError, match="includes itself"):
        read_robot(tmp_path / "models" / "loop.sdf")


def test_package_found_through_package_xml_up_the_tree(tmp_path, monkeypatch):
    # a ROS workspace: src/my_robot_description/urdf/robot.urdf names package://my_robot_description/...
    # and package://my_meshes/... (a sibling package whose folder has another name)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = tmp_path / "src" / "my_robot_description"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='3'><name>my_robot_description</name></package>")
    meshes = tmp_path / "src" / "my_meshes"
    meshes.mkdir()
    (meshes / "package.xml").write_text("<package><name> my_meshes </name></package>")
    shapes.write_stl(shapes.box(0.1, 0.1, 0.1), meshes / "b.stl")
    shapes.write_stl(shapes.box(0.1, 0.1, 0.2), pkg / "b2.stl")
    urdf = pkg / "urdf" / "robot.urdf"
    urdf.write_text('<robot name="r"><link name="a"><collision><geometry><mesh filename="package://my_meshes/b.stl"/>'
                    '</geometry></collision></link><link name="b"><collision><geometry>'
                    '<mesh filename="package://my_robot_description/b2.stl"/></geometry></collision></link></robot>')
    a, b = read_robot(urdf).links
    assert a.elements[0].mesh == str(meshes / "b.stl") and b.elements[0].mesh == str(pkg / "b2.stl")
    # a folder named like the package but declaring another name is not it
    (meshes / "package.xml").write_text("<package><name>other</name></package>")
    with pytest.raises(RobotDescriptionError, match="cannot resolve package 'my_meshes'"):
        read_robot(urdf)


def _collada_polylist_with_a_pathless_image(path, extents):
    trimesh = pytest.importorskip("trimesh")
    text = trimesh.exchange.dae.export_collada(trimesh.creation.box(extents=extents)).decode()
    newparams = ('<newparam sid="s-surface"><surface type="2D"><init_from>img1</init_from></surface></newparam>'
                 '<newparam sid="s-sampler"><sampler2D><source>s-surface</source></sampler2D></newparam>')
    text = re.sub(r"(<profile_COMMON>)", r"\1" + newparams, text)
    text = re.sub(r"<diffuse>\s*<color>[^<]*</color>\s*</diffuse>",
                  '<diffuse><texture texture="s-sampler" texcoord="UVSET0"/></diffuse>', text)
    text = text.replace("<library_effects>", '<library_images><image id="img1" name="img1"/></library_images>'
                                             "<library_effects>")
    count = int(re.search(r'<triangles count="(\d+)"', text).group(1))
    text = re.sub(r"<triangles (count=\"\d+\"[^>]*)>", r"<polylist \1><vcount>" + " ".join(["3"] * count)
                  + "</vcount>", text).replace("</triangles>", "</polylist>")
    # the <p> must follow <vcount> and the inputs: move <vcount> right before <p>
    text = re.sub(r"(<polylist [^>]*>)(<vcount>[^<]*</vcount>)(.*?)(<p>)", r"\1\3\2\4", text, flags=re.DOTALL)
    path.write_text(text)


def test_collada_with_an_image_without_a_path_reads_its_geometry(tmp_path):
    # Gazebo's pulley.dae, gear.dae, disk.dae were "no triangle mesh": pycollada dropped the geometry bound to
    # a material whose image has no path
    path = tmp_path / "pulley.dae"
    _collada_polylist_with_a_pathless_image(path, (0.1, 0.2, 0.3))
    assert "<polylist" in path.read_text() and '<image id="img1" name="img1"/>' in path.read_text()
    raw = load_mesh(path, units="m")
    assert len(raw.faces) == 12
    extent = raw.vertices.max(axis=0) - raw.vertices.min(axis=0)
    np.testing.assert_allclose(extent, [0.1, 0.2, 0.3], rtol=1e-7)          # float32 in the file


# -- xacro without --package (issue 23 item 5) -------------------------------------------------------------

def _workspace(tmp_path):
    pkg = tmp_path / "ws" / "src" / "my_desc"
    (pkg / "urdf" / "inc").mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="3"><name>my_desc</name></package>')
    (pkg / "urdf" / "inc" / "part.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="part"><link name="p"><collision>'
        '<geometry><box size="0.1 0.2 0.3"/></geometry></collision></link></xacro:macro></robot>')
    return pkg


def test_xacro_find_uses_package_xml_two_folders_up(tmp_path, monkeypatch):
    pytest.importorskip("xacro")
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = _workspace(tmp_path)
    src = pkg / "urdf" / "robot.urdf.xacro"
    src.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   '<xacro:include filename="$(find my_desc)/urdf/inc/part.xacro"/><xacro:part/></robot>')
    (link,) = read_robot(src, run_xacro=True).links
    assert link.name == "p" and link.elements[0].size == pytest.approx((0.1, 0.2, 0.3))


def test_xacro_failures_are_one_clean_sentence(tmp_path, monkeypatch):
    pytest.importorskip("xacro")
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = _workspace(tmp_path)
    src = pkg / "urdf" / "bad.urdf.xacro"
    src.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   '<xacro:include filename="$(find nowhere_pkg)/x.xacro"/></robot>')
    with pytest.raises(RobotDescriptionError) as info:
        read_robot(src, run_xacro=True)
    message = str(info.value)
    # was: "xacro expansion failed (<class 'inertia_tool.errors.RobotDescriptionError'>: $(find nowhere_pkg):
    # package 'nowhere_pkg' is not among ... $(find nowhere_pkg): package 'nowhere_pkg' i)"
    assert "<class" not in message and "Error" not in message
    assert message.count("nowhere_pkg") == 2 and message.endswith("in the 8 folders above")
    long_name = "an_undefined_property_" * 30
    src.write_text(f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a"><collision>'
                   f'<geometry><box size="${{{long_name} * 2}} 1 1"/></geometry></collision></link></robot>')
    with pytest.raises(RobotDescriptionError) as info:
        read_robot(src, run_xacro=True)
    message = str(info.value)
    assert "<class" not in message and message.endswith(" …")
    quoted = message.split("xacro expansion failed: ", 1)[1][:-2]
    assert len(quoted) <= 300 and (long_name + " * 2").startswith(quoted.split("'")[1][:50])


def test_xacro_message_drops_class_names_and_repeats():
    from inertia_tool.robot.xacro_expand import _xacro_message
    exc = RuntimeError("<class 'xacro.XacroException'>: missing file. <class 'xacro.XacroException'>: missing file.")
    assert _xacro_message(exc) == "missing file."
    assert _xacro_message(ValueError("")) == "unknown failure"
    words = " ".join(f"word{k}" for k in range(200))
    cut = _xacro_message(ValueError(words))
    assert cut.endswith(" …") and cut[:-2] in words and words[len(cut) - 2] == " "


def test_includes_that_multiply_are_bounded(tmp_path):
    # each level includes the next twice: 2**12 reads without a bound on the total
    for k in range(12):
        (tmp_path / f"m{k}.sdf").write_text(f'<sdf version="1.6"><model name="m{k}">'
                                            f'<include><uri>m{k + 1}.sdf</uri><name>a</name></include>'
                                            f'<include><uri>m{k + 1}.sdf</uri><name>b</name></include></model></sdf>')
    (tmp_path / "m12.sdf").write_text('<sdf version="1.6"><model name="leaf"><link name="l"/></model></sdf>')
    with pytest.raises(RobotDescriptionError, match="more than 512 files"):
        read_robot(tmp_path / "m0.sdf")
    for k in range(12):
        (tmp_path / f"j{k}.xml").write_text(f'<mujoco><include file="j{k + 1}.xml"/><include file="j{k + 1}.xml"/>'
                                            '</mujoco>')
    (tmp_path / "j12.xml").write_text('<mujoco/>')
    with pytest.raises(RobotDescriptionError, match="more than 512 included files"):
        read_robot(tmp_path / "j0.xml")


GROUND_PLANE = ('<model name="ground_plane"><static>true</static><link name="link"><collision name="c"><geometry>'
                '<plane><normal>0 0 1</normal><size>100 100</size></plane></geometry></collision><visual name="v">'
                '<geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry></visual></link>'
                '</model>')


def test_stock_sun_and_ground_plane_not_on_disk_are_skipped_with_a_note(tmp_path, gazebo_models):
    # issue 23 item 4: nearly every Gazebo world includes model://sun and model://ground_plane, which are not
    # shipped with the robot; they hold no link with mass, so the world is read without them and each is named
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://sun</uri></include>'
                     '<include><uri>model://ground_plane</uri></include>'
                     '<include><uri>model://gripper</uri></include></world></sdf>')
    with pytest.warns(SkippedModelWarning) as caught:
        robot = read_robot(world)
    assert [link.name for link in robot.links] == ["gripper::finger"]
    messages = [str(w.message) for w in caught if issubclass(w.category, SkippedModelWarning)]
    assert len(messages) == 2 and "'sun'" in messages[0] and "'ground_plane'" in messages[1]
    assert all("\n" not in m for m in messages)


def test_a_ground_plane_on_disk_or_inline_is_a_link_without_geometry(tmp_path, gazebo_models):
    plane = tmp_path / "models" / "ground_plane"
    plane.mkdir()
    (plane / "model.sdf").write_text(f'<sdf version="1.6">{GROUND_PLANE}</sdf>')
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://ground_plane</uri></include>'
                     f'{GROUND_PLANE.replace("ground_plane", "floor")}<model name="t"><static>true</static>'
                     '<link name="terrain"><collision name="h"><geometry><heightmap><uri>h.png</uri>'
                     '<size>10 10 1</size></heightmap></geometry></collision></link></model>'
                     '<include><uri>model://gripper</uri></include></world></sdf>')
    robot = read_robot(world)
    names = {link.name: link for link in robot.links}
    assert set(names) == {"ground_plane::link", "floor::link", "t::terrain", "gripper::finger"}
    assert names["ground_plane::link"].elements == () and names["t::terrain"].elements == ()
    results = {r.name: r for r in link_inertials(robot, density=1000)}
    assert results["gripper::finger"].properties.mass == pytest.approx(1000 * 0.01 * 0.02 * 0.03, rel=1e-6)
    assert links_without_result(robot, results.values()) == []


def test_a_missing_model_names_the_folders_searched(tmp_path, gazebo_models, monkeypatch):
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(tmp_path / "elsewhere"))
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://sunflower</uri></include></world>'
                     '</sdf>')
    with pytest.raises(RobotDescriptionError) as caught:
        read_robot(world)
    message = str(caught.value)
    assert "cannot find model 'sunflower'" in message and "\n" not in message
    assert f"GZ_SIM_RESOURCE_PATH={str(tmp_path / 'elsewhere')!r}" in message
    assert "GAZEBO_MODEL_PATH (unset)" in message and str(tmp_path / "models") in message


def test_cli_reads_a_world_with_stock_models_and_says_what_it_skipped(tmp_path, gazebo_models, capsys):
    from inertia_tool.cli import main
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.6"><world name="w"><include><uri>model://sun</uri></include>'
                     '<include><uri>model://ground_plane</uri></include>'
                     '<include><uri>model://gripper</uri></include></world></sdf>')
    assert main(["robot", str(world), "--density", "1000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [link["name"] for link in out["links"]] == ["gripper::finger"]
    skipped = [w for w in out["warnings"] if "skipped" in w]
    assert len(skipped) == 2 and "'sun'" in skipped[0] and "'ground_plane'" in skipped[1]


def test_fuel_urls_of_stock_models_are_skipped_and_others_named(tmp_path, gazebo_models):
    # gz-sim worlds include the sun and the ground plane from Gazebo Fuel; nothing is downloaded
    world = tmp_path / "models" / "w.world"
    world.write_text('<sdf version="1.9"><world name="w">'
                     '<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Sun</uri></include>'
                     '<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground%20Plane/2</uri>'
                     '</include><include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/gripper</uri>'
                     '</include></world></sdf>')
    with pytest.warns(SkippedModelWarning):
        robot = read_robot(world)
    assert [link.name for link in robot.links] == ["gripper::finger"]       # found on disk by its name
    world.write_text('<sdf version="1.9"><world name="w"><include><uri>https://fuel.gazebosim.org/1.0/'
                     'OpenRobotics/models/Fancy Table</uri></include></world></sdf>')
    with pytest.raises(RobotDescriptionError, match="a Gazebo Fuel model \\('Fancy Table'\\).*'fancy_table'"):
        read_robot(world)


def _versions_model(folder, name):
    """A Gazebo model folder as osrf gazebo_models ships them: one SDFormat file per version, model.config
    listing them oldest first (the oldest a `<gazebo>` root, which SDFormat 1.5+ readers refuse)."""
    folder.mkdir(parents=True)
    (folder / "model.config").write_text(
        f"<?xml version='1.0'?>\n<model><name>{name}</name><sdf version='1.2'>model-1_2.sdf</sdf>"
        "<sdf version='1.4'>model-1_4.sdf</sdf><sdf version='1.10'>model.sdf</sdf>"
        "<sdf version='1.5'>model-1_5.sdf</sdf></model>\n")
    (folder / "model-1_2.sdf").write_text("<?xml version='1.0'?>\n<gazebo version='1.2'><model name='old'/></gazebo>\n")
    for file, size in (("model-1_4.sdf", 0.3), ("model-1_5.sdf", 0.2), ("model.sdf", 0.1)):
        (folder / file).write_text(f"<?xml version='1.0'?>\n<sdf version='1.4'><model name='{name}'><link name='l'>"
                                   f"<collision name='c'><geometry><box><size>{size} {size} {size}</size></box>"
                                   "</geometry></collision></link></model></sdf>\n")


def test_a_gazebo_model_folder_is_one_model_its_newest_version(tmp_path, gazebo_models):
    """osrf gazebo_models: 455 descriptions audited for 251 model folders (each version of a model counted, the
    1.2 files 'unreadable'); a folder with a model.config is one model, the newest version it lists (1.10 is
    newer than 1.5: versions compare as numbers), which is also what an <include> of the folder reads."""
    from inertia_tool.robot.corpus import audit_corpus, find_descriptions
    models = tmp_path / "zoo"
    _versions_model(models / "bowl", "bowl")
    found = find_descriptions([models])
    assert [p.rsplit("/", 2)[-2:] for p in found] == [["bowl", "model.sdf"]]
    audits = audit_corpus([models], density=1000)
    assert len(audits) == 1 and audits[0].problem is None
    assert audits[0].inertials[0].properties.mass == pytest.approx(1.0, rel=1e-12)      # 0.1 m cube
    # named directly, an older version is still audited
    older = str(models / "bowl" / "model-1_4.sdf")
    assert find_descriptions([older]) == [older]
    # an include of the folder reads the newest version too
    world = tmp_path / "world.sdf"
    world.write_text(f"<?xml version='1.0'?>\n<sdf version='1.6'><world name='w'><include><uri>{models / 'bowl'}"
                     "</uri></include></world></sdf>\n")
    robot = read_robot(world)
    assert [r.properties.mass for r in link_inertials(robot, density=1000)] == [pytest.approx(1.0, rel=1e-12)]


_SDF_BOX = ("<sdf version='1.6'><model name='m'><link name='l'><inertial><mass>2</mass></inertial>"
            "<collision name='c'><geometry><box><size>0.1 0.2 0.3</size></box></geometry></collision></link>"
            "</model></sdf>\n")


@pytest.mark.parametrize("head, inside", [
    ("\n<?xml version='1.0'?>\n", ""),                                   # lunar_tranquillitatis_pit
    ("<?xml version='1.0'?>\n", "<!-- m from 2700 kg/m3\n <!-- divided by 4 -->"),   # src_doorway
    ("<!-- licence -->\n  <?xml version='1.0' encoding='UTF-8'?>\n", "<!-- a comment ending in a hyphen--->"),
])
def test_what_gazebo_reads_and_xml_does_not_is_read_and_written_back_unchanged(tmp_path, head, inside):
    """osrf gazebo_models: a blank line before the declaration, '--' inside a comment (a comment opened again
    inside one), as Gazebo's parser reads them; before, 'not well-formed XML'. A corrected copy keeps every
    byte of the original outside the changed inertial (the tolerance blanks without moving offsets)."""
    path = tmp_path / "model.sdf"
    text = head + _SDF_BOX.replace("<link name='l'>", "<link name='l'>" + inside)
    path.write_text(text)
    robot = read_robot(path)
    [result] = link_inertials(robot, density=1000)
    assert result.properties.mass == pytest.approx(6.0, rel=1e-12)
    out = tmp_path / "fixed.sdf"
    write_corrected(robot, [result], out)
    written = out.read_text()
    assert written.startswith(head + "<sdf version='1.6'>")        # the writer adds a note after the root
    assert "<model name='m'><link name='l'>" + inside + "<inertial>" in written
    assert written.endswith(text.split("</inertial>", 1)[1])
    assert read_robot(out).links[0].declared.mass == pytest.approx(6.0, rel=1e-12)


def test_unquoted_attributes_stay_refused_with_the_reason(tmp_path):
    """osrf submarine: `name=blade1_visual` (no quotes), which XML and this reader refuse: one line naming it."""
    path = tmp_path / "model.sdf"
    path.write_text(_SDF_BOX.replace("name='c'", "name=c"))
    with pytest.raises(RobotDescriptionError, match=r"model\.sdf: not well-formed XML"):
        read_robot(path)


def test_a_light_only_sdf_says_there_is_nothing_to_audit(tmp_path):
    """osrf sun/model.sdf: a <light> alone, read directly (an include of it adds nothing, as before)."""
    path = tmp_path / "model.sdf"
    path.write_text("<?xml version='1.0'?>\n<sdf version='1.5'><light type='directional' name='sun'/></sdf>\n")
    with pytest.raises(RobotDescriptionError, match=r"no <model> or <world> to audit: the file holds only "
                                                    r"<light> \(a light or an actor has no links\)"):
        read_robot(path)


# -- SDFormat <polyline>: an extruded polygonal region, even-odd holes (issue 23 item 4) ---------------------

from hypothesis import given, settings, strategies as st  # noqa: E402

from inertia_tool.errors import InvalidMeshError  # noqa: E402
from inertia_tool.integrals import second_moment_to_inertia, volume_moments  # noqa: E402
from inertia_tool.mass.extrusion import extruded_region, polygon_region  # noqa: E402
from inertia_tool.mass.properties import combine  # noqa: E402
from inertia_tool.robot.geometry import element_bounds, points_inside_element  # noqa: E402


def _ngon(radius, sides, turn=0.0, centre=(0.0, 0.0)):
    angles = turn + 2 * np.pi * np.arange(sides) / sides
    return np.column_stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)])


def _same(a, b, rel=1e-10):
    scale = np.abs(b.inertia).max()
    assert a.volume == pytest.approx(b.volume, rel=rel)
    np.testing.assert_allclose(a.center_of_mass, b.center_of_mass, atol=rel * 10)
    np.testing.assert_allclose(a.inertia, b.inertia, atol=rel * scale)


def test_polyline_rectangle_is_the_box():
    # a 2 × 3 rectangle with a corner at (1, −4), extruded 0.5 from z = 0: the box of mass_shapes, centred
    rectangle = [(1, -4), (3, -4), (3, -1), (1, -1)]
    for points in (rectangle, rectangle[::-1], rectangle + rectangle[:1]):      # either winding, closed or not
        _same(extruded_region([points], 0.5), shapes.box(2, 3, 0.5, center=(2, -2.5, 0.25)).exact)


@pytest.mark.parametrize("sides, turn", [(3, 0.0), (6, 0.3), (20, 1.0), (64, -0.2)])
def test_polyline_regular_ngon_ring_is_the_difference_of_two_prisms(sides, turn):
    # outer R = 1.3, inner r = 0.8·R·cos(π/n) rotated by `turn` (the in-plane tensor of a regular n-gon is
    # isotropic, so the turn leaves it alone); the ring is prism(R) − prism(r), both centred at z = h/2
    h, outer = 0.25, 1.3
    inner = 0.8 * outer * np.cos(np.pi / sides)
    big = shapes.prism(outer, h, sides, center=(0, 0, h / 2)).exact
    small = shapes.prism(inner, h, sides, center=(0, 0, h / 2)).exact
    ring = extruded_region([_ngon(outer, sides), _ngon(inner, sides, turn)], h)
    assert ring.volume == pytest.approx(big.volume - small.volume, rel=1e-12)
    np.testing.assert_allclose(ring.center_of_mass, [0, 0, h / 2], atol=1e-12)
    np.testing.assert_allclose(ring.inertia, big.inertia - small.inertia, atol=1e-12 * np.abs(big.inertia).max())


def test_polyline_island_inside_a_hole_counts_again():
    # three nested squares (even-odd): the outermost and the innermost are material, the middle one a hole
    h = 0.2
    squares = [[(-s, -s), (s, -s), (s, s), (-s, s)] for s in (2.0, 1.5, 0.5)]
    region = extruded_region(squares, h)
    box = [shapes.box(2 * s, 2 * s, h, center=(0, 0, h / 2)).exact for s in (2.0, 1.5, 0.5)]
    assert region.volume == pytest.approx(box[0].volume - box[1].volume + box[2].volume, rel=1e-13)
    np.testing.assert_allclose(region.inertia, box[0].inertia - box[1].inertia + box[2].inertia, rtol=1e-12)
    _, signs = polygon_region(squares[::-1])
    assert signs == (1, -1, 1)


def test_polyline_l_shape_is_two_boxes():
    h = 0.7
    l_shape = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 3), (0, 3)]
    boxes = combine([shapes.box(2, 1, h, center=(1, 0.5, h / 2)).exact,
                     shapes.box(1, 2, h, center=(0.5, 2, h / 2)).exact])
    _same(extruded_region([l_shape], h), boxes)
    assert abs(extruded_region([l_shape], h).inertia[0, 1]) > 0.1           # the product of inertia is there


def _prism_mesh(polygon, centre, h):
    """A closed, outward-wound triangle mesh of the prism over a CCW polygon star-shaped from ``centre``."""
    n = len(polygon)
    bottom = np.column_stack([polygon, np.zeros(n)])
    top = np.column_stack([polygon, np.full(n, h)])
    vertices = np.vstack([bottom, top, [[*centre, 0.0], [*centre, h]]])
    i = np.arange(n)
    j = (i + 1) % n
    faces = np.vstack([np.column_stack([np.full(n, 2 * n), j, i]),                 # bottom, normal −z
                       np.column_stack([np.full(n, 2 * n + 1), n + i, n + j]),     # top, normal +z
                       np.column_stack([i, j, n + j]), np.column_stack([i, n + j, n + i])])
    return vertices, faces


def _engine(vertices, faces):
    moments = volume_moments(vertices, faces)
    return moments.volume, moments.centroid, second_moment_to_inertia(moments.second_moment)


@st.composite
def _star_polygons(draw):
    n = draw(st.integers(3, 24))
    gaps = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=n, max_size=n)))
    angles = draw(st.floats(0, 6.3)) + np.cumsum(gaps / gaps.sum() * 2 * np.pi)
    if np.max(gaps / gaps.sum() * 2 * np.pi) >= 0.95 * np.pi:         # keep the centre in the kernel
        angles = draw(st.floats(0, 6.3)) + 2 * np.pi * np.arange(n) / n
    radii = np.array(draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n)))
    centre = np.array([draw(st.floats(-50, 50)), draw(st.floats(-50, 50))])
    polygon = centre + radii[:, None] * np.column_stack([np.cos(angles), np.sin(angles)])
    return polygon, centre, draw(st.floats(0.05, 3.0))


@settings(max_examples=60, deadline=None)
@given(_star_polygons(), st.booleans(), st.floats(0.2, 0.9))
def test_polyline_random_star_polygons_match_the_engine_on_the_triangulated_prism(star, clockwise, shrink):
    polygon, centre, h = star
    volume, centroid, inertia = _engine(*_prism_mesh(polygon, centre, h))
    given_points = polygon[::-1] if clockwise else polygon
    solid = extruded_region([given_points], h)
    assert solid.volume == pytest.approx(volume, rel=1e-9)
    np.testing.assert_allclose(solid.center_of_mass, centroid, atol=1e-9 * (1 + np.abs(centre).max()))
    np.testing.assert_allclose(solid.inertia, inertia, atol=1e-8 * np.abs(inertia).max())
    # the same star shrunk about its centre is a hole: the engine integrates the outer shell plus the inner one
    # wound inwards
    hole = centre + shrink * (polygon - centre)
    v_out, f_out = _prism_mesh(polygon, centre, h)
    v_in, f_in = _prism_mesh(hole, centre, h)
    vertices = np.vstack([v_out, v_in])
    faces = np.vstack([f_out, f_in[:, ::-1] + len(v_out)])
    volume, centroid, inertia = _engine(vertices, faces)
    ring = extruded_region([hole, given_points], h)
    assert ring.volume == pytest.approx(volume, rel=1e-9)
    np.testing.assert_allclose(ring.center_of_mass, centroid, atol=1e-9 * (1 + np.abs(centre).max()))
    np.testing.assert_allclose(ring.inertia, inertia, atol=1e-8 * np.abs(inertia).max())


@pytest.mark.parametrize("polygons, expected", [
    ([[(0, 0), (1, 1), (1, 0), (0, 1)]], "polygon 1 crosses itself"),                # a bow tie
    ([[(0, 0), (2, 0), (1, 0), (1, 1)]], "polygon 1 crosses itself"),                # an edge folding back
    ([[(0, 0), (2, 0), (2, 2), (1, 0.0), (0, 2)]], "polygon 1 crosses itself"),      # a corner on an edge
    ([[(0, 0), (1, 0)]], "at least 3 distinct points, found 2"),
    ([[(0, 0), (1, 0), (1, 0), (0, 0)]], "at least 3 distinct points, found 2"),     # repeats dropped
    ([[(0, 0), (1, 1), (2, 2)]], "expected a positive area, found its 3 points on one line"),
    ([[(0, 0), (2, 0), (2, 2), (0, 2)], [(1, 1), (3, 1), (3, 3), (1, 3)]], "polygons 1 and 2 cross"),
    ([[(0, 0), (2, 0), (2, 2), (0, 2)], [(0, 0.5), (1, 0.5), (1, 1.5), (0, 1.5)]], "polygons 1 and 2 cross"),
    ([], "at least one polygon"),
])
def test_polyline_bad_polygons_are_refused_with_the_reason(polygons, expected):
    with pytest.raises(InvalidMeshError, match=expected):
        polygon_region(polygons)


def _polyline_sdf(path, polylines, *, pose="0 0 0 0 0 0", inertial=""):
    body = "".join("<polyline>" + (f"<height>{h}</height>" if h is not None else "")
                   + "".join(f"<point>{x} {y}</point>" for x, y in points) + "</polyline>"
                   for points, h in polylines)
    path.write_text(f'<sdf version="1.6"><model name="m"><link name="hoop">{inertial}<collision name="c">'
                    f"<pose>{pose}</pose><geometry>{body}</geometry></collision></link></model></sdf>")
    return path


def test_polyline_sdf_ring_reads_as_one_element_placed_by_its_pose(tmp_path):
    outer, inner = _ngon(1.0, 12).tolist(), _ngon(0.6, 12).tolist()
    path = _polyline_sdf(tmp_path / "ring.sdf", [(outer, 0.1), (inner, 0.1)], pose="0 0 2 1.5707963267948966 0 0")
    robot = read_robot(path)
    (element,) = robot.links[0].elements
    assert element.kind == "polyline" and element.size == (0.1,) and len(element.polygons) == 2
    (result,) = link_inertials(robot, density=1000)
    local = extruded_region([outer, inner], 0.1)
    assert result.properties.mass == pytest.approx(1000 * local.volume, rel=1e-12)
    # the pose turns the ring upright (element z → link −y) and lifts it by 2
    np.testing.assert_allclose(result.properties.center_of_mass, [0, -0.05, 2], atol=1e-12)
    assert points_inside_element(element, [0.8, -0.05, 2]) and not points_inside_element(element, [0, -0.05, 2])
    assert not points_inside_element(element, [0.8, 0.05, 2])
    np.testing.assert_allclose(element_bounds(element), [[-1, -0.1, 1], [1, 0, 3]], atol=1e-12)


def test_polyline_height_defaults_to_one_metre_and_different_heights_are_refused(tmp_path):
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    robot = read_robot(_polyline_sdf(tmp_path / "a.sdf", [(square, None)]))
    assert robot.links[0].elements[0].size == (1.0,)
    hole = [(0.2, 0.2), (0.8, 0.2), (0.8, 0.8), (0.2, 0.8)]
    with pytest.raises(RobotDescriptionError, match="expected one <height> for all <polyline>s.*found 0.1, 0.2"):
        read_robot(_polyline_sdf(tmp_path / "b.sdf", [(square, 0.1), (hole, 0.2)]))


@pytest.mark.parametrize("polylines, expected", [
    ([([(0, 0), (1, 1), (1, 0), (0, 1)], 0.1)], "polygon 1 crosses itself"),
    ([([(0, 0), (1, 0)], 0.1)], "at least 3 distinct points"),
    ([([(0, 0), (1, 0), (1, 1)], 0)], "height"),
])
def test_polyline_sdf_refusals_name_the_file_and_the_link(tmp_path, polylines, expected):
    path = _polyline_sdf(tmp_path / "bad.sdf", polylines)
    with pytest.raises(RobotDescriptionError, match=expected) as caught:
        read_robot(path)
    assert str(path) in str(caught.value) and "link 'hoop'" in str(caught.value) and "\n" not in str(caught.value)


HOOP_RED = "/work/data/gazebo/hoop_red/model.sdf"


@pytest.mark.skipif(not __import__("os").path.exists(HOOP_RED), reason="osrf gazebo_models not unpacked here")
def test_osrf_hoop_red_reads():
    """osrf gazebo_models ``hoop_red``: a static link holding a 5 m pole (0.3 × 0.1 box) and a ring extruded
    0.1 m from two 20-gons (outer circumradius 1.23625 m, inner 1.05964 m, the first point repeated at the end).
    The model declares no ``<inertial>`` (it is static), so there is no declared mass to compare with; at
    1000 kg/m³ the link weighs 1000·(0.15 + A·0.1) kg with A the ring's area."""
    robot = read_robot(HOOP_RED)
    (link,) = robot.links
    kinds = sorted(e.kind for e in link.elements)
    assert kinds == ["box", "polyline"] and link.declared is None
    ring = next(e for e in link.elements if e.kind == "polyline")
    assert [len(p) for p in ring.polygons] == [20, 20]
    area = extruded_region(ring.polygons, 1.0).volume
    assert 0.95 * np.pi * (1.23625 ** 2 - 1.05964 ** 2) < area < np.pi * (1.23625 ** 2 - 1.05964 ** 2)
    (result,) = link_inertials(robot, density=1000)
    assert result.method == "exact"
    assert result.properties.mass == pytest.approx(1000 * (0.3 * 0.1 * 5 + 0.1 * area), rel=1e-12)


# -- SDFormat <mesh><submesh>: one named node of a COLLADA file, optionally re-centred (issue 23 item 4) -------

from dataclasses import replace  # noqa: E402

from inertia_tool.errors import MeshReadError  # noqa: E402
from inertia_tool.mesh.collada_nodes import collada_node_names, select_collada_node  # noqa: E402

_TETRA = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float), np.array([[0, 2, 1], [0, 1, 3],
                                                                                    [0, 3, 2], [1, 2, 3]]))


def _box_arrays(extents):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=extents)
    return np.asarray(box.vertices), np.asarray(box.faces)


def _collada_geometry(gid, vertices, faces):
    return (f'<geometry id="{gid}" name="{gid}"><mesh><source id="{gid}-p"><float_array id="{gid}-a" '
            f'count="{vertices.size}">{" ".join(map(repr, vertices.ravel().tolist()))}</float_array>'
            f'<technique_common><accessor source="#{gid}-a" count="{len(vertices)}" stride="3"><param name="X" '
            'type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
            f'</technique_common></source><vertices id="{gid}-v"><input semantic="POSITION" source="#{gid}-p"/>'
            f'</vertices><triangles count="{len(faces)}"><input semantic="VERTEX" source="#{gid}-v" offset="0"/>'
            f'<p>{" ".join(map(str, faces.ravel().tolist()))}</p></triangles></mesh></geometry>')


def _collada_scene(path):
    """Three nodes: 'Body' at (1, 2, 3) holding a 0.1 × 0.2 × 0.3 box and, in an unnamed child node 2 further
    along x, a tetrahedron (so Gazebo names both 'Body'); 'Wheel' at (5, 0, 0) holding a 0.4 cube; 'Lever' holding the
    unit corner tetrahedron (bounding-box centre (½, ½, ½), centroid (¼, ¼, ¼))."""
    geometries = (_collada_geometry("box", *_box_arrays((0.1, 0.2, 0.3)))
                  + _collada_geometry("cube", *_box_arrays((0.4, 0.4, 0.4))) + _collada_geometry("tet", *_TETRA))
    nodes = ('<node id="n1" name="Body"><translate>1 2 3</translate><instance_geometry url="#box"/>'
             '<node id="n2"><translate>2 0 0</translate><instance_geometry url="#tet"/></node></node>'
             '<node id="n3" name="Wheel"><translate>5 0 0</translate><instance_geometry url="#cube"/></node>'
             '<node id="n4" name="Lever"><instance_geometry url="#tet"/></node>')
    path.write_text('<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" '
                    'version="1.4.1"><asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>'
                    f'<library_geometries>{geometries}</library_geometries><library_visual_scenes>'
                    f'<visual_scene id="s">{nodes}</visual_scene></library_visual_scenes>'
                    '<scene><instance_visual_scene url="#s"/></scene></COLLADA>')
    return path


def _submesh_sdf(path, mesh, name, center, scale="1 1 1"):
    path.write_text(f'<sdf version="1.6"><model name="m"><link name="wheel"><collision name="c"><geometry><mesh>'
                    f'<uri>{mesh}</uri><scale>{scale}</scale><submesh><name>{name}</name><center>{center}</center>'
                    '</submesh></mesh></geometry></collision></link></model></sdf>')
    return path


@pytest.mark.parametrize("name, center, volume, com", [
    ("Wheel", "false", 0.064, [5, 0, 0]),
    ("Wheel", "true", 0.064, [0, 0, 0]),
    ("Lever", "false", 1 / 6, [0.25, 0.25, 0.25]),
    ("Lever", "true", 1 / 6, [-0.25, -0.25, -0.25]),       # the bounding-box centre moves, not the centroid
    ("Body", "false", 0.006 + 1 / 6,
     (0.006 * np.array([1, 2, 3]) + np.array([3.25, 2.25, 3.25]) / 6) / (0.006 + 1 / 6)),
])
def test_submesh_reads_only_the_named_node_as_gazebo_names_it(tmp_path, name, center, volume, com):
    mesh = _collada_scene(tmp_path / "vehicle.dae")
    robot = read_robot(_submesh_sdf(tmp_path / "m.sdf", "vehicle.dae", name, center))
    (element,) = robot.links[0].elements
    assert element.submesh == name and element.submesh_center == (center == "true")
    (result,) = link_inertials(robot, density=1)
    assert result.method == "exact"
    assert result.properties.volume == pytest.approx(volume, rel=1e-6)
    np.testing.assert_allclose(result.properties.center_of_mass, com, atol=1e-6)
    assert collada_node_names(str(mesh)) == ["Body", "Wheel", "Lever"]


def test_submesh_is_centred_before_the_scale(tmp_path):
    _collada_scene(tmp_path / "vehicle.dae")
    robot = read_robot(_submesh_sdf(tmp_path / "m.sdf", "vehicle.dae", "Lever", "true", scale="2 2 2"))
    (result,) = link_inertials(robot, density=1)
    assert result.properties.volume == pytest.approx(8 / 6, rel=1e-6)
    np.testing.assert_allclose(result.properties.center_of_mass, [-0.5, -0.5, -0.5], atol=1e-6)


def test_submesh_missing_names_the_ones_there_and_non_collada_is_refused(tmp_path):
    _collada_scene(tmp_path / "vehicle.dae")
    robot = read_robot(_submesh_sdf(tmp_path / "m.sdf", "vehicle.dae", "Steering", "true"))
    (result,) = link_inertials(robot, density=1)            # the link gets no numbers and the reason
    assert result.properties is None
    assert re.search(r"vehicle\.dae: expected a sub-mesh \(COLLADA node\) named 'Steering', found 'Body', "
                     r"'Wheel', 'Lever'$", result.problem)
    with pytest.raises(MeshReadError, match="named 'Steering'"):
        select_collada_node(str(tmp_path / "vehicle.dae"), "Steering")
    shapes.write_stl(shapes.box(1, 1, 1), tmp_path / "box.stl")
    with pytest.raises(RobotDescriptionError, match=r"link 'wheel'.*COLLADA \(\.dae\) files only"):
        read_robot(_submesh_sdf(tmp_path / "n.sdf", "box.stl", "Body", "false"))
    with pytest.raises(RobotDescriptionError, match=r"<submesh><center> expected true or false, got 'yes'"):
        read_robot(_submesh_sdf(tmp_path / "o.sdf", "vehicle.dae", "Body", "yes"))


POLARIS = "/work/data/gazebo/polaris_ranger_ev/model.sdf"


@pytest.mark.skipif(not __import__("os").path.exists(POLARIS), reason="osrf gazebo_models not unpacked here")
def test_osrf_polaris_steering_wheel_submesh_is_read_and_centred():
    """osrf ``polaris_ranger_ev``: every wheel, pedal and the steering wheel is a ``<submesh>`` of polaris.dae
    with ``<center>true``; the steering wheel's sub-mesh is open (28 boundary edges), so it is an estimate
    with --repair, centred on its bounding box."""
    robot = read_robot(POLARIS)
    wheel = next(link for link in robot.links if link.name == "steering_wheel")
    (element,) = wheel.elements
    assert element.submesh == "Steering_Wheel" and element.submesh_center
    low, high = element_bounds(replace(element, rotation=np.eye(3), translation=np.zeros(3)))
    np.testing.assert_allclose(low + high, 0, atol=1e-6)


@settings(max_examples=30, deadline=None)
@given(_star_polygons(), st.floats(-1e6, 1e6), st.floats(-1e6, 1e6))
def test_polyline_moved_in_its_plane_keeps_its_central_tensor(star, dx, dy):
    # far from the frame's origin the sums are taken about the polygons' box centre: the central tensor of the
    # moved region matches the original's to round-off of its own size, not of the distance
    polygon, _, h = star
    here = extruded_region([polygon], h)
    there = extruded_region([polygon + [dx, dy]], h)
    assert there.volume == pytest.approx(here.volume, rel=1e-9)
    np.testing.assert_allclose(there.center_of_mass - [dx, dy, 0], here.center_of_mass,
                               atol=1e-9 * (1 + abs(dx) + abs(dy)))
    np.testing.assert_allclose(there.inertia, here.inertia, atol=1e-7 * np.abs(here.inertia).max())


def test_polyline_point_budget_is_checked_before_the_work():
    from inertia_tool.mass.extrusion import MAX_POLYGON_POINTS
    with pytest.raises(InvalidMeshError, match=f"at most {MAX_POLYGON_POINTS} polygon points"):
        polygon_region([_ngon(1.0, MAX_POLYGON_POINTS // 2 + 1), _ngon(0.5, MAX_POLYGON_POINTS // 2 + 1)])


def test_submesh_read_failure_names_the_users_file_not_a_copy(tmp_path):
    # a node that holds only lines: the reader's "no triangle mesh" names vehicle.dae [submesh 'Wire']
    path = _collada_scene(tmp_path / "vehicle.dae")
    text = path.read_text().replace("</library_geometries>", '<geometry id="wire" name="wire"><mesh><source '
                                    'id="w-p"><float_array id="w-a" count="6">0 0 0 1 0 0</float_array>'
                                    '<technique_common><accessor source="#w-a" count="2" stride="3"><param name="X" '
                                    'type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>'
                                    '</accessor></technique_common></source><vertices id="w-v"><input '
                                    'semantic="POSITION" source="#w-p"/></vertices><lines count="1"><input '
                                    'semantic="VERTEX" source="#w-v" offset="0"/><p>0 1</p></lines></mesh>'
                                    '</geometry></library_geometries>')
    text = text.replace("</visual_scene>", '<node id="n5" name="Wire"><instance_geometry url="#wire"/></node>'
                                           "</visual_scene>")
    path.write_text(text)
    robot = read_robot(_submesh_sdf(tmp_path / "m.sdf", "vehicle.dae", "Wire", "false"))
    (result,) = link_inertials(robot, density=1)
    assert result.properties is None and f"{path} [submesh 'Wire']" in result.problem
    assert "inertia_tool_submesh_" not in result.problem


def test_a_mesh_file_is_read_once_per_content_and_its_warnings_come_every_time(tmp_path):
    """The link integrals, the audit's bounds and its inside tests each want a link's mesh: it is read once
    (robot.geometry's read cache), its arrays read-only, the reader's warnings issued on every use; a file
    rewritten with other bytes of the same size is read again (the key hashes the content)."""
    import warnings

    from inertia_tool.robot import geometry

    path = tmp_path / "part.stl"
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), path)
    calls = []
    real = geometry._read_mesh_file

    def counting(*args):
        calls.append(args[0])
        return real(*args)

    geometry._READ_CACHE.clear()
    try:
        geometry._read_mesh_file = counting
        first = geometry._raw_mesh(str(path), None)
        again = geometry._raw_mesh(str(path), None)
        assert again is first and len(calls) == 1
        with pytest.raises(ValueError):
            first.vertices[0, 0] = 1.0                          # shared arrays are read-only
        shapes.write_stl(shapes.box(0.3, 0.2, 0.1), path)      # same size, other bytes
        other = geometry._raw_mesh(str(path), None)
        assert len(calls) == 2 and not np.array_equal(other.vertices, first.vertices)
        # a warning of the reader (a non-planar quadrilateral of an OBJ) comes with every use, not only the first
        quad = tmp_path / "quad.obj"
        quad.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0.3\nv 0 1 0\nv 0.5 0.5 -1\nf 1 2 3 4\nf 2 1 5\nf 3 2 5\n"
                        "f 4 3 5\nf 1 4 5\n")
        seen = []
        for _ in range(2):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                geometry._raw_mesh(str(quad), None)
            seen.append(sorted(str(w.message) for w in caught))
        assert len(calls) == 3 and seen[0] == seen[1] and any("not planar" in m for m in seen[0])
    finally:
        geometry._read_mesh_file = real
        geometry._READ_CACHE.clear()


def _exact_turn(a, b, c):
    from fractions import Fraction as Q
    (ax, ay), (bx, by), (cx, cy) = [(Q(float(x)), Q(float(y))) for x, y in (a, b, c)]
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (d > 0) - (d < 0)


def test_polyline_a_hole_within_rounding_of_the_outline_is_a_hole_not_a_touch():
    # the hole's first corner c lies 1 part in 1e17 to the left of the outline's edge a → b: a float turn calls
    # it on the edge ("polygons touch", refused), and a float ray test calls it outside, which made the hole a
    # second body (+19 % mass).  Exact turns place it inside, so the region is the outline less the triangle.
    a, b, c = (0.1, 0.1), (0.7, 0.35118216247002565), (0.6702782177955612, 0.33873952659240225)
    assert _exact_turn(a, b, c) == 1                       # truly inside, not on the edge
    outline = np.array([a, b, (0.7, 1.0), (0.1, 1.0)])
    hole = np.array([c, (0.65, 0.6), (0.5, 0.5)])
    _, signs = polygon_region([outline, hole])
    assert signs == (1, -1)

    def area(p):
        x, y = p[:, 0], p[:, 1]
        return 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))

    assert extruded_region([outline, hole], 0.2).volume == pytest.approx(0.2 * (area(outline) - area(hole)),
                                                                          rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.integers(3, 9), st.integers(0, 2**32 - 1), st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_point_in_polygon_is_exact_near_edges(sides, seed, t, lift):
    # points placed on an edge by rounded interpolation, then nudged by a few ulps off it: the even-odd answer must
    # match an exact rational ray test, which a float crossing-abscissa test gets wrong within rounding
    from fractions import Fraction as Q

    from inertia_tool.mass.extrusion import point_in_polygon
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, sides))
    polygon = np.column_stack([np.cos(angles), np.sin(angles)]) * rng.uniform(0.5, 2.0, (sides, 1))
    k = int(rng.integers(sides))
    a, b = polygon[k], polygon[(k + 1) % sides]
    point = a + t * (b - a)
    point = point + np.array([1, -1]) * lift * 4 * np.spacing(np.abs(point).max())

    def exact_inside(p):
        px, py = Q(float(p[0])), Q(float(p[1]))
        inside = False
        for i in range(sides):
            (ax, ay), (bx, by) = [(Q(float(x)), Q(float(y))) for x, y in (polygon[i], polygon[(i + 1) % sides])]
            if (ay <= py) != (by <= py):
                x = ax + (py - ay) * (bx - ax) / (by - ay)
                if x == px:
                    return None                            # on the boundary: either answer is allowed
                inside ^= px < x
        return inside

    truth = exact_inside(point)
    if truth is not None:
        assert point_in_polygon(point, polygon) == truth


def test_json_geometry_names_the_submesh(tmp_path, capsys):
    """Issue 23 item 5 (robots4): each ``geometry`` entry of ``robot --json`` names its SDFormat sub-mesh (the
    COLLADA node integrated), null for a whole file; the output still validates against the shipped schema."""
    import json

    from inertia_tool.cli import main
    from inertia_tool.reports.serialize import output_schema
    _collada_scene(tmp_path / "vehicle.dae")
    path = _submesh_sdf(tmp_path / "m.sdf", "vehicle.dae", "Wheel", "true")
    assert main(["robot", str(path), "--density", "1000", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["links"][0]["geometry"] == [{"kind": "mesh", "name": "c", "mesh": "vehicle.dae", "submesh": "Wheel"}]
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.Draft202012Validator(output_schema()).validate(out)
    whole = tmp_path / "w.sdf"
    whole.write_text(path.read_text().replace("<submesh><name>Wheel</name><center>true</center></submesh>", ""))
    assert main(["robot", str(whole), "--density", "1000", "--json"]) == 0
    entry = json.loads(capsys.readouterr().out)["links"][0]["geometry"][0]
    assert entry["submesh"] is None and entry["mesh"] == "vehicle.dae"
    assert "submesh" in output_schema()["$defs"]["robot_link"]["properties"]["geometry"]["items"]["properties"]


def test_an_sdformat_1_2_file_names_the_version_gazebo_loads(tmp_path):
    """osrf gazebo_models ship ``model-1_2.sdf`` (root ``<gazebo version="1.2">``) beside ``model.sdf``; the
    refusal said only "not an SDFormat file" (robots17): it names the format and the file Gazebo loads."""
    (tmp_path / "model.config").write_text('<model><sdf version="1.2">model-1_2.sdf</sdf>'
                                           '<sdf version="1.6">model.sdf</sdf></model>')
    (tmp_path / "model-1_2.sdf").write_text('<gazebo version="1.2"><model name="m"/></gazebo>')
    (tmp_path / "model.sdf").write_text('<sdf version="1.6"><model name="m"><link name="a"/></model></sdf>')
    with pytest.raises(RobotDescriptionError) as info:
        read_robot(str(tmp_path / "model-1_2.sdf"))
    message = str(info.value)
    assert "an SDFormat 1.2 file (root element <gazebo>" in message and "\n" not in message
    assert message.endswith(f"names {tmp_path / 'model.sdf'} as the newest version, which Gazebo loads")
    (tmp_path / "model.config").unlink()
    with pytest.raises(RobotDescriptionError, match=r"which this tool does not read; expected <sdf>$"):
        read_robot(str(tmp_path / "model-1_2.sdf"))
