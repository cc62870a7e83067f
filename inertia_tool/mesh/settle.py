"""Where the shells of a closed surface meet: the exact face-pair contacts (:func:`~.intersect.surface_contacts`),
folds that enclose nothing taken out (R3a), and touching shells settled by their vertices (R4).

:func:`find_contacts` is the stage :func:`~.prepare.prepare_mesh` runs after the shells are found;
:func:`settle_touching` is the part of R4 that :mod:`~.classify` applies to shells that touch.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import MeshResolvedWarning
from .checks import shell_labels
from .edges import unique_rows
from .intersect import SurfaceContacts, surface_contacts
from .nonmanifold import WeldedBodies, welded_bodies
from .policy import ShellContacts, touching_relations
from .shells import Shells, drop_flat, measured

if TYPE_CHECKING:       # imported on use at run time (below)
    from .folds import Folds
    from .nesting import Nesting

__all__ = ["FoundContacts", "find_contacts", "settle_touching", "outside_patches", "MAX_TOUCHING_PAIRS"]


class FoundContacts(NamedTuple):
    """What :func:`find_contacts` found.

    Attributes
    ----------
    shells : Shells
        The shells, after any folds were taken out (R3a).
    contacts : SurfaceContacts
        Their face pairs that meet beyond what they share by index (with the edges where bodies are welded, R1b;
        without the crossings of a repair patch).
    folds : Folds or None
        The folds taken out (R3a), or None.
    patch_notes : tuple of str
        How many crossings of repair patches were set aside (a patched surface only).
    """

    shells: Shells
    contacts: SurfaceContacts
    folds: Folds | None
    patch_notes: tuple[str, ...]


def find_contacts(shells: Shells, *, welded: WeldedBodies | None, patched: bool, split_welded: bool, n_read: int,
                  diag: float, source: str) -> FoundContacts:
    """The face pairs of ``shells`` that meet, with R3a applied (an unpatched surface) or the patches' crossings
    set aside (a patched one: they lie within the patches' doubt, which the estimate's bound carries).

    Parameters
    ----------
    shells : Shells
    welded : WeldedBodies or None
        R1b's bodies of ``shells`` (their welded edges count as contacts), or None.
    patched : bool
        The surface was patched (``repair``); faces with a vertex index from ``n_read`` on are the patches'.
    split_welded : bool
        R1b applies (again, after R3a).
    n_read : int
        Vertices read from the file.
    diag : float
        m, R2's scale.
    source : str
        Names the mesh in messages.
    """
    contacts = surface_contacts(shells.vertices, shells.faces)
    if welded is not None and len(welded.contact):      # R1b: bodies welded along an edge meet there (R4 decides)
        contacts = _with_welded(contacts, welded)
    folds = None
    if not patched and (len(contacts.crossing) or len(contacts.coplanar_opposite)):                      # R3a
        shells, contacts, folds = _take_out_folds(shells, contacts, split_welded, diag, source)
    patch_notes: tuple[str, ...] = ()
    if patched:
        contacts, patch_notes = outside_patches(contacts, shells.faces, n_read)
    return FoundContacts(shells, contacts, folds, patch_notes)


def _with_welded(contacts: SurfaceContacts, welded: WeldedBodies) -> SurfaceContacts:
    """``contacts`` with the face pairs where R1b's bodies are welded along an edge added to its contacts."""
    return dataclasses.replace(contacts, contact=np.concatenate(
        [np.asarray(contacts.contact, dtype=np.int64).reshape(-1, 2), welded.contact]))


def _take_out_folds(shells: Shells, contacts: SurfaceContacts, split_welded: bool, diag: float,
                    source: str) -> tuple[Shells, SurfaceContacts, Folds | None]:
    """R3a: sliver fans and internal walls taken out (:func:`~.folds.settle_folds`) and the stages after R1 run
    again on what is left; everything unchanged when there are none or they cannot be shown to enclose nothing.

    Returns the shells, their contacts and the folds (None when unchanged)."""
    from .folds import settle_folds        # imported on use: only surfaces with flagged face pairs
    v = shells.vertices
    folds = settle_folds(v, shells.faces, contacts)          # R1 shells: a wall's sheets may lie in two R1b bodies
    if folds is None:
        return shells, contacts, None
    f = folds.faces
    labels, n_shells = shell_labels(f, len(v))                                  # R1
    welded = welded_bodies(f, len(v), labels, n_shells, v) if split_welded and n_shells else None
    if welded is not None and welded.split:                                     # R1b
        labels, n_shells = welded.labels, welded.n_shells
    m = len(f)
    shells, _ = drop_flat(measured(v, f, labels, n_shells), diag, source, warn=False)
    f, labels, n_shells = shells.faces, shells.labels, shells.n_shells
    contacts = folds.contacts if len(f) == m else surface_contacts(v, f)
    if welded is not None and len(f) != m:                # R2 relabelled: the welded contacts anew
        welded = welded_bodies(f, len(v), labels, n_shells, v)
    if welded is not None:                 # R1b: bodies welded along an edge still meet there (R4 decides)
        if len(welded.contact):
            contacts = _with_welded(contacts, welded)
    warnings.warn(MeshResolvedWarning(f"{source}: {folds.describe()}"), stacklevel=5)
    return shells, contacts, folds


def outside_patches(contacts: SurfaceContacts, faces: np.ndarray,
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


#: Touching shell pairs whose vertices are tested against each other (R4), at most; beyond, the pairs go to the
#: boolean like crossing ones.
MAX_TOUCHING_PAIRS = 512


def settle_touching(v: np.ndarray, f: np.ndarray, labels: np.ndarray, contacts: SurfaceContacts,
                    touch: ShellContacts, nest: Nesting | None
                    ) -> tuple[ShellContacts, Nesting | None, np.ndarray, np.ndarray]:
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
    apart : (k, 2) int
        Pairs that touch from outside, found by the vertices (neither holds the other).
    """
    none = np.zeros((0, 2), dtype=np.int64)
    if nest is None or not touch.complete:
        return touch, nest, none, none
    faces_touching = np.concatenate([np.asarray(contacts.coplanar_opposite, dtype=np.int64).reshape(-1, 2),
                                     np.asarray(contacts.contact, dtype=np.int64).reshape(-1, 2)])
    faces_touching = faces_touching[labels[faces_touching[:, 0]] != labels[faces_touching[:, 1]]]
    if not len(faces_touching):
        return touch, nest, none, none
    pairs = unique_rows(np.sort(labels[faces_touching], axis=1))
    n = len(touch.crossing)
    crossed = np.zeros((n, n), dtype=bool)
    cw = np.asarray(touch.crossing_with, dtype=np.int64).reshape(-1, 2)
    crossed[cw[:, 0], cw[:, 1]] = True
    pairs = pairs[~crossed[pairs[:, 0], pairs[:, 1]]]
    if not len(pairs):
        return touch, nest, none, none
    from .nesting import touching_sides      # imported on use: touching shells are rare
    tested, beyond = pairs[:MAX_TOUCHING_PAIRS], pairs[MAX_TOUCHING_PAIRS:]
    sides = touching_sides(v, f, labels, tested, faces_touching)
    found = touching_relations(sides.pairs, sides.inside, sides.outside)
    if len(found.crossing):
        crossing = touch.crossing.copy()
        crossing[found.crossing.reshape(-1)] = True
        touch = dataclasses.replace(touch, crossing=crossing)
    more = np.concatenate([cw, found.crossing, found.unknown, beyond]).reshape(-1, 2)
    touch = dataclasses.replace(touch, crossing_with=unique_rows(np.sort(more, axis=1)))
    decided = np.concatenate([found.within, found.apart]).reshape(-1, 2)
    if len(decided):
        drop = np.zeros((n, n), dtype=bool)
        drop[decided[:, 0], decided[:, 1]] = drop[decided[:, 1], decided[:, 0]] = True
        keep = ~drop[nest.shell, nest.other]
        nest = dataclasses.replace(nest, shell=nest.shell[keep], other=nest.other[keep], winding=nest.winding[keep])
    return touch, nest, found.within, np.asarray(found.apart, dtype=np.int64).reshape(-1, 2)
