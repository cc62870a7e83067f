"""Jacobi elliptic functions and Legendre integrals in the forms the free rigid body needs.

Everything takes the parameter ``m = k²`` **and** its complement ``m1 = 1 − m`` as separate inputs, so the
near-separatrix regime ``m → 1`` (where ``1 − m`` cannot be recovered from ``m`` in floating point, and
``scipy.special.ellipj`` loses accuracy) is computed from the accurately known ``m1``:

* :func:`jacobi_sn_cn_dn` — arithmetic-geometric-mean (descending Landen) algorithm started from
  ``b0 = √m1`` (Abramowitz & Stegun 16.4; the ``arcsin`` of the descent written as a well-conditioned
  ``arctan2``), after reducing the argument by the half-period ``2K`` so the
  recursion only sees ``|u| ≤ K``; ``dn = √(cn² + m1 sn²)`` (no cancellation near ``m = 1``).
  At ``m1 = 0`` the closed forms ``sn = tanh``, ``cn = dn = sech`` are used.
* :func:`elliptic_f_from_sn_cn` — the elliptic argument ``u = F(am u | m)`` from a point ``(sn, cn)`` on the
  circle, via Carlson's ``R_F`` (DLMF 19.25.5), continued over ``cn < 0``.
* :func:`elliptic_pi_of_argument` — ``∫₀ᵘ dv / (1 − n sn² v)`` = Π(n; am u | m) with Carlson's ``R_F``,
  ``R_J`` (DLMF 19.25.14) and its quasi-periodicity ``Π(n; φ + jπ) = Π(n; φ) + 2j Π(n | m)``.
* :func:`jacobi_sn_complex` — ``sn`` of a complex argument by the addition theorem (A&S 16.21.1).
* :func:`weierstrass_p` — Weierstrass' ℘ from its invariants ``g2, g3`` (real, ``Δ = g2³ − 27 g3² > 0``), as
  ``℘(z) = e3 + (e1 − e3) / sn²(√(e1 − e3) z | m)``, ``m = (e2 − e3)/(e1 − e3)`` (A&S 18.9.11), with the roots
  ``e1 > e2 > e3`` of ``4e³ − g2 e − g3``; half-periods ``ω1 = K/√(e1 − e3)``, ``ω3 = i K'/√(e1 − e3)``
  (:func:`weierstrass_half_periods`).  Used by the heavy top of exercise 4.10 (``dynamics.top_motion``).
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipkm1, elliprf, elliprj

from ..errors import UsageError

__all__ = ["complete_k", "jacobi_sn_cn_dn", "elliptic_f_from_sn_cn", "elliptic_pi_of_argument", "jacobi_sn_complex",
           "weierstrass_roots", "weierstrass_half_periods", "weierstrass_p", "weierstrass_p_derivative"]

_AGM_MAX_STEPS = 60
#: The AGM of :func:`jacobi_sn_cn_dn` stops at ``c ≤ 2⁻⁵³ a`` (as Cephes' ``ellpj``): the deeper levels would
#: change φ by less than an ulp, and a stricter bound can stall for ever at a one-ulp ``a − b`` (for m = 0.5 it
#: ran all 60 levels, 30× slower).
_AGM_STOP = 2.0 ** -53


def complete_k(m1: float) -> float:
    """Complete elliptic integral ``K(m)`` from the complementary parameter ``m1 = 1 − m`` ∈ [0, 1].

    The one K of the package (the free body's polhode period, the top's nutation period, the exact free
    flow).  scipy's ``ellipkm1`` keeps full relative precision as ``m → 1`` (``m1 → 0``), where
    ``ellipk(1 − m1)`` would lose the digits of ``m1``; ``K → ∞`` at ``m1 = 0`` (the separatrix).

    Parameters
    ----------
    m1 : float
        ``1 − m``.
    """
    return float(ellipkm1(m1))


def _reduce(u: np.ndarray, k: float):
    """``u = 2K j + r`` with ``|r| ≤ K``; returns ``(r, j)`` (j as float array of integers)."""
    j = np.round(u / (2.0 * k))
    return u - 2.0 * k * j, j


def jacobi_sn_cn_dn(u, m: float, m1: float):
    """Jacobi elliptic functions ``sn, cn, dn`` of argument ``u`` and parameter ``m`` (``m1 = 1 − m``).

    Parameters
    ----------
    u : array_like
        Elliptic argument.
    m, m1 : float
        Parameter and its complement, ``0 ≤ m ≤ 1``, ``m + m1 = 1`` (both given to keep ``m1`` exact).

    Returns
    -------
    sn, cn, dn : ndarray (shape of ``u``)
    """
    u = np.asarray(u, dtype=np.float64)
    if m1 <= 0.0:  # separatrix: sn = tanh, cn = dn = sech
        sech = 1.0 / np.cosh(u)
        return np.tanh(u), sech, sech
    if m <= 0.0:
        return np.sin(u), np.cos(u), np.ones_like(u)
    k = complete_k(m1)
    r, j = _reduce(u, k)
    sign = np.where(np.mod(j, 2.0) == 0.0, 1.0, -1.0)  # sn(u + 2K) = −sn u, cn(u + 2K) = −cn u
    a, b, c = 1.0, np.sqrt(m1), np.sqrt(m)
    a_list, b_list, c_list = [a], [b], [c]
    for _ in range(_AGM_MAX_STEPS):
        if abs(c) <= _AGM_STOP * a:
            break
        a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.5 * (a - b)
        a_list.append(a)
        b_list.append(b)
        c_list.append(c)
    n_steps = len(a_list) - 1
    phi = (2.0 ** n_steps) * a_list[-1] * r
    for i in range(n_steps, 0, -1):
        # asin(c sin φ / a) as atan2(c sin φ, √(a² cos² φ + b² sin² φ)) using a² − c² = b²: no loss of
        # accuracy where the argument of asin is near ±1 (which happens for m → 1).
        s_phi, c_phi = np.sin(phi), np.cos(phi)
        phi = 0.5 * (phi + np.arctan2(c_list[i] * s_phi,
                                      np.sqrt((a_list[i] * c_phi) ** 2 + (b_list[i] * s_phi) ** 2)))
    sn, cn = np.sin(phi), np.cos(phi)
    dn = np.sqrt(cn * cn + m1 * sn * sn)
    return sign * sn, sign * cn, dn


def elliptic_f_from_sn_cn(sn: float, cn: float, m: float, m1: float) -> float:
    """The argument ``u ∈ (−2K, 2K]`` with ``sn(u|m) = sn``, ``cn(u|m) = cn`` (a point on the unit circle).

    ``F(φ|m) = sin φ R_F(cos² φ, 1 − m sin² φ, 1)`` for ``|φ| ≤ π/2`` (DLMF 19.25.5), continued by
    ``F(π − φ) = 2K − F(φ)`` for ``cn < 0``; ``1 − m sin² φ`` is evaluated as ``cn² + m1 sn²``.
    At ``m1 = 0`` (separatrix) ``u = asinh(sn / cn)`` (requires ``cn > 0``).
    """
    norm = np.hypot(sn, cn)
    sn, cn = sn / norm, cn / norm
    if m1 <= 0.0:
        return float(np.arcsinh(sn / cn))
    base = sn * float(elliprf(cn * cn, cn * cn + m1 * sn * sn, 1.0))
    if cn >= 0.0:
        return float(base)
    k = complete_k(m1)
    return float((1.0 if sn >= 0.0 else -1.0) * 2.0 * k - base)


def elliptic_pi_of_argument(u, n: float, m: float, m1: float):
    """``Π(n; am u | m) = ∫₀ᵘ dv / (1 − n sn²(v|m))`` for ``n < 1`` (the free-body precession integral).

    With ``u = 2K j + r``, ``|r| ≤ K``: ``Π = Π(n; am r) + 2 j Π(n | m)`` where, for ``|φ| ≤ π/2``,
    ``Π(n; φ|m) = s R_F(c², Δ², 1) + (n/3) s³ R_J(c², Δ², 1, 1 − n s²)`` (DLMF 19.25.14, ``s = sin φ``,
    ``c = cos φ``, ``Δ² = 1 − m s²``) and ``Π(n|m) = R_F(0, m1, 1) + (n/3) R_J(0, m1, 1, 1 − n)``.
    At ``m1 = 0``: ``∫ du / (1 − n tanh² u)`` = ``[u + √ν atan(√ν tanh u)] / (1 + ν)``, ``ν = −n``; with
    ``n ≥ 0`` it is ``[u − √n atanh(√n tanh u)] / (1 − n)``.

    Returns
    -------
    ndarray (shape of ``u``)
    """
    u = np.asarray(u, dtype=np.float64)
    if m1 <= 0.0:
        x = np.tanh(u)
        if n < 0.0:
            root = np.sqrt(-n)
            return (u + root * np.arctan(root * x)) / (1.0 - n)
        if n == 0.0:
            return u
        root = np.sqrt(n)
        return (u - root * np.arctanh(root * x)) / (1.0 - n)
    k = complete_k(m1)
    r, j = _reduce(u, k)
    sn, cn, _ = jacobi_sn_cn_dn(r, m, m1)
    cn = np.abs(cn)  # |r| ≤ K so cn ≥ 0 up to round-off
    delta2 = cn * cn + m1 * sn * sn
    s2 = sn * sn
    incomplete = sn * elliprf(cn * cn, delta2, 1.0) + (n / 3.0) * sn * s2 * elliprj(cn * cn, delta2, 1.0,
                                                                                      1.0 - n * s2)
    complete = float(elliprf(0.0, m1, 1.0) + (n / 3.0) * elliprj(0.0, m1, 1.0, 1.0 - n))
    return incomplete + 2.0 * j * complete


def jacobi_sn_complex(z, m: float, m1: float):
    """``sn(x + i y | m)`` for complex ``z`` (A&S 16.21.1):

    ``sn = (s d1 + i c d s1 c1) / (c1² + m s² s1²)`` with ``s, c, d`` of ``(x | m)`` and ``s1, c1, d1`` of
    ``(y | m1)`` (Jacobi's imaginary transformation).  ``0 < m < 1``.

    Returns
    -------
    complex ndarray (shape of ``z``); ``inf`` at the poles ``2jK + i(2k + 1)K'``.
    """
    z = np.asarray(z, dtype=np.complex128)
    s, c, d = jacobi_sn_cn_dn(z.real, m, m1)
    s1, c1, d1 = jacobi_sn_cn_dn(z.imag, m1, m)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (s * d1 + 1j * c * d * s1 * c1) / (c1 * c1 + m * s * s * s1 * s1)


def weierstrass_roots(g2: float, g3: float) -> tuple[float, float, float]:
    """Roots ``e1 > e2 > e3`` of ``4e³ − g2 e − g3`` (real invariants with ``Δ = g2³ − 27 g3² > 0``).

    Trigonometric form: ``e_k = 2√(g2/12) cos((acos(27 g3 / √(27 g2³)) − 2πk)/3)``, ``k = 0, 1, 2``; the roots
    sum to zero.

    Raises
    ------
    UsageError
        If the invariants are not finite or ``Δ ≤ 0`` (a lattice that is not rectangular: not implemented).
    """
    if not (np.isfinite(g2) and np.isfinite(g3)):
        raise UsageError(f"Expected finite invariants g2, g3, got {g2!r}, {g3!r}")
    disc = g2 ** 3 - 27.0 * g3 ** 2
    if not (g2 > 0 and disc > 0):
        raise UsageError(f"Expected a rectangular lattice, Δ = g2³ − 27 g3² > 0, got g2 = {g2!r}, g3 = {g3!r} "
                         f"(Δ = {disc:.6g})")
    r = 2.0 * np.sqrt(g2 / 12.0)
    angle = np.arccos(np.clip(27.0 * g3 / np.sqrt(27.0 * g2 ** 3), -1.0, 1.0)) / 3.0
    e1, e2, e3 = (r * np.cos(angle - 2.0 * np.pi * k / 3.0) for k in (0, 1, 2))
    e1, e2, e3 = sorted((float(e1), float(e2), float(e3)), reverse=True)
    return e1, e2, e3


def _lattice(g2: float, g3: float):
    e1, e2, e3 = weierstrass_roots(g2, g3)
    span = e1 - e3
    m, m1 = (e2 - e3) / span, (e1 - e2) / span
    return e1, e2, e3, np.sqrt(span), m, m1


def weierstrass_half_periods(g2: float, g3: float) -> tuple[float, complex]:
    """Half-periods ``(ω1, ω3) = (K(m), i K(m1)) / √(e1 − e3)`` of ℘ for real ``g2, g3`` with ``Δ > 0``:
    ``℘(ω1) = e1``, ``℘(ω1 + ω3) = e2``, ``℘(ω3) = e3``."""
    _, _, _, root, m, m1 = _lattice(g2, g3)
    return float(complete_k(m1)) / root, 1j * float(complete_k(m)) / root


def weierstrass_p(z, g2: float, g3: float):
    """Weierstrass' ``℘(z; g2, g3)`` for complex ``z``, real invariants with ``Δ > 0`` (A&S 18.9.11).

    ``℘(z) = e3 + (e1 − e3) / sn²(√(e1 − e3) z | m)``, ``m = (e2 − e3)/(e1 − e3)``; it satisfies
    ``℘′² = 4℘³ − g2 ℘ − g3`` and has double poles on the lattice ``2jω1 + 2kω3``.  With
    ``g2 = 60 Σ′ w⁻⁴``, ``g3 = 140 Σ′ w⁻⁶`` over the lattice points ``w`` (Chapter 4 exercise 4.10 writes the
    sums without the factors 60 and 140).

    Parameters
    ----------
    z : array_like
        Complex (or real) argument.
    g2, g3 : float
        Real invariants with ``g2³ − 27 g3² > 0``.

    Returns
    -------
    complex ndarray (shape of ``z``)
    """
    e1, e2, e3, root, m, m1 = _lattice(g2, g3)
    sn = jacobi_sn_complex(root * np.asarray(z, dtype=np.complex128), m, m1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return e3 + (e1 - e3) / (sn * sn)


def weierstrass_p_derivative(z, g2: float, g3: float):
    """``℘′(z) = −2 (e1 − e3)^{3/2} cn dn / sn³`` at ``√(e1 − e3) z`` (derivative of :func:`weierstrass_p`)."""
    e1, e2, e3, root, m, m1 = _lattice(g2, g3)
    w = root * np.asarray(z, dtype=np.complex128)
    sn = jacobi_sn_complex(w, m, m1)
    # cn and dn of the complex argument from sn: choose the branches by continuity through the real formulas
    s, c, d = jacobi_sn_cn_dn(w.real, m, m1)
    s1, c1, d1 = jacobi_sn_cn_dn(w.imag, m1, m)
    den = c1 * c1 + m * s * s * s1 * s1
    cn = (c * c1 - 1j * s * d * s1 * d1) / den          # A&S 16.21.2
    dn = (d * c1 * d1 - 1j * m * s * c * s1) / den       # A&S 16.21.3
    with np.errstate(divide="ignore", invalid="ignore"):
        return -2.0 * root ** 3 * cn * dn / sn ** 3
