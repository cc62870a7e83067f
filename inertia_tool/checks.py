"""Mesh checks: does the triangle set bound a solid, and how is it split into shells?

The engine refuses to guess: a surface must be closed (every edge shared by exactly two faces), traversed
in opposite directions by the two (consistent winding), before its signed-tetrahedron integral means
anything.  These functions are pure and vectorised (sorting 64-bit edge keys), fast on millions of faces.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["EdgeTopology", "MeshReport", "degenerate_faces", "edge_topology", "shell_labels", "winding_number"]


@dataclass(frozen=True)
class EdgeTopology:
    """Edge census of an indexed triangle mesh.

    Attributes
    ----------
    edges : int
        Distinct undirected edges.
    boundary_edges : int
        Edges used by one face only (holes).
    nonmanifold_edges : int
        Edges used by more than two faces.
    misoriented_edges : int
        Edges used by two faces in the same direction (inconsistent winding, e.g. one face flipped).
    sample : (k, 2, 3) float
        Up to 5 offending edges' end points (boundary first, then non-manifold, then misoriented), m.
    """

    edges: int
    boundary_edges: int
    nonmanifold_edges: int
    misoriented_edges: int
    sample: np.ndarray = field(repr=False)

    @property
    def closed(self) -> bool:
        """Every edge shared by exactly two faces."""
        return self.boundary_edges == 0 and self.nonmanifold_edges == 0

    @property
    def oriented(self) -> bool:
        """Closed and consistently wound (each edge traversed once in each direction)."""
        return self.closed and self.misoriented_edges == 0


@dataclass(frozen=True)
class MeshReport:
    """What the checks found and what was done about it.

    Attributes
    ----------
    source : str
        File or object description.
    units : str
        Length unit of the source coordinates (results are in m).
    file_faces : int
        Triangles in the source.
    vertices : int
        Distinct vertices after welding.
    faces : int
        Triangles integrated (file faces less the dropped degenerate ones, after any repair).
    degenerate_faces : int
        Triangles dropped because two of their corners are the same vertex.
    zero_area_faces : int
        Triangles kept for connectivity although their area is zero (collinear corners).
    bodies : int
        Closed shells with positive volume (after flipping inside-out ones).
    cavities : int
        Shells with negative volume nested inside a body (voids).
    flipped_shells : int
        Shells that were inside out (negative volume, not inside another shell) and were flipped.
    overlapping_shells : int
        Bodies found inside another body (their volume counts twice).
    watertight : bool
        Closed and consistently wound as read (before any repair).
    welded_tolerance : float or None
        Grid spacing (m) used to weld nearly coincident vertices, when exact welding left the mesh open.
    repaired : bool
        Whether ``repair=True`` changed the mesh.
    repair_actions : tuple of str
        What the repair did.
    repair_volume_change : float or None
        Relative change of the signed volume (about the bounding-box centre) caused by the repair.
    bbox_min, bbox_max : (3,) float
        Bounding box, m, mesh axes.
    """

    source: str
    units: str
    file_faces: int
    vertices: int
    faces: int
    degenerate_faces: int
    zero_area_faces: int
    bodies: int
    cavities: int
    flipped_shells: int
    overlapping_shells: int
    watertight: bool
    welded_tolerance: float | None
    repaired: bool
    repair_actions: tuple
    repair_volume_change: float | None
    bbox_min: np.ndarray
    bbox_max: np.ndarray


def degenerate_faces(vertices: np.ndarray, faces: np.ndarray, *, area_rtol: float = 1e-14):
    """Classify degenerate triangles.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    area_rtol : float
        A triangle counts as zero-area when twice its area is below ``area_rtol · L²`` with ``L`` the
        bounding-box diagonal.

    Returns
    -------
    repeated : (m,) bool
        Faces with a repeated vertex index (dropped: they add nothing and break the edge census).
    zero_area : int
        Count of other faces whose area is zero (collinear corners; kept, as they may close a T-junction).
    """
    f = faces
    repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
    if len(vertices) == 0:
        return repeated, 0
    diag2 = float(np.sum((vertices.max(axis=0) - vertices.min(axis=0)) ** 2))
    zero = 0
    step = 1 << 20
    for s in range(0, len(f), step):
        fc = f[s:s + step]
        a = vertices[fc[:, 0]]
        cr = np.cross(vertices[fc[:, 1]] - a, vertices[fc[:, 2]] - a)
        tiny = np.einsum("ij,ij->i", cr, cr) <= (area_rtol * diag2) ** 2
        zero += int(np.count_nonzero(tiny & ~repeated[s:s + step]))
    return repeated, zero


def edge_topology(faces: np.ndarray, n_vertices: int, vertices: np.ndarray | None = None) -> EdgeTopology:
    """Count boundary, non-manifold and misoriented edges.

    Each directed edge ``a→b`` becomes the key ``(min·n + max)·2 + [a > b]``; after one sort, an undirected
    edge of a closed, consistently wound surface appears exactly twice, once in each direction.

    Parameters
    ----------
    faces : (m, 3) int
        Faces without repeated indices.
    n_vertices : int
    vertices : (n, 3) float, optional
        Only used to report where the offending edges are.
    """
    n = np.int64(max(int(n_vertices), 1))
    key = np.empty(3 * len(faces), dtype=np.int64)
    m = len(faces)
    for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0))):
        a = faces[:, i].astype(np.int64)
        b = faces[:, j].astype(np.int64)
        lo = np.minimum(a, b)
        hi = np.maximum(a, b)
        key[k * m:(k + 1) * m] = (lo * n + hi) * 2 + (a > b)
    key.sort()
    if len(key) == 0:
        return EdgeTopology(0, 0, 0, 0, np.zeros((0, 2, 3)))
    undirected = key >> 1
    starts = np.flatnonzero(np.r_[True, undirected[1:] != undirected[:-1]])
    lengths = np.diff(np.r_[starts, len(key)])
    boundary = starts[lengths == 1]
    nonmanifold = starts[lengths > 2]
    pair = starts[lengths == 2]
    misoriented = pair[(key[pair] & 1) == (key[pair + 1] & 1)]
    sample = np.zeros((0, 2, 3))
    if vertices is not None and (len(boundary) or len(nonmanifold) or len(misoriented)):
        picks = np.r_[boundary[:5], nonmanifold[:5], misoriented[:5]][:5]
        u = undirected[picks]
        sample = np.stack([vertices[u // n], vertices[u % n]], axis=1)
    return EdgeTopology(edges=len(starts), boundary_edges=len(boundary), nonmanifold_edges=len(nonmanifold),
                        misoriented_edges=len(misoriented), sample=sample)


def shell_labels(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Connected components of the surface (shells), by shared vertices.

    Returns
    -------
    labels : (m,) int
        Shell index of each face, numbered ``0..count-1`` in order of first appearance.
    count : int
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = len(faces)
    if m == 0:
        return np.zeros(0, dtype=np.intp), 0
    rows = np.concatenate([faces[:, 0], faces[:, 1]])
    cols = np.concatenate([faces[:, 1], faces[:, 2]])
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n_vertices, n_vertices)).tocsr()
    _, vertex_label = connected_components(graph, directed=False)
    face_label = vertex_label[faces[:, 0]]
    # renumber in order of first appearance, keeping only labels that own faces
    _, first, inverse = np.unique(face_label, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))
    return order[inverse].astype(np.intp), len(first)


def winding_number(point, vertices: np.ndarray, faces: np.ndarray) -> float:
    """Generalised winding number of a closed oriented surface about ``point``.

    Sum of the signed solid angles of the triangles (Van Oosterom & Strackee, IEEE Trans. Biomed. Eng.
    30 (1983) 125) over 4π: 1 inside an outward-wound shell, 0 outside, −1 inside an inward-wound one.
    """
    p = np.asarray(point, dtype=np.float64)
    total = 0.0
    step = 1 << 18
    for s in range(0, len(faces), step):
        f = faces[s:s + step]
        a = vertices[f[:, 0]] - p
        b = vertices[f[:, 1]] - p
        c = vertices[f[:, 2]] - p
        la = np.linalg.norm(a, axis=1)
        lb = np.linalg.norm(b, axis=1)
        lc = np.linalg.norm(c, axis=1)
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", a, c) * lb
               + np.einsum("ij,ij->i", b, c) * la)
        total += float(np.sum(2.0 * np.arctan2(num, den)))
    return total / (4.0 * np.pi)
