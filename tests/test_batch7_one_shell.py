"""``integrals.one_shell_moments`` (the clean-part fast path's integrals, issue 25 item 6) against the general
functions it stands in for: the moments bit for bit those of ``body_volume_moments``, and its two decisions (would
``accurate_shells`` integrate the shell again? is ``total_roundoff`` within ``ROUNDOFF_RTOL``?) never accepting
what the general path does not, and declining only within their margin of the boundary."""

from __future__ import annotations

import math
import struct

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from adversary_solids import box, cylinder, icosphere, random_rotation, torus
from inertia_tool import integrals
from inertia_tool.integrals import accurate_shells, body_volume_moments, bounding_box, one_shell_moments, \
    roundoff_bounds, total_roundoff
from inertia_tool.tolerances import ROUNDOFF_RTOL

MARGIN = 1e-6


def _bits(shell):
    return (struct.pack("<d", shell.volume), shell.centroid.tobytes(), shell.second_moment.tobytes(),
            struct.pack("<d", shell.area), shell.zero_area_faces)


def _refine_ratio(v, f, labels, shells, origin):
    """How far ``accurate_shells``' one-shell test is from refining: its larger share over its budget (> 1:
    refined), from the general functions themselves."""
    b = roundoff_bounds(v, f, labels, shells, origin)
    share_v, share_i, total_v, total_i = integrals._shares(shells, b.volume, b.centroid, b.second_moment,
                                                           magnitude=True)
    if not (np.isfinite(total_v) and total_v != 0 and total_i != 0):
        return 0.0
    budget = 0.5 * ROUNDOFF_RTOL
    return max(float(share_v[0]) / (budget * total_v), float(share_i[0]) / (budget * total_i))


@st.composite
def shells(draw):
    kind = draw(st.sampled_from(("box", "icosphere", "cylinder", "torus")))
    v, f = {"box": lambda: box((1.0, 0.7, 0.4), subdivide=draw(st.integers(0, 1))),
            "icosphere": lambda: icosphere(0.5, draw(st.integers(0, 1))),
            "cylinder": lambda: cylinder(0.3, 1.0, draw(st.integers(3, 24))),
            "torus": lambda: torus(0.5, 0.15, 10, 6)}[kind]()
    scale = 10.0 ** draw(st.floats(-6, 3))
    thin = 10.0 ** -draw(st.floats(0, 13))                  # down to slivers R7 integrates again
    offset = 10.0 ** draw(st.floats(-3, 8)) * draw(st.sampled_from((0.0, 1.0, -1.0)))
    v = v * np.array([1.0, 1.0, thin]) * scale
    if draw(st.booleans()):                                 # turned: a thin slab's corners no longer exact
        v = v @ random_rotation(np.random.default_rng(draw(st.integers(0, 2**32 - 1)))).T
    v = v + np.array([offset, 0.5 * offset, -offset])
    return np.ascontiguousarray(v), np.ascontiguousarray(f)


@settings(max_examples=40, deadline=None)
@given(shells())
@example((box((1.0, 1.0, 1e-8))[0] @ random_rotation(np.random.default_rng(0)).T + 77.0, box((1.0, 1.0, 1e-8))[1]))
@example(box((1.0, 2.0, 3.0)))
def test_one_shell_moments_agrees_with_the_general_functions(mesh):
    v, f = mesh
    lo, hi = bounding_box(v)
    centre = 0.5 * (lo + hi)
    labels = np.zeros(len(f), dtype=np.intp)
    with np.errstate(all="ignore"):
        general = body_volume_moments(v, f, labels, 1, origin=centre)
        kept, refined, bound = accurate_shells(v, f, labels, general, centre)
        ratio = _refine_ratio(v, f, labels, general, centre)
        total = total_roundoff(kept, bound)
        got = one_shell_moments(v, f, centre, (lo, hi), rtol=ROUNDOFF_RTOL, margin=MARGIN)
    if got is None:                                 # declined: R7 refines it, or it is within the margin of doing so
        assert refined or not ratio <= 1 - 2 * MARGIN or not (abs(general[0].volume) > 0)
        return
    shell, within = got
    assert _bits(shell) == _bits(general[0])
    assert refined == 0 and _bits(kept[0]) == _bits(shell)          # accepted: accurate_shells keeps it as it is
    if within:
        assert total <= ROUNDOFF_RTOL
    else:
        assert not total <= ROUNDOFF_RTOL * (1 - 2 * MARGIN)


def test_a_sliver_is_declined_and_a_box_is_not():
    """Not vacuous: a thin turned slab is one R7 integrates again; a box is kept, within rtol."""
    v, f = box((1.0, 1.0, 1e-8))
    v = v @ random_rotation(np.random.default_rng(0)).T + 77.0
    lo, hi = bounding_box(v)
    labels = np.zeros(len(f), dtype=np.intp)
    assert accurate_shells(v, f, labels, body_volume_moments(v, f, labels, 1, origin=0.5 * (lo + hi)),
                           0.5 * (lo + hi))[1] == 1
    assert one_shell_moments(v, f, 0.5 * (lo + hi), (lo, hi)) is None
    v, f = box((1.0, 2.0, 3.0))
    lo, hi = bounding_box(v)
    got = one_shell_moments(v, f, 0.5 * (lo + hi), (lo, hi))
    assert got is not None and got[1] and math.isclose(got[0].volume, 6.0, rel_tol=1e-15)
