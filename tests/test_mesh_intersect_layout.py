"""mesh/intersect.py: the C face-pair scan's memory layout (issue 25, item 1) changes no answer.

The scan keeps each face's box as six bytes on its leaf's grid (``_accel.c`` section 8, ``ct_grid``) instead of
float32 numbers, maps its boxes and corner indices only after the sort, the twins and the stars' lists are
given back, and builds the hierarchy's shape before any box.  The grid test must stay conservative: every pair
whose closed float64 boxes meet is still a candidate.  Independent truth: with no star or patch pruning the
candidate count is exactly the number of face pairs whose closed boxes meet, counted here by brute force over
all pairs; and the pairs found are the numpy twin's.  The meshes are built to sit on the grid's edges: corners
on a small lattice (boxes touching exactly, faces flat along an axis, leaves of zero extent along an axis),
scaled by powers of two from below float32's normal range to beyond its largest value (the leaf boxes are
then infinite and the grid is not cut), and moved far from the origin (the grid's origin then dwarfs its step).

The peak memory of the check is measured in a fresh process (VmHWM reset by ``/proc/self/clear_refs``): the
regression of issue 25 was ~75 bytes a face at the check's high point (1e7 faces: 1,125 MiB, 2.36x the file).
"""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool import _native
from contact_scans import FIELDS, run_scan

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")

FUZZ = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def box_meeting_pairs(v: np.ndarray, f: np.ndarray) -> int:
    """Pairs of distinct faces whose closed float64 bounding boxes meet, by brute force over all pairs."""
    corners = v[f]
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    meet = np.all(lo[:, None, :] <= hi[None, :, :], axis=2) & np.all(lo[None, :, :] <= hi[:, None, :], axis=2)
    return int(np.count_nonzero(np.triu(meet, k=1)))


@st.composite
def lattice_meshes(draw):
    """``(vertices, faces)``: 20-300 faces with corners on a small integer lattice (exact box contacts, flat
    faces, repeated corners), some in one plane, scaled by 2^k and shifted far from the origin."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    m = draw(st.integers(20, 300))
    span = draw(st.sampled_from([2, 4, 9]))
    n = draw(st.integers(4, 60))
    v = rng.integers(0, span + 1, (n, 3)).astype(float)
    if draw(st.booleans()):
        v[:, draw(st.integers(0, 2))] = 1.0       # every face flat along one axis: leaves of zero extent there
    # short faces: a corner and two neighbours within one lattice step, so boxes touch rather than overlap
    first = rng.integers(0, n, m)
    near = np.argsort(np.abs(v[:, None, :] - v[None, :, :]).sum(axis=2), axis=1)[:, :4]
    f = np.stack([first, near[first, rng.integers(0, 4, m)], near[first, rng.integers(0, 4, m)]], axis=1)
    if draw(st.booleans()):
        f = np.r_[f, rng.integers(0, n, (m // 4, 3))]    # and some long ones across the lattice
    k = draw(st.sampled_from([-140, -126, -60, 0, 60, 127, 140]))
    v = v * 2.0 ** k
    shift = draw(st.sampled_from([0.0, 2.0 ** 30, -3.0 ** 20]))
    v = v + shift * 2.0 ** k                       # exact or rounded: the truth is taken from these coordinates
    return v, f


@FUZZ
@given(mesh=lattice_meshes())
def test_every_box_meeting_pair_is_a_candidate(mesh):
    """Unpruned, the C scan's candidates are exactly the pairs whose closed float64 boxes meet (brute force):
    the byte grid loses none, at any scale, far from the origin, beyond float32's range."""
    v, f = mesh
    fast = run_scan(v, f, accel=True, _star_faces=0, _patches=False)
    assert fast.complete
    assert fast.candidate_pairs == box_meeting_pairs(v, f)


@FUZZ
@given(mesh=lattice_meshes(), dtype=st.sampled_from([np.int32, np.int64]))
def test_c_scan_is_the_numpy_twin_on_lattice_meshes(mesh, dtype):
    """The pairs found are the numpy twin's, with stars and patches (as the analysis runs) and without;
    without patches the counts are the twin's too."""
    v, f = mesh
    f = f.astype(dtype)
    ref = run_scan(v, f, accel=False)
    for patches in (True, False):
        fast = run_scan(v, f, accel=True, _patches=patches)
        for name in FIELDS:
            assert np.array_equal(getattr(fast, name), getattr(ref, name)), (name, patches)
        if not patches:
            assert (fast.candidate_pairs, fast.tested_pairs) == (ref.candidate_pairs, ref.tested_pairs)


@pytest.mark.parametrize("scale", [2.0 ** -130, 1.0, 2.0 ** 130])
def test_a_row_of_triangles_touching_at_corners_far_from_the_origin(scale):
    """64 coplanar unit triangles in a row, (t, 0, 0), (t + 1, 0, 0), (t, 1, 0), unwelded, at x + 2^40 (scaled
    below float32's normal range, at 1, beyond its largest value): triangle t meets triangle t + 1 only at the
    corner (t + 1, 0, 0), which is on no shared index: exactly the 63 pairs (t, t + 1), each a contact, and
    their boxes meet only on the plane x = t + 1 (four leaves of the hierarchy, their grids' steps far below
    the offset)."""
    t = np.arange(64, dtype=float)
    zero = 0 * t
    tri = np.stack([np.stack([t, zero, zero], 1), np.stack([t + 1, zero, zero], 1),
                    np.stack([t, zero + 1, zero], 1)], axis=1)
    v = ((tri + np.array([2.0 ** 40, 0.0, 0.0])) * scale).reshape(-1, 3)
    f = np.arange(len(v)).reshape(-1, 3)
    want = np.stack([np.arange(63), np.arange(1, 64)], axis=1)
    unpruned = run_scan(v, f, accel=True, _star_faces=0, _patches=False)
    assert unpruned.candidate_pairs == box_meeting_pairs(v, f) == 63
    for result in (unpruned, run_scan(v, f, accel=True), run_scan(v, f, accel=False)):
        assert np.array_equal(result.contact, want)
        assert not len(result.crossing) and not len(result.coplanar_opposite)


_PEAK_CHILD = textwrap.dedent(r"""
    import sys
    import numpy as np
    from inertia_tool._native import accel
    from inertia_tool.mesh.intersect import surface_contacts

    def status(key):
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key):
                    return int(line.split()[1]) * 1024

    n_major, n_minor = 600, 250                    # a closed torus of 300,000 faces
    u = 2 * np.pi * np.arange(n_major) / n_major
    w = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = 50.0 + 20.0 * np.cos(ww)
    v = np.stack([ring * np.cos(uu), ring * np.sin(uu), 20.0 * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a, b = i * n_minor + j, ((i + 1) % n_major) * n_minor + j
    c, d = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor, i * n_minor + (j + 1) % n_minor
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    f = f.astype(np.int32)
    surface_contacts(v[:100], f[:10] % 100)         # imports and first-call allocations
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")
    before = status("VmRSS:")
    r = surface_contacts(v, f)
    assert not len(r.crossing) and not len(r.contact) and not len(r.coplanar_opposite)
    print(len(f), status("VmHWM:") - before, int(accel() is not None))
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM and clear_refs are Linux's")
def test_check_peak_memory_per_face():
    """Regression (issue 25): the face-pair check's own peak, above what the process held before it, on a
    300,000-face torus in a fresh process.  It was ~75 bytes a face (the sort's words, the float32 boxes, the
    corner indices, the twins, the stars' lists and the positions all at once); now the boxes are 16-bit steps
    on their leaf's grid and the arrays of the hierarchy are mapped only after the sort's and the twins' are
    given back: about 37 (34-40 at 1e7 faces, depending on the phase), asserted at most 44."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    env.pop(_native.NO_ACCEL_ENV, None)
    out = subprocess.run([sys.executable, "-c", _PEAK_CHILD], capture_output=True, text=True, env=env,
                         check=True, timeout=120).stdout.split()
    faces, extra, c_path = int(out[0]), int(out[1]), int(out[2])
    if not c_path:                              # e.g. _accel.c edited since the build: the numpy twin ran
        pytest.skip("the child process did not load the C extension")
    assert extra / faces <= 44, f"the check's peak: {extra / faces:.1f} bytes a face above its caller's"
