"""The cavity (and insert) as closed meshes inside the part, keeping the wall from its surface.

* :func:`_cavity_values` — the region ``depth ≥ wall + margin`` and ``s_k q_k < 0`` as a scalar field on the
  grid's cell centres (depth from the grid, quadrics analytic, creases rounded by a smooth minimum), meshed by
  marching tetrahedra (:mod:`.tetra`);
* :func:`_region` — its mesh, slivers dropped, the wall measured exactly from every vertex
  (``design.grid.surface_distance``) and the mesh remade deeper when it is too thin;
* :func:`cut_pocket` — the part's surface plus the cavity's turned inward (no boolean: the cavity keeps the
  wall from the surface); with an insert, the pocket (cavity ∪ insert region) is meshed the same way as one
  region, and the insert as another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import PhysicsError
from .grid import surface_distance
from .optimize import QuadricCavity

__all__ = ["cut_pocket", "Pocket", "DEPTH_MARGIN", "SIMPLIFY", "EDGE_MARGIN", "MIN_VOID_CELLS", "MAX_MESH_ATTEMPTS"]

#: Cells of extra depth asked of the cavity beyond the wall (the depths near the wall are exact at the cell
#: centres; the margin covers the linear interpolation of the level set between them).
DEPTH_MARGIN = 0.5

#: The cavity mesh is simplified (``Manifold.simplify``) within this fraction of a cell: marching tetrahedra
#: make about four times the triangles a surface of that detail needs (memory and time of the re-analysis, size
#: of the file); the surface moves by at most this much, and the wall is measured after.
SIMPLIFY = 0.02

#: Largest cavity mesh (triangles) simplified through manifold3d, whose structures hold about 200 bytes a
#: triangle (bounds the memory at resolution 128); larger ones are kept as marching tetrahedra made them.
SIMPLIFY_MAX_TRIANGLES = 250_000

#: Fraction of a lattice edge kept between a cavity vertex and the lattice points (``design.tetra``): distinct
#: vertices stay about 0.03 cells apart, far beyond the rounding of a float32 file.
EDGE_MARGIN = 0.05

#: Smallest separate void kept, in cell volumes.
MIN_VOID_CELLS = 8

#: Attempts at meshing the cavity, each with half a cell more margin if the measured wall came out thin.
MAX_MESH_ATTEMPTS = 4


def _cavity_values(grid, terms, centre, half: float, origin, frame, threshold: float, lo, hi):
    """The scalar field ``min(depth − threshold, −s_k q_k · half_extent …)`` (m, positive inside the region) at
    the grid's cell centres from ``lo`` to ``hi`` (index triples, inclusive, within the grid), with one layer
    of −h around them (so that the surface closes), for the quadric ``terms`` ``[(coefficients, s_k)]``
    (``s = +1``: inside where ``q < 0``; ``−1``: outside it), creases rounded over a quarter cell.

    Returns (values (nx + 2, ny + 2, nz + 2), position of the first sample (3,) m)."""
    h = grid.spacing
    shape = tuple(int(hi[d] - lo[d] + 1) for d in range(3))
    first = grid.origin + h * (np.asarray(lo, dtype=np.float64) - 1.0)
    axes = [grid.origin[d] + h * np.arange(lo[d], hi[d] + 1, dtype=np.float64) for d in range(3)]
    # frame coordinates, normalised: x̂ = (Rᵀ (x − o) − centre)/half, one axis at a time
    r = np.asarray(frame, dtype=np.float64)
    shift = (-(r.T @ np.asarray(origin, dtype=np.float64)) - np.asarray(centre)) / half
    # ``terms`` is one list of quadrics (their intersection) or a list of such lists (the union of the regions)
    alternatives = terms if isinstance(terms[0], list) else [terms]
    smooth = 0.25 * h
    padded = np.full((shape[0] + 2, shape[1] + 2, shape[2] + 2), -h)
    for start in range(0, shape[0], _SLAB):              # a slab at a time: its temporaries, not the box's
        stop = min(start + _SLAB, shape[0])
        x_axis = axes[0][start:stop]
        normalised = []
        for row in range(3):
            normalised.append((r[0, row] / half) * x_axis[:, None, None]
                              + ((r[1, row] / half) * axes[1])[None, :, None]
                              + ((r[2, row] / half) * axes[2])[None, None, :] + shift[row])
        u, v, w = normalised
        deep = grid.signed_distance[lo[0] + start:lo[0] + stop, lo[1]:hi[1] + 1,
                                    lo[2]:hi[2] + 1].astype(np.float64) - threshold
        union = None
        for alternative in alternatives:
            value = deep
            for t, sign in alternative:
                c = np.asarray(t, dtype=np.float64) / np.linalg.norm(t)
                q = (c[0] + c[1] * u + c[2] * v + c[3] * w + c[4] * u * u + c[5] * v * v + c[6] * w * w
                     + c[7] * u * v + c[8] * u * w + c[9] * v * w)
                inner = -sign * q * half
                # smooth minimum (rounds the crease where the wall meets the quadric, so the two sheets of the
                # marching tetrahedra do not pinch at a shared point): min(d, e) − k log(1 + exp(−|d − e|/k))
                value = np.minimum(value, inner) - smooth * np.log1p(np.exp(-np.abs(value - inner) / smooth))
            union = value if union is None else np.maximum(union, value)
        padded[1 + start:1 + stop, 1:-1, 1:-1] = union
    return padded, first


#: Lattice planes evaluated at once by :func:`_cavity_values` (bounds its temporaries).
_SLAB = 8


def _manifold_of(vertices, faces):
    import manifold3d

    mesh = manifold3d.Mesh64(vert_properties=np.array(vertices, dtype=np.float64, order="C"),   # writable copies
                             tri_verts=np.array(faces, dtype=np.uint64, order="C"))
    return manifold3d.Manifold(mesh)


def _arrays_of(manifold: Any) -> tuple[np.ndarray, np.ndarray]:
    mesh = manifold.to_mesh64()
    return np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)


def _storage_rounded(vertices, storage_scale: float | None) -> np.ndarray:
    """The vertices as a float32 file in the unit ``storage_scale`` (m per unit) holds them (None: as they are)."""
    v = np.asarray(vertices, dtype=np.float64)
    if storage_scale is None:
        return v
    return (v / storage_scale).astype(np.float32).astype(np.float64) * storage_scale


def _without_specks(vertices, faces, min_volume: float):
    """The mesh without its connected pieces of volume below ``min_volume`` (m³)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(vertices)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges), dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n))
    count, label = connected_components(graph, directed=False)
    face_label = label[faces[:, 0]]
    tri = vertices[faces]
    six_volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    volume = np.bincount(face_label, weights=six_volume, minlength=count) / 6.0
    keep = np.abs(volume[face_label]) >= min_volume
    if np.all(keep):
        return vertices, faces
    kept = faces[keep]
    used, new_index = np.unique(kept.ravel(), return_inverse=True)
    return vertices[used], new_index.reshape(-1, 3)


def _simplified(vertices, faces, tolerance: float):
    """manifold3d's ``simplify`` of a closed mesh (edges collapsed within ``tolerance``, m), or None if manifold3d
    does not take it as a manifold."""
    import manifold3d

    solid = _manifold_of(vertices, faces)
    if solid.status() != manifold3d.Error.NoError:
        return None
    return _arrays_of(solid.simplify(tolerance))


def _box(grid, cells):
    """Grid index range (lo, hi, inclusive) of the lattice around ``cells`` (centres, m), two cells wider."""
    index = np.rint((cells - grid.origin) / grid.spacing).astype(np.int64)
    return (np.maximum(index.min(axis=0) - 2, 0), np.minimum(index.max(axis=0) + 2, np.array(grid.shape) - 1))


def _region(grid, terms, centre, half, cells, vertices, faces, origin, frame, wall: float, tree=None,
            storage_scale: float | None = None, *, box=None, margins=None, simplify: bool = True):
    """Closed meshes of the region of ``terms`` deeper than the wall, by marching tetrahedra on the grid's cell
    centres (``design.tetra``), rounded as the file will hold them, each with its wall measured exactly;
    remeshed deeper (up to ``MAX_MESH_ATTEMPTS``) if thinner than ``wall``.

    Returns a list of candidates ``(vertices, faces, measured wall)``, preferred first: the mesh simplified by
    manifold3d within ``SIMPLIFY`` cells (when it has at most ``SIMPLIFY_MAX_TRIANGLES`` triangles), then the
    marching tetrahedra's own; empty when the region is.  ``box`` (lattice range), ``margins`` (the depth
    margins tried, m) and ``simplify=False`` let two regions be meshed on the same lattice and field values, so
    that where their fields agree their surfaces are the same triangles."""
    from .tetra import marching_tetrahedra

    h = grid.spacing
    lo, hi = _box(grid, cells) if box is None else box
    if margins is None:
        margins = [DEPTH_MARGIN * h + 0.5 * h * k for k in range(MAX_MESH_ATTEMPTS)]
    thinnest = math.inf
    for margin in margins:
        values, first = _cavity_values(grid, terms, centre, half, origin, frame, wall + margin, lo, hi)
        region_v, region_f = marching_tetrahedra(values, first, h, edge_margin=EDGE_MARGIN)
        del values
        # slivers the marching tetrahedra leave where the field grazes zero: voids smaller than (2h)³ change
        # the moments by nothing measurable and no print could be emptied of them
        if len(region_f):
            region_v, region_f = _without_specks(region_v, region_f, MIN_VOID_CELLS * h ** 3)
        if not len(region_f):
            return []
        meshes = []
        if simplify and len(region_f) <= SIMPLIFY_MAX_TRIANGLES:
            simplified = _simplified(region_v, region_f, SIMPLIFY * h)
            if simplified is not None and len(simplified[1]):
                meshes.append(simplified)
        meshes.append((region_v, region_f))
        kept = []
        for mesh_v, mesh_f in meshes:
            mesh_v = _storage_rounded(mesh_v, storage_scale)
            measured = float(surface_distance(mesh_v, vertices, faces, cutoff=wall + h, tree=tree).min())
            thinnest = min(thinnest, measured)
            if measured >= wall:
                kept.append((mesh_v, mesh_f, measured))
        if kept:
            return kept
    raise PhysicsError(f"could not mesh a cavity keeping a wall of {wall:g} m: the thinnest came out "
                       f"{thinnest:g} m after {len(margins)} attempts")


@dataclass(frozen=True)
class Pocket:
    """One way of meshing the design: the hollowed part and the insert (None without), as the file will hold
    them.

    Attributes
    ----------
    vertices : (n, 3) float
        The hollowed part, m: the part's surface and the cavity's, wound inward (outward of the material).
    faces : (m, 3) int
    insert_vertices, insert_faces : arrays or None
        The insert, m.
    measured_wall : float
        Smallest distance from a vertex of the cavity (or insert) surface to the part's surface, m.
    """

    vertices: np.ndarray
    faces: np.ndarray
    insert_vertices: np.ndarray | None
    insert_faces: np.ndarray | None
    measured_wall: float


def cut_pocket(vertices, faces, grid, design, centres, origin, frame, wall: float, *, tree=None,
               storage_scale: float | None = None) -> list[Pocket]:
    """Mesh the cavity (and the insert), check the wall exactly, and hollow the part.

    The cavity keeps at least ``wall`` from the part's surface (measured), so the hollowed part is the part's
    surface plus the cavity's, turned inward: no boolean, and nothing of the cavity comes within rounding of
    the outer surface.  With an insert the pocket is the union of the cavity and the insert regions (the larger
    of their fields, one surface) and the insert its own region, both on one lattice with the same margin and
    not simplified: where the insert bounds the pocket, both surfaces are the same triangles.

    ``design`` is a :class:`QuadricCavity` or a :class:`~.insert.QuadricInsert`; ``storage_scale`` (m per unit)
    rounds the new vertices as a float32 file in that unit holds them.  Returns the candidates, preferred
    first (empty: no cavity).
    """
    cavity = design if isinstance(design, QuadricCavity) else design.cavity
    inserted = getattr(design, "inserted", None)
    part_v = _storage_rounded(vertices, storage_scale)
    part_f = np.asarray(faces, dtype=np.int64)
    holes: list = []
    in_q1 = cavity.removed if inserted is None else cavity.removed | (inserted & (cavity.values(
        (centres - origin) @ frame) < 0))
    if np.any(in_q1) and not (inserted is not None and np.any(inserted)):
        holes = _region(grid, [(cavity.coefficients, 1.0)], cavity.centre, cavity.half_extent,
                        centres[in_q1], vertices, faces, origin, frame, wall, tree, storage_scale)
    pockets: list[Pocket] = []
    if inserted is None or not np.any(inserted):
        for hole_v, hole_f, measured in holes:
            pockets.append(Pocket(np.vstack([part_v, hole_v]), np.vstack([part_f, hole_f[:, ::-1] + len(part_v)]),
                                  None, None, measured))
        return pockets
    # the pocket is the union of both regions (the larger of their fields), meshed as one surface: no boolean.
    # Pocket and insert are meshed on one lattice with the same margin and not simplified, so that where the
    # insert bounds the pocket both surfaces are the same triangles (the insert sits in its pocket, no overlap)
    pocket_cells = centres[inserted | in_q1]
    pocket_terms = [[(design.insert_coefficients, 1.0)]] + ([[(cavity.coefficients, 1.0)]] if np.any(in_q1) else [])
    box = _box(grid, pocket_cells)
    h = grid.spacing
    failure = None
    for k in range(MAX_MESH_ATTEMPTS):
        margin = [DEPTH_MARGIN * h + 0.5 * h * k]
        try:
            inserts = _region(grid, [(design.insert_coefficients, 1.0)], cavity.centre, cavity.half_extent,
                              pocket_cells, vertices, faces, origin, frame, wall, tree, storage_scale, box=box,
                              margins=margin, simplify=False)
            pocket_meshes = _region(grid, pocket_terms, cavity.centre, cavity.half_extent, pocket_cells, vertices,
                                    faces, origin, frame, wall, tree, storage_scale, box=box, margins=margin,
                                    simplify=False)
        except PhysicsError as exc:
            failure = exc
            continue
        if not inserts:          # no insert region after all: the pocket is the cavity alone
            return [Pocket(np.vstack([part_v, pv]), np.vstack([part_f, pf[:, ::-1] + len(part_v)]), None, None, w)
                    for pv, pf, w in pocket_meshes]
        (ins_v, ins_f, ins_wall), (pocket_v, pocket_f, measured) = inserts[0], pocket_meshes[0]
        pockets.append(Pocket(np.vstack([part_v, pocket_v]), np.vstack([part_f, pocket_f[:, ::-1] + len(part_v)]),
                              ins_v, ins_f, min(measured, ins_wall)))
        return pockets
    raise failure or PhysicsError("could not mesh the pocket and the insert")
