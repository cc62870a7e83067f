"""R0 up to rounding: the bound on what a near copy could add to the second moment
(``policy._steiner_second_moment_bound``).

The bound must hold for the δ-neighbourhood of any triangle seen from any centre. It is checked against an
independent estimate: points drawn uniformly in a box round the triangle, kept when their exact distance to the
triangle (closest point by regions, written here) is at most δ, with the estimate's own 5-sigma allowance.
It must also be no larger than the bound it replaced (Steiner volume × (farthest corner + δ)²) and equal to the
prism's closed form when δ → 0.
"""
import numpy as np
from hypothesis import given, settings, strategies as st

from inertia_tool.mesh.policy import _steiner_bound, _steiner_second_moment_bound


def _distance_to_triangle(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Exact Euclidean distance from each row of ``p`` to the triangle abc: the projection if it falls inside,
    else the nearest of the three edges (clamped segment distance)."""
    n = np.cross(b - a, c - a)
    n = n / np.linalg.norm(n)
    h = (p - a) @ n
    q = p - np.outer(h, n)

    def side(u, v):
        return np.cross(v - u, q - u) @ n

    inside = (side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)

    def seg(u, v):
        d = v - u
        t = np.clip((p - u) @ d / (d @ d), 0.0, 1.0)
        return np.linalg.norm(p - (u + np.outer(t, d)), axis=1)

    edge = np.minimum(np.minimum(seg(a, b), seg(b, c)), seg(c, a))
    return np.where(inside, np.abs(h), edge)


coordinate = st.floats(-2.0, 2.0, allow_nan=False)
point = st.tuples(coordinate, coordinate, coordinate)


@settings(max_examples=15, deadline=None)
@given(a=point, b=point, c=point, centre=point, delta=st.floats(0.02, 0.6), seed=st.integers(0, 2**31))
def test_bound_holds_over_the_neighbourhood_of_a_triangle(a, b, c, centre, delta, seed):
    v = np.array([a, b, c], dtype=float)
    area = 0.5 * np.linalg.norm(np.cross(v[1] - v[0], v[2] - v[0]))
    if area < 1e-3:
        return
    f = np.array([[0, 1, 2]])
    centre = np.asarray(centre, dtype=float)
    bound = _steiner_second_moment_bound(v, f, delta, centre)
    lo, hi = v.min(axis=0) - delta, v.max(axis=0) + delta
    box = float(np.prod(hi - lo))
    rng = np.random.default_rng(seed)
    x = lo + (hi - lo) * rng.random((40_000, 3))
    inside = _distance_to_triangle(x, *v) <= delta
    w = np.where(inside, np.sum((x - centre) ** 2, axis=1), 0.0) * box
    estimate, sigma = w.mean(), w.std() / np.sqrt(len(w))
    assert estimate <= bound + 5 * sigma, (estimate, sigma, bound)
    reach = float(np.sqrt(np.max(np.sum((v - centre) ** 2, axis=1)))) + delta
    assert bound <= _steiner_bound(v, f, delta) * reach ** 2 * (1 + 1e-9)


def test_thin_neighbourhood_is_the_prism_closed_form():
    """As δ → 0 the bound is 2δ·∫|p − c|² dA: for the triangle (1,0,0), (0,1,0), (0,0,1) from the origin, the
    integral is A/12·(3 + |(1,1,1)|²) = A/2 with A = √3/2 (a quadrature of the face agrees)."""
    v = np.eye(3)
    f = np.array([[0, 1, 2]])
    delta = 1e-7
    area = np.sqrt(3) / 2
    assert abs(_steiner_second_moment_bound(v, f, delta, np.zeros(3)) / (2 * delta * area / 2) - 1) < 1e-5
    # independent: a midpoint-rule quadrature of ∫|p|² dA over the face
    k = 400
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    keep = i + j < k - 1
    s, t = (i[keep] + 1 / 3) / k, (j[keep] + 1 / 3) / k
    p = v[0] + np.outer(s, v[1] - v[0]) + np.outer(t, v[2] - v[0])
    quad = np.mean(np.sum(p ** 2, axis=1)) * area
    assert abs(quad / (area / 2) - 1) < 5e-3
