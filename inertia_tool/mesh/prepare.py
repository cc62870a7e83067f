"""From a raw mesh to a checked one: the stages that decide what the triangles mean as a solid, in order.

1. :mod:`.surface`: degenerate faces, extent, a shell listed twice by index (R0), the tolerance weld, the edge
   census and repair on request (:mod:`.resolve`): a closed surface, or a bounded estimate.
2. :mod:`.shells`: shells and welded bodies (R1, R1b), copies (R0), round-off (R7), flat shells (R2).
3. :mod:`.welded`: bodies welded where coplanar faces make the split undefined (R1b).
4. :mod:`.settle`: the exact face-pair contacts (:mod:`.intersect`), folds that enclose nothing (R3a).
5. :mod:`.self_crossing`: a shell that passes through itself (R3).
6. :mod:`.classify`: bodies and cavities by nesting depth, touching shells, overlap candidates (R4).
7. :mod:`.unite`: the boolean union of overlapping bodies (R5, R6).
8. :mod:`.certify`: the certificate (R7) and a patched surface's bound.

Each stage refuses what it cannot interpret (open, non-manifold or inconsistently wound surfaces without
``repair``, flat shells, coordinates beyond float64's safe range) with an :class:`InvalidMeshError`; where only
an estimate can be given (``repair``), the stage hands one back and the stages after it do not run.  Every rule
is stated in :mod:`.policy`.  The per-shell volume moments (:mod:`inertia_tool.integrals`, used here to read the
sign of each shell) are handed on, so that the faces are integrated once.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..errors import InternalInvariantError, InvalidMeshError, UsageError
from ..integrals import VolumeMoments, bounding_box
from ..tolerances import MERGE_TOLERANCE
from ..values import frozen_value
from .certify import certify, first_checks, misread_reading, with_interior_note, with_weld_doubt
from .checks import MeshReport
from .classify import orient_shells
from .hole_assumptions import NOTHING_ASSUMED, USER_ASSUMPTIONS, UserAssumptions
from .policy import Certificate
from .read import RawMesh
from .resolve import Resolution
from .uncertainty import Estimate
from .self_crossing import with_patch_doubt, settle_self_crossing
from .settle import find_contacts
from .shells import counted, find_shells
from .surface import close_surface
from .unite import NOTHING_LEFT, unite_overlaps
from .welded import settle_welded

__all__ = ["PreparedMesh", "prepare_mesh", "OVERLAP_MODES"]


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


def prepare_mesh(raw: RawMesh, *, repair: bool = False, merge_tolerance: float = MERGE_TOLERANCE,
                 overlap: str = "union", self_crossing: str = "refuse",
                 assume: UserAssumptions = NOTHING_ASSUMED) -> PreparedMesh:
    """Check a raw mesh and classify its shells (see the module docstring for the stages).

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
    assume : UserAssumptions
        The user's assumptions about the holes a repair fills (only with ``repair``; ``LoadOptions.assume``),
        passed to :func:`~.holes.patched_estimate`.  Those the result rests on are named in its certificate
        (:attr:`~.policy.Certificate.assumptions`).  Default: none.

    Returns
    -------
    PreparedMesh

    Raises
    ------
    InvalidMeshError
        Not a solid (and ``repair`` is off), flat, or beyond float64's safe range.
    UsageError
        ``assume`` not a :class:`~.hole_assumptions.UserAssumptions`, or stated without ``repair``.
    """
    if overlap not in OVERLAP_MODES:
        raise UsageError(f"Expected `overlap` to be one of {', '.join(OVERLAP_MODES)}, got {overlap!r}")
    if self_crossing not in ("refuse", "unverified"):
        raise UsageError(f"Expected `self_crossing` to be 'refuse' or 'unverified', got {self_crossing!r}")
    if not isinstance(assume, UserAssumptions):
        raise UsageError(f"Expected `assume` to be a UserAssumptions, got {assume!r}")
    if assume and not repair:
        raise UsageError(f"`assume` ({', '.join(assume.names)}) is an assumption about the holes a repair fills: "
                         "expected it with `repair=True`")
    source = raw.source
    surface = close_surface(raw, repair=repair, merge_tolerance=merge_tolerance, assume=assume)
    found, diag = surface.found, surface.diag
    common: dict[str, Any] = dict(source=source, units=raw.units, file_faces=raw.file_faces,
                                  degenerate_faces=surface.degenerate, watertight=surface.watertight,
                                  welded_tolerance=found.welded_tolerance, flipped_faces=found.flipped_faces,
                                  nonmanifold_edges=found.nonmanifold_edges)
    patched = found.estimate if found.estimate is not None and found.estimate.method == "patched" else None
    if found.estimate is not None and patched is None:
        return _estimated(found, common, None)
    # a patched surface is closed: its shells are classified and overlaps united like any other, and the bounds of
    # the patches carry over to the result
    split_welded = bool(found.nonmanifold_edges) and patched is None
    as_read = surface.vertices is raw.vertices         # the box of the vertices read still holds
    first = find_shells(surface.vertices, surface.faces, split_welded=split_welded, known=surface.census,
                        centre=0.5 * (surface.lo + surface.hi) if as_read else None, diag=diag, source=source)
    welded = settle_welded(first.shells, split_welded=split_welded, overlap=overlap, repair=repair, diag=diag,
                           source=source)                                                           # R1b
    weld = surface.found.weld          # what the tolerance weld moved: a forced estimate's doubt too (R4)
    if welded.forced is not None:      # on a patched surface the patches' doubt is added (as R3's forced estimate)
        forced = welded.forced if patched is None else with_patch_doubt(welded.forced, patched, source)
        return _estimated(with_weld_doubt(forced, weld, source), common, patched)
    met = find_contacts(welded.shells, welded=welded.welded, patched=patched is not None,
                        split_welded=split_welded, n_read=len(raw.vertices), diag=diag, source=source)   # R3a
    if patched is not None:
        found = dataclasses.replace(found, notes=found.notes + met.patch_notes)
    crossed = settle_self_crossing(met.shells, met.contacts, arranged=welded.arranged, self_crossing=self_crossing,
                                   overlap=overlap, repair=repair, patched=patched, diag=diag, source=source,
                                   region=welded.region)                                                    # R3
    if crossed.forced is not None:
        return _estimated(with_weld_doubt(crossed.forced, weld, source), common, patched)
    oriented = orient_shells(crossed.shells, crossed.contacts, crossed.touch, source=source,
                             multiplicity=counted(crossed.shells, surface.repeated, first.repeated))        # R4, R0
    kind, checks = first_checks(oriented.touch, crossed.unverified)
    resolved_edges = found.nonmanifold_edges if met.folds is None and welded.arranged is None else None
    contacts = oriented.contacts if oriented.contacts is not None else crossed.contacts   # R4 may leave shells out
    united = unite_overlaps(oriented, contacts, nonmanifold_edges=resolved_edges, method=found.method,
                            kind=kind, checks=checks, overlap=overlap, repair=repair, diag=diag,
                            source=source)                                                     # R5, R6
    if united.forced is not None:       # R4: the shells left out where the file's winding stands are said too
        forced = with_interior_note(united.forced, oriented, source)
        forced = forced if patched is None else with_patch_doubt(forced, patched, source)
        return _estimated(with_weld_doubt(forced, weld, source), {**common, "overlapping_shells": united.overlaps},
                          patched)
    united, spread = misread_reading(oriented, united, method=found.method, source=source)     # R4's label
    shells = united.shells
    if not sum(s.volume for s in shells.moments) > 0:        # bodies and cavities cancel: no solid to certify
        raise InvalidMeshError(NOTHING_LEFT.format(source=source))
    certified = certify(shells, kind=united.kind, checks=united.checks, method=united.method, patched=patched,
                        arranged=crossed.arranged is not None, verified=crossed.verified,
                        ambiguous=bool(oriented.ambiguous), folds=met.folds is not None,
                        sheets_removed=found.method == "sheets-removed", source=source, spread=spread,
                        scale_rounding=raw.scale_rounding, weld=weld, arranged_region=crossed.region,
                        assumed=assume.names)                                                              # R7
    stages = (first.dropped, crossed.arranged, met.folds.describe() if met.folds is not None else None,
              crossed.unverified)
    notes = (*found.notes, *surface.coincident, *first.coincident, *oriented.notes,
             *(note for note in stages if note is not None), *united.notes, *certified.notes)
    v, f = shells.vertices, shells.faces
    bbox_min, bbox_max = (surface.lo, surface.hi) if v is raw.vertices else bounding_box(v)
    report = MeshReport(vertices=len(v), faces=len(f), zero_area_faces=sum(s.zero_area_faces for s in shells.moments),
                        bodies=int(np.count_nonzero(united.owner == np.arange(shells.n_shells))),
                        cavities=united.cavities, flipped_shells=int(np.count_nonzero(oriented.flip)),
                        overlapping_shells=united.overlaps, repaired=patched is not None,
                        repair_actions=notes if patched is not None else (), repair_volume_change=None,
                        bbox_min=bbox_min, bbox_max=bbox_max, method=certified.method,
                        uncertainty=certified.uncertainty, notes=notes,
                        certificate=_with_users(certified.certificate, patched), **common)
    return PreparedMesh(vertices=v, faces=f, labels=shells.labels, shells=tuple(shells.moments), owner=united.owner,
                        report=report)


def _with_users(certificate: Certificate, patched: Estimate | None) -> Certificate:
    """``certificate`` naming the user's assumptions the patched surface ``patched`` took (unchanged without)."""
    users = {a.name for a in USER_ASSUMPTIONS}
    taken = tuple(name for name in patched.assumptions if name in users) if patched is not None else ()
    return dataclasses.replace(certificate, assumptions=taken) if taken else certificate


def _estimated(found: Resolution, common: dict[str, Any], patched: Estimate | None) -> PreparedMesh:
    """A PreparedMesh holding one estimated solid (``repair=True``); ``patched``: the patched surface it was
    formed from, if any (the user's assumptions it took carry over)."""
    est = found.estimate
    if est is None:
        raise InternalInvariantError("an estimated resolution was expected to carry its estimate; found none "
                                     f"(method {found.method!r})")
    moments = VolumeMoments(volume=est.volume, centroid=est.centroid, second_moment=est.second_moment,
                            area=est.area)
    lo, hi = bounding_box(found.vertices)
    common = {"overlapping_shells": 0, **common}
    taken = _with_users(Certificate("estimate"), patched if patched is not None else est)
    report = MeshReport(certificate=taken, vertices=len(found.vertices), faces=len(found.faces),
                        zero_area_faces=0, bodies=1,
                        cavities=0, flipped_shells=0, repaired=True, repair_actions=found.notes,
                        repair_volume_change=None, bbox_min=lo, bbox_max=hi, method=est.method,
                        uncertainty=est.uncertainty, notes=found.notes, **common)
    return PreparedMesh(vertices=found.vertices, faces=found.faces, labels=np.zeros(len(found.faces), dtype=np.intp),
                        shells=(moments,), owner=np.zeros(1, dtype=np.intp), report=report)
