"""Mesh checks: does the triangle set bound a solid, and how is it split into shells?

The engine refuses to guess: a surface must be closed (every edge shared by exactly two faces), traversed
in opposite directions by the two (consistent winding), before its signed-tetrahedron integral means
anything.  These functions are pure and vectorised (sorting 64-bit edge keys), fast on millions of faces.
``edge_topology`` and ``shell_labels`` run in the C extension when it is built (``inertia_tool._native``),
with identical results; the numpy code here is the reference and the fallback.
"""

from __future__ import annotations

from dataclasses import field
from collections.abc import Sequence
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from ..values import frozen_value
from .._native import accel, faces_for_c, label_dtype, threads
from .edges import edge_keys
from .policy import Certificate

if TYPE_CHECKING:
    from numpy.typing import ArrayLike
    from .uncertainty import Uncertainty

__all__ = ["EdgeTopology", "MeshReport", "repeated_corner_faces", "edge_topology", "shell_labels", "census_and_shells",
           "winding_number"]


@frozen_value
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


@frozen_value
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
        Bodies found overlapping another body (the shared volume counts twice).
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
    method : str
        How the solid was obtained from the surface: ``"exact"`` (the surface integral as it stands),
        ``"oriented"`` (faces wound the wrong way turned, then exact), ``"welded"`` (vertices closer than
        ``welded_tolerance`` merged, then exact), ``"deduplicated"`` (repeated faces dropped, then exact),
        ``"sealed"`` (T-junctions split and crack lips welded without moving any point, then exact),
        ``"sheets-removed"`` (open sheets inside the solid, or fins outside it with ``repair``, left out; R3b),
        ``"union"`` (overlapping bodies united by a boolean, then exact), ``"sum"`` (overlapping bodies'
        integrals added: shared volume counted twice, on request), ``"patched"`` / ``"winding"`` (estimates
        of ``repair=True``, see ``uncertainty``), ``"nesting"`` (a shell wound outward inside another read as a
        cavity by nesting depth where the file does not decide between that and the union: an estimate whose
        bounds cover both, R4).
    uncertainty : Uncertainty or None
        Bounds when ``method`` is an estimate (``mass`` relative, ``center_of_mass`` m, ``inertia`` relative
        Frobenius); None when the result is exact for the polyhedron.
    notes : tuple of str
        What was found and done, one sentence each (non-manifold edges, flipped faces, welds, overlaps).
    flipped_faces : int
        Faces turned to agree with their neighbours.
    nonmanifold_edges : int
        Edges shared by more than two faces in the integrated surface (bodies or walls touching).
    certificate : Certificate
        How far the result can be trusted and the checks that ran and passed (``kind`` one of ``exact``,
        ``united``, ``summed``, ``unverified``, ``estimate``; see :mod:`~.policy`).  The default, for reports
        built outside :func:`~.prepare.prepare_mesh`, is ``unverified``.
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
    repair_actions: tuple[str, ...]
    repair_volume_change: float | None
    bbox_min: np.ndarray
    bbox_max: np.ndarray
    method: str = "exact"
    uncertainty: Uncertainty | None = None
    notes: tuple[str, ...] = ()
    flipped_faces: int = 0
    nonmanifold_edges: int = 0
    certificate: Certificate = Certificate("unverified")

    @property
    def exact(self) -> bool:
        """The mass properties are exact for the polyhedron integrated, proven by the checks of the certificate
        (``exact``, ``united``, or ``summed`` on request); False for estimates and unverified integrals."""
        return self.uncertainty is None and self.certificate.kind in ("exact", "united", "summed")


def repeated_corner_faces(faces: np.ndarray) -> np.ndarray:
    """(m,) bool: triangles with a repeated vertex index.

    They enclose nothing and break the edge census, so the pipeline drops and counts them.  Triangles with
    three distinct but collinear corners (zero area) are kept — they may close a T-junction — and are
    counted by the integration pass (``VolumeMoments.zero_area_faces``).
    """
    f = faces
    repeated: np.ndarray = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
    return repeated


def _edge_keys(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """Directed-edge keys ``2·key + [a > b]`` (:func:`~.edges.edge_keys`), (3m,) int64, sorted; built in chunks of
    faces, so the temporaries stay small on large meshes."""
    m = len(faces)
    key = np.empty(3 * m, dtype=np.int64)
    step = 1 << 18
    for s in range(0, m, step):
        undirected, forward = edge_keys(faces[s:s + step], n_vertices)
        out = key[3 * s:3 * s + len(undirected)]
        np.multiply(undirected, 2, out=out)
        out += forward
    key.sort()
    return key


def _all_paired(key: np.ndarray) -> bool:
    """Fast path: True when every undirected edge occurs exactly twice, once in each direction.

    In the sorted key array that means pairs ``(2e, 2e+1)`` at positions ``2i, 2i+1`` with distinct
    edges from one pair to the next.  Checked in chunks, no large temporaries.
    """
    if len(key) % 2:
        return False
    even, odd = key[0::2], key[1::2]
    step = 1 << 20
    for s in range(0, len(even), step):
        e = even[s:s + step]
        o = odd[s:s + step]
        if not (np.all((e & 1) == 0) and np.all(o == e + 1)):
            return False
        nxt = even[s + 1:s + step + 1]
        if not np.all(nxt > o[:len(nxt)]):
            return False
    return True


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
    if len(faces) == 0:
        return EdgeTopology(0, 0, 0, 0, np.zeros((0, 2, 3)))
    lib = accel()
    if lib is not None:
        return _edge_topology_c(lib, faces, n_vertices, vertices)
    key = _edge_keys(faces, n_vertices)
    if _all_paired(key):
        return EdgeTopology(edges=len(key) // 2, boundary_edges=0, nonmanifold_edges=0, misoriented_edges=0,
                            sample=np.zeros((0, 2, 3)))
    n = np.int64(max(int(n_vertices), 1))
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


#: Faces above which the C extension's one-adjacency census (``census_shells``, 32-bit offsets) is not used.
_CENSUS_SHELLS_MAX_FACES = (2**32 - 1) // 3


def _edge_topology_c(lib: ModuleType, faces: np.ndarray, n_vertices: int,
                     vertices: np.ndarray | None) -> EdgeTopology:
    """``edge_topology`` on the C extension (a sorted per-vertex adjacency instead of one global sort)."""
    if len(faces) <= _CENSUS_SHELLS_MAX_FACES:
        *counts, _ = lib.census_shells(faces_for_c(faces), int(n_vertices), None, threads())
    else:
        counts = lib.edge_census(faces_for_c(faces), int(n_vertices), threads())
    return _topology_from_census(counts, vertices)


def _topology_from_census(counts: Sequence[Any], vertices: np.ndarray | None) -> EdgeTopology:
    """An EdgeTopology from the C census ``(edges, boundary, nonmanifold, misoriented, *samples)``."""
    edges, boundary, nonmanifold, misoriented, *samples = counts
    picks = (samples[0] + samples[1] + samples[2])[:5]    # same order as the numpy path
    sample = np.zeros((0, 2, 3))
    if vertices is not None and picks:
        u, v = np.array(picks, dtype=np.intp).T
        sample = np.stack([vertices[u], vertices[v]], axis=1)
    return EdgeTopology(edges=edges, boundary_edges=boundary, nonmanifold_edges=nonmanifold,
                        misoriented_edges=misoriented, sample=sample)


def shell_labels(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Connected components of the surface (shells), joined through shared edges.

    Two faces are in one shell when a chain of faces, each sharing an edge with the next, joins them.  Faces
    that meet only at a vertex are in different shells: a non-manifold vertex is split into its fans
    (rule R1 of :mod:`~.policy`), so two bodies sharing a corner are two shells, tested against each other.

    Returns
    -------
    labels : (m,) int32 (int64 from 2**31 faces: :func:`~inertia_tool._native.label_dtype`)
        Shell index of each face, ``0..count-1`` (numbered by the smallest vertex index of the shell when no
        vertex is shared between shells, else in order of each shell's first face).
    count : int
    """
    lib = accel()
    if lib is not None and len(faces) <= _CENSUS_SHELLS_MAX_FACES:
        return census_and_shells(faces, n_vertices)[1:]
    labels, count = _vertex_shell_labels(faces, n_vertices)
    if len(faces) < 2:
        return labels, count
    edge_labels, edge_count = _edge_shell_labels(faces, n_vertices)
    if edge_count == count:
        return labels, count
    return edge_labels, edge_count


def census_and_shells(faces: np.ndarray, n_vertices: int,
                      vertices: np.ndarray | None = None) -> tuple[EdgeTopology, np.ndarray, int]:
    """:func:`edge_topology` and :func:`shell_labels` of the same faces, with identical results.

    The C extension takes both from one sorted adjacency (each edge bucketed by its smaller end, the buckets
    sorted on :func:`~inertia_tool._native.threads` threads: ``census_shells``); without it, or beyond its
    32-bit offsets, the two functions run one after the other.

    Returns
    -------
    topology : EdgeTopology
    labels : (m,) int
        Shell index of each face, as :func:`shell_labels`.
    count : int
    """
    lib = accel()
    if lib is None or len(faces) > _CENSUS_SHELLS_MAX_FACES:
        labels, count = shell_labels(faces, n_vertices)
        return edge_topology(faces, n_vertices, vertices), labels, count
    # on a kept mapping of the extension (uninitialised, like numpy.empty): a later analysis in the process
    # writes its labels into pages faulted in already
    dtype = label_dtype(len(faces))     # int32: the C kernel keeps its union-find parents in place
    labels = np.frombuffer(lib.Scratch(len(faces) * dtype.itemsize), dtype=dtype)
    *counts, count = lib.census_shells(faces_for_c(faces), int(n_vertices), labels, threads())
    if len(faces) == 0:
        return EdgeTopology(0, 0, 0, 0, np.zeros((0, 2, 3))), labels, 0
    if count == 1:        # one shell: every label 0, as a read-only view of one zero; the buffer goes back to the
        labels = np.broadcast_to(np.zeros(1, dtype=dtype), (len(faces),))   # pool, which the check unmaps
    return _topology_from_census(counts, vertices), labels, int(count)


def _edge_shell_labels(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Components of faces joined through shared (undirected) edges, numbered by first face.

    The C extension buckets the edges by their smaller end and unites the faces of each edge
    (``edge_shell_labels``); the numpy path sorts the edge keys, links the faces sharing a key and takes
    scipy's ``connected_components``.
    """
    m = len(faces)
    lib = accel()
    if lib is not None and m < 2**31 - 1:
        out = np.empty(m, dtype=label_dtype(m))
        count = lib.edge_shell_labels(faces_for_c(faces), int(n_vertices), out)
        return out, int(count)
    key = edge_keys(faces, n_vertices)[0]
    order = np.argsort(key)
    skey = key[order]
    same = skey[1:] == skey[:-1]
    del key, skey
    rows, cols = order[:-1][same] // 3, order[1:][same] // 3
    del order, same
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(m, m))
    n_components, label = connected_components(graph, directed=False)
    _, first = np.unique(label, return_index=True)
    rank = np.empty(n_components, dtype=np.intp)
    rank[np.argsort(first, kind="stable")] = np.arange(n_components)
    return rank[label].astype(label_dtype(m)), int(n_components)


def _vertex_shell_labels(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Connected components of the surface by shared vertices (the C extension when built)."""
    m = len(faces)
    if m == 0:
        return np.zeros(0, dtype=label_dtype(0)), 0
    lib = accel()
    if lib is not None:      # union-find over vertices, the same numbering
        labels = np.empty(m, dtype=label_dtype(m))
        count = lib.shell_labels(faces_for_c(faces), int(n_vertices), labels)
        return labels, int(count)
    from scipy.sparse import coo_matrix     # the numpy path only: scipy.sparse costs ~0.2 s to import
    from scipy.sparse.csgraph import connected_components

    # each face links corner 0 to corners 1 and 2: enough to connect all three
    rows = np.repeat(np.asarray(faces[:, 0]), 2)
    cols = np.asarray(faces[:, 1:]).reshape(-1)
    graph = coo_matrix((np.ones(2 * m, dtype=np.int8), (rows, cols)), shape=(n_vertices, n_vertices)).tocsr()
    del rows, cols
    count, vertex_label = connected_components(graph, directed=True, connection="weak")
    face_label = vertex_label[faces[:, 0]]
    if count == 1:
        return np.zeros(m, dtype=label_dtype(m)), 1
    present = np.zeros(count, dtype=bool)
    present[face_label] = True
    remap = np.cumsum(present) - 1
    return remap[face_label].astype(label_dtype(m)), int(present.sum())


def winding_number(point: ArrayLike, vertices: np.ndarray, faces: np.ndarray) -> float:
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
