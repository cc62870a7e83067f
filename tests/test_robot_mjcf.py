"""MJCF read as MuJoCo reads it (inertia_tool.robot.mjcf): <include>, default classes and their override rules,
sizes from classes for `fromto`, mesh refpos/refquat, <frame>, geom density/mass/shellinertia (the model's own
densities), massless geoms.  The independent reference is MuJoCo's compiler itself (inertiafromgeom)."""

import os

import numpy as np
import pytest

from inertia_tool.errors import RobotDescriptionError, UsageError
from inertia_tool.mass import shapes, shell_shapes
from inertia_tool.mass.surface import surface_moments
from inertia_tool.robot import audit_links, link_inertials, read_robot

from conftest import assert_tensor_close
from mujoco_reference import assert_like_mujoco

mujoco = pytest.importorskip("mujoco")


# one model using what the Menagerie files use: an included robot, two top-level <default> blocks, nested
# classes with childclass, an orientation from a class overridden by the geom's own (anymal_b), a fromto
# capsule whose radius comes from its class (agilex_piper, arx_l5), a size given in part, a mesh with
# refpos/refquat and scale (shadow_dexee), frames, and per-geom density and mass
SCENE = """<mujoco model="scene">
  <include file="robot.xml"/>
  <worldbody><light pos="0 0 3"/></worldbody>
</mujoco>
"""

ROBOT = """<mujoco model="robot">
  <compiler angle="radian" meshdir="assets" inertiafromgeom="true"/>
  <default>
    <mesh inertia="exact"/>
    <default class="arm">
      <geom type="capsule" size="0.02 0.1" quat="0 1 0 0" density="2700"/>
      <default class="blocky">
        <geom type="box" size="0.03 0.04 0.05"/>
      </default>
    </default>
  </default>
  <include file="parts.xml"/>
  <asset>
    <mesh name="cone" file="cone.stl" scale="0.001 0.002 0.001" refpos="3 -2 10" refquat="0.9 0.1 -0.3 0.2"/>
  </asset>
  <worldbody>
    <body name="base" pos="0 0 0.1">
      <freejoint/>
      <geom class="arm" euler="0.3 0.2 0.1"/>
      <geom class="arm" fromto="0 0 0 0.1 0.2 0.05"/>
      <geom class="blocky" size="0.01" pos="0.1 0 0"/>
      <body name="upper" pos="0 0 0.3" childclass="blocky">
        <joint type="ball"/>
        <geom pos="0 0 0.05"/>
        <geom class="wheel" pos="0.1 0 0"/>
        <frame pos="0 0.1 0" euler="0 0 1.2" childclass="arm">
          <geom pos="0.05 0 0" density="7800"/>
          <body name="tool" pos="0.1 0 0">
            <joint type="hinge"/>
            <geom type="mesh" mesh="cone" pos="0 -0.02 0.01" xyaxes="0 1 0 -1 0 0"/>
            <geom type="sphere" size="0.015" mass="0.25" pos="0 0 0.05"/>
          </body>
        </frame>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

PARTS = """<mujoco>
  <default>
    <default class="wheel"><geom type="cylinder" size="0.05 0.01" zaxis="1 0 0" density="500"/></default>
  </default>
</mujoco>
"""


@pytest.fixture
def scene(tmp_path):
    (tmp_path / "assets").mkdir()
    shapes.write_stl(shapes.cone(20.0, 50.0, segments=40), tmp_path / "assets" / "cone.stl")
    (tmp_path / "scene.xml").write_text(SCENE)
    (tmp_path / "robot.xml").write_text(ROBOT)
    (tmp_path / "parts.xml").write_text(PARTS)
    return tmp_path / "scene.xml"


def test_menagerie_style_scene_matches_mujoco_with_the_models_own_densities(scene):
    robot = read_robot(scene)
    assert [link.name for link in robot.links] == ["base", "upper", "tool"]
    results = link_inertials(robot, density="model")
    assert all(r.method == "exact" and r.uncertainty is None for r in results)
    assert_like_mujoco(scene, results)


def test_with_one_density_mujoco_agrees_when_its_geoms_have_that_density(scene, tmp_path):
    # the same bodies at 1000 kg/m³ everywhere: MuJoCo with every density attribute and mass removed
    text = (tmp_path / "robot.xml").read_text()
    for attr in ('density="2700"', 'density="7800"', 'density="500"', 'mass="0.25"'):
        text = text.replace(attr, "")
    (tmp_path / "robot.xml").write_text(text)
    (tmp_path / "parts.xml").write_text(PARTS.replace('density="500"', ""))
    assert_like_mujoco(scene, link_inertials(read_robot(scene), density=1000))


def test_the_geoms_own_orientation_replaces_its_class_orientation(tmp_path):
    # anymal_b: a class gives quat, the geom gives euler; MuJoCo takes the geom's (and the other way round)
    for cls, own in (('quat="0 1 0 0"', 'euler="90 0 0"'), ('euler="90 0 0"', 'quat="0.7 0 0.7 0.1"')):
        path = tmp_path / "o.xml"
        path.write_text(f'<mujoco><compiler inertiafromgeom="true"/><default><default class="c"><geom {cls}/>'
                        f'</default></default><worldbody><body name="b"><freejoint/><geom class="c" type="box" '
                        f'size="0.1 0.2 0.3" pos="0.1 0 0" {own}/></body></worldbody></mujoco>')
        assert_like_mujoco(path, link_inertials(read_robot(path), density=1000))


def _box_tensor(tmp_path, orientation):
    path = tmp_path / "o.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom type="box" size="0.1 0.2 0.3" pos="0 0.5 0" '
                    f'{orientation}/></body></worldbody></mujoco>')
    return link_inertials(read_robot(path), density=1000)[0].properties.inertia


@pytest.mark.parametrize("attribute, numbers", [
    ("quat", (1.0, 1.0, 0.0, 0.0)), ("quat", (0.7, 0.0, 0.7, 0.1)), ("axisangle", (1.0, 2.0, 3.0, 40.0)),
    ("zaxis", (1.0, 1.0, 0.0)), ("xyaxes", (1.0, 1.0, 0.0, -1.0, 2.0, 0.5))])
@pytest.mark.parametrize("factor", [1e300, 1e-300])
def test_an_orientation_scaled_near_the_float_limits_is_the_same_rotation(tmp_path, attribute, numbers, factor):
    # a quaternion or axis stands for its direction: ×1e300 once overflowed the norm to inf and silently gave
    # the identity rotation (an unrotated tensor labelled exact), ×1e-300 underflowed it to a refusal; xyaxes
    # shorter than 1e-6 are refused, as MuJoCo refuses them (next test)
    if attribute == "xyaxes" and factor < 1:
        factor = 1e-5
    scaled = [x * factor for x in numbers[:3]] + list(numbers[3:]) if attribute == "axisangle" \
        else [x * factor for x in numbers]
    reference = _box_tensor(tmp_path, f'{attribute}="{" ".join(map(repr, numbers))}"')
    assert_tensor_close(_box_tensor(tmp_path, f'{attribute}="{" ".join(map(repr, scaled))}"'), reference, 1e-12)


@pytest.mark.parametrize("xyaxes", ["1 1 0 1 1.0000001 0", "1 0 0 1e-5 1e-7 0", "1e-300 0 0 0 1 0"])
def test_nearly_parallel_xyaxes_are_refused_as_mujoco_refuses_them(tmp_path, xyaxes):
    # the part of y across x was a rounding residue of 1e-17 and set the rotation's second column
    with pytest.raises(ValueError, match="too small"):
        mujoco.MjModel.from_xml_string(f'<mujoco><worldbody><body><geom type="box" size="1 1 1" xyaxes="{xyaxes}"/>'
                                       '</body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="xyaxes are zero or parallel"):
        _box_tensor(tmp_path, f'xyaxes="{xyaxes}"')


def test_two_orientations_on_one_element_are_still_refused(tmp_path):
    path = tmp_path / "o.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom type="sphere" size="1" quat="1 0 0 0" '
                    'euler="0 0 1"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="more than one orientation"):
        read_robot(path)


def test_massless_geoms_are_left_out_and_named(tmp_path):
    # Robotiq 2F-85 pads: mass="0" boxes in a collision class; MuJoCo gives them no mass whatever their group
    path = tmp_path / "pad.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><default><default class="pad"><geom type="box" '
                    'mass="0" size="0.011 0.004 0.009" group="3"/></default></default><worldbody>'
                    '<body name="finger"><freejoint/><geom type="box" size="0.01 0.02 0.03"/>'
                    '<geom class="pad" name="pad1" pos="0 0.03 0"/><geom type="sphere" size="0.01" density="0" '
                    'pos="0 0 0.1"/></body><body name="ghost" pos="1 0 0"><freejoint/><inertial mass="1" '
                    'pos="0 0 0" diaginertia="1 1 1"/><geom class="pad"/></body></worldbody></mujoco>')
    finger, ghost = link_inertials(read_robot(path), density="model")
    assert len(finger.warnings) == 2
    assert "'pad1' is massless in the description (mass=0)" in finger.warnings[0]
    assert "density=0" in finger.warnings[1]
    assert finger.properties.mass == pytest.approx(1000 * 0.02 * 0.04 * 0.06, rel=1e-14)
    assert ghost.properties is None and ghost.problem.startswith(
        "every geom is massless in the description (--density RHO")
    # with one density for everything the pads count as geometry (the user asked for that density)
    assert link_inertials(read_robot(path), density=1000)[0].properties.mass > finger.properties.mass


@pytest.mark.parametrize("geom", ['type="sphere" size="0.3"', 'type="box" size="0.1 0.2 0.3"',
                                  'type="cylinder" size="0.1 0.2"', 'type="capsule" size="0.1 0.2"',
                                  'type="capsule" fromto="0 0 0 0.1 0.2 0.3" size="0.05"'])
def test_shellinertia_matches_mujoco(tmp_path, geom):
    path = tmp_path / "s.xml"
    pose = "" if "fromto" in geom else 'pos="0.1 0.2 0.3" euler="10 20 30"'    # MuJoCo refuses pos with fromto
    path.write_text(f'<mujoco><compiler inertiafromgeom="true"/><worldbody><body name="b"><freejoint/>'
                    f'<geom {geom} shellinertia="true" density="3" {pose}/></body></worldbody></mujoco>')
    assert_like_mujoco(path, link_inertials(read_robot(path), density="model"), rtol=1e-12)


def test_mesh_shell_inertia_matches_mujoco(tmp_path):
    shapes.write_stl(shapes.cone(0.2, 0.5, segments=32), tmp_path / "cone.stl")
    path = tmp_path / "s.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><asset><mesh name="m" file="cone.stl" '
                    'inertia="shell" scale="1 2 1" refpos="0.1 0 0"/></asset><worldbody><body name="b"><freejoint/>'
                    '<geom type="mesh" mesh="m" density="3" pos="0.1 0.2 0.3"/></body></worldbody></mujoco>')
    assert_like_mujoco(path, link_inertials(read_robot(path), density="model"), rtol=1e-9)


def test_shell_closed_forms_against_fine_triangulations():
    # independent: the surface integral of trimesh's fine meshes (exact for the polyhedron) approaches the
    # closed form as the triangulation refines
    trimesh = pytest.importorskip("trimesh")
    cases = [(shell_shapes.sphere_shell(0.3), trimesh.creation.icosphere(subdivisions=6, radius=0.3), 1e-3),
             (shell_shapes.box_shell((0.2, 0.4, 0.6)), trimesh.creation.box(extents=(0.2, 0.4, 0.6)), 1e-13),
             (shell_shapes.cylinder_shell(0.1, 0.4), trimesh.creation.cylinder(radius=0.1, height=0.4, sections=2048),
              1e-5),
             (shell_shapes.capsule_shell(0.1, 0.4), trimesh.creation.capsule(height=0.4, radius=0.1, count=[256, 256]),
              1e-3)]
    for exact, mesh, rtol in cases:
        moments = surface_moments(mesh.vertices, mesh.faces)
        assert moments.area == pytest.approx(exact.mass, rel=rtol)
        c = moments.second_moment
        assert_tensor_close(np.trace(c) * np.eye(3) - c, exact.inertia, rtol * 3)


def test_an_ellipsoid_shell_is_a_reason_not_a_number(tmp_path):
    path = tmp_path / "e.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom type="ellipsoid" size="1 2 3" shellinertia="true"/>'
                    '</body><body name="c"><geom type="sphere" size="1"/></body></worldbody></mujoco>')
    b, c = link_inertials(read_robot(path), density="model")
    assert b.properties is None and "ellipsoid" in b.problem
    assert c.properties is not None


def test_model_densities_need_mjcf():
    from robot_data import UR5, PACKAGES
    with pytest.raises(UsageError, match="MJCF"):
        link_inertials(read_robot(UR5, packages=PACKAGES), density="model")


def test_include_cycle_depth_and_missing_file_are_refused(tmp_path):
    (tmp_path / "a.xml").write_text('<mujoco><include file="b.xml"/></mujoco>')
    (tmp_path / "b.xml").write_text('<mujoco><include file="a.xml"/></mujoco>')
    with pytest.raises(RobotDescriptionError, match="includes itself"):
        read_robot(tmp_path / "a.xml")
    for k in range(20):
        (tmp_path / f"d{k}.xml").write_text(f'<mujoco><include file="d{k + 1}.xml"/></mujoco>')
    (tmp_path / "d20.xml").write_text('<mujoco><worldbody><body name="x"><geom size="1"/></body></worldbody>'
                                      '</mujoco>')
    with pytest.raises(RobotDescriptionError, match="nested more than 16 deep"):
        read_robot(tmp_path / "d0.xml")
    assert read_robot(tmp_path / "d5.xml").links[0].name == "x"
    (tmp_path / "m.xml").write_text('<mujoco><include file="nowhere.xml"/></mujoco>')
    with pytest.raises(RobotDescriptionError, match="nowhere.xml.*no such file"):
        read_robot(tmp_path / "m.xml")
    (tmp_path / "u.xml").write_text('<mujoco><include file="r.urdf"/></mujoco>')
    (tmp_path / "r.urdf").write_text('<robot name="r"/>')
    with pytest.raises(RobotDescriptionError, match="expected <mujoco> or <mujocoinclude>"):
        read_robot(tmp_path / "u.xml")


def test_include_found_beside_the_including_file_and_its_meshdir(tmp_path):
    # MuJoCo looks in the main model's folder first, then beside the including file; a mesh of an included
    # file in a sub-folder is found through that file's own meshdir (MuJoCo itself would need it in the main
    # folder's meshdir: the fallback only applies where MuJoCo finds nothing)
    sub = tmp_path / "robots" / "arm"
    (sub / "meshes").mkdir(parents=True)
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), sub / "meshes" / "part.stl")
    (tmp_path / "scene.xml").write_text('<mujoco><include file="robots/arm/arm.xml"/></mujoco>')
    (sub / "arm.xml").write_text('<mujoco><compiler meshdir="meshes"/><include file="body.xml"/></mujoco>')
    (sub / "body.xml").write_text('<mujoco><asset><mesh file="part.stl"/></asset><worldbody><body name="b">'
                                  '<geom type="mesh" mesh="part"/></body></worldbody></mujoco>')
    (result,) = link_inertials(read_robot(tmp_path / "scene.xml"), density=1000)
    assert result.properties.mass == pytest.approx(6.0, rel=1e-6)          # float32 STL corners
    assert read_robot(tmp_path / "scene.xml").links[0].elements[0].mesh == os.path.join(sub, "meshes", "part.stl")


def test_partial_size_keeps_the_class_numbers(tmp_path):
    # size="0.01" on a box whose class says "0.03 0.04 0.05": MuJoCo reads 0.01 0.04 0.05
    path = tmp_path / "p.xml"
    path.write_text('<mujoco><default><default class="k"><geom type="box" size="0.03 0.04 0.05"/></default>'
                    '</default><worldbody><body name="b"><geom class="k" size="0.01"/></body></worldbody></mujoco>')
    assert read_robot(path).links[0].elements[0].size == pytest.approx((0.02, 0.08, 0.1))


def test_replicate_names_and_masses_match_mujoco(tmp_path):
    path = tmp_path / "r.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><worldbody>'
                    '<replicate count="2" offset="1 0 0" sep="o"><replicate count="11" offset="0 1 0" sep="i">'
                    '<body name="b"><freejoint/><geom type="box" size="0.1 0.2 0.3" euler="10 0 0"/>'
                    '<body name="c"><joint/><geom size="0.05" pos="0 0 0.2"/></body></body></replicate></replicate>'
                    '</worldbody></mujoco>')
    results = link_inertials(read_robot(path), density=1000)
    assert [r.name for r in results][:4] == ["bi00o0", "ci00o0", "bi01o0", "ci01o0"] and len(results) == 44
    assert_like_mujoco(path, results)


def test_attach_of_a_missing_model_is_refused_not_skipped(tmp_path):
    # <attach> is read (tests/test_robot_mjcf_extras.py); a model file that is not there is named, never skipped
    path = tmp_path / "a.xml"
    path.write_text('<mujoco><asset><model name="g" file="g.xml"/></asset><worldbody><body name="b">'
                    '<attach model="g" body="hand" prefix="g_"/></body></worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match="<attach model='g'>: the model file .*g.xml does not exist"):
        read_robot(path)


@pytest.mark.parametrize("kind", ["capsule", "cylinder", "box", "sphere", "ellipsoid"])
def test_a_primitive_fitted_to_a_mesh_matches_mujoco(tmp_path, kind):
    # arx_l5: <geom mesh="link1" class="collision"/> where the class says type="capsule" and nothing gives a size
    # ("capsule needs 1 size values, got None"): MuJoCo fits the primitive to the mesh's equivalent inertia box
    trimesh = pytest.importorskip("trimesh")
    block = trimesh.creation.box(extents=[0.1, 0.2, 0.4])
    block.apply_transform(trimesh.transformations.euler_matrix(0.3, 0.5, 0.7))
    block.apply_translation([0.3, 0.1, 0.2])
    block.export(tmp_path / "block.stl")
    path = tmp_path / "fit.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><default><default class="collision">'
                    f'<geom type="{kind}" group="3"/></default></default><asset><mesh name="m" file="block.stl" '
                    'scale="1 1.5 1"/></asset><worldbody><body name="b"><freejoint/><geom class="collision" mesh="m" '
                    'pos="0.01 0 0.02" euler="0.1 0.2 0.3" fitscale="1.2"/></body></worldbody></mujoco>')
    robot = read_robot(path)
    assert robot.links[0].elements[0].fit_scale == 1.2
    assert_like_mujoco(path, link_inertials(robot, density=1000), rtol=1e-6)     # float32 STL corners


@pytest.mark.parametrize("kind", ["capsule", "cylinder", "box", "sphere", "ellipsoid"])
def test_a_primitive_fitted_to_a_meshs_bounding_box_matches_mujoco(tmp_path, kind):
    # Menagerie's realsense_d435i: <compiler fitaabb="true"> and a capsule fitted to a mesh, refused before; the
    # mesh is a convex hull of scattered points, so the bounding box's centre is not the centre of volume
    trimesh = pytest.importorskip("trimesh")
    points = np.random.default_rng(23).normal(size=(40, 3)) * [0.03, 0.05, 0.12] + [0.2, 0.1, -0.1]
    trimesh.convex.convex_hull(points).export(tmp_path / "hull.stl")
    path = tmp_path / "fit.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true" fitaabb="true"/><asset><mesh name="m" '
                    'file="hull.stl" scale="1 1.5 1"/></asset><worldbody><body name="b"><freejoint/>'
                    f'<geom type="{kind}" mesh="m" pos="0.01 0 0.02" euler="0.1 0.2 0.3" fitscale="1.2"/>'
                    '</body></worldbody></mujoco>')
    robot = read_robot(path)
    assert robot.links[0].elements[0].fit_aabb
    assert_like_mujoco(path, link_inertials(robot, density=1000), rtol=1e-6)     # float32 STL corners


def test_a_primitive_fitted_to_a_mesh_is_as_sure_as_the_mesh(tmp_path):
    # arx_l5 link2: a capsule fitted to a mesh whose bodies overlap was labelled "exact", and differed from
    # MuJoCo's fit (which counts the overlap twice) by 1.6e-3; the fit is only as sure as the mesh's integrals
    trimesh = pytest.importorskip("trimesh")
    from conftest import write_binary_stl
    a = trimesh.creation.box(extents=[0.1, 0.1, 0.3])
    b = trimesh.creation.box(extents=[0.3, 0.1, 0.1])
    both = trimesh.util.concatenate([a, b])                   # two closed boxes crossing each other
    write_binary_stl(tmp_path / "cross.stl", both.vertices, both.faces)
    path = tmp_path / "c.xml"
    path.write_text('<mujoco><asset><mesh name="m" file="cross.stl"/></asset><worldbody><body name="b">'
                    '<geom type="capsule" mesh="m"/></body><body name="c"><geom type="mesh" mesh="m"/></body>'
                    '</worldbody></mujoco>')
    fit, mesh = link_inertials(read_robot(path), density=1000)
    assert mesh.method in ("united", "unverified")
    assert fit.method == mesh.method


def test_all_geoms_with_the_models_densities_is_mujocos_inertia_from_geometry(tmp_path):
    # Menagerie style: visual geoms (contype 0) with their default density count in MuJoCo's inertia from
    # geometry, a geom outside inertiagrouprange does not; --geometry all --density model reproduces it
    path = tmp_path / "g.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true" inertiagrouprange="0 3"/><default>'
                    '<default class="visual"><geom contype="0" conaffinity="0" group="2"/></default></default>'
                    '<worldbody><body name="b"><freejoint/><geom type="box" size="0.1 0.2 0.3" group="3"/>'
                    '<geom class="visual" type="sphere" size="0.1" pos="0.3 0 0" density="500"/>'
                    '<geom type="sphere" size="0.2" pos="0 0.5 0" group="4"/></body></worldbody></mujoco>')
    results = link_inertials(read_robot(path, geometry="all"), density="model")
    assert_like_mujoco(path, results, rtol=1e-12)
    with pytest.raises(UsageError, match="MJCF only"):
        from robot_data import UR5, PACKAGES
        read_robot(UR5, packages=PACKAGES, geometry="all")


def test_menagerie_2f85_finger_matches_mujoco_body_by_body():
    # real MJCF (MuJoCo Menagerie robotiq_2f85, the right linkage; tests/data/README.md): classes, mesh classes
    # with a scale, massless pad boxes (mass="0" in a class), visual geoms of the default density; every geom
    # in inertiagrouprange with the file's densities against MuJoCo's compiler with exact mesh inertia
    from pathlib import Path
    path = Path(__file__).parent / "data" / "robots" / "menagerie_2f85" / "2f85_right_finger.xml"
    spec = mujoco.MjSpec.from_file(str(path))
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    model = spec.compile()
    results = {r.name: r for r in link_inertials(read_robot(path, geometry="all"), density="model")}
    assert len(results) == model.nbody - 1
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        props = results[model.body(i).name].properties
        assert props.mass == pytest.approx(model.body_mass[i], rel=1e-6)         # float32 STL corners
        np.testing.assert_allclose(props.center_of_mass, model.body_ipos[i], atol=1e-8)
        assert_tensor_close(props.inertia, rot @ np.diag(model.body_inertia[i]) @ rot.T, 1e-6)
    pad = {r.name: r for r in link_inertials(read_robot(path), density="model")}["right_pad"]
    assert pad.properties is None and pad.problem.startswith(
        "every geom is massless in the description (--density RHO")
    assert [w.split(" is massless")[0] for w in pad.warnings] == ["box 'right_pad1'", "box 'right_pad2'"]


def test_a_capsule_fitted_to_an_open_mesh_with_repair_is_audited_without_stopping(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    from conftest import write_binary_stl
    from inertia_tool.robot import audit_links
    ball = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
    ball.apply_scale([1.0, 1.5, 3.0])
    write_binary_stl(tmp_path / "open.stl", ball.vertices, ball.faces[:-1])     # one small triangle missing
    path = tmp_path / "o.xml"
    path.write_text('<mujoco><asset><mesh name="m" file="open.stl"/></asset><worldbody><body name="b">'
                    '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom type="capsule" mesh="m"/></body>'
                    '<body name="c"><geom type="sphere" size="0.1"/></body></worldbody></mujoco>')
    robot = read_robot(path)
    results = link_inertials(robot, density=1000, repair=True)
    assert results[0].properties is not None and results[1].properties is not None
    audits = audit_links(robot, results)
    assert audits[0].com_inside_geometry is None and audits[0].issues        # no box without repair: unknown
    # a bound follows for a fit to a repaired mesh (robots10: fitted_mass_bound); it holds against the capsule fitted
    # to the whole mesh
    assert results[0].method == "estimate" and results[0].uncertainty.inertia is None
    write_binary_stl(tmp_path / "whole.stl", ball.vertices, ball.faces)
    whole = tmp_path / "w.xml"
    whole.write_text(path.read_text().replace("open.stl", "whole.stl"))
    truth = link_inertials(read_robot(whole), density=1000)[0].properties
    got = results[0].properties
    assert abs(got.mass - truth.mass) <= results[0].uncertainty.mass * got.mass
    assert np.linalg.norm(got.center_of_mass - truth.center_of_mass) <= results[0].uncertainty.center_of_mass + 1e-15
    unrepaired = link_inertials(robot, density=1000)
    assert unrepaired[0].properties is None and "mesh needs repair" in unrepaired[0].problem


def test_geoms_of_an_explicit_contact_pair_are_collision_geometry(tmp_path):
    # Menagerie's MJX models switch every geom's contype/conaffinity off and list their contacts as
    # <contact><pair>: MuJoCo collides those geoms all the same (a contact appears), so they are collision geometry
    path = tmp_path / "pairs.xml"
    path.write_text('<mujoco><default><geom contype="0" conaffinity="0"/></default><worldbody>'
                    '<body name="foot"><freejoint/><geom name="sole" type="sphere" size="0.1"/>'
                    '<geom name="shin" type="box" size="0.1 0.1 0.1" pos="0 0 0.5"/></body>'
                    '<body name="floor" pos="0 0 -0.15"><geom name="plate" type="box" size="1 1 0.1"/></body>'
                    '</worldbody><contact><pair geom1="sole" geom2="plate"/></contact></mujoco>')
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.ncon == 1 and {model.geom(data.contact.geom1[0]).name, model.geom(data.contact.geom2[0]).name} == {
        "sole", "plate"}
    links = {link.name: link for link in read_robot(path).links}
    assert [e.name for e in links["foot"].elements] == ["sole"]
    assert [e.name for e in links["floor"].elements] == ["plate"]
    visual = {link.name: link for link in read_robot(path, geometry="visual").links}
    assert [e.name for e in visual["foot"].elements] == ["shin"] and visual["floor"].elements == ()


def test_a_body_without_a_geom_in_the_group_range_says_so(tmp_path):
    path = tmp_path / "g.xml"
    path.write_text('<mujoco><compiler inertiagrouprange="0 2"/><worldbody><body name="b">'
                    '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom type="sphere" size="0.1" group="3"/>'
                    '</body></worldbody></mujoco>')
    result = link_inertials(read_robot(path, geometry="all"), density="model")[0]
    assert result.properties is None and result.problem == "no geom in <compiler inertiagrouprange>"


def test_included_files_as_mujoco_reads_them_mujocoinclude_root_and_meshes_beside_the_included_file(tmp_path):
    # MyoSuite and Meta-World include <mujocoinclude> files; MuJoCo Playground's mjx_scene.xml includes
    # Menagerie's mjx_panda.xml (meshdir="assets", mesh file="assets/link0.stl") from another folder, which
    # MuJoCo finds beside the included file when <main folder>/<meshdir>/<file> does not exist
    robot = tmp_path / "menagerie" / "panda"
    (robot / "assets").mkdir(parents=True)
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), robot / "assets" / "link0.stl")
    (robot / "panda.xml").write_text('<mujoco><compiler meshdir="assets"/><include file="defaults.xml"/>'
                                     '<asset><mesh name="l0" file="assets/link0.stl"/></asset><worldbody>'
                                     '<body name="link0"><geom class="k" type="mesh" mesh="l0"/></body>'
                                     '</worldbody></mujoco>')
    (robot / "defaults.xml").write_text('<mujocoinclude><default><default class="k"><geom density="500"/>'
                                        '</default></default></mujocoinclude>')
    scene = tmp_path / "playground" / "xmls" / "mjx_scene.xml"
    scene.parent.mkdir(parents=True)
    scene.write_text('<mujoco><include file="../../menagerie/panda/panda.xml"/></mujoco>')
    spec = mujoco.MjSpec.from_file(str(scene))
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    model = spec.compile()
    description = read_robot(scene)
    assert description.links[0].elements[0].mesh == str(robot / "assets" / "link0.stl")
    (result,) = link_inertials(description, density="model")
    assert result.properties.mass == pytest.approx(model.body("link0").mass[0], rel=1e-12)
    assert result.properties.mass == pytest.approx(500 * 0.006, rel=1e-6)               # float32 corners


def test_a_plane_in_a_body_has_no_mass_as_in_mujoco(tmp_path):
    # MuJoCo Playground's mjx_cabinet.xml: a plane geom in body 'barrier' (MuJoCo gives a plane no inertia)
    path = tmp_path / "p.xml"
    path.write_text('<mujoco><compiler inertiafromgeom="true"/><worldbody><body name="barrier" pos="0 0 1">'
                    '<geom type="plane" size="1 1 0.1"/><geom type="sphere" size="0.1" pos="0 0.2 0"/></body>'
                    '</worldbody></mujoco>')
    assert_like_mujoco(path, link_inertials(read_robot(path), density=1000), rtol=1e-12)


def test_a_missing_mesh_file_refuses_the_model_or_only_its_body(tmp_path):
    # MuJoCo Menagerie as distributed without its largest files (ur5e's upperarm_3.obj, franka_fr3's link0.obj):
    # by default the description is refused with the file named; per-link, the body says which file is missing
    # and every other body is computed; a massless geom's missing file costs nothing with the model's densities
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box(extents=[0.1, 0.2, 0.3]).export(tmp_path / "here.stl")
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><asset><mesh name="here" file="here.stl"/><mesh name="gone" file="gone.obj"/></asset>'
                    '<worldbody><body name="a"><geom type="mesh" mesh="here"/></body>'
                    '<body name="b"><geom type="mesh" mesh="gone"/><geom type="box" size="0.1 0.1 0.1"/></body>'
                    '<body name="c"><geom type="mesh" mesh="gone" density="0"/><geom type="sphere" size="0.1"/></body>'
                    '</worldbody></mujoco>')
    with pytest.raises(RobotDescriptionError, match=r"gone\.obj.*which does not exist"):
        read_robot(path)
    with pytest.raises(UsageError, match="missing_meshes"):
        read_robot(path, missing_meshes="skip")
    robot = read_robot(path, missing_meshes="per-link")
    a, b, c = link_inertials(robot, density="model")
    assert a.properties.mass == pytest.approx(6.0, rel=1e-6) and a.method == "exact"      # float32 STL
    assert b.properties is None and b.problem == f"mesh file missing: {tmp_path / 'gone.obj'}"
    assert c.properties.mass == pytest.approx(1000 * 4 / 3 * np.pi * 0.1 ** 3, rel=1e-12)
    assert link_inertials(robot, density=1000)[2].problem.startswith("mesh file missing")
    audit_links(robot, link_inertials(robot, density="model"))          # the audit does not stop at the file
