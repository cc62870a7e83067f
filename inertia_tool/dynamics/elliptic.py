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
"""

from __future__ import annotations

import numpy as np
from scipy.special import ellipkm1, elliprf, elliprj

__all__ = ["complete_k", "jacobi_sn_cn_dn", "elliptic_f_from_sn_cn", "elliptic_pi_of_argument"]

_AGM_MAX_STEPS = 60


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
        if abs(c) <= 1e-17 * a:
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
