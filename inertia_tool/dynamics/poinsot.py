"""Poinsot construction (§4.4.1): the polhode on the inertia ellipsoid and the herpolhode on the invariant plane.

The inertia ellipsoid ``ω·I·ω = 2T`` is fixed in the body; ω(t) traces the *polhode* on it.  In space, ω(t)
lies on the *invariant plane* ``L̂·ω = 2T/|L|`` (normal to the fixed ``L``, distance ``2T/|L|`` from the
centre of mass) and traces the *herpolhode* there; the ellipsoid rolls without slipping on the plane.
"""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..rotations import perpendicular_basis
from .simulation import simulate
from .torque_free import free_body_parameters
from .trajectory import resolve_body

__all__ = ["polhode", "herpolhode", "invariant_plane"]


def polhode(body, angular_velocity, *, samples: int = 257, separatrix_span: float = 12.0):
    """The polhode: one closed loop of the body angular velocity on the inertia ellipsoid.

    Parameters
    ----------
    body : MassProperties, PrincipalAxes, (3,) or (3, 3) array_like
        As for :func:`~inertia_tool.dynamics.simulation.simulate`.
    angular_velocity : (3,) array_like
        A point of the polhode, mesh axes, rad/s.
    samples : int
        Number of points (≥ 2).  The loop spans one period of ω(t) (``4K/λ``; ``2π/Ω`` for a symmetric body).
    separatrix_span : float
        On the separatrix (no period) the curve spans ``u ∈ [−span, span]/λ`` s around the given point.

    Returns
    -------
    t : (samples,) float
        Times from the given point, s.
    angular_velocity : (samples, 3) float
        Body angular velocity, mesh axes, rad/s (on ``ω·I·ω = 2T``).
    """
    if int(samples) < 2:
        raise UsageError(f"Expected `samples` >= 2, got {samples}")
    principal = resolve_body(body)
    omega = np.asarray(angular_velocity, dtype=np.float64)
    params = free_body_parameters(principal.moments, principal.axes.T @ omega)
    if np.isfinite(params.period):
        times = np.linspace(0.0, params.period, int(samples))
    elif params.case == "separatrix":
        times = np.linspace(0.0, 2.0 * separatrix_span / params.rate, int(samples))
        backward = simulate(body, -omega, times[: int(samples) // 2 + 1]).angular_velocity[::-1] * -1.0
        forward = simulate(body, omega, times[: int(samples) - len(backward) + 1]).angular_velocity[1:]
        half = times[: len(backward)]
        return np.concatenate([-half[::-1], times[1:len(forward) + 1]]), np.concatenate([backward, forward])
    else:  # fixed point (steady spin, sphere): the polhode is a single point
        times = np.linspace(0.0, 1.0, int(samples))
    return times, simulate(body, omega, times).angular_velocity


def invariant_plane(body, angular_velocity, *, orientation=None):
    """Unit normal ``L̂`` (space frame) and distance ``2T/|L|`` (rad/s) of the invariant plane at ``t = 0``.

    Parameters
    ----------
    body, angular_velocity, orientation
        As for :func:`~inertia_tool.dynamics.simulation.simulate` (torque-free).
    """
    traj = simulate(body, angular_velocity, [0.0], orientation=orientation)
    big_l = traj.angular_momentum[0]
    mom = np.linalg.norm(big_l)
    if mom == 0:
        raise UsageError("The invariant plane needs a non-zero angular velocity")
    return big_l / mom, 2.0 * traj.energy[0] / mom


def herpolhode(body, angular_velocity, t, *, orientation=None):
    """The herpolhode: the trace of ω(t) in space on the invariant plane (§4.4.1).

    Parameters
    ----------
    body, angular_velocity, orientation
        As for :func:`~inertia_tool.dynamics.simulation.simulate` (torque-free).
    t : (N,) array_like
        Increasing times, s.

    Returns
    -------
    points : (N, 3) float
        ``ω(t)`` in the space frame, rad/s; every point satisfies ``L̂·ω = 2T/|L|``.
    plane_coordinates : (N, 2) float
        The same points in an orthonormal basis ``(e1, e2)`` of the plane, rad/s, measured from the foot of
        the perpendicular from the centre of mass; ``e1`` is the space axis most orthogonal to ``L̂``,
        projected, ``e2 = L̂ × e1``.
    """
    traj = simulate(body, angular_velocity, t, orientation=orientation)
    points = traj.angular_velocity_space
    normal, distance = invariant_plane(body, angular_velocity, orientation=orientation)
    e1, e2 = perpendicular_basis(normal)
    rel = points - distance * normal
    return points, np.stack([rel @ e1, rel @ e2], -1)
