"""Marching tetrahedra on a regular lattice, vectorised: the closed surface ``{f > 0}`` of sampled values.

Each lattice cube is cut into the six tetrahedra of the Freudenthal (Kuhn) triangulation — ``000 → e_a →
e_a + e_b → 111`` for the six orders ``(a, b, c)`` of the axes — which neighbouring cubes share face for face.
The zero set of the piecewise-linear interpolant of ``f`` on these tetrahedra is cut out one tetrahedron at a
time (one triangle where one corner differs from the other three, two where two and two).  A vertex of the
surface lies on a lattice edge and is named by that edge (its lower end and direction), so the tetrahedra around
an edge share it: when no sample is zero the result is a closed, consistently oriented 2-manifold (the zero set
of a piecewise-linear function on a triangulation, every corner strictly on one side).  Samples equal to 0 are
counted outside, and the lattice's outer layer must be ≤ 0 so that the surface closes inside it.

The triangles face from ``f > 0`` to ``f ≤ 0`` (outward of the region).  Their orientation comes from a table,
not from their normals: a triangle on the edges of a tetrahedron keeps its orientation relative to the corners
wherever its vertices lie in the open edges, so degenerate (zero-area) triangles are oriented as well as the rest.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

__all__ = ["marching_tetrahedra"]

_UNIT = np.eye(3, dtype=np.int64)


def _tetrahedra() -> list[tuple[np.ndarray, int]]:
    """The six Freudenthal tetrahedra of the unit cube: (corner offsets (4, 3), orientation ±1)."""
    out = []
    for a, b, _ in permutations(range(3)):
        corners = np.array([[0, 0, 0], _UNIT[a], _UNIT[a] + _UNIT[b], [1, 1, 1]], dtype=np.int64)
        out.append((corners, int(round(np.linalg.det(corners[1:] - corners[0])))))
    return out


def _case_table() -> dict[int, list[list[tuple[int, int]]]]:
    """For each pattern of corners inside (bit i: corner i of a positively oriented tetrahedron has f > 0), the
    triangles as three edges ``(i, j)``, ``i < j``, ordered so that the normal points to the outside corners."""
    ref = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])      # positively oriented
    table: dict[int, list[list[tuple[int, int]]]] = {}
    for code in range(1, 15):
        ins = [i for i in range(4) if code >> i & 1]
        outs = [i for i in range(4) if not code >> i & 1]
        if len(ins) == 1 or len(outs) == 1:
            lone, rest = (ins[0], outs) if len(ins) == 1 else (outs[0], ins)
            cycles = [[(lone, r) for r in rest]]
        else:
            (a, b), (c, d) = ins, outs
            ring = [(a, c), (a, d), (b, d), (b, c)]
            cycles = [[ring[0], ring[1], ring[2]], [ring[0], ring[2], ring[3]]]
        towards_out = ref[outs].mean(axis=0) - ref[ins].mean(axis=0)
        triangles = []
        for cycle in cycles:
            edges = [(min(e), max(e)) for e in cycle]
            p = np.array([0.5 * (ref[i] + ref[j]) for i, j in edges])
            if np.cross(p[1] - p[0], p[2] - p[0]) @ towards_out < 0:
                edges = [edges[0], edges[2], edges[1]]
            triangles.append(edges)
        table[code] = triangles
    return table


_TETRAHEDRA = _tetrahedra()
_CASES = _case_table()


def marching_tetrahedra(values, origin, spacing: float, *, edge_margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The surface ``{f = 0}`` around ``{f > 0}`` of lattice samples.

    Parameters
    ----------
    values : (nx, ny, nz) float
        ``f`` at the lattice points ``origin + spacing · (i, j, k)``; the outer layer must be ≤ 0.
    origin : (3,) float
        Position of sample (0, 0, 0), m.
    spacing : float
        Lattice step, m.
    edge_margin : float
        Fraction of a lattice edge (0 to 0.25) kept between a surface vertex and the edge's ends: the crossing
        is moved inside ``[margin, 1 − margin]``.  The surface stays an embedded manifold wherever its
        vertices lie in the open edges; with a margin, distinct vertices stay at least about
        ``0.5 margin · spacing`` apart, so that rounding them (a float32 file) cannot fold a triangle over
        another.

    Returns
    -------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Triangles facing out of ``{f > 0}``; empty when no sample is positive.
    """
    f = np.asarray(values, dtype=np.float64)
    nx, ny, nz = f.shape
    inside = f > 0
    # cubes with corners on both sides
    any_in = np.zeros((nx - 1, ny - 1, nz - 1), dtype=bool)
    all_in = np.ones((nx - 1, ny - 1, nz - 1), dtype=bool)
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                corner = inside[dx:nx - 1 + dx, dy:ny - 1 + dy, dz:nz - 1 + dz]
                any_in |= corner
                all_in &= corner
    cube = np.nonzero(any_in & ~all_in)
    del any_in, all_in
    base = (cube[0] * ny + cube[1]) * nz + cube[2]
    strides = np.array([ny * nz, nz, 1], dtype=np.int64)
    flat_inside = inside.ravel()
    keys = []
    for corners, orientation in _TETRAHEDRA:
        lin = base[:, None] + corners @ strides                      # (m, 4) lattice indices of the corners
        code = (flat_inside[lin] * np.array([1, 2, 4, 8])).sum(axis=1)
        for case, triangles in _CASES.items():
            rows = np.nonzero(code == case)[0]
            if not len(rows):
                continue
            for edges in triangles:
                if orientation < 0:
                    edges = [edges[0], edges[2], edges[1]]
                tri = np.empty((len(rows), 3), dtype=np.int64)
                for slot, (i, j) in enumerate(edges):
                    step = corners[j] - corners[i]                  # in {0, 1}³: corner i is the lower end
                    direction = int(4 * step[0] + 2 * step[1] + step[2]) - 1
                    tri[:, slot] = lin[rows, i] * 7 + direction
                keys.append(tri)
    if not keys:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    all_keys = np.concatenate(keys)
    unique, inverse = np.unique(all_keys.ravel(), return_inverse=True)
    lower, edge_direction = np.divmod(unique, 7)
    code = edge_direction + 1
    step = np.column_stack([(code >> 2) & 1, (code >> 1) & 1, code & 1])
    upper = lower + step @ strides
    flat = f.ravel()
    f0, f1 = flat[lower], flat[upper]
    t = f0 / (f0 - f1)                                               # one end > 0, the other ≤ 0: t in (0, 1]
    if edge_margin > 0:
        np.clip(t, edge_margin, 1.0 - edge_margin, out=t)
    index = np.column_stack(np.unravel_index(lower, f.shape)).astype(np.float64)
    vertices = np.asarray(origin, dtype=np.float64) + spacing * (index + t[:, None] * step)
    return vertices, inverse.reshape(-1, 3).astype(np.int64)
