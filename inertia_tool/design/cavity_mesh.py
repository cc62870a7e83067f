"""The cavity (and insert) as closed meshes, subtracted from the part with a robust boolean (manifold3d).

* :func:`_cavity_values` — the region ``depth ≥ wall + margin`` and ``s_k q_k < 0`` as a scalar field on the
  grid's cell centres (depth from the grid, quadrics analytic, creases rounded by a smooth minimum), meshed by
  marching tetrahedra (:mod:`.tetra`);
* :func:`_region` — its mesh, slivers dropped, the wall measured exactly from every vertex
  (``design.grid.surface_distance``) and the mesh remade deeper when it is too thin;
* :func:`cut_pocket` — pocket = cavity ∪ insert, ``part − pocket``, pinched vertices separated.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import PhysicsError, UsageError
from .grid import surface_distance
from .optimize import QuadricCavity

__all__ = ["cut_pocket", "DEPTH_MARGIN", "SNAP", "MIN_VOID_CELLS", "MAX_MESH_ATTEMPTS"]

#: Cells of extra depth asked of the cavity beyond the wall (the depths near the wall are exact at the cell
#: centres; the margin covers the linear interpolation of the level set between them).
DEPTH_MARGIN = 0.5

#: Edges of the cavity mesh shorter than this fraction of a cell are collapsed (``Manifold.simplify``), so
#: that a float32 STL of the result keeps every vertex distinct.
SNAP = 1e-3

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
    depth = grid.signed_distance[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1, lo[2]:hi[2] + 1]
    shape = depth.shape
    first = grid.origin + h * (np.asarray(lo, dtype=np.float64) - 1.0)
    axes = [grid.origin[d] + h * np.arange(lo[d], hi[d] + 1, dtype=np.float64) for d in range(3)]
    # frame coordinates, normalised: x̂ = (Rᵀ (x − o) − centre)/half, one axis at a time (no (n, 3) temporaries)
    r = np.asarray(frame, dtype=np.float64)
    shift = (-(r.T @ np.asarray(origin, dtype=np.float64)) - np.asarray(centre)) / half
    normalised = []
    for row in range(3):
        parts = [(r[d, row] / half) * axes[d] for d in range(3)]
        normalised.append(parts[0][:, None, None] + parts[1][None, :, None] + parts[2][None, None, :] + shift[row])
    u, v, w = normalised
    value = depth - threshold
    smooth = 0.25 * h
    for t, sign in terms:
        c = np.asarray(t, dtype=np.float64) / np.linalg.norm(t)
        q = (c[0] + c[1] * u + c[2] * v + c[3] * w + c[4] * u * u + c[5] * v * v + c[6] * w * w
             + c[7] * u * v + c[8] * u * w + c[9] * v * w)
        inner = -sign * q * half
        # smooth minimum (rounds the crease where the wall meets the quadric, so the two sheets of the
        # marching tetrahedra do not pinch at a shared point): min(d, e) − k log(1 + exp(−|d − e|/k))
        value = np.minimum(value, inner) - smooth * np.log1p(np.exp(-np.abs(value - inner) / smooth))
    padded = np.full((shape[0] + 2, shape[1] + 2, shape[2] + 2), -h)
    padded[1:-1, 1:-1, 1:-1] = value
    return padded, first


def _manifold_of(vertices, faces):
    import manifold3d

    mesh = manifold3d.Mesh64(vert_properties=np.array(vertices, dtype=np.float64, order="C"),   # writable copies
                             tri_verts=np.array(faces, dtype=np.uint64, order="C"))
    return manifold3d.Manifold(mesh)


def _arrays_of(manifold: Any) -> tuple[np.ndarray, np.ndarray]:
    mesh = manifold.to_mesh64()
    return np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)


def _separate_pinches(vertices, faces, distance: float):
    """Move apart vertices that share a position (float32), each by ``distance`` along its outward normal.

    Marching tetrahedra can leave two sheets of the cavity touching at one point, as two distinct vertices at
    the same position: a valid manifold, but a mesh file welds them into a non-manifold vertex.  Moving each
    copy along its normal (into the cavity it bounds), or against it where that would push one tip of
    material into another (checked by :func:`~inertia_tool.mesh.intersect.surface_contacts`), separates the
    sheets by ``2 distance``; when neither way leaves the surface free of crossings it is left touching.
    """
    v = np.array(vertices, dtype=np.float64)
    _, inverse, counts = np.unique(v.astype(np.float32), axis=0, return_inverse=True, return_counts=True)
    shared = counts[inverse.ravel()] > 1
    if not np.any(shared):
        return v, faces
    from ..mesh.intersect import surface_contacts

    tri = v[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    vertex_normal = np.zeros_like(v)
    for k in range(3):
        np.add.at(vertex_normal, faces[:, k], normal)
    length = np.linalg.norm(vertex_normal[shared], axis=1)
    step = distance * vertex_normal[shared] / np.where(length > 0, length, 1.0)[:, None]
    # two void lobes touching at a point separate when each copy moves into its own void (along the normal);
    # two tips of material touching separate the other way: moving them into the void pushes each tip into
    # the other's material and the surface passes through itself.  Keep the way that leaves no crossing.
    for sign in (1.0, -1.0):
        moved = v.copy()
        moved[shared] += sign * step
        if not len(surface_contacts(moved, faces).crossing):
            return moved, faces
    return v, faces          # the sheets only touch at the shared positions: a valid solid as it stands


def _region(grid, terms, centre, half, cells, vertices, faces, origin, frame, wall: float, tree=None):
    """A closed mesh (manifold) of the region of ``terms`` deeper than the wall, by marching tetrahedra on the
    grid's cell centres (``design.tetra``), with its wall measured exactly; remeshed deeper (up to
    ``MAX_MESH_ATTEMPTS``) if thinner than ``wall``.  Returns (manifold or None when empty, measured wall)."""
    import manifold3d

    from .tetra import marching_tetrahedra

    h = grid.spacing
    index = np.rint((cells - grid.origin) / h).astype(np.int64)
    lo = np.maximum(index.min(axis=0) - 2, 0)
    hi = np.minimum(index.max(axis=0) + 2, np.array(grid.shape) - 1)
    margin = DEPTH_MARGIN * h
    for _ in range(MAX_MESH_ATTEMPTS):
        values, first = _cavity_values(grid, terms, centre, half, origin, frame, wall + margin, lo, hi)
        region_v, region_f = marching_tetrahedra(values, first, h)
        del values
        if not len(region_f):
            return None, math.inf
        region = _manifold_of(region_v, region_f)
        if region.status() != manifold3d.Error.NoError:
            raise PhysicsError(f"the cavity surface is not a manifold ({region.status()})")
        # marching tetrahedra can leave vertices closer than a float32 STL can tell apart: merge them
        region = region.simplify(SNAP * h)
        # slivers the marching tetrahedra leave where the field grazes zero: voids smaller than (2h)³ change
        # the moments by nothing measurable and no print could be emptied of them
        pieces = [piece for piece in region.decompose() if piece.volume() >= MIN_VOID_CELLS * h ** 3]
        if not pieces:
            return None, math.inf
        region = manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add)
        region_v, _ = _arrays_of(region)
        measured = float(surface_distance(region_v, vertices, faces, cutoff=wall + h, tree=tree).min())
        if measured >= wall + SNAP * h:          # pinches are separated by SNAP·h below
            return region, measured - SNAP * h
        margin += 0.5 * h
    raise PhysicsError(f"could not mesh a cavity keeping a wall of {wall:g} m: the thinnest came out "
                       f"{measured:g} m after {MAX_MESH_ATTEMPTS} attempts")


def cut_pocket(vertices, faces, grid, design, centres, origin, frame, wall: float, *, tree=None):
    """Mesh the cavity (and the insert), check the wall exactly, subtract, separate pinches.

    ``design`` is a :class:`QuadricCavity` or a :class:`~.insert.QuadricInsert`.  Returns (vertices, faces,
    insert vertices or None, insert faces or None, measured wall)."""
    try:
        import manifold3d
    except ImportError as exc:                # pragma: no cover - a dependency of the package
        raise UsageError("spin_it needs manifold3d (pip install manifold3d)") from exc
    cavity = design if isinstance(design, QuadricCavity) else design.cavity
    inserted = getattr(design, "inserted", None)
    h = grid.spacing
    walls = [math.inf]
    insert = hole = None
    if inserted is not None and np.any(inserted):
        insert, measured = _region(grid, [(design.insert_coefficients, 1.0)], cavity.centre, cavity.half_extent,
                                   centres[inserted], vertices, faces, origin, frame, wall, tree)
        walls.append(measured)
    in_q1 = cavity.removed if inserted is None else cavity.removed | (inserted & (cavity.values(
        (centres - origin) @ frame) < 0))
    if np.any(in_q1):
        hole, measured = _region(grid, [(cavity.coefficients, 1.0)], cavity.centre, cavity.half_extent,
                                 centres[in_q1], vertices, faces, origin, frame, wall, tree)
        walls.append(measured)
    if hole is None and insert is None:
        return vertices, faces, None, None, math.inf
    # the pocket is the union of both regions: the part keeps none of it, the insert fills its own share
    pocket = hole if insert is None else (insert if hole is None else hole + insert)
    part = _manifold_of(vertices, faces)
    if part.status() != manifold3d.Error.NoError:
        raise PhysicsError(f"the part is not a manifold solid for the boolean ({part.status()})")
    result = part - pocket
    if result.status() != manifold3d.Error.NoError:
        raise PhysicsError(f"the boolean subtraction failed ({result.status()})")
    out_v, out_f = _separate_pinches(*_arrays_of(result), SNAP * h)
    ins_v = ins_f = None
    if insert is not None:
        ins_v, ins_f = _separate_pinches(*_arrays_of(insert), SNAP * h)
    return out_v, out_f, ins_v, ins_f, min(walls)
