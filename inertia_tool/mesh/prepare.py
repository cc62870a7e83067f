"""From a raw mesh to a checked one: degenerate faces, the tolerance weld, the edge census, repair on request,
and the classification of shells (inside-out shells flipped, cavities attached to the body around them,
overlapping bodies found).

This stage decides what the triangles mean as a solid; it refuses what it cannot interpret (open,
non-manifold or inconsistently wound surfaces without ``repair``, flat shells, coordinates beyond float64's
safe range).  It hands the per-shell volume moments on (:mod:`inertia_tool.integrals`, used here to read the
sign of each shell), so that the faces are integrated once.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..values import frozen_value
from ..errors import (ArrangementError, DegenerateFacesWarning, InsideOutWarning, InvalidMeshError, MeshRepairedWarning,
                      MeshResolvedWarning, OverlapWarning, UsageError)
from ..integrals import (RoundoffBound, VolumeMoments, accurate_shells, body_volume_moments, bounding_box,
                         total_roundoff, volume_moments)
from ..tolerances import FLAT_RTOL, MERGE_TOLERANCE, ROUNDOFF_RTOL
from .checks import MeshReport, census_and_shells, edge_topology, repeated_corner_faces, shell_labels
from .read import RawMesh
from .policy import (TOUCH_VOLUME_RTOL, Certificate, ShellContacts, coincident_message, coincident_surfaces,
                     inward_crossing_outward, near_copies, near_copies_message, negligible_flat, orient_by_depth,
                     self_crossing_message, shell_contacts, touching_relations, welded_bodies,
                     within_up_to_rounding)
from .resolve import Resolution, resolve_surface
from .intersect import SurfaceContacts, surface_contacts
from ..rounding import round_up

if TYPE_CHECKING:       # imported on use at run time (below)
    from .uncertainty import Estimate
    from .nesting import Nesting
    from .union import UnionSurface

__all__ = ["PreparedMesh", "prepare_mesh", "classify_shells", "MAX_COORDINATE", "MIN_EXTENT"]

#: Largest |coordinate| (m) accepted: the second moments grow like L⁵ and must stay far from float64
#: overflow (1.8e308) for any density; 1e30 m is already beyond the observable universe.
MAX_COORDINATE = 1e30


#: Smallest bounding-box diagonal (m) accepted: below it L⁵ approaches float64 underflow.
MIN_EXTENT = 1e-30


#: Ways to count overlapping bodies: their union (the physical solid) or the sum of their integrals.
OVERLAP_MODES = ("union", "sum")


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
    shells: tuple[VolumeMoments, ...]
    owner: np.ndarray
    report: MeshReport


def classify_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n_shells: int,
                    shells: Sequence[VolumeMoments], diag: float, *, source: str = "mesh",
                    check_crossing: bool = True) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Orient shells by nesting depth (R4), attach cavities to their bodies, count overlap candidates (R5, R6).

    The same rules :func:`prepare_mesh` applies (:mod:`~.policy`), for callers that hold several prepared
    meshes side by side (an assembly's parts).

    Returns
    -------
    flip : (s,) bool
        Shells to turn inside out.
    owner : (s,) int
        Body each shell belongs to.
    cavities : int
    overlaps : int
        Shells whose surface crosses another's, that R4 had to turn (inside another shell against their own
        winding), or whose probes all lie on another surface; or (when the intersection check cannot finish,
        or ``check_crossing`` is False) whose box meets another's: candidates for the boolean to confirm.
        Shells that only touch are not counted.
    """
    vols = np.array([s.volume for s in shells])
    if n_shells == 1:
        return vols < 0, np.zeros(1, dtype=np.intp), 0, 0
    contacts = surface_contacts(vertices, faces) if check_crossing else None
    touch = shell_contacts(contacts, labels, n_shells) if contacts is not None else None
    nest = _nesting(vertices, faces, labels, n_shells)
    touch_within = np.zeros((0, 2), dtype=np.int64)
    if touch is not None and contacts is not None:
        touch, nest, touch_within = _settle_touching(vertices, faces, labels, contacts, touch, nest)
    crossing_with = touch.crossing_with if touch is not None else np.zeros((0, 2), dtype=np.int64)
    within = None
    if touch is not None and touch.complete:
        within, crossing_with = _within(vertices, faces, labels, vols, crossing_with)
    flip, owner, depth = orient_by_depth(vols, nest, crossing_with,
                                         crossing_known=touch is not None and touch.complete,
                                         within=_both(within, touch_within))
    undecided = nest.undecided if nest is not None else np.zeros(n_shells, dtype=bool)
    if touch is not None and touch.complete:
        # touching shells that their points found apart or nested share no volume (R4: those crossing along shared
        # edges are in ``touch.crossing`` now, those the points could not decide in ``crossing_with``); a shell
        # that R4 had to turn lies in another's material or void against its own winding: counted as a candidate
        candidates = touch.crossing | flip | undecided
        candidates[np.asarray(touch.crossing_with, dtype=np.int64).reshape(-1)] = True
    else:
        candidates = _boxes_meet(vertices, faces, labels, n_shells) | undecided
    return flip, owner, int(np.count_nonzero(depth % 2 == 1)), int(np.count_nonzero(candidates))


def _check_magnitude(lo: np.ndarray, hi: np.ndarray, source: str) -> None:
    """Refuse coordinates (bounding box ``lo``, ``hi``) whose volume integrals (∝ L⁵) would overflow or underflow
    float64."""
    top = float(np.max(np.abs(np.concatenate((lo, hi)))))    # = max |coordinate| (NaN propagates)
    if not top <= MAX_COORDINATE:
        raise InvalidMeshError(f"{source}: coordinates reach {top:.3g} m, beyond the ±{MAX_COORDINATE:g} m the "
                               "volume integrals can hold without overflow (check the length `units`)")
    span = hi - lo
    diag = float(np.hypot(np.hypot(span[0], span[1]), span[2]))   # no underflow in the squares
    if 0 < diag < MIN_EXTENT:
        raise InvalidMeshError(f"{source}: the mesh spans only {diag:.3g} m, below the {MIN_EXTENT:g} m the "
                               "volume integrals can hold without underflow (check the length `units`)")


def prepare_mesh(raw: RawMesh, *, repair: bool = False, merge_tolerance: float = MERGE_TOLERANCE,
                 overlap: str = "union", self_crossing: str = "refuse") -> PreparedMesh:
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
    self_crossing : {"refuse", "unverified"}
        A shell that passes through itself (rule R3): refused (default; with ``repair`` estimated), or, for
        meshes made by a boolean whose output crosses itself by rounding (spin-it's hollowed parts),
        integrated as it stands and certified ``unverified`` with a note counting the crossing face pairs.

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
    if self_crossing not in ("refuse", "unverified"):
        raise UsageError(f"Expected `self_crossing` to be 'refuse' or 'unverified', got {self_crossing!r}")
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
    topo, census_labels, census_shells = census_and_shells(f, len(v), v)   # R1's shells from the same adjacency
    coincident_notes: list[str] = []
    if topo.nonmanifold_edges:                # R0: a shell listed twice with the same vertex indices
        f, note = _leave_out_coincident(v, f, None, source)
        if note is not None:
            coincident_notes.append(note)
            topo, census_labels, census_shells = census_and_shells(f, len(v), v)
    watertight = topo.oriented
    found = Resolution(v, f, "exact", (), 0, None, 0)
    n_read = len(v)                           # vertices beyond these are the apexes of repair patches
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
    # bounds of the patches carry over to the result.  Every rule applied below is stated in mesh/policy.py.
    split_welded = bool(found.nonmanifold_edges) and patched is None
    known = (census_labels, census_shells) if topo.oriented else None          # f is the census's: unchanged
    labels, n_shells = _bodies(v, f, split_welded, known)                        # R1, R1b
    if n_shells == 0:
        raise InvalidMeshError(f"{source}: no triangles are left after removing degenerate ones")
    # the reference point body_volume_moments and accurate_shells would take (the bounding-box centre), from the
    # box computed above while the vertices are the ones read
    centre = 0.5 * (lo + hi) if v is raw.vertices else None
    shells = body_volume_moments(v, f, labels, n_shells, origin=centre)
    twins = _twin_candidates(shells, labels)
    if twins is not None:                     # R0: a shell listed twice with its own vertices
        f, note = _leave_out_coincident(v, f, twins, source, labels)
        if note is not None:
            coincident_notes.append(note)
            labels, n_shells = _bodies(v, f, split_welded)
            shells = body_volume_moments(v, f, labels, n_shells, origin=centre)
        near = near_copies(v, f, labels, shells)                                # R0 up to rounding
        if near.copies:
            f = f[~near.drop]
            coincident_notes.append(near_copies_message(near))
            warnings.warn(MeshResolvedWarning(f"{source}: {coincident_notes[-1]}"), stacklevel=3)
            labels, n_shells = _bodies(v, f, split_welded)
            shells = body_volume_moments(v, f, labels, n_shells, origin=centre)
    shells, bound = _accurate(v, f, labels, shells, centre)  # R7: signs and moments within the round-off bound
    f, labels, n_shells, shells, dropped_note, bound = _drop_flat(v, f, labels, shells, diag, source, bound)  # R2
    welded = None
    welded_arranged, welded_failed = None, ""
    if split_welded:                                                             # R1b (again: R2 relabels)
        given = labels                           # the shells ``welded.ambiguous_shells`` is indexed by
        welded = welded_bodies(f, len(v), labels, n_shells, v)
        if welded.split:
            labels, n_shells = welded.labels, welded.n_shells
            shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
        if welded.ambiguous and overlap == "union" and welded.ambiguous_shells is not None:   # R1b: {w ≥ 1}
            try:
                v, f, labels, n_shells, shells, bound, welded_arranged = _arrange_welded(
                    v, f, given, welded.ambiguous_shells, diag, source)
                # R1b on the new surface: the other shells' welded bodies are split again (R1 joined them)
                welded = welded_bodies(f, len(v), labels, n_shells, v)
                if welded.ambiguous:
                    raise ArrangementError("its result still has welded bodies whose faces cannot be paired")
                if welded.split:
                    labels, n_shells = welded.labels, welded.n_shells
                    shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
            except ArrangementError as exc:
                welded_failed = f"; its solid {{winding number ≥ 1}} could not be built: {exc}"
                welded_arranged = None
        if welded is not None and welded.ambiguous:   # R1b: coplanar faces of two bodies facing the same way
            n_amb = welded.ambiguous
            reason = (f"{n_amb} shell{'s' if n_amb > 1 else ''} with non-manifold edges where coplanar faces of two "
                      "bodies facing the same way meet could not be split into closed bodies (which faces close "
                      "which body is undefined there); the bodies overlap, and the summed integral would count "
                      "their common volume twice" + welded_failed)
            if not repair:
                raise InvalidMeshError(f"{source}: {reason}; `repair=True` gives a bounded estimate of the solid "
                                       "{winding number ≥ 1}")
            forced = resolve_surface(v, f, diag=diag, source=source, repair=True, merge_tolerance=0.0,
                                     moments=volume_moments, force_estimate=True, reason=reason)
            warnings.warn(MeshRepairedWarning(f"{source}: repaired ({forced.method}, an estimate): "
                                              f"{'; '.join(forced.notes)}"), stacklevel=3)
            return _estimated(forced, common)
    contacts = surface_contacts(v, f)
    if welded is not None and len(welded.contact):      # R1b: bodies welded along an edge meet there (R4 decides)
        contacts = dataclasses.replace(contacts, contact=np.concatenate(
            [np.asarray(contacts.contact, dtype=np.int64).reshape(-1, 2), welded.contact]))
    folds = None
    if patched is None and (len(contacts.crossing) or len(contacts.coplanar_opposite)):                 # R3a
        v, f, labels, n_shells, shells, contacts, bound, folds = _settle_folds(v, f, labels, n_shells, shells, contacts,
                                                                               bound, split_welded, diag, source)
    if patched is not None:
        contacts, patch_notes = _outside_patches(contacts, f, n_read)
        found = Resolution(found.vertices, found.faces, found.method, found.notes + patch_notes,
                           found.flipped_faces, found.welded_tolerance, found.nonmanifold_edges, found.estimate)
    touch = shell_contacts(contacts, labels, n_shells)
    crossing_note, arranged = None, welded_arranged
    arrange_failed, arranged_verified = "", welded_arranged is not None
    if touch.self_crossing.any() and self_crossing == "refuse" and overlap == "union" and patched is None:   # R3
        try:
            v, f, labels, n_shells, shells, contacts, touch, arranged, arranged_verified, bound = \
                _arrange_self_crossing(v, f, labels, contacts, touch, diag, source)
        except ArrangementError as exc:
            arrange_failed = f"; its solid {{winding number ≥ 1}} could not be built: {exc}"
    if touch.self_crossing.any() and self_crossing == "unverified" and not repair:
        crossing_note = (f"the surface passes through itself at {touch.self_crossing_pairs:,} face pairs: "
                         "integrated as it stands (a crossed region counts twice), not verified")
        warnings.warn(MeshResolvedWarning(f"{source}: {crossing_note}"), stacklevel=3)
    elif touch.self_crossing.any():                                              # R3
        message = self_crossing_message(source, touch, v, f, contacts.crossing, labels) + arrange_failed
        if not repair:
            raise InvalidMeshError(message, details={"self_crossing_face_pairs": touch.self_crossing_pairs})
        forced = resolve_surface(v, f, diag=diag, source=source, repair=True, merge_tolerance=0.0,
                                 moments=volume_moments, force_estimate=True,
                                 reason=f"the surface passes through itself at {touch.self_crossing_pairs:,} "
                                        f"face pairs{arrange_failed}")
        if patched is not None:
            forced = _with_patch_doubt(forced, patched, source)
        warnings.warn(MeshRepairedWarning(f"{source}: repaired ({forced.method}, an estimate): "
                                          f"{'; '.join(forced.notes)}"), stacklevel=3)
        return _estimated(forced, common)
    nest = _nesting(v, f, labels, n_shells)
    file_volumes = np.array([s.volume for s in shells])
    touch, nest, touch_within = _settle_touching(v, f, labels, contacts, touch, nest)                   # R4
    within, crossing_with = None, touch.crossing_with
    if touch.complete:
        within, crossing_with = _within(v, f, labels, file_volumes, crossing_with)
    flip, owner, depth = orient_by_depth(file_volumes, nest, crossing_with, crossing_known=touch.complete,
                                         within=_both(within, touch_within))                            # R4
    f, shells = _apply_flips(f, labels, shells, flip, n_shells, source)
    cavities = int(np.count_nonzero(depth % 2 == 1))
    method, notes = found.method, list(found.notes) + coincident_notes
    ambiguous = inward_crossing_outward(file_volumes, flip, crossing_with)
    if ambiguous:
        plural = ambiguous > 1
        notes.append(f"{ambiguous} inward-wound shell{'s' if plural else ''} cross{'' if plural else 'es'} "
                     "an outward one: read as a cavity cut from it (the solid where the winding number is at least "
                     "one); if it is a body written inside out, fix its winding. Not verified")
        warnings.warn(InsideOutWarning(f"{source}: {notes[-1]}"), stacklevel=3)
    if within is not None and len(within):
        n_within = len(np.unique(within[:, 0]))
        notes.append(f"{n_within} shell{'s' if n_within > 1 else ''} meet{'' if n_within > 1 else 's'} the "
                     "shell around it only on its boundary (a cavity flush with its body's face, a part resting on "
                     "a cavity's floor; the faces there coincide or cross by rounding): read by nesting depth and "
                     "formed by the boolean")
    if dropped_note is not None:
        notes.append(dropped_note)
    if arranged is not None:
        notes.append(arranged)
    if folds is not None:
        notes.append(folds.describe())
    if crossing_note is not None:
        notes.append(crossing_note)
    checks = ["edge-balanced", "consistently-oriented"]
    undecided = nest.undecided if nest is not None else np.zeros(n_shells, dtype=bool)
    if touch.complete:
        candidates = touch.crossing | touch.touching | undecided
    else:       # the check gave up: every shell whose box meets another's goes to the boolean
        candidates = _boxes_meet(v, f, labels, n_shells) | undecided
    really = np.zeros(n_shells, dtype=bool)
    really[crossing_with.reshape(-1)] = True
    overlaps = int(np.count_nonzero(really))
    kind = "exact" if touch.complete and crossing_note is None else "unverified"
    if touch.complete and not touch.crossing.any() and crossing_note is None:
        checks.append("no-crossing-faces")
    # R3a may have taken out every non-manifold edge (a wall's rims): then nothing is left for the boolean to confirm
    nonmanifold = found.nonmanifold_edges if folds is None and welded_arranged is None \
        else edge_topology(f, len(v), v).nonmanifold_edges
    if candidates.any() or nonmanifold:                                         # R5, R6
        united = _unite(v, f, labels, owner, source, repair)
        summed = sum(s.volume for s in shells)
        if united is not None and not touch.crossing.any() and \
                abs(united.volume - summed) <= TOUCH_VOLUME_RTOL * abs(summed):
            overlaps = 0                      # surfaces touch, no volume is shared: the sum is the solid
            checks.append("touching-confirmed")
            if int(np.count_nonzero(candidates)):
                notes.append(f"{int(np.count_nonzero(candidates))} shells touch another (the boolean union's "
                             "volume equals their sum: no volume is shared)")
        elif united is not None and overlap == "union" and touch.complete and \
                abs(united.volume - summed) <= TOUCH_VOLUME_RTOL * abs(summed):
            # R6 up to rounding: faces cross, yet the boolean finds no volume shared beyond TOUCH_VOLUME_RTOL (copies
            # touching face to face after a rotation, a cavity flush with its body's face): the surface as written
            # is the solid to that tolerance, not exactly (the crossing slivers are thinner than the rounding)
            overlaps = 0
            kind = "united"
            checks = ["edge-balanced", "consistently-oriented", "boolean-union", "touching-up-to-rounding"]
            crossed = np.asarray(contacts.crossing, dtype=np.int64).reshape(-1, 2)
            n_pairs = int(np.count_nonzero(labels[crossed[:, 0]] != labels[crossed[:, 1]]))
            notes.append(f"touching up to rounding: {n_pairs:,} face pairs of shells that touch cross by float64 "
                         f"rounding (faces coplanar only to rounding, e.g. after a rotation); the boolean union's "
                         f"volume equals the summed volume within {TOUCH_VOLUME_RTOL:g} (difference "
                         f"{abs(united.volume - summed):.3g} m³), so the summed integral is given, certified united "
                         "(the solid is ambiguous at the rounding level: not exact)")
            warnings.warn(MeshResolvedWarning(f"{source}: {notes[-1]}"), stacklevel=3)
        elif united is None:
            found = resolve_surface(v, f, diag=diag, source=source, repair=True, merge_tolerance=0.0,
                                    moments=volume_moments, force_estimate=True)
            return _estimated(found, {**common, "overlapping_shells": max(overlaps, 1)})
        else:
            overlaps = max(overlaps, 1) if really.any() or not touch.crossing.any() else 0
            shared = shared_text(summed, united.volume)
            if overlap == "sum" and overlaps:
                method, kind = "sum", "summed"
                notes.append(f"overlapping bodies: their integrals are added, so {shared} is counted twice "
                             "(`overlap` 'sum')")
                warnings.warn(OverlapWarning(f"{source}: {notes[-1]}"), stacklevel=3)
            else:
                excess = united.volume - summed
                if excess > TOUCH_VOLUME_RTOL * abs(summed):
                    # the union of the bodies, each with its own cavities cut, cannot exceed the summed integral
                    # unless a shell read as a cavity reaches out of its body: the boolean cuts it only where it
                    # lies in the body.  Unless the file's winding said so (``ambiguous``: an inward shell crossing
                    # an outward one), R4 misread a nesting: not a proven solid.
                    notes.append(f"the boolean union is {excess:.3g} m³ larger than the summed integral: a shell "
                                 "read as a cavity reaches out of the body around it and is cut only where it lies "
                                 "in the body" + ("" if ambiguous else "; the nesting read by R4 disagrees with "
                                                  "the boolean: not verified"))
                    warnings.warn(OverlapWarning(f"{source}: {notes[-1]}"), stacklevel=3)
                elif overlaps:        # else only shells within others (R4): their cavities are cut, nothing shared
                    notes.append(f"overlapping bodies united by a boolean: {shared} counted once")
                    warnings.warn(OverlapWarning(f"{source}: {notes[-1]}"), stacklevel=3)
                method = "union"
                # R6/R7: the boolean found shared volume; "united" is proven only when crossing faces were found
                # too (else the two checks disagree: manifold3d's tolerance or a crossing the check cannot see)
                kind = "united" if touch.complete and touch.crossing.any() and \
                    not excess > TOUCH_VOLUME_RTOL * abs(summed) else "unverified"
                if touch.complete and not touch.crossing.any():
                    notes.append(f"no faces were found crossing, yet the union's volume differs from the sum by "
                                 f"{abs(summed - united.volume):.3g} m³ (manifold3d's tolerance, or bodies passing "
                                 "through each other at shared edges): the result is the union, not verified")
                checks = ["edge-balanced", "consistently-oriented", "boolean-union"]
                v, f = united.vertices, united.faces
                after = surface_contacts(v, f)           # manifold3d's output can pass through itself by rounding
                if len(after.crossing) or not after.complete:
                    kind = "unverified"
                    notes.append(f"the union formed by the boolean passes through itself at {len(after.crossing):,} "
                                 "face pairs (rounding in manifold3d): not verified")
                labels, n_shells = shell_labels(f, len(v))
                shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
                f, labels, n_shells, shells, left, bound = _drop_flat(v, f, labels, shells, diag, source, bound,
                                                                      warn=False)
                nest = _nesting(v, f, labels, n_shells)
                flip2, owner, depth = orient_by_depth(np.array([s.volume for s in shells]), nest,
                                                      np.zeros((0, 2), dtype=np.int64))
                f, shells = _apply_flips(f, labels, shells, flip2, n_shells, source, warn=False)
                cavities = int(np.count_nonzero(depth % 2 == 1))
    roundoff = total_roundoff(shells, bound)
    if patched is None:                                                          # R7: exact up to round-off
        if roundoff > ROUNDOFF_RTOL and kind in ("exact", "united"):
            kind = "unverified"
            notes.append("the float64 round-off of the integrals is bounded only by "
                         f"{round_up(roundoff, 2):.2g} of the result "
                         f"(above {ROUNDOFF_RTOL:g}: a sliver thinner than its coordinates' rounding, too large for "
                         "exact arithmetic): not verified")
    bodies = int(np.count_nonzero(owner == np.arange(n_shells)))
    bbox_min, bbox_max = (lo, hi) if v is raw.vertices else bounding_box(v)
    uncertainty = None
    if patched is not None:
        from .uncertainty import check_useful, uncertainty_from     # imported on use: repair only
        total = _total(shells)
        uncertainty = uncertainty_from(total.volume, total.centroid, total.second_moment,
                                       patched.uncertainty.volume_in_doubt, patched.far)
        check_useful(total.volume, uncertainty, source=source, what="the patched surface")
        # a patched surface whose union could not be verified (R6) keeps "unverified": the patches' bound does
        # not cover what the boolean changed beyond them
        method, kind = "patched", ("unverified" if kind == "unverified" else "estimate")
    if arranged is not None:                  # R3: the arrangement's surface, checked like any other
        method = "union" if method == "exact" else method
        kind = {"exact": "united"}.get(kind, kind)
        checks.insert(2, "winding-arrangement")
        if not arranged_verified:             # crossings left by rounding: not proven
            kind = "unverified" if kind == "united" else kind
            checks = [c for c in checks if c != "no-crossing-faces"]
    if ambiguous and kind in ("exact", "united"):
        kind = "unverified"                   # R4: a reading of the file's winding, not a proven solid
    if folds is not None and "no-crossing-faces" in checks:
        checks.insert(checks.index("no-crossing-faces"), "zero-volume-folds")      # R3a: what makes it exact
    if found.method == "sheets-removed" and "no-crossing-faces" in checks:
        checks.insert(checks.index("no-crossing-faces"), "open-sheets")            # R3b: what makes it exact
    certificate = Certificate(kind, tuple(checks) if kind != "estimate" else ())
    report = MeshReport(vertices=len(v), faces=len(f), zero_area_faces=sum(s.zero_area_faces for s in shells),
                        bodies=bodies, cavities=cavities, flipped_shells=int(np.count_nonzero(flip)),
                        overlapping_shells=overlaps, repaired=patched is not None,
                        repair_actions=tuple(notes) if patched is not None else (),
                        repair_volume_change=None, bbox_min=bbox_min, bbox_max=bbox_max, method=method,
                        uncertainty=uncertainty, notes=tuple(notes), certificate=certificate, **common)
    return PreparedMesh(vertices=v, faces=f, labels=labels, shells=tuple(shells), owner=owner, report=report)


def _settle_folds(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int, shells: list[VolumeMoments],
                  contacts: SurfaceContacts, bound: RoundoffBound, split_welded: bool, diag: float,
                  source: str) -> tuple[Any, ...]:
    """R3a: sliver fans and internal walls taken out (:func:`~.folds.settle_folds`) and the stages after R1 run
    again on what is left; everything unchanged when there are none or they cannot be shown to enclose nothing.

    Returns ``(v, f, labels, n_shells, shells, contacts, bound, folds)`` (``folds`` None when unchanged)."""
    from .folds import settle_folds        # imported on use: only surfaces with flagged face pairs
    folds = settle_folds(v, f, contacts)          # R1 shells: a wall's sheets may lie in two R1b bodies
    if folds is None:
        return v, f, labels, n_shells, shells, contacts, bound, None
    f = folds.faces
    labels, n_shells = shell_labels(f, len(v))                                  # R1
    welded = welded_bodies(f, len(v), labels, n_shells, v) if split_welded and n_shells else None
    if welded is not None and welded.split:                                     # R1b
        labels, n_shells = welded.labels, welded.n_shells
    shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
    m = len(f)
    f, labels, n_shells, shells, _, bound = _drop_flat(v, f, labels, shells, diag, source, bound, warn=False)
    contacts = folds.contacts if len(f) == m else surface_contacts(v, f)
    if welded is not None and len(f) != m:                # R2 relabelled: the welded contacts anew
        welded = welded_bodies(f, len(v), labels, n_shells, v)
    if welded is not None:                 # R1b: bodies welded along an edge still meet there (R4 decides)
        if len(welded.contact):
            contacts = dataclasses.replace(contacts, contact=np.concatenate(
                [np.asarray(contacts.contact, dtype=np.int64).reshape(-1, 2), welded.contact]))
    warnings.warn(MeshResolvedWarning(f"{source}: {folds.describe()}"), stacklevel=4)
    return v, f, labels, n_shells, shells, contacts, bound, folds


def _arrange_self_crossing(v: np.ndarray, f: np.ndarray, labels: np.ndarray, contacts: SurfaceContacts,
                           touch: ShellContacts, diag: float, source: str) -> tuple[Any, ...]:
    """R3: every shell passing through itself replaced by the boundary of its {winding number ≥ 1}
    (:mod:`~.arrange`), then the stages after R1 run again on the new surface.

    Returns ``(v, f, labels, n_shells, shells, contacts, touch, note, verified, bound)`` (``bound`` the shells'
    round-off bounds, R7); raises ArrangementError.
    Crossings left by rounding the new points (``verified`` False) are taken out of ``touch`` (the result is
    then certified ``unverified``)."""
    from .arrange import arrange_shells      # imported on use: self-crossing shells are rare
    done = arrange_shells(v, f, labels, contacts.crossing)
    v, f = done.vertices, done.faces
    labels, n_shells = shell_labels(f, len(v))
    shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
    f, labels, n_shells, shells, _, bound = _drop_flat(v, f, labels, shells, diag, source, bound, warn=False)
    contacts = surface_contacts(v, f)
    touch = shell_contacts(contacts, labels, n_shells)
    if touch.self_crossing.any():
        if not done.crossings_left:
            raise ArrangementError("the arranged surface still passes through itself")
        touch = dataclasses.replace(touch, self_crossing=np.zeros_like(touch.self_crossing), self_crossing_pairs=0)
    pairs = sum(a.crossing_pairs for a in done.arrangements)
    note = (f"the surface passes through itself at {pairs:,} face pairs: cut along the intersection curves and "
            "the faces bounding the region of winding number ≥ 1 kept (a region enclosed twice counts once)")
    if done.inside_out:
        note += f"; {done.inside_out} self-crossing shell(s) wound inward were turned first"
    if done.crossings_left:
        note += (f"; {done.crossings_left:,} face pairs of the result still cross after rounding the intersection "
                 "points to float64 (a crossing in special position): not verified")
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=4)
    return v, f, labels, n_shells, shells, contacts, touch, note, not done.crossings_left, bound


def _arrange_welded(v: np.ndarray, f: np.ndarray, labels: np.ndarray, chosen: np.ndarray, diag: float,
                    source: str) -> tuple[Any, ...]:
    """R1b: the shells whose welded bodies could not be split replaced by the boundary of their {winding number
    ≥ 1} (:mod:`~.coplanar`), then R1 and R2 again on the new surface.

    Returns ``(v, f, labels, n_shells, shells, bound, note)``; raises ArrangementError (the result must not
    cross itself, as R7 needs)."""
    from .coplanar import arrange_coplanar_shells      # imported on use: welded coplanar bodies are rare
    v, f, done = arrange_coplanar_shells(v, f, chosen[labels])
    if done.crossings_left:
        raise ArrangementError(f"{done.crossings_left:,} face pairs of the result cross after rounding the overlay's "
                               "points to float64")
    labels, n_shells = shell_labels(f, len(v))
    shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
    f, labels, n_shells, shells, _, bound = _drop_flat(v, f, labels, shells, diag, source, bound, warn=False)
    note = (f"bodies welded along edges where faces overlap in a common plane ({done.coplanar_pairs:,} face pairs "
            f"in {done.planes:,} plane{'s' if done.planes != 1 else ''}): the faces bounding the region of winding "
            "number ≥ 1 kept, split along each other's edges (the common volume counts once)")
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=4)
    return v, f, labels, n_shells, shells, bound, note


def shared_text(summed: float, united: float) -> str:
    """The shared volume of overlapping bodies in words, m³ (never negative).  A union larger than the summed
    integral beyond rounding (``TOUCH_VOLUME_RTOL``) is a cavity reaching out of its body: the boolean cuts it
    only where it lies in the body, the summed integral all of it."""
    shared = summed - united
    if shared >= 0:
        return f"{shared:.6g} m³ of shared volume"
    if -shared <= TOUCH_VOLUME_RTOL * abs(summed):
        return f"no shared volume (the union is {-shared:.3g} m³ larger than the sum, within rounding)"
    return (f"no shared volume; the union is {-shared:.3g} m³ larger than the summed integral (a cavity reaching "
            "out of its body is cut only where it lies in the body)")


def _outside_patches(contacts: SurfaceContacts, faces: np.ndarray,
                     n_read: int) -> tuple[SurfaceContacts, tuple[str, ...]]:
    """Contacts with the crossings that involve a repair patch taken out (those lie within the patches' doubt,
    which the estimate's bound carries), and a note saying how many there were."""
    crossing = np.asarray(contacts.crossing, dtype=np.int64).reshape(-1, 2)
    patch = np.any(faces[crossing[:, 0]] >= n_read, axis=1) | np.any(faces[crossing[:, 1]] >= n_read, axis=1)
    if not patch.any():
        return contacts, ()
    kept = dataclasses.replace(contacts, crossing=crossing[~patch])
    return kept, (f"{int(np.count_nonzero(patch)):,} face pairs where a patch crosses the surface (within the "
                  "patches' volume in doubt)",)


def _nesting(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> Nesting | None:
    """The shells' winding numbers at each other's probe points (None for one shell)."""
    if n_shells < 2:
        return None
    from .nesting import shell_nesting      # imported on use: one shell needs none
    return shell_nesting(v, f, labels, n_shells)


#: Touching shell pairs whose vertices are tested against each other (R4), at most; beyond, the pairs go to the
#: boolean like crossing ones.
MAX_TOUCHING_PAIRS = 512


def _settle_touching(v: np.ndarray, f: np.ndarray, labels: np.ndarray, contacts: SurfaceContacts,
                     touch: ShellContacts, nest: Nesting | None) -> tuple[ShellContacts, Nesting | None, np.ndarray]:
    """R4 for shells that touch without a crossing face pair: their vertices decide (:func:`~.nesting.touching_sides`,
    :func:`~.policy.touching_relations`), not one probe point.

    Surfaces that cross exactly along edges and vertices of both meshes are crossing shells (added to ``touch``'s
    crossing pairs, so R5 unites them); a pair the vertices cannot decide (or beyond ``MAX_TOUCHING_PAIRS``) joins
    the crossing pairs for the boolean to decide (R4's ``within_up_to_rounding``, R5, R6).  The probes' winding
    numbers between every decided pair are dropped from ``nest``.

    Returns
    -------
    touch : ShellContacts
    nest : Nesting or None
    within : (j, 2) int
        ``(shell, container)`` pairs found by the vertices.
    """
    none = np.zeros((0, 2), dtype=np.int64)
    if nest is None or not touch.complete:
        return touch, nest, none
    faces_touching = np.concatenate([np.asarray(contacts.coplanar_opposite, dtype=np.int64).reshape(-1, 2),
                                     np.asarray(contacts.contact, dtype=np.int64).reshape(-1, 2)])
    faces_touching = faces_touching[labels[faces_touching[:, 0]] != labels[faces_touching[:, 1]]]
    if not len(faces_touching):
        return touch, nest, none
    pairs = np.unique(np.sort(labels[faces_touching], axis=1), axis=0)
    n = len(touch.crossing)
    crossed = np.zeros((n, n), dtype=bool)
    cw = np.asarray(touch.crossing_with, dtype=np.int64).reshape(-1, 2)
    crossed[cw[:, 0], cw[:, 1]] = True
    pairs = pairs[~crossed[pairs[:, 0], pairs[:, 1]]]
    if not len(pairs):
        return touch, nest, none
    from .nesting import touching_sides      # imported on use: touching shells are rare
    tested, beyond = pairs[:MAX_TOUCHING_PAIRS], pairs[MAX_TOUCHING_PAIRS:]
    sides = touching_sides(v, f, labels, tested, faces_touching)
    found = touching_relations(sides.pairs, sides.inside, sides.outside)
    if len(found.crossing):
        crossing = touch.crossing.copy()
        crossing[found.crossing.reshape(-1)] = True
        touch = dataclasses.replace(touch, crossing=crossing)
    more = np.concatenate([cw, found.crossing, found.unknown, beyond]).reshape(-1, 2)
    touch = dataclasses.replace(touch, crossing_with=np.unique(np.sort(more, axis=1), axis=0))
    decided = np.concatenate([found.within, found.apart]).reshape(-1, 2)
    if len(decided):
        drop = np.zeros((n, n), dtype=bool)
        drop[decided[:, 0], decided[:, 1]] = drop[decided[:, 1], decided[:, 0]] = True
        keep = ~drop[nest.shell, nest.other]
        nest = dataclasses.replace(nest, shell=nest.shell[keep], other=nest.other[keep], winding=nest.winding[keep])
    return touch, nest, found.within


def _both(within: np.ndarray | None, more: np.ndarray) -> np.ndarray | None:
    """``(shell, container)`` pairs from the boolean (R4's ``within_up_to_rounding``) and from the vertices."""
    if within is None:
        return more if len(more) else None
    return np.concatenate([np.asarray(within, dtype=np.int64).reshape(-1, 2), more]).reshape(-1, 2)


#: Crossing shell pairs tested for lying one within the other (R4), at most; beyond, a pair stays crossing.
MAX_WITHIN_PAIRS = 256


def _within(v: np.ndarray, f: np.ndarray, labels: np.ndarray, volumes: np.ndarray,
            crossing_with: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """R4: the crossing pairs whose one shell lies within the other up to rounding (``(shell, container)``), and the
    pairs that cross for real (:func:`~.policy.within_up_to_rounding`, volumes shared by manifold3d)."""
    pairs = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    if not len(pairs):
        return np.zeros((0, 2), dtype=np.int64), pairs
    from .union import common_volumes            # imported on use: crossings are rare
    tested = pairs[:MAX_WITHIN_PAIRS]
    within, really = within_up_to_rounding(volumes, tested, common_volumes(v, f, labels, volumes, tested))
    return within, np.concatenate([really, pairs[MAX_WITHIN_PAIRS:]])


def _accurate(v: np.ndarray, f: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments],
              origin: np.ndarray | None = None) -> tuple[list[VolumeMoments], RoundoffBound]:
    """R7: the shells with their round-off bounded (:func:`~inertia_tool.integrals.accurate_shells`: a sliver
    thinner than its coordinates' rounding integrated exactly, so that even its sign is right), and each shell's
    round-off bound.  ``origin``: the point ``shells`` were integrated about (default the vertices' bounding-box
    centre, computed again)."""
    better, _, bound = accurate_shells(v, f, labels, list(shells), origin)
    return better, bound


def _bodies(v: np.ndarray, f: np.ndarray, split_welded: bool,
            known: tuple[np.ndarray, int] | None = None) -> tuple[np.ndarray, int]:
    """R1 (edge-connected shells) and, on a surface with non-manifold edges, R1b (bodies welded along their
    crossing split apart, :func:`~.policy.welded_bodies`).  ``known``: the shell labels of ``f`` if already
    taken (with the edge census)."""
    labels, n_shells = known if known is not None else shell_labels(f, len(v))
    if split_welded and n_shells:
        welded = welded_bodies(f, len(v), labels, n_shells, v)
        if welded.split:
            return welded.labels, welded.n_shells
    return labels, n_shells


def _twin_candidates(shells: Sequence[VolumeMoments], labels: np.ndarray) -> np.ndarray | None:
    """(m,) bool: faces of shells that could be copies of another (R0: same face count, |volume| and area equal
    to 1e-9), or None when no two shells could be."""
    n = len(shells)
    if n < 2:
        return None
    count = np.bincount(labels, minlength=n)
    size = np.array([[abs(s.volume), s.area] for s in shells])
    order = np.lexsort((size[:, 0], count))
    a, b = order[:-1], order[1:]
    close = (count[a] == count[b]) & np.all(np.abs(size[a] - size[b]) <= 1e-9 * np.maximum(size[a], size[b]), axis=1)
    if not close.any():
        return None
    shell = np.zeros(n, dtype=bool)
    shell[a[close]] = shell[b[close]] = True
    return np.asarray(shell[labels])


def _leave_out_coincident(v: np.ndarray, f: np.ndarray, among: np.ndarray | None, source: str,
                          labels: np.ndarray | None = None) -> tuple[np.ndarray, str | None]:
    """R0: the faces without the later copy of each shell listed twice and without shells cancelled by their exact
    inverted copy, with the note (warned); refused when nothing is left."""
    found = coincident_surfaces(v, f, among, labels)
    if not found.drop.any():
        return f, None
    if found.drop.all():
        raise InvalidMeshError(f"{source}: the mesh is a closed surface listed together with its exact inverted copy "
                               f"({len(f) // 2:,} faces each, same corners, opposite winding): they cancel to "
                               "nothing (winding number 0 everywhere, no volume); remove one copy, or reverse it "
                               "if the surface was meant twice")
    note = coincident_message(found)
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=4)
    return f[~found.drop], note


def _boxes_meet(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> np.ndarray:
    """(s,) bool: shells whose bounding box meets another shell's."""
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    tri = v[f[order]]
    lo = np.minimum.reduceat(tri.min(axis=1), starts, axis=0)
    hi = np.maximum.reduceat(tri.max(axis=1), starts, axis=0)
    meet = np.all(lo[:, None] <= hi[None], axis=2) & np.all(lo[None] <= hi[:, None], axis=2)
    np.fill_diagonal(meet, False)
    return np.asarray(meet.any(axis=1))


def _drop_flat(v: np.ndarray, f: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments], diag: float,
               source: str, bound: RoundoffBound, *,
               warn: bool = True) -> tuple[np.ndarray, np.ndarray, int, list[VolumeMoments], str | None,
                                           RoundoffBound]:
    """R2: leave out closed shells that enclose no volume; refuse when nothing else is left.  ``bound`` is the
    round-off bound of ``shells`` (R7), returned anew when they are recomputed."""
    n_shells = len(shells)
    flat = np.array([abs(s.volume) <= FLAT_RTOL * diag ** 3 for s in shells], dtype=bool)
    if not flat.any():
        return f, labels, n_shells, shells, None, bound
    if flat.all():
        what = "the mesh encloses" if n_shells == 1 else f"all {n_shells} shells enclose"
        raise InvalidMeshError(f"{source}: {what} no volume (flat or collapsed surface); for a sheet or a "
                               "thin-walled part use the shell model with a wall `thickness`")
    flat &= negligible_flat(shells, flat)        # a thin but real solid whose moments count stays
    if not flat.any():
        return f, labels, n_shells, shells, None, bound
    dropped_faces = int(np.count_nonzero(flat[labels]))
    f = f[~flat[labels]]
    labels, n_shells = shell_labels(f, len(v))
    shells, bound = _accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
    n_flat = int(np.count_nonzero(flat))
    note = (f"{n_flat} closed piece{'s' if n_flat > 1 else ''} enclosing no volume ({dropped_faces:,} faces: "
            "zero-thickness walls, coincident opposite faces or flat slivers) left out; they contribute nothing "
            "to the integrals")
    if warn:
        warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=4)
    return f, labels, n_shells, shells, note, bound


def _apply_flips(f: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments], flip: np.ndarray, n_shells: int,
                 source: str, *, warn: bool = True) -> tuple[np.ndarray, list[VolumeMoments]]:
    """Turn the shells marked by R4, with an :class:`InsideOutWarning` naming how many."""
    if not flip.any():
        return f, shells
    face_flip = flip[labels]
    f = f.copy()
    f[face_flip] = f[face_flip][:, ::-1]
    shells = [VolumeMoments(-s.volume, s.centroid, -s.second_moment, s.area, s.zero_area_faces) if flip[k] else s
              for k, s in enumerate(shells)]
    if warn:
        n_flipped = int(np.count_nonzero(flip))
        what = "the mesh is" if n_shells == 1 or n_flipped == n_shells else f"{n_flipped} of {n_shells} shells are"
        warnings.warn(InsideOutWarning(f"{source}: {what} inside out for its nesting depth (a body wound inward "
                                       "or a cavity outward); flipped"), stacklevel=4)
    return f, shells


def _total(shells: Sequence[VolumeMoments]) -> VolumeMoments:
    """The moments of all shells together (cavities negative): volume, centroid, central second moment."""
    volume = sum(s.volume for s in shells)
    centroid = np.asarray(sum(s.volume * s.centroid for s in shells), dtype=np.float64) / volume
    second = np.asarray(sum(s.second_moment + s.volume * np.outer(s.centroid - centroid, s.centroid - centroid)
                            for s in shells), dtype=np.float64)
    return VolumeMoments(volume=volume, centroid=centroid, second_moment=second, area=sum(s.area for s in shells))


def _unite(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, owner: np.ndarray, source: str,
           repair: bool) -> UnionSurface | None:
    """The union of the closed pieces (a :class:`~.union.UnionSurface`), or None when the boolean refuses.

    Each piece belongs to the body that owns its shell, so cavities are cut from their own body only.
    """
    from .union import UnionError, closed_groups, two_manifold, union_surface      # on use: overlaps are rare
    groups, n_groups = closed_groups(faces, len(vertices))
    # within the shells: bodies welded along their crossing (R1b) are closed apart, though one group to closed_groups
    _, groups = np.unique(np.stack([np.asarray(labels, dtype=np.int64), groups], axis=1), axis=0, return_inverse=True)
    groups = groups.reshape(-1)
    n_groups = int(groups.max()) + 1 if len(groups) else 0
    pieces = body_volume_moments(vertices, faces, groups, n_groups)
    volume = np.array([p.volume for p in pieces])
    lo, hi = bounding_box(vertices)
    solid = np.abs(volume) > FLAT_RTOL * float(np.linalg.norm(hi - lo)) ** 3    # sheets (a face and its reverse)
    shell_of_group = np.zeros(n_groups, dtype=np.int64)
    shell_of_group[groups] = labels
    keep = solid[groups]
    _, groups = np.unique(groups[keep], return_inverse=True)
    groups = groups.reshape(-1)
    try:
        united = union_surface(vertices, faces[keep], groups, int(np.count_nonzero(solid)),
                               volume[solid] > 0, body=np.asarray(owner)[shell_of_group[solid]])
        summed = float(np.sum(volume[solid]))
        # manifold3d assumes manifold pieces and does not always say when one is not (bodies welded face to face,
        # joined by closed_groups at four-face rims): its union of such a piece is no witness (welded slabs came
        # back 3 % short); when it disagrees with the summed integral, the union is not formed
        if abs(united.volume - summed) > TOUCH_VOLUME_RTOL * abs(summed) and \
                not two_manifold(faces[keep], groups):
            raise UnionError("a closed piece has non-manifold edges (shared by more than two faces) and the "
                             "boolean's union of it disagrees with the summed integral")
        return united
    except UnionError as exc:
        if repair:
            return None
        raise InvalidMeshError(f"{source}: overlapping bodies whose union cannot be formed ({exc}); "
                               "`overlap` 'sum' adds them (shared volume counted twice), `repair=True` gives a "
                               "bounded estimate") from None


def _with_patch_doubt(forced: Resolution, patched: Estimate, source: str) -> Resolution:
    """The estimate of a patched surface that then turned out to pass through itself, with the patches' own doubt
    added to the grid's.

    The grid estimate bounds its distance from the solid {w ≥ 1} of the surface it was given, the patched one;
    that solid differs from the true one only where the patches' bound says (the doubtful regions over the holes,
    :mod:`~.holes`).  So the volume in doubt is the sum of both, lying within the farther of the two reaches from
    the estimate's centroid (the patches' measured from the patched centroid, plus the distance between the
    centroids).  The grid's cell-by-cell first and second moments of doubt are not kept: the bound is wider
    than either alone, never narrower than the truth allows (before, the patches' doubt was dropped)."""
    from .uncertainty import check_useful, uncertainty_from
    est = forced.estimate
    assert est is not None, "a forced resolution carries its estimate"
    doubt = est.uncertainty.volume_in_doubt + patched.uncertainty.volume_in_doubt
    far = max(est.far, patched.far + float(np.linalg.norm(np.asarray(est.centroid) - patched.centroid)))
    unc = uncertainty_from(est.volume, est.centroid, est.second_moment, doubt, far)
    check_useful(est.volume, unc, source=source, what="the patched surface's winding-number estimate")
    note = (f"the holes' patches add their own {patched.uncertainty.volume_in_doubt:.3g} m³ in doubt to the "
            "grid's")
    return dataclasses.replace(forced, estimate=dataclasses.replace(est, uncertainty=unc),
                               notes=forced.notes + (note,))


def _estimated(found: Resolution, common: dict[str, Any]) -> PreparedMesh:
    """A PreparedMesh holding one estimated solid (``repair=True``)."""
    est = found.estimate
    assert est is not None, "only an estimated Resolution reaches here"
    moments = VolumeMoments(volume=est.volume, centroid=est.centroid, second_moment=est.second_moment,
                            area=est.area)
    lo, hi = bounding_box(found.vertices)
    common = {"overlapping_shells": 0, **common}
    report = MeshReport(certificate=Certificate("estimate"), vertices=len(found.vertices), faces=len(found.faces),
                        zero_area_faces=0, bodies=1,
                        cavities=0, flipped_shells=0, repaired=True, repair_actions=found.notes,
                        repair_volume_change=None, bbox_min=lo, bbox_max=hi, method=est.method,
                        uncertainty=est.uncertainty, notes=found.notes, **common)
    return PreparedMesh(vertices=found.vertices, faces=found.faces, labels=np.zeros(len(found.faces), dtype=np.intp),
                        shells=(moments,), owner=np.zeros(1, dtype=np.intp), report=report)
