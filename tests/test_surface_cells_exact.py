"""``grid_cells._surface_cells`` marks exactly the cells a surface meets (session 16, issues 23/25).

The grid estimates' bounds rest on one promise: every cell whose closed box meets a face is marked (a free cell
holds no surface, so two neighbouring free cells form a box no face crosses).  The cells are now found by
clipping each triangle to the grid's slabs and rows with a margin ``ε = 2⁻⁴⁰ (1 + |u|max)`` cells; checked here
on both paths (C, section 10, and the numpy twin) against

* an independent exact test: Akenine-Möller's separating axes (the box's 3 normals, the triangle's normal and
  the 9 products of its edges with the box's axes) evaluated in integers (the doubles are dyadic rationals,
  scaled by ``2**200``; the cell ``[lo + i h, lo + (i + 1) h]`` too): every cell it finds meeting the triangle is
  marked, and every marked cell meets the triangle once the box is widened by ``2⁻³⁰`` cells (no margin beyond
  the round-off's);
* dense sampling of each triangle (at a twentieth of a cell, edges and corners included): every sample's cell
  is marked, on larger random soups the exact test would be slow on.

One path (the kernel when built): ``test_mesh_surface_cells`` shows the numpy twin marks the same cells, bit for
bit.

Generators: free triangles, needles (a corner within 1e-9 of the opposite edge), slivers (a corner within 1e-7
of another), points, triangles in a plane of cell faces, and corners on the lattice of cell corners and
half-cells (where the cell boundaries pass through them, up to the rounding of ``lo + i h``), with cells of
sides that are not binary fractions and grids far from the origin.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from inertia_tool.mesh.grid_cells import _surface_cells

PATHS = ["c"] if HAVE_ACCEL else ["numpy"]


def _marked(path, v, f, lo, h, dims):
    with pytest.MonkeyPatch.context() as patch:
        if path == "c":
            patch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
        else:
            patch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
        return _surface_cells(v, f, lo, h, dims).reshape(dims)


def _scaled(values, shift):
    """The doubles ``values`` times ``2**shift`` as Python ints (exact: a double is a dyadic rational whose
    denominator divides ``2**shift`` for the shifts used here; checked)."""
    out = []
    for x in values:
        num, den = float(x).as_integer_ratio()
        whole, rest = divmod(num << shift, den)
        if rest:
            raise ValueError(f"expected a double with a denominator dividing 2**{shift}, got {x!r}")
        out.append(whole)
    return out


def _meets(tri, box_lo, box_hi):
    """Whether the closed triangle ``tri`` (3 points of ints) meets the closed box (ints), exactly: no
    separating axis among the box's normals, the triangle's normal and the edges' products with the box's axes
    (touching counts as meeting).  A degenerate triangle (segment, point) has a zero normal and zero products
    where edges vanish; the remaining axes are the facet normals of its Minkowski sum with the box, so the test
    stays exact.  Doubled coordinates about the box's centre keep everything integer."""
    centre2 = [box_lo[i] + box_hi[i] for i in range(3)]
    half2 = [box_hi[i] - box_lo[i] for i in range(3)]
    p = [[2 * q[i] - centre2[i] for i in range(3)] for q in tri]
    e = [[p[(k + 1) % 3][i] - p[k][i] for i in range(3)] for k in range(3)]
    normal = (e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
              e[0][0] * e[1][1] - e[0][1] * e[1][0])
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), normal]
    for d in e:                                            # d × x, d × y, d × z
        axes += [(0, d[2], -d[1]), (-d[2], 0, d[0]), (d[1], -d[0], 0)]
    for axis in axes:
        if not any(axis):
            continue
        proj = [q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2] for q in p]
        reach = half2[0] * abs(axis[0]) + half2[1] * abs(axis[1]) + half2[2] * abs(axis[2])
        if min(proj) > reach or max(proj) < -reach:
            return False
    return True


#: Bits of the fixed point of the exact test: the cases' doubles (53-bit mantissas, none below 2**-140 unless
#: zero) and the widening's 2**-30 cells are multiples of 2**-SHIFT (:func:`_scaled` refuses one that is not).
SHIFT = 200


def _exact_cells(v, f, lo, h, dims, widen_bits=None):
    """(dims) bool: the cells whose closed box, widened by ``2**-widen_bits`` cells (None: not widened), meets a
    face (exact, in integers scaled by ``2**SHIFT``)."""
    out = np.zeros(dims, dtype=bool)
    H = _scaled([h], SHIFT)[0]
    LO = _scaled(lo, SHIFT)
    W = 0 if widen_bits is None else H >> widen_bits
    if widen_bits is not None and W << widen_bits != H:
        raise ValueError("expected the widening to be exact")
    for face in f:
        tri = [_scaled(v[k], SHIFT) for k in face]
        rng = []
        for i in range(3):
            cmin, cmax = min(q[i] for q in tri), max(q[i] for q in tri)
            rng.append(range(max(0, (cmin - LO[i]) // H - 2), min(dims[i], (cmax - LO[i]) // H + 3)))
        for cell in itertools.product(*rng):
            if out[cell]:
                continue
            box_lo = [LO[i] + cell[i] * H - W for i in range(3)]
            box_hi = [LO[i] + (cell[i] + 1) * H + W for i in range(3)]
            out[cell] = _meets(tri, box_lo, box_hi)
    return out


@st.composite
def small_cases(draw):
    """1-3 triangles on a grid of up to 7 cells a side that holds them (with a cell to spare each way)."""
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    h = draw(st.sampled_from([1.0, 0.1, 1.0 / 3.0, 0.07, 2.5e-4]))
    cells = draw(st.integers(2, 6))
    lo = np.full(3, draw(st.sampled_from([0.0, -0.7, 1234.5, -3e4]))) + rng.uniform(-1, 1, 3) * h
    dims = (cells + 2, cells + 1, cells + 2)
    n = draw(st.integers(1, 3))
    kind = draw(st.sampled_from(["free", "needle", "sliver", "point", "lattice", "plane"]))
    u = rng.uniform(1.0, cells, size=(n, 3, 3))           # grid units, inside the grid
    if kind == "needle":
        t = rng.uniform(0, 1, size=(n, 1))
        u[:, 2] = u[:, 0] + t * (u[:, 1] - u[:, 0]) + rng.normal(size=(n, 3)) * 1e-9
    elif kind == "sliver":
        u[:, 2] = u[:, 0] + rng.normal(size=(n, 3)) * 1e-7
    elif kind == "point":
        u[:, 1] = u[:, 2] = u[:, 0]
    elif kind == "lattice":
        u = rng.integers(2, 2 * cells + 1, size=(n, 3, 3)) / 2.0
    elif kind == "plane":                                 # in a plane of cell faces, corners anywhere in it
        axis = int(rng.integers(0, 3))
        u[:, :, axis] = float(rng.integers(1, cells + 1))
    v = (lo + h * u.reshape(-1, 3)).astype(np.float64)
    f = np.arange(3 * n, dtype=np.int64).reshape(n, 3)
    return v, f, lo, h, dims


@pytest.mark.parametrize("path", PATHS)
@settings(max_examples=35, deadline=None)
@given(case=small_cases())
def test_marked_cells_are_the_cells_the_faces_meet(path, case):
    v, f, lo, h, dims = case
    marked = _marked(path, v, f, lo, h, dims)
    meets = _exact_cells(v, f, lo, h, dims)
    assert not np.any(meets & ~marked), "a cell the surface meets is not marked"
    near = _exact_cells(v, f, lo, h, dims, widen_bits=30)
    assert not np.any(marked & ~near), "a cell farther than 2**-30 cells from the surface is marked"


@st.composite
def soups(draw):
    """Up to 40 triangles of all kinds, scale 1e-3 to 1e3, far from the origin or not, on a grid of 4-30 cells
    along the longest side (padded by a cell; the surface inside it)."""
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    n = draw(st.integers(1, 40))
    scale = 10.0 ** draw(st.integers(-3, 3))
    offset = draw(st.sampled_from([0.0, 1.0, 1e4])) * scale
    a = rng.normal(size=(n, 3)) * scale + offset
    b = a + rng.normal(size=(n, 3)) * scale * draw(st.sampled_from([1.0, 30.0]))
    kind = draw(st.sampled_from(["free", "needle", "sliver"]))
    if kind == "free":
        c = a + rng.normal(size=(n, 3)) * scale
    elif kind == "needle":
        t = rng.uniform(0, 1, size=(n, 1))
        c = a + t * (b - a) + rng.normal(size=(n, 3)) * scale * 1e-9
    else:
        c = a + rng.normal(size=(n, 3)) * scale * 1e-7
    v = np.concatenate([a, b, c])
    f = np.stack([np.arange(n), n + np.arange(n), 2 * n + np.arange(n)], axis=1)
    cells = draw(st.integers(4, 30))
    vlo, vhi = v.min(axis=0), v.max(axis=0)
    h = float((vhi - vlo).max()) / cells
    lo = vlo - h
    dims = tuple(int(x) for x in np.ceil((vhi + h - lo) / h).astype(np.int64))
    return v, f, lo, h, dims


@pytest.mark.parametrize("path", PATHS)
@settings(max_examples=25, deadline=None)
@given(case=soups())
def test_every_sample_of_the_surface_is_in_a_marked_cell(path, case):
    v, f, lo, h, dims = case
    marked = _marked(path, v, f, lo, h, dims).reshape(-1)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    longest = np.max(np.linalg.norm(np.stack([b - a, c - b, a - c]), axis=2), axis=0)
    for k in range(len(f)):
        n = int(min(300, max(1, np.ceil(20 * longest[k] / h))))
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        s, t = i[keep] / n, j[keep] / n
        pts = a[k] * (1 - s - t)[:, None] + b[k] * s[:, None] + c[k] * t[:, None]
        idx = np.clip(np.floor((pts - lo) / h).astype(np.int64), 0, np.array(dims) - 1)
        assert marked[np.ravel_multi_index(idx.T, dims)].all()


def test_a_long_needle_marks_only_its_cells():
    """A 1.19 km needle 0.39 mm wide (the UR5e's worst face, scaled) on a 1 m grid: the cells along it, at a
    cost of the cells, not of (length / spacing)² samples."""
    v = np.array([[0.5, 0.5, 0.5], [1190.5, 0.5, 0.5], [600.0, 0.50039, 0.5]])
    f = np.array([[0, 1, 2]])
    dims = (1192, 3, 3)
    for path in PATHS:
        grid = _marked(path, v, f, np.zeros(3), 1.0, dims)
        assert grid[:1191, 0, 0].all() and grid.sum() == 1191
