"""Review 10 (issue 21, "certified answers"): an adversarial review of the bend bound, the clean-part fast path
and R0/R4's copy rules, by generators written apart from the code they judge.

* The bend bound (``hole_bounds.bend_doubt_volumes``, assumption ``bend``) on holes in the top of a closed
  height-field solid (a box whose top is ``z = g(x, y)`` on a grid: waves of random amplitude and frequency, with
  or without noise), turned at random, in mm, m or km, near or far from the origin.  Where the assumption holds
  (checked here: every removed face faces the fan's side and is no steeper against the rim's mean plane than the
  steepest face touching the rim), the cone patch must lie within the hole's bound against the exact closed
  solid, and every answered estimate within its stated bounds.  Where it fails on purpose (a pin or a pit: a
  vertex whose faces are all gone, raised or sunk; the rim shows no sign of it), an answer outside its bounds
  must name an assumption that a check of ``test_holes7_bend.py`` shows false.
* The clean-part fast path against the full path on parts that are barely clean or barely not: a corner moved
  onto another face's plane within a few ulps, coordinates scaled to the edge of the C filters' safe range, flat
  slivers near R7's margin, a corner pushed inward to the far side (or exactly onto it), a tiny turn far from the
  origin, a face split at a point a few ulps off it.  Any difference in result, certificate, warning or error is a
  defect (none was found: 4,163 cases of seeds 1000..1299 and 2000..5999).
* D2: a copy scaled by 1 + 100 ulp lies inside its copy without crossing it; R4's copy rule sees only crossing
  pairs, so the nesting depth makes it a cavity (honest label, absurd number).
* A defect found (D1): a vertex no face uses widens the extent the flatness rule (R2) and the units heuristic
  read, so a valid solid with one stray point far away is refused as "encloses no volume".
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from adversary_solids import box, cylinder, icosphere, torus
from test_batch7_fast_path import _check_both_ways
from test_hole_bounds import _holds
from test_holes7_bend import _grow, _named_assumption_fails, _rim
from inertia_tool.errors import InvalidMeshError
from inertia_tool.integrals import volume_moments
from inertia_tool.mass.pipeline import mass_properties
from inertia_tool.mesh.hole_bounds import bend_doubt_volumes
from inertia_tool.mesh.holes import patched_estimate
from inertia_tool.mesh.read import load_mesh
from inertia_tool.tolerances import ESTIMATE_MAX_MASS_RTOL


# ------------------------------------------------------------------------------------------ height fields
def _height_field(rng):
    """A closed outward solid: the unit square's grid (n × n) with top ``z = 1 + a sin(kx x + φ) cos(ky y)`` (plus
    noise half the time) over a flat bottom, side walls between; and ``n``."""
    n = int(rng.integers(6, 16))
    x = np.linspace(0.0, 1.0, n)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    amp, kx, ky, phase = rng.uniform(0, 0.3), rng.uniform(0, 8), rng.uniform(0, 8), rng.uniform(0, 6)
    gz = 1.0 + amp * np.sin(kx * gx + phase) * np.cos(ky * gy)
    if rng.random() < 0.5:
        gz = gz + rng.uniform(0, 0.02, size=gz.shape)
    top = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    bottom = top * [1.0, 1.0, 0.0]
    v = np.vstack([top, bottom])
    m = n * n
    idx = np.arange(m).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    faces = [np.stack([a, b, c], 1), np.stack([a, c, d], 1), np.stack([a, c, b], 1) + m, np.stack([a, d, c], 1) + m]
    ring = np.r_[idx[:, 0], idx[-1, 1:], idx[::-1, -1][1:], idx[0, ::-1][1:-1]]
    nxt = np.roll(ring, -1)
    faces += [np.stack([ring, ring + m, nxt], 1), np.stack([nxt, ring + m, nxt + m], 1)]
    f = np.vstack(faces)
    if volume_moments(v, f).volume < 0:
        f = f[:, ::-1].copy()
    return v, f


def _bend_holds(v, f, gone):
    """Whether ``bend`` holds for the one hole left by removing ``f[gone]`` (checked here, apart from the bound):
    every removed face faces the fan's side and is no steeper against the rim's mean plane than the steepest face
    touching the rim (a piecewise-linear graph's slope is its faces' ``tan`` of that angle)."""
    open_f = np.delete(f, gone, axis=0)
    edges, label, n_loops, _, apex = _rim(v, open_f)
    if n_loops != 1:
        return False
    a, b = v[edges[:, 0]] - apex[0], v[edges[:, 1]] - apex[0]
    normal = np.cross(a, b).sum(axis=0)
    normal /= np.linalg.norm(normal)
    ring = open_f[np.isin(open_f, np.unique(edges)).any(axis=1)]

    def cosines(tri):
        n = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
        return -(n @ normal) / np.linalg.norm(n, axis=1)

    lost = cosines(f[gone])
    return bool((lost > 0).all() and (lost >= cosines(ring).min() - 1e-12).all())


def _holed(seed, pin):
    """A height field turned and placed at random, less a patch of its top (a pin or pit on it when ``pin``):
    ``(v, f, gone)``, or None when the draw leaves no hole of that kind."""
    rng = np.random.default_rng(seed)
    v, f = _height_field(rng)
    inner = np.flatnonzero(np.all((v[f][:, :, :2] > 1e-9) & (v[f][:, :, :2] < 1 - 1e-9) & (v[f][:, :, 2:] > 0),
                                  axis=(1, 2)))
    if not len(inner):
        return None
    gone = _grow(f, int(rng.choice(inner)), int(rng.integers(1, max(2, len(inner) // 3))))
    gone = gone[np.isin(gone, inner)]
    if pin:
        interior = np.setdiff1d(np.unique(f[gone]), np.unique(np.delete(f, gone, axis=0)))
        if not len(interior):
            return None
        v = v.copy()
        v[int(rng.choice(interior)), 2] += float(rng.choice([-1, 1])) * rng.uniform(0.05, 0.9)
    scale = float(rng.choice([1e-3, 1.0, 1e3]))
    shift = rng.uniform(-1, 1, 3) * float(rng.choice([0.0, 1.0, 1e3])) * scale
    v = (v * scale) @ Rotation.from_quat(rng.normal(size=4)).as_matrix().T + shift
    return v, f, gone


def _estimate(v, open_f):
    """``patched_estimate`` as ``repair=True`` answers it, or None where it refuses."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = patched_estimate(v, open_f, volume_moments)
    if est.unbounded or not est.uncertainty.mass <= ESTIMATE_MAX_MASS_RTOL or not est.volume > 0:
        return None
    return est


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_bend_bound_holds_on_height_field_holes_where_the_assumption_holds(seed):
    case = _holed(seed, pin=False)
    if case is None:
        return
    v, f, gone = case
    truth = volume_moments(v, f)
    open_f = np.delete(f, gone, axis=0)
    if _bend_holds(v, f, gone):
        edges, label, n_loops, _, apex = _rim(v, open_f)
        doubt, _ = bend_doubt_volumes(v, open_f, edges, label, n_loops, apex)
        if np.isfinite(doubt[0]):           # the cone to the rim's centroid closing the open surface, exactly
            cap = np.c_[edges[:, 1], edges[:, 0], np.full(len(edges), len(v))]
            cone = volume_moments(np.vstack([v, apex]), np.vstack([open_f, cap]))
            assert abs(cone.volume - truth.volume) <= doubt[0], (seed, cone.volume, truth.volume, doubt[0])
    est = _estimate(v, open_f)
    if est is not None and not _holds(est, truth):
        assert not _bend_holds(v, f, gone) and _named_assumption_fails(v, f, gone, est), (seed, est.assumptions)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_a_pin_or_pit_taken_whole_is_inside_the_bound_or_names_a_false_assumption(seed):
    case = _holed(seed, pin=True)
    if case is None:
        return
    v, f, gone = case
    est = _estimate(v, np.delete(f, gone, axis=0))
    if est is None:
        return
    assert est.assumptions, est.detail
    if not _holds(est, volume_moments(v, f)):
        assert _named_assumption_fails(v, f, gone, est), (seed, est.assumptions, est.uncertainty.mass)


# ------------------------------------------------------------------------------- fast path, barely clean
def _barely(seed):
    """A small clean piece, then one mutation that leaves it barely clean or barely not (module docstring)."""
    rng = np.random.default_rng(seed)
    kind = ("box", "icosphere", "cylinder", "torus")[seed % 4]
    size = int(rng.integers(0, 3))
    v, f = {"box": lambda: box((1.0, 0.5 + 0.25 * size, 0.75), subdivide=size % 2),
            "icosphere": lambda: icosphere(0.7, size % 2),
            "cylinder": lambda: cylinder(0.4, 1.0, 5 + 3 * size),
            "torus": lambda: torus(0.6, 0.2, 8 + 2 * size, 5 + size)}[kind]()
    v, f = np.array(v, dtype=np.float64), np.array(f, dtype=np.int64)
    mutation = int(rng.integers(0, 6))
    if mutation == 0:                          # a corner onto another face's plane, ± a few ulps
        k, a = int(rng.integers(len(f))), int(rng.integers(len(v)))
        if a in f[k]:
            return v, f
        p = v[f[k]]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        target = rng.dirichlet([1.0, 1.0, 1.0]) @ p
        v[a] = target + n / np.linalg.norm(n) * int(rng.integers(-3, 4)) * np.spacing(np.abs(target).max())
    elif mutation == 1:                        # the C filters' safe range's edges (2^-240, 2^299)
        v = v * 2.0 ** float(rng.choice([-241.0, -238.0, 296.0, 297.0, 300.0]))
    elif mutation == 2:                        # a flat sliver near R7's margin
        v[:, 2] *= 10.0 ** -float(rng.uniform(5, 10))
        v = v + 10.0 ** float(rng.uniform(-2, 5))
    elif mutation == 3:                        # a corner pushed to the far side, or just short of it, or onto it
        a = int(rng.integers(len(v)))
        centre = v.mean(axis=0)
        t = float(rng.choice([0.999999999, 1.0, 1.000000001, 2.0, 1.0 - 2.0 ** -52]))
        reach = 0.5 * float((v.max(0) - v.min(0)).min()) / max(float(np.linalg.norm(centre - v[a])), 1e-300)
        v[a] = centre + (centre - v[a]) * t * reach
    elif mutation == 4:                        # a turn of ~1e-12 rad, far from the origin
        turn = Rotation.from_rotvec([0.0, 0.0, 1e-12 * rng.normal()]).as_matrix()
        v = v @ turn.T + np.array([1e6, -3e5, 7e4]) * rng.uniform(0.5, 2)
    else:                                      # a face split at a point a few ulps off it
        k = int(rng.integers(len(f)))
        p = v[f[k]]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        centre = p.mean(0) + n / np.linalg.norm(n) * int(rng.integers(-2, 3)) * np.spacing(np.abs(p).max())
        i = len(v)
        a, b, c = f[k]
        v = np.vstack([v, centre])
        f = np.vstack([np.delete(f, k, axis=0), [[a, b, i], [b, c, i], [c, a, i]]])
    return v, f


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1))
def test_fast_path_agrees_on_barely_clean_parts(seed):
    _check_both_ways(*_barely(seed))


# ---------------------------------------------------------------------------------------------- defects
def test_a_stray_vertex_no_face_uses_does_not_make_a_solid_flat():
    """D1 (review 10, fixed): the reader leaves out vertices no face uses (``read._used_vertices``), so R2's extent
    is the surface's; before, one unused vertex 1e5 m from a 1 × 2 × 3 m box made it "enclose no volume"."""
    v, f = box((1.0, 2.0, 3.0))
    v = np.vstack([v, [[1e5, 0.0, 0.0]]])
    props = mass_properties(load_mesh((v, f)), density=1.0)
    assert props.mass == pytest.approx(6.0, rel=1e-12)


def test_a_copy_scaled_by_a_hundred_ulps_is_not_read_as_its_own_cavity():
    """D2 (review 10, fixed): a copy scaled by 1 + 100 ulp nests inside its original without crossing it; R4's copy
    rule now reads nested pairs too (``policy.nested_copies``), so the pair is united, not a body and its cavity
    (before: 3.0e-14 m³ for 0.457 m³, labelled ``unverified``)."""
    v, f = icosphere(0.5, 1)
    v, f = np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)
    bigger = v * (1 + 100 * 2.0 ** -52)
    truth = volume_moments(bigger, f).volume
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            props = mass_properties((np.vstack([v, bigger]), np.vstack([f, f + len(v)])), density=1.0)
        except InvalidMeshError:
            return                                                  # a refusal would be honest too
    assert props.mass == pytest.approx(truth, rel=1e-9)
