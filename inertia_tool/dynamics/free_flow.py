"""One step of the exact torque-free flow, on Python floats: the "drift" of the splitting integrator.

:func:`~inertia_tool.dynamics.torque_free.torque_free_motion` evaluates the closed form at many times from one
initial state (vectorised numpy, ~0.4 ms per call).  A splitting method needs the opposite: the flow over one
short time ``h`` from a *new* state at every stage (the torque kick changes ``E``, ``|L|`` and hence the elliptic
parameter each time).  This module evaluates the same closed form (Landau–Lifshitz §37, orientation after
Celledoni, Fassò, Säfström & Zanna 2008, *SIAM J. Sci. Comput.* 30, 2084) for one state and one ``h`` in
~15 µs, using scalar scipy special functions and three identities that avoid inverting the initial state:

* Addition theorem of the Jacobi functions (DLMF 22.8.1–3), from the known ``sn u0 = σ ω2/b``, ``cn u0 = ω1/a``,
  ``dn u0 = ω3/c`` and ``sn, cn, dn`` of the increment ``v = λ h`` (so ``u0 = F(am u0|m)`` is never needed)::

      sn(u0+v) = (s0 cv dv + sv c0 d0)/D,  cn(u0+v) = (c0 cv − s0 d0 sv dv)/D,
      dn(u0+v) = (d0 dv − m s0 c0 sv cv)/D,  D = 1 − m s0² sv².

* The precession about ``L`` (LL §37; notation of :mod:`.torque_free`)::

      ψ(h) − ψ(0) = M h/I3 + M (I3 − I1)/(I1 I3 λ) [Π(n; φ1) − Π(n; φ0)],  φ = am u,

  with ``Π(n; φ + jπ) = Π(n; φ) + 2j Π(n|m)`` and Carlson's form for ``|φ| ≤ π/2`` (DLMF 19.25.14); the angle
  ``am`` advances by ``π`` per ``2K`` of ``u`` and monotonically, which fixes the branch of ``φ1``.

* The orientation increment in the body (principal) frame ``R = W0ᵀ R_z(ψ(h) − ψ(0)) W1`` where ``W`` is the
  nodal frame of ``L`` (rows ``(L × d)/|L × d|``, ``L̂ × row1``, ``L̂``; ``d`` the principal axis the polhode
  circles, with the sign of :mod:`.torque_free`'s canonical labels), so ``Q(h) = Q(0) R``.

Symmetric and spherical bodies and steady spins use ``Q(h) = Q0 Rot(L̂_body, M h/I⊥) Rot(e_k, β h)``,
``β = (1/I_k − 1/I⊥) L_k`` (§4.4.1, Eq. 4.27).  States within ``1 − m < NEAR_SEPARATRIX_M1`` of the separatrix
fall back to :func:`~inertia_tool.dynamics.torque_free.torque_free_motion` (rare; slower, equally exact).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ellipj, elliprf, elliprj

from .elliptic import complete_k, jacobi_sn_cn_dn
from .torque_free import NEGLIGIBLE_COMPONENT, torque_free_motion

__all__ = ["free_flow_step", "NEAR_SEPARATRIX_M1"]

#: Below this ``1 − m`` the step uses :func:`torque_free_motion` (separatrix-safe) instead of the scalar path.
NEAR_SEPARATRIX_M1 = 1e-9
#: Below this ``1 − m`` the increment's ``sn, cn, dn`` come from :func:`.elliptic.jacobi_sn_cn_dn` (computed
#: from ``m1``) rather than ``scipy.special.ellipj`` (computed from ``m``).
_ELLIPJ_M1_FLOOR = 1e-4


def _quat_mul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw)


def _rotvec_quat(x, y, z):
    """Quaternion of the active rotation by the rotation vector ``(x, y, z)`` (angle = its norm)."""
    angle = math.sqrt(x * x + y * y + z * z)
    if angle == 0.0:
        return (1.0, 0.0, 0.0, 0.0)
    s = math.sin(0.5 * angle) / angle
    return (math.cos(0.5 * angle), s * x, s * y, s * z)


def _matrix_quat(r):
    """Scalar-first quaternion of a rotation matrix given as 9 floats, row-major (Shepperd's method)."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = r
    trace = r00 + r11 + r22
    if trace >= max(r00, r11, r22):
        s = 2.0 * math.sqrt(1.0 + trace)
        return (0.25 * s, (r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s)
    if r00 >= r11 and r00 >= r22:
        s = 2.0 * math.sqrt(1.0 + r00 - r11 - r22)
        return ((r21 - r12) / s, 0.25 * s, (r01 + r10) / s, (r02 + r20) / s)
    if r11 >= r22:
        s = 2.0 * math.sqrt(1.0 - r00 + r11 - r22)
        return ((r02 - r20) / s, (r01 + r10) / s, 0.25 * s, (r12 + r21) / s)
    s = 2.0 * math.sqrt(1.0 - r00 - r11 + r22)
    return ((r10 - r01) / s, (r02 + r20) / s, (r12 + r21) / s, 0.25 * s)


def _nodal_rows(lx, ly, lz, dx, dy, dz, mom):
    """Rows of the nodal frame ``W`` of ``L``: ``(L × d)/|L × d|``, ``L̂ × row1``, ``L̂``."""
    ax, ay, az = ly * dz - lz * dy, lz * dx - lx * dz, lx * dy - ly * dx
    p = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / p, ay / p, az / p
    ux, uy, uz = lx / mom, ly / mom, lz / mom
    return (ax, ay, az), (uy * az - uz * ay, uz * ax - ux * az, ux * ay - uy * ax), (ux, uy, uz)


def _pi_reduced(s, c, n, m1):
    """``Π(n; φ|m)`` for ``|φ| ≤ π/2`` from ``s = sin φ``, ``c = cos φ ≥ 0`` (DLMF 19.25.14)."""
    c2 = c * c
    s2 = s * s
    delta2 = c2 + m1 * s2
    return s * float(elliprf(c2, delta2, 1.0)) + (n / 3.0) * s * s2 * float(elliprj(c2, delta2, 1.0, 1.0 - n * s2))


def _symmetric_step(moments, w, q, h, k, i_perp):
    """``Q(h) = Q0 Rot(L̂, M h/I⊥) Rot(e_k, β h)``, ``ω(h) = Rot(e_k, −β h) ω0`` (body frame)."""
    lx, ly, lz = moments[0] * w[0], moments[1] * w[1], moments[2] * w[2]
    big_l = (lx, ly, lz)
    beta = (1.0 / moments[k] - 1.0 / i_perp) * big_l[k]
    scale = h / i_perp
    q1 = _quat_mul(q, _rotvec_quat(lx * scale, ly * scale, lz * scale))
    spin = [0.0, 0.0, 0.0]
    spin[k] = beta * h
    q1 = _quat_mul(q1, _rotvec_quat(*spin))
    cb, sb = math.cos(beta * h), math.sin(beta * h)
    i, j = (k + 1) % 3, (k + 2) % 3
    w1 = [0.0, 0.0, 0.0]
    w1[k] = w[k]
    w1[i] = cb * w[i] + sb * w[j]       # Rot(e_k, −βh) ω
    w1[j] = -sb * w[i] + cb * w[j]
    return tuple(w1), q1


def _fallback_step(moments, w, q, h):
    omega, quat, _ = torque_free_motion(np.asarray(moments), np.asarray(w), np.array([0.0, h]),
                                        orientation=np.asarray(q))
    return tuple(omega[1].tolist()), tuple(quat[1].tolist())


def free_flow_step(moments, angular_velocity, orientation, h):
    """Exact torque-free motion over one time step, principal frame, on Python floats.

    Parameters
    ----------
    moments : tuple of 3 float
        Principal moments ``I1 ≤ I2 ≤ I3``, kg·m² (exactly equal values select the symmetric closed form).
    angular_velocity : tuple of 3 float
        Body angular velocity ``ω(0)``, principal frame, rad/s.
    orientation : tuple of 4 float
        Scalar-first unit quaternion of principal frame → space at time 0.
    h : float
        Time step, s (any sign; negative steps run the flow backwards, as the splitting compositions need).

    Returns
    -------
    angular_velocity : tuple of 3 float
        ``ω(h)``, principal frame, rad/s.
    orientation : tuple of 4 float
        Quaternion at ``h`` (unit up to round-off; not sign-normalised).
    """
    i1, i2, i3 = (float(x) for x in moments)
    w1, w2, w3 = (float(x) for x in angular_velocity)
    orientation = tuple(float(x) for x in orientation)
    h = float(h)
    big = max(abs(w1), abs(w2), abs(w3))
    if big == 0.0 or h == 0.0:
        return (w1, w2, w3), tuple(orientation)
    if i1 == i3:
        return (w1, w2, w3), _quat_mul(orientation, _rotvec_quat(w1 * h, w2 * h, w3 * h))
    if i1 == i2:
        return _symmetric_step((i1, i2, i3), (w1, w2, w3), orientation, h, 2, i1)
    if i2 == i3:
        return _symmetric_step((i1, i2, i3), (w1, w2, w3), orientation, h, 0, i3)
    tiny = NEGLIGIBLE_COMPONENT * big
    if int(abs(w1) > tiny) + int(abs(w2) > tiny) + int(abs(w3) > tiny) <= 1:  # steady spin about a principal axis
        return (w1, w2, w3), _quat_mul(orientation, _rotvec_quat(w1 * h, w2 * h, w3 * h))
    if h < 0.0:  # time reversal: ω(−h; ω0) = −ω(h; −ω0), Q(−h; ω0, Q0) = Q(h; −ω0, Q0)
        wb, qb = free_flow_step((i1, i2, i3), (-w1, -w2, -w3), orientation, -h)
        return (-wb[0], -wb[1], -wb[2]), qb
    # canonical labels of torque_free._canonical: (j1, j2, j3), ω_c = P ω, d = P^T e3
    if i3 * (i3 - i2) * w3 * w3 - i1 * (i2 - i1) * w1 * w1 >= 0.0:
        j1, j2, j3, v1, v2, v3 = i1, i2, i3, w1, w2, w3
        d_axis = 2
    else:
        j1, j2, j3, v1, v2, v3 = i3, i2, i1, w3, -w2, w1
        d_axis = 0
    d_sign = 1.0
    if v3 < 0.0:
        v1, v3, d_sign = -v1, -v3, -1.0
    k0 = j1 * (j3 - j1) * v1 * v1 + j2 * (j3 - j2) * v2 * v2          # 2E I3 − M²
    k1 = j2 * (j2 - j1) * v2 * v2 + j3 * (j3 - j1) * v3 * v3          # M² − 2E I1
    gap = j3 * (j3 - j2) * v3 * v3 - j1 * (j2 - j1) * v1 * v1         # M² − 2E I2
    m1 = max((j3 - j1) * gap / ((j3 - j2) * k1), 0.0)
    m = (j2 - j1) * k0 / ((j3 - j2) * k1)
    if m1 < 0.5:
        m = 1.0 - m1
    else:
        m1 = 1.0 - m
    if m1 < NEAR_SEPARATRIX_M1:
        return _fallback_step((i1, i2, i3), (w1, w2, w3), orientation, h)
    a = math.sqrt(k0 / (j1 * (j3 - j1)))
    b = math.sqrt(k0 / (j2 * (j3 - j2)))
    c = math.sqrt(k1 / (j3 * (j3 - j1)))
    lam = math.sqrt((j3 - j2) * k1 / (j1 * j2 * j3))
    sigma = 1.0 if j3 > j2 else -1.0
    s0, c0, d0 = sigma * v2 / b, v1 / a, v3 / c
    norm = math.hypot(s0, c0)
    s0, c0 = s0 / norm, c0 / norm
    d0 = math.sqrt(c0 * c0 + m1 * s0 * s0)
    kk = complete_k(m1)
    v = lam * h
    turns = math.floor(v / (2.0 * kk))       # whole half-periods of sn: am advances by π each
    vr = v - 2.0 * kk * turns
    if m1 < _ELLIPJ_M1_FLOOR:
        sv, cv, dv = (float(x) for x in jacobi_sn_cn_dn(np.array(vr), m, m1))
    else:
        sv, cv, dv, _ = (float(x) for x in ellipj(vr, m))
    if turns % 2:  # sn(v + 2K) = −sn v, cn(v + 2K) = −cn v
        sv, cv = -sv, -cv
    den = 1.0 - m * s0 * s0 * sv * sv
    s1 = (s0 * cv * dv + sv * c0 * d0) / den
    c1 = (c0 * cv - s0 * d0 * sv * dv) / den
    d1 = (d0 * dv - m * s0 * c0 * sv * cv) / den
    # Π(n; φ1) − Π(n; φ0): φ0 ∈ (−π, π] from (s0, c0); φ1 = φ0 + π·turns + δ, δ ∈ [0, π)
    n = -j3 * (j2 - j1) / (j1 * (j3 - j2))
    phi0 = math.atan2(s0, c0)
    delta = (math.atan2(s1, c1) - phi0 - math.pi * turns) % (2.0 * math.pi)
    if delta > 1.5 * math.pi:
        delta -= 2.0 * math.pi
    phi1 = phi0 + math.pi * turns + delta
    half0 = round(phi0 / math.pi)
    half1 = round(phi1 / math.pi)
    sign0 = -1.0 if half0 % 2 else 1.0
    sign1 = -1.0 if half1 % 2 else 1.0
    big_pi = _pi_reduced(sign1 * s1, abs(c1), n, m1) - _pi_reduced(sign0 * s0, abs(c0), n, m1)
    if half1 != half0:
        complete = float(elliprf(0.0, m1, 1.0)) + (n / 3.0) * float(elliprj(0.0, m1, 1.0, 1.0 - n))
        big_pi += 2.0 * (half1 - half0) * complete
    mom = math.sqrt((j1 * v1) ** 2 + (j2 * v2) ** 2 + (j3 * v3) ** 2)
    psi = mom * h / j3 + mom * (j3 - j1) / (j1 * j3 * lam) * big_pi
    # new canonical ω, back to principal labels
    u1, u2, u3 = a * c1, sigma * b * s1, c * d1
    if d_sign < 0.0:
        u1, u3 = -u1, -u3
    if d_axis == 2:
        out = (u1, u2, u3)
    else:
        out = (u3, -u2, u1)
    d = [0.0, 0.0, 0.0]
    d[d_axis] = d_sign
    # R = W0ᵀ R_z(ψ) W1 in principal components
    r1, r2, r3 = _nodal_rows(i1 * w1, i2 * w2, i3 * w3, d[0], d[1], d[2], mom)
    t1, t2, t3 = _nodal_rows(i1 * out[0], i2 * out[1], i3 * out[2], d[0], d[1], d[2], mom)
    cz, sz = math.cos(psi), math.sin(psi)
    col1 = (cz * r1[0] + sz * r2[0], cz * r1[1] + sz * r2[1], cz * r1[2] + sz * r2[2])
    col2 = (-sz * r1[0] + cz * r2[0], -sz * r1[1] + cz * r2[1], -sz * r1[2] + cz * r2[2])
    rot = [col1[i] * t1[j] + col2[i] * t2[j] + r3[i] * t3[j] for i in range(3) for j in range(3)]
    return out, _quat_mul(orientation, _matrix_quat(rot))
