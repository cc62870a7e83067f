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


import numpy as np

from ..values import frozen_value
from ..errors import DegenerateFacesWarning, InsideOutWarning, InvalidMeshError, MeshRepairedWarning, OverlapWarning
from ..mass.volume import VolumeMoments, body_volume_moments, bounding_box, reference_point
from ..tolerances import FLAT_RTOL, MERGE_TOLERANCE
from .checks import MeshReport, edge_topology, repeated_corner_faces, shell_labels, winding_number
from .read import RawMesh
from .weld import weld_tolerance

__all__ = ["PreparedMesh", "prepare_mesh", "classify_shells", "MAX_COORDINATE", "MIN_EXTENT"]

#: Largest |coordinate| (m) accepted: the second moments grow like L⁵ and must stay far from float64
#: overflow (1.8e308) for any density; 1e30 m is already beyond the observable universe.
MAX_COORDINATE = 1e30


#: Smallest bounding-box diagonal (m) accepted: below it L⁵ approaches float64 underflow.
MIN_EXTENT = 1e-30


#: Upper bound on triangle-point solid-angle evaluations spent on cavity / overlap classification.
_WINDING_BUDGET = 200_000_000


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


def _describe_edges(topo, source: str) -> str:
    parts = []
    if topo.boundary_edges:
        parts.append(f"{topo.boundary_edges:,} boundary edges (holes)")
    if topo.nonmanifold_edges:
        parts.append(f"{topo.nonmanifold_edges:,} non-manifold edges (shared by 3+ faces)")
    if topo.misoriented_edges:
        parts.append(f"{topo.misoriented_edges:,} edges with inconsistent winding (flipped faces)")
    where = ""
    if len(topo.sample):
        a, b = topo.sample[0]
        where = f", e.g. the edge ({a[0]:.6g}, {a[1]:.6g}, {a[2]:.6g})–({b[0]:.6g}, {b[1]:.6g}, {b[2]:.6g}) m"
    return (f"{source}: not a closed, consistently wound solid: {'; '.join(parts)}{where}; "
            "`repair=True` gives a bounded estimate")


def _repair(vertices, faces, source):
    """Close holes and fix winding with trimesh; returns new arrays and the list of actions."""
    import trimesh

    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    actions = []
    before_faces = len(mesh.faces)
    if not mesh.is_winding_consistent:
        trimesh.repair.fix_winding(mesh)
        actions.append("made the winding consistent")
    if not mesh.is_watertight:
        trimesh.repair.fill_holes(mesh)
        if len(mesh.faces) != before_faces:
            actions.append(f"filled holes with {len(mesh.faces) - before_faces} new triangles")
    if not (mesh.is_watertight and mesh.is_winding_consistent):
        raise InvalidMeshError(f"{source}: could not be repaired into a closed solid "
                               "(holes too complex or non-manifold edges remain)")
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces), actions


def _signed_volume(vertices, faces) -> float:
    o = reference_point(vertices)
    a = vertices[faces[:, 0]] - o
    return float(np.einsum("ij,ij->i", a, np.cross(vertices[faces[:, 1]] - o, vertices[faces[:, 2]] - o)).sum() / 6)


def classify_shells(vertices, faces, labels, n_shells, shells, diag):
    """Flip inside-out shells, attach cavities to their bodies, detect overlaps.

    Returns (shells, owner, flipped, cavities, overlaps, face_flip_mask_per_shell).
    """
    vols = np.array([s.volume for s in shells])
    flip = np.zeros(n_shells, dtype=bool)
    owner = np.arange(n_shells)
    if n_shells == 1:
        flip[0] = vols[0] < 0
        return flip, owner, 0, 0
    # bounding boxes per shell and one probe point per shell (centroid of its first face)
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    corner = vertices[faces[order]]
    lo = np.minimum.reduceat(corner.min(axis=1), starts, axis=0)
    hi = np.maximum.reduceat(corner.max(axis=1), starts, axis=0)
    probe = corner[starts].mean(axis=1)
    face_count = np.diff(np.r_[starts, len(faces)])
    sign = np.sign(vols)
    if vols.sum() < 0:
        # the whole mesh is inside out: flip every shell first
        sign = -sign
        flip[:] = True
    winding = np.zeros(n_shells)
    budget = _WINDING_BUDGET
    for s in range(n_shells):
        inside_box = np.all((probe[s] >= lo) & (probe[s] <= hi), axis=1)
        inside_box[s] = False
        for t in np.flatnonzero(inside_box):
            budget -= face_count[t]
            if budget < 0:
                break
            orient = -1.0 if flip[t] else 1.0
            w = orient * winding_number(probe[s], vertices, faces[order[starts[t]:starts[t] + face_count[t]]])
            winding[s] += w
            if sign[s] < 0 and w > 0.5 and sign[t] > 0:
                owner[s] = t
    cavities = 0
    overlapped = np.zeros(n_shells, dtype=bool)
    cavity = np.zeros(n_shells, dtype=bool)
    for s in range(n_shells):
        inside_material = winding[s] > 0.5
        if sign[s] < 0:
            if inside_material:
                cavities += 1           # a void inside a body: keep its negative volume
                cavity[s] = True
            else:
                flip[s] = not flip[s]   # an inside-out body on its own: flip it
                owner[s] = s
        elif inside_material:
            overlapped[s] = True
    if budget > 0:
        overlapped |= _overlap_probes(vertices, faces, order, starts, face_count, lo, hi, flip, ~cavity,
                                      diag, budget)
    return flip, owner, cavities, int(np.count_nonzero(overlapped))


def _overlap_probes(vertices, faces, order, starts, face_count, lo, hi, flip, body, diag, budget,
                    probes_per_shell: int = 16, nudge: float = 1e-6):
    """Bodies with material of another body just inside their surface (partial overlaps).

    The centroids of each body's ``probes_per_shell`` largest faces, moved ``nudge · diag`` inward, are
    tested against every other body whose bounding box holds them (winding number > 1/2 means inside).
    Catches overlaps whose vertices all lie outside the other body (two crossing bars); an overlap that
    no probe reaches stays undetected.  Spends at most ``budget`` triangle-point evaluations.
    """
    n_shells = len(starts)
    found = np.zeros(n_shells, dtype=bool)
    for s in np.flatnonzero(body):
        others = np.flatnonzero(np.all(lo <= hi[s], axis=1) & np.all(hi >= lo[s], axis=1))
        others = others[others != s]
        if not np.any(body[others]):
            continue
        f = faces[order[starts[s]:starts[s] + face_count[s]]]
        a, b, c = vertices[f[:, 0]], vertices[f[:, 1]], vertices[f[:, 2]]
        normal = np.cross(b - a, c - a)
        length = np.linalg.norm(normal, axis=1)
        pick = np.argsort(-length, kind="stable")[:probes_per_shell]
        pick = pick[length[pick] > 0]
        outward = normal[pick] / length[pick, None] * (-1.0 if flip[s] else 1.0)
        points = (a[pick] + b[pick] + c[pick]) / 3.0 - nudge * diag * outward
        material = np.zeros(len(points))   # signed count of the other shells' material at each probe
        for t in others:
            faces_t = faces[order[starts[t]:starts[t] + face_count[t]]]
            orient = -1.0 if flip[t] else 1.0   # cavities stay inward-wound and count negative
            for k in np.flatnonzero(np.all((points >= lo[t]) & (points <= hi[t]), axis=1)):
                budget -= face_count[t]
                if budget < 0:
                    return found
                material[k] += orient * winding_number(points[k], vertices, faces_t)
        found[s] = bool(np.any(material > 0.5))
    return found


def _check_magnitude(vertices, source: str) -> None:
    """Refuse coordinates whose volume integrals (∝ L⁵) would overflow or underflow float64."""
    if not len(vertices):
        return
    lo, hi = bounding_box(vertices)
    top = float(np.max(np.abs(np.r_[lo, hi])))    # = max |coordinate| (NaN propagates)
    if not top <= MAX_COORDINATE:
        raise InvalidMeshError(f"{source}: coordinates reach {top:.3g} m, beyond the ±{MAX_COORDINATE:g} m the "
                               "volume integrals can hold without overflow (check the length `units`)")
    span = hi - lo
    diag = float(np.hypot(np.hypot(span[0], span[1]), span[2]))   # no underflow in the squares
    if 0 < diag < MIN_EXTENT:
        raise InvalidMeshError(f"{source}: the mesh spans only {diag:.3g} m, below the {MIN_EXTENT:g} m the "
                               "volume integrals can hold without underflow (check the length `units`)")


def prepare_mesh(raw: RawMesh, *, repair: bool = False,
                 merge_tolerance: float = MERGE_TOLERANCE) -> PreparedMesh:
    """Check a raw mesh and classify its shells (see the module docstring for the policy).

    Parameters
    ----------
    raw : RawMesh
        Vertices in metres and faces, from :func:`~inertia_tool.mesh.read.load_mesh`.
    repair : bool
        Estimate instead of refusing a mesh that does not bound a solid (see
        :class:`~inertia_tool.mesh.options.LoadOptions`).
    merge_tolerance : float
        Tolerance-weld spacing relative to the bounding-box diagonal; 0 disables it.

    Returns
    -------
    PreparedMesh

    Raises
    ------
    InvalidMeshError
        Not a solid (and ``repair`` is off or cannot help), flat, or beyond float64's safe range.
    """
    source = raw.source
    v, f = raw.vertices, raw.faces
    if len(f) == 0:
        raise InvalidMeshError(f"{source}: the mesh has no triangles")
    _check_magnitude(v, source)
    repeated = repeated_corner_faces(f)
    n_repeated = int(np.count_nonzero(repeated))
    if n_repeated == len(f):
        raise InvalidMeshError(f"{source}: all {len(f):,} triangles are degenerate (no area); nothing to integrate")
    if n_repeated:
        f = f[~repeated]
        warnings.warn(DegenerateFacesWarning(f"{source}: {n_repeated:,} degenerate triangles (a repeated corner) "
                                             "were ignored"), stacklevel=3)
    lo, hi = bounding_box(v)
    diag = float(np.linalg.norm(hi - lo))
    if not diag > 0:
        raise InvalidMeshError(f"{source}: all vertices coincide; the mesh has no extent")
    topo = edge_topology(f, len(v), v)
    watertight = topo.oriented
    welded = None
    if not topo.closed and merge_tolerance and merge_tolerance > 0:
        tol = merge_tolerance * diag
        f2 = weld_tolerance(v, f, tol)
        keep = ~((f2[:, 0] == f2[:, 1]) | (f2[:, 1] == f2[:, 2]) | (f2[:, 2] == f2[:, 0]))
        f2 = f2[keep]
        topo2 = edge_topology(f2, len(v), v)
        if topo2.closed and len(f2):  # welding must not collapse the whole surface
            f, topo, welded = f2, topo2, tol
            watertight = topo.oriented
    repaired = False
    actions: list[str] = []
    volume_change = None
    if not topo.oriented:
        if not repair:
            raise InvalidMeshError(_describe_edges(topo, source),
                                   details={"boundary_edges": topo.boundary_edges,
                                            "nonmanifold_edges": topo.nonmanifold_edges,
                                            "misoriented_edges": topo.misoriented_edges})
        before = _signed_volume(v, f)
        v, f, actions = _repair(v, f, source)
        after = _signed_volume(v, f)
        volume_change = (abs(after) - abs(before)) / abs(after) if after else None
        repaired = bool(actions)
        if repaired:
            change = f"; volume changed by {100 * volume_change:+.3g}%" if volume_change is not None else ""
            warnings.warn(MeshRepairedWarning(f"{source}: repaired: {', '.join(actions)}{change}"), stacklevel=3)
    labels, n_shells = shell_labels(f, len(v))
    if n_shells == 0:
        raise InvalidMeshError(f"{source}: no triangles are left after removing degenerate ones")
    shells = body_volume_moments(v, f, labels, n_shells)
    flat = [k for k, s in enumerate(shells) if abs(s.volume) <= FLAT_RTOL * diag ** 3]
    if flat:
        what = "the mesh encloses" if n_shells == 1 else f"{len(flat)} of {n_shells} shells enclose"
        raise InvalidMeshError(f"{source}: {what} no volume (flat or collapsed surface)")
    flip, owner, cavities, overlaps = classify_shells(v, f, labels, n_shells, shells, diag)
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
    if overlaps:
        warnings.warn(OverlapWarning(f"{source}: {overlaps} bod{'y overlaps' if overlaps == 1 else 'ies overlap'} "
                                     "another body; the overlapping volume is counted twice"), stacklevel=3)
    bodies = int(np.count_nonzero(owner == np.arange(n_shells)))
    bbox_min, bbox_max = bounding_box(v)
    report = MeshReport(source=source, units=raw.units, file_faces=raw.file_faces, vertices=len(v), faces=len(f),
                        degenerate_faces=n_repeated, zero_area_faces=sum(s.zero_area_faces for s in shells),
                        bodies=bodies, cavities=cavities,
                        flipped_shells=int(np.count_nonzero(flip)), overlapping_shells=overlaps,
                        watertight=watertight, welded_tolerance=welded, repaired=repaired,
                        repair_actions=tuple(actions), repair_volume_change=volume_change,
                        bbox_min=bbox_min, bbox_max=bbox_max)
    return PreparedMesh(vertices=v, faces=f, labels=labels, shells=tuple(shells), owner=owner, report=report)
