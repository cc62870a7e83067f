"""Independent reference integrations for the dynamics tests (scipy DOP853 on Euler's equations + q̇ = ½ q⊗ω)."""

import numpy as np
from scipy.integrate import solve_ivp


def euler_quaternion_rhs(tensor, torque=None):
    tensor = np.asarray(tensor, float)
    inv = np.linalg.inv(tensor)

    def f(t, y):
        w, q = y[:3], y[3:]
        tau = np.zeros(3) if torque is None else np.asarray(torque(t, q, w), float)
        dw = inv @ (np.cross(tensor @ w, w) + tau)
        qw, qx, qy, qz = q
        wx, wy, wz = w
        dq = 0.5 * np.array([-qx * wx - qy * wy - qz * wz, qw * wx + qy * wz - qz * wy,
                             qw * wy + qz * wx - qx * wz, qw * wz + qx * wy - qy * wx])
        return np.concatenate([dw, dq])

    return f


def dop853(tensor, w0, t, q0=(1.0, 0.0, 0.0, 0.0), torque=None, rtol=1e-13, atol=1e-14, **kw):
    """Returns ω (N, 3) and q (N, 4) (sign-canonical w >= 0)."""
    y0 = np.concatenate([np.asarray(w0, float), np.asarray(q0, float)])
    sol = solve_ivp(euler_quaternion_rhs(tensor, torque), (t[0], t[-1]), y0, method="DOP853", rtol=rtol,
                    atol=atol, t_eval=t, **kw)
    assert sol.success
    q = sol.y[3:].T / np.linalg.norm(sol.y[3:].T, axis=1, keepdims=True)
    return sol.y[:3].T, np.where(q[:, :1] < 0, -q, q), sol
