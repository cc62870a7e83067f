"""R2's flat rule (``shells.drop_flat``, review 12's R7) decided by each shell's own round-off budget when the
diagonal's scale calls every shell flat: needles and plates of aspect 1..1e8, turned and moved, against the exact
rational integrals of the coordinates as written (``review12_generators.rational_moments``); a flat sheet and a
collapsed sliver are still refused as enclosing no volume."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, reject, settings
from hypothesis import strategies as st

import review12_generators as G
from adversary_solids import box
from inertia_tool import mass_properties
from inertia_tool.errors import InertiaToolError, InvalidMeshError


def _answer(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mass_properties((vertices, faces), density=1.0)


def _dims(length: float, aspect: float, needle: bool) -> tuple[float, float, float]:
    return (length / aspect, length / aspect, length) if needle else (length, length, length / aspect)


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(length=st.floats(1e-3, 1e2), log_aspect=st.floats(0.0, 8.0), needle=st.booleans(),
       turned=st.booleans(), far=st.sampled_from([0.0, 1.0, 1e3]), seed=st.integers(0, 2 ** 32 - 1))
def test_needles_and_plates_are_never_silently_wrong(length, log_aspect, needle, turned, far, seed):
    """A box ``length`` long, ``length / aspect`` across (needle) or thick (plate), turned by a random rotation
    and placed ``far`` m out or not: a proven label holds to the judge's tolerances against the exact integrals
    of the coordinates as written, an estimate within its bounds; a refusal may not say "no volume" (the thinnest,
    1e-11 m at 1e3 m out, is still 100 float64 spacings thick)."""
    rng = np.random.default_rng(seed)
    v, f = box(_dims(length, 10.0 ** log_aspect, needle))
    if turned:
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        v = v @ q.T
    v = v + rng.uniform(-1, 1, 3) * far
    try:
        truth = G.rational_moments([tuple(p) for p in v.tolist()], [list(t) for t in f.tolist()])
    except ZeroDivisionError:               # the offset's rounding collapsed it: the coordinates enclose nothing
        reject()
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    try:
        props = _answer(v, f)
    except InertiaToolError as exc:
        # every box here is thousands of roundings thick: "no volume" would be false
        assert "no volume" not in str(exc), (str(exc), truth.volume)
        return
    verdict = G.judge_numbers(props.mesh.certificate.kind, props.mass, props.center_of_mass, props.inertia,
                              props.mesh.uncertainty, truth, diag)
    assert not verdict.silent, verdict


@pytest.mark.parametrize("needle", [True, False], ids=["needle", "plate"])
@pytest.mark.parametrize("aspect", [1e2, 1e4, 1e6, 1e8])
def test_an_axis_aligned_needle_or_plate_is_exact(needle, aspect):
    """At the origin, axis-aligned, every coordinate exact: the answer is the box's closed form, labelled exact
    (the needles of aspect 1e6 and more were refused as "no volume" before)."""
    a, b, c = _dims(1.0, aspect, needle)
    props = _answer(*box((a, b, c)))
    assert props.mesh.certificate.kind == "exact"
    assert props.mass == pytest.approx(a * b * c, rel=1e-12)
    expected = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * a * b * c / 12.0
    np.testing.assert_allclose(props.inertia, expected, rtol=1e-9, atol=1e-12 * float(expected.max()))


@pytest.mark.parametrize("dims", [(1.0, 1.0, 0.0), (1e-6, 0.0, 1.0)], ids=["sheet", "line"])
def test_a_surface_without_volume_is_still_refused(dims):
    """Zero thickness: every face has its reverse (the volume is 0 to the bit): refused as before."""
    with pytest.raises(InvalidMeshError, match="encloses no volume"):
        _answer(*box(dims))


@pytest.mark.parametrize("lift", [1e-17, 1e-300])
def test_a_sliver_flat_up_to_rounding_is_still_refused(lift):
    """A unit square sheet with one corner lifted by less than the float64 rounding of a coordinate near 1 m
    (1.1e-16): the lift could be rounding of a flat surface, so it encloses no volume up to round-off: refused."""
    v, f = box((1.0, 1.0, 0.0))
    v = v.copy()
    v[np.argmax(v.sum(axis=1)), 2] = lift
    with pytest.raises(InvalidMeshError, match="encloses no volume"):
        _answer(v, f)


def test_a_sliver_lifted_beyond_rounding_keeps_its_volume():
    """The same sheet lifted by 1e-12 m (4,500 times the rounding): a real wedge of 1e-12 / 3 m³, exact, though
    only 1.2e-13 of diagonal³ (the old rule's scale called it flat)."""
    v, f = box((1.0, 1.0, 0.0))
    v = v.copy()
    v[np.argmax(v.sum(axis=1)), 2] = 1e-12
    truth = G.rational_moments([tuple(p) for p in v.tolist()], [list(t) for t in f.tolist()])
    props = _answer(v, f)
    assert props.mesh.certificate.kind == "exact"
    assert props.mass == pytest.approx(abs(truth.volume), rel=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_a_turned_sheet_is_refused(seed):
    """A zero-thickness square turned by a random rotation: its corners are rounded off the plane, and the
    volume that encloses is within its budget: refused as before."""
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    v, f = box((1.0, 0.5, 0.0))
    with pytest.raises(InvalidMeshError, match="encloses no volume"):
        _answer(v @ q.T + 0.25, f)
