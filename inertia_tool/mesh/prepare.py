"""From a raw mesh to a checked one: degenerate faces, the tolerance weld, the edge census, repair on request,
and the classification of shells (inside-out shells flipped, cavities attached to the body around them,
overlapping bodies found).

This stage decides what the triangles mean as a solid; it refuses what it cannot interpret (open,
non-manifold or inconsistently wound surfaces without ``repair``, flat shells, coordinates beyond float64's
safe range).  It hands the per-shell volume moments on (:mod:`inertia_tool.mass.volume`, used here to read the
sign of each shell), so that the faces are integrated once.
"""

from __future__ import annotations

import warnings


from typing import Any

import numpy as np

from ..values import frozen_value
from ..errors import (DegenerateFacesWarning, InsideOutWarning, InvalidMeshError, MeshRepairedWarning,
                      MeshResolvedWarning, OverlapWarning, UsageError)
from ..mass.volume import VolumeMoments, body_volume_moments, bounding_box, volume_moments
from ..tolerances import FLAT_RTOL, MERGE_TOLERANCE
from .checks import MeshReport, edge_topology, repeated_corner_faces, shell_labels
from .read import RawMesh
from .estimate import check_useful, uncertainty_from
from .resolve import Resolution, resolve_surface

__all__ = ["PreparedMesh", "prepare_mesh", "classify_shells", "MAX_COORDINATE", "MIN_EXTENT"]

#: Largest |coordinate| (m) accepted: the second moments grow like L⁵ and must stay far from float64
#: overflow (1.8e308) for any density; 1e30 m is already beyond the observable universe.
MAX_COORDINATE = 1e30


#: Smallest bounding-box diagonal (m) accepted: below it L⁵ approaches float64 underflow.
MIN_EXTENT = 1e-30


#: Ways to count overlapping bodies: their union (the physical solid) or the sum of their integrals.
OVERLAP_MODES = ("union", "sum")

#: Work bound of the surface-crossing test: candidate face pairs per face (beyond it the boolean decides).
CROSSING_PAIRS_PER_FACE = 16

#: Overlap confirmed when the union's volume falls short of the summed volume by more than this (relative).
UNION_VOLUME_RTOL = 1e-9


@frozen_value
class PreparedMesh:
    """A checked mesh ready for integration, with its shells classified.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes.
    faces : (m, 3) int
        Outward-wound after any flips.
    labels : (m,) int
        Shell of each face.
    shells : tuple of VolumeMoments
        Per-shell unit-density moments (after flips; cavities have negative volume).
    owner : (k,) int
        For each shell, the body it belongs to (a cavity belongs to the body around it).
    report : MeshReport
    """

    vertices: np.ndarray
    faces: np.ndarray
    labels: np.ndarray
    shells: tuple
    owner: np.ndarray
    report: MeshReport


def classify_shells(vertices, faces, labels, n_shells, shells, diag, *, source: str = "mesh",
                    check_crossing: bool = True, pairs_per_face: int = CROSSING_PAIRS_PER_FACE):
    """Flip inside-out shells, attach cavities to their bodies, find overlapping bodies.

    Every shell is classified, always: the winding number of every other shell at a point of each shell
    comes from exact ray crossings against a sorted index of the faces (:func:`~.nesting.shell_nesting`),
    about one pass over the faces however many shells there are.  A shell all of whose probe points lie on
    other shells' surfaces counts as an overlap candidate (the boolean union then decides).  Bodies whose surfaces
    touch or cross
    another shell's surface are found by triangle–triangle tests (:func:`~.union.crossing_shells`) on the
    faces of all but the largest shell, within a work bound of ``pairs_per_face`` candidate pairs per face;
    beyond it (CAD fans of long triangles) every shell whose box meets another's is a candidate and the
    boolean union decides (``check_crossing=False`` goes there directly).

    Returns
    -------
    flip : (s,) bool
        Shells to turn inside out.
    owner : (s,) int
        Body each shell belongs to.
    cavities : int
    overlaps : int
        Shells inside another body's material or whose surface meets another shell's (a candidate overlap,
        for the boolean union to confirm).
    """
    vols = np.array([s.volume for s in shells])
    flip = np.zeros(n_shells, dtype=bool)
    owner = np.arange(n_shells)
    if n_shells == 1:
        flip[0] = vols[0] < 0
        return flip, owner, 0, 0
    sign = np.sign(vols)
    if vols.sum() < 0:
        # the whole mesh is inside out: flip every shell first
        sign = -sign
        flip[:] = True
    from .nesting import shell_nesting    # imported on use (as crossing_shells and the union): one shell needs none
    from .union import crossing_shells
    nest = shell_nesting(vertices, faces, labels, n_shells)
    w = nest.winding * np.where(flip[nest.other], -1, 1)
    winding = np.bincount(nest.shell, weights=w, minlength=n_shells)
    # a cavity belongs to the smallest body whose material holds it
    holds = (sign[nest.shell] < 0) & (sign[nest.other] > 0) & (w > 0)
    if holds.any():
        order = np.argsort(-np.abs(vols[nest.other[holds]]), kind="stable")   # smallest last: it wins
        owner[nest.shell[holds][order]] = nest.other[holds][order]
    inside_material = winding > 0.5
    cavity = (sign < 0) & inside_material
    lonely = (sign < 0) & ~inside_material
    flip[lonely] = ~flip[lonely]                 # an inside-out body on its own: flip it
    owner[lonely] = np.flatnonzero(lonely)
    # a shell every probe of which lies on another surface touches it: an overlap candidate for the boolean
    overlapped = ((sign > 0) & inside_material) | nest.undecided
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    p0, p1, p2 = (vertices[faces[order, k]] for k in range(3))
    lo = np.minimum.reduceat(np.minimum(np.minimum(p0, p1), p2), starts, axis=0)
    hi = np.maximum.reduceat(np.maximum(np.maximum(p0, p1), p2), starts, axis=0)
    del p0, p1, p2
    boxes_meet = np.all(lo[:, None] <= hi[None], axis=2) & np.all(lo[None] <= hi[:, None], axis=2)
    np.fill_diagonal(boxes_meet, False)
    if boxes_meet.any() and not check_crossing:
        overlapped |= boxes_meet.any(axis=1)
    elif boxes_meet.any():
        largest = int(np.argmax(np.bincount(labels, minlength=n_shells)))
        query = labels != largest
        crossing = crossing_shells(vertices, faces, labels, query,
                                   max_pairs=max(pairs_per_face * len(faces), 1 << 16))
        if crossing is None:            # too many candidate pairs to test: let the boolean decide
            crossing = boxes_meet.any(axis=1)
        overlapped |= crossing
    return flip, owner, int(np.count_nonzero(cavity)), int(np.count_nonzero(overlapped))


def _check_magnitude(lo, hi, source: str) -> None:
    """Refuse coordinates (bounding box ``lo``, ``hi``) whose volume integrals (∝ L⁵) would overflow or underflow
    float64."""
    top = float(np.max(np.abs(np.r_[lo, hi])))    # = max |coordinate| (NaN propagates)
    if not top <= MAX_COORDINATE:
        raise InvalidMeshError(f"{source}: coordinates reach {top:.3g} m, beyond the ±{MAX_COORDINATE:g} m the "
                               "volume integrals can hold without overflow (check the length `units`)")
    span = hi - lo
    diag = float(np.hypot(np.hypot(span[0], span[1]), span[2]))   # no underflow in the squares
    if 0 < diag < MIN_EXTENT:
        raise InvalidMeshError(f"{source}: the mesh spans only {diag:.3g} m, below the {MIN_EXTENT:g} m the "
                               "volume integrals can hold without underflow (check the length `units`)")


def prepare_mesh(raw: RawMesh, *, repair: bool = False, merge_tolerance: float = MERGE_TOLERANCE,
                 overlap: str = "union") -> PreparedMesh:
    """Check a raw mesh and classify its shells (see the module docstring for the policy).

    Parameters
    ----------
    raw : RawMesh
        Vertices in metres and faces, from :func:`~inertia_tool.mesh.read.load_mesh`.
    repair : bool
        Give a bounded estimate instead of refusing a mesh that does not bound a solid (holes, cracks, stray
        pieces; see :mod:`~inertia_tool.mesh.resolve`).
    merge_tolerance : float
        Distance, relative to the bounding-box diagonal, within which vertices are merged when the bit-exact
        weld leaves the surface unbalanced; 0 disables it.
    overlap : {"union", "sum"}
        Overlapping bodies: integrate their union (the physical solid; default) or add their integrals
        (shared volume counted twice, said in the report).

    Returns
    -------
    PreparedMesh

    Raises
    ------
    InvalidMeshError
        Not a solid (and ``repair`` is off), flat, or beyond float64's safe range.
    """
    if overlap not in OVERLAP_MODES:
        raise UsageError(f"Expected `overlap` to be one of {', '.join(OVERLAP_MODES)}, got {overlap!r}")
    source = raw.source
    v, f = raw.vertices, raw.faces
    if len(f) == 0:
        raise InvalidMeshError(f"{source}: the mesh has no triangles")
    lo, hi = bounding_box(v)          # of the mesh as read: reused below while the vertices are these
    _check_magnitude(lo, hi, source)
    repeated = repeated_corner_faces(f)
    n_repeated = int(np.count_nonzero(repeated))
    if n_repeated == len(f):
        raise InvalidMeshError(f"{source}: all {len(f):,} triangles are degenerate (no area); nothing to integrate")
    if n_repeated:
        f = f[~repeated]
        warnings.warn(DegenerateFacesWarning(f"{source}: {n_repeated:,} degenerate triangles (a repeated corner) "
                                             "were ignored"), stacklevel=3)
    diag = float(np.linalg.norm(hi - lo))
    if not diag > 0:
        raise InvalidMeshError(f"{source}: all vertices coincide; the mesh has no extent")
    topo = edge_topology(f, len(v), v)
    watertight = topo.oriented
    found = Resolution(v, f, "exact", (), 0, None, 0)
    if not topo.oriented:                     # clean meshes skip all of this
        found = resolve_surface(v, f, diag=diag, source=source, repair=repair, merge_tolerance=merge_tolerance,
                                moments=volume_moments)
        v, f = found.vertices, found.faces
        if found.method != "exact" or found.notes:
            warning = MeshRepairedWarning if found.estimate is not None else MeshResolvedWarning
            what = f"repaired ({found.method}, an estimate)" if found.estimate is not None else found.method
            warnings.warn(warning(f"{source}: {what}: {'; '.join(found.notes)}"), stacklevel=3)
    common: dict[str, Any] = dict(source=source, units=raw.units, file_faces=raw.file_faces,
                                  degenerate_faces=n_repeated,
                  watertight=watertight, welded_tolerance=found.welded_tolerance, flipped_faces=found.flipped_faces,
                  nonmanifold_edges=found.nonmanifold_edges)
    patched = found.estimate if found.estimate is not None and found.estimate.method == "patched" else None
    if found.estimate is not None and patched is None:
        return _estimated(found, common)
    # a patched surface is closed: its shells are classified and overlaps united like any other, and the
    # bounds of the patches carry over to the result
    labels, n_shells = shell_labels(f, len(v))
    if n_shells == 0:
        raise InvalidMeshError(f"{source}: no triangles are left after removing degenerate ones")
    shells = body_volume_moments(v, f, labels, n_shells)
    flat = [k for k, s in enumerate(shells) if abs(s.volume) <= FLAT_RTOL * diag ** 3]
    dropped_note = None
    if flat and patched is not None and len(flat) < n_shells:
        # with repair, stray pieces that enclose nothing (loose triangles, sheets) carry no material in the solid
        # model: they are left out and said so, instead of refusing the part they float beside
        keep_shell = np.ones(n_shells, dtype=bool)
        keep_shell[flat] = False
        f = f[keep_shell[labels]]
        labels, n_shells = shell_labels(f, len(v))
        shells = body_volume_moments(v, f, labels, n_shells)
        dropped_note = (f"{len(flat)} stray piece{'s' if len(flat) > 1 else ''} enclosing no volume (loose "
                        "triangles or sheets) left out")
        warnings.warn(MeshRepairedWarning(f"{source}: {dropped_note}"), stacklevel=3)
        flat = []
    if flat:
        what = "the mesh encloses" if n_shells == 1 else f"{len(flat)} of {n_shells} shells enclose"
        raise InvalidMeshError(f"{source}: {what} no volume (flat or collapsed surface); for a sheet or a "
                               "thin-walled part use the shell model with a wall `thickness`")
    flip, owner, cavities, overlaps = classify_shells(v, f, labels, n_shells, shells, diag, source=source,
                                                      check_crossing=not found.nonmanifold_edges)
    if flip.any():
        face_flip = flip[labels]
        f = f.copy()
        f[face_flip] = f[face_flip][:, ::-1]
        shells = [VolumeMoments(-s.volume, s.centroid, -s.second_moment, s.area, s.zero_area_faces) if flip[k] else s
                  for k, s in enumerate(shells)]
        n_flipped = int(np.count_nonzero(flip))
        what = "the mesh is" if n_shells == 1 or n_flipped == n_shells else f"{n_flipped} of {n_shells} shells are"
        warnings.warn(InsideOutWarning(f"{source}: {what} inside out (normals point inward); flipped"),
                      stacklevel=3)
    method, notes = found.method, list(found.notes)
    if dropped_note is not None:
        notes.append(dropped_note)
    if overlaps or found.nonmanifold_edges:
        united = _unite(v, f, labels, owner, source, repair)
        summed = sum(s.volume for s in shells)
        if united is not None and abs(united.volume - summed) <= UNION_VOLUME_RTOL * abs(summed):
            overlaps = 0                      # surfaces touch, no volume is shared
        elif united is None:
            found = resolve_surface(v, f, diag=diag, source=source, repair=True, merge_tolerance=0.0,
                                    moments=volume_moments, force_estimate=True)
            return _estimated(found, {**common, "overlapping_shells": max(overlaps, 1)})
        elif overlap == "sum":
            method = "sum"
            notes.append(f"overlapping bodies: their integrals are added, so {summed - united.volume:.6g} m³ of "
                         "shared volume is counted twice (`overlap` 'sum')")
            warnings.warn(OverlapWarning(f"{source}: {notes[-1]}"), stacklevel=3)
        else:
            notes.append(f"overlapping bodies united by a boolean: {summed - united.volume:.6g} m³ shared volume "
                         "counted once")
            warnings.warn(OverlapWarning(f"{source}: {notes[-1]}"), stacklevel=3)
            method, overlaps = "union", max(overlaps, 1)
            v, f = united.vertices, united.faces
            labels, n_shells = shell_labels(f, len(v))
            shells = body_volume_moments(v, f, labels, n_shells)
            flip, owner, cavities, _ = classify_shells(v, f, labels, n_shells, shells, diag, source=source)
    bodies = int(np.count_nonzero(owner == np.arange(n_shells)))
    bbox_min, bbox_max = (lo, hi) if v is raw.vertices else bounding_box(v)
    uncertainty = None
    if patched is not None:
        total = _total(shells)
        uncertainty = uncertainty_from(total.volume, total.centroid, total.second_moment,
                                       patched.uncertainty.volume_in_doubt, patched.far)
        check_useful(total.volume, uncertainty, source=source, what="the patched surface")
        method = "patched"
    report = MeshReport(vertices=len(v), faces=len(f), zero_area_faces=sum(s.zero_area_faces for s in shells),
                        bodies=bodies, cavities=cavities, flipped_shells=int(np.count_nonzero(flip)),
                        overlapping_shells=overlaps, repaired=patched is not None,
                        repair_actions=tuple(notes) if patched is not None else (),
                        repair_volume_change=None, bbox_min=bbox_min, bbox_max=bbox_max, method=method,
                        uncertainty=uncertainty, notes=tuple(notes), **common)
    return PreparedMesh(vertices=v, faces=f, labels=labels, shells=tuple(shells), owner=owner, report=report)


def _total(shells) -> VolumeMoments:
    """The moments of all shells together (cavities negative): volume, centroid, central second moment."""
    volume = sum(s.volume for s in shells)
    centroid = sum(s.volume * s.centroid for s in shells) / volume
    second = sum(s.second_moment + s.volume * np.outer(s.centroid - centroid, s.centroid - centroid) for s in shells)
    return VolumeMoments(volume=volume, centroid=centroid, second_moment=second, area=sum(s.area for s in shells))


def _unite(vertices, faces, labels, owner, source, repair):
    """The union of the closed pieces (a :class:`~.union.UnionSurface`), or None when the boolean refuses.

    Each piece belongs to the body that owns its shell, so cavities are cut from their own body only.
    """
    from .union import UnionError, closed_groups, union_surface      # imported on use: overlaps are rare
    groups, n_groups = closed_groups(faces, len(vertices))
    pieces = body_volume_moments(vertices, faces, groups, n_groups)
    volume = np.array([p.volume for p in pieces])
    lo, hi = bounding_box(vertices)
    solid = np.abs(volume) > FLAT_RTOL * float(np.linalg.norm(hi - lo)) ** 3    # sheets (a face and its reverse)
    shell_of_group = np.zeros(n_groups, dtype=np.int64)
    shell_of_group[groups] = labels
    keep = solid[groups]
    _, groups = np.unique(groups[keep], return_inverse=True)
    try:
        return union_surface(vertices, faces[keep], groups.reshape(-1), int(np.count_nonzero(solid)),
                             volume[solid] > 0, body=np.asarray(owner)[shell_of_group[solid]])
    except UnionError as exc:
        if repair:
            return None
        raise InvalidMeshError(f"{source}: overlapping bodies whose union cannot be formed ({exc}); "
                               "`overlap` 'sum' adds them (shared volume counted twice), `repair=True` gives a "
                               "bounded estimate") from None


def _estimated(found: Resolution, common: dict[str, Any]) -> PreparedMesh:
    """A PreparedMesh holding one estimated solid (``repair=True``)."""
    est = found.estimate
    assert est is not None, "only an estimated Resolution reaches here"
    moments = VolumeMoments(volume=est.volume, centroid=est.centroid, second_moment=est.second_moment,
                            area=est.area)
    lo, hi = bounding_box(found.vertices)
    common = {"overlapping_shells": 0, **common}
    report = MeshReport(vertices=len(found.vertices), faces=len(found.faces), zero_area_faces=0, bodies=1,
                        cavities=0, flipped_shells=0, repaired=True, repair_actions=found.notes,
                        repair_volume_change=None, bbox_min=lo, bbox_max=hi, method=est.method,
                        uncertainty=est.uncertainty, notes=found.notes, **common)
    return PreparedMesh(vertices=found.vertices, faces=found.faces, labels=np.zeros(len(found.faces), dtype=np.intp),
                        shells=(moments,), owner=np.zeros(1, dtype=np.intp), report=report)
