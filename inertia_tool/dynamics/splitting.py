"""Splitting integrator for torques that depend on time and orientation only: exact free flow + torque kicks.

The motion with torque (Euler's equations, Eq. 4.26; Eq. 4.27 in principal axes, plus ``Q̇ = Q [ω]×``) is
the sum of two vector fields, each solved exactly:

* **A, the free rigid body** (``τ = 0``): ``I ω̇ = (I ω) × ω``, ``Q̇ = Q [ω]×`` — the closed form of
  Landau–Lifshitz §37 / Celledoni, Fassò, Säfström & Zanna (2008), one step by
  :func:`.free_flow.free_flow_step`.  It advances the time.
* **B, the kick** (orientation and time frozen): ``I ω̇ = τ(t, Q)``.  With ``Q`` frozen the torque is constant,
  so ``L_space ← L_space + h τ_space`` — in body axes ``ω ← ω + h I⁻¹ τ_body(t, Q)`` — is exact.  This needs
  a torque that does **not** depend on ω (gravity, gravity gradient, a magnetic dipole in a field, springs
  on orientation); an ω-dependent torque would make B itself an ODE.

A symmetric composition ``e^{b1 h B} e^{a1 h A} e^{b2 h B} … e^{a1 h A} e^{b1 h B}`` of these exact flows is
the integrator.  It is a composition of exact flows of two Lie–Poisson vector fields, so it is a Poisson map
of the Lie–Poisson/canonical structure on T*SO(3) (symplectic), preserves ``|q| = 1`` exactly (both flows are
rotations of ``Q``), is time-symmetric, and conserves ``|L|`` across the free parts; for a conservative torque
``τ = −∂V`` it has no secular drift in the total energy ``½ ω·Iω + V(Q)`` (Hairer, Lubich & Wanner, *Geometric
Numerical Integration*, 2nd ed., §IX.8).  With a time-dependent torque the kick uses the stage time (the
drifts advance ``t``), which is the standard extension (time as a coordinate moved by A).

*Order.*  Because A is linear in ω in the kinematics and quadratic in ω in Euler's equations while B does not
depend on ω, ``[B, [B, [B, A]]] = 0`` (grade A as +1 and B as −1 in powers of ω: that bracket would have
grade −2, impossible for a polynomial field).  So the Runge–Kutta–Nyström order conditions apply and the
optimised SRKN schemes of Blanes & Moan, "Practical symplectic partitioned Runge–Kutta and Runge–Kutta–Nyström
methods", *J. Comput. Appl. Math.* 142 (2002) 313–330, Table 3, reach order 4 with 6 and order 6 with 11 torque
evaluations per step (the last kick of a step and the first of the next share one evaluation).  Orders are
verified numerically in ``tests/test_dynamics_splitting.py``.

*Error.*  The local error is a sum of nested commutators each containing B at least once, so it is
proportional to the torque: ``O(h^{p+1} ‖τ‖ ‖ω‖^p)``-type terms, with no term from the free motion alone.  When
the torque is weak compared to the spin (``‖τ‖/(I ω²)`` small), the step can be much longer than the spin
period — an explicit method must resolve the spin.  When the torque is strong (its time scale ``√(I/‖∂τ/∂Q‖)``
comparable to the spin period or shorter), there is no such advantage and a general-purpose integrator with
error control (``method="numerical"``) can be as good per unit work.

*Step size.*  Within each interval between requested output times the step is constant and divides the
interval exactly (outputs are steps, never interpolants).  The nominal step comes from a step-doubling error
estimate (one step ``h`` against two of ``h/2``, which are then discarded: the global error of a symplectic
method stays small only while the step is constant) taken on the first step and every ``probe_every`` steps
after it, scaled RMS norm ``atol + rtol·|y|`` over ``(ω, q)`` as in :mod:`.integrate`, new
``h = h·clip(0.9 err^{−1/(p+1)}, 0.2, 4)``; a probed step that fails the tolerance is redone with the smaller
step.  The estimate is of the *local* error; the global error of a long run is larger (as for any
integrator, and as ``rtol``/``atol`` of :mod:`.integrate`).  ``max_step`` bounds it; ``step`` fixes it (no error
control).

*Implementation.*  The steps between output times and probes run as one call of the C kernel
``_accel.split_steps`` (``_accel.c``, section 7: the free flow's closed form with its own AGM and Carlson
functions, the frame change and the torque calls in one loop, ~1.5 µs per stage plus the torque against
~28 µs here) when :func:`~inertia_tool._native.accel` provides it, else as :func:`_python_steps`; the two agree
to round-off.  ``benchmarks/bench_integrator.py`` measures both against DOP853 (``docs/dynamics.md``).
"""

from __future__ import annotations

import math


import numpy as np

from ..values import frozen_value
from ..errors import NonFiniteResultError, PhysicsError, UsageError
from ..rotations import matrix_to_quaternion
from .._native import accel
from .free_flow import NEAR_SEPARATRIX_M1, free_flow_step
from .torque_free import NEGLIGIBLE_COMPONENT

__all__ = ["SplittingScheme", "SCHEMES", "DEFAULT_SCHEME", "integrate_splitting"]


@frozen_value
class SplittingScheme:
    """A symmetric composition ``e^{b1 h B} e^{a1 h A} … e^{a_s h A} e^{b_{s+1} h B}`` (kick first and last).

    Attributes
    ----------
    name : str
        Key in :data:`SCHEMES`.
    order : int
        Order ``p`` (local error ``O(h^{p+1})``) for torques that depend on time and orientation only.
    drifts : tuple of float
        ``a_i``: fractions of ``h`` for the exact free flows (sum 1).
    kicks : tuple of float
        ``b_i``: fractions of ``h`` for the kicks (``len(drifts) + 1`` values, sum 1).
    source : str
        Where the coefficients come from.
    """

    name: str
    order: int
    drifts: tuple
    kicks: tuple
    source: str


def _strang_composition(weights):
    """Kick/drift coefficients of ``S(w_1 h) … S(w_r h)`` with ``S`` the kick-drift-kick Strang splitting."""
    drifts = tuple(weights)
    kicks = [0.5 * weights[0]]
    for left, right in zip(weights[:-1], weights[1:]):
        kicks.append(0.5 * (left + right))
    kicks.append(0.5 * weights[-1])
    return drifts, tuple(kicks)


def _blanes_moan_4():
    b1, b2, b3 = 0.0829844064174052, 0.396309801498368, -0.0390563049223486
    a1, a2 = 0.245298957184271, 0.604872665711080
    a3 = 0.5 - (a1 + a2)
    b4 = 1.0 - 2.0 * (b1 + b2 + b3)
    return (a1, a2, a3, a3, a2, a1), (b1, b2, b3, b4, b3, b2, b1)


def _blanes_moan_6():
    b = [0.0414649985182624, 0.198128671918067, -0.0400061921041533, 0.0752539843015807, -0.0115113874206879]
    a = [0.123229775946271, 0.290553797799558, -0.127049212625417, -0.246331761062075, 0.357208872795928]
    b.append(0.5 - sum(b))
    a_mid = 1.0 - 2.0 * sum(a)
    return tuple(a + [a_mid] + a[::-1]), tuple(b + b[::-1])


def _yoshida_4():
    cube = 2.0 ** (1.0 / 3.0)
    outer = 1.0 / (2.0 - cube)
    return _strang_composition([outer, -cube * outer, outer])


def _yoshida_6():
    w1, w2, w3 = -1.17767998417887, 0.235573213359357, 0.784513610477560
    w0 = 1.0 - 2.0 * (w1 + w2 + w3)
    return _strang_composition([w3, w2, w1, w0, w1, w2, w3])


def _scheme(name, order, maker, source):
    drifts, kicks = maker()
    return SplittingScheme(name, order, drifts, kicks, source)


#: Available compositions, by name.
SCHEMES = {s.name: s for s in (
    _scheme("strang", 2, lambda: _strang_composition([1.0]), "Strang (1968); kick-drift-kick"),
    _scheme("yoshida4", 4, _yoshida_4, "Yoshida, Phys. Lett. A 150 (1990) 262, triple jump (Eq. 5.19)"),
    _scheme("yoshida6", 6, _yoshida_6, "Yoshida, Phys. Lett. A 150 (1990) 262, Table 1 solution A"),
    _scheme("blanes-moan4", 4, _blanes_moan_4,
            "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 3, SRKN_6^b"),
    _scheme("blanes-moan6", 6, _blanes_moan_6,
            "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313, Table 3, SRKN_11^b"),
)}

#: Scheme used by default: order 6, 11 torque evaluations and 11 exact free flows per step.
DEFAULT_SCHEME = "blanes-moan6"

_Q_IDENTITY = (1.0, 0.0, 0.0, 0.0)


def _quat_mul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw)


def _make_torque(torque, axes):
    """``τ_principal(t, q_principal, ω_principal)`` from the caller's mesh-axes ``torque(t, q_mesh, ω_mesh)``
    (``q_mesh = q_principal ⊗ q_axes⁻¹``, ``ω_mesh = axes ω``, ``τ_principal = axesᵀ τ_mesh``)."""
    if np.array_equal(axes, np.eye(3)):
        def identity_frame(t, q, w):
            tau = torque(t, np.array(q), np.array(w))
            return float(tau[0]), float(tau[1]), float(tau[2])
        return identity_frame
    qa = matrix_to_quaternion(axes).tolist()
    qa_inv = (qa[0], -qa[1], -qa[2], -qa[3])
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = axes.tolist()

    def rotated_frame(t, q, w):
        w0, w1, w2 = w
        w_mesh = np.array([a00 * w0 + a01 * w1 + a02 * w2, a10 * w0 + a11 * w1 + a12 * w2,
                           a20 * w0 + a21 * w1 + a22 * w2])
        tau = torque(t, np.array(_quat_mul(q, qa_inv)), w_mesh)
        t0, t1, t2 = float(tau[0]), float(tau[1]), float(tau[2])
        return a00 * t0 + a10 * t1 + a20 * t2, a01 * t0 + a11 * t1 + a21 * t2, a02 * t0 + a12 * t1 + a22 * t2
    return rotated_frame


def _composition_step(scheme, moments, torque_p, t, w, q, tau, h):
    """One step of the composition from ``(t, ω, q)`` with ``tau`` = torque at ``(t, q)`` (principal frame).

    Returns ``(ω, q, τ at the end)``; the end torque is the next step's first (FSAL)."""
    i1, i2, i3 = moments
    w0, w1, w2 = w
    drifts, kicks = scheme.drifts, scheme.kicks
    time = t
    for index, a in enumerate(drifts):
        hb = kicks[index] * h
        w0 += hb * tau[0] / i1
        w1 += hb * tau[1] / i2
        w2 += hb * tau[2] / i3
        (w0, w1, w2), q = free_flow_step(moments, (w0, w1, w2), q, a * h)
        time += a * h
        if torque_p is not None:
            tau = torque_p(time, q, (w0, w1, w2))
            if not (math.isfinite(tau[0]) and math.isfinite(tau[1]) and math.isfinite(tau[2])):
                raise FloatingPointError(f"the torque is not finite at t = {time!r} s: {tau}")
    hb = kicks[-1] * h
    w0 += hb * tau[0] / i1
    w1 += hb * tau[1] / i2
    w2 += hb * tau[2] / i3
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])  # round-off only
    return (w0, w1, w2), (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm), tau


def _python_steps(scheme, moments, torque_p, t, w, q, tau, h, count):
    """``count`` composition steps of length ``h`` from time ``t`` (step ``k`` starts at ``t + k h``).

    The pure-Python twin of the C kernel ``_accel.split_steps`` (same arithmetic; the special functions are
    scipy's here and the C file's own there, so results agree to round-off)."""
    for k in range(count):
        w, q, tau = _composition_step(scheme, moments, torque_p, t + k * h, w, q, tau, h)
    return w, q, tau


def _steps_function(scheme, moments, torque, axes, torque_p):
    """``steps(t, w, q, tau, h, count) -> (w, q, tau)``: the C kernel ``_accel.split_steps`` when
    :func:`~inertia_tool._native.accel` has it (it calls the caller's mesh-axes ``torque`` itself, with the
    frame change of :func:`_make_torque`), else :func:`_python_steps` with the wrapped ``torque_p``."""
    kernel = accel()
    if kernel is None or not hasattr(kernel, "split_steps"):
        def python_steps(t, w, q, tau, h, count):
            return _python_steps(scheme, moments, torque_p, t, w, q, tau, h, count)
        return python_steps
    c_steps = kernel.split_steps
    drifts, kicks = tuple(scheme.drifts), tuple(scheme.kicks)
    if np.array_equal(axes, np.eye(3)):
        frame = None
    else:
        qa = matrix_to_quaternion(axes).tolist()
        frame = (tuple(axes.ravel().tolist()), (qa[0], -qa[1], -qa[2], -qa[3]))
    q_proto, w_proto = np.zeros(4), np.zeros(3)

    def compiled_steps(t, w, q, tau, h, count):
        return c_steps(moments, drifts, kicks, w, q, tau, t, h, count, torque, frame, q_proto, w_proto,
                       NEGLIGIBLE_COMPONENT, NEAR_SEPARATRIX_M1, free_flow_step)
    return compiled_steps


def _error_norm(w_big, q_big, w_fine, q_fine, w_old, q_old, rtol, atol):
    total = 0.0
    for big, fine, old in zip(w_big + q_big, w_fine + q_fine, w_old + q_old):
        scale = atol + rtol * max(abs(fine), abs(old))
        total += ((big - fine) / scale) ** 2
    return math.sqrt(total / 7.0)


def integrate_splitting(moments, axes, angular_velocity, orientation, t, torque, *, scheme: str = DEFAULT_SCHEME,
                        rtol: float = 1e-12, atol: float = 1e-12, max_step: float | None = None,
                        step: float | None = None, probe_every: int = 32, max_steps: int = 1_000_000):
    """Integrate the motion under a torque ``τ(t, Q)`` by composing the exact free flow with torque kicks.

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments ``I1 ≤ I2 ≤ I3``, kg·m².
    axes : (3, 3) array_like
        Principal axes as columns in mesh axes (proper rotation, principal → mesh components).
    angular_velocity : (3,) array_like
        Body angular velocity at ``t[0]``, **mesh axes**, rad/s.
    orientation : (4,) array_like
        Scalar-first unit quaternion of body (mesh axes) → space at ``t[0]``.
    t : (N,) array_like
        Strictly increasing output times, s.
    torque : callable or None
        ``torque(t, orientation (4,), angular_velocity (3,)) -> (3,)`` N·m in **mesh axes**, depending on time
        and orientation only (the angular velocity is passed but must not change the result).
    scheme : str
        Key of :data:`SCHEMES` (default ``"blanes-moan6"``, order 6).
    rtol, atol : float
        Local error tolerance per step (scaled RMS over ``ω`` in rad/s and ``q``), for the step-doubling
        estimate of the module docstring.
    max_step : float, optional
        Upper bound on the step, s.
    step : float, optional
        Fixed nominal step, s (no error control; each output interval is divided into
        ``ceil(Δt/step)`` equal steps).
    probe_every : int
        Steps between step-doubling error estimates (the first step is always probed).
    max_steps : int
        Bound on steps (including rejected probes); :class:`~inertia_tool.errors.PhysicsError` beyond it.

    Returns
    -------
    angular_velocity : (N, 3) float
        Mesh axes, rad/s.
    orientation : (N, 4) float
        Unit quaternions of body (mesh axes) → space.
    steps : int
        Composition steps taken (probe comparisons included).

    Raises
    ------
    NonFiniteResultError
        The torque returned infinity or NaN.
    PhysicsError
        More than ``max_steps`` steps.
    """
    if scheme not in SCHEMES:
        raise UsageError(f"Expected `scheme` in {tuple(SCHEMES)}, got {scheme!r}")
    if not (rtol > 0 and atol > 0):
        raise UsageError(f"Expected positive `rtol` and `atol`, got {rtol}, {atol}")
    for name, value in (("max_step", max_step), ("step", step)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise UsageError(f"Expected a positive finite `{name}`, got {value}")
    if int(probe_every) < 1:
        raise UsageError(f"Expected `probe_every` >= 1, got {probe_every}")
    plan = SCHEMES[scheme]
    axes = np.asarray(axes, dtype=np.float64)
    moments_t = tuple(float(x) for x in moments)
    times = np.asarray(t, dtype=np.float64)
    torque_p = _make_torque(torque, axes) if torque is not None else None
    steps_function = _steps_function(plan, moments_t, torque, axes, torque_p)

    def advance(t_start, w_start, q_start, tau_start, h_step, count):
        try:
            return steps_function(t_start, w_start, q_start, tau_start, h_step, count)
        except FloatingPointError as exc:  # raised by either path for a non-finite torque
            raise NonFiniteResultError(f"{exc}; the splitting integration cannot continue") from None

    w = tuple((axes.T @ np.asarray(angular_velocity, dtype=np.float64)).tolist())
    qa = matrix_to_quaternion(axes).tolist()
    q_mesh = np.asarray(orientation, dtype=np.float64)
    q = _quat_mul(tuple((q_mesh / np.linalg.norm(q_mesh)).tolist()), tuple(qa))  # principal → space
    t_now = float(times[0])
    tau = torque_p(t_now, q, w) if torque_p is not None else (0.0, 0.0, 0.0)
    NonFiniteResultError.check(f"the torque at t = {t_now!r} s", tau, because="it is not finite")
    span = float(times[-1] - times[0])
    h_nominal = step if step is not None else (max_step if max_step is not None else max(span, 1e-300))
    if max_step is not None:
        h_nominal = min(h_nominal, max_step)
    exponent = 1.0 / (plan.order + 1)
    out_w = np.empty((len(times), 3))
    out_q = np.empty((len(times), 4))
    out_w[0], out_q[0] = w, q
    steps = 0
    since_probe = probe_every  # probe on the first step
    for index in range(1, len(times)):
        target = float(times[index])
        while True:
            remaining = target - t_now
            if remaining <= 0.0:
                break
            count = max(1, math.ceil(remaining / h_nominal * (1.0 - 1e-12)))
            h = remaining / count
            if steps >= max_steps:
                raise PhysicsError(f"Splitting integration needed more than max_steps={max_steps} steps "
                                   f"by t={t_now:g} s")
            if step is not None or since_probe < probe_every:
                batch = count if step is not None else min(count, probe_every - since_probe)
                batch = min(batch, max_steps - steps)
                w, q, tau = advance(t_now, w, q, tau, h, batch)
                steps += batch
                since_probe += batch
                t_now = target if batch == count else t_now + batch * h
                continue
            w_big, q_big, tau_big = advance(t_now, w, q, tau, h, 1)
            w_fine, q_fine, _ = advance(t_now, w, q, tau, 0.5 * h, 2)
            steps += 3
            if q_big[0] * q_fine[0] + q_big[1] * q_fine[1] + q_big[2] * q_fine[2] + q_big[3] * q_fine[3] < 0:
                q_fine = tuple(-x for x in q_fine)
            err = _error_norm(w_big, q_big, w_fine, q_fine, w, q, rtol, atol)
            if not math.isfinite(err):
                h_nominal = 0.25 * h
                continue
            factor = min(4.0, max(0.2, 0.9 * err ** -exponent)) if err > 0 else 4.0
            h_nominal = h * factor if max_step is None else min(h * factor, max_step)
            if err <= 1.0:
                # keep the full step, not the two halves: a symplectic method's global error stays small when
                # the step is constant (its modified Hamiltonian does not change); halves would break that
                w, q, tau = w_big, q_big, tau_big
                t_now = target if count == 1 else t_now + h
                since_probe = 1
        out_w[index], out_q[index] = w, q
    qa_inv = np.array([qa[0], -qa[1], -qa[2], -qa[3]])
    q_out = _quat_mul(tuple(out_q.T), tuple(qa_inv))  # principal → space composed with mesh → principal
    return out_w @ axes.T, np.stack(q_out, axis=1), steps
