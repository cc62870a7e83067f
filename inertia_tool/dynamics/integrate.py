"""Numerical rigid-body integration with an external torque: Euler's equations plus quaternion kinematics.

State (all in the body's *mesh* axes, so no frame change per evaluation): angular velocity ``ω`` and the
scalar-first orientation quaternion ``q`` (body → space, ``docs/conventions.md``)::

    I ω̇ = (I ω) × ω + τ(t, q, ω)        Euler's equations, Eq. (4.26) (Eq. 4.27 in principal axes)
    q̇  = ½ q ⊗ (0, ω)                   body angular velocity acting on the right

Method: Gragg–Bulirsch–Stoer extrapolation (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.9): the
explicit midpoint rule with ``n_j = 2, 4, 6, …, 2k`` substeps, Aitken–Neville extrapolation in ``h²`` to
order ``2k`` (default ``k = 6``: order 12), step size control on the difference of the last two
extrapolated columns.  Steps never cross a requested output time (so outputs are exact steps, not
interpolants).  After every step the quaternion is renormalised to the unit sphere (the exact flow keeps
``|q| = 1``; the projection removes the ``O(h^{2k+1})`` drift), so orientations are always proper rotations.

The torque is a callable ``torque(t, orientation, angular_velocity) -> (3,)``: time in s, the scalar-first
unit quaternion (4,) of body → space, the body angular velocity (3,) in rad/s in mesh axes; it returns the
torque about the centre of mass in N·m **in body (mesh) axes**.  (For a torque known in space axes
``τ_s``, return ``Qᵀ τ_s`` with ``Q = quaternion_to_matrix(orientation)``.)
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import PhysicsError, UsageError

__all__ = ["integrate_rigid_body", "DEFAULT_COLUMNS"]

#: Default number of extrapolation columns ``k`` (order ``2k``).
DEFAULT_COLUMNS = 6


def _make_rhs(tensor: np.ndarray, torque):
    """The right-hand side ``f(t, y)`` for ``y = (ω, q)`` written on Python floats (it runs millions of
    times; small-array numpy calls would dominate)."""
    inv = np.linalg.inv(tensor)
    (t00, t01, t02), (t10, t11, t12), (t20, t21, t22) = tensor.tolist()
    (i00, i01, i02), (i10, i11, i12), (i20, i21, i22) = inv.tolist()
    empty = np.empty

    def rhs(t, y):
        wx, wy, wz, qw, qx, qy, qz = y.tolist()
        lx = t00 * wx + t01 * wy + t02 * wz
        ly = t10 * wx + t11 * wy + t12 * wz
        lz = t20 * wx + t21 * wy + t22 * wz
        cx = ly * wz - lz * wy
        cy = lz * wx - lx * wz
        cz = lx * wy - ly * wx
        if torque is not None:
            tau = torque(t, y[3:], y[:3])
            cx += float(tau[0])
            cy += float(tau[1])
            cz += float(tau[2])
        out = empty(7)
        out[0] = i00 * cx + i01 * cy + i02 * cz
        out[1] = i10 * cx + i11 * cy + i12 * cz
        out[2] = i20 * cx + i21 * cy + i22 * cz
        out[3] = 0.5 * (-qx * wx - qy * wy - qz * wz)
        out[4] = 0.5 * (qw * wx + qy * wz - qz * wy)
        out[5] = 0.5 * (qw * wy + qz * wx - qx * wz)
        out[6] = 0.5 * (qw * wz + qx * wy - qy * wx)
        return out

    return rhs


def _gbs_step(rhs, t0, y0, f0, h_big, columns):
    """One extrapolated step; returns ``(y_new, error_vector)``."""
    table = []
    for j in range(1, columns + 1):
        n = 2 * j
        h = h_big / n
        z_prev = y0
        z = y0 + h * f0
        two_h = 2.0 * h
        for i in range(1, n):
            z_prev, z = z, z_prev + two_h * rhs(t0 + i * h, z)
        row = [z]
        for k in range(1, j):
            ratio = (j / (j - k)) ** 2  # (n_j / n_{j-k})²
            prev = table[-1][k - 1]
            row.append(row[k - 1] + (row[k - 1] - prev) / (ratio - 1.0))
        table.append(row)
    best = table[-1][-1]
    return best, best - table[-1][-2]


def integrate_rigid_body(tensor, angular_velocity, orientation, t, torque, *, rtol: float = 1e-12,
                         atol: float = 1e-12, columns: int = DEFAULT_COLUMNS, first_step: float | None = None,
                         max_steps: int = 1_000_000):
    """Integrate Euler's equations and the quaternion kinematics with an external torque.

    Parameters
    ----------
    tensor : (3, 3) array_like
        Inertia tensor about the centre of mass in the body axes used for ``angular_velocity``, kg·m².
    angular_velocity : (3,) array_like
        Body angular velocity at ``t[0]``, rad/s.
    orientation : (4,) array_like
        Scalar-first quaternion of body → space at ``t[0]``.
    t : (N,) array_like
        Strictly increasing output times, s.
    torque : callable or None
        ``torque(t, orientation (4,), angular_velocity (3,)) -> (3,)`` N·m in body axes (module docstring).
    rtol, atol : float
        Local error tolerances on every state component (``|ω|`` in rad/s, ``q`` dimensionless).
    columns : int
        Extrapolation columns ``k`` (order ``2k``), 2 … 12.
    first_step : float, optional
        Initial step, s; default estimated from ``|ω|`` and the tolerance.
    max_steps : int
        Bound on accepted plus rejected steps; :class:`~inertia_tool.errors.PhysicsError` beyond it.

    Returns
    -------
    angular_velocity : (N, 3) float
    orientation : (N, 4) float
        Unit quaternions (sign continuous along the trajectory).
    """
    if not 2 <= int(columns) <= 12:
        raise UsageError(f"Expected `columns` between 2 and 12, got {columns}")
    if not (rtol > 0 and atol > 0):
        raise UsageError(f"Expected positive `rtol` and `atol`, got {rtol}, {atol}")
    if torque is not None and not callable(torque):
        raise UsageError(f"Expected `torque` to be callable or None, got {type(torque).__name__}")
    columns = int(columns)
    tensor = np.asarray(tensor, dtype=np.float64)
    times = np.asarray(t, dtype=np.float64)
    rhs = _make_rhs(tensor, torque)
    y = np.concatenate([np.asarray(angular_velocity, dtype=np.float64), np.asarray(orientation, dtype=np.float64)])
    y[3:] /= np.linalg.norm(y[3:])
    out = np.empty((len(times), 7))
    out[0] = y
    t_now = float(times[0])
    span = float(times[-1] - times[0])
    if first_step is None:
        rate = max(float(np.linalg.norm(y[:3])), 1e-300)
        h = min(0.5 / rate, span if span > 0 else 1.0)
    else:
        h = float(first_step)
    exponent = 1.0 / (2 * columns - 1)
    steps = 0
    f_now = rhs(t_now, y)
    for index in range(1, len(times)):
        target = float(times[index])
        while t_now < target:
            if steps >= max_steps:
                raise PhysicsError(f"Integration needed more than max_steps={max_steps} steps by t={t_now:g} s")
            steps += 1
            last = h >= target - t_now
            h_try = target - t_now if last else h
            y_new, err_vec = _gbs_step(rhs, t_now, y, f_now, h_try, columns)
            scale = atol + rtol * np.maximum(np.abs(y), np.abs(y_new))
            err = math.sqrt(float(np.mean((err_vec / scale) ** 2)))
            if not math.isfinite(err):
                h = 0.25 * h_try
                continue
            factor = 0.94 * (0.65 / err) ** exponent if err > 0 else 4.0
            factor = min(4.0, max(0.2, factor))
            if err <= 1.0:
                t_now = target if last else t_now + h_try
                y = y_new
                y[3:] /= math.sqrt(float(y[3:] @ y[3:]))
                f_now = rhs(t_now, y)
                h = max(h, h_try * factor) if last else h_try * factor
            else:
                h = h_try * min(factor, 0.9)
        out[index] = y
    return out[:, :3].copy(), out[:, 3:].copy()
