"""The heavy top's ``u(t) = cos θ(t)`` through Weierstrass' ℘ (Chapter 4, "Rigid Body Motion", exercise 4.10).

Eq. (4.40) reads ``u̇² = f(u) = β u³ − (α + a²) u² + (2ab − β) u + (α − b²)``.  With ``u = c + (4/β) P`` and
``c = (α + a²)/(3β)`` (which removes the quadratic term), ``P`` obeys ``Ṗ² = 4P³ − g2 P − g3`` with

    g2 = −(β/4) (3βc² − 2(α + a²) c + 2ab − β),    g3 = −(β²/16) (βc³ − (α + a²) c² + (2ab − β) c + α − b²),

and the roots ``e_k = β (u_k − c)/4`` (``u_U ↔ e1``, ``u_N ↔ e2``, ``u_X ↔ e3``).  The real solution that
oscillates between ``u_X`` and ``u_N`` is ``℘`` on the line through the imaginary half-period ``ω3 = iτ/2``:

    u(t) = c + (4/β) ℘(t − ω3),     t = 0 at the bottom of a wobble (θ = θ_max, u = u_X),

doubly periodic with real period ``T = 2ω1`` — the nutation period ``4K(m)/√(β(u_U − u_X))`` of
``inertia_tool.dynamics.top`` — and imaginary period ``τ``.  (Exercise 4.10(g) writes ``u = β ℘(t − iτ/2) + c``;
matching the ``u³`` coefficients gives the factor ``4/β`` used here.)

The top is described by any object with the attributes ``a, b, alpha, beta`` of
``inertia_tool.dynamics.top.HeavyTopReport`` (1/s, 1/s²).
"""

from __future__ import annotations

import numpy as np

from ..errors import PhysicsError
from .elliptic import weierstrass_half_periods, weierstrass_p

__all__ = ["top_weierstrass_invariants", "top_cos_theta"]


def top_weierstrass_invariants(top) -> tuple[float, float, float]:
    """``(g2, g3, c)`` of the substitution ``u = c + (4/β) P`` for a heavy top (module docstring).

    Parameters
    ----------
    top : HeavyTopReport
        Supplies ``a, b, alpha, beta``.

    Raises
    ------
    PhysicsError
        Without gravity torque (``β = 0``, ``f`` is quadratic and ``u(t)`` harmonic) or without nutation
        (``Δ ≤ 0``: two roots of ``f`` coincide).
    """
    a, b, alpha, beta = float(top.a), float(top.b), float(top.alpha), float(top.beta)
    if beta <= 0.0:
        raise PhysicsError("The top feels no gravity torque (β = 0): u(t) is harmonic, ℘ does not apply")
    quad = alpha + a * a
    lin = 2.0 * a * b - beta
    const = alpha - b * b
    c = quad / (3.0 * beta)
    g2 = -(beta / 4.0) * (3.0 * beta * c * c - 2.0 * quad * c + lin)
    g3 = -(beta * beta / 16.0) * (beta * c ** 3 - quad * c * c + lin * c + const)
    if g2 ** 3 - 27.0 * g3 ** 2 <= 0.0:
        raise PhysicsError("The top does not nutate (two roots of f(u) coincide): u is constant")
    return g2, g3, c


def top_cos_theta(top, t) -> np.ndarray:
    """``u(t) = cos θ(t) = c + (4/β) ℘(t − ω3)``, ``t`` in s from a moment at ``θ = θ_max`` (exercise 4.10).

    Parameters
    ----------
    top : HeavyTopReport
        A nutating heavy top (``β > 0``).
    t : array_like
        s.

    Returns
    -------
    ndarray (shape of ``t``), real.
    """
    g2, g3, c = top_weierstrass_invariants(top)
    _, omega3 = weierstrass_half_periods(g2, g3)
    p = weierstrass_p(np.asarray(t, dtype=np.float64) - omega3, g2, g3)
    return c + (4.0 / float(top.beta)) * p.real
