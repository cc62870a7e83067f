"""Adversarial review 7 (issue 21, target 4: zero silent wrong answers) of the rules the last sessions added.

* the fourth hole assumption (``mesh/holes.py``, :func:`~inertia_tool.mesh.holes.convex_hole_bound`): where what
  remains of a surface with holes is convex, the part is taken to be convex too;
* R3b through T-vertices (``mesh/sheets.py``, ``_seamed_sheet``): a cut face kept inside a part whose rim meets
  the other half only at T-vertices;
* R4's reading of a body wound outward wholly inside another (``mesh/certify.py``, ``misread_reading``): exact
  when the turned surface is proven, else an estimate whose bounds span both readings;
* real files (trimesh's models, Gazebo's and Menagerie's meshes, when present on this machine) with random
  damage that keeps the solid, checked against the undamaged file's exact values.

Truths come from code independent of the rule under test: exact rationals over the intended solid's
tetrahedra (``adversary_solids.truth_from_pieces``), manifold3d's booleans, or the undamaged file's exact
integral.  The rule is the one of ``tests/test_adversarial_solids.py``: an answer labelled ``exact`` or
``united`` within 1e-9 of the truth, an ``estimate`` within its own bounds, or a refusal.  Failures found are
kept below as strict-xfail reproducers whose reason names the rule at fault.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adversary_solids as S

FAST = settings(max_examples=10, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def _verdict(v, f, truth, recipe="", repair=False):
    """The adversarial harness's verdict on ``(v, f)`` against ``truth`` (an ``adversary_solids.Truth``)."""
    case = S.Case("review7", np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64), truth, recipe)
    return S.judge_truth(case, truth, repair=repair)


def _assert_honest(verdict, recipe=""):
    assert verdict.label != "crashed", f"{recipe}: {verdict.wrong}"
    assert not S.silent(verdict), f"silent wrong answer ({verdict.label}) on {recipe}: {verdict.wrong}"
    return verdict


# -------------------------------------------------------------------- the fourth hole assumption (convex)
def _dented_sphere(subdivisions, depth):
    """An icosphere of radius 1 whose vertex 0 is pushed in by ``depth`` (a dent, the part no longer convex), and
    the same surface with the dent's faces (vertex 0's ring) removed: what remains is convex."""
    v, f = S.icosphere(1.0, subdivisions)
    v = v.copy()
    v[0] *= 1.0 - depth
    truth = S.truth_from_pieces([(1, (v, f))])
    return v, f[~np.any(f == 0, axis=1)], truth


@pytest.mark.xfail(strict=True, reason="convex_hole_bound (fourth hole assumption): a dent taken whole by the hole "
                   "on a convex remainder; the ball bound (first assumption) held, the convex one replaces it and "
                   "misses the truth")
def test_a_dent_taken_whole_stays_inside_the_convex_hole_bound():
    """Icosphere (3 subdivisions, radius 1) with one vertex pushed in by 0.05 (a dimple 5 % of the radius deep,
    inside the ball over its rim) and the dimple's six faces removed.  The rest is convex, so the fourth
    assumption takes the part to be convex: stated ±5.7e-5 of the mass, found 1.47e-4 off (centre of mass
    1.44e-4 m off, bound 5.8e-5 m).  Without the convex bound the ball bound, ±9.7e-4, holds."""
    v, f, truth = _dented_sphere(3, 0.05)
    _assert_honest(_verdict(v, f, truth, "icosphere(3) dented 0.05 at vertex 0, dent's ring removed", repair=True))


@FAST
@given(seed=st.integers(0, 2 ** 32 - 1), share=st.floats(0.02, 0.4))
def test_holes_in_a_convex_part_stay_inside_the_convex_hole_bound(seed, share):
    """Where the fourth assumption holds (the part is convex: a random polytope, moved at random), the bound
    holds: a connected patch of faces removed (up to 40 % of them), repair=True, truth the closed polytope."""
    from solids import random_convex

    solid = random_convex(seed % 100_000, n=int(10 + seed % 40))
    v, f = solid.vertices, solid.faces
    rng = np.random.default_rng(seed)
    truth = S.truth_from_pieces([(1, (v, f))])
    patch = _patch(f, int(rng.integers(len(f))), max(1, int(share * len(f))))
    keep = np.ones(len(f), dtype=bool)
    keep[patch] = False
    _assert_honest(_verdict(v, f[keep], truth, f"random_convex({seed}) less {len(patch)} faces", repair=True))


def _patch(f, start, size):
    """Up to ``size`` faces grown breadth-first from ``start`` through shared edges (indices into ``f``)."""
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(f)), 3)
    by_edge: dict[tuple[int, int], list[int]] = {}
    for (a, b), o in zip(edges.tolist(), owner.tolist()):
        by_edge.setdefault((a, b), []).append(o)
    neighbours: list[list[int]] = [[] for _ in range(len(f))]
    for faces in by_edge.values():
        for x in faces:
            neighbours[x].extend(y for y in faces if y != x)
    seen, queue = {start}, [start]
    for face in queue:                                # grows to at most len(f)
        if len(seen) >= size:
            break
        for n in neighbours[face]:
            if n not in seen and len(seen) < size:
                seen.add(n)
                queue.append(n)
    return np.array(sorted(seen), dtype=np.int64)
