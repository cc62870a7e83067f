"""The cavity bounded by a quadric, optimised over its 10 coefficients.

For an objective ``f(μ)`` of the mass moments only (``inertia_tool.design.moments``), removing the material of
a small cell at ``x`` changes ``f`` by ``−∇f · ψ(x) dV`` where ``ψ(x) = (1, x, y, z, x², y², z², xy, xz, yz)``:
the first-order change is a **quadratic polynomial** in ``x``, so an optimal cavity is the part of the allowed
region where a quadric is negative (Hafner et al., "Spin-It Faster", SIGGRAPH 2024).  The cavity here is

    C(θ) = {x allowed : q(x) = θ̂ · ψ(x̂) < 0},   θ̂ = θ/|θ|,   x̂ = (x − centre)/half_extent,

its indicator on the cells smoothed as ``σ(−q/τ)`` (logistic) so that ``f`` is differentiable in ``θ``; the
width ``τ`` is annealed down to half a cell and the final cavity is the sharp ``q < 0``.  Starts: the
first-order quadric ``q = −∇f(μ_part) · ψ`` (carve wherever removing material helps) and a central ball;
BFGS (scipy; 10 unknowns) with the analytic gradient ``∂f/∂θ = −∇f · Σ_i ψ_i σ′_i ∂(−q_i/τ)/∂θ``, ``∇f`` by forward
differences in the 10 moments.  Finally the sharp cavity is polished by the fixed point of its optimality
condition (Hafner et al.: the cavity is where the first-order quadric at its own moments is negative).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import PhysicsError

__all__ = ["QuadricCavity", "optimize_quadric_cavity", "quadric_values"]

#: Sigmoid widths (in units of the normalised coordinate) of the annealing stages, before the last one at
#: half a cell.
ANNEALING = (0.3, 0.1, 0.03)

#: Most fixed-point steps of the optimality condition after the annealing (each one objective gradient).
MAX_POLISH_STEPS = 30

#: Most BFGS iterations per annealing stage and start.
MAX_ITERATIONS_PER_STAGE = 40


@dataclass(frozen=True)
class QuadricCavity:
    """An optimised quadric cavity on the cells of the allowed region.

    Attributes
    ----------
    coefficients : (10,) float
        Unit vector ``θ̂`` of ``q(x̂) = θ̂ · (1, x̂, ŷ, ẑ, x̂², ŷ², ẑ², x̂ŷ, x̂ẑ, ŷẑ)`` in frame coordinates.
    centre : (3,) float
        m, frame coordinates of ``x̂ = 0``.
    half_extent : float
        m, the scale of ``x̂``.
    removed : (n,) bool
        Which allowed cells the sharp cavity removes.
    objective_solid, objective : float
        The objective without a cavity and with the sharp cavity (on the cells).
    evaluations : int
        Objective evaluations spent.
    seconds : float
        Wall-clock time of the optimisation.
    """

    coefficients: np.ndarray
    centre: np.ndarray
    half_extent: float
    removed: np.ndarray
    objective_solid: float
    objective: float
    evaluations: int
    seconds: float

    def values(self, points) -> np.ndarray:
        """``q`` at frame points (n, 3) m (negative inside the cavity)."""
        return quadric_values(self.coefficients, (np.asarray(points) - self.centre) / self.half_extent)


def _monomials(x) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    a, b, c = x[:, 0], x[:, 1], x[:, 2]
    return np.column_stack([np.ones(len(x)), a, b, c, a * a, b * b, c * c, a * b, a * c, b * c])


def quadric_values(coefficients, normalized_points) -> np.ndarray:
    """``θ̂ · ψ(x̂)`` at normalised points (n, 3)."""
    theta = np.asarray(coefficients, dtype=np.float64)
    return _monomials(normalized_points) @ (theta / np.linalg.norm(theta))


def _moment_scales(mu_part: np.ndarray, size: float) -> np.ndarray:
    m = abs(mu_part[0])
    return np.array([m] + [m * size] * 3 + [m * size * size] * 6)


def _gradient_in_moments(objective, mu, scales, value, rel_step=1e-7) -> np.ndarray:
    """Forward differences of ``objective`` in the 10 moments (``value`` = objective(mu)), steps relative to
    the moment scales (mass, mass·size, mass·size²)."""
    grad = np.empty(10)
    for k in range(10):
        step = rel_step * scales[k]
        up = mu.copy()
        up[k] += step
        grad[k] = (objective(up) - value) / step
    return grad


def optimize_quadric_cavity(objective, mu_part, points, spacing: float, *, size: float) -> QuadricCavity:
    """Optimise a quadric cavity over the allowed cells.

    Parameters
    ----------
    objective : callable
        ``f(μ) -> float`` of the 10 moments (unit density, frame of ``points``).
    mu_part : (10,) float
        Moments of the solid part at unit density.
    points : (n, 3) float
        Centres of the cells that may be removed (frame coordinates, m).
    spacing : float
        Cell edge, m.
    size : float
        Part size, m (scales the finite-difference steps).

    Returns
    -------
    QuadricCavity
    """
    from scipy.optimize import minimize
    from scipy.special import expit

    from .moments import cell_moment_rows

    started = time.perf_counter()
    pts = np.asarray(points, dtype=np.float64)
    mu_part = np.asarray(mu_part, dtype=np.float64)
    solid_value = objective(mu_part)
    if len(pts) == 0:
        return QuadricCavity(np.r_[1.0, np.zeros(9)], np.zeros(3), 1.0, np.zeros(0, bool), solid_value,
                             solid_value, 1, time.perf_counter() - started)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    half = float(max(0.5 * np.max(hi - lo), spacing))
    phi = _monomials((pts - centre) / half)                   # (n, 10)
    psi = cell_moment_rows(pts, spacing)                      # (n, 10)
    scales = _moment_scales(mu_part, size)
    count = [0]

    def counted(mu):
        count[0] += 1
        return objective(mu)

    # the (n,)- and (n, 10)-sized products avoid BLAS (np.einsum, np.sum): OpenBLAS threads its dot product at
    # this size, and on a busy machine waking the threads took 3-8 ms per call instead of 0.1 ms (measured)
    def smooth(theta, tau):
        norm = np.linalg.norm(theta)
        u = theta / norm
        q = np.einsum("ij,j->i", phi, u)
        c = expit(-q / tau)
        mu = mu_part - np.einsum("ij,i->j", psi, c)
        value = counted(mu)
        g_mu = _gradient_in_moments(counted, mu, scales, value)
        a = np.einsum("ij,j->i", psi, g_mu)
        slope = c * (1.0 - c)
        slope[slope < 1e-12] = 0.0          # cells far from the boundary: no gradient, and no subnormal floats
        b = a * slope / (tau * norm)
        grad = np.einsum("ij,i->j", phi, b) - float(np.sum(b * q)) * u
        return value, grad

    def sharp(theta):
        removed = np.einsum("ij,j->i", phi, theta) < 0
        return counted(mu_part - psi[removed].sum(axis=0)), removed

    # ψ·g is a quadratic polynomial: its coefficients in the monomials of x̂ are fitted exactly on a few cells
    sample = np.unique(np.linspace(0, len(pts) - 1, min(len(pts), 200)).astype(int))

    def first_order(mu, value):
        """The quadric of cells whose removal lowers f to first order at μ: q = −∇f(μ) · ψ."""
        g = _gradient_in_moments(counted, mu, scales, value)
        theta, *_ = np.linalg.lstsq(phi[sample], -np.einsum("ij,j->i", psi[sample], g), rcond=None)
        return theta / max(np.linalg.norm(theta), 1e-300)

    def polish(theta, value, removed):
        """Fixed-point iteration of the optimality condition (the cavity is where the first-order quadric at
        its own moments is negative), accepting only improvements; plain or averaged with the current θ."""
        for _ in range(MAX_POLISH_STEPS):
            target = first_order(mu_part - psi[removed].sum(axis=0), value)
            for trial in (target, theta + target):
                trial = trial / np.linalg.norm(trial)
                trial_value, trial_removed = sharp(trial)
                if trial_value < value:
                    theta, value, removed = trial, trial_value, trial_removed
                    break
            else:
                break
        return theta, value, removed

    # starts: the first-order quadric at the solid part (carve where removing material lowers f), a ball
    starts = [first_order(mu_part, solid_value), np.array([-0.25, 0, 0, 0, 1, 1, 1, 0, 0, 0], dtype=float)]
    cell = spacing / half
    schedule = [t for t in ANNEALING if t > 0.5 * cell] + [0.5 * cell]
    best_value, best_theta, best_removed = solid_value, None, np.zeros(len(pts), bool)
    for theta in starts:
        if not np.all(np.isfinite(theta)) or np.linalg.norm(theta) == 0:
            continue
        theta = theta / np.linalg.norm(theta)
        for tau in schedule:
            result = minimize(smooth, theta, args=(tau,), jac=True, method="BFGS",
                              options={"maxiter": MAX_ITERATIONS_PER_STAGE, "gtol": 1e-9})
            theta = result.x / np.linalg.norm(result.x)
        theta, value, removed = polish(theta, *sharp(theta))
        if value < best_value:
            best_value, best_theta, best_removed = value, theta, removed
    if best_theta is None:
        best_theta = np.r_[1.0, np.zeros(9)]                # q ≡ 1: no cavity helps
    if not np.isfinite(best_value):
        raise PhysicsError("the cavity optimisation produced a non-finite objective")
    return QuadricCavity(coefficients=best_theta, centre=centre, half_extent=half, removed=best_removed,
                         objective_solid=float(solid_value), objective=float(best_value), evaluations=count[0],
                         seconds=time.perf_counter() - started)
