"""Link mass properties from geometry (inertia_tool.robot.geometry): closed forms, poses, scale, sums,
and MuJoCo's own inertia-from-geometry as the independent reference for MJCF."""

import numpy as np
import pytest
import trimesh

import inertia_tool as it
from inertia_tool.mass import shapes
from inertia_tool.errors import UsageError
from inertia_tool.mesh.read import load_mesh
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.description import GeometryElement, LinkGeometry, rpy_to_matrix
from inertia_tool.robot.geometry import (element_mass_properties, link_mass_properties, points_inside_element,
                                         _capsule, _ellipsoid)

from conftest import assert_tensor_close
from robot_data import PACKAGES, UR5


def _element(kind, size=(), rpy=(0, 0, 0), xyz=(0, 0, 0), **kw):
    return GeometryElement(kind, rpy_to_matrix(rpy), xyz, size=size, **kw)


def test_capsule_closed_form_against_fine_meshes():
    # independent: trimesh's capsule meshes integrated by the engine approach the closed form as O(1/n²), so
    # Richardson extrapolation of n = 64 and 128, (4 P₁₂₈ − P₆₄)/3, must agree far better than either mesh
    r, length = 0.03, 0.1
    props = []
    for n in (64, 128):
        mesh = trimesh.creation.capsule(height=length, radius=r, count=[n, n])
        mesh.merge_vertices()                         # trimesh leaves the seam vertices duplicated
        props.append(it.mass_properties(mesh, density=1.0))
    exact = _capsule(r, length)
    assert abs(props[1].volume / exact.volume - 1) < 1e-3
    assert (4 * props[1].volume - props[0].volume) / 3 == pytest.approx(exact.volume, rel=1e-5)
    assert_tensor_close((4 * props[1].inertia - props[0].inertia) / 3, exact.inertia, 2e-5)


def _scaled_rule(props, scale):
    """The mesh-scale rule written out independently: volume |det S| V, centre S c, central second moments
    Σ = ∫ x xᵀ dV become |det S| S Σ S, and I = tr(Σ) 1 − Σ (Eq. 4.13)."""
    s = np.asarray(scale, dtype=float)
    det = abs(float(np.prod(s)))
    sigma = 0.5 * np.trace(props.inertia) * np.eye(3) - props.inertia
    sigma = det * (s[:, None] * sigma * s[None, :])
    return det * props.volume, s * props.center_of_mass, np.trace(sigma) * np.eye(3) - sigma


@pytest.mark.parametrize("scale", [(0.3, 0.4, 0.5), (0.3, -0.4, 0.5), (-1e-3, -1e-3, -1e-3)])
def test_a_scaled_mesh_follows_the_scale_rule(tmp_path, scale):
    # the scale is applied to the vertices before the engine integrates them; the integrals must be the
    # analytic transformation of the unscaled mesh's (a mirror reverses the faces, so the volume stays positive)
    solid = shapes.sphere(1.0, segments=3, rings=2)
    path = str(tmp_path / "s.stl")
    shapes.write_stl(solid, path)
    unscaled = element_mass_properties(_element("mesh", mesh=path))
    props = element_mass_properties(_element("mesh", mesh=path, scale=scale))
    volume, com, inertia = _scaled_rule(unscaled, scale)
    assert props.volume == pytest.approx(volume, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, com, atol=1e-15)
    assert_tensor_close(props.inertia, inertia, 1e-12)


def test_scaled_sphere_approaches_the_ellipsoid():
    # the rule on a fine sphere mesh: the ellipsoid's closed form, to the mesh's own discretisation error
    sphere = it.mass_properties(trimesh.creation.icosphere(5), density=1.0)
    volume, _, inertia = _scaled_rule(sphere, [0.3, 0.4, 0.5])
    exact = _ellipsoid(0.3, 0.4, 0.5)
    assert volume == pytest.approx(exact.volume, rel=2e-3)
    assert_tensor_close(inertia, exact.inertia, 5e-3)


def test_engine_messages_speak_of_the_scaled_body(tmp_path):
    # two overlapping millimetre boxes scaled by 0.001 in the description: the overlap warning gives the shared
    # volume of the body as placed, in m³ (it gave the file's mm³ labelled m³: 224.416 m³ for a Robotiq base)
    a = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    b = a.copy()
    b.apply_translation((5.0, 0.0, 0.0))
    path = str(tmp_path / "two.stl")
    trimesh.util.concatenate([a, b]).export(path)
    with pytest.warns(it.errors.OverlapWarning) as record:
        props = element_mass_properties(_element("mesh", mesh=path, scale=(1e-3, 1e-3, 1e-3)))
    assert props.volume == pytest.approx(1.5e-6, rel=1e-9)
    message = str(record[0].message)
    assert "5e-07 m³" in message, message


def test_two_boxes_side_by_side_are_one_box():
    # parallel-axis sum in the link frame: two unit cubes at x = 0.5 and 1.5 are the 2×1×1 box centred at x = 1
    link = LinkGeometry("l", (_element("box", (1, 1, 1), xyz=(0.5, 0, 0)), _element("box", (1, 1, 1), xyz=(1.5, 0, 0))),
                        None)
    props = link_mass_properties(link)
    exact = shapes.box(2, 1, 1, center=(1, 0, 0)).exact
    assert props.mass == pytest.approx(exact.mass, rel=1e-15)
    np.testing.assert_allclose(props.center_of_mass, exact.center_of_mass, atol=1e-15)
    assert_tensor_close(props.inertia, exact.inertia, 1e-14)


def test_rolled_cylinder_turns_its_axis():
    # roll of +90° about x takes the cylinder axis z to -y: the axial moment MR²/2 appears in I_yy
    r, h = 0.05, 0.4
    props = element_mass_properties(_element("cylinder", (r, h), rpy=(np.pi / 2, 0, 0), xyz=(0, 0, 1)))
    m = np.pi * r * r * h
    assert_tensor_close(props.inertia,
                        np.diag([m * (r * r / 4 + h * h / 12), m * r * r / 2, m * (r * r / 4 + h * h / 12)]),
                        1e-14)
    np.testing.assert_allclose(props.center_of_mass, [0, 0, 1], atol=1e-15)


def test_mesh_element_with_origin_and_scale(tmp_path):
    # a cylinder mesh written in mm, read through <mesh scale="0.001 ..."> and an origin, against mesh_exact
    solid = shapes.cylinder(20.0, 50.0, segments=64)
    path = tmp_path / "cyl.stl"
    shapes.write_stl(solid, path)
    rpy, xyz, s = (0.3, -0.2, 1.1), (0.1, 0.2, 0.3), (0.001, 0.002, 0.001)
    props = element_mass_properties(_element("mesh", rpy=rpy, xyz=xyz, mesh=str(path), scale=s))
    # reference: scale the file's (float32) vertices, then move them, then integrate
    raw = load_mesh(path)
    verts = (raw.vertices * s) @ rpy_to_matrix(rpy).T + xyz
    reference = it.mass_properties((verts, raw.faces), density=1.0)
    assert props.volume == pytest.approx(reference.volume, rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, reference.center_of_mass, atol=1e-14)
    assert_tensor_close(props.inertia, reference.inertia, 1e-11)


def test_mirrored_mesh_scale_keeps_a_positive_volume(tmp_path):
    solid = shapes.box(1, 2, 3, center=(1, 0, 0))
    path = tmp_path / "box.stl"
    shapes.write_stl(solid, path)
    props = element_mass_properties(_element("mesh", mesh=str(path), scale=(-1, 1, 1)))
    assert props.volume == pytest.approx(6.0)
    np.testing.assert_allclose(props.center_of_mass, [-1, 0, 0], atol=1e-14)


def test_inside_tests_of_the_primitives():
    cap = _element("capsule", (0.1, 0.4), rpy=(0, np.pi / 2, 0))      # axis along x
    assert points_inside_element(cap, [0.29, 0, 0]) and not points_inside_element(cap, [0.31, 0, 0])
    box = _element("box", (1, 2, 3), xyz=(5, 0, 0))
    assert points_inside_element(box, [5.4, 0.9, 1.4]) and not points_inside_element(box, [4.4, 0, 0])


def test_density_material_keep_mass_are_exclusive():
    robot = read_robot(UR5, packages=PACKAGES)
    with pytest.raises(UsageError):
        link_inertials(robot, density=1000, keep_mass=True)
    with pytest.raises(UsageError):
        link_inertials(robot)


def test_keep_mass_reports_the_implied_density():
    robot = read_robot(UR5, packages=PACKAGES)
    by_name = {r.name: r for r in link_inertials(robot, keep_mass=True)}
    upper = by_name["upper_arm_link"]
    assert upper.properties.mass == 8.393
    assert upper.density == pytest.approx(8.393 / upper.properties.volume)
    steel = {r.name: r for r in link_inertials(robot, material="steel")}["upper_arm_link"]
    # same shape: the tensors differ only by the mass ratio
    assert_tensor_close(upper.properties.inertia, steel.properties.inertia * (8.393 / steel.properties.mass), 1e-13)
    assert by_name["world"].properties is None and "no collision geometry" in by_name["world"].problem


MJCF = """<mujoco model="t">
  <compiler angle="degree"/>
  <asset><mesh name="m" file="{mesh}" scale="0.001 0.002 0.001"/></asset>
  <default><geom density="1000"/><default class="c"><geom type="capsule" size="0.02 0.05"/></default></default>
  <worldbody>
    <body name="a" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.1 0.05 0.02" pos="0.1 0 0" euler="10 20 30"/>
      <geom class="c" pos="0 0.1 0" axisangle="1 1 0 40"/>
      <geom type="cylinder" fromto="0 0 0 0.1 0.2 0.3" size="0.03"/>
      <geom type="ellipsoid" size="0.03 0.04 0.05" quat="0.9 0.1 0.2 0.3" pos="0 0 -0.1"/>
      <frame pos="0.2 0 0" euler="0 0 90"><geom type="sphere" size="0.04" pos="-0.1 0 0"/></frame>
      <geom type="mesh" mesh="m" pos="0 -0.2 0" xyaxes="0 1 0 -1 0 0"/>
      <body name="b" pos="0 0 0.5"><joint type="ball"/><geom type="box" size="0.01 0.02 0.03" zaxis="1 1 1"/></body>
    </body>
  </worldbody>
</mujoco>
"""


def test_mjcf_bodies_match_mujocos_inertia_from_geometry(tmp_path):
    # independent code: MuJoCo's compiler computes each body's inertia from its geoms (density 1000 here)
    mujoco = pytest.importorskip("mujoco")
    mesh = tmp_path / "cone.stl"
    shapes.write_stl(shapes.cone(20.0, 50.0, segments=48), mesh)
    path = tmp_path / "t.xml"
    path.write_text(MJCF.format(mesh=mesh))
    model = mujoco.MjModel.from_xml_path(str(path))
    ours = {r.name: r.properties for r in link_inertials(read_robot(path), density=1000)}
    for body in ("a", "b"):
        i = model.body(body).id
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        tensor = rot @ np.diag(model.body_inertia[i]) @ rot.T
        assert ours[body].mass == pytest.approx(model.body_mass[i], rel=1e-12)
        np.testing.assert_allclose(ours[body].center_of_mass, model.body_ipos[i], atol=1e-12)
        assert_tensor_close(ours[body].inertia, tensor, 1e-10)


def test_cassie_sdf_primitives_in_closed_form():
    # a real SDFormat model: the pelvis is a sphere r = 0.14 at (0.02, 0, 0.04); the left hip pitch a cylinder
    # r = 0.06, l = 0.18 posed at (0.053, 0, -0.0379) with pitch 1.57 rad (its axis turned towards x)
    from robot_data import CASSIE_SDF
    robot = read_robot(CASSIE_SDF)
    assert robot.format == "sdf" and len(robot.links) == 23
    ours = {r.name: r.properties for r in link_inertials(robot, density=1000) if r.properties is not None}
    assert len(ours) == 9
    pelvis = ours["pelvis"]
    m = 1000 * 4 / 3 * np.pi * 0.14 ** 3
    assert pelvis.mass == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(pelvis.center_of_mass, [0.02, 0, 0.04], atol=1e-16)
    assert_tensor_close(pelvis.inertia, np.eye(3) * 0.4 * m * 0.14 ** 2, 1e-14)
    hip = ours["left-hip-pitch"]
    m = 1000 * np.pi * 0.06 ** 2 * 0.18
    pitch = rpy_to_matrix([0, 1.57, 0])
    local = np.diag([m * (0.06 ** 2 / 4 + 0.18 ** 2 / 12)] * 2 + [m * 0.06 ** 2 / 2])
    np.testing.assert_allclose(hip.center_of_mass, [0.053, 0, -0.0379], atol=1e-16)
    assert_tensor_close(hip.inertia, pitch @ local @ pitch.T, 1e-14)


def test_a_link_whose_mesh_is_open_says_so_and_the_others_still_compute(tmp_path):
    from conftest import box_arrays, write_binary_stl
    v, f = box_arrays((0.1, 0.1, 0.1))
    write_binary_stl(tmp_path / "open.stl", v, f[:-1])                   # one triangle missing: a hole
    write_binary_stl(tmp_path / "closed.stl", v, f)
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="holed"><collision><geometry><mesh filename="open.stl"/></geometry>'
                    '</collision></link><link name="fine"><collision><geometry><mesh filename="closed.stl"/>'
                    '</geometry></collision></link></robot>')
    holed, fine = link_inertials(read_robot(urdf), density=1000)
    assert holed.properties is None and "mesh needs repair" in holed.problem and "open.stl" in holed.problem
    assert "boundary edges" in holed.problem
    assert fine.properties.mass == pytest.approx(1.0, rel=1e-7)                # float32 STL corners


@pytest.mark.parametrize("model", ["humanoid.xml", "walker2d.xml"])
def test_gymnasium_mjcf_models_match_mujocos_inertia_from_geometry(model):
    # real MJCF files (Gymnasium 1.4.0): every body's mass, centre and tensor from its geoms at 1000 kg/m³,
    # against MuJoCo's compiler on the same file (inertiafromgeom="true"; geoms without their own density)
    mujoco = pytest.importorskip("mujoco")
    from robot_data import GYM
    compiled = mujoco.MjModel.from_xml_path(str(GYM / model))
    robot = read_robot(GYM / model)
    assert not any(link.elements for link in read_robot(GYM / model, geometry="visual").links)   # all geoms collide
    ours = {r.name: r.properties for r in link_inertials(robot, density=1000)}
    assert len(ours) == compiled.nbody - 1
    for name, props in ours.items():
        i = compiled.body(name).id
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, compiled.body_iquat[i])
        rot = rot.reshape(3, 3)
        assert props.mass == pytest.approx(compiled.body_mass[i], rel=1e-13)
        np.testing.assert_allclose(props.center_of_mass, compiled.body_ipos[i], atol=1e-14)
        assert_tensor_close(props.inertia, rot @ np.diag(compiled.body_inertia[i]) @ rot.T, 1e-12)

