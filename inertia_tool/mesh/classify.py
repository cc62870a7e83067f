"""R4 to R6 of :mod:`~.policy`, the reading of closed shells: which is a body and which a cavity (by nesting
depth, turning shells wound against it), the body each cavity belongs to, and which shells may overlap
(candidates for the boolean of :mod:`~.unite`).

:func:`orient_shells` is the stage :func:`~.prepare.prepare_mesh` runs once no shell passes through itself;
:func:`classify_shells` applies the same rules for callers that hold several prepared meshes side by side.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import InsideOutWarning, InvalidMeshError, MeshResolvedWarning
from ..integrals import RoundoffBound, VolumeMoments
from ..tolerances import TOUCH_VOLUME_RTOL
from .edges import unique_rows
from .intersect import SurfaceContacts, surface_contacts
from .multiplicity import container_windings, multiplicity_changes
from .policy import (MisreadNesting, ShellContacts, boxes_holding, cavities_in_overlap, inward_crossing_outward,
                     inward_crossing_shells, misread_nesting, misread_voids, nested_copies, orient_by_depth,
                     outward_crossing_groups, pairs_without, reading_difference, rounding_volumes, shell_contacts,
                     undecided_shells, winding_stands, within_up_to_rounding)
from .settle import settle_touching
from .shells import Shells, apply_flips

if TYPE_CHECKING:       # imported on use at run time (below)
    from .nesting import Nesting

__all__ = ["Orientation", "orient_shells", "classify_shells", "shell_nesting_or_none", "boxes_meet",
           "MAX_WITHIN_PAIRS"]


class Orientation(NamedTuple):
    """What :func:`orient_shells` read.

    Attributes
    ----------
    shells : Shells
        Turned where R4 says (bodies outward, cavities inward).
    touch : ShellContacts
        The shells' contacts, with touching pairs settled by their vertices.
    flip : (s,) bool
        Shells turned.
    owner : (s,) int
        Body each shell belongs to.
    depth : (s,) int
        Nesting depth (odd: a cavity).
    candidates : (s,) bool
        Shells the boolean must look at (crossing, touching, undecided; every shell whose box meets another's
        when the contact check gave up).
    crossing : (s,) bool
        Shells that cross another for real (R4 could not read one within the other).
    ambiguous : int
        Inward-wound shells crossing an outward one (read as cavities cut from it: a reading, not proven).
    notes : tuple of str
        What was read, in words (the ``ambiguous`` one warned).
    misread : MisreadNesting or None
        Shells the file winds outward that nesting depth reads as cavities (a reading the file does not decide:
        :func:`~.certify.misread_reading` labels it).
    groups : MisreadNesting or None
        Groups of crossing shells wound outward at odd depth, kept as bodies (``kept="union"``): the same two
        readings (:func:`~.policy.outward_crossing_groups`; labelled by :func:`~.certify.misread_reading`).
    by_winding : bool
        R4c: cavities lie inside bodies that overlap, or cross each other, and the file's winding is read as it
        stands (no shell turned): the boolean forms ``{w ≥ 1}`` without owners (:func:`~.union.winding_solid`).
    voids : MisreadNesting or None
        Shells the file winds inward inside a cavity (a void inside a void) that nesting depth reads as bodies
        (:func:`~.policy.misread_voids`; labelled by :func:`~.certify.misread_reading`, as ``misread``).
    multiplicity : (s,) int or None
        How many times R0 found each shell listed (:func:`~.multiplicity.shell_multiplicity`), where that
        changes ``{w ≥ 1}`` and R4c counts it (:func:`~.union.winding_solid`); None: each shell once.
    turned_reading : bool
        R4c was taken because a misread reading rested on a shell R4 turned (:func:`_rests_on_a_turn`): where R4c
        refuses, ``repair`` refuses too (:func:`~.policy.turned_reading_refusal`).
    interior : MisreadNesting or None
        Nests whose own winding is a solid's where depth would read a shell wound outward as a cavity
        (:func:`~.policy.winding_stands`, ``kept="winding"``): the shells ``interior.drop`` (numbered as in the
        file's shells) were left out of ``shells``, and the depth reading is named by
        :func:`~.certify.misread_reading`.
    contacts : SurfaceContacts or None
        The face pairs of ``shells`` when shells were left out (``interior``), for the later stages; None: the
        contacts given.
    """

    shells: Shells
    touch: ShellContacts
    flip: np.ndarray
    owner: np.ndarray
    depth: np.ndarray
    candidates: np.ndarray
    crossing: np.ndarray
    ambiguous: int
    notes: tuple[str, ...]
    misread: MisreadNesting | None = None
    groups: MisreadNesting | None = None
    by_winding: bool = False
    voids: MisreadNesting | None = None
    multiplicity: np.ndarray | None = None
    turned_reading: bool = False
    interior: MisreadNesting | None = None
    contacts: SurfaceContacts | None = None


def orient_shells(shells: Shells, contacts: SurfaceContacts, touch: ShellContacts, *, source: str,
                  multiplicity: np.ndarray | None = None) -> Orientation:
    """R4: the shells oriented by nesting depth (touching pairs decided by their vertices, crossing pairs that lie
    one within the other up to rounding by the boolean), with the overlap candidates of R5 and R6.

    ``multiplicity``: (s,) int, how many times R0 found each shell listed (None: once each).  Where counting a
    shell that many times changes ``{w ≥ 1}`` (:func:`~.multiplicity.multiplicity_changes`), the solid is formed
    by R4c, which counts it (R0), when R4 turned no shell; otherwise refused.

    Where depth would read a shell the file winds outward as a cavity in a nest whose own winding is a solid's (no
    region below 0: :func:`~.policy.winding_stands`), the shells with winding at least one on both sides are left
    out and the rest read again (their winding is then 0 or 1 everywhere in that nest); ``interior`` says so."""
    return _orient_shells(shells, contacts, touch, source=source, multiplicity=multiplicity, again=False)


def _orient_shells(shells: Shells, contacts: SurfaceContacts, touch: ShellContacts, *, source: str,
                   multiplicity: np.ndarray | None, again: bool, unplaced: np.ndarray | None = None) -> Orientation:
    """:func:`orient_shells`; ``again``: the shells are what :func:`~.policy.winding_stands` left (not asked
    again: the nests it kept have winding 0 or 1 everywhere); ``unplaced``: (s,) bool, the shells the whole file
    left undecided, kept undecided here (:func:`_still_undecided`)."""
    v, f, labels, n_shells = shells.vertices, shells.faces, shells.labels, shells.n_shells
    nest = shell_nesting_or_none(v, f, labels, n_shells)
    file_volumes = np.array([s.volume for s in shells.moments])
    touch, nest, touch_within, touch_apart = settle_touching(v, f, labels, contacts, touch, nest)
    within, crossing_with = None, touch.crossing_with
    copies = np.zeros((0, 2), dtype=np.int64)
    if touch.complete:
        rounding = rounding_volumes(v, shells.moments)
        within, crossing_with = _within(v, f, labels, file_volumes, crossing_with, rounding)
        # R4: a shell left undecided because its probes lay on a shell it touches from inside or outside (a box
        # flush with its container on five faces) is probed again without that shell, as past crossing partners
        # (session 18: and past the shells it touches from outside, a slab flush between two boxes)
        nest = _decide_past_partners(v, f, labels, n_shells, nest, np.concatenate(
            [np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2), within.reshape(-1, 2),
             np.asarray(touch_within, dtype=np.int64).reshape(-1, 2), touch_apart]))
        apart = (crossing_with, touch_within)          # nested copies not yet moved to the crossing pairs
        crossing_with, touch_within, copies = _copies_nested(file_volumes, nest, crossing_with, touch_within,
                                                             rounding)
    if unplaced is not None:
        nest = _still_undecided(nest, unplaced)
    flip, owner, depth = orient_by_depth(file_volumes, nest, crossing_with, crossing_known=touch.complete,
                                         within=_both(within, touch_within))
    # R4 (session 16): where a nest's own winding is a solid's (no region below 0), it stands: the shells with
    # winding ≥ 1 on both sides are left out and the rest read again (two nested outward boxes: the outer box)
    # (session 17: per nest, a nest none of whose shells crosses any shell, or a sub-nest inside a nest with
    # crossings, the rest read by the other rules)
    # Nested copies (a shell inside another wound alike, all but the rounding of its volume) are nested shells for
    # it, not crossing ones: wound outward, the inner one has winding 1 and 2 on its sides and is left out, exact
    # (before: united by the boolean, ``unverified``)
    if touch.complete and not again:
        s_cross, s_within = apart               # the same pairs as now where no nested copies were found
        s_depth = orient_by_depth(file_volumes, nest, s_cross, within=_both(within, s_within))[2] if len(copies) \
            else depth
        # a shell left undecided keeps the rule only from the nests it may lie in (by the shells' boxes; session 18)
        boxes = shell_boxes(v, f, labels, n_shells) if nest is not None and np.asarray(nest.undecided).any() \
            else None
        for inside_crossed in (True, False):
            stands = winding_stands(file_volumes, s_depth, nest, _both(within, s_within), s_cross, multiplicity,
                                    inside_crossed=inside_crossed, boxes=boxes)
            if stands is None or stands.drop is None:
                break
            read = _read_without(shells, contacts, stands, multiplicity, nest, _both(within, s_within), source)
            if read is not None:
                return read
    misread = misread_nesting(file_volumes, flip, depth, nest, _both(within, touch_within)) \
        if touch.complete else None                                                   # R4: the file does not decide
    groups = outward_crossing_groups(file_volumes, flip, depth, crossing_with) if touch.complete else None
    shared = cavities_in_overlap(nest, crossing_with, depth) if touch.complete else 0
    crossed_cavities = _crossing_cavities(crossing_with, depth, owner) if touch.complete else 0
    # R4c: where the depth cannot name a cavity's body (cavities inside overlapping bodies, cavities crossing each
    # other), the solid is {w ≥ 1} of the shells as the file winds them, formed without owners
    inward = inward_crossing_shells(file_volumes, flip, crossing_with) if touch.complete else np.zeros(0, bool)
    held_cavities = bool(inward.any()) and bool(np.all(depth[inward] % 2 == 1))   # each inside a body, as wound
    spanning = _cavities_across_bodies(file_volumes, flip, crossing_with) if touch.complete else 0
    # R4c: a shell inside a cavity that keeps the file's winding because it crosses a body (even depth, wound inward)
    # has a depth that means nothing; there R4c takes precedence over the misread readings (review 11's D5 family)
    in_kept = _inside_kept_cavities(file_volumes, flip, depth, nest, _both(within, touch_within), crossing_with) \
        if touch.complete else 0
    # R4: a shell inside a void read as an island (the file's winding is −1 there; session 14's N8)
    voids = misread_voids(file_volumes, flip, depth, nest, _both(within, touch_within)) if touch.complete else None
    # R4: a misread reading inside a shell R4 turned rests on that turn: neither of its readings is the file's winding
    # (session 14's N5: three outward boxes crossing inside an inward box, 48 or 34 cells for the file's 26); the
    # file's winding is read as it stands (R4c), refused where inward shells lie outside every body
    on_turn = _rests_on_a_turn([r for r in (misread, groups) if r is not None], file_volumes, flip, nest,
                               _both(within, touch_within))
    if in_kept or on_turn:
        misread = groups = voids = None
    if misread is not None or voids is not None:      # R4: by how much the file's winding differs, where known exactly
        known = reading_difference(file_volumes, depth, nest, _both(within, touch_within), crossing_with)
        misread = None if misread is None else dataclasses.replace(misread, difference=known)
        voids = None if voids is None else dataclasses.replace(voids, difference=known)
    # R0: a shell listed k times counts k times in the winding; where that changes {w ≥ 1} (a box listed twice
    # inside a void: session 14's N6) R4c forms it, counting each piece that often (union.winding_solid)
    many = touch.complete and _counted_more_than_once(multiplicity, file_volumes, flip, nest,
                                                      _both(within, touch_within), crossing_with)
    by_winding = bool(shared or crossed_cavities or held_cavities or spanning or in_kept or on_turn or many) \
        and misread is None and groups is None
    if by_winding:      # shells inside others keep the file's winding; a body inside out on its own is still turned,
        # but not one holding a shell wound against its depth (which keeps the file's winding here): turning the one
        # and not the other is neither the file's winding nor R4's reading (session 14: an inward box holding an
        # outward one, beside hollow bodies crossing, was turned and united with it, 24 cells for the file's 0 and
        # the depth reading's 12)
        against = (depth > 0) & ((file_volumes > 0) != (depth % 2 == 0))
        kept_turns = flip & (depth == 0) & ~_holds(nest, _both(within, touch_within), against, n_shells)
        if many and (kept_turns != flip).any():
            raise InvalidMeshError(_many_refusal(source, multiplicity))
        flip = kept_turns
        voids = None                # R4c keeps a void inside a void as wound: the file's winding, no reading
    elif many:          # a reading by nesting depth (misread, groups, voids) cannot count a shell twice
        raise InvalidMeshError(_many_refusal(source, multiplicity))
    quiet = np.zeros(n_shells, dtype=bool)
    for reading in (misread, voids):  # warned once, with both readings, by certify.misread_reading
        if reading is not None:
            quiet[reading.shells] = True
    shells = apply_flips(shells, flip & ~quiet, source)
    shells = apply_flips(shells, flip & quiet, source, warn=False)
    notes = []
    ambiguous = inward_crossing_outward(file_volumes, flip, crossing_with)
    if shared and by_winding:
        notes.append(f"{_cavities_in_overlap(shared)} (two hollow parts overlapping): no body can be named for "
                     f"{'them' if shared > 1 else 'it'}, so the solid is formed where the winding number of the "
                     "shells as the file winds them is at least one")
        warnings.warn(InsideOutWarning(f"{source}: {notes[-1]}"), stacklevel=4)
    if by_winding:      # an inward shell crossing an outward one is a cavity as wound; one outside every body is
        ambiguous = shared = 0                      # refused by the boolean (w < 0 there: unite.unite_overlaps)
    elif shared:
        notes.append(f"{_cavities_in_overlap(shared)}: each is cut from one of them, and which one the file does not "
                     "say (two hollow parts overlapping); the union of the bodies less their cavities is given, not "
                     "verified")
        warnings.warn(InsideOutWarning(f"{source}: {notes[-1]}"), stacklevel=4)
        ambiguous += shared
    if ambiguous - shared:
        plural = ambiguous - shared > 1
        notes.append(f"{ambiguous - shared} inward-wound shell{'s' if plural else ''} cross{'' if plural else 'es'} "
                     "an outward one: read as a cavity cut from it (the solid where the winding number is at least "
                     "one); if it is a body written inside out, fix its winding. Not verified")
        warnings.warn(InsideOutWarning(f"{source}: {notes[-1]}"), stacklevel=4)
    if len(copies):
        n_copies = len(np.unique(copies[:, 0]))
        notes.append(f"{n_copies} shell{'s' if n_copies > 1 else ''} lie{'' if n_copies > 1 else 's'} inside a shell "
                     f"wound alike, without crossing it, and hold{'' if n_copies > 1 else 's'} all but "
                     f"{2 * TOUCH_VOLUME_RTOL:g} of its volume or all but the rounding neighbourhood of its surface "
                     "(a copy scaled or moved by rounding): read as "
                     "copies, not as a body and its cavity (R4), and united by the boolean")
        warnings.warn(MeshResolvedWarning(f"{source}: {notes[-1]}"), stacklevel=4)
    if within is not None and len(within):
        n_within = len(np.unique(within[:, 0]))
        notes.append(f"{n_within} shell{'s' if n_within > 1 else ''} meet{'' if n_within > 1 else 's'} the "
                     "shell around it only on its boundary (a cavity flush with its body's face, a part resting on "
                     "a cavity's floor; the faces there coincide or cross by rounding): read by nesting depth and "
                     "formed by the boolean")
    undecided = nest.undecided if nest is not None else np.zeros(n_shells, dtype=bool)
    if touch.complete:
        candidates = touch.crossing | touch.touching | undecided
    else:       # the check gave up: every shell whose box meets another's goes to the boolean
        candidates = boxes_meet(v, shells.faces, labels, n_shells) | undecided
    candidates[copies.reshape(-1)] = True                 # nested copies: the boolean forms their union
    if by_winding:
        # R4c's solid is formed by the boolean (union.winding_solid) even where no shell touches another: a body
        # listed twice around a cavity listed once (winding 2 − 1 = 1, material) was the summed integral, the
        # cavity cut once (session 16: `exact` 7.875 m³ for {w ≥ 1} = 8)
        candidates[:] = True
    # R4/R7: a shell left undecided is read by its own sign (depth 0), which no probe checked; where its box lies
    # within another shell's it may lie inside that shell, and the answer rests on an unchecked reading: not proven
    # (session 18: a slab flush between two boxes inside an inward box was a body, ``united`` 9 cells high)
    unsure = _maybe_inside(nest, _both(within, touch_within), v, shells.faces, labels, n_shells) \
        if touch.complete and nest is not None and np.asarray(nest.undecided).any() else 0
    if unsure:
        notes.append(f"{unsure} shell{'s' if unsure > 1 else ''} whose probe points all lie on other surfaces "
                     f"may lie inside another shell (its bounding box within the other's): read by "
                     f"{'their' if unsure > 1 else 'its'} own winding, not by a nesting depth. Not verified")
        warnings.warn(InsideOutWarning(f"{source}: {notes[-1]}"), stacklevel=4)
        ambiguous += unsure
    crossing = np.zeros(n_shells, dtype=bool)
    crossing[crossing_with.reshape(-1)] = True
    return Orientation(shells, touch, flip, owner, depth, candidates, crossing, ambiguous, tuple(notes), misread,
                       groups, by_winding, voids, multiplicity if by_winding else None, on_turn and by_winding)


def _read_without(shells: Shells, contacts: SurfaceContacts, stands: MisreadNesting, multiplicity: np.ndarray | None,
                  nest: Nesting | None, within: np.ndarray | None, source: str) -> Orientation | None:
    """:func:`orient_shells` of the shells :func:`~.policy.winding_stands` kept (``stands.drop`` left out), or None
    when the other rules would turn a shell it kept inside a nest with crossings (its sub-nest's winding would then
    not stand as decided: the caller asks again for the nests apart only; so also where they refuse the rest read
    so, their warnings then not given).  The shells kept in the nests decided count once in the winding (R0): their
    winding is 0 or 1 there."""
    drop = np.asarray(stands.drop, dtype=bool)
    unplaced = None if nest is None else undecided_shells(nest, within)[~drop]
    kept_shells, kept_contacts = _without_shells(shells, contacts, drop)
    kept_touch = shell_contacts(kept_contacts, kept_shells.labels, kept_shells.n_shells)
    decided = _in_nests(stands.roots, nest, within, len(drop))
    left = None
    if multiplicity is not None:
        k = np.where(decided, 1, np.asarray(multiplicity, dtype=np.int64))[~drop]
        left = None if np.all(k == k[0]) else k
    with warnings.catch_warnings(record=True) as said:      # said only if this reading is taken
        warnings.simplefilter("always")
        try:
            read = _orient_shells(kept_shells, kept_contacts, kept_touch, source=source, multiplicity=left,
                                  again=True, unplaced=unplaced)
        except InvalidMeshError:
            if stands.others:       # the other rules refuse the rest read so: ask again for the nests apart only
                return None
            raise
    if stands.others and np.asarray(read.flip)[decided[~drop]].any():
        return None
    for found in said:
        warnings.warn(found.message, stacklevel=4)
    return read._replace(interior=stands, contacts=read.contacts if read.contacts is not None else kept_contacts)


def _maybe_inside(nest: Nesting, within: np.ndarray | None, v: np.ndarray, f: np.ndarray, labels: np.ndarray,
                  n_shells: int) -> int:
    """How many shells left undecided (:func:`~.policy.undecided_shells`) have their bounding box within another
    shell's (:func:`~.policy.boxes_holding`, compared exactly: a shell inside another lies within its corners'
    extremes), so may lie inside it.  The first ``MAX_WITHIN_PAIRS`` are compared; any beyond count as inside."""
    unplaced = np.flatnonzero(undecided_shells(nest, within))
    if not len(unplaced):
        return 0
    held = boxes_holding(shell_boxes(v, f, labels, n_shells), unplaced[:MAX_WITHIN_PAIRS])[1]
    return int(np.count_nonzero(held)) + max(0, len(unplaced) - MAX_WITHIN_PAIRS)


def _still_undecided(nest: Nesting | None, unplaced: np.ndarray) -> Nesting | None:
    """``nest`` with the shells ``unplaced`` ((s,) bool) undecided, their probes' winding numbers dropped.

    R4: a shell the whole file left undecided keeps the rule only from the nests it may lie in
    (:func:`~.policy.winding_stands`), and the rest of the file is read by the other rules *as it would have been*:
    with the shells left out, a probe of that shell that lay on one of them (or whose ray met an edge of one) may
    now be clean, and the depth rule would then place it where the file's reading gave it its own sign (a slab
    flush between two boxes inside a third, the two boxes left out: read as a cavity, 4 cells short of ``{w ≥ 1}``,
    ``exact``)."""
    if nest is None or not np.any(unplaced):
        return nest
    from .nesting import Nesting as Found
    keep = ~unplaced[np.asarray(nest.shell, dtype=np.int64)]
    return Found(shell=np.asarray(nest.shell)[keep], other=np.asarray(nest.other)[keep],
                 winding=np.asarray(nest.winding)[keep], probes=nest.probes,
                 undecided=np.asarray(nest.undecided, dtype=bool) | unplaced)


def _in_nests(roots: np.ndarray | None, nest: Nesting | None, within: np.ndarray | None, n_shells: int) -> np.ndarray:
    """(s,) bool: the shells ``roots`` and every shell inside one of them
    (:func:`~.multiplicity.container_windings`)."""
    out = np.zeros(n_shells, dtype=bool)
    if roots is None or not len(roots):
        return out
    out[np.asarray(roots, dtype=np.int64)] = True
    shell, other, _ = container_windings(np.ones(n_shells), nest, within)
    out[shell[out[other]]] = True
    return out


def _without_shells(shells: Shells, contacts: SurfaceContacts, drop: np.ndarray) -> tuple[Shells, SurfaceContacts]:
    """``shells`` without the shells ``drop`` ((s,) bool; the rest numbered in order), their moments and round-off
    bounds kept as integrated, and ``contacts`` without the face pairs that involve a face left out (the rest
    numbered as the faces kept)."""
    keep = ~np.asarray(drop, dtype=bool)
    keep_face = keep[shells.labels]
    number = np.cumsum(keep) - 1
    face_number = np.cumsum(keep_face) - 1
    bound = shells.bound
    kept = Shells(shells.vertices, shells.faces[keep_face],
                  number[shells.labels[keep_face]].astype(shells.labels.dtype, copy=False),   # int32 stays int32
                  int(np.count_nonzero(keep)), [m for m, k in zip(shells.moments, keep) if k],
                  RoundoffBound(volume=np.asarray(bound.volume)[keep], centroid=np.asarray(bound.centroid)[keep],
                                second_moment=np.asarray(bound.second_moment)[keep]))

    def pairs(found: np.ndarray) -> np.ndarray:
        p = np.asarray(found, dtype=np.int64).reshape(-1, 2)
        return np.asarray(face_number[p[keep_face[p].all(axis=1)]], dtype=np.intp).reshape(-1, 2)

    return kept, dataclasses.replace(contacts, crossing=pairs(contacts.crossing), contact=pairs(contacts.contact),
                                     coplanar_opposite=pairs(contacts.coplanar_opposite))


def _rests_on_a_turn(readings: Sequence[MisreadNesting], volumes: np.ndarray, flip: np.ndarray, nest: Nesting | None,
                     within: np.ndarray | None) -> bool:
    """R4: a shell around the shells of a misread reading (:func:`~.policy.misread_nesting`,
    :func:`~.policy.outward_crossing_groups`) was turned by R4, so both readings rest on that turn, and neither is
    the file's own winding (which the note of the reading says the union is).  By the winding numbers at the
    shells' probe points or by touching (``within``: ``(shell, container)`` pairs)."""
    if not readings:
        return False
    ids = np.concatenate([r.shells for r in readings])
    shell, other, _ = container_windings(volumes, nest, within)
    around = np.isin(shell, ids) & ~np.isin(other, ids)
    return bool(np.asarray(flip, dtype=bool)[other[around]].any())


def _counted_more_than_once(multiplicity: np.ndarray | None, volumes: np.ndarray, flip: np.ndarray,
                            nest: Nesting | None, within: np.ndarray | None, crossing_with: np.ndarray) -> bool:
    """R0: some shell listed more than once, and counting it that often may change ``{w ≥ 1}`` of the shells as R4
    turned them (:func:`~.multiplicity.multiplicity_changes`)."""
    if multiplicity is None:
        return False
    oriented = np.where(np.asarray(flip, dtype=bool), -np.sign(volumes), np.sign(volumes)).astype(np.int64)
    shell, other, winding = container_windings(volumes, nest, within)
    turned = np.where(np.asarray(flip, dtype=bool)[other], -winding, winding)
    return multiplicity_changes(multiplicity, oriented, shell, other, turned,
                                np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2))


def _many_refusal(source: str, multiplicity: np.ndarray | None) -> str:
    """R0's refusal, one line: shells listed more than once where that count changes ``{w ≥ 1}`` and R4 turned a
    shell for its nesting depth (no one reading counts both)."""
    k = np.asarray(multiplicity if multiplicity is not None else [], dtype=np.int64)
    times = " or ".join(str(int(t)) for t in np.unique(k[k > 1])) or "several"
    n = int(np.count_nonzero(k > 1))
    return (f"{source}: {n} closed surface{'s' if n > 1 else ''} listed {times} times, where counted that often "
            "(R0) the winding number gives another solid than counted once, and a shell is wound against its "
            "nesting depth: the file does not say which solid it means; remove the copies, or wind every shell as "
            "its role says")


def _copies_nested(volumes: np.ndarray, nest: Nesting | None, crossing_with: np.ndarray,
                   touch_within: np.ndarray, rounding: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R4's copy rule on nested pairs (:func:`~.policy.nested_copies`): ``(crossing_with, touch_within, copies)``
    with the ``(shell, container)`` pairs that are copies (nested without crossing, by the winding numbers at the
    probe points or by touching vertices) moved from the nested pairs to the crossing ones.  Only once the
    face-pair check is complete (a shell inside another then lies wholly inside it)."""
    cross = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    touching = np.asarray(touch_within, dtype=np.int64).reshape(-1, 2)
    pairs = [touching]
    if nest is not None:
        shell, other = np.asarray(nest.shell, dtype=np.int64), np.asarray(nest.other, dtype=np.int64)
        undecided = np.asarray(nest.undecided, dtype=bool)
        held = (np.asarray(nest.winding) != 0) & (shell != other) & ~undecided[shell]
        pairs.append(np.c_[shell[held], other[held]])
    nested = np.concatenate(pairs).reshape(-1, 2)
    nested = pairs_without(nested, cross)      # pairs that cross have no nesting (their copies are R4's already)
    copies = nested[nested_copies(volumes, nested, rounding=rounding)] if len(nested) else nested
    if not len(copies):
        return cross, touching, np.zeros((0, 2), dtype=np.int64)
    copies = unique_rows(np.sort(copies, axis=1))
    return np.concatenate([cross, copies]), pairs_without(touching, copies), copies


def _cavities_in_overlap(count: int) -> str:
    """The subject of the notes on cavities inside overlapping bodies: "2 cavities lie inside bodies that ..."."""
    plural = count > 1
    return f"{count} cavit{'ies' if plural else 'y'} lie{'' if plural else 's'} inside bodies that overlap one another"


def _cavities_across_bodies(volumes: np.ndarray, flip: np.ndarray, crossing_with: np.ndarray) -> int:
    """R4c: shells wound inward that cross two or more outward ones.  No one body owns such a cavity, and cut from
    one owner alone its part in the others stays material while the note says ``{w ≥ 1}`` (review 11, D4: 2.875 m³
    for 2.75)."""
    pairs = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    if not len(pairs):
        return 0
    wound = np.where(flip, -np.sign(volumes), np.sign(volumes))
    bodies: dict[int, set[int]] = {}
    for a, b in ((0, 1), (1, 0)):
        hit = (wound[pairs[:, a]] < 0) & (wound[pairs[:, b]] > 0)
        for cavity, body in pairs[hit][:, [a, b]].tolist():
            bodies.setdefault(cavity, set()).add(body)
    return sum(1 for crossed in bodies.values() if len(crossed) >= 2)


def _inside_kept_cavities(volumes: np.ndarray, flip: np.ndarray, depth: np.ndarray, nest: Nesting | None,
                          within: np.ndarray | None, crossing_with: np.ndarray) -> int:
    """R4c: how many shells lie inside a shell wound inward at even depth (a cavity that crosses a body, kept as the
    file winds it: R4 gives it no depth of its own), by the winding numbers at their probe points or by touching
    or the boolean (``within``: ``(shell, container)`` pairs).  Their depth counts a cavity as if it were a body,
    so it names no role: review 11's D5 (a box flush inside a void crossing a body, its winding 1 − 1 = 0 as wound)
    was read as a misread cavity and answered 1.6875 ±0.93 % for ``{w ≥ 1}`` = 1.65625."""
    wound = np.where(flip, -np.sign(volumes), np.sign(volumes))
    kept = (wound < 0) & (np.asarray(depth) % 2 == 0)
    if not kept.any():
        return 0
    shell, other, _ = container_windings(volumes, nest, within)
    found = pairs_without(np.c_[shell, other], np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2))
    return len(np.unique(found[kept[found[:, 1]], 0])) if len(found) else 0


def _crossing_cavities(crossing_with: np.ndarray, depth: np.ndarray, owner: np.ndarray) -> int:
    """R4c: pairs of cavities of one body whose surfaces cross (their common volume is taken out twice by the
    summed integral; with three meeting at a point no pairwise correction is right)."""
    pairs = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    if not len(pairs):
        return 0
    odd = np.asarray(depth) % 2 == 1
    own = np.asarray(owner)
    return int(np.count_nonzero(odd[pairs[:, 0]] & odd[pairs[:, 1]] & (own[pairs[:, 0]] == own[pairs[:, 1]])))


def classify_shells(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray, n_shells: int,
                    shells: Sequence[VolumeMoments], diag: float, *, source: str = "mesh",
                    check_crossing: bool = True) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Orient shells by nesting depth (R4), attach cavities to their bodies, count overlap candidates (R5, R6).

    The same rules :func:`~.prepare.prepare_mesh` applies (:mod:`~.policy`), for callers that hold several
    prepared meshes side by side (an assembly's parts).

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
    nest = shell_nesting_or_none(vertices, faces, labels, n_shells)
    touch_within = np.zeros((0, 2), dtype=np.int64)
    if touch is not None and contacts is not None:
        touch, nest, touch_within, _ = settle_touching(vertices, faces, labels, contacts, touch, nest)
    crossing_with = touch.crossing_with if touch is not None else np.zeros((0, 2), dtype=np.int64)
    within = None
    if touch is not None and touch.complete:
        rounding = rounding_volumes(vertices, shells)
        within, crossing_with = _within(vertices, faces, labels, vols, crossing_with, rounding)
        crossing_with, touch_within, _ = _copies_nested(vols, nest, crossing_with, touch_within, rounding)
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
        candidates = boxes_meet(vertices, faces, labels, n_shells) | undecided
    return flip, owner, int(np.count_nonzero(depth % 2 == 1)), int(np.count_nonzero(candidates))


def shell_nesting_or_none(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> Nesting | None:
    """The shells' winding numbers at each other's probe points (None for one shell)."""
    if n_shells < 2:
        return None
    from .nesting import shell_nesting      # imported on use: one shell needs none
    return shell_nesting(v, f, labels, n_shells)


def _holds(nest: Nesting | None, within: np.ndarray | None, held: np.ndarray, n_shells: int) -> np.ndarray:
    """(s,) bool: shells that hold one of the shells ``held`` ((s,) bool), by the winding number of the holder at
    the held shell's probe point (``nest``) or as a ``(shell, container)`` pair of ``within`` (flush contact)."""
    out = np.zeros(n_shells, dtype=bool)
    if nest is not None:
        inside = (np.asarray(nest.winding) != 0) & held[np.asarray(nest.shell, dtype=np.int64)]
        out[np.asarray(nest.other, dtype=np.int64)[inside]] = True
    if within is not None and len(within):
        pairs = np.asarray(within, dtype=np.int64).reshape(-1, 2)
        out[pairs[held[pairs[:, 0]], 1]] = True
    return out


def _both(within: np.ndarray | None, more: np.ndarray) -> np.ndarray | None:
    """``(shell, container)`` pairs from the boolean (R4's ``within_up_to_rounding``) and from the vertices."""
    if within is None:
        return more if len(more) else None
    return np.concatenate([np.asarray(within, dtype=np.int64).reshape(-1, 2), more]).reshape(-1, 2)


#: Undecided shells probed again without their partners (crossing them, within them, holding them or touching them
#: from outside; R4), at most; beyond, they stay undecided.
MAX_REPROBED = 16


def _decide_past_partners(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int, nest: Nesting | None,
                          partners: np.ndarray) -> Nesting | None:
    """R4: shells left undecided because every probe lay on the surface of a partner, probed again with their
    partners left out.

    ``partners``: (k, 2) int shell pairs whose relation is already known from their contact: pairs that cross (a
    copy listed twice, its coordinates rounded apart), ``(shell, container)`` pairs of a shell lying within
    another up to touching, placed by the boolean or by touching vertices (a box flush inside another on
    five faces leaves the outer one undecided; not probed again, R4 reads the pair by depth, ``exact`` 0.55 m³ where
    the file's winding gives the outer box, 3.83), and pairs touching from outside (a slab flush between two boxes
    inside an inward box, its own sign deciding, is a body where every reading makes it a cavity, ``united`` 9
    cells high).  A shell's depth never counts a shell it crosses (:func:`~.policy.orient_by_depth`), a shell
    within another is none of its containers, the pair's own relation being kept by those pairs, and a shell
    touching another from outside lies outside it (its winding is 0 there); so the partners' surfaces need not be
    kept clear of.  The winding numbers of
    the other shells at the new probe are added to ``nest`` and the shell is decided.  At most
    :data:`MAX_REPROBED` shells are probed again; the others stay undecided."""
    pairs = np.asarray(partners, dtype=np.int64).reshape(-1, 2)
    if nest is None or not len(pairs) or not np.asarray(nest.undecided).any():
        return nest
    undecided = np.asarray(nest.undecided, dtype=bool).copy()
    todo = [s for s in np.flatnonzero(undecided) if np.any(pairs == s)][:MAX_REPROBED]
    if not todo:
        return nest
    from .nesting import Nesting as Found, shell_nesting
    shell, other, winding = [nest.shell], [nest.other], [nest.winding]
    probes = np.array(nest.probes, dtype=np.float64, copy=True)
    for s in todo:
        own = np.unique(np.concatenate([pairs[pairs[:, 0] == s, 1], pairs[pairs[:, 1] == s, 0]]))
        keep = ~np.isin(labels, own)
        kept = np.flatnonzero(np.bincount(labels[keep], minlength=n_shells) > 0)   # old labels, ascending
        if len(kept) < 2:
            undecided[s] = False           # nothing else to lie in: depth 0
            continue
        relabel = np.full(n_shells, -1, dtype=np.int64)
        relabel[kept] = np.arange(len(kept))
        sub = shell_nesting(v, f[keep], relabel[labels[keep]], len(kept))
        mine = int(relabel[s])
        if sub.undecided[mine]:
            continue
        rows = sub.shell == mine
        shell.append(np.full(int(np.count_nonzero(rows)), s, dtype=np.int64))
        other.append(kept[sub.other[rows]])
        winding.append(sub.winding[rows])
        probes[s] = sub.probes[mine]
        undecided[s] = False
    return Found(shell=np.concatenate(shell), other=np.concatenate(other), winding=np.concatenate(winding),
                 probes=probes, undecided=undecided)


#: Crossing shell pairs tested for lying one within the other (R4), at most; beyond, a pair stays crossing.
MAX_WITHIN_PAIRS = 256


def _within(v: np.ndarray, f: np.ndarray, labels: np.ndarray, volumes: np.ndarray,
            crossing_with: np.ndarray, rounding: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """R4: the crossing pairs whose one shell lies within the other up to rounding (``(shell, container)``), and the
    pairs that cross for real (:func:`~.policy.within_up_to_rounding`, volumes shared by manifold3d)."""
    pairs = np.asarray(crossing_with, dtype=np.int64).reshape(-1, 2)
    if not len(pairs):
        return np.zeros((0, 2), dtype=np.int64), pairs
    from .union import common_volumes            # imported on use: crossings are rare
    tested = pairs[:MAX_WITHIN_PAIRS]
    within, really = within_up_to_rounding(volumes, tested, common_volumes(v, f, labels, volumes, tested),
                                           rounding=rounding)
    return within, np.concatenate([really, pairs[MAX_WITHIN_PAIRS:]])


def shell_boxes(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> np.ndarray:
    """(s, 2, 3) float: each shell's bounding box, its lowest and highest corner (m), from its faces' corners."""
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    tri = v[f[order]]
    lo = np.minimum.reduceat(tri.min(axis=1), starts, axis=0)
    hi = np.maximum.reduceat(tri.max(axis=1), starts, axis=0)
    return np.stack([lo, hi], axis=1)


def boxes_meet(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> np.ndarray:
    """(s,) bool: shells whose bounding box meets another shell's."""
    box = shell_boxes(v, f, labels, n_shells)
    lo, hi = box[:, 0], box[:, 1]
    meet = np.all(lo[:, None] <= hi[None], axis=2) & np.all(lo[None] <= hi[:, None], axis=2)
    np.fill_diagonal(meet, False)
    return np.asarray(meet.any(axis=1))
