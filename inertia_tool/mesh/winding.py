"""Generalized winding number of a triangle soup at many points.

``w(p) = Σ_f Ω_f(p) / 4π``, the signed solid angles of the triangles seen from ``p`` (Van Oosterom &
Strackee, IEEE Trans. Biomed. Eng. 30 (1983) 125).  For a closed outward surface it is 1 inside and 0
outside; for an open or broken one it varies smoothly and stays near 1 deep inside and near 0 far outside,
which makes ``w > 1/2`` a robust inside test for meshes with holes, cracks, duplicated faces and stray
pieces (Jacobson, Kavan & Sorkine-Hornung, "Robust inside-outside segmentation using generalized winding
numbers", ACM TOG 32(4) 33, SIGGRAPH 2013).

Evaluation: libigl's hierarchical ``fast_winding_number`` (Barill et al., "Fast winding numbers for soups
and clouds", ACM TOG 37(4) 43, SIGGRAPH 2018) when the optional ``libigl`` package is installed; otherwise
a treecode in the same spirit (:func:`winding_numbers_bounded`: faces in a binary tree of clusters, far
clusters replaced by their dipole term where a stated bound on the error allows, near faces summed exactly;
in C, ``_accel.c`` section 13, when the extension is built, with numpy's :func:`_treecode_numpy` the
reference, the same values bit for bit on x86-64), which returns that bound with each value; the exact
direct sum (``points × faces`` work) is kept as the reference.
"""

from __future__ import annotations

import numpy as np

from ..errors import UsageError

__all__ = ["winding_numbers", "winding_numbers_bounded", "winding_integers", "integer_tree", "fast_available"]

_BLOCK = 1 << 22     # point-triangle pairs per vectorised block of the direct sum


def fast_available() -> bool:
    """Whether libigl's hierarchical evaluation can be used."""
    try:
        import igl  # noqa: F401
    except ImportError:
        return False
    return hasattr(igl, "fast_winding_number")


def _solid_angles(q: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Signed solid angle of triangles (a, b, c) seen from points q (all (k, 3)), Van Oosterom–Strackee."""
    a, b, c = a - q, b - q, c - q
    la, lb, lc = (np.sqrt(np.einsum("...i,...i", x, x)) for x in (a, b, c))
    num = np.einsum("...i,...i", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("...i,...i", a, b) * lc + np.einsum("...i,...i", a, c) * lb
           + np.einsum("...i,...i", b, c) * la)
    angle: np.ndarray = 2.0 * np.arctan2(num, den)
    return angle


def _direct(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a0, b0, c0 = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    out = np.zeros(len(points))
    per = max(1, _BLOCK // max(len(faces), 1))
    for s in range(0, len(points), per):
        p = points[s:s + per, None, :]
        out[s:s + per] = _solid_angles(p, a0[None], b0[None], c0[None]).sum(axis=1) / (4 * np.pi)
    return out


#: The C kernel's limits (``WT_PARTS``, ``WT_LEVELS`` in ``_accel.c`` section 13): blocks of (point, leaf) pairs
#: one point's leaves may span, and levels of the tree; beyond them (never below ~60M faces) numpy evaluates.
_C_PARTS = 64
_C_LEVELS = 64


def _leaf_block(leaf: int) -> int:
    """(point, leaf) pairs per vectorised block of the treecode's near field (each pair up to ``leaf`` faces)."""
    return max(1, _BLOCK // (leaf * 4))


class _Tree:
    """Faces in Morton order, grouped into a binary tree of clusters (leaves of ``leaf`` faces).

    Per level ``ℓ`` (0 = leaves) and cluster: ``normal`` = Σ area vectors (m²), ``area`` = Σ areas (m²),
    ``centre`` = area-weighted centroid (m), ``radius`` = largest distance from it to a corner (m).
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, leaf: int) -> None:
        a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
        centroid = (a + b + c) / 3.0
        lo, hi = centroid.min(axis=0), centroid.max(axis=0)
        cells = np.clip(((centroid - lo) / np.maximum(hi - lo, np.finfo(float).tiny) * 1023), 0, 1023).astype(np.int64)
        code = np.zeros(len(faces), dtype=np.int64)
        for bit in range(10):
            for axis in range(3):
                code |= ((cells[:, axis] >> bit) & 1) << (3 * bit + axis)
        order = np.argsort(code, kind="stable")
        self.a, self.b, self.c = a[order], b[order], c[order]
        self.leaf = leaf
        area_vec = 0.5 * np.cross(self.b - self.a, self.c - self.a)
        area = np.linalg.norm(area_vec, axis=1)
        cen = centroid[order]
        self.levels: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        size = leaf
        n = len(faces)
        while True:
            starts = np.arange(0, n, size)
            normal = np.add.reduceat(area_vec, starts, axis=0)
            total = np.add.reduceat(area, starts)
            weight = np.add.reduceat(cen * area[:, None], starts, axis=0)
            plain = np.add.reduceat(cen, starts, axis=0) / np.diff(np.r_[starts, n])[:, None]
            centre = np.where(total[:, None] > 0, weight / np.where(total > 0, total, 1.0)[:, None], plain)
            owner = np.repeat(np.arange(len(starts)), np.diff(np.r_[starts, n]))
            reach = np.maximum(np.maximum(np.linalg.norm(self.a - centre[owner], axis=1),
                                          np.linalg.norm(self.b - centre[owner], axis=1)),
                               np.linalg.norm(self.c - centre[owner], axis=1))
            radius = np.maximum.reduceat(reach, starts)
            # first moment of the area vectors about the centre: M = Σ a_f ⊗ (c_f − p̃), (k, 3, 3)
            outer = np.add.reduceat((area_vec[:, :, None] * cen[:, None, :]).reshape(n, 9), starts, axis=0)
            moment = outer.reshape(-1, 3, 3) - normal[:, :, None] * centre[:, None, :]
            self.levels.append((normal, total, centre, radius, moment))
            if len(starts) <= 8:
                break
            size *= 2
        # the same clusters flattened for the C twin (_accel.c section 13): rows [normal, area, centre, radius,
        # moment] level by level from the leaves, and the first row of each level
        self.clusters = np.ascontiguousarray(np.concatenate(
            [np.concatenate([nm, ar[:, None], ce, ra[:, None], mo.reshape(-1, 9)], axis=1)
             for nm, ar, ce, ra, mo in self.levels]), dtype=np.float64)
        self.bounds = np.cumsum([0] + [len(level[1]) for level in self.levels]).astype(np.int64)
        self.triangles = np.ascontiguousarray(np.concatenate([self.a, self.b, self.c], axis=1), dtype=np.float64)


def _treecode(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, *, tolerance: float = 1e-4,
              leaf: int = 16, chunk: int = 2048, tree: _Tree | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Winding numbers by a Barnes–Hut treecode, with a bound on the error at each point.

    A cluster of faces (area vectors ``a_f``, centroids ``c_f``, total area ``A``, area-weighted centre ``p̃``,
    radius ``r``) seen from a point ``q`` at distance ``d = |p̃ − q| > 2r`` contributes the first two terms of
    the Taylor expansion of its solid angle about ``p̃`` (as in Barill et al. 2018) instead of the sum over
    its faces: with ``g(x) = (x − q)/|x − q|³``, ``u = p̃ − q`` and ``M = Σ a_f ⊗ (c_f − p̃)``,
    ``4π w ≈ N·g(p̃) + (tr M − 3 ûᵀMû)/|u|³`` (``N = Σ a_f``; the first-order term is exact for the linear
    part of ``g`` because a triangle's first moment is its area times its centroid).  The remainder is bounded
    by the third derivative of ``1/|x|``, whose norm is ``6/|x|⁴`` (Legendre: ``|P₃| ≤ 1``), so the error is
    at most ``3·A·r² / (4π (d − r)⁴)``; the expansion is used only where that is at most ``tolerance``, and
    the bounds of the clusters used are summed per point.  Everything closer is refined down to leaves of
    ``leaf`` faces, summed exactly.

    ``tree``, when given, is ``_Tree(vertices, faces, leaf)`` built before (it does not depend on the points
    or the tolerance: :func:`winding_integers` builds it once for both of its passes).

    Returns
    -------
    winding : (p,) float
    error : (p,) float
        Bound on ``|winding − exact|`` (0 where every face was summed exactly; round-off aside).
    """
    if tree is None or tree.leaf != leaf:
        tree = _Tree(vertices, faces, leaf)
    if len(points) and len(faces):
        from .._native import accel, threads
        lib = accel()
        per = _leaf_block(leaf)
        if lib is not None and len(tree.levels[0][0]) // per + 2 <= _C_PARTS and len(tree.levels) <= _C_LEVELS:
            # the same clusters, decisions, terms and order of the sums in C (_accel.c section 13), point by
            # point: numpy's values bit for bit where its kernels round as measured (x86-64), else to round-off,
            # each within its own bound (issue 25: the treecode was ~30 % of Piper's link2.stl repair)
            out = np.empty(len(points))
            err = np.empty(len(points))
            lib.winding_tree(np.ascontiguousarray(points, dtype=np.float64), tree.clusters, tree.bounds,
                             tree.triangles, int(leaf), float(tolerance), int(chunk), per, out, err, threads())
            return out, err
    return _treecode_numpy(points, tree, tolerance=tolerance, chunk=chunk)


def _treecode_numpy(points: np.ndarray, tree: _Tree, *, tolerance: float, chunk: int = 2048
                    ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_treecode` in numpy, level by level for blocks of ``chunk`` points: the reference of the C kernel
    and the path without it (``INERTIA_TOOL_NO_ACCEL``)."""
    leaf = tree.leaf
    n_faces = len(tree.a)
    top = len(tree.levels) - 1
    out = np.zeros(len(points))
    err = np.zeros(len(points))
    for s in range(0, len(points), chunk):
        q = points[s:s + chunk]
        n_top = len(tree.levels[top][0])
        pt = np.repeat(np.arange(len(q)), n_top)
        cl = np.tile(np.arange(n_top), len(q))
        w = np.zeros(len(q))
        e = np.zeros(len(q))
        for level in range(top, -1, -1):
            normal, area, centre, radius, moment = tree.levels[level]
            delta = centre[cl] - q[pt]
            d = np.sqrt(np.einsum("ij,ij->i", delta, delta))
            r = radius[cl]
            with np.errstate(divide="ignore", invalid="ignore"):
                bound = 3.0 * area[cl] * r ** 2 / (4 * np.pi * np.maximum(d - r, 0.0) ** 4)
            far = (d > 2 * r) & (bound <= tolerance)
            if far.any():
                u, dist, m = delta[far], d[far], moment[cl[far]]
                unit = u / dist[:, None]
                first = (np.trace(m, axis1=1, axis2=2) - 3 * np.einsum("ki,kij,kj->k", unit, m, unit)) / dist ** 3
                dipole = (np.einsum("ij,ij->i", normal[cl[far]], u) / dist ** 3 + first) / (4 * np.pi)
                w += np.bincount(pt[far], weights=dipole, minlength=len(q))
                e += np.bincount(pt[far], weights=bound[far], minlength=len(q))
            pt, cl = pt[~far], cl[~far]
            if level:
                n_below = len(tree.levels[level - 1][0])
                child = np.stack([2 * cl, 2 * cl + 1], axis=1)
                keep = child < n_below
                pt = np.repeat(pt, 2)[keep.reshape(-1)]
                cl = child.reshape(-1)[keep.reshape(-1)]
        # leaves still near: every face of them exactly, in blocks
        first = cl * leaf
        count = np.minimum(first + leaf, n_faces) - first
        per = _leaf_block(leaf)
        for k in range(0, len(pt), per):
            p_, f_, c_ = pt[k:k + per], first[k:k + per], count[k:k + per]
            idx = np.repeat(f_, c_) + (np.arange(int(c_.sum())) - np.repeat(np.cumsum(c_) - c_, c_))
            who = np.repeat(p_, c_)
            omega = _solid_angles(q[who], tree.a[idx], tree.b[idx], tree.c[idx])
            w += np.bincount(who, weights=omega, minlength=len(q)) / (4 * np.pi)
        out[s:s + chunk] = w
        err[s:s + chunk] = e
    return out, err


def winding_numbers(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, *,
                    fast: bool | None = None) -> np.ndarray:
    """Generalized winding number at each point, (p,) float.

    Parameters
    ----------
    points : (p, 3) float
    vertices : (n, 3) float
    faces : (m, 3) int
    fast : bool, optional
        Use libigl's approximation (relative error ~1e-3 of a full turn far from the surface) — the default
        when libigl is installed — or force the exact direct sum (``False``).
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if len(points) == 0 or len(faces) == 0:
        return np.zeros(len(points))
    if fast is None:
        fast = fast_available()
    if fast:
        import igl
        centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
        return np.asarray(igl.fast_winding_number(vertices - centre, faces, points - centre), dtype=np.float64)
    return _direct(points, vertices, faces)


#: Relative round-off of one solid angle of :func:`_direct` (``2·atan2``) in units of machine epsilon, used for
#: the error bound of :func:`winding_numbers_summed`: each term is off by a few ulps of π, the sum by at most
#: the terms' count times that, divided by 4π.
DIRECT_ROUNDOFF_ULPS = 8.0


def winding_numbers_summed(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray]:
    """Winding numbers by the exact direct sum over every face, with a bound on their round-off: ``(winding,
    error)``, both (p,) float, ``error = DIRECT_ROUNDOFF_ULPS · ε · m`` (``m`` faces).  About the bounding box's
    centre, as :func:`winding_numbers_bounded`; cheaper than its treecode for a few points (issue 23: the one
    point per region of UR5e's grids, 0.035 s against 0.1 s for the tree of 40k faces)."""
    points, vertices, faces = _contiguous(points, vertices, faces)
    if len(points) == 0 or len(faces) == 0:
        return np.zeros(len(points)), np.zeros(len(points))
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    bound = DIRECT_ROUNDOFF_ULPS * np.finfo(np.float64).eps * len(faces)
    return _direct(points - centre, vertices - centre, faces), np.full(len(points), bound)


def _contiguous(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The query points and the surface as C-contiguous float64 / int64 arrays (the kernels' layout)."""
    return (np.ascontiguousarray(points, dtype=np.float64), np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(faces, dtype=np.int64))


#: Per-cluster error tolerance of the first, cheaper treecode pass of :func:`winding_integers` (10× the
#: default's: on G1's torso 3,621 region points against 51,420 faces, 10.0 → 5.4 s, 99.6 % of them settled).
INTEGER_FIRST_TOLERANCE = 1e-3


#: Faces per leaf of the tree of :func:`winding_integers`.
INTEGER_LEAF = 16


class IntegerTree:
    """The tree of faces :func:`winding_integers` evaluates with, built once for several calls on one surface
    (:func:`integer_tree`).

    Attributes
    ----------
    centre : (3,) float
        m, the centre of the vertices' bounding box; the tree holds the vertices less it.
    faces : (m, 3) int
        The faces it was built from (a caller passing other faces is refused).
    vertices : (n, 3) float
        m, the vertices it was built from (compared by value with a caller's).
    shifted : (n, 3) float
        m, ``vertices − centre``.
    tree : _Tree
        ``_Tree(shifted, faces, INTEGER_LEAF)``.
    """

    __slots__ = ("centre", "faces", "vertices", "shifted", "tree")

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        self.vertices, self.faces = vertices, faces
        self.centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
        self.shifted = vertices - self.centre
        self.tree = _Tree(self.shifted, faces, INTEGER_LEAF)


def integer_tree(vertices: np.ndarray, faces: np.ndarray) -> IntegerTree:
    """The tree of :func:`winding_integers` for a surface, to pass to several calls on it (``tree=``): the values
    are those each call would compute with its own tree, to the bit (the tree depends on the surface only; issue
    25: :func:`~inertia_tool.mesh.grid_corrected.corrected_estimate` evaluates its front probes and its regions'
    integers on one surface)."""
    _, vertices, faces = _contiguous(np.zeros((0, 3)), vertices, faces)
    return IntegerTree(vertices, faces)


def winding_integers(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, *,
                     offset: np.ndarray | float = 0.0, margin: float = 0.25, tolerance: float = 1e-4,
                     first_tolerance: float = INTEGER_FIRST_TOLERANCE, tree: IntegerTree | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`winding_numbers_bounded` at points where ``winding + offset`` is known to be an integer (off a
    closed surface), for callers that only round it: ``(winding, error)``, (p,) float each.

    A first pass runs the treecode at ``first_tolerance``; a point it settles (``|w + offset − round| + error ≤
    margin``, ``margin < 1/2``) keeps that value and bound, the others are evaluated again at ``tolerance``.
    Rounded, a settled value is the true integer (it lies within its proven bound of it, and the integer is
    the only one within ``1/2``), so every caller that rounds points settled at ``tolerance`` gets the same
    integers as from one pass at ``tolerance`` (each point's value does not depend on the others evaluated
    with it); a point settled only by the first pass is proven by its own bound.

    ``tree``: :func:`integer_tree` of the same ``vertices`` and ``faces`` (refused otherwise), built once for
    several calls; by default each call builds its own.
    """
    points, vertices, faces = _contiguous(points, vertices, faces)
    if len(points) == 0 or len(faces) == 0:
        return np.zeros(len(points)), np.zeros(len(points))
    # winding_numbers_bounded's two calls, with the tree of faces built once (issue 25: ~0.35 s of a 72k-face
    # part's second pass; the same values to the bit)
    if tree is None:
        tree = IntegerTree(vertices, faces)
    elif not (tree.faces is faces or np.array_equal(tree.faces, faces)) or not (
            tree.vertices is vertices or np.array_equal(tree.vertices, vertices)):
        raise UsageError("Expected `tree` built from the same vertices and faces, got the tree of another surface")
    centre, shifted = tree.centre, tree.shifted
    w, err = _treecode(points - centre, shifted, faces, tolerance=first_tolerance, leaf=INTEGER_LEAF, tree=tree.tree)
    total = w + offset
    again = np.flatnonzero(np.abs(total - np.round(total)) + err > margin)
    if len(again) and first_tolerance != tolerance:
        w[again], err[again] = _treecode(points[again] - centre, shifted, faces, tolerance=tolerance,
                                         leaf=INTEGER_LEAF, tree=tree.tree)
    return w, err


def winding_numbers_bounded(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray, *,
                            tolerance: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
    """Winding numbers with a bound on their error, by the numpy treecode (no libigl needed).

    Returns ``(winding, error)``, both (p,) float; see :func:`_treecode` for the bound.
    """
    points, vertices, faces = _contiguous(points, vertices, faces)
    if len(points) == 0 or len(faces) == 0:
        return np.zeros(len(points)), np.zeros(len(points))
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    return _treecode(points - centre, vertices - centre, faces, tolerance=tolerance)
