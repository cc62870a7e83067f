"""Tests of inertia_tool.balancing.rotor: hand-computed corrections, ISO 21940-11 examples, kinds, bearing loads."""

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia_tool.balancing.rotor import (ISO_GRADES, balance, balance_grade, permissible_unbalance, shaft_frame,
                                  unbalance_state)
from inertia_tool.errors import UsageError
from inertia_tool.mass.properties import MassProperties, combine, point_mass
from inertia_tool.integrals import second_moment_to_inertia, volume_moments

STEEL = 7850.0
Z = [0.0, 0.0, 1.0]


def _solid(mesh, density=STEEL, name="solid"):
    vm = volume_moments(mesh.vertices, mesh.faces)
    return MassProperties(mass=density * vm.volume, volume=vm.volume, center_of_mass=vm.centroid,
                          inertia=second_moment_to_inertia(vm.second_moment, density), name=name)


@pytest.fixture(scope="module")
def disc():
    """A symmetric steel disc: radius 0.2 m, thickness 0.05 m, centred on the origin, axis z."""
    return _solid(trimesh.creation.cylinder(radius=0.2, height=0.05, sections=96), name="disc")


def _run(body, **kw):
    args = dict(axis_point=[0, 0, 0], axis_direction=Z, rpm=3000, planes=(-0.04, 0.04), radius=0.2)
    args.update(kw)
    return balance(body, **args)


# ---- hand-computed corrections -------------------------------------------------------------------------
def test_lumps_in_the_correction_planes_hand_computed(disc):
    # 40 g at 150 mm on +x in plane z=-0.04, 25 g at 150 mm on +y in plane z=+0.04.  Corrections at 200 mm:
    # 40 g·150/200 = 30 g opposite (180°) in plane 1, 25 g·150/200 = 18.75 g at 270° in plane 2.
    body = combine([disc, point_mass(0.040, [0.15, 0, -0.04]), point_mass(0.025, [0, 0.15, 0.04])])
    rep = _run(body)
    c1, c2 = rep.corrections
    assert c1.mass == pytest.approx(0.030, rel=1e-9)
    assert math.degrees(c1.angle) == pytest.approx(180.0, abs=1e-7)
    assert c2.mass == pytest.approx(0.01875, rel=1e-9)
    assert math.degrees(c2.angle) == pytest.approx(270.0, abs=1e-7)
    np.testing.assert_allclose(c1.position, [-0.2, 0, -0.04], atol=1e-12)
    np.testing.assert_allclose(c2.position, [0, -0.2, 0.04], atol=1e-12)
    np.testing.assert_allclose(c1.removal_position, [0.2, 0, -0.04], atol=1e-12)
    assert math.degrees(c2.removal_angle) == pytest.approx(90.0, abs=1e-7)


def test_lump_outside_the_planes_hand_computed(disc):
    # 100 g at (0.1, 0, 0.06), planes at ±0.04, radius 0.2: U = 0.01 kg·m, W = 6e-4 kg·m².
    # c1 = (z2 U − W)/(z1 − z2) = (4e-4 − 6e-4)/(−0.08) = +2.5e-3 → 12.5 g at 0°;
    # c2 = (W − z1 U)/(z1 − z2) = (6e-4 + 4e-4)/(−0.08) = −1.25e-2 → 62.5 g at 180°.
    body = combine([disc, point_mass(0.1, [0.1, 0, 0.06])])
    rep = _run(body)
    c1, c2 = rep.corrections
    assert (c1.mass, c2.mass) == pytest.approx((0.0125, 0.0625), rel=1e-9)
    assert math.cos(c1.angle) == pytest.approx(1.0, abs=1e-12)
    assert math.degrees(c2.angle) == pytest.approx(180.0, abs=1e-7)
    assert rep.initial.kind == "quasi-static"


def test_corrections_cancel_static_and_couple_unbalance(disc):
    body = combine([disc, point_mass(0.05, [0.15, 0.02, 0.02]), point_mass(0.03, [-0.03, -0.1, -0.02]),
                    point_mass(0.01, [0.05, -0.12, 0.0])])
    rep = _run(body, grade="G6.3", bearings=(-0.12, 0.12))
    assert rep.initial.kind == "dynamic"
    # independent check: add the corrections ourselves and look at the first moment and the products.
    fixed = combine([body] + [point_mass(c.mass, c.position) for c in rep.corrections])
    scale_u = np.linalg.norm(rep.initial.static_unbalance)
    scale_w = np.linalg.norm(rep.initial.moment_unbalance)
    np.testing.assert_allclose(fixed.mass * fixed.center_of_mass[:2], 0, atol=1e-12 * scale_u)
    j = np.asarray(fixed.inertia_about([0, 0, 0]))
    np.testing.assert_allclose([j[0, 2], j[1, 2]], 0, atol=1e-12 * scale_w)
    # the report's own verification says the same
    assert np.linalg.norm(rep.corrected.static_unbalance) < 1e-12 * scale_u
    assert np.linalg.norm(rep.corrected.moment_unbalance) < 1e-12 * scale_w
    assert rep.corrected.kind == "balanced"
    assert rep.corrected_grade.name == "G 0.4" and rep.corrected_value < 1e-9


def test_removing_material_balances_too(disc):
    body = combine([disc, point_mass(0.05, [0.15, 0.02, 0.02]), point_mass(0.03, [-0.03, -0.1, -0.03])])
    rep = _run(body)
    # removing = negative mass at the removal point
    removed = combine([body] + [MassProperties(-c.mass, 0.0, c.removal_position, np.zeros((3, 3)))
                                for c in rep.corrections])
    state = unbalance_state(removed, shaft_frame([0, 0, 0], Z))
    assert np.linalg.norm(state.static_unbalance) < 1e-12 * np.linalg.norm(rep.initial.static_unbalance)
    assert np.linalg.norm(state.moment_unbalance) < 1e-12 * np.linalg.norm(rep.initial.moment_unbalance)


def test_symmetric_wheel_needs_no_correction(disc):
    rep = _run(disc, grade="G2.5")
    assert rep.initial.kind == "balanced"
    for c in rep.corrections:
        assert c.mass < 1e-12
    assert rep.achieved_grade.name == "G 0.4"


def test_single_plane_leaves_the_couple(disc):
    body = combine([disc, point_mass(0.05, [0.1, 0, 0.02]), point_mass(0.02, [0, 0.1, -0.02])])
    rep = _run(body, planes=0.0, single_plane=True)
    assert rep.single_plane and len(rep.corrections) == 1
    (c,) = rep.corrections
    # U = (5e-3, 2e-3) kg·m → c = −U at 0.2 m: 26.926 g at 180° + atan(2/5)
    assert c.mass == pytest.approx(math.hypot(5e-3, 2e-3) / 0.2, rel=1e-9)
    assert math.degrees(c.angle) == pytest.approx(180 + math.degrees(math.atan2(2, 5)), abs=1e-7)
    np.testing.assert_allclose(rep.corrected.static_unbalance, 0, atol=1e-15)
    # the moment about z=0 is untouched: W = (0.05·0.1·0.02, 0.02·0.1·(−0.02))
    np.testing.assert_allclose(rep.corrected.moment_unbalance[:2], [1e-4, -4e-5], rtol=1e-9)
    assert rep.corrected.kind == "couple"


def test_single_plane_defaults_to_the_plane_of_the_centre_of_mass(disc):
    body = combine([disc.transformed(translation=[0, 0, 0.01]), point_mass(0.05, [0.1, 0, 0.01])])
    rep = balance(body, axis_point=[0, 0, 0], axis_direction=Z, rpm=1000, radius=0.2, single_plane=True)
    assert rep.corrections[0].plane == pytest.approx(body.center_of_mass[2], rel=1e-12)


# ---- ISO 21940-11 ---------------------------------------------------------------------------------------
def test_iso_21940_11_example_1kg_3000rpm_g6_3():
    u = permissible_unbalance(1.0, 3000 * 2 * math.pi / 60, "G6.3")
    assert u * 1e6 == pytest.approx(20.05, abs=0.005)         # g·mm


def test_iso_21940_11_example_2kg_10000rpm_g6_3():
    u = permissible_unbalance(2.0, 10000 * 2 * math.pi / 60, "G 6.3")
    assert u * 1e6 == pytest.approx(12.0, abs=0.05)           # g·mm (12.03)


def test_grade_table_and_names():
    assert [g.value for g in ISO_GRADES] == [0.4, 1, 2.5, 6.3, 16, 40, 100, 250, 630, 1600, 4000]
    assert balance_grade("g2.5").name == "G 2.5" and balance_grade(40).name == "G 40"
    with pytest.raises(UsageError, match="ISO 21940-11"):
        balance_grade("G5")


def test_achieved_grade_of_a_displaced_disc(disc):
    # a pure static offset e: per bearing plane (symmetric) U_k = M e / 2 with share 1/2 → G = e Ω.
    e = 20e-6
    body = disc.transformed(translation=[e, 0, 0])
    rep = _run(body, rpm=3000, grade="G6.3", bearings=(-0.1, 0.1))
    omega = 3000 * 2 * math.pi / 60
    assert rep.achieved_value == pytest.approx(e * omega * 1e3, rel=1e-6)   # 6.28 mm/s
    assert rep.achieved_grade.name == "G 6.3"
    assert rep.initial.kind == "static"
    assert rep.initial.offset == pytest.approx(e, rel=1e-9)
    np.testing.assert_allclose(rep.initial.static_unbalance, [disc.mass * e, 0, 0], rtol=1e-9, atol=1e-15)
    for plane in rep.tolerance_planes:
        assert plane.permissible == pytest.approx(rep.permissible_unbalance / 2, rel=1e-9)
        assert plane.within_tolerance


def test_allocation_lever_rule_and_limits(disc):
    # centre of mass at z = 0; bearings at -0.05 and +0.15: shares L_B/L = 0.75 → limited to 0.7, 0.3.
    rep = _run(disc, grade="G6.3", bearings=(-0.05, 0.15))
    assert [p.share for p in rep.tolerance_planes] == pytest.approx([0.7, 0.3])
    assert any("0.7" in n for n in rep.notes)
    rep = _run(disc, grade="G6.3", bearings=(-0.08, 0.12))
    assert [p.share for p in rep.tolerance_planes] == pytest.approx([0.6, 0.4], rel=1e-6)


# ---- kinds (ISO 21940-2) --------------------------------------------------------------------------------
def test_tilted_disc_is_couple_unbalance_with_the_tilt_of_its_axis(disc):
    angle = math.radians(0.5)
    tilted = disc.transformed(rotation=Rotation.from_rotvec([angle, 0, 0]).as_matrix())
    state = unbalance_state(tilted, shaft_frame([0, 0, 0], Z))
    assert state.kind == "couple"
    assert state.tilt == pytest.approx(angle, rel=1e-9)
    # the disc's axis R ẑ = (0, −sin a, cos a) leans towards −y: 270°
    assert math.degrees(state.tilt_angle) == pytest.approx(270.0, abs=1e-6)


def test_couple_from_two_opposite_lumps(disc):
    body = combine([disc, point_mass(0.02, [0.1, 0, 0.03]), point_mass(0.02, [-0.1, 0, -0.03])])
    assert unbalance_state(body, shaft_frame([0, 0, 0], Z)).kind == "couple"


def test_quasi_static_and_dynamic(disc):
    frame = shaft_frame([0, 0, 0], Z)
    one_lump = combine([disc, point_mass(0.05, [0.1, 0, 0.03])])
    assert unbalance_state(one_lump, frame).kind == "quasi-static"
    assert unbalance_state(one_lump, frame).axis_distance < 1e-12
    two = combine([disc, point_mass(0.05, [0.1, 0, 0.03]), point_mass(0.05, [0, 0.1, -0.03])])
    state = unbalance_state(two, frame)
    assert state.kind == "dynamic" and state.axis_distance > 1e-6


# ---- forces and torque ----------------------------------------------------------------------------------
def _lumped(disc):
    lumps = [(0.05, [0.15, 0.02, 0.02]), (0.03, [-0.03, -0.1, -0.03]), (0.02, [0.07, 0.09, 0.05])]
    return combine([disc] + [point_mass(m, p) for m, p in lumps]), lumps


def test_bearing_forces_against_sum_of_point_mass_centrifugal_forces(disc):
    body, lumps = _lumped(disc)
    rpm = 1500
    omega = rpm * 2 * math.pi / 60
    za, zb = -0.12, 0.15
    rep = _run(body, rpm=rpm, bearings=(za, zb))
    # independent statics: each lump pushes m Ω² r⊥ outwards; share it between the bearings by the lever rule
    load_a, load_b = np.zeros(3), np.zeros(3)
    for m, p in lumps:
        f = m * omega ** 2 * np.array([p[0], p[1], 0.0])
        load_b += f * (p[2] - za) / (zb - za)
        load_a += f * (zb - p[2]) / (zb - za)
    np.testing.assert_allclose(rep.tolerance_planes[0].force, load_a, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(rep.tolerance_planes[1].force, load_b, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(rep.force, -(load_a + load_b), rtol=1e-9, atol=1e-9)


def test_torque_is_eq_4_26_rate_of_angular_momentum(disc):
    body, lumps = _lumped(disc)
    omega = 2000 * 2 * math.pi / 60
    rep = _run(body, speed=omega, rpm=None)
    # τ = Σ r × (m a) with the centripetal acceleration a = −Ω² r⊥ of each lump (the disc adds nothing)
    tau = sum(np.cross(p, m * (-omega ** 2) * np.array([p[0], p[1], 0.0])) for m, p in lumps)
    np.testing.assert_allclose(rep.torque, tau, rtol=1e-9, atol=1e-9 * np.abs(tau).max())


# ---- frames and invariance ------------------------------------------------------------------------------
def test_shaft_frame_is_right_handed_and_documented():
    frame = shaft_frame([0, 0, 0], [0, 0, 2])
    np.testing.assert_allclose(frame.axes, np.eye(3))
    frame = shaft_frame([1, 2, 3], [1, 1, 0])
    assert np.linalg.det(frame.axes) == pytest.approx(1.0)
    np.testing.assert_allclose(frame.axes[:, 0], [0, 0, 1])     # z is the mesh axis most orthogonal
    np.testing.assert_allclose(frame.to_mesh(frame.to_shaft([4, 5, 6])), [4, 5, 6])


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 0.1),
       st.lists(st.floats(-0.05, 0.05), min_size=3, max_size=3))
def test_corrections_move_with_the_body(rotvec, shift):
    body = combine([point_mass(3.0, [0, 0, 0]), point_mass(1.0, [0.1, 0, 0.05]), point_mass(1.0, [-0.1, 0, -0.05]),
                    point_mass(1.0, [0, 0.1, 0]), point_mass(1.0, [0, -0.1, 0.0]),
                    point_mass(0.05, [0.08, 0.03, 0.04]), point_mass(0.03, [0.0, -0.09, -0.02])])
    rot = Rotation.from_rotvec(rotvec).as_matrix()
    ref = _run(body)
    moved = _run(body.transformed(rotation=rot, translation=shift), axis_point=shift, axis_direction=rot @ Z)
    for a, b in zip(ref.corrections, moved.corrections):
        assert b.mass == pytest.approx(a.mass, rel=1e-9)
        np.testing.assert_allclose(b.position, rot @ a.position + shift, atol=1e-12)
    assert moved.initial.kind == ref.initial.kind


# ---- errors ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw, match", [
    (dict(radius=0.0), "radius"),
    (dict(rpm=0), "rpm"),
    (dict(rpm=-100), "rpm"),
    (dict(planes=(0.04, 0.04)), "coincide"),
    (dict(bearings=(0.1, 0.1)), "coincide"),
    (dict(axis_point=[5.0, 0, 0]), "axis"),
    (dict(axis_direction=[0, 0, 0]), "axis_direction"),
    (dict(grade="G7"), "grade"),
    (dict(speed=10.0), "exactly one"),
    (dict(planes=(0.1, 0.2, 0.3)), "planes"),
])
def test_errors(disc, kw, match):
    with pytest.raises(UsageError, match=match):
        _run(disc, **kw)


# ---- shaft through an eccentric part (review finding: cams and crank arms are normal balancing jobs) ---------
@pytest.fixture(scope="module")
def cam():
    """A steel disc of radius 40 mm, 10 mm thick, centred 30 mm off the z axis (an eccentric cam), from a mesh."""
    from inertia_tool import mass_properties
    mesh = trimesh.creation.cylinder(radius=0.04, height=0.01, sections=64)
    mesh.apply_translation([0.03, 0.0, 0.0])
    return mass_properties(mesh, density=STEEL)


def test_eccentric_cam_on_a_shaft_through_it_is_balanced(cam):
    rep = _run(cam, planes=(-0.004, 0.004), radius=0.02)
    assert rep.initial.kind in ("static", "quasi-static", "dynamic")
    assert rep.initial.offset == pytest.approx(0.03, rel=1e-3)
    np.testing.assert_allclose(rep.corrected.static_unbalance, 0, atol=1e-12 * cam.mass * 0.03)


def test_shaft_missing_the_part_is_refused(cam):
    with pytest.raises(UsageError, match="does not pass through the part"):
        _run(cam, axis_point=[0.2, 0.0, 0.0], planes=(-0.004, 0.004), radius=0.02)


def test_one_plane_needs_single_plane(disc):
    with pytest.raises(UsageError, match="planes"):
        _run(disc, planes=(0.01,))
    with pytest.raises(UsageError, match="one correction plane"):
        _run(disc, planes=(-0.01, 0.01), single_plane=True)
