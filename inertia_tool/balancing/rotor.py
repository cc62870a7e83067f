"""Static and dynamic balancing of a rigid rotor about a given shaft axis (the chapter's "Tire balancing", §4.3.2).

A body turning on an axle is **statically balanced** when its centre of mass lies on the axis and
**dynamically balanced** when the axis is also a principal axis; small masses placed on the rim make it so.
This module turns that into the numbers a balancing technician uses: static and couple unbalance, the
ISO 21940-2 kind of unbalance, rotating bearing loads at speed, the ISO 21940-11 tolerance for a balance
quality grade, and the correction masses in one or two planes, verified by re-analysing the corrected body.

Pure engine: SI numpy arrays in, frozen dataclasses out (see ``docs/conventions.md``, "Shaft frame").

Notation (all in the shaft frame, lengths measured from ``axis_point``):

* A vector ``v`` perpendicular to the shaft is also written as the complex number ``v_x + i v_y``.
* Static (resultant) unbalance ``U = ∫ r⊥ dm = M e`` (kg·m), ``e`` the offset of the centre of mass.
* Moment of unbalance about ``axis_point``: ``W = ∫ z r⊥ dm = −(J_xz, J_yz)`` (kg·m²), where ``J`` is the
  inertia tensor about ``axis_point`` in shaft axes (tensor convention, ``J_xz = −∫xz dm``).
* Couple unbalance: the moment of unbalance about the centre-of-mass plane, ``W_c = W − z_c U``.
* A point mass ``m`` at radius ``r``, angle ``θ`` and axial position ``z`` adds ``m r e^{iθ}`` to ``U`` and
  ``z m r e^{iθ}`` to ``W``; the body is balanced when ``U = 0`` and ``W = 0``.

Dynamics at constant speed ``Ω`` about the fixed axis (Eq. 4.26 with ``ω = Ω ẑ``, ``ω̇ = 0``): the supports
exert on the rotor the force ``F = −Ω² U`` (centripetal, Eq. for ``R̈`` in §4.3.2) and, about ``axis_point``,
the torque ``τ = ω × (J ω) = Ω² (−J_yz, J_xz, 0)``.  Both rotate with the part.  Gravity is not included.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..values import frozen_value
from ..errors import ImplausibleCorrectionWarning, NonFiniteResultError, UsageError
from ..mass.properties import MassProperties, combine, point_mass
from ..rotations import perpendicular_basis

__all__ = ["BalanceGrade", "ISO_GRADES", "ShaftFrame", "shaft_frame", "PlaneUnbalance", "Correction",
           "UnbalanceState", "BalanceReport", "balance", "permissible_unbalance", "balance_grade", "unbalance_state",
           "UNBALANCE_KINDS", "LARGE_CORRECTION_FRACTION"]

#: The kinds of unbalance of ISO 21940-2 (plus ``balanced`` when both parts are within the tolerance).
UNBALANCE_KINDS = ("balanced", "static", "couple", "quasi-static", "dynamic")


@frozen_value
class BalanceGrade:
    """A balance quality grade of ISO 21940-11.

    Attributes
    ----------
    name : str
        ``"G 6.3"``.
    value : float
        The grade number ``e_per·Ω`` in mm/s (6.3 for G 6.3).
    typical_parts : str
        Examples of rotors usually balanced to this grade (paraphrased from the standard's table).
    """

    name: str
    value: float
    typical_parts: str

    @property
    def speed_eccentricity(self) -> float:
        """The grade as ``e_per·Ω`` in SI, m/s."""
        return self.value * 1e-3


#: ISO 21940-11:2016 balance quality grades (Table 1 of the standard, typical rotors paraphrased).
ISO_GRADES = (
    BalanceGrade("G 0.4", 0.4, "gyroscopes, spindles and armatures of high-precision systems"),
    BalanceGrade("G 1", 1.0, "small electric armatures for special needs, tape-recorder and phonograph drives, "
                             "grinding-machine drives"),
    BalanceGrade("G 2.5", 2.5, "gas and steam turbines, turbo-generators and -compressors, machine-tool drives, "
                               "computer disk drives, medium and large armatures with special needs"),
    BalanceGrade("G 6.3", 6.3, "general machinery: pump impellers, fans, flywheels, electric motor rotors, "
                               "machine-tool parts, gears of process plant, parts of process machinery"),
    BalanceGrade("G 16", 16.0, "drive shafts with special needs, parts of agricultural and crushing machinery, "
                               "car engine components with special needs"),
    BalanceGrade("G 40", 40.0, "car wheels and rims, wheel sets, drive shafts, crankshafts of elastically "
                               "mounted fast four-stroke engines"),
    BalanceGrade("G 100", 100.0, "complete engines of cars, trucks and locomotives; crankshafts of fast diesel "
                                 "engines with six or more cylinders"),
    BalanceGrade("G 250", 250.0, "crankshafts of fast four-cylinder diesel engines, rigidly mounted"),
    BalanceGrade("G 630", 630.0, "crankshafts of large four-stroke engines, rigidly mounted; elastically "
                                 "mounted marine diesel engines"),
    BalanceGrade("G 1600", 1600.0, "crankshafts of large two-stroke engines, rigidly mounted"),
    BalanceGrade("G 4000", 4000.0, "crankshafts of slow marine diesel engines with an odd number of cylinders, "
                                   "rigidly mounted"),
)


def balance_grade(value) -> BalanceGrade:
    """The standard grade named by ``value``: ``"G6.3"``, ``"G 6.3"``, ``"6.3"`` or ``6.3``.

    Parameters
    ----------
    value : str or float or BalanceGrade
        The grade's name or its number (mm/s); a ``BalanceGrade`` is returned as it is.

    Raises
    ------
    UsageError
        When ``value`` is not one of the eleven grades of ISO 21940-11.
    """
    if isinstance(value, BalanceGrade):
        return value
    text = str(value).strip().upper().replace(" ", "")
    if text.startswith("G"):
        text = text[1:]
    try:
        number = float(text)
    except ValueError:
        number = float("nan")
    for g in ISO_GRADES:
        if math.isclose(g.value, number, rel_tol=1e-9):
            return g
    names = ", ".join(g.name.replace(" ", "") for g in ISO_GRADES)
    raise UsageError(f"Expected a balance quality grade of ISO 21940-11 ({names}), got {value!r}")


def permissible_unbalance(mass: float, speed: float, quality_grade) -> float:
    """Permissible residual unbalance ``U_per = G·m/Ω`` of ISO 21940-11, in kg·m.

    Parameters
    ----------
    mass : float
        Rotor mass, kg.
    speed : float
        Maximum service speed Ω, rad/s.
    quality_grade : BalanceGrade, str or float
        ``"G6.3"``; the grade number is ``e_per·Ω`` in mm/s.

    Returns
    -------
    float
        kg·m (multiply by 1e6 for g·mm).  1 kg at 3000 rpm, G 6.3: 2.005e-5 kg·m = 20.05 g·mm.
    """
    g = balance_grade(quality_grade)
    _check_positive(mass, "mass", "kg")
    _check_positive(speed, "speed", "rad/s")
    return g.speed_eccentricity * mass / speed


def _check_positive(value, name: str, unit: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise UsageError(f"Expected `{name}` to be a positive finite number ({unit}), got {value!r}")
    return v


# --------------------------------------------------------------------------------------------------------
# Shaft frame
# --------------------------------------------------------------------------------------------------------
@frozen_value
class ShaftFrame:
    """The frame balancing works in: origin on the shaft, z along it, rotating with the part.

    Attributes
    ----------
    origin : (3,) float
        ``axis_point``, m, mesh axes.
    axes : (3, 3) float
        Proper rotation whose columns are the shaft x, y, z axes in mesh axes.  z is the unit
        ``axis_direction``; x is the mesh axis most orthogonal to z (smallest ``|e_i·z|``, the first on a
        tie) with its z component removed, normalised; y = z × x.  Angles run from x towards y.
    """

    origin: np.ndarray
    axes: np.ndarray

    def to_shaft(self, point) -> np.ndarray:
        """Shaft-frame coordinates (m) of a mesh-axes point (m); works on (..., 3) arrays."""
        return (np.asarray(point, dtype=np.float64) - self.origin) @ self.axes

    def to_mesh(self, shaft_point) -> np.ndarray:
        """Mesh-axes point (m) of shaft-frame coordinates (m); works on (..., 3) arrays."""
        return self.origin + np.asarray(shaft_point, dtype=np.float64) @ self.axes.T

    def vector_to_mesh(self, shaft_vector) -> np.ndarray:
        """Mesh-axes components of a shaft-frame vector."""
        return np.asarray(shaft_vector, dtype=np.float64) @ self.axes.T


def _readonly(a) -> np.ndarray:
    a = np.array(a, dtype=np.float64)
    a.flags.writeable = False
    return a


def shaft_frame(axis_point, axis_direction) -> ShaftFrame:
    """Build the :class:`ShaftFrame` of a shaft through ``axis_point`` (m) along ``axis_direction``."""
    origin = np.asarray(axis_point, dtype=np.float64)
    z = np.asarray(axis_direction, dtype=np.float64)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise UsageError(f"Expected `axis_point` to be 3 finite numbers, got {np.asarray(axis_point).tolist()}")
    if z.shape != (3,) or not np.all(np.isfinite(z)) or np.linalg.norm(z) == 0:
        raise UsageError(f"Expected `axis_direction` to be 3 finite numbers, not all zero, got "
                         f"{np.asarray(axis_direction).tolist()}")
    z = z / np.linalg.norm(z)
    x, y = perpendicular_basis(z)          # x: the mesh axis most orthogonal to the shaft, projected
    return ShaftFrame(origin=_readonly(origin), axes=_readonly(np.column_stack([x, y, z])))


# --------------------------------------------------------------------------------------------------------
# Unbalance state of a body about a shaft
# --------------------------------------------------------------------------------------------------------
@frozen_value
class UnbalanceState:
    """How a body is (un)balanced about a shaft.  Vectors are in the shaft frame (their z component is 0
    for the transverse ones); reference point ``axis_point`` unless a name says otherwise.

    Attributes
    ----------
    mass : float
        kg.
    center_of_mass : (3,) float
        m, shaft frame.
    offset : float
        Distance of the centre of mass from the shaft, m (``|e|``).
    static_unbalance : (3,) float
        ``U = M e`` (x, y, 0), kg·m, shaft frame.
    moment_unbalance : (3,) float
        ``W = ∫ z r⊥ dm`` about ``axis_point`` (x, y, 0), kg·m², shaft frame.
    couple_unbalance : (3,) float
        ``W_c = W − z_c U``: the moment of unbalance about the plane of the centre of mass, kg·m².
    products_of_inertia : (2,) float
        ``(J_xz, J_yz)`` about ``axis_point`` in shaft axes, kg·m², tensor convention (−∫xz dm).
    principal_axis : (3,) float
        Unit central principal axis nearest the shaft (mesh axes, oriented with positive shaft z).
    tilt : float
        Angle between that principal axis and the shaft, rad.
    tilt_angle : float
        Direction the principal axis leans towards, rad from shaft x towards y (0 when ``tilt`` is 0).
    axis_distance : float
        Shortest distance between the principal-axis line (through the centre of mass) and the shaft, m.
    kind : str
        One of :data:`UNBALANCE_KINDS` (ISO 21940-2), judged with the tolerances given to :func:`balance`.
    """

    mass: float
    center_of_mass: np.ndarray
    offset: float
    static_unbalance: np.ndarray
    moment_unbalance: np.ndarray
    couple_unbalance: np.ndarray
    products_of_inertia: np.ndarray
    principal_axis: np.ndarray
    tilt: float
    tilt_angle: float
    axis_distance: float
    kind: str

    def bearing_torque(self, speed: float) -> np.ndarray:
        """Torque (N·m, shaft frame, about ``axis_point``) the supports exert on the rotor at speed Ω (rad/s).

        Eq. (4.26) with ``ω = Ω ẑ`` constant: ``τ = ω × (J ω) = Ω² (−J_yz, J_xz, 0)``; it rotates with the part.
        """
        jxz, jyz = self.products_of_inertia
        return speed ** 2 * np.array([-jyz, jxz, 0.0])


def _nearest_principal_axis(inertia: np.ndarray, z: np.ndarray, rtol: float) -> np.ndarray:
    """Unit central principal axis closest to ``z`` (mesh axes); within a degenerate eigenspace, the
    projection of ``z`` onto it (every direction there is principal)."""
    values, vectors = np.linalg.eigh(0.5 * (inertia + inertia.T))
    scale = max(abs(values).max(), 1e-300)
    best, best_norm = z, -1.0
    for k in range(3):
        group = [j for j in range(3) if abs(values[j] - values[k]) <= rtol * scale]
        basis = vectors[:, group]
        proj = basis @ (basis.T @ z)
        norm = float(np.linalg.norm(proj))
        if norm > best_norm:
            best, best_norm = proj / norm if norm > 0 else vectors[:, k], norm
    return best if best @ z >= 0 else -best


def unbalance_state(props: MassProperties, frame: ShaftFrame, *, offset_tol: float | None = None,
                    tilt_tol: float = 1e-8, equal_rtol: float = 1e-9) -> UnbalanceState:
    """Static and couple unbalance of ``props`` about the shaft ``frame``, and its ISO 21940-2 kind.

    Parameters
    ----------
    props : MassProperties
        The body, SI, mesh axes.
    frame : ShaftFrame
        The shaft.
    offset_tol : float, optional
        Offsets (m) of the centre of mass, and distances between the principal axis and the shaft, at or
        below this count as zero when judging the kind.  Default ``1e-9`` × the body's RMS radius
        ``√(tr I_cm / M)``.
    tilt_tol : float
        Tilts (rad) at or below this count as zero.
    equal_rtol : float
        Relative tolerance under which principal moments count as equal (then the nearest principal axis
        is the projection of the shaft onto their common eigenspace).

    Notes
    -----
    ISO 21940-2 kinds, from the central principal axis nearest the shaft:
    *static* — parallel to the shaft, displaced; *couple* — tilted, crossing the shaft at the centre of
    mass (which is on the shaft); *quasi-static* — tilted, crossing the shaft elsewhere; *dynamic* — skew
    to the shaft.  The kind is a statement about the unbalance before any tolerance of a grade.
    """
    rot = frame.axes
    z_hat = rot[:, 2]
    com = frame.to_shaft(props.center_of_mass)
    mass = props.mass
    about = np.asarray(props.inertia_about(frame.origin))
    j_shaft = rot.T @ about @ rot
    products = np.array([j_shaft[0, 2], j_shaft[1, 2]])
    u_static = mass * np.array([com[0], com[1], 0.0])
    w_moment = np.array([-products[0], -products[1], 0.0])
    w_couple = w_moment - com[2] * u_static
    offset = float(math.hypot(com[0], com[1]))

    axis = _nearest_principal_axis(props.inertia, z_hat, equal_rtol)
    axis_shaft = rot.T @ axis
    tilt = float(math.atan2(math.hypot(axis_shaft[0], axis_shaft[1]), axis_shaft[2]))
    tilt_angle = float(math.atan2(axis_shaft[1], axis_shaft[0]) % (2 * math.pi)) if tilt > 0 else 0.0
    cross = np.cross(axis_shaft, [0.0, 0.0, 1.0])
    cross_norm = float(np.linalg.norm(cross))
    distance = abs(float(com @ cross)) / cross_norm if cross_norm > 0 else offset

    if offset_tol is None:
        rms = math.sqrt(max(np.trace(props.inertia), 0.0) / mass) if mass > 0 else 0.0
        offset_tol = 1e-9 * rms
    displaced = offset > offset_tol
    tilted = tilt > tilt_tol
    if not displaced and not tilted:
        kind = "balanced"
    elif not tilted:
        kind = "static"
    elif not displaced:
        kind = "couple"
    elif distance <= offset_tol:
        kind = "quasi-static"
    else:
        kind = "dynamic"
    return UnbalanceState(mass=mass, center_of_mass=_readonly(com), offset=offset,
                          static_unbalance=_readonly(u_static), moment_unbalance=_readonly(w_moment),
                          couple_unbalance=_readonly(w_couple), products_of_inertia=_readonly(products),
                          principal_axis=_readonly(axis), tilt=tilt, tilt_angle=tilt_angle,
                          axis_distance=float(distance), kind=kind)


# --------------------------------------------------------------------------------------------------------
# Planes, corrections, report
# --------------------------------------------------------------------------------------------------------
@frozen_value
class PlaneUnbalance:
    """The unbalance of the body as seen in one plane perpendicular to the shaft.

    Attributes
    ----------
    position : float
        Axial position of the plane, m from ``axis_point`` along the shaft.
    unbalance : (3,) float
        Equivalent unbalance in this plane (x, y, 0), kg·m, shaft frame: with the partner plane it
        reproduces ``U`` and ``W`` (two-plane resolution) or it is ``U`` itself (one plane).
    permissible : float
        Allocated permissible residual unbalance ``U_per`` for this plane, kg·m (``nan`` without a grade).
    share : float
        Fraction of the rotor's ``U_per`` allocated to this plane (ISO 21940-11 lever rule, clamped).
    force : (3,) float
        Rotating load the rotor puts on a bearing in this plane at the analysed speed, ``Ω² × unbalance``, N,
        shaft frame at the instant the rotating frame coincides with it (meaningful for bearing planes).
    """

    position: float
    unbalance: np.ndarray
    permissible: float
    share: float
    force: np.ndarray

    @property
    def magnitude(self) -> float:
        """``|unbalance|``, kg·m."""
        return float(math.hypot(self.unbalance[0], self.unbalance[1]))

    @property
    def angle(self) -> float:
        """Angle of the unbalance, rad in [0, 2π), from shaft x towards y."""
        return float(math.atan2(self.unbalance[1], self.unbalance[0]) % (2 * math.pi))

    @property
    def within_tolerance(self) -> bool:
        """``magnitude ≤ permissible`` (False without a grade)."""
        return bool(self.magnitude <= self.permissible)


@frozen_value
class Correction:
    """A correction mass that balances the body.

    Attributes
    ----------
    plane : float
        Axial position of the correction plane, m from ``axis_point``.
    mass : float
        kg to **add** (positive) at ``position``; removing the same mass at ``removal_position`` does the same.
    radius : float
        m from the shaft.
    angle : float
        rad in [0, 2π), from shaft x towards y, where the mass is added.
    position : (3,) float
        Where the added mass goes, m, mesh axes.
    removal_angle : float
        ``angle + π`` (mod 2π): where the same mass is removed instead.
    removal_position : (3,) float
        The removal point, m, mesh axes.
    """

    plane: float
    mass: float
    radius: float
    angle: float
    position: np.ndarray
    removal_angle: float
    removal_position: np.ndarray


@frozen_value
class BalanceReport:
    """Everything about balancing one rotor at one speed (SI; shaft-frame vectors unless stated).

    Attributes
    ----------
    name : str
        The body's name.
    frame : ShaftFrame
        The shaft: ``axis_point`` and the shaft axes (see ``docs/conventions.md``).
    speed : float
        Ω, rad/s (the maximum service speed for the grade).
    initial : UnbalanceState
        Static and couple unbalance, principal-axis tilt and ISO 21940-2 kind of the body as it is.
    torque : (3,) float
        Torque the supports exert on the rotor at Ω about ``axis_point``, N·m (Eq. 4.26), rotating with it.
    force : (3,) float
        Total force the supports exert on the rotor, ``−Ω² U``, N (centripetal), rotating with it.
    quality_grade : BalanceGrade or None
        The grade asked for.
    permissible_unbalance : float
        ``U_per = G·M/Ω``, kg·m (``nan`` without a grade).
    tolerance_planes : tuple of PlaneUnbalance
        Where the tolerance is checked: the bearing planes when ``bearings`` are given (ISO 21940-11's
        recommended reference planes), else the correction plane(s).  Their ``force`` is the bearing load.
    achieved_value : float
        The smallest grade number (mm/s) the body meets as it is: ``max_k |U_k| Ω / (share_k M)`` in mm/s.
    achieved_grade : BalanceGrade or None
        The finest standard grade with ``value ≥ achieved_value`` (None when worse than G 4000).
    correction_planes : tuple of PlaneUnbalance
        The body's unbalance resolved into the correction plane(s).
    corrections : tuple of Correction
        Masses to add (one per correction plane) so that ``U`` (and ``W`` with two planes) vanish.
    single_plane : bool
        True for a static (one-plane) correction: the couple unbalance is left as it is.
    corrected : UnbalanceState
        Verification: the body plus the correction point masses, re-analysed by the engine.
    corrected_value : float
        ``achieved_value`` of the corrected body, mm/s.
    corrected_grade : BalanceGrade or None
        Standard grade the corrected body meets.
    notes : tuple of str
        Caveats (centre of mass outside the tolerance planes, clamped allocation, ...).
    drillings : tuple of DrilledHole
        With ``drill_diameter``: the holes that do the corrections' work by removing material
        (:mod:`.drilling`); empty otherwise.
    drilled : UnbalanceState or None
        Verification of the drilling: the body less the exact drilled cylinders, re-analysed.
    drilled_value : float
        ``achieved_value`` of the drilled body, mm/s (``nan`` without drilling).
    drilled_grade : BalanceGrade or None
        Standard grade the drilled body meets.
    residual_bound : float or None
        For a part whose mass properties are an estimate (a repaired surface): the bound on the true static
        unbalance's distance from the one reported, before and after the correction, kg·m
        (:func:`_estimate_note`); None for a part proven exact.
    """

    name: str
    frame: ShaftFrame
    speed: float
    initial: UnbalanceState
    torque: np.ndarray
    force: np.ndarray
    quality_grade: BalanceGrade | None
    permissible_unbalance: float
    tolerance_planes: tuple
    achieved_value: float
    achieved_grade: BalanceGrade | None
    correction_planes: tuple
    corrections: tuple
    single_plane: bool
    corrected: UnbalanceState
    corrected_value: float
    corrected_grade: BalanceGrade | None
    notes: tuple
    drillings: tuple = ()
    drilled: UnbalanceState | None = None
    drilled_value: float = float("nan")
    drilled_grade: BalanceGrade | None = None
    residual_bound: float | None = None

    @property
    def mass(self) -> float:
        """Rotor mass, kg."""
        return self.initial.mass

    @property
    def rpm(self) -> float:
        """Speed in revolutions per minute."""
        return self.speed * 60.0 / (2 * math.pi)


def _resolve(u: np.ndarray, w: np.ndarray, planes) -> list[np.ndarray]:
    """Split resultant ``U`` and moment ``W`` into equivalent unbalances in 1 or 2 planes.

    Two planes: ``U_1 + U_2 = U``, ``z_1 U_1 + z_2 U_2 = W`` → ``U_1 = (z_2 U − W)/(z_2 − z_1)``,
    ``U_2 = (W − z_1 U)/(z_2 − z_1)``.  One plane: ``U_1 = U``.
    """
    if len(planes) == 1:
        return [u.copy()]
    z1, z2 = planes
    return [(z2 * u - w) / (z2 - z1), (w - z1 * u) / (z2 - z1)]


def _shares(planes, z_com: float) -> tuple[list[float], list[str]]:
    """ISO 21940-11 allocation of ``U_per`` to two tolerance planes by the lever rule, limited to 0.3..0.7."""
    if len(planes) == 1:
        return [1.0], []
    za, zb = planes
    length = zb - za
    share_a = (zb - z_com) / length
    notes = []
    if not 0.0 <= share_a <= 1.0:
        notes.append("the centre of mass lies outside the tolerance planes (overhung rotor): ISO 21940-11 "
                     "treats such rotors separately; the simple lever rule with its 0.3/0.7 limits is used here")
    clamped = min(max(share_a, 0.3), 0.7)
    if clamped != share_a and 0.0 <= share_a <= 1.0:
        notes.append(f"the lever-rule share {share_a:.2f}/{1 - share_a:.2f} was limited to "
                     f"{clamped:.1f}/{1 - clamped:.1f} (ISO 21940-11: no plane below 0.3 or above 0.7 of U_per)")
    return [clamped, 1.0 - clamped], notes


def _plane_data(state: UnbalanceState, planes, speed: float, u_per: float, shares) -> tuple:
    parts = _resolve(state.static_unbalance, state.moment_unbalance, planes)
    return tuple(PlaneUnbalance(position=float(z), unbalance=_readonly(p), permissible=u_per * s, share=s,
                                force=_readonly(speed ** 2 * p))
                 for z, p, s in zip(planes, parts, shares))


def _achieved(planes: tuple, mass: float, speed: float) -> tuple[float, BalanceGrade | None]:
    value = max(p.magnitude * speed / (p.share * mass) for p in planes) * 1e3   # mm/s
    for g in ISO_GRADES:
        if value <= g.value:
            return value, g
    return value, None


def _axial_positions(values, name: str, count) -> tuple[float, ...]:
    arr = np.atleast_1d(np.asarray(values, dtype=np.float64)).ravel()
    if arr.size not in count or not np.all(np.isfinite(arr)):
        want = " or ".join(str(c) for c in count)
        raise UsageError(f"Expected `{name}` to be {want} finite axial position(s) in m, got "
                         f"{np.asarray(values).tolist()}")
    return tuple(float(v) for v in arr)


def _line_meets_box(point: np.ndarray, direction: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the infinite line ``point + s·direction`` crosses the axis-aligned box ``[lo, hi]`` (slabs)."""
    s_min, s_max = -np.inf, np.inf
    for k in range(3):
        if abs(direction[k]) < 1e-300:
            if not lo[k] <= point[k] <= hi[k]:
                return False
            continue
        a = (lo[k] - point[k]) / direction[k]
        b = (hi[k] - point[k]) / direction[k]
        s_min = max(s_min, min(a, b))
        s_max = min(s_max, max(a, b))
    return s_min <= s_max


def _check_shaft_meets_part(props: MassProperties, frame, offset: float, k_max: float, max_axis_offset: float):
    """Refuse a shaft that misses the part (see ``balance``'s ``max_axis_offset``)."""
    mesh = props.mesh
    if mesh is not None:
        lo, hi = np.asarray(mesh.bbox_min, float), np.asarray(mesh.bbox_max, float)
        pad = 0.01 * float(np.linalg.norm(hi - lo))
        if not _line_meets_box(frame.origin, frame.axes[:, 2], lo - pad, hi + pad):
            raise UsageError(f"The shaft axis does not pass through the part (it misses its bounding box "
                             f"{np.round(lo, 6).tolist()}–{np.round(hi, 6).tolist()} m; it passes {offset:.6g} m "
                             "from the centre of mass): check `axis_point`, `axis_direction` and the length `units`")
    elif offset > max_axis_offset * k_max:
        raise UsageError(f"The shaft axis passes {offset:.6g} m from the centre of mass, more than "
                         f"{max_axis_offset:g} × the largest radius of gyration ({k_max:.6g} m): expected an "
                         "axis through the part")


#: A correction whose masses add up to more than this fraction of the part's mass is reported (a sizeable
#: change of the part: a larger radius needs proportionally less mass).
LARGE_CORRECTION_FRACTION = 0.10


def _bounding_boxes(props: MassProperties) -> list[tuple[np.ndarray, np.ndarray]]:
    """The bounding boxes (m, mesh axes) of the meshes a body came from: its own, else its parts'."""
    if props.mesh is not None:
        return [(np.asarray(props.mesh.bbox_min, float), np.asarray(props.mesh.bbox_max, float))]
    return [box for part in props.parts for box in _bounding_boxes(part)]


def _part_extent(props: MassProperties, frame) -> tuple[float, float, float] | None:
    """``(largest radius, lowest z, highest z)`` of the part's bounding-box corners in the shaft frame (an
    outer bound of the part), or ``None`` when the body did not come from a mesh."""
    boxes = _bounding_boxes(props)
    if not boxes:
        return None
    corners = np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]]
                        for lo, hi in boxes for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    shaft = frame.to_shaft(corners)
    return float(np.max(np.hypot(shaft[:, 0], shaft[:, 1]))), float(shaft[:, 2].min()), float(shaft[:, 2].max())


def _correction_notes(props: MassProperties, frame, radius: float, planes, corrections,
                      fraction: float = LARGE_CORRECTION_FRACTION) -> list[str]:
    """Corrections outside the part or heavy compared with it, each also raised as
    :class:`~inertia_tool.errors.ImplausibleCorrectionWarning` (the report keeps them in its notes)."""
    notes = []
    extent = _part_extent(props, frame)
    if extent is not None:
        r_max, z_lo, z_hi = extent
        slack = 1e-9 * max(r_max, z_hi - z_lo)
        if radius > r_max + slack:
            notes.append(f"the correction `radius` {radius:.6g} m lies outside the part: no point of its bounding "
                         f"box is farther than {r_max:.6g} m from the shaft (check the radius and its unit)")
        outside = [z for z in planes if not z_lo - slack <= z <= z_hi + slack]
        if outside:
            notes.append(f"correction `planes` at {', '.join(f'{z:.6g}' for z in outside)} m lie outside the part, "
                         f"which spans {z_lo:.6g} to {z_hi:.6g} m along the shaft from the axis point (check the "
                         "planes and their unit)")
    added = sum(c.mass for c in corrections)
    if props.mass > 0 and added > fraction * props.mass:
        notes.append(f"the correction masses add up to {added:.6g} kg, {100 * added / props.mass:.3g} % of the "
                     f"part's {props.mass:.6g} kg: a sizeable change of the part (a larger `radius` needs "
                     "proportionally less mass)")
    for note in notes:
        warnings.warn(ImplausibleCorrectionWarning(f"{props.name}: {note}"), stacklevel=3)
    return notes


def _estimate_note(props: MassProperties, state: UnbalanceState, omega: float) -> tuple[float | None, str | None]:
    """``(bound kg·m, note)`` for a part whose mass properties are an estimate (review19: a repaired part was
    "balanced, meets G 0.4" with its centre of mass known to 0.36 mm only); ``(None, None)`` when proven.

    The true part's first moment about the shaft differs from the reported one by at most
    ``M (1 + δm) δc + δm M e``: the first term the centre's shift (``|c_T − c_P| ≤ δc``, the true mass at most
    ``M (1 + δm)``), the second the mass's error at the reported offset ``e``.  Point masses added by the
    correction are exact, so the same bound holds after it.  An assembly's centre-of-mass bounds are per part
    (``reports.serialize.method_and_uncertainty``): said, not bounded."""
    mesh = props.mesh
    bounds = getattr(mesh, "uncertainty", None) if mesh is not None else None
    if bounds is None:
        if any(getattr(getattr(p, "mesh", None), "uncertainty", None) is not None for p in props.parts):
            return None, ("some parts are estimates (repaired surfaces): the unbalance before and after the "
                          "correction is not proven, and not bounded here (the parts' own bounds are in the "
                          "analysis of each part)")
        return None, None
    dm, dc = float(bounds.mass), float(bounds.center_of_mass)
    bound = props.mass * ((1.0 + dm) * dc + dm * float(state.offset))
    speed = bound / props.mass * omega * 1e3
    return bound, (f"the part is an estimate (its surface repaired): its centre of mass is known to within "
                   f"{dc:.3g} m and its mass to ±{100 * dm:.3g} %, so the true static unbalance lies within "
                   f"{bound:.3g} kg·m ({bound * 1e6:.3g} g·mm; e·Ω {speed:.3g} mm/s) of the one given, before and "
                   "after the correction: the verification holds for the repaired surface; the couple unbalance "
                   f"is uncertain as the inertia (±{100 * float(bounds.inertia):.3g} % of its norm)")


def balance(props: MassProperties, *, axis_point, axis_direction, rpm: float | None = None,
            speed: float | None = None, planes=None, radius: float, grade=None, bearings=None,
            single_plane: bool = False, max_axis_offset: float = 10.0, offset_tol: float | None = None,
            tilt_tol: float = 1e-8, drill_diameter: float | None = None, part_mesh=None) -> BalanceReport:
    """Balancing report of a rigid rotor turning about a given shaft (§4.3.2 "Tire balancing", Eq. 4.26,
    ISO 21940-2 and ISO 21940-11).

    Parameters
    ----------
    props : MassProperties
        The rotor, SI, mesh axes.
    axis_point : (3,) array_like
        A point of the shaft, m, mesh axes; the origin of the shaft frame and of the axial positions.
    axis_direction : (3,) array_like
        Direction of the shaft (any length), mesh axes.
    rpm, speed : float
        Service speed in rev/min **or** Ω in rad/s (exactly one; positive).
    planes : sequence of 2 floats, or 1 float with ``single_plane=True``
        Axial positions of the correction planes, m from ``axis_point`` along the shaft.  A single-plane
        (static) correction needs ``single_plane=True``; then without ``planes`` the plane of the centre of
        mass is used.
    radius : float
        Radius at which correction masses go, m (positive).
    grade : str, float or BalanceGrade, optional
        ISO 21940-11 balance quality grade (``"G6.3"``).  Without it no tolerance is checked.
    bearings : sequence of 2 floats, optional
        Axial positions of the bearings, m from ``axis_point``.  They become the tolerance planes and the
        report gives the rotating bearing loads.
    single_plane : bool
        Static correction in one plane (narrow discs); the couple unbalance stays.
    max_axis_offset : float
        A shaft must pass through the part: when the body came from a mesh, the shaft line must cross its
        bounding box (enlarged by 1 % of its diagonal); otherwise its distance from the centre of mass may not
        exceed this multiple of the largest central radius of gyration.  Eccentric cams, crank arms and
        counterweights turning about a shaft through them are accepted.
    offset_tol, tilt_tol : float
        Tolerances of the kind classification, see :func:`unbalance_state`.
    drill_diameter : float, optional
        Also propose removing material: each correction becomes a hole of this diameter (m) drilled parallel
        to the shaft at ``radius``, at the removal angle, from the correction plane (:mod:`.drilling`).
    part_mesh : (vertices, faces), optional
        The part's closed surface (m, mesh axes), to check with the winding number that each hole lies
        inside the part.

    Returns
    -------
    BalanceReport

    Raises
    ------
    UsageError
        Non-positive speed or radius, coinciding planes or bearings, a shaft far from the part, an unknown
        grade, or malformed vectors.

    Notes
    -----
    Two-plane correction: masses ``m_k`` at radius ``r`` and angles ``θ_k`` in planes ``z_k`` with
    ``c_k = m_k r e^{iθ_k}`` must cancel ``U`` and ``W``: ``c_1 + c_2 = −U``, ``z_1 c_1 + z_2 c_2 = −W``,
    so ``c_k = −U_k`` (the body's equivalent unbalance in plane ``k``, see :class:`PlaneUnbalance`).
    Then the centre of mass is on the shaft and ``J_xz = J_yz = 0``: the shaft is a principal axis.
    Removing ``m_k`` at ``θ_k + π`` has the same effect.
    """
    frame = shaft_frame(axis_point, axis_direction)
    if (rpm is None) == (speed is None):
        raise UsageError("Expected exactly one of `rpm` (rev/min) and `speed` (rad/s)")
    omega = _check_positive(speed, "speed", "rad/s") if speed is not None else \
        _check_positive(rpm, "rpm", "rev/min") * 2 * math.pi / 60.0
    NonFiniteResultError.check(f"the squared speed Ω² at Ω = {omega:g} rad/s", omega * omega,
                               because="the rotating loads (∝ Ω²) overflow; the speed is outside any physical range")
    r = float(radius)
    if not (math.isfinite(r) and r > 0):
        raise UsageError(f"Expected a positive correction `radius` in m, got {radius!r}")
    _check_positive(props.mass, "props.mass", "kg")
    quality = None if grade is None else balance_grade(grade)

    state = unbalance_state(props, frame, offset_tol=offset_tol, tilt_tol=tilt_tol)
    k_max = math.sqrt(max(np.linalg.eigvalsh(props.inertia).max(), 0.0) / props.mass)
    _check_shaft_meets_part(props, frame, state.offset, k_max, max_axis_offset)
    length_scale = max(k_max, r)
    if planes is None:
        if not single_plane:
            raise UsageError("Expected two correction `planes` (or one with single_plane=True)")
        planes_t: tuple[float, ...] = (float(state.center_of_mass[2]),)
    else:
        planes_t = _axial_positions(planes, "planes", (1, 2) if single_plane else (2,))
    if len(planes_t) == 1:
        pass
    elif single_plane:
        raise UsageError("Expected one correction plane with single_plane=True, got two")
    elif abs(planes_t[1] - planes_t[0]) <= 1e-9 * length_scale:
        raise UsageError(f"The correction planes coincide (both at {planes_t[0]:.6g} m): expected two distinct "
                         "axial positions")
    bearings_t = None
    if bearings is not None:
        bearings_t = _axial_positions(bearings, "bearings", (2,))
        if abs(bearings_t[1] - bearings_t[0]) <= 1e-9 * length_scale:
            raise UsageError(f"The bearings coincide (both at {bearings_t[0]:.6g} m): expected two distinct "
                             "axial positions")

    u_per = permissible_unbalance(props.mass, omega, quality) if quality is not None else float("nan")
    notes = []
    tol_positions = bearings_t if bearings_t is not None else planes_t
    shares, share_notes = _shares(tol_positions, float(state.center_of_mass[2]))
    notes += share_notes
    if single_plane and bearings_t is None:
        notes.append("single-plane check: the whole U_per applies to the static unbalance; the couple "
                     "unbalance is not toleranced (give `bearings` to check it)")
    tolerance = _plane_data(state, tol_positions, omega, u_per, shares)
    corr_shares = shares if bearings_t is None else _shares(planes_t, float(state.center_of_mass[2]))[0]
    correction_planes = _plane_data(state, planes_t, omega, u_per, corr_shares)

    corrections = []
    for plane in correction_planes:
        c = -plane.unbalance
        mag = float(math.hypot(c[0], c[1]))
        ang = float(math.atan2(c[1], c[0]) % (2 * math.pi)) if mag > 0 else 0.0
        rem = (ang + math.pi) % (2 * math.pi)
        pos = frame.to_mesh([r * math.cos(ang), r * math.sin(ang), plane.position])
        rpos = frame.to_mesh([r * math.cos(rem), r * math.sin(rem), plane.position])
        corrections.append(Correction(plane=plane.position, mass=mag / r, radius=r, angle=ang,
                                      position=_readonly(pos), removal_angle=rem,
                                      removal_position=_readonly(rpos)))

    notes += _correction_notes(props, frame, r, planes_t, corrections)
    residual_bound, estimate_note = _estimate_note(props, state, omega)
    if estimate_note is not None:
        notes.append(estimate_note)
    corrected_body = combine([props] + [point_mass(c.mass, c.position, name="correction") for c in corrections],
                             name=props.name)
    corrected = unbalance_state(corrected_body, frame, offset_tol=offset_tol, tilt_tol=tilt_tol)
    corrected_tolerance = _plane_data(corrected, tol_positions, omega, u_per, shares)

    achieved_value, achieved = _achieved(tolerance, props.mass, omega)
    corrected_value, corrected_grade = _achieved(corrected_tolerance, corrected_body.mass, omega)
    drilling: dict[str, Any] = {}
    if drill_diameter is not None:
        from .drilling import drill_holes, remove_cylinders
        holes = drill_holes(props, frame, planes_t, r, float(drill_diameter), state.static_unbalance,
                            state.moment_unbalance, part_mesh=part_mesh)
        drilled_body = remove_cylinders(props, holes)
        drilled = unbalance_state(drilled_body, frame, offset_tol=offset_tol, tilt_tol=tilt_tol)
        drilled_value, drilled_grade = _achieved(_plane_data(drilled, tol_positions, omega, u_per, shares),
                                                 drilled_body.mass, omega)
        if not any(h.inside_checked for h in holes):
            notes.append("the holes were not checked to lie inside the part (give `part_mesh`)")
        drilling = dict(drillings=holes, drilled=drilled, drilled_value=drilled_value, drilled_grade=drilled_grade)
    elif part_mesh is not None:
        raise UsageError("`part_mesh` is only used to check drilled holes: give `drill_diameter` too")
    report = BalanceReport(name=props.name, frame=frame, speed=omega, initial=state,
                           torque=_readonly(state.bearing_torque(omega)),
                           force=_readonly(-omega ** 2 * state.static_unbalance), quality_grade=quality,
                           permissible_unbalance=u_per, tolerance_planes=tolerance, achieved_value=achieved_value,
                           achieved_grade=achieved, correction_planes=correction_planes,
                           corrections=tuple(corrections), single_plane=single_plane, corrected=corrected,
                           corrected_value=corrected_value, corrected_grade=corrected_grade, notes=tuple(notes),
                           residual_bound=residual_bound, **drilling)
    for what, value in (("rotating force", report.force), ("torque of the supports", report.torque),
                        ("correction masses", [c.mass for c in corrections]),
                        ("plane loads", [p.force for p in tolerance] or 0.0)):
        NonFiniteResultError.check(f"{props.name or 'part'}: the {what}", value)
    return report
