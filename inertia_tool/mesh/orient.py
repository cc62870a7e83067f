"""Directed-edge balance and consistent orientation of a triangle surface.

The divergence-theorem integral of a triangle surface (``volume.py``) is the integral of the winding number
over space.  It is the volume of a solid whenever the surface is a *cycle*: every directed edge ``a→b`` is
matched by as many reverse edges ``b→a`` (then the winding number is piecewise constant and integer, and
the surface is the boundary of the solid where it is 1).  That holds for closed 2-manifolds, but also for
bodies touching along an edge or at a vertex and for walls meeting at an edge, which a manifold check
refuses.  :func:`edge_balance` tests the cycle condition; :func:`orient_consistently` repairs the common
way of breaking it, some faces wound the wrong way, by orienting each patch of faces connected through
manifold edges consistently (two faces sharing a manifold edge must traverse it in opposite directions).

Both are vectorised: one sort of 64-bit directed-edge keys, and the orientation is a connected-components
pass over a doubled face graph (no Python loop over faces).
"""

from __future__ import annotations

import numpy as np

from ..values import frozen_value
from .edges import edge_keys

__all__ = ["EdgeBalance", "edge_balance", "Orientation", "orient_consistently"]


@frozen_value
class EdgeBalance:
    """Directed-edge census: is the surface a cycle (every directed edge matched by a reverse one)?

    Attributes
    ----------
    edges : int
        Distinct undirected edges.
    boundary_edges : int
        Edges used by exactly one face (holes, cracks).
    nonmanifold_edges : int
        Edges used by more than two faces.
    unbalanced_edges : int
        Edges whose count of faces traversing ``a→b`` differs from the count traversing ``b→a``
        (boundary edges included).
    """

    edges: int
    boundary_edges: int
    nonmanifold_edges: int
    unbalanced_edges: int

    @property
    def balanced(self) -> bool:
        """Every directed edge matched by a reverse one: the surface integral is the volume of a solid."""
        return self.unbalanced_edges == 0


def edge_balance(faces: np.ndarray, n_vertices: int) -> EdgeBalance:
    """Count the undirected edges whose two directions are used by different numbers of faces.

    Parameters
    ----------
    faces : (m, 3) int
        Triangles without repeated corners.
    n_vertices : int

    Returns
    -------
    EdgeBalance
    """
    if len(faces) == 0:
        return EdgeBalance(0, 0, 0, 0)
    key, forward = edge_keys(faces, n_vertices)
    order = np.argsort(key, kind="stable")
    key = key[order]
    sign = np.where(forward[order], 1, -1).astype(np.int64)
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[starts, len(key)])
    net = np.add.reduceat(sign, starts)
    return EdgeBalance(edges=len(starts), boundary_edges=int(np.count_nonzero(count == 1)),
                       nonmanifold_edges=int(np.count_nonzero(count > 2)),
                       unbalanced_edges=int(np.count_nonzero(net)))


@frozen_value
class Orientation:
    """Result of :func:`orient_consistently`.

    Attributes
    ----------
    faces : (m, 3) int
        The faces with the flipped ones reversed.
    flipped_faces : int
        Faces reversed.
    patches : int
        Patches of faces connected through manifold edges (each oriented as one).
    orientable : bool
        False when some patch is non-orientable (a Möbius strip or Klein bottle); its faces are then left as
        they were.
    """

    faces: np.ndarray
    flipped_faces: int
    patches: int
    orientable: bool


def orient_consistently(faces: np.ndarray, n_vertices: int, vertices: np.ndarray | None = None) -> Orientation:
    """Orient the faces of each manifold-connected patch consistently, keeping the file's majority.

    Two faces sharing an edge used by exactly these two faces must traverse it in opposite directions.  On
    the doubled graph whose nodes are ``(face, as is)`` and ``(face, reversed)`` a consistent pair links
    like to like and an inconsistent pair links each to the other's opposite; a patch is orientable iff no
    face is connected to its own reverse, and its consistent orientations are the two components.  Of the
    two, the one that reverses the smaller area (the smaller count without ``vertices``) is kept: the file's
    own winding decides which side is out, so an intentionally inward-wound cavity stays a cavity.

    Parameters
    ----------
    faces : (m, 3) int
    n_vertices : int
    vertices : (n, 3) float, optional
        Used to weigh faces by area when choosing which of a patch's two orientations to keep.

    Returns
    -------
    Orientation
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    faces = np.asarray(faces)
    m = len(faces)
    if m == 0:
        return Orientation(faces, 0, 0, True)
    key, forward = edge_keys(faces, n_vertices)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.flatnonzero(np.r_[True, skey[1:] != skey[:-1]])
    count = np.diff(np.r_[starts, len(skey)])
    pair = starts[count == 2]                      # manifold edges: positions of their two uses
    e1, e2 = order[pair], order[pair + 1]
    f1, f2 = e1 // 3, e2 // 3
    same_direction = forward[e1] == forward[e2]    # inconsistent: one of the two faces must turn
    # doubled graph: node f is face f as is, node f + m the same face reversed
    rows = np.r_[f1, f1 + m]
    cols = np.r_[np.where(same_direction, f2 + m, f2), np.where(same_direction, f2, f2 + m)]
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(2 * m, 2 * m))
    _, node = connected_components(graph, directed=False)
    patch_graph = coo_matrix((np.ones(len(f1), dtype=np.int8), (f1, f2)), shape=(m, m))
    n_patches, patch = connected_components(patch_graph, directed=False)
    orientable_face = node[:m] != node[m:]
    # root of each patch: its first face; a face keeps its winding iff it sits in the root's component
    root = np.full(n_patches, m, dtype=np.int64)
    np.minimum.at(root, patch, np.arange(m))
    flip = node[:m] != node[root[patch]]
    bad_patch = np.zeros(n_patches, dtype=bool)
    bad_patch[patch[~orientable_face]] = True
    flip[bad_patch[patch]] = False
    if vertices is not None:
        v = np.asarray(vertices, dtype=np.float64)
        weight = 0.5 * np.linalg.norm(np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]]),
                                      axis=1)
    else:
        weight = np.ones(m)
    flipped_weight = np.bincount(patch, weights=weight * flip, minlength=n_patches)
    total_weight = np.bincount(patch, weights=weight, minlength=n_patches)
    turn = flipped_weight > 0.5 * total_weight      # keep the orientation that reverses less
    flip ^= turn[patch] & ~bad_patch[patch]
    out = faces.copy()
    out[flip] = out[flip][:, ::-1]
    return Orientation(faces=out, flipped_faces=int(np.count_nonzero(flip)), patches=int(n_patches),
                       orientable=not bool(bad_patch.any()))
