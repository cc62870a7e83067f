"""The most likely cause of a declared inertial that disagrees with its geometry, with its evidence.

For a link whose declared tensor ``I_d`` (about the declared centre of mass, link axes) differs from the
geometry's tensor at the declared mass, ``R = (m_d / m_g) I_g``, each rule below proposes what the author may
have done, *undoes it* on the declared tensor and measures how close the result comes to ``R`` (relative
Frobenius difference, as the audit does).  A cause is reported only when undoing it brings the difference
within ``tolerance`` and at least halves it; the evidence sentence gives both numbers.  Rules (each one
named place, checked in this order, all reported that pass):

* ``unit``: the tensor (or the mass) off by a power of 10³ — 10³ (g·m² or g), 10⁶ (kg·mm²), 10⁹ (g·mm²) —
  in either direction; undone by dividing by the nearest such power of ``tr I_d / tr R`` (mass:
  ``m_d / m_g``, only when the declared mass makes an implausible density and the corrected one a plausible
  one).
* ``decimal``: the tensor off by 10 or 100 (a digit slipped); undone likewise.
* ``origin``: the tensor taken about the link origin instead of the centre of mass: ``I_d = I_c + m_d
  (|c|² 1 − c cᵀ)`` (parallel-axis theorem, Eq. 4.16 of Chapter 4, "Rigid Body Motion"), ``c`` the declared
  centre of mass; undone by subtracting the shift.
* ``axes``: the right principal moments in the wrong axes (swapped or rotated): the eigenvalues of ``I_d``
  match those of ``R`` within ``tolerance`` while the tensors differ; the evidence gives the angle between the
  principal frames and the correction is ``R``'s axes with the declared moments.
* ``placeholder``: an isotropic tensor ``k 1`` (``diaginertia="0.001 0.001 0.001"``) for geometry whose
  principal moments differ by more than ``anisotropy``: a placeholder; the geometry's tensor replaces it.
  Or a *box*: a tensor diagonal in the link axes that is the tensor of the solid box of the declared mass
  whose edges are the geometry's bounding box (each within ``box_rtol``), while the geometry's own tensor differs:
  the box's edges follow from the moments, ``a_x² = 6 (I_yy + I_zz − I_xx) / m`` (cyclic; from
  ``I_xx = m (a_y² + a_z²) / 12``), so the evidence is the two boxes side by side.
* ``other_link`` (:func:`copied_masses`, across links): the declared mass is exactly another link's, whose
  geometry it fits, while this link's geometry gives a mass ``mass_tolerance`` or more away — a value copied
  from the other link; the geometry's mass replaces it.

:func:`nearest_valid_tensor` gives, for a declared tensor that fails the simulators' checks (a negative
moment, ``I1 + I2 < I3``), the tensor with the same axes whose moments are projected onto the valid set.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..values import frozen_value

__all__ = ["Diagnosis", "diagnose_inertial", "copied_masses", "nearest_valid_tensor", "CAUSES", "UNIT_FACTORS",
           "DECIMAL_FACTORS"]

#: Cause keys, in the order the rules are tried.
CAUSES = ("unit", "decimal", "origin", "axes", "placeholder", "other_link")

#: Factors a unit slip multiplies by (kg·m² read as g·m², kg·mm², g·mm²; and the inverses).
UNIT_FACTORS = (1e3, 1e6, 1e9)

#: Factors a decimal slip multiplies by.
DECIMAL_FACTORS = (10.0, 100.0)


@frozen_value
class Diagnosis:
    """One likely cause of a declared inertial's disagreement with the geometry.

    Attributes
    ----------
    cause : str
        One of :data:`CAUSES`.
    explanation : str
        One sentence with the evidence (the difference before and after undoing the cause).
    before : float
        Relative Frobenius difference of the declared tensor from the geometry's (at the declared mass).
    after : float
        The same after undoing the cause.
    inertia : (3, 3) float or None
        kg·m², the declared tensor with the cause undone (about the declared centre of mass, link axes).
    mass : float or None
        kg, the declared mass with the cause undone (unit slips of the mass), else None.
    """

    cause: str
    explanation: str
    before: float
    after: float
    inertia: np.ndarray | None = None
    mass: float | None = None


def _difference(tensor: np.ndarray, reference: np.ndarray) -> float:
    return float(np.linalg.norm(tensor - reference) / np.linalg.norm(reference))


def _power_of_ten(ratio: float, factors, *, slack: float = 0.3) -> float | None:
    """The factor ``f`` or ``1/f`` of ``factors`` whose log10 is within ``slack`` of ``log10(ratio)``."""
    if not (ratio > 0 and math.isfinite(ratio)):
        return None
    exponent = math.log10(ratio)
    for f in factors:
        for candidate in (f, 1.0 / f):
            if abs(exponent - math.log10(candidate)) <= slack:
                return candidate
    return None


def _frame_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Degrees of the smallest rotation between two principal frames (columns), axis signs free.

    Either frame may be left-handed (``numpy.linalg.eigh`` fixes no sign): all eight sign choices are tried
    and those that make ``a bᵀ`` a rotation (determinant +1) kept."""
    best = 180.0
    for signs in itertools.product((1, -1), repeat=3):
        r = (a * np.array(signs)) @ b.T
        if np.linalg.det(r) < 0:
            continue
        cos = (np.trace(r) - 1.0) / 2.0
        best = min(best, math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
    return best


def diagnose_inertial(declared_mass: float, declared_com, declared_inertia, geometry_mass: float,
                      geometry_inertia, *, tolerance: float = 0.25, anisotropy: float = 0.1,
                      density_range: tuple = (500.0, 19300.0), geometry_volume: float | None = None,
                      geometry_extents=None, box_rtol: float = 0.05) -> tuple:
    """Likely causes of a declared inertial's disagreement with the geometry (see the module docstring).

    Parameters
    ----------
    declared_mass : float
        kg, positive.
    declared_com : (3,) float
        m, link frame.
    declared_inertia : (3, 3) float
        kg·m² about ``declared_com``, link axes.
    geometry_mass : float
        kg, the geometry's at the density used (positive).
    geometry_inertia : (3, 3) float
        kg·m² about the geometry's centre of mass, link axes.
    tolerance : float
        Relative Frobenius difference below which a corrected tensor counts as agreeing (the audit's).
    anisotropy : float
        Relative spread of the geometry's principal moments above which an isotropic declared tensor is a
        placeholder.
    density_range : (float, float)
        kg/m³ of plausible materials (for unit slips of the mass).
    geometry_volume : float, optional
        m³ (for unit slips of the mass).
    geometry_extents : (3,) float, optional
        m, the edges of the geometry's bounding box in link axes (for a placeholder box).
    box_rtol : float
        Largest difference of each edge of the box the declared tensor describes from the bounding box's,
        relative to that edge, for a placeholder box.

    Returns
    -------
    tuple of Diagnosis
        Those that pass, best (smallest ``after``) first; empty when the tensors agree or nothing explains
        the difference.
    """
    tensor = 0.5 * (np.asarray(declared_inertia, dtype=np.float64) + np.asarray(declared_inertia).T)
    reference = np.asarray(geometry_inertia, dtype=np.float64) * (declared_mass / geometry_mass)
    if not (np.all(np.isfinite(tensor)) and np.linalg.norm(reference) > 0 and declared_mass > 0):
        return ()
    before = _difference(tensor, reference)
    found = []
    if geometry_volume is not None and geometry_volume > 0:
        density = declared_mass / geometry_volume
        mass_unit = _power_of_ten(declared_mass / geometry_mass, UNIT_FACTORS)
        low, high = density_range
        if mass_unit is not None and not low <= density <= high and low <= density / mass_unit <= high:
            found.append(Diagnosis(cause="unit", explanation=f"unit slip of the mass: {declared_mass:g} kg makes "
                                   f"{density:.4g} kg/m³; {declared_mass / mass_unit:g} kg (÷{mass_unit:g}) makes "
                                   f"{density / mass_unit:.4g} kg/m³", before=before, after=before,
                                   mass=declared_mass / mass_unit))
    if before <= tolerance:
        return tuple(found)

    def consider(cause: str, corrected: np.ndarray, sentence: str, mass: float | None = None) -> None:
        after = _difference(corrected, reference)
        if after <= tolerance and after <= 0.5 * before:
            found.append(Diagnosis(cause=cause, explanation=f"{sentence}: undone, the tensors differ by {after:.1%} "
                                   f"instead of {before:.0%}", before=before, after=after, inertia=corrected,
                                   mass=mass))

    ratio = float(np.trace(tensor) / np.trace(reference))
    unit = _power_of_ten(ratio, UNIT_FACTORS)
    if unit is not None:
        reading = "read as g·m², kg·mm² or g·mm²" if unit > 1 else "given in larger units"
        consider("unit", tensor / unit, f"unit slip: the declared tensor is {ratio:.4g}× the geometry's, close to "
                                        f"{unit:g} (kg·m² {reading})")
    decimal = _power_of_ten(ratio, DECIMAL_FACTORS, slack=0.15)
    if decimal is not None:
        consider("decimal", tensor / decimal, f"decimal slip: the declared tensor is {ratio:.4g}× the geometry's, "
                                              f"close to {decimal:g}")
    c = np.asarray(declared_com, dtype=np.float64)
    shift = declared_mass * (float(c @ c) * np.eye(3) - np.outer(c, c))
    if np.linalg.norm(shift) > 0:
        consider("origin", tensor - shift, "tensor about the link origin instead of the centre of mass "
                                           f"({np.linalg.norm(c) * 1e3:.1f} mm away)")
    moments_d, axes_d = np.linalg.eigh(tensor)
    moments_r, axes_r = np.linalg.eigh(reference)
    spread = float(np.linalg.norm(moments_d - moments_r) / np.linalg.norm(moments_r))
    if spread <= tolerance:
        angle = _frame_angle(axes_d, axes_r)
        corrected = axes_r @ np.diag(moments_d) @ axes_r.T
        consider("axes", corrected, f"principal moments right ({spread:.1%} apart) in axes turned by {angle:.0f}°")
    iso = abs(tensor[0, 0]) > 0 and np.allclose(tensor, tensor[0, 0] * np.eye(3), rtol=1e-9, atol=0.0)
    if iso and (moments_r[-1] - moments_r[0]) > anisotropy * moments_r[-1]:
        after = _difference(reference, reference)
        found.append(Diagnosis(cause="placeholder", explanation=f"placeholder: the declared tensor is "
                               f"{tensor[0, 0]:g}·1 (isotropic) while the geometry's principal moments span "
                               f"{moments_r[0]:.3g}–{moments_r[-1]:.3g} kg·m²", before=before, after=after,
                               inertia=reference))
    if not iso and geometry_extents is not None:
        box = _box_placeholder(tensor, declared_mass, np.asarray(geometry_extents, dtype=np.float64), box_rtol)
        if box is not None:
            found.append(Diagnosis(cause="placeholder", explanation=f"placeholder box: the declared tensor is that "
                                   f"of a solid {box} box of {declared_mass:g} kg, the link's bounding box, while "
                                   f"the geometry's tensor differs from it by {before:.0%}", before=before,
                                   after=0.0, inertia=reference))
    return tuple(sorted(found, key=lambda d: d.after))


def _box_placeholder(tensor: np.ndarray, mass: float, extents: np.ndarray, rtol: float) -> str | None:
    """``"0.1 × 0.2 × 0.3 m"`` when ``tensor`` (link axes) is diagonal and is the solid box of ``mass`` whose
    edges are ``extents``, each within ``rtol`` of its own length; else None."""
    moments = np.diag(tensor)
    if not (np.all(np.isfinite(extents)) and extents.max() > 0 and mass > 0):
        return None
    if np.abs(tensor - np.diag(moments)).max() > 1e-6 * np.abs(moments).max():
        return None
    squares = 6.0 * (moments.sum() - 2.0 * moments) / mass           # a_i² = 6 (I_j + I_k − I_i) / m
    if np.any(squares < 0):
        return None
    edges = np.sqrt(squares)
    if np.any(np.abs(edges - extents) > rtol * extents):
        return None
    return " × ".join(f"{e:.3g}" for e in edges) + " m"


def copied_masses(names, declared_masses, geometry_masses, *, mass_tolerance: float = 0.25) -> dict:
    """Links whose declared mass is exactly another link's, copied from it (the ``other_link`` rule of the
    module docstring).

    Parameters
    ----------
    names : sequence of str
    declared_masses, geometry_masses : sequence of float
        kg per link (nan where missing), geometry at the density used.
    mass_tolerance : float
        Relative mass difference that counts as a disagreement (the audit's).

    Returns
    -------
    dict
        Link name → :class:`Diagnosis` (``mass`` the geometry's) for each link found.
    """
    fits: dict = {}
    for name, declared, geometry in zip(names, declared_masses, geometry_masses):
        if declared > 0 and geometry > 0 and abs(declared / geometry - 1.0) <= mass_tolerance:
            fits.setdefault(float(declared), (name, declared / geometry))
    out = {}
    for name, declared, geometry in zip(names, declared_masses, geometry_masses):
        if not (declared > 0 and geometry > 0) or abs(declared / geometry - 1.0) <= mass_tolerance:
            continue
        source = fits.get(float(declared))
        if source is None or source[0] == name:
            continue
        ratio = declared / geometry
        out[name] = Diagnosis(cause="other_link", explanation=f"mass from another link: {declared:g} kg is exactly "
                              f"the declared mass of {source[0]!r}, whose geometry it fits ({source[1]:.3g}×), "
                              f"while this link's geometry gives {geometry:.4g} kg ({ratio:.3g}×)",
                              before=abs(ratio - 1.0), after=0.0, mass=float(geometry))
    return out


def nearest_valid_tensor(tensor, *, max_iterations: int = 10_000, rtol: float = 1e-14) -> np.ndarray:
    """The valid tensor nearest to ``tensor`` in the Frobenius norm.

    Valid is what the simulators accept: every principal moment ≥ 0 and ``I_a + I_b ≥ I_c``.  The set is
    spectral (it depends on the eigenvalues only, in any order), so the nearest valid tensor keeps the
    principal axes (von Neumann's trace inequality) and its moments are the Euclidean projection of the given
    ones onto the cone cut out by the six half-spaces, computed with Dykstra's alternating projections
    (exact for an intersection of convex sets, unlike plain alternation), at most ``max_iterations`` rounds.

    Parameters
    ----------
    tensor : (3, 3) float
        kg·m², symmetric.

    Returns
    -------
    (3, 3) float
        Equal to ``tensor`` when it is already valid.
    """
    t = 0.5 * (np.asarray(tensor, dtype=np.float64) + np.asarray(tensor, dtype=np.float64).T)
    moments, axes = np.linalg.eigh(t)
    normals = [np.array(n, dtype=np.float64) for n in ((1, 0, 0), (0, 1, 0), (0, 0, 1),
                                                         (1, 1, -1), (1, -1, 1), (-1, 1, 1))]
    if all(float(n @ moments) >= 0 for n in normals):
        return t
    x = moments.copy()
    increments = [np.zeros(3) for _ in normals]
    scale = float(np.max(np.abs(moments))) or 1.0
    for _ in range(max_iterations):
        previous = x.copy()
        for k, n in enumerate(normals):
            y = x + increments[k]
            gap = float(n @ y)
            projected = y - (gap / float(n @ n)) * n if gap < 0 else y
            increments[k] = y - projected
            x = projected
        if np.max(np.abs(x - previous)) <= rtol * scale:
            break
    x = np.maximum(x, 0.0)
    return axes @ np.diag(x) @ axes.T
