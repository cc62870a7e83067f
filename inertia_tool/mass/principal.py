"""Principal moments and right-handed principal axes of an inertia tensor (Eq. 4.25).

Pure functions on SI arrays.  Conventions (ascending moments, axes as columns of a proper rotation,
sign choice, degenerate planes) are on ``docs/conventions.md``.
"""

from __future__ import annotations

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


def _canonical_sign(v: NDArray[np.float64]) -> NDArray[np.float64]:
    k = int(np.argmax(np.abs(v)))
    return -v if v[k] < 0 else v


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` of two (3,) float64 vectors, with the very operations of ``np.cross`` (each component one
    product minus another, rounded as numpy rounds them: bit-identical), without its axis handling, which costs
    ~25 times the arithmetic on one pair of vectors (a tenth of a small part's analysis)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


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
    if not np.all(np.isfinite(t)):
        raise UsageError("Expected a finite inertia tensor, got NaN or infinity")
    if not rtol >= 0:
        raise UsageError(f"Expected `rtol` >= 0, got {rtol}")
    t = 0.5 * (t + t.T)
    moments, vecs = np.linalg.eigh(t)
    scale = max(abs(moments[-1]), np.finfo(float).tiny)
    eq01 = abs(moments[1] - moments[0]) <= rtol * scale
    eq12 = abs(moments[2] - moments[1]) <= rtol * scale
    eq02 = abs(moments[2] - moments[0]) <= rtol * scale
    pairs = tuple(p for p, flag in (((0, 1), eq01), ((1, 2), eq12), ((0, 2), eq02)) if flag)
    if eq01 and eq12 or eq02:
        axes = np.eye(3)
        pairs = ((0, 1), (1, 2), (0, 2))
    elif eq01:
        a3 = _canonical_sign(vecs[:, 2])
        a1, a2 = perpendicular_basis(a3)
        axes = np.column_stack([a1, a2, a3])
    elif eq12:
        a1 = _canonical_sign(vecs[:, 0])
        a2, a3 = perpendicular_basis(a1)
        axes = np.column_stack([a1, a2, a3])
    else:
        a1 = _canonical_sign(vecs[:, 0])
        a2 = _canonical_sign(vecs[:, 1])
        axes = np.column_stack([a1, a2, _cross3(a1, a2)])
    # re-orthonormalise (eigh returns orthonormal vectors to round-off; keep det exactly +1 in spirit)
    q, r = np.linalg.qr(axes)
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 2] = -q[:, 2]
    ref = np.zeros(3) if reference_point is None else np.asarray(reference_point, dtype=np.float64).reshape(3)
    return PrincipalAxes(moments=moments, axes=q, reference_point=ref, mass=float(mass),
                         equal_pairs=pairs, rtol=float(rtol))
