"""A dense insert beside the cavity: two quadrics, 20 unknowns (Bächer et al. 2014 fill with a second material).

With an insert of density ``ρ2 = r ρ`` allowed, each allowed cell is either part material, void or insert:

    insert  where q2(x̂) < 0,        void  where q1(x̂) < 0 and q2(x̂) ≥ 0,        part material elsewhere,

so (unit part density) ``μ = μ_part + Σ_i ψ_i [(r − 1) s2_i − (1 − s2_i) s1_i]`` with ``s_k`` the (smoothed)
indicators ``σ(−q_k/τ)``.  The objective of the moments is still linear in the density, so both boundaries are
quadrics (the first-order change of adding insert material at ``x`` is ``(r − 1) ∇f · ψ(x)``).  Optimisation:
from the cavity-only optimum and the first-order insert quadric there, BFGS on the 20 coefficients through the
same annealing schedule as :mod:`.optimize`; the sharp design is kept only if it beats the cavity alone.

A **ring insert** is tried beside it (a heavy rim about the spin axis: the obvious fix of a top): the allowed
cells beyond a radius ``ρ``, itself a quadric ``ρ² − x² − y² < 0``, for the outermost 5 % to 50 % of them
(``RING_FRACTIONS``), with the cavity-only optimum.  Both shapes that beat the cavity alone are handed to
``spin_it``, which meshes and re-analyses each and keeps the better exact objective.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .optimize import ANNEALING, MAX_ITERATIONS_PER_STAGE, QuadricCavity, _gradient_in_moments, _moment_scales, \
    _monomials

__all__ = ["QuadricInsert", "optimize_cavity_and_insert", "ring_coefficients", "RING_FRACTIONS"]


@dataclass(frozen=True)
class QuadricInsert:
    """A cavity and a dense insert on the cells of the allowed region.

    Attributes
    ----------
    cavity : QuadricCavity
        The void's quadric ``q1`` (its ``removed`` are the void cells) and the shared normalisation.
    insert_coefficients : (10,) float
        Unit ``θ̂2`` of the insert's quadric ``q2`` (same monomials and normalisation as ``cavity``).
    inserted : (n,) bool
        Cells filled with insert material.
    density_ratio : float
        ``ρ2/ρ``.
    objective_cavity_only, objective : float
        The objective with the best cavity alone and with cavity and insert (on the cells).
    shape : str
        ``"quadric"`` (the optimised second quadric), ``"ring"`` (a rim about the spin axis) or ``"none"``.
    alternatives : tuple of QuadricInsert
        The other shapes that also beat the cavity alone on the cells, and last the cavity alone: the cells
        and the meshed part differ by up to a cell at the wall (where a rim lies), so ``spin_it`` meshes and
        re-analyses each and keeps the best exact objective.
    """

    cavity: QuadricCavity
    insert_coefficients: np.ndarray
    inserted: np.ndarray
    density_ratio: float
    objective_cavity_only: float
    objective: float
    shape: str = "quadric"
    alternatives: tuple["QuadricInsert", ...] = ()

    def insert_values(self, points) -> np.ndarray:
        """``q2`` at frame points (n, 3) m (negative inside the insert)."""
        x = (np.asarray(points) - self.cavity.centre) / self.cavity.half_extent
        return _monomials(x) @ (self.insert_coefficients / np.linalg.norm(self.insert_coefficients))


#: Fractions of the allowed cells (the outermost about the axis) a ring insert may take.
RING_FRACTIONS = (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5)


def ring_coefficients(radius: float, centre, half: float) -> np.ndarray:
    """Unit ``θ̂`` of the quadric ``q = ρ² − (x² + y²)`` (frame coordinates, m: the spin axis is ``e3`` through the
    frame origin) in the normalised monomials of ``x = centre + half · x̂``: ``q < 0`` outside the cylinder of
    radius ``ρ`` about the axis, so that the insert is the ring (annulus) of the allowed region beyond ``ρ``."""
    c0, c1 = float(centre[0]), float(centre[1])
    theta = np.array([radius ** 2 - c0 * c0 - c1 * c1, -2.0 * c0 * half, -2.0 * c1 * half, 0.0, -half * half,
                      -half * half, 0.0, 0.0, 0.0, 0.0])
    return theta / np.linalg.norm(theta)


def _best_ring(objective_of_insert, points, centre, half: float):
    """The ring insert (the outermost ``RING_FRACTIONS`` of the allowed cells about the axis) of lowest objective:
    its unit ``θ̂``, or None without cells."""
    radius = np.hypot(points[:, 0], points[:, 1])
    if not len(radius):
        return None
    rings = [ring_coefficients(float(np.quantile(radius, 1.0 - fraction)), centre, half)
             for fraction in RING_FRACTIONS]
    return min(rings, key=objective_of_insert)


def optimize_cavity_and_insert(objective, mu_part, points, spacing: float, cavity: QuadricCavity, *,
                               size: float, density_ratio: float) -> QuadricInsert:
    """Add a dense insert to an optimised cavity (module docstring).

    Parameters
    ----------
    objective : callable
        ``f(μ) -> float`` (unit part density).
    mu_part : (10,) float
        Moments of the solid part at unit density.
    points : (n, 3) float
        Allowed cell centres, frame coordinates, m.
    spacing : float
        Cell edge, m.
    cavity : QuadricCavity
        The cavity-only optimum on the same cells (start and fallback).
    size : float
        Part size, m.
    density_ratio : float
        ``ρ2/ρ`` (> 1).

    Returns
    -------
    QuadricInsert
    """
    from scipy.optimize import minimize
    from scipy.special import expit

    from .moments import cell_moment_rows

    started = time.perf_counter()
    r = float(density_ratio)
    pts = np.asarray(points, dtype=np.float64)
    centre, half = cavity.centre, cavity.half_extent
    phi = _monomials((pts - centre) / half)
    psi = cell_moment_rows(pts, spacing)
    scales = _moment_scales(mu_part, size)
    sample = np.unique(np.linspace(0, len(pts) - 1, min(len(pts), 200)).astype(int))

    def moments(void, insert):
        weight = (r - 1.0) * insert - (1.0 - insert) * void
        return mu_part + np.einsum("ij,i->j", psi, weight)

    def sharp(theta1, theta2):
        insert = (np.einsum("ij,j->i", phi, theta2) < 0).astype(float)
        void = (np.einsum("ij,j->i", phi, theta1) < 0).astype(float) * (1.0 - insert)
        return objective(moments(void, insert)), void > 0, insert > 0

    def smooth(theta, tau):
        t1, t2 = theta[:10], theta[10:]
        n1, n2 = np.linalg.norm(t1), np.linalg.norm(t2)
        u1, u2 = t1 / n1, t2 / n2
        q1, q2 = np.einsum("ij,j->i", phi, u1), np.einsum("ij,j->i", phi, u2)
        s1, s2 = expit(-q1 / tau), expit(-q2 / tau)
        mu = moments(s1, s2)
        value = objective(mu)
        a = np.einsum("ij,j->i", psi, _gradient_in_moments(objective, mu, scales, value))
        slope1, slope2 = s1 * (1.0 - s1), s2 * (1.0 - s2)
        slope1[slope1 < 1e-12] = 0.0
        slope2[slope2 < 1e-12] = 0.0
        b1 = a * (1.0 - s2) * slope1 / (tau * n1)            # ∂μ/∂(−q1/τ) = −(1 − s2) ψ σ′, and −q1 flips sign
        b2 = -a * (r - 1.0 + s1) * slope2 / (tau * n2)
        g1 = np.einsum("ij,i->j", phi, b1) - float(np.sum(b1 * q1)) * u1
        g2 = np.einsum("ij,i->j", phi, b2) - float(np.sum(b2 * q2)) * u2
        return value, np.concatenate([g1, g2])

    # the insert starts where adding dense material helps at the cavity optimum: q2 = +∇f · ψ
    void0 = cavity.removed.astype(float)
    mu0 = moments(void0, np.zeros(len(pts)))
    g0 = _gradient_in_moments(objective, mu0, scales, objective(mu0))
    theta2, *_ = np.linalg.lstsq(phi[sample], np.einsum("ij,j->i", psi[sample], g0), rcond=None)
    theta = np.concatenate([cavity.coefficients, theta2 / max(np.linalg.norm(theta2), 1e-300)])
    cell = spacing / half
    for tau in [t for t in ANNEALING if t > 0.5 * cell] + [0.5 * cell]:
        result = minimize(smooth, theta, args=(tau,), jac=True, method="BFGS",
                          options={"maxiter": MAX_ITERATIONS_PER_STAGE, "gtol": 1e-9})
        theta = np.concatenate([result.x[:10] / np.linalg.norm(result.x[:10]),
                                result.x[10:] / np.linalg.norm(result.x[10:])])
    from dataclasses import replace

    def made(theta1, theta2, shape: str) -> QuadricInsert:
        value, void, insert = sharp(theta1, theta2)
        new_cavity = replace(cavity, coefficients=theta1, removed=void, objective=float(value),
                             seconds=cavity.seconds + time.perf_counter() - started)
        return QuadricInsert(cavity=new_cavity, insert_coefficients=theta2, inserted=insert, density_ratio=r,
                             objective_cavity_only=cavity.objective, objective=float(value), shape=shape)

    # the optimised insert quadric, and a ring (a heavy rim about the axis) with the cavity-only optimum
    designs = [made(theta[:10], theta[10:], "quadric")]
    ring = _best_ring(lambda t2: sharp(cavity.coefficients, t2)[0], pts, centre, half)
    if ring is not None:
        designs.append(made(cavity.coefficients, ring, "ring"))
    better = sorted((d for d in designs if d.objective < cavity.objective), key=lambda d: d.objective)
    no_insert = QuadricInsert(cavity=cavity, insert_coefficients=np.r_[1.0, np.zeros(9)],
                              inserted=np.zeros(len(pts), bool), density_ratio=r,
                              objective_cavity_only=cavity.objective, objective=cavity.objective, shape="none")
    if not better:
        return no_insert
    return replace(better[0], alternatives=(*better[1:], no_insert))
