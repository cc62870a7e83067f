"""Exact motion of a torque-free rigid body (Euler–Poinsot case), in the principal frame.

Landau & Lifshitz, *Mechanics*, §37 (angular velocity through Jacobi elliptic functions, precession angle
through the elliptic integral of the third kind); the orientation follows the construction of Celledoni,
Fassò, Säfström & Zanna (2008), *SIAM J. Sci. Comput.* 30, 2084: rotate space so the (constant) angular
momentum ``L`` is along z; the attitude is then the body-frame direction of ``L`` (known from ω(t)) plus
one angle ψ(t) about ``L``, integrated in closed form with Carlson's ``R_F``, ``R_J``
(:mod:`inertia_tool.dynamics.elliptic`).  The chapter covers the symmetric case (§4.4.1, "Euler's
equations", Eq. 4.27) and the Poinsot construction.

Notation (principal frame, ``I1 < I2 < I3``; ``E`` kinetic energy, ``M = |L|``)::

    2E I3 − M² = I1(I3−I1)ω1² + I2(I3−I2)ω2²      (≥ 0)
    M² − 2E I1 = I2(I2−I1)ω2² + I3(I3−I1)ω3²      (≥ 0)
    M² − 2E I2 = I3(I3−I2)ω3² − I1(I2−I1)ω1²      (sign picks the regime)

Each is evaluated from the components (no cancellation between ``M²`` and ``2E I_k``).

*Regime* ``M² ≥ 2E I2`` (polhode circles axis 3): ``ω1 = a cn u``, ``ω2 = b sn u``, ``ω3 = c dn u`` with
``u = λ t + u0`` and

    a² = (2E I3 − M²)/(I1(I3−I1)),  b² = (2E I3 − M²)/(I2(I3−I2)),  c² = (M² − 2E I1)/(I3(I3−I1)),
    λ² = (I3−I2)(M² − 2E I1)/(I1 I2 I3),  m = (I2−I1)(2E I3 − M²)/((I3−I2)(M² − 2E I1)),
    1 − m = (I3−I1)(M² − 2E I2)/((I3−I2)(M² − 2E I1)).

*Regime* ``M² < 2E I2`` (polhode circles axis 1): the same formulas after relabelling the axes by the proper
rotation ``C = [[0,0,1],[0,−1,0],[1,0,0]]`` (``I' = (I3, I2, I1)``); all the ratios above stay positive, and
Euler's equations (4.27) then need ``ω2 = −b sn u`` (the differences ``I'3 − I'2`` etc. change sign).
The sign of ``ω3`` (``dn > 0``) is handled by the symmetry ``diag(−1, 1, −1)`` of Euler's equations, the
separatrix ``M² = 2E I2`` (``m = 1``: ``sn = tanh``, ``cn = dn = sech``) also by ``diag(−1, −1, 1)``.

*Precession* about ``L`` (LL §37): ``ψ̇ = M (I1ω1² + I2ω2²)/(I1²ω1² + I2²ω2²)
= M/I3 + M (I3−I1)/(I1 I3) / (1 − n sn² u)`` with ``n = −I3(I2−I1)/(I1(I3−I2))``, so
``ψ(t) = M t/I3 + M (I3−I1)/(I1 I3 λ) [Π(n; am u) − Π(n; am u0)]`` where whole half-periods of ``sn`` add
``2Π(n|m)`` each (counted, not integrated).

Symmetric bodies (``I1 = I2`` or ``I2 = I3``, symmetry axis ``k``, transverse moment ``I⊥``) and steady spins
about a principal axis use ``Q(t) = Rot(L̂, M t/I⊥) Q0 Rot(e_k, (1/I_k − 1/I⊥) L_k t)``: in the body the
angular velocity precesses about the symmetry axis at ``Ω = ω3 (I3 − I1)/I1`` (§4.4.1).  Spherical bodies
turn uniformly about the fixed ω.
"""

from __future__ import annotations



import numpy as np

from ..values import frozen_value
from ..errors import UsageError
from ..rotations import matrix_to_quaternion, quaternion_multiply, quaternion_to_matrix, \
    rotation_vector_to_quaternion
from .elliptic import complete_k, elliptic_f_from_sn_cn, elliptic_pi_of_argument, jacobi_sn_cn_dn

__all__ = ["ELLIPTIC_M1_FLOOR", "FreeBodyParameters", "free_body_parameters", "torque_free_motion", "precession_angle",
           "FREE_CASES"]

#: Names of the closed forms :func:`torque_free_motion` may use.
FREE_CASES = ("spherical", "axisymmetric", "principal-axis spin", "elliptic", "separatrix")

#: Off-axis components below this fraction of |ω| are treated as zero (their squares would underflow in the
#: invariants); the state is then a steady spin about a principal axis.
NEGLIGIBLE_COMPONENT = 1e-150

#: Below this ``1 − m`` (a state within ~1e-5 of the intermediate axis, or of the separatrix) the
#: closed-form orientation loses accuracy: near the quarter period ``cn u`` is small and the precession
#: integral Π inherits round-off amplified by about ``1/√(1 − m)`` (measured: orientation error ≈
#: 6e-17/√(1 − m) over a few periods, so 6e-12 at this floor; ω(t) itself stays exact).
#: ``simulate(method="auto")`` integrates such states numerically instead.
ELLIPTIC_M1_FLOOR = 1e-10

_RELABEL = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
_FLIP_13 = np.diag([-1.0, 1.0, -1.0])
_FLIP_12 = np.diag([-1.0, -1.0, 1.0])


@frozen_value
class FreeBodyParameters:
    """Constants of the elliptic (Landau–Lifshitz §37) solution for one initial state.

    Attributes
    ----------
    case : str
        One of :data:`FREE_CASES`.
    moments : (3,) float
        Principal moments ``I1 ≤ I2 ≤ I3``, kg·m².
    energy : float
        Kinetic energy ``E = ½ Σ I_i ω_i²``, J.
    angular_momentum : float
        ``M = |L|``, kg·m²/s.
    circled_axis : int
        Principal axis index (0 or 2) the polhode circles (``2`` when ``M² ≥ 2E I2``); ``-1`` if not elliptic.
    parameter, complementary_parameter : float
        ``m = k²`` and ``1 − m`` (nan outside the elliptic/separatrix cases).
    rate : float
        ``λ``, rad/s: ``u = λ t + u0`` (nan outside the elliptic/separatrix cases).
    quarter_period : float
        ``K(m)`` (inf on the separatrix, nan outside the elliptic case).
    period : float
        Period of ω(t), ``4K/λ`` s (inf on the separatrix); for symmetric bodies ``2π/|Ω|``; nan otherwise.
    """

    case: str
    moments: np.ndarray
    energy: float
    angular_momentum: float
    circled_axis: int
    parameter: float
    complementary_parameter: float
    rate: float
    quarter_period: float
    period: float

    @property
    def flip_time(self) -> float:
        """Half period ``2K(m)/λ`` s: the time between reversals of ω2 (the Dzhanibekov flip)."""
        return 2.0 * self.quarter_period / self.rate


def _check_inputs(moments, angular_velocity):
    moments = np.asarray(moments, dtype=np.float64)
    w = np.asarray(angular_velocity, dtype=np.float64)
    if moments.shape != (3,):
        raise UsageError(f"Expected `moments` to have shape (3,), got {moments.shape}")
    if w.shape != (3,):
        raise UsageError(f"Expected `angular_velocity` to have shape (3,), got {w.shape}")
    if not (np.all(np.isfinite(moments)) and np.all(np.isfinite(w))):
        raise UsageError("Expected finite `moments` and `angular_velocity`")
    if not (moments[0] > 0 and moments[0] <= moments[1] <= moments[2]):
        raise UsageError(f"Expected positive ascending principal moments I1 <= I2 <= I3, got {moments.tolist()}")
    return moments, w


def _classify(moments, w) -> str:
    i1, i2, i3 = moments
    if i1 == i3:
        return "spherical"
    if i1 == i2 or i2 == i3:
        return "axisymmetric"
    if np.count_nonzero(np.abs(w) > NEGLIGIBLE_COMPONENT * np.max(np.abs(w))) <= 1:
        return "principal-axis spin"
    return "elliptic"


def _canonical(moments, w):
    """Proper signed permutation ``P`` (ω_c = P ω) putting the state in the canonical regime of the module
    docstring, the relabelled moments and the canonical ω."""
    i1, i2, i3 = moments
    g = i3 * (i3 - i2) * w[2] ** 2 - i1 * (i2 - i1) * w[0] ** 2
    p = np.eye(3) if g >= 0.0 else _RELABEL.copy()
    ic = np.diag(p @ np.diag(moments) @ p.T).copy()
    wc = p @ w
    if wc[2] < 0.0:
        p = _FLIP_13 @ p
        wc = _FLIP_13 @ wc
    return p, ic, wc


def _elliptic_constants(ic, wc):
    j1, j2, j3 = ic
    w1, w2, w3 = wc
    k0 = j1 * (j3 - j1) * w1 ** 2 + j2 * (j3 - j2) * w2 ** 2          # 2E I3 − M²
    k1 = j2 * (j2 - j1) * w2 ** 2 + j3 * (j3 - j1) * w3 ** 2          # M² − 2E I1
    g = j3 * (j3 - j2) * w3 ** 2 - j1 * (j2 - j1) * w1 ** 2           # M² − 2E I2
    a = np.sqrt(k0 / (j1 * (j3 - j1)))
    b = np.sqrt(k0 / (j2 * (j3 - j2)))
    c = np.sqrt(k1 / (j3 * (j3 - j1)))
    lam = np.sqrt((j3 - j2) * k1 / (j1 * j2 * j3))
    m = (j2 - j1) * k0 / ((j3 - j2) * k1)
    m1 = max((j3 - j1) * g / ((j3 - j2) * k1), 0.0)
    if m1 < 0.5:
        m = 1.0 - m1
    else:
        m1 = 1.0 - m
    return a, b, c, lam, min(max(m, 0.0), 1.0), m1


def free_body_parameters(moments, angular_velocity) -> FreeBodyParameters:
    """Constants of the exact torque-free solution (see the module docstring for the formulas).

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments ``I1 ≤ I2 ≤ I3``, kg·m².
    angular_velocity : (3,) array_like
        Body angular velocity in the principal frame, rad/s.

    Returns
    -------
    FreeBodyParameters
    """
    moments, w = _check_inputs(moments, angular_velocity)
    energy = 0.5 * float(np.sum(moments * w * w))
    mom = float(np.linalg.norm(moments * w))
    case = _classify(moments, w)
    nan = float("nan")
    if case in ("spherical", "principal-axis spin"):
        return FreeBodyParameters(case, moments, energy, mom, -1, nan, nan, nan, nan, nan)
    if case == "axisymmetric":
        k, i_perp = (2, moments[0]) if moments[0] == moments[1] else (0, moments[2])
        omega = abs(w[k] * (moments[k] - i_perp) / i_perp)
        period = 2.0 * np.pi / omega if omega > 0 else float("inf")
        return FreeBodyParameters(case, moments, energy, mom, k, nan, nan, omega, nan, period)
    p, ic, wc = _canonical(moments, w)
    _, _, _, lam, m, m1 = _elliptic_constants(ic, wc)
    circled = 2 if p[2, 2] != 0 else 0
    if m1 == 0.0:
        return FreeBodyParameters("separatrix", moments, energy, mom, circled, m, m1, lam, float("inf"),
                                  float("inf"))
    kk = complete_k(m1)
    return FreeBodyParameters("elliptic", moments, energy, mom, circled, m, m1, lam, kk, 4.0 * kk / lam)


def _rotations_about(axis, angles) -> np.ndarray:
    """Quaternions (N, 4) of active rotations by ``angles`` (N,) about the unit ``axis`` (3,)."""
    return rotation_vector_to_quaternion(np.asarray(angles)[:, None] * axis[None, :])


def _axisymmetric_motion(moments, w, tau, q0, k, i_perp):
    """``Q(t) = Rot(L̂, M t/I⊥) Q0 Rot(e_k, β t)``, ``β = (1/I_k − 1/I⊥) L_k``; ``ω(t) = Rot(e_k, −β t) ω0``."""
    big_l_body = moments * w
    big_l_space = quaternion_to_matrix(q0) @ big_l_body
    mom = np.linalg.norm(big_l_space)
    axis_k = np.zeros(3)
    axis_k[k] = 1.0
    beta = (1.0 / moments[k] - 1.0 / i_perp) * big_l_body[k]
    q_body = _rotations_about(axis_k, beta * tau)
    if mom > 0:
        q_space = _rotations_about(big_l_space / mom, mom * tau / i_perp)
        q = quaternion_multiply(quaternion_multiply(q_space, q0), q_body)
    else:
        q = quaternion_multiply(np.broadcast_to(q0, q_body.shape), q_body)
    omega = np.einsum("nji,j->ni", quaternion_to_matrix(q_body), w)  # Rot(e_k, βt)ᵀ ω0
    return omega, q


def _nodal_frames(big_l):
    """Rotations ``W`` (N, 3, 3) with ``W L = |L| e_z``: rows ``(L2, −L1, 0)/√(L1² + L2²)``, ``L̂ × row1``,
    ``L̂`` (the Euler-angle frame of LL §37 with ``L`` along z)."""
    mom = np.linalg.norm(big_l, axis=-1, keepdims=True)
    row3 = big_l / mom
    perp = np.hypot(big_l[:, 0], big_l[:, 1])[:, None]
    row1 = np.stack([big_l[:, 1], -big_l[:, 0], np.zeros(len(big_l))], -1) / perp
    row2 = np.cross(row3, row1)
    return np.stack([row1, row2, row3], -2)


def _precession(ic, wc, tau, u, u0, lam, m, m1):
    """ψ(t) − ψ(0) = M τ/I3 + M (I3 − I1)/(I1 I3 λ) [Π(n; am u) − Π(n; am u0)] (canonical labels)."""
    j1, j2, j3 = ic
    mom = float(np.linalg.norm(ic * wc))
    n = -j3 * (j2 - j1) / (j1 * (j3 - j2))
    big_pi = elliptic_pi_of_argument(u, n, m, m1) - elliptic_pi_of_argument(np.array([u0]), n, m, m1)[0]
    return mom * tau / j3 + mom * (j3 - j1) / (j1 * j3 * lam) * big_pi


def precession_angle(moments, angular_velocity, t):
    """Angle ψ(t) − ψ(t[0]) turned about ``L`` by the nodal frame of LL §37 (elliptic and separatrix cases).

    ``ψ̇ = M (I_a ω_a² + I_b ω_b²) / (I_a² ω_a² + I_b² ω_b²)`` where ``a, b`` are the two principal axes other
    than the one the polhode circles (:attr:`FreeBodyParameters.circled_axis`), evaluated in closed form
    (module docstring).  Exposed for verification against quadrature.

    Parameters
    ----------
    moments : (3,) array_like
        Distinct principal moments, ascending, kg·m².
    angular_velocity : (3,) array_like
        Principal-frame angular velocity at ``t[0]``, rad/s (not along a principal axis).
    t : (N,) array_like
        Times, s.

    Returns
    -------
    (N,) float, rad
    """
    moments, w = _check_inputs(moments, angular_velocity)
    if _classify(moments, w) != "elliptic":
        raise UsageError("precession_angle needs distinct moments and ω off the principal axes")
    tau = np.asarray(t, dtype=np.float64) - float(np.asarray(t, dtype=np.float64).ravel()[0])
    p, ic, wc = _canonical(moments, w)
    a, b, _, lam, m, m1 = _elliptic_constants(ic, wc)
    if m1 == 0.0 and wc[0] < 0.0:
        wc = _FLIP_12 @ wc
    sigma = 1.0 if ic[2] > ic[1] else -1.0
    u0 = elliptic_f_from_sn_cn(sigma * wc[1] / b, wc[0] / a, m, m1)
    return _precession(ic, wc, tau, lam * tau + u0, u0, lam, m, m1)


def _elliptic_motion(moments, w, tau, q0):
    p, ic, wc = _canonical(moments, w)
    a, b, c, lam, m, m1 = _elliptic_constants(ic, wc)
    sep = m1 == 0.0
    if sep and wc[0] < 0.0:
        p, wc = _FLIP_12 @ p, _FLIP_12 @ wc
    sigma = 1.0 if ic[2] > ic[1] else -1.0  # relabelled regime: ω2 = −b sn u (Euler's equations' signs)
    u0 = elliptic_f_from_sn_cn(sigma * wc[1] / b, wc[0] / a, m, m1)
    u = lam * tau + u0
    sn, cn, dn = jacobi_sn_cn_dn(u, m, m1)
    omega_c = np.stack([a * cn, sigma * b * sn, c * dn], -1)
    omega_c[tau == 0.0] = wc  # the exact initial state (removes round-off of the inversion)
    psi = _precession(ic, wc, tau, u, u0, lam, m, m1)
    frames = _nodal_frames(omega_c * ic)
    w0_frame = _nodal_frames((ic * wc)[None, :])[0]
    cz, sz, zero, one = np.cos(psi), np.sin(psi), np.zeros_like(psi), np.ones_like(psi)
    rz = np.stack([np.stack([cz, -sz, zero], -1), np.stack([sz, cz, zero], -1),
                   np.stack([zero, zero, one], -1)], -2)
    q0m = quaternion_to_matrix(q0)
    q_mat = (q0m @ p.T @ w0_frame.T) @ rz @ frames @ p
    return omega_c @ p, matrix_to_quaternion(q_mat), ("separatrix" if sep else "elliptic")


def torque_free_motion(moments, angular_velocity, t, *, orientation=None):
    """Exact motion of a torque-free rigid body from its principal moments and initial state.

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments ``I1 ≤ I2 ≤ I3``, kg·m² (exactly equal values select the symmetric closed forms).
    angular_velocity : (3,) array_like
        Body angular velocity at ``t[0]``, principal frame, rad/s.
    t : (N,) array_like
        Increasing times, s; the initial state holds at ``t[0]``.
    orientation : (4,) array_like, optional
        Scalar-first unit quaternion of the principal frame → space rotation at ``t[0]``; default identity.

    Returns
    -------
    angular_velocity : (N, 3) float
        Principal frame, rad/s.
    orientation : (N, 4) float
        Scalar-first quaternions (``w ≥ 0``) of principal frame → space.
    case : str
        Which closed form was used (:data:`FREE_CASES`).
    """
    moments, w = _check_inputs(moments, angular_velocity)
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise UsageError(f"Expected `t` to be a non-empty finite 1-D array, got shape {t.shape}")
    q0 = np.array([1.0, 0.0, 0.0, 0.0]) if orientation is None else np.asarray(orientation, dtype=np.float64)
    if q0.shape != (4,) or not np.all(np.isfinite(q0)) or np.linalg.norm(q0) == 0:
        raise UsageError(f"Expected `orientation` to be a finite non-zero quaternion of shape (4,), got {q0}")
    q0 = q0 / np.linalg.norm(q0)
    # Scale invariance ω(t; c ω0) = c ω(c t; ω0), Q(t; c ω0) = Q(c t; ω0): solve with max |ω0| = 1 so no
    # square of a component under- or overflows.
    scale = float(np.max(np.abs(w)))
    if scale > 0.0:
        w = w / scale
    tau = (t - t[0]) * (scale if scale > 0.0 else 1.0)
    case = _classify(moments, w)
    if case == "spherical":
        omega, q = _axisymmetric_motion(moments, w, tau, q0, 2, moments[2])
    elif case == "principal-axis spin":
        k = int(np.argmax(np.abs(w)))
        w = np.where(np.arange(3) == k, w, 0.0)
        omega, q = _axisymmetric_motion(moments, w, tau, q0, k, moments[k])
    elif case == "axisymmetric":
        k, i_perp = (2, moments[0]) if moments[0] == moments[1] else (0, moments[2])
        omega, q = _axisymmetric_motion(moments, w, tau, q0, k, i_perp)
    else:
        omega, q, case = _elliptic_motion(moments, w, tau, q0)
    q = np.where(q[:, :1] < 0, -q, q)
    return omega * (scale if scale > 0.0 else 1.0), q, case
