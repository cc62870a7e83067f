"""The face-pair check's high point (issue 25, ``check7``): it set the analysis's peak at 1.50x the file at 1e7
faces.  The C scan (``_accel.c`` section 8) now

* builds the faces across each edge (the twins) in rounds over ranges of vertices (``ct_twins``), each round
  listing the faces of its own vertices only (``INERTIA_TOOL_CT_TWIN_ROUNDS`` sets the count, for these tests);
* gives back the pages of arrays whose content is dead until a later phase writes them again (the sort words
  after the order is unpacked, the positions after the twins, the twins' block kept for the boxes);
* keeps no corner indices by hierarchy position for the traversal: each traversal reads the corner indices of
  the two leaves it is at from the caller's faces, through the order (``CtIdCache``), and the per-face star
  bits and leaf apexes are made where the boxes are.

None of this may change an answer.  Independent truths: the same call with one round and unpoisoned blocks (the
build before this change computed exactly that), the numpy twin (a grid broad phase and numpy predicates: the
same pairs and classes), and a brute force over all pairs for the small meshes.  The meshes exercise every
branch of the twins: closed fans, a fan of more than 64 faces (matched by sorting), edges in three faces and a
face holding one vertex twice (no twins there), and vertex numberings unrelated to the geometry (each round's
vertices then lie everywhere on the surface).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool import _native
from inertia_tool.mesh.intersect import surface_contacts
from intersect_reference import pair_kinds, brute_kind
from test_mesh_intersect_layout import _PEAK_CHILD  # the same 300,000-face torus child as its peak test

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")

ROUNDS = "INERTIA_TOOL_CT_TWIN_ROUNDS"
POISON = "INERTIA_TOOL_CT_POISON"
FIELDS = ("crossing", "coplanar_opposite", "contact", "complete", "candidate_pairs", "tested_pairs",
          "exact_evaluations", "degenerate_faces")


def _fields(r):
    return tuple(np.asarray(getattr(r, k)).tolist() for k in FIELDS)


def _run(v, f, env: dict[str, str | None] | None = None, **kwargs):
    """surface_contacts under the given environment (None: variable unset)."""
    with pytest.MonkeyPatch.context() as mp:
        for key in (ROUNDS, POISON, _native.NO_ACCEL_ENV):
            mp.delenv(key, raising=False)
        for key, value in (env or {}).items():
            if value is not None:
                mp.setenv(key, value)
        return surface_contacts(v, f, **kwargs)


def _torus(n_major: int, n_minor: int, major: float = 50.0, minor: float = 20.0):
    u = 2 * np.pi * np.arange(n_major) / n_major
    w = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = major + minor * np.cos(ww)
    v = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a, b = i * n_minor + j, ((i + 1) % n_major) * n_minor + j
    c, d = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor, i * n_minor + (j + 1) % n_minor
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.int32)


def _crossing_tori():
    """Two tori of 6,400 faces each crossing near their rims: crossing pairs found."""
    v, f = _torus(80, 40)
    return np.concatenate([v, v + [135.0, 0.5, 0.25]]), np.concatenate([f, f + len(v)]).astype(np.int32)


def _capped_cylinder_with_defects(sections: int = 100):
    """A cylinder with fan caps of ``sections`` faces round each centre (the twins' sorted path: more than 64
    faces at one vertex), one side face repeated (its edges then in three faces) and one face holding a
    corner twice (no twins at that vertex)."""
    t = 2 * np.pi * np.arange(sections) / sections
    ring = np.stack([np.cos(t), np.sin(t)], axis=1) * 10.0
    v = np.concatenate([np.c_[ring, np.zeros(sections)], np.c_[ring, np.full(sections, 30.0)],
                        [[0.0, 0.0, 0.0], [0.0, 0.0, 30.0]]])
    k = np.arange(sections)
    k1 = (k + 1) % sections
    bottom, top = 2 * sections, 2 * sections + 1
    f = np.concatenate([np.stack([k, k1, k1 + sections], 1), np.stack([k, k1 + sections, k + sections], 1),
                        np.stack([np.full(sections, bottom), k1, k], 1),
                        np.stack([np.full(sections, top), k + sections, k1 + sections], 1)])
    f = np.concatenate([f, f[3:4], [[5, 5, 40]]])
    return v, f.astype(np.int32)


def _shuffled_torus(seed: int = 7):
    """A torus whose vertex numbers are a random permutation: each round's range of vertices is scattered."""
    v, f = _torus(90, 40)
    perm = np.random.default_rng(seed).permutation(len(v))
    w = np.empty_like(v)
    w[perm] = v
    return w, perm[f].astype(np.int32)


MESHES = {"crossing tori": _crossing_tori, "capped cylinder, defects": _capped_cylinder_with_defects,
          "shuffled torus": _shuffled_torus}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_twins_in_rounds_give_every_field_of_one_round(name):
    """Every field of surface_contacts is the same for 1, 2, 3, 5 and 64 rounds of twins (more rounds than some
    ranges have vertices), with blocks poisoned (0xA5: a read before a write would show) and int64 faces."""
    v, f = MESHES[name]()
    one = _fields(_run(v, f, {ROUNDS: "1"}))
    for rounds in ("2", "3", "5", "64"):
        assert _fields(_run(v, f, {ROUNDS: rounds})) == one, rounds
    assert _fields(_run(v, f, {ROUNDS: "3", POISON: "1"})) == one
    assert _fields(_run(v, f.astype(np.int64), {ROUNDS: "5", POISON: "1"})) == one
    # the numpy twin (grid broad phase, numpy predicates) finds the same pairs, and so does the C scan without
    # patches, whose candidate and tested counts are then the twin's (its exact evaluations are its own)
    numpy_twin = _fields(_run(v, f, {_native.NO_ACCEL_ENV: "1"}))
    unpatched = _fields(_run(v, f, {ROUNDS: "3"}, _patches=False))
    assert numpy_twin[:4] == one[:4]
    assert unpatched[:6] + unpatched[7:] == numpy_twin[:6] + numpy_twin[7:]


def test_the_meshes_reach_the_branches_they_are_for():
    """The fixtures are what the docstring says: crossing pairs found on the crossing tori, a vertex of more
    than 64 faces and a face with a repeated corner on the cylinder."""
    assert len(_run(*_crossing_tori()).crossing)
    v, f = _capped_cylinder_with_defects()
    assert np.bincount(f.ravel()).max() > 64
    assert np.any((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2]))


@st.composite
def small_meshes(draw):
    """20-60 faces: corners on a small lattice (exact touches, shared and repeated corners), vertex numbers in
    random order, some faces repeated or reversed (edges in three faces, misoriented pairs)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(6, 30))
    m = draw(st.integers(20, 50))
    v = rng.integers(0, draw(st.sampled_from([2, 3, 6])) + 1, (n, 3)).astype(float)
    first = rng.integers(0, n, m)
    near = np.argsort(np.abs(v[:, None, :] - v[None, :, :]).sum(axis=2), axis=1)[:, :5]
    f = np.stack([first, near[first, rng.integers(0, 5, m)], near[first, rng.integers(0, 5, m)]], axis=1)
    if draw(st.booleans()):
        f = np.r_[f, f[: m // 5], f[: m // 5, ::-1]]
    return v * 0.5, f.astype(np.int32)


def _brute_force(v, f):
    """{(i, j): kind} of every pair of nonzero-area faces that meets beyond what it shares by index (rational
    clipping, over the pairs whose closed boxes meet: no other pair can meet)."""
    corners = v[f]
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    meet = np.all(lo[:, None, :] <= hi[None, :, :], axis=2) & np.all(lo[None, :, :] <= hi[:, None, :], axis=2)
    out = {}
    for i, j in zip(*np.nonzero(np.triu(meet, k=1))):
        shared = [(a, b) for a in range(3) for b in range(3) if f[i][a] == f[j][b]]
        kind = brute_kind(v[f[i]], v[f[j]], shared)
        if kind:
            out[(int(i), int(j))] = kind
    return out


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mesh=small_meshes(), rounds=st.integers(2, 9))
def test_rounds_on_small_adversarial_meshes(mesh, rounds):
    """Hypothesis: random lattice meshes (touching boxes, coplanar faces, repeated and reversed faces) give the
    same fields for any number of rounds as for one, and their pairs are those of a brute force over all pairs
    (exact rational classification, ``tests/intersect_reference.py``)."""
    v, f = mesh
    one = _run(v, f, {ROUNDS: "1"})
    assert _fields(_run(v, f, {ROUNDS: str(rounds), POISON: "1"})) == _fields(one)
    assert pair_kinds(one) == _brute_force(v, f)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM and clear_refs are Linux's")
def test_check_peak_per_face_with_twins_in_rounds():
    """Regression (issue 25): the check's own high point on a 300,000-face torus in a fresh process, with the
    twins in four rounds (what meshes of 2^19 faces or more get).  It was 37-39 bytes a face (the sort words
    under the positions and twins, the twins' block under the stars' lists, the corner indices beside the
    boxes: 1e7 faces +373 MiB); now about 29 (1e7 faces: 27), asserted at most 34."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p), ROUNDS: "4"}
    env.pop(_native.NO_ACCEL_ENV, None)
    env.pop(POISON, None)
    out = subprocess.run([sys.executable, "-c", _PEAK_CHILD], capture_output=True, text=True, env=env,
                         check=True, timeout=120).stdout.split()
    faces, extra, c_path = int(out[0]), int(out[1]), int(out[2])
    if not c_path:
        pytest.skip("the child process did not load the C extension")
    assert extra / faces <= 34, f"the check's peak: {extra / faces:.1f} bytes a face above its caller's"
