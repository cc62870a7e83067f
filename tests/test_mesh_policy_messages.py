"""The points R0 and R3 name in their messages (``policy.point_text``): told within a thousandth of the part's size,
however far from the origin the part lies (issue 21: ``:.6g`` named a 1 mm part 1e8 m out to the nearest km)."""

from __future__ import annotations

import re

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import adversary_solids as S
from inertia_tool.mesh.multiplicity import coincident_surfaces
from inertia_tool.mesh.policy import ShellContacts, coincident_message, part_size, self_crossing_message

_POINT = re.compile(r"near \(([^,]+), ([^,]+), ([^)]+)\) m")


def _named(message: str) -> np.ndarray:
    found = _POINT.search(message)
    assert found, message
    return np.array([float(x) for x in found.groups()])


parts = dict(size=st.floats(1e-6, 10.0), far=st.floats(0.0, 1e9), direction=st.tuples(*[st.floats(-1, 1)] * 3),
             stretch=st.tuples(*[st.floats(0.05, 1.0)] * 3))


@settings(max_examples=40, deadline=None)
@given(**parts)
def test_the_crossing_named_is_told_within_the_part(size, far, direction, stretch):
    """R3's refusal names the centre of the first crossing face pair; read back from the message it lies within
    1e-3 of the part's size of the true centre, for parts from 1 µm to 10 m up to 1e9 m out."""
    d = np.array(direction)
    offset = far * d / max(np.linalg.norm(d), 1e-12)
    v, f = S.box(size * np.array(stretch), offset)
    assume(size * min(stretch) > 1e3 * np.spacing(far))         # a box its coordinates can still tell
    pair = np.array([[0, len(f) // 2 + 1]])
    found = ShellContacts(self_crossing=np.array([True]), self_crossing_pairs=1, crossing=np.array([False]),
                          crossing_with=np.zeros((0, 2), dtype=np.int64), touching=np.array([False]), complete=True)
    message = self_crossing_message("<part>", found, v, f, pair, np.zeros(len(f), dtype=np.int64))
    truth = v[f[pair[0]]].reshape(-1, 3).mean(axis=0)
    assert np.all(np.abs(_named(message) - truth) <= 1e-3 * part_size(v, f)), (message, truth)


@settings(max_examples=25, deadline=None)
@given(**parts)
def test_the_copy_named_is_told_within_the_part(size, far, direction, stretch):
    """R0's note names a corner of the first surface left out (a box listed twice): read back, within 1e-3 of the
    part's size of that corner."""
    d = np.array(direction)
    offset = far * d / max(np.linalg.norm(d), 1e-12)
    v, f = S.box(size * np.array(stretch), offset)
    assume(size * min(stretch) > 1e3 * np.spacing(far))         # a box its coordinates can still tell
    v2, f2 = S.concat((v, f), (v, f))
    found = coincident_surfaces(v2, f2)
    assert found.repeated == 1
    message = coincident_message(found, part_size(v2, f2))
    assert np.all(np.abs(_named(message) - found.where) <= 1e-3 * part_size(v2, f2)), (message, found.where)
