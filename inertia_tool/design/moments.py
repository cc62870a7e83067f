"""Mass moments as one vector, and what spinning asks of them (Chapter 4, "Rigid Body Motion", §4.3–4.4).

Every mass property is linear in the density field: the **moment vector** of a body in a frame (origin ``o``,
orthonormal axes ``e1, e2, e3``) is

    μ = (∫dm, ∫x dm, ∫y dm, ∫z dm, ∫x² dm, ∫y² dm, ∫z² dm, ∫xy dm, ∫xz dm, ∫yz dm)        (10 numbers)

in frame coordinates, so a body with a cavity is ``μ_part − ρ μ_cavity``.  From it follow the centre of mass
``c = s/m`` and the inertia tensor about the frame origin ``I = tr(S) 𝟙 − S`` (Eq. 4.13 with ``S = ∫ r rᵀ dm``),
about the centre of mass by the parallel-axis theorem (Eq. 4.16).

The objectives of the spin designs are functions of ``μ`` alone (Hafner et al., "Spin-It Faster", SIGGRAPH
2024: the optimal cavity of such an objective is bounded by a quadric):

* yo-yo (free spin about ``e3``, §4.4.1): ``e3`` a principal axis through the centre of mass with the largest
  moment.  ``f = w_c (c1² + c2²)/L² + w_p (I13² + I23²)/I33² + (I11² + I22² + 2 I12²)/I33²`` (central tensor);
  the last term is Spin-It's ``(I_a/I_c)² + (I_b/I_c)²`` (Bächer et al., SIGGRAPH 2014), small when ``I33``
  dominates the transverse moments.
* top (heavy symmetric top on the pivot ``o``, §4.4.3): centre of mass on ``e3`` above the pivot, ``e3`` a
  principal axis about the pivot with equal transverse moments, and the sleeping-top threshold
  ``ω_c² = 4 I1 M g l / I3²`` as small as possible:
  ``f = ω_c²/ω_ref² + w_c (c1² + c2²)/L² + w_p [(I11 − I22)² + 4 I12² + I13² + I23²]/I33²`` (tensor about the
  pivot, ``I1 = (I11 + I22)/2``, ``l = c3``).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import PhysicsError

__all__ = ["moment_vector", "cell_moment_rows", "frame_quantities", "yoyo_objective", "top_objective",
           "OBJECTIVES"]


def moment_vector(props, origin, frame) -> np.ndarray:
    """The 10-vector μ of a ``MassProperties`` in the frame (origin m, mesh axes; ``frame`` (3, 3), columns
    the frame axes in mesh components)."""
    r = np.asarray(frame, dtype=np.float64)
    d = r.T @ (np.asarray(props.center_of_mass) - np.asarray(origin, dtype=np.float64))
    central = r.T @ np.asarray(props.inertia) @ r
    second = 0.5 * np.trace(central) * np.eye(3) - central + props.mass * np.outer(d, d)
    m = props.mass
    return np.array([m, m * d[0], m * d[1], m * d[2], second[0, 0], second[1, 1], second[2, 2], second[0, 1],
                     second[0, 2], second[1, 2]])


def cell_moment_rows(points, spacing: float) -> np.ndarray:
    """μ of unit-density cubes of edge ``spacing`` centred at ``points`` (frame coordinates, (n, 3) m): (n, 10).

    A cube's second moments about its centre are ``h⁵/12`` on the diagonal and 0 off it."""
    p = np.asarray(points, dtype=np.float64)
    v = spacing ** 3
    own = v * spacing ** 2 / 12.0
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    return np.column_stack([np.full(len(p), v), v * x, v * y, v * z, v * x * x + own, v * y * y + own,
                            v * z * z + own, v * x * y, v * x * z, v * y * z])


def frame_quantities(mu) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """``(m, c, I_origin, I_center)`` from μ: mass, centre of mass (3,), inertia about the frame origin and
    about the centre of mass (3, 3), all in frame components (tensor convention)."""
    mu = np.asarray(mu, dtype=np.float64)
    m = mu[0]
    if not m > 0:
        raise PhysicsError(f"Expected a positive mass in the design, got {m!r}")
    c = mu[1:4] / m
    s = np.array([[mu[4], mu[7], mu[8]], [mu[7], mu[5], mu[9]], [mu[8], mu[9], mu[6]]])
    i_origin = np.trace(s) * np.eye(3) - s
    s_center = s - m * np.outer(c, c)
    i_center = np.trace(s_center) * np.eye(3) - s_center
    return m, c, i_origin, i_center


def yoyo_objective(mu, *, size: float, center_weight: float, product_weight: float,
                   axis_through_origin: bool) -> float:
    """The yo-yo objective of the module docstring; ``center_weight`` applies only with
    ``axis_through_origin`` (the spin axis is the frame's ``e3`` through ``o``; otherwise only its direction)."""
    _, c, _, i = frame_quantities(mu)
    value = (i[0, 0] ** 2 + i[1, 1] ** 2 + 2.0 * i[0, 1] ** 2) / i[2, 2] ** 2
    value += product_weight * (i[0, 2] ** 2 + i[1, 2] ** 2) / i[2, 2] ** 2
    if axis_through_origin:
        value += center_weight * (c[0] ** 2 + c[1] ** 2) / size ** 2
    return float(value)


def top_objective(mu, *, size: float, center_weight: float, product_weight: float,
                  reference_threshold: float) -> float:
    """The top objective of the module docstring (gravity folded into ``reference_threshold``: both are
    ``I1 M l / I3²``, 1/s² up to the factor 4g)."""
    m, c, i, _ = frame_quantities(mu)
    i1 = 0.5 * (i[0, 0] + i[1, 1])
    height = max(c[2], 1e-6 * size)          # the centre of mass must stay above the pivot
    value = i1 * m * height / i[2, 2] ** 2 / reference_threshold
    value += center_weight * (c[0] ** 2 + c[1] ** 2) / size ** 2
    value += product_weight * ((i[0, 0] - i[1, 1]) ** 2 + 4.0 * i[0, 1] ** 2 + i[0, 2] ** 2
                               + i[1, 2] ** 2) / i[2, 2] ** 2
    return float(value)


def top_threshold_measure(mu) -> float:
    """``I1 M l / I3²`` (about the pivot), the sleeping threshold ``ω_c²`` over ``4g``."""
    m, c, i, _ = frame_quantities(mu)
    return float(0.5 * (i[0, 0] + i[1, 1]) * m * c[2] / i[2, 2] ** 2)


#: The objectives by design mode; each takes the part's moment vector and its keyword weights.
OBJECTIVES: dict[str, Callable[..., float]] = {"yoyo": yoyo_objective, "top": top_objective}
