"""The equivalent inertia ellipsoid: the uniform solid ellipsoid with a body's mass and principal moments.

Drawn by the HTML report as the picture of an inertia tensor.  Its semi-axes are lengths (m), comparable with
the part itself, unlike the Poinsot ellipsoid ``xᵀ I x = 1`` whose semi-axes ``1/√I_k`` have units
kg^-½ m^-1.  The two share their axes; the long axis of the equivalent ellipsoid lies along the *smallest*
moment.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PhysicsError, UsageError
from ..tolerances import TRIANGLE_INEQUALITY_RTOL

__all__ = ["equivalent_ellipsoid_semi_axes"]


def equivalent_ellipsoid_semi_axes(moments: ArrayLike, mass: float, *,
                                   rtol: float = TRIANGLE_INEQUALITY_RTOL) -> np.ndarray:
    """Semi-axes of the uniform solid ellipsoid with mass ``mass`` and principal moments ``moments``.

    A solid ellipsoid of semi-axes ``a_1, a_2, a_3`` and mass ``m`` has ``I_1 = m (a_2² + a_3²)/5`` and
    cyclically (the moments of inertia of Eq. 4.13 integrated over the ellipsoid); solving,
    ``a_k² = 5 (I_i + I_j − I_k) / (2 m)`` for ``{i, j, k} = {1, 2, 3}``.

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments about the centre of mass, kg·m² (any order; the result follows it).
    mass : float
        kg, > 0.
    rtol : float
        A combination ``I_i + I_j − I_k`` down to ``−rtol · max(I)`` (round-off on a flat body) gives a
        zero semi-axis; below that the moments violate the triangle inequality.

    Returns
    -------
    (3,) float
        Semi-axes in m, ``result[k]`` along the axis of ``moments[k]``.

    Raises
    ------
    PhysicsError
        If the moments violate the triangle inequality (no body has them).
    """
    m_ = np.asarray(moments, dtype=np.float64)
    if m_.shape != (3,) or not np.all(np.isfinite(m_)):
        raise UsageError(f"Expected three finite moments of shape (3,), got {m_.tolist()}")
    if not (np.isfinite(mass) and mass > 0):
        raise UsageError(f"Expected a positive finite mass in kg, got {mass}")
    combos = m_.sum() - 2.0 * m_                  # I_i + I_j − I_k
    if np.any(combos < -rtol * np.max(np.abs(m_))):
        raise PhysicsError(f"Principal moments {m_.tolist()} kg·m² violate the triangle inequality; "
                           "no ellipsoid (no body) has them")
    semi_axes: NDArray[np.float64] = np.sqrt(np.clip(combos, 0.0, None) * 5.0 / (2.0 * mass))
    return semi_axes
