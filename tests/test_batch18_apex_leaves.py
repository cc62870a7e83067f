"""The C face-pair scan's leaf pairs against a leaf whose faces all hold one certified big-star vertex (``_accel.c``
section 8, ``ct_traverse``; issue 25 item 6, batch18).

A fan-capped cylinder's hierarchy has leaves holding only cap slivers (their apex: the cap's centre, a certified
star of every cap face) and a few leaves mixing slivers with the wall faces beside them.  In a leaf pair where one
leaf has an apex, the other leaf's faces holding it are taken out of the pair's masks at once: every pair they
would make lies within that certified star, which the scan leaves out uncounted face by face anyway.  So the pairs
found, their kinds and the counts must be what they were: checked here against the numpy twin (an independent
enumeration and certification, no leaves, no apexes) pair for pair, and the C scan without patches against the
numpy twin's counts, on cylinders turned and moved at random, whole or with one defect the scan must report (a
wall corner pushed through the cap, a cap centre lifted off its plane, a sliver folded onto its neighbour).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from contact_scans import fan_capped_cylinder, run_scan, same_pairs

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def _turned(v: np.ndarray, seed: int, offset: float) -> np.ndarray:
    """``v`` turned by a random proper rotation (QR of a Gaussian matrix) and moved by ``offset`` on each axis."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return v @ q.T + offset


def _defect(v: np.ndarray, f: np.ndarray, n: int, kind: str, at: int) -> tuple[np.ndarray, np.ndarray]:
    """One defect near section ``at`` of a cylinder of ``n`` sections from :func:`fan_capped_cylinder`."""
    v = v.copy()
    if kind == "pierce":              # a top ring vertex pushed down through the bottom cap
        v[n + at] = [0.5 * v[at][0], 0.5 * v[at][1], -0.3]
    elif kind == "lift":              # the bottom cap's centre off its plane: a cone, no longer a flat fan
        v[2 * n] = [0.0, 0.0, 0.05]
    elif kind == "fold":              # a bottom rim vertex moved onto the cap's centre side: slivers overlap
        v[at] = [0.2 * v[at][0] - 0.3 * v[(at + 1) % n][1], 0.2 * v[at][1] + 0.3 * v[(at + 1) % n][0], 0.0]
    return v, f


def _scans_agree(v, f):
    """The C scan with and without patches against the numpy twin: the same pairs, and the unpatched scan counts
    what the twin counts; returns the patched scan."""
    fast = run_scan(v, f, accel=True)
    unpatched = run_scan(v, f, accel=True, _patches=False)
    ref = run_scan(v, f, accel=False)
    same_pairs(fast, ref)
    same_pairs(unpatched, ref)
    assert (unpatched.candidate_pairs, unpatched.tested_pairs) == (ref.candidate_pairs, ref.tested_pairs)
    return fast


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(sections=st.integers(16, 160), radius=st.floats(0.5, 40.0), height=st.floats(0.5, 90.0),
       seed=st.integers(0, 2**31 - 1), offset=st.floats(-20.0, 20.0),
       kind=st.sampled_from(["none", "lift"]), at=st.integers(0, 10_000))
def test_cylinders_find_what_the_numpy_twin_finds(sections, radius, height, seed, offset, kind, at):
    v, f = fan_capped_cylinder(sections, radius=radius, height=height)
    v, f = _defect(v, f, sections, kind, at % sections) if kind != "none" else (v, f)
    v = _turned(v, seed, offset)
    fast = _scans_agree(v, f)
    if kind == "none":                # a closed cylinder meets itself nowhere but where faces share corners
        assert not len(fast.crossing) and not len(fast.coplanar_opposite)


@pytest.mark.parametrize("kind", ["pierce", "fold"])
def test_cylinders_with_a_defect_report_it_as_the_numpy_twin_does(kind):
    """A wall corner pushed through the cap, or a rim vertex folding two slivers over each other: pairs the
    scan must report, as the numpy twin does."""
    v, f = _defect(*fan_capped_cylinder(48, radius=3.0, height=5.0), 48, kind, 7)
    v = _turned(v, 7, 3.0)
    fast = run_scan(v, f, accel=True)
    ref = run_scan(v, f, accel=False)
    same_pairs(fast, ref)
    assert len(fast.crossing) + len(fast.coplanar_opposite) > 0


@pytest.mark.parametrize("sections", [300, pytest.param(1076, marks=pytest.mark.slow)])
def test_catalogue_sized_cylinders_match_the_unpatched_scan_and_the_twin(sections):
    """Sizes of the batch catalogue's cylinders (up to 1,200 sections; in a numpy model of the hierarchy's Morton
    order, 13 of the 269 leaves of trimesh's 1,076-section cylinder mix cap slivers with wall faces); the numpy twin
    counts what the unpatched C scan counts."""
    v, f = fan_capped_cylinder(sections, radius=17.0, height=42.0)
    v = _turned(v, sections, 55.0)
    fast = _scans_agree(v, f)
    assert not len(fast.crossing) and not len(fast.coplanar_opposite)
