"""Review19's count (issue 21) on main 12f5892: what it found, pinned.

- ``bench_adversarial.py --seed 2603 --case 1422``: a ball around a cavity, the whole nest listed twice, the ball's
  copy exact and the cavity's copy rounded apart.  R0 counted the exact repeat twice and the copy up to rounding
  once (``near_copies`` left it out without counting it), so the file's winding inside the cavity (2 − 2 = 0) was
  read as 1: the cavity was left out as a shell "with winding at least one on both sides" and the ball answered
  ``exact``, 2.1 % heavy.  A copy up to rounding now counts as the exact repeat it stands for
  (``shells._with_near_copies``).
"""

import numpy as np
import pytest

from adversary_solids import KINDS, concat, flipped, icosphere, judge, make_case, silent
from inertia_tool import mass_properties


def _rounded_apart(v):
    """``v`` computed apart: ``(v + c) − c``, equal up to rounding, and not equal (asserted)."""
    c = np.array([3.7, -2.9, 1.3])
    copy = (v + c) - c
    assert np.any(copy != v) and np.abs(copy - v).max() < 1e-15
    return copy


def _listed(piece, exact: int, rounded: int):
    """``piece`` listed ``1 + exact`` times bit for bit (its own vertices) and ``rounded`` times rounded apart."""
    v, f = piece
    return [(v.copy(), f)] * (1 + exact) + [(_rounded_apart(v), f)] * rounded


@pytest.mark.parametrize("outer, inner", [((1, 0), (0, 1)),     # the case found: the ball exact, the cavity rounded
                                          ((0, 1), (1, 0)),     # the other way round
                                          ((0, 1), (0, 1)),     # both rounded apart
                                          ((1, 1), (0, 2)),     # the ball three times, the cavity three times
                                          ((1, 0), (0, 0)),     # the ball twice, the cavity once: the ball (R0)
                                          ((0, 0), (0, 1))])    # the cavity twice: winding −1, depth: the hollow ball
def test_copies_up_to_rounding_count_as_repeats(outer, inner):
    ball = icosphere(1.0, 1)
    cavity = flipped(icosphere(0.3, 1))
    pieces = _listed(ball, *outer) + _listed(cavity, *inner)
    v, f = concat(*pieces)
    k_ball, k_cavity = 1 + sum(outer), 1 + sum(inner)
    once = mass_properties(concat(ball, cavity), density=1.0)
    alone = mass_properties(ball, density=1.0)
    # R0 counts each surface as often as it is listed; inside the cavity the winding is k_ball − k_cavity: the
    # file's solid is the ball alone where that is ≥ 1, the hollow ball where it is 0, and the hollow ball by
    # depth (R4) where it is below 0
    want = alone if k_ball - k_cavity >= 1 else once
    got = mass_properties((v, f), density=1.0)
    assert got.mesh.certificate.kind in ("exact", "united")
    assert abs(got.volume - want.volume) <= 1e-12 * want.volume
    assert np.linalg.norm(got.inertia - want.inertia) <= 1e-12 * np.linalg.norm(want.inertia)


def test_seed_2603_case_1422():
    """The reproducer as ``bench_adversarial.py`` draws it (``KINDS[i % 17]``, ``default_rng([seed, i])``): judged
    against its exact rational truth, right and ``exact`` (2.1 % heavy, ``exact``, before)."""
    assert KINDS[1422 % len(KINDS)] == "duplicated"
    case = make_case("duplicated", np.random.default_rng([2603, 1422]))
    verdict = judge(case)
    assert not silent(verdict), verdict
    assert verdict.label == "exact"
