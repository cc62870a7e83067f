"""Overlapping bodies: a sound test for crossing surfaces, and the union by a robust boolean (manifold3d).

When closed shells overlap (two bodies modelled through each other, or one surface passing through itself
at non-manifold edges), the summed divergence-theorem integral counts the shared volume twice: the winding
number there is 2.  The physical solid is the union ``{w ≥ 1}``.

* :func:`crossing_shells` finds the shells whose surface touches or crosses a surface, by the exact
  face-pair classification of :func:`~.intersect.surface_contacts` (every pair of faces whose boxes meet,
  shared vertices included); :func:`union_surface` is the arbiter (the union's volume equals the summed volume
  when nothing overlaps).
* :func:`closed_groups` splits a balanced surface into closed, manifold pieces: the patches of faces joined
  through manifold edges, with unclosed patches merged across the edges they share.
* :func:`union_surface` builds one manifold3d ``Manifold`` per piece (float64 ``Mesh64``), takes the union of
  the outward pieces minus the union of the inward ones (cavities) and returns the result as a triangle
  surface, which the caller integrates exactly like any other.
* :func:`winding_solid` forms ``{w ≥ 1}`` of pieces as wound, from the sets each covered at least ``t`` times,
  where no body can be named for a cavity (hollow parts overlapping).

manifold3d (Elalish et al., "Manifold", github.com/elalish/manifold; PyPI ``manifold3d``) guarantees a
manifold output for manifold inputs, with symbolic perturbation for coplanar and touching cases.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from ..values import frozen_value

__all__ = ["crossing_shells", "closed_groups", "union_surface", "UnionSurface", "UnionError", "common_volumes",
           "two_manifold", "piece_solids", "PieceSolids", "winding_solid", "WINDING_PIECES"]


class UnionError(RuntimeError):
    """The boolean union could not be formed (manifold3d missing, or a piece it rejects)."""


# -- which shells meet another surface -------------------------------------------------------------------

def crossing_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, query: np.ndarray, *,
                    max_pairs: int | None = None) -> np.ndarray | None:
    """Shells having a face that meets another face beyond what the two share by index (crossing, coplanar
    overlap or boundary contact), for faces in ``query``; a thin caller of
    :func:`~.intersect.surface_contacts`, which tests every pair of faces (the same shell included).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face.
    query : (m,) bool
        Only pairs with at least one face in ``query`` count.
    max_pairs : int, optional
        Work bound on candidate pairs; beyond it the test gives up and returns None (the caller then lets
        the boolean union decide).

    Returns
    -------
    (s,) bool or None
        Per shell (``s = labels.max() + 1``): some face of it meets another face of the mesh.
    """
    from .intersect import surface_contacts

    n_shells = int(labels.max()) + 1 if len(labels) else 0
    found = np.zeros(n_shells, dtype=bool)
    query = np.asarray(query, dtype=bool)
    if not np.any(query):
        return found
    contacts = surface_contacts(vertices, faces, max_pairs=max_pairs)
    if not contacts.complete:
        return None
    pairs = np.concatenate([contacts.crossing, contacts.coplanar_opposite, contacts.contact])
    pairs = pairs[query[pairs[:, 0]] | query[pairs[:, 1]]]
    found[labels[pairs.reshape(-1)]] = True
    return found


# -- closed pieces and their union ------------------------------------------------------------------------

def closed_groups(faces: np.ndarray, n_vertices: int) -> tuple[np.ndarray, int]:
    """Split a balanced surface into pieces each closed and balanced on its own.

    Patches are the components of the faces joined through manifold edges (exactly two faces); a patch
    that is not closed on its own (its boundary runs along non-manifold edges) is merged with the unclosed
    patches it shares such edges with.

    Returns
    -------
    labels : (m,) int
        Piece of each face, ``0..count-1``.
    count : int
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .edges import edge_keys

    f = np.asarray(faces)
    m = len(f)
    key, forward = edge_keys(f, n_vertices)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.flatnonzero(np.r_[True, skey[1:] != skey[:-1]])
    count = np.diff(np.r_[starts, len(skey)])
    pair = starts[count == 2]
    f1, f2 = order[pair] // 3, order[pair + 1] // 3
    n_patch, patch = connected_components(coo_matrix((np.ones(len(f1), dtype=np.int8), (f1, f2)), shape=(m, m)),
                                          directed=False)
    # patches unbalanced on their own: join those meeting at a non-manifold edge
    keyed_patch = patch[order // 3]
    edge_of = np.repeat(np.arange(len(starts)), count)
    sign = np.where(forward[order], 1, -1)
    patch_edge = keyed_patch.astype(np.int64) * len(starts) + edge_of
    unique, inverse = np.unique(patch_edge, return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=sign)      # net direction count of each (patch, edge)
    unbalanced = np.zeros(n_patch, dtype=bool)
    unbalanced[(unique[net != 0] // len(starts)).astype(np.int64)] = True
    big = starts[count > 2]
    rows, cols = [], []
    for s, c in zip(big, count[count > 2]):
        members = np.unique(keyed_patch[s:s + c])
        members = members[unbalanced[members]]
        if len(members) > 1:
            rows.append(members[:-1])
            cols.append(members[1:])
    if rows:
        r, c = np.concatenate(rows), np.concatenate(cols)
        _, group = connected_components(coo_matrix((np.ones(len(r), dtype=np.int8), (r, c)),
                                                   shape=(n_patch, n_patch)), directed=False)
    else:
        group = np.arange(n_patch)
    _, labels = np.unique(group[patch], return_inverse=True)
    return labels.reshape(-1).astype(np.intp), int(labels.max()) + 1 if m else 0


@frozen_value
class UnionSurface:
    """The boundary of the union, as produced by manifold3d.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes.
    faces : (k, 3) int64
        Outward-wound, closed, manifold.
    volume : float
        manifold3d's own volume of the result, m³ (a cross-check of the exact integral).
    manifold_pieces : bool
        Every piece given to the boolean was two-manifold (:func:`two_manifold`), the input manifold3d's
        guarantees assume.  A piece that :func:`closed_groups` joined at non-manifold edges (bodies welded at
        shared edges or faces) is not: the union then proves nothing about it, even where its volume agrees.
    """

    vertices: np.ndarray
    faces: np.ndarray
    volume: float
    manifold_pieces: bool = True


#: A ``manifold3d.Manifold``: the package ships no type information, so to mypy it is ``Any``.
_Manifold = Any


def two_manifold(faces: np.ndarray, groups: np.ndarray | None = None) -> bool:
    """Whether every edge of ``faces`` (m, 3) is used by exactly two faces, in opposite directions (by vertex
    index), within each group of ``groups`` (m,) when given: the input manifold3d's booleans assume."""
    from .edges import edge_keys

    f = np.asarray(faces, dtype=np.int64)
    key, forward = edge_keys(f, int(f.max()) + 1 if len(f) else 1)
    group = np.zeros(len(key), dtype=np.int64) if groups is None else np.repeat(np.asarray(groups, np.int64), 3)
    order = np.lexsort((key, group))
    skey, sgroup, fwd = key[order], group[order], forward[order]
    same = (skey[1:] == skey[:-1]) & (sgroup[1:] == sgroup[:-1])      # slot i and i + 1 on one edge of one group
    return bool(len(skey) % 2 == 0 and np.all(same[0::2]) and not np.any(same[1::2])
                and np.all(fwd[0::2] != fwd[1::2]))


def _manifold(m3: ModuleType, vertices: np.ndarray, faces: np.ndarray) -> _Manifold:
    used, inverse = np.unique(faces, return_inverse=True)
    mesh = m3.Mesh64(vert_properties=np.ascontiguousarray(vertices[used], dtype=np.float64),
                     tri_verts=np.ascontiguousarray(inverse.reshape(-1, 3), dtype=np.uint64))
    solid = m3.Manifold(mesh)
    status = str(solid.status())
    if not status.endswith("NoError"):
        raise UnionError(f"a closed piece of {len(faces):,} faces is not accepted by the boolean ({status})")
    return solid


class PieceSolids(NamedTuple):
    """manifold3d solids built once and shared by the booleans that need them (:func:`union_surface` builds the
    closed pieces' solids; :func:`common_volumes` reuses those that are whole shells).

    Attributes
    ----------
    centre : (3,) float64
        m, mesh axes: the solids are built on the vertices less it (the centre of their bounding box; the boolean
        works near the origin).  A solid is only reused by a caller whose vertices give the same centre.
    solids : dict of int to Manifold
        The solid of each piece (or shell), wound outward (material), keyed by its index.
    """

    centre: np.ndarray
    solids: dict[int, _Manifold]


def _local_frame(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """float64 vertices less the centre of their bounding box (the boolean works near the origin), and the
    centre."""
    v = np.asarray(vertices, dtype=np.float64)
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    return v - centre, centre


def _import_manifold3d() -> ModuleType:
    try:
        import manifold3d as m3
    except ImportError as exc:  # pragma: no cover - a runtime dependency
        raise UnionError("the union of overlapping bodies needs the manifold3d package") from exc
    module: ModuleType = m3
    return module


def piece_solids(vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray, n_groups: int,
                 outward: np.ndarray, body: np.ndarray | None = None) -> PieceSolids:
    """The manifold3d solid of each closed piece, each wound outward (a cavity turned), in the order
    :func:`union_surface` takes them (body by body); parameters as for :func:`union_surface`.

    Returns
    -------
    PieceSolids
        Keyed by piece; a piece without faces has no solid.

    Raises
    ------
    UnionError
        manifold3d is missing, or refuses a piece (the first refused in that order is named).
    """
    m3 = _import_manifold3d()
    local, centre = _local_frame(vertices)
    f = np.asarray(faces, dtype=np.int64)
    body = np.zeros(n_groups, dtype=np.int64) if body is None else np.asarray(body)
    order = np.argsort(groups, kind="stable")
    starts = np.searchsorted(groups[order], np.arange(n_groups + 1))
    solids: dict[int, _Manifold] = {}
    for b in np.unique(body):
        for g in np.flatnonzero(body == b).tolist():
            piece = f[order[starts[g]:starts[g + 1]]]
            if len(piece):
                solids[g] = _manifold(m3, local, piece if outward[g] else piece[:, ::-1])
    return PieceSolids(centre, solids)


def union_surface(vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray, n_groups: int,
                  outward: np.ndarray, body: np.ndarray | None = None, *,
                  solids: PieceSolids | None = None) -> UnionSurface:
    """The solid of overlapping pieces: per body, its outward pieces united minus its inward ones; all united.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    groups : (m,) int
        Closed piece of each face (see :func:`closed_groups`).
    n_groups : int
    outward : (n_groups,) bool
        Whether each piece is wound outward (material); inward pieces are cavities.
    body : (n_groups,) int, optional
        The body each piece belongs to (a cavity belongs to the body around it); cavities are subtracted
        from their own body only, so a part sitting inside another part's void stays.  Default: one body.
    solids : PieceSolids, optional
        The pieces' solids as :func:`piece_solids` builds them from the same arguments (built here when not
        given; a caller that reuses them builds them once).

    Returns
    -------
    UnionSurface

    Raises
    ------
    UnionError
    """
    m3 = _import_manifold3d()
    if solids is None:
        solids = piece_solids(vertices, faces, groups, n_groups, outward, body)
    body = np.zeros(n_groups, dtype=np.int64) if body is None else np.asarray(body)
    united = []
    for b in np.unique(body):
        material: list[_Manifold] = []
        voids: list[_Manifold] = []
        for g in np.flatnonzero(body == b).tolist():
            if g in solids.solids:
                (material if outward[g] else voids).append(solids.solids[g])
        if not material:
            continue
        solid = m3.Manifold.batch_boolean(material, m3.OpType.Add) if len(material) > 1 else material[0]
        if voids:
            solid = solid - (m3.Manifold.batch_boolean(voids, m3.OpType.Add) if len(voids) > 1 else voids[0])
        united.append(solid)
    if not united:
        raise UnionError("no outward-wound piece to unite")
    solid = m3.Manifold.batch_boolean(united, m3.OpType.Add) if len(united) > 1 else united[0]
    out = solid.to_mesh64()
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3] + solids.centre
    tris = np.asarray(out.tri_verts, dtype=np.int64).reshape(-1, 3)
    return UnionSurface(vertices=verts, faces=tris, volume=float(solid.volume()),
                        manifold_pieces=two_manifold(np.asarray(faces, dtype=np.int64), groups))


#: Work bound of :func:`winding_solid`: closed pieces (material and voids together).  The level sets take at most
#: ``pieces × depth`` booleans (depth the most pieces overlapping at a point); beyond this count it refuses.
WINDING_PIECES = 24


def _levels(m3: ModuleType, pieces: list[_Manifold], times: list[int] | None = None) -> list[_Manifold]:
    """``L_t = {x: at least t of the pieces contain x}`` for ``t = 1, 2, ...`` up to the last non-empty one, a piece
    counted ``times`` over (R0: a shell listed ``k`` times; default once each).

    One pass over the pieces, ``L_t ← L_t ∪ (P ∩ L_{t−k})`` for a piece ``P`` counted ``k`` times (``L_s`` everything
    for ``s ≤ 0``): at most ``len(pieces) × depth`` booleans, never one per subset, and no piece is cut by itself
    (a box listed twice is not intersected with its copy, whose faces coincide)."""
    levels: list[_Manifold] = []
    for piece, k in zip(pieces, times if times is not None else [1] * len(pieces)):
        grown: list[_Manifold] = []
        for t in range(1, len(levels) + k + 1):
            below = t - k                                 # L_{t-k} of the old levels; everything when below 1
            met = piece if below < 1 else piece ^ levels[below - 1]
            old = levels[t - 1] if t <= len(levels) else None
            if below >= 1 and met.is_empty():
                if old is None:
                    break                                 # deeper levels are empty too (L_t shrinks with t)
                grown.append(old)
                continue
            grown.append(met if old is None else old + met)
        levels = grown
    return levels


def winding_solid(vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray, n_groups: int,
                  outward: np.ndarray, *, solids: PieceSolids | None = None,
                  multiplicity: np.ndarray | None = None) -> tuple[UnionSurface, float]:
    """The solid ``{w ≥ 1}`` of closed pieces wound as given, without reading which body a cavity belongs to.

    With material pieces ``B_i`` (wound outward) and voids ``C_j`` (wound inward) the winding number is
    ``w = Σ [B_i] − Σ [C_j]``, so ``w ≥ 1`` exactly where, for some ``t ≥ 1``, at least ``t`` of the ``B_i`` and
    fewer than ``t`` of the ``C_j`` contain the point: ``{w ≥ 1} = ∪_t (L_t(B) − L_t(C))`` with ``L_t`` the set
    covered at least ``t`` times (:func:`_levels`).  Two hollow parts overlapping (a cavity inside both bodies, or
    one cavity inside the other) need no owner for their cavities: review 10 found the owner-by-owner union
    3–31 % high on every such draw.

    Parameters
    ----------
    vertices, faces, groups, n_groups, outward, solids
        As for :func:`union_surface` (``outward``: as the file winds each piece).
    multiplicity : (n_groups,) int, optional
        How many times each piece counts in ``w`` (R0: a shell listed ``k`` times is ``k`` of the ``B_i`` or
        ``C_j``); default once each.

    Returns
    -------
    surface : UnionSurface
    outside : float
        m³, the volume of the voids outside every material piece (``L_1(C) − L_1(B)``): there the file's winding
        is negative with no body around, a body written inside out or a cavity placed wrong, which the file does
        not decide; 0 when every void lies in material.  (Voids overlapping inside material make ``w < 0`` too,
        and are simply empty: two crossing cavities.)

    Raises
    ------
    UnionError
        More than :data:`WINDING_PIECES` pieces, manifold3d missing or refusing a piece, or nothing left.
    """
    if n_groups > WINDING_PIECES:
        raise UnionError(f"{n_groups} closed pieces, more than the {WINDING_PIECES} the winding-number boolean "
                         "takes")
    m3 = _import_manifold3d()
    if solids is None:
        solids = piece_solids(vertices, faces, groups, n_groups, outward)
    times = np.ones(n_groups, dtype=np.int64) if multiplicity is None else np.asarray(multiplicity, dtype=np.int64)
    material = [g for g in range(n_groups) if g in solids.solids and outward[g]]
    voids = [g for g in range(n_groups) if g in solids.solids and not outward[g]]
    if not material:
        raise UnionError("no outward-wound piece to unite")
    cover = _levels(m3, [solids.solids[g] for g in material], [int(times[g]) for g in material])
    holes = _levels(m3, [solids.solids[g] for g in voids], [int(times[g]) for g in voids])
    kept = [level - holes[t] if t < len(holes) else level for t, level in enumerate(cover)]
    outside = float((holes[0] - cover[0]).volume()) if holes else 0.0
    solid = m3.Manifold.batch_boolean(kept, m3.OpType.Add) if len(kept) > 1 else kept[0]
    out = solid.to_mesh64()
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3] + solids.centre
    tris = np.asarray(out.tri_verts, dtype=np.int64).reshape(-1, 3)
    return UnionSurface(vertices=verts, faces=tris, volume=float(solid.volume()),
                        manifold_pieces=two_manifold(np.asarray(faces, dtype=np.int64), groups)), outside


def common_volumes(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, volumes: np.ndarray,
                   pairs: np.ndarray, *, solids: PieceSolids | None = None) -> np.ndarray:
    """Volume shared by the solids of two shells, each taken wound outward, for each pair (manifold3d, float64).

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face.
    volumes : (s,) float
        Signed volume of each shell as wound (the sign says which way to turn it outward).
    pairs : (k, 2) int
        Pairs of shells.
    solids : PieceSolids, optional
        Solids already built of some shells, keyed by shell, each wound outward (e.g. the pieces
        :func:`union_surface` took that are whole shells): used for the shells of positive volume when their
        centre is this surface's; every other shell's solid is built here.

    Returns
    -------
    (k,) float
        ``vol(A ∩ B)`` in m³, NaN where manifold3d is missing or refuses a shell (not a closed manifold alone).
    """
    out = np.full(len(pairs), np.nan)
    try:
        import manifold3d as m3
    except ImportError:  # pragma: no cover - a runtime dependency
        return out
    local, centre = _local_frame(vertices)
    built: dict[int, _Manifold | None] = {}
    if solids is not None and np.array_equal(solids.centre, centre):       # the same frame: the same solids
        built.update((k, s) for k, s in solids.solids.items() if volumes[k] > 0)

    def solid(k: int) -> _Manifold | None:
        if k not in built:
            piece = np.asarray(faces)[labels == k]
            try:
                built[k] = _manifold(m3, local, piece if volumes[k] > 0 else piece[:, ::-1])
            except UnionError:
                built[k] = None
        return built[k]

    for row, (a, b) in enumerate(np.asarray(pairs, dtype=np.int64).reshape(-1, 2).tolist()):
        sa, sb = solid(a), solid(b)
        if sa is not None and sb is not None:
            out[row] = float((sa ^ sb).volume())
    return out
