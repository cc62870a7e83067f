"""Principal moments and right-handed principal axes of an inertia tensor (Eq. 4.25).

Pure functions on SI arrays.  Conventions (ascending moments, axes as columns of a proper rotation,
sign choice, degenerate planes) are on ``docs/conventions.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..values import frozen_value
from ..errors import UsageError
from ..rotations import perpendicular_basis
from ..tolerances import EQUAL_MOMENTS_RTOL

if TYPE_CHECKING:     # annotations only: numpy.typing is not loaded at run time
    from numpy.typing import ArrayLike, NDArray

__all__ = ["PrincipalAxes", "principal_axes", "DEFAULT_EQUAL_RTOL"]

#: Default relative tolerance under which two principal moments count as equal (relative to the largest);
#: the same number as :data:`inertia_tool.tolerances.EQUAL_MOMENTS_RTOL`, under the name callers import.
DEFAULT_EQUAL_RTOL = EQUAL_MOMENTS_RTOL

#: The least positive normal float64 (the scale floor of the equal-moments test).
_TINY = float(np.finfo(np.float64).tiny)


@frozen_value
class PrincipalAxes:
    """Principal moments and axes of an inertia tensor about a stated point.

    Attributes
    ----------
    moments : (3,) float
        Principal moments ``I1 ≤ I2 ≤ I3`` in kg·m².
    axes : (3, 3) float
        Proper rotation (det +1); column ``k`` is the unit axis of ``moments[k]`` in mesh axes, so
        ``tensor = axes @ diag(moments) @ axes.T``.
    reference_point : (3,) float
        Point the tensor is taken about, m, mesh axes (the centre of mass for ``MassProperties.principal``).
    mass : float
        kg; ``nan`` when unknown (then ``radii_of_gyration`` is nan).
    equal_pairs : tuple of (int, int)
        Index pairs of moments equal within ``rtol``; the axes within such a plane are a free choice.
    rtol : float
        Relative tolerance (of the largest moment) used for ``equal_pairs``.
    """

    moments: NDArray[np.float64]
    axes: NDArray[np.float64]
    reference_point: NDArray[np.float64]
    mass: float
    equal_pairs: tuple[tuple[int, int], ...]
    rtol: float

    @property
    def radii_of_gyration(self) -> np.ndarray:
        """(3,) m: ``k_i = √(I_i / m)``."""
        return np.sqrt(np.clip(self.moments, 0.0, None) / self.mass)

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3): the same matrix as ``axes`` (principal-frame components → mesh components)."""
        return self.axes

    @property
    def is_axisymmetric(self) -> bool:
        """True when exactly two moments are equal within ``rtol``."""
        return len(self.equal_pairs) == 1

    @property
    def is_spherical(self) -> bool:
        """True when all three moments are equal within ``rtol``."""
        return len(self.equal_pairs) == 3

    @property
    def triangle_inequality_margin(self) -> float:
        """``(I1 + I2 − I3) / I3``: ≥ 0 for every physical body (0 for a flat plate)."""
        i1, i2, i3 = self.moments
        return float((i1 + i2 - i3) / i3) if i3 > 0 else float("nan")


def _canonical_sign(v: list[float]) -> list[float]:
    """``v`` or ``-v``: the one whose component of largest magnitude (the first on a tie) is positive."""
    k = max(range(3), key=lambda i: abs(v[i]))
    return [-x for x in v] if v[k] < 0 else v


def _cross3(a: Sequence[float] | np.ndarray, b: Sequence[float] | np.ndarray) -> np.ndarray:
    """``a × b`` of two 3-vectors (arrays or sequences of floats), with the very operations of ``np.cross`` (each
    component one product minus another, rounded as numpy rounds them: bit-identical), without its axis
    handling, which costs ~25 times the arithmetic on one pair of vectors (a tenth of a small part's analysis)."""
    a0, a1, a2 = a.tolist() if isinstance(a, np.ndarray) else a
    b0, b1, b2 = b.tolist() if isinstance(b, np.ndarray) else b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _orthonormalised(columns: list[Sequence[float]]) -> list[list[float]]:
    """The columns of ``Q`` in ``A = Q R`` with ``R``'s diagonal positive, for the 3×3 matrix ``A`` whose columns
    are ``columns`` (nearly orthonormal: eigenvectors, their cross product, a basis of their plane), then the
    third column negated if ``det Q < 0``.

    ``Q`` with a positive diagonal of ``R`` is unique for a full-rank ``A``, so this is what a Householder QR
    followed by the sign fix gives (as this module did through ``numpy.linalg.qr``), computed by modified
    Gram–Schmidt on Python floats: on columns orthonormal to round-off both agree to a few units in the last
    place, and Gram–Schmidt loses nothing there, at a twentieth of the cost of the LAPACK call on a 3×3 (which
    was a sixth of a small part's analysis)."""
    q: list[list[float]] = []
    for a in columns:
        v = list(a)
        for u in q:                                   # modified Gram–Schmidt: project out each earlier column
            d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
            v = [v[0] - d * u[0], v[1] - d * u[1], v[2] - d * u[2]]
        norm = math.hypot(v[0], v[1], v[2])
        q.append([v[0] / norm, v[1] / norm, v[2] / norm])
    c0, c1, c2 = _cross3(q[1], q[2]).tolist()
    if q[0][0] * c0 + q[0][1] * c1 + q[0][2] * c2 < 0:
        q[2] = [-x for x in q[2]]
    return q


def principal_axes(tensor: ArrayLike, *, reference_point: ArrayLike | None = None, mass: float = float("nan"),
                   rtol: float = DEFAULT_EQUAL_RTOL) -> PrincipalAxes:
    """Diagonalise a symmetric inertia tensor.

    Parameters
    ----------
    tensor : (3, 3) array_like
        Inertia tensor in kg·m² (tensor convention, off-diagonals −∫xy dm).
    reference_point : (3,) array_like, optional
        Point the tensor is about (carried into the result); default the origin.
    mass : float, optional
        kg, for radii of gyration.
    rtol : float
        Two moments ``I_a, I_b`` count as equal when ``|I_a − I_b| ≤ rtol · max(I)``.  In an equal pair the
        axes are replaced by a deterministic basis of their plane (see ``docs/conventions.md``) instead of
        the arbitrary one the eigen-solver returns.

    Returns
    -------
    PrincipalAxes
    """
    t = np.asarray(tensor, dtype=np.float64)
    if t.shape != (3, 3):
        raise UsageError(f"Expected `tensor` to have shape (3, 3), got {t.shape}")
    if not np.isfinite(t).all():
        raise UsageError("Expected a finite inertia tensor, got NaN or infinity")
    if not rtol >= 0:
        raise UsageError(f"Expected `rtol` >= 0, got {rtol}")
    t = 0.5 * (t + t.T)
    moments, vecs = np.linalg.eigh(t)
    m0, m1, m2 = moments.tolist()
    scale = max(abs(m2), _TINY)
    eq01 = abs(m1 - m0) <= rtol * scale
    eq12 = abs(m2 - m1) <= rtol * scale
    eq02 = abs(m2 - m0) <= rtol * scale
    pairs = tuple(p for p, flag in (((0, 1), eq01), ((1, 2), eq12), ((0, 2), eq02)) if flag)
    v = vecs.T.tolist()                               # v[k]: the eigenvector of moments[k]
    if eq01 and eq12 or eq02:
        columns: list[Sequence[float]] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        pairs = ((0, 1), (1, 2), (0, 2))
    elif eq01:
        top = _canonical_sign(v[2])
        e1, e2 = perpendicular_basis(top)
        columns = [e1.tolist(), e2.tolist(), top]
    elif eq12:
        bottom = _canonical_sign(v[0])
        e1, e2 = perpendicular_basis(bottom)
        columns = [bottom, e1.tolist(), e2.tolist()]
    else:
        first, second = _canonical_sign(v[0]), _canonical_sign(v[1])
        columns = [first, second, _cross3(first, second).tolist()]
    # re-orthonormalise (eigh returns orthonormal vectors to round-off; det +1)
    axes = np.array(_orthonormalised(columns)).T
    ref = np.zeros(3) if reference_point is None else np.asarray(reference_point, dtype=np.float64).reshape(3)
    return PrincipalAxes(moments=moments, axes=axes, reference_point=ref, mass=float(mass),
                         equal_pairs=pairs, rtol=float(rtol))
