"""The heavy symmetric top (§4.4.3): nutation limits and period, precession type, sleeping and steady tops.

A symmetric body (moments ``I1 = I2`` transverse, ``I3`` axial, both about the fixed pivot) with its centre
of mass at distance ``l`` along the symmetry axis, in gravity ``g``.  θ is the tilt of the symmetry axis
from the upward vertical, φ its azimuth (precession), ψ the spin angle (z-y-z Euler angles, Eq. 4.31).
The conserved momenta give ``a = I3 ω3 / I1`` and ``b = p_φ / I1 = φ̇ sin²θ + a cos θ``; with ``u = cos θ``
the energy reduces to ``u̇² = f(u) = (1 − u²)(α − β u) − (b − a u)²`` (Eq. 4.40), ``α = 2E'/I1``,
``β = 2 M g l / I1``.  The roots ``u_X ≤ u_N ≤ 1 ≤ u_U`` of the cubic bound the nutation,
``θ_max = acos u_X``, ``θ_min = acos u_N``, and the nutation period is the closed form

    T = 2 ∫_{u_X}^{u_N} du / √f(u) = 4 K(m) / √(β (u_U − u_X)),   m = (u_N − u_X)/(u_U − u_X)

(``K`` the complete elliptic integral of the first kind; cf. exercise 4.10).  φ̇ = (b − a u)/(1 − u²)
(Eq. 4.38) vanishes at ``u' = b/a``, which classifies the path of the axis (Fig. 4.3).

Pure functions on SI numbers.  Units: kg·m², kg, m, rad, rad/s, m/s².
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..values import frozen_value
from ..errors import AsymmetricTopWarning, NonFiniteResultError, PhysicsError, UsageError
from ..mass.properties import MassProperties
from ..tolerances import MAX_TRAJECTORY_SAMPLES
from ..units import STANDARD_GRAVITY          # m/s² (re-exported: the top's default gravity)

__all__ = ["HeavyTopReport", "TopTrajectory", "heavy_top", "heavy_top_on_pivot", "simulate_top", "steady_precession",
           "STANDARD_GRAVITY", "PRECESSION_KINDS"]


#: Labels of ``HeavyTopReport.precession_kind``.
PRECESSION_KINDS = ("looping", "undulating", "cusp", "steady", "planar")


@frozen_value
class HeavyTopReport:
    """Analysis of a heavy symmetric top (§4.4.3).  All angles in rad, rates in rad/s, times in s.

    Attributes
    ----------
    transverse_moment, axial_moment : float
        ``I1`` and ``I3`` about the pivot, kg·m².
    mass, length, gravity : float
        ``M`` kg, pivot-to-centre-of-mass distance ``l`` m, ``g`` m/s².
    theta0, omega3, theta_dot0, phi_dot0 : float
        Initial tilt from the upward vertical, spin ``ω3 = ψ̇ + φ̇ cos θ`` (constant), initial θ̇ and φ̇.
    a, b, alpha, beta : float
        The chapter's constants: ``a = I3 ω3/I1``, ``b = p_φ/I1`` (1/s), ``α = 2E'/I1``, ``β = 2Mgl/I1`` (1/s²).
    roots : (float, float, float)
        ``(u_X, u_N, u_U)``, the roots of ``f(u)`` (Eq. 4.40); ``u_U = inf`` when ``β = 0``.
    theta_min, theta_max : float
        Nutation limits ``acos u_N`` and ``acos u_X``.
    nutation_period : float
        Time for θ to go from θ_max to θ_min and back; ``inf`` if the top creeps towards an unstable
        equilibrium (e.g. an upright top that is spun too slowly).  With no nutation (``u_X = u_N``), the
        period of small nutations about that steady motion.
    precession_kind : str
        Fig. 4.3: ``"looping"`` (φ̇ changes sign: ``u_X < b/a < u_N``), ``"undulating"`` (φ̇ keeps its sign),
        ``"cusp"`` (φ̇ = 0 at θ_min: ``b/a = u_N``, the top released from rest); also ``"steady"`` (no
        nutation, ``u_N − u_X ≤ kind_atol``) and ``"planar"`` (``a = b = 0``: a pendulum swinging in a plane).
    precession_zero_u : float or None
        ``u' = b/a`` where φ̇ vanishes; ``None`` when ``a = 0``.
    sleeping_stable : bool
        Whether the upright spinning top is stable, ``I3² ω3² > 4 I1 M g l`` (§4.4.3 with θ = 0).
    sleeping_margin : float
        ``I3² ω3² / (4 I1 M g l)`` (> 1 for a stable sleeping top); ``inf`` without gravity torque.
    precession_rate_slow, precession_rate_fast : float or None
        Steady precession rates φ̇ at θ0 from ``I1 cos θ φ̇² − I3 ω3 φ̇ + M g l = 0`` (smaller and larger
        magnitude); ``None`` where no real root exists (too little spin) or, for the fast rate, at θ = π/2.
    pivot : (3,) float or None
        The pivot, m, mesh axes (set by :func:`heavy_top_on_pivot`).
    symmetry_axis : (3,) float or None
        Unit vector pivot → centre of mass, mesh axes (set by :func:`heavy_top_on_pivot`).
    transverse_asymmetry : float
        ``(I1b − I1a)/I1`` of the two moments transverse to the symmetry axis about the pivot, plus the
        off-axis coupling ``|I n̂ − I3 n̂|/I1`` (0 for a true symmetric top; set by :func:`heavy_top_on_pivot`).
    """

    transverse_moment: float
    axial_moment: float
    mass: float
    length: float
    gravity: float
    theta0: float
    omega3: float
    theta_dot0: float
    phi_dot0: float
    a: float
    b: float
    alpha: float
    beta: float
    roots: tuple
    theta_min: float
    theta_max: float
    nutation_period: float
    precession_kind: str
    precession_zero_u: float | None
    sleeping_stable: bool
    sleeping_margin: float
    precession_rate_slow: float | None
    precession_rate_fast: float | None
    pivot: np.ndarray | None = None
    symmetry_axis: np.ndarray | None = None
    transverse_asymmetry: float = 0.0

    @property
    def critical_sleeping_spin(self) -> float:
        """Spin ω3 (rad/s) above which the upright top is stable: ``√(4 I1 M g l) / I3``."""
        return math.sqrt(4.0 * self.transverse_moment * self.mass * self.gravity * self.length) / self.axial_moment

    def f(self, u):
        """The cubic ``f(u) = (1 − u²)(α − β u) − (b − a u)²`` of Eq. (4.40), 1/s²; ``u`` array_like."""
        u = np.asarray(u, dtype=np.float64)
        return (1.0 - u * u) * (self.alpha - self.beta * u) - (self.b - self.a * u) ** 2

    def simulate(self, duration: float, *, samples: int = 2001, rtol: float = 1e-10, atol: float = 1e-12):
        """Integrate this top for ``duration`` s; see :func:`simulate_top`."""
        return simulate_top(self, duration, samples=samples, rtol=rtol, atol=atol)


@frozen_value
class TopTrajectory:
    """Motion of the symmetry axis of a heavy top, sampled at ``t``.

    Attributes
    ----------
    t : (N,) float
        s.
    axis : (N, 3) float
        Unit vector of the symmetry axis (pivot → centre of mass), space frame, z up.
    angular_momentum : (N, 3) float
        About the pivot, kg·m²/s, space frame.
    theta, phi : (N,) float
        Tilt from the upward vertical and azimuth (unwrapped) of the axis, rad (Euler angles θ, φ).
    energy : (N,) float
        ``T + U`` in J (a conserved quantity: its drift measures the integration error).
    """

    t: np.ndarray
    axis: np.ndarray
    angular_momentum: np.ndarray
    theta: np.ndarray
    phi: np.ndarray
    energy: np.ndarray

    def measured_nutation_period(self) -> float:
        """Mean interval between upward crossings of the mid-level ``(min θ + max θ)/2``, s (linear
        interpolation between samples); ``nan`` with fewer than two crossings or no visible nutation."""
        lo, hi = float(self.theta.min()), float(self.theta.max())
        if hi - lo <= 1e-9 * max(1.0, hi):
            return math.nan
        crossings = _upward_crossings(self.t, self.theta, 0.5 * (lo + hi))
        return float(np.diff(crossings).mean()) if len(crossings) >= 2 else math.nan

    def measured_precession_rate(self, *, pole_tol: float = 1e-3) -> float:
        """Mean precession rate ``(φ_end − φ_start)/(t_end − t_start)``, rad/s (unwrapped azimuth).

        ``nan`` when the axis comes within ``pole_tol`` (in sin θ) of the vertical: the azimuth φ is undefined
        there (a top hanging still, a pendulum swinging through the vertical) and its unwrapped jumps are
        not a precession.
        """
        if float(np.min(np.abs(np.sin(self.theta)))) < pole_tol:
            return math.nan
        return float((self.phi[-1] - self.phi[0]) / (self.t[-1] - self.t[0]))


def _upward_crossings(t: np.ndarray, y: np.ndarray, level: float) -> np.ndarray:
    """Times where ``y`` crosses ``level`` upwards, linearly interpolated between samples."""
    idx = np.nonzero((y[:-1] < level) & (y[1:] >= level))[0]
    return t[idx] + (level - y[idx]) * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])


def _quadratic_roots(qa: float, qb: float, qc: float) -> tuple[float, float]:
    """Real roots of ``qa x² + qb x + qc`` without cancellation (discriminant clamped at 0)."""
    if qa == 0.0:
        if qb == 0.0:
            return math.nan, math.nan
        return -qc / qb, math.nan
    disc = max(qb * qb - 4.0 * qa * qc, 0.0)
    q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))
    if q == 0.0:
        return 0.0, 0.0
    return q / qa, qc / q


def _cubic_roots(a: float, b: float, alpha: float, beta: float, u0: float, phi_dot0: float, theta_dot0: float,
                 turning: bool, max_doublings: int = 200) -> tuple[float, float, float]:
    """``(u_X, u_N, u_U)`` of Eq. (4.40) for a top starting at ``u0``.

    ``turning`` (θ̇0 = 0 or sin θ0 = 0) means ``u0`` is itself a root; the cubic is then deflated exactly:
    with ``d = u0 − u``, ``s² = 1 − u0²``, ``w = φ̇0``, ``v = θ̇0`` (``v s = 0`` here), ``f = d · g(d)``,
    ``g(d) = −β d² + (2 u0 β − w² s² − a² − v²) d + s² (β + 2 u0 w² − 2 a w) + 2 u0 v²``.
    Otherwise ``f(u0) > 0`` and the roots are bracketed in ``[−1, u0]``, ``[u0, 1]``, ``[1, ∞)``.
    """
    def f(u):
        return (1.0 - u * u) * (alpha - beta * u) - (b - a * u) ** 2

    if turning:
        s2 = 1.0 - u0 * u0
        w = phi_dot0
        v2 = theta_dot0 * theta_dot0
        d1, d2 = _quadratic_roots(-beta, 2.0 * u0 * beta - w * w * s2 - a * a - v2,
                                  s2 * (beta + 2.0 * u0 * w * w - 2.0 * a * w) + 2.0 * u0 * v2)
        others = [u0 - d for d in (d1, d2) if not math.isnan(d)]
        roots = sorted([u0] + others)
        if beta == 0.0:                  # quadratic f: only two finite roots
            return roots[0], roots[1], math.inf
        return roots[0], roots[1], roots[2]
    from scipy.optimize import brentq   # scipy imported on use: keeps `analyze` fast to start
    u_x = brentq(f, -1.0, u0, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500)
    u_n = brentq(f, u0, 1.0, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500)
    if beta == 0.0:
        return u_x, u_n, math.inf
    hi = 2.0
    for _ in range(max_doublings):
        if f(hi) > 0:
            break
        hi *= 2.0
    else:
        raise PhysicsError("could not bracket the unphysical root u_U of Eq. (4.40)")
    u_u = brentq(f, 1.0, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500)
    return u_x, u_n, u_u


def _nutation_period(u_x: float, u_n: float, u_u: float, alpha: float, beta: float, a: float) -> float:
    if beta == 0.0:
        return 2.0 * math.pi / math.sqrt(alpha + a * a)       # f quadratic: harmonic in u
    span = u_u - u_x
    if span <= 0.0:
        return math.inf
    one_minus_m = (u_u - u_n) / span
    if one_minus_m <= 0.0:
        return math.inf
    from .elliptic import complete_k   # scipy.special on first use: `analyze` never needs it
    return 4.0 * complete_k(one_minus_m) / math.sqrt(beta * span)


def steady_precession(i1: float, i3: float, omega3: float, mgl: float,
                      theta: float) -> tuple[float | None, float | None]:
    """Roots φ̇ of ``I1 cos θ φ̇² − I3 ω3 φ̇ + M g l = 0`` (θ-equation of the Lagrangian with θ̇ = θ̈ = 0)."""
    c = math.cos(theta)
    qa, qb, qc = i1 * c, -i3 * omega3, mgl
    if abs(qa) <= 1e-15 * max(abs(qb), abs(qc), 1e-300):
        return (qc / -qb if qb != 0 else None), None
    disc = qb * qb - 4.0 * qa * qc
    if disc < 0:
        return None, None
    r1, r2 = _quadratic_roots(qa, qb, qc)
    slow, fast = sorted((r1, r2), key=abs)
    return slow, fast


def heavy_top(I1: float, I3: float, mass: float, length: float, *, theta0: float, omega3: float,
              theta_dot0: float = 0.0, phi_dot0: float = 0.0, g: float = STANDARD_GRAVITY,
              kind_atol: float = 1e-9) -> HeavyTopReport:
    """Analyse a heavy symmetric top with one point fixed (§4.4.3, Eqs. 4.36–4.40).

    Parameters
    ----------
    I1 : float
        Transverse moment about the pivot, kg·m² (``I1 = I2``).
    I3 : float
        Moment about the symmetry axis, kg·m².
    mass : float
        kg.
    length : float
        Distance from the pivot to the centre of mass along the symmetry axis, m (≥ 0).
    theta0 : float
        Initial tilt of the symmetry axis from the upward vertical, rad, in ``[0, π]``.
    omega3 : float
        Spin about the symmetry axis, ``ω3 = ψ̇ + φ̇ cos θ``, rad/s (conserved).
    theta_dot0, phi_dot0 : float
        Initial nutation and precession rates, rad/s.  Both 0: the axis is released from rest.
    g : float
        Gravity, m/s² (default standard gravity 9.80665).
    kind_atol : float
        Absolute tolerance in ``u = cos θ`` for the labels "cusp" (``|b/a − u_N| ≤ kind_atol``) and
        "steady" (``u_N − u_X ≤ kind_atol``).

    Returns
    -------
    HeavyTopReport
    """
    values = dict(I1=I1, I3=I3, mass=mass, length=length, theta0=theta0, omega3=omega3,
                  theta_dot0=theta_dot0, phi_dot0=phi_dot0, g=g, kind_atol=kind_atol)
    for name, v in values.items():
        if not (isinstance(v, (int, float, np.floating, np.integer)) and math.isfinite(v)):
            raise UsageError(f"Expected a finite number for `{name}`, got {v!r}")
    if not (I1 > 0 and I3 > 0 and mass > 0):
        raise PhysicsError(f"Expected positive I1, I3 and mass, got {I1}, {I3}, {mass}")
    if length < 0 or g < 0:
        raise UsageError(f"Expected `length` >= 0 and `g` >= 0, got {length}, {g}")
    if not 0.0 <= theta0 <= math.pi:
        raise UsageError(f"Expected `theta0` in [0, π] rad, got {theta0}")
    i1, i3 = float(I1), float(I3)
    mgl = float(mass) * float(g) * float(length)
    u0, s = math.cos(theta0), math.sin(theta0)
    a = i3 * omega3 / i1
    # the analysis squares and cubes these (energies, the cubic f(u)): refuse what a float64 cannot hold
    largest = max(abs(a), abs(phi_dot0), abs(theta_dot0), math.sqrt(2.0 * mgl / i1), abs(i3 * omega3))
    NonFiniteResultError.check(f"the cube of the top's largest rate or angular momentum ({largest:g})",
                               largest * largest * largest * 1e3,
                               because="the spin, precession or nutation rate is outside any physical range")
    b = phi_dot0 * s * s + a * u0
    beta = 2.0 * mgl / i1
    alpha = theta_dot0 ** 2 + (phi_dot0 * s) ** 2 + beta * u0
    # u0 is a root of f when the tilt is at a turning point, or at a pole (u0 = ±1, where f(±1) = −(b ∓ a)² = 0)
    turning = theta_dot0 == 0.0 or s == 0.0
    if beta == 0.0 and alpha + a * a == 0.0:
        raise PhysicsError("The top neither spins, moves nor feels gravity: there is no motion to analyse")
    u_x, u_n, u_u = _cubic_roots(a, b, alpha, beta, u0, phi_dot0, theta_dot0, turning)
    u_x, u_n = max(-1.0, min(u_x, 1.0)), max(-1.0, min(u_n, 1.0))
    period = _nutation_period(u_x, u_n, u_u, alpha, beta, a)

    u_prime = b / a if a != 0.0 else None
    if a == 0.0 and b == 0.0:
        kind = "planar"
    elif u_n - u_x <= kind_atol:
        kind = "steady"
    elif u_prime is not None and abs(u_prime - u_n) <= kind_atol:
        kind = "cusp"
    elif u_prime is not None and u_x < u_prime < u_n:
        kind = "looping"
    else:
        kind = "undulating"

    margin = (i3 * omega3) ** 2 / (4.0 * i1 * mgl) if mgl > 0 else math.inf
    slow, fast = steady_precession(i1, i3, omega3, mgl, theta0)
    return HeavyTopReport(transverse_moment=i1, axial_moment=i3, mass=float(mass), length=float(length),
                          gravity=float(g), theta0=float(theta0), omega3=float(omega3),
                          theta_dot0=float(theta_dot0), phi_dot0=float(phi_dot0), a=a, b=b, alpha=alpha,
                          beta=beta, roots=(u_x, u_n, u_u), theta_min=math.acos(u_n), theta_max=math.acos(u_x),
                          nutation_period=period, precession_kind=kind, precession_zero_u=u_prime,
                          sleeping_stable=bool(margin > 1.0), sleeping_margin=margin,
                          precession_rate_slow=slow, precession_rate_fast=fast)


#: Most output samples of :func:`simulate_top` (bounds memory and the integrator's work; ``tolerances``).
MAX_TOP_SAMPLES = MAX_TRAJECTORY_SAMPLES


def simulate_top(top: HeavyTopReport, duration: float, *, samples: int = 2001, rtol: float = 1e-10,
                 atol: float = 1e-12) -> TopTrajectory:
    """Integrate the heavy symmetric top in vector form and return the path of its symmetry axis.

    State: the unit symmetry axis ``n`` and the angular momentum ``L`` about the pivot (space frame).
    For a symmetric top ``ω = L/I1 + (1/I3 − 1/I1)(L·n) n``, so ``ṅ = ω × n = (L × n)/I1`` and
    ``L̇ = τ = l n × (−M g ẑ)`` (Eq. 4.26 about the fixed point).  This form has no Euler-angle
    singularity at θ = 0; θ and φ are read off ``n`` afterwards (``n = (sin θ cos φ, sin θ sin φ, cos θ)``
    by Eq. 4.31).  ``L·n = I3 ω3`` and ``L·ẑ = I1 b`` are conserved exactly by the equations.

    Parameters
    ----------
    top : HeavyTopReport
        Parameters and initial conditions (φ0 = 0: the axis starts in the xz-plane).
    duration : float
        s, > 0.
    samples : int
        Number of output times, evenly spaced in ``[0, duration]``; 2 to :data:`MAX_TOP_SAMPLES`.
    rtol, atol : float
        Tolerances of the DOP853 integrator (``scipy.integrate.solve_ivp``).

    Returns
    -------
    TopTrajectory
    """
    if not (duration > 0 and math.isfinite(duration)):
        raise UsageError(f"Expected a positive finite `duration`, got {duration!r}")
    if not 2 <= int(samples) <= MAX_TOP_SAMPLES:
        raise UsageError(f"Expected 2 <= `samples` <= {MAX_TOP_SAMPLES}, got {samples!r}")
    i1, i3 = top.transverse_moment, top.axial_moment
    mgl = top.mass * top.gravity * top.length
    th = top.theta0
    n0 = np.array([math.sin(th), 0.0, math.cos(th)])
    ndot0 = top.theta_dot0 * np.array([math.cos(th), 0.0, -math.sin(th)]) \
        + top.phi_dot0 * np.array([0.0, math.sin(th), 0.0])
    l0 = i1 * np.cross(n0, ndot0) + i3 * top.omega3 * n0
    zhat = np.array([0.0, 0.0, 1.0])

    def rhs(_t, y):
        n, lvec = y[:3], y[3:]
        return np.concatenate([np.cross(lvec, n) / i1, mgl * np.cross(zhat, n)])

    t = np.linspace(0.0, float(duration), int(samples))
    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (0.0, float(duration)), np.concatenate([n0, l0]), method="DOP853", t_eval=t,
                    rtol=rtol, atol=atol)
    if not sol.success:
        raise PhysicsError(f"integration of the top failed: {sol.message}")
    n = sol.y[:3].T
    lv = sol.y[3:].T
    n = n / np.linalg.norm(n, axis=1)[:, None]
    theta = np.arccos(np.clip(n[:, 2], -1.0, 1.0))
    phi = np.unwrap(np.arctan2(n[:, 1], n[:, 0]))
    l_axial = np.einsum("ij,ij->i", lv, n)
    l_perp2 = np.einsum("ij,ij->i", lv, lv) - l_axial ** 2
    energy = 0.5 * l_perp2 / i1 + 0.5 * l_axial ** 2 / i3 + mgl * n[:, 2]
    return TopTrajectory(t=t, axis=n, angular_momentum=lv, theta=theta, phi=phi, energy=energy)


def heavy_top_on_pivot(props: MassProperties, pivot, *, theta0: float, omega3: float, theta_dot0: float = 0.0,
                       phi_dot0: float = 0.0, g: float = STANDARD_GRAVITY, rtol: float = 1e-3,
                       kind_atol: float = 1e-9) -> HeavyTopReport:
    """Analyse a body spinning on a fixed ``pivot`` as a heavy symmetric top.

    The inertia about the pivot follows from the parallel-axis theorem (``MassProperties.inertia_about``,
    Eq. 4.16); the symmetry axis is the unit vector from the pivot to the centre of mass and ``length`` its
    distance.  ``I3 = n̂·I·n̂``; ``I1`` is the mean of the two moments transverse to ``n̂``.

    Parameters
    ----------
    props : MassProperties
        The body (load a mesh first with :func:`inertia_tool.mass_properties`).
    pivot : (3,) array_like
        The fixed point, m, mesh axes.
    theta0, omega3, theta_dot0, phi_dot0, g, kind_atol
        As in :func:`heavy_top`.
    rtol : float
        Relative tolerance (of ``I1``) for the symmetric-top check: an ``AsymmetricTopWarning`` is issued
        when the two transverse moments differ, or ``n̂`` is not a principal axis about the pivot, by more.

    Returns
    -------
    HeavyTopReport

    Raises
    ------
    PhysicsError
        If the pivot is at the centre of mass (no gravity torque and no defined symmetry axis).
    """
    if not isinstance(props, MassProperties):
        raise UsageError(f"Expected `props` to be a MassProperties (load the mesh with mass_properties first), "
                         f"got {type(props).__name__}")
    tensor = np.asarray(props.inertia_about(pivot).tensor)
    offset = props.center_of_mass - np.asarray(pivot, dtype=float)
    length = float(np.linalg.norm(offset))
    gyration = math.sqrt(max(float(np.trace(props.inertia)), 0.0) / props.mass)   # body size, m
    if length <= 1e-9 * gyration:
        raise PhysicsError("The pivot is at the centre of mass: gravity exerts no torque and the symmetry axis "
                           "(pivot → centre of mass) is undefined; use inertia_tool.dynamics.spin_stability "
                           "for a free body")
    n = offset / length
    i3 = float(n @ tensor @ n)
    e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    basis = np.column_stack([e1, e2])
    transverse = np.linalg.eigvalsh(basis.T @ tensor @ basis)
    i1 = float(transverse.mean())
    coupling = float(np.linalg.norm(tensor @ n - i3 * n))
    spread = float(transverse[1] - transverse[0])
    if spread > rtol * i1 or coupling > rtol * i1:
        warnings.warn(f"not a symmetric top about this pivot: transverse moments {transverse[0]:.6g} and "
                      f"{transverse[1]:.6g} kg·m² differ by {spread / i1:.2%}, off-axis coupling "
                      f"{coupling / i1:.2%} of I1 (tolerance {rtol:g}); the analysis uses their mean",
                      AsymmetricTopWarning, stacklevel=2)
    report = heavy_top(i1, i3, props.mass, length, theta0=theta0, omega3=omega3, theta_dot0=theta_dot0,
                       phi_dot0=phi_dot0, g=g, kind_atol=kind_atol)
    return replace(report, pivot=np.asarray(pivot, dtype=float).copy(), symmetry_axis=n,
                   transverse_asymmetry=(spread + coupling) / i1)
