"""Review 10 (issue 21): an estimate's bounds include the float64 round-off of integrating the estimated solid.

The round-off bound is the exact path's (:func:`inertia_tool.integrals.roundoff_bounds`, totalled by
:func:`~inertia_tool.integrals.total_roundoff_parts`), added by :func:`~inertia_tool.mesh.uncertainty.with_roundoff`.
Truths are exact rational integrals (:class:`fractions.Fraction`) of the surfaces as given.
"""

from __future__ import annotations


import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from adversary_solids import _outward_exactly, box, fraction_moments, icosphere, random_rotation, \
    repaired_estimate_errors, truth_from_pieces
from inertia_tool.integrals import body_volume_moments, roundoff_bounds, total_roundoff_parts


def _part(seed):
    """A box (whole or subdivided) or an icosphere, scaled 1 mm..10 m, turned at random, near the origin or up
    to 1e6 of its size away (integer offsets: the corners are the rounded rotation alone)."""
    rng = np.random.default_rng(seed)
    kind = int(rng.integers(3))
    if kind < 2:
        v, f = box(rng.uniform(0.2, 2.0, size=3), subdivide=kind)
    else:
        v, f = icosphere(float(rng.uniform(0.2, 1.0)), 1)
    far = 0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(0, 6)
    v = (v * 10.0 ** rng.uniform(-3, 1)) @ random_rotation(rng).T + np.round(rng.normal(size=3) * far)
    return rng, v, _outward_exactly(v, f)


@settings(max_examples=25, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_integration_roundoff_bound_holds_against_rationals(seed):
    """The new term on its own: the float64 moments of a turned, far-off part against its exact rational ones,
    volume, centroid (the new first-order centroid term) and central inertia, each within its part."""
    _, v, f = _part(seed)
    labels = np.zeros(len(f), dtype=np.int64)
    origin = 0.5 * (v.min(axis=0) + v.max(axis=0))
    shells = body_volume_moments(v, f, labels, 1, origin=origin)
    bound_volume, bound_centroid, bound_inertia = total_roundoff_parts(
        shells, roundoff_bounds(v, f, labels, shells, origin))
    vol, first, second = fraction_moments(v, f)
    centroid = [x / vol for x in first]
    central = np.array([[float(second[r][q] - vol * centroid[r] * centroid[q]) for q in range(3)] for r in range(3)])
    inertia = np.trace(central) * np.eye(3) - central
    got = shells[0]
    got_inertia = np.trace(got.second_moment) * np.eye(3) - got.second_moment
    assert abs(got.volume - float(vol)) <= bound_volume * abs(float(vol)) * (1 + 1e-6) + 1e-300
    assert np.linalg.norm(got.centroid - np.array([float(x) for x in centroid])) <= bound_centroid * (1 + 1e-6)
    assert np.linalg.norm(got_inertia - inertia) <= bound_inertia * np.linalg.norm(inertia) * (1 + 1e-6) + 1e-300


@settings(max_examples=20, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_estimate_with_a_lost_face_is_within_its_bounds(seed):
    """A part with one face lost, filled (``repair``) and answered as an estimate: mass, centre of mass and
    inertia within the stated bounds of the exact rational truth of the part as it was.  (Review 10 searched
    1,800 such draws for one the bounds without the round-off term miss and found none: the holes' 16-ulp slab
    left at least 14× room; the term is there because the bound must not rest on that slack.)"""
    rng, v, f = _part(seed)
    truth = truth_from_pieces([(1, (v, f))])
    judged = repaired_estimate_errors(v, np.delete(f, rng.integers(len(f)), axis=0), truth)
    if judged is None:
        return                                           # refused with a reason: no number to judge
    (dvol, dcom, din), unc = judged
    assert dvol <= unc.mass and dcom <= unc.center_of_mass and din <= unc.inertia, (dvol, dcom, din, unc)
