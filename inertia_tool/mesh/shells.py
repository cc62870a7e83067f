"""The shells of a closed surface and their moments: rules R0 (copies), R1 and R1b (shells, bodies welded along
their crossing), R2 (shells enclosing no volume) and R7 (round-off) of :mod:`~.policy`.

:func:`find_shells` is the stage :func:`~.prepare.prepare_mesh` runs once the surface is closed; the helpers are
the steps the later stages repeat on a surface they changed (:func:`reshelled`: R1, R7 and R2 again).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from ..errors import InsideOutWarning, InvalidMeshError, MeshResolvedWarning
from ..integrals import RoundoffBound, VolumeMoments, accurate_shells, body_volume_moments
from ..tolerances import FLAT_RTOL
from .checks import shell_labels
from .multiplicity import coincident_surfaces, face_keys, shell_multiplicity
from .nonmanifold import welded_bodies
from .policy import (NearCopies, coincident_message, copy_candidates, near_copies, near_copies_message,
                     negligible_flat, part_size)

__all__ = ["Shells", "FoundShells", "find_shells", "bodies", "measured", "reshelled", "drop_flat", "flat_pieces",
           "apply_flips", "leave_out_coincident", "total", "counted"]


class Shells(NamedTuple):
    """A closed surface split into shells, with each shell's moments.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes.
    faces : (m, 3) int
    labels : (m,) int
        Shell of each face.
    n_shells : int
    moments : list of VolumeMoments
        Per-shell unit-density moments (cavities negative once oriented).
    bound : RoundoffBound
        The round-off bound of each shell's ``moments`` (R7).
    """

    vertices: np.ndarray
    faces: np.ndarray
    labels: np.ndarray
    n_shells: int
    moments: list[VolumeMoments]
    bound: RoundoffBound


class FoundShells(NamedTuple):
    """What :func:`find_shells` found.

    Attributes
    ----------
    shells : Shells
    coincident : tuple of str
        R0's notes (shells listed twice, or twice up to rounding), each warned.
    dropped : str or None
        R2's note (closed shells enclosing no volume left out), warned.
    repeated : (keys, counts) or None
        The faces R0 kept in place of their repeats (:func:`~.multiplicity.face_keys`) and how many times each
        counts in the winding number (:func:`~.multiplicity.shell_multiplicity` reads it).
    """

    shells: Shells
    coincident: tuple[str, ...]
    dropped: str | None
    repeated: tuple[np.ndarray, np.ndarray] | None = None


def find_shells(vertices: np.ndarray, faces: np.ndarray, *, split_welded: bool, known: tuple[np.ndarray, int] | None,
                centre: np.ndarray | None, diag: float, source: str) -> FoundShells:
    """R1 and R1b (shells, welded bodies split), R0 (a shell listed twice, exactly or up to rounding, left out once),
    R7 (moments within their round-off bound) and R2 (shells enclosing no volume left out), in that order.

    Parameters
    ----------
    vertices, faces : (n, 3) float, (m, 3) int
        A closed surface (m).
    split_welded : bool
        Apply R1b (the surface has non-manifold edges and is not patched).
    known : (labels, n_shells) or None
        The shell labels of ``faces`` if already taken (with the edge census).
    centre : (3,) float or None
        The point to integrate about (the bounding-box centre of ``vertices``, computed again when None).
    diag : float
        m, the bounding-box diagonal of the mesh as read (R2's scale).
    source : str
        Names the mesh in messages.

    Raises
    ------
    InvalidMeshError
        No triangle is left, or every shell encloses no volume.
    """
    v, f = vertices, faces
    labels, n_shells = bodies(v, f, split_welded, known)                            # R1, R1b
    if n_shells == 0:
        raise InvalidMeshError(f"{source}: no triangles are left after removing degenerate ones")
    moments = body_volume_moments(v, f, labels, n_shells, origin=centre)
    notes: list[str] = []
    twins = _twin_candidates(moments, labels)
    repeated = None
    if twins is not None:                     # R0: a shell listed twice with its own vertices
        f, note, repeated = leave_out_coincident(v, f, twins, source, labels)
        if note is not None:
            notes.append(note)
            labels, n_shells = bodies(v, f, split_welded)
            moments = body_volume_moments(v, f, labels, n_shells, origin=centre)
        near = near_copies(v, f, labels, moments)                                   # R0 up to rounding
        if near.copies:
            repeated = _with_near_copies(v, f, labels, near, repeated)
            f = f[~near.drop]
            notes.append(near_copies_message(near))
            warnings.warn(MeshResolvedWarning(f"{source}: {notes[-1]}"), stacklevel=4)
            labels, n_shells = bodies(v, f, split_welded)
            moments = body_volume_moments(v, f, labels, n_shells, origin=centre)
    moments, bound = accurate(v, f, labels, moments, centre)    # R7: signs and moments within the round-off bound
    shells, dropped = drop_flat(Shells(v, f, labels, n_shells, moments, bound), diag, source, stacklevel=5)   # R2
    return FoundShells(shells, tuple(notes), dropped, repeated)


def _with_near_copies(v: np.ndarray, f: np.ndarray, labels: np.ndarray, near: NearCopies,
                      repeated: tuple[np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, np.ndarray] | None:
    """R0's record of repeats (:func:`leave_out_coincident`'s third item) with the copies up to rounding added: a
    shell whose ``j`` copies rounded apart were left out counts ``j`` times more, as ``j`` exact repeats would (its
    faces' count in ``repeated``, 1 where absent, plus ``j``).  Review19 (seed 2603 case 1422): a ball listed twice
    exactly round a cavity listed twice rounded apart counted 2 and 1, so the file's winding (0 inside the cavity)
    was read as 1 there and the cavity left out, 2.1 % heavy and certified ``exact``."""
    times = near.times
    if times is None or not times.any():
        return repeated
    keep = ~near.drop & (times[labels] > 0)
    keys = face_keys(v, f[keep])
    extra = times[labels[keep]]
    if repeated is None:
        return keys, 1 + extra
    old_keys, old_count = repeated
    both = np.concatenate([np.asarray(old_keys, dtype=np.float64).reshape(-1, 9), keys])
    unique, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    # each record says how many times more than once its face counts; a face in both adds the two
    more = np.concatenate([np.asarray(old_count, dtype=np.int64) - 1, extra])
    count = np.ones(len(unique), dtype=np.int64)
    np.add.at(count, inverse, more)
    return unique, count


def bodies(v: np.ndarray, f: np.ndarray, split_welded: bool,
           known: tuple[np.ndarray, int] | None = None) -> tuple[np.ndarray, int]:
    """R1 (edge-connected shells) and, on a surface with non-manifold edges, R1b (bodies welded along their
    crossing split apart, :func:`~.nonmanifold.welded_bodies`).  ``known``: the shell labels of ``f`` if already
    taken (with the edge census)."""
    labels, n_shells = known if known is not None else shell_labels(f, len(v))
    if split_welded and n_shells:
        welded = welded_bodies(f, len(v), labels, n_shells, v)
        if welded.split:
            return welded.labels, welded.n_shells
    return labels, n_shells


def accurate(v: np.ndarray, f: np.ndarray, labels: np.ndarray, shells: list[VolumeMoments],
             origin: np.ndarray | None = None) -> tuple[list[VolumeMoments], RoundoffBound]:
    """R7: the shells with their round-off bounded (:func:`~inertia_tool.integrals.accurate_shells`: a sliver
    thinner than its coordinates' rounding integrated exactly, so that even its sign is right), and each shell's
    round-off bound.  ``origin``: the point ``shells`` were integrated about (default the vertices' bounding-box
    centre, computed again)."""
    better, _, bound = accurate_shells(v, f, labels, list(shells), origin)
    return better, bound


def measured(v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> Shells:
    """The shells ``labels`` names, with their moments integrated and their round-off bounded (R7)."""
    moments, bound = accurate(v, f, labels, body_volume_moments(v, f, labels, n_shells))
    return Shells(v, f, labels, n_shells, moments, bound)


def reshelled(v: np.ndarray, f: np.ndarray, diag: float, source: str) -> Shells:
    """R1, R7 and R2 again on a surface a later stage made (an arrangement, a union): the edge-connected shells,
    their moments, and those enclosing no volume left out without a warning (the stage says what it did)."""
    labels, n_shells = shell_labels(f, len(v))
    shells, _ = drop_flat(measured(v, f, labels, n_shells), diag, source, warn=False)
    return shells


def _twin_candidates(shells: Sequence[VolumeMoments], labels: np.ndarray) -> np.ndarray | None:
    """(m,) bool: faces of shells that could be copies of another (R0, :func:`~.policy.copy_candidates`), or None
    when no two shells could be."""
    first, second = copy_candidates(shells, labels)
    if not len(first):
        return None
    shell = np.zeros(len(shells), dtype=bool)
    shell[first] = shell[second] = True
    return np.asarray(shell[labels])


def leave_out_coincident(v: np.ndarray, f: np.ndarray, among: np.ndarray | None, source: str,
                         labels: np.ndarray | None = None
                         ) -> tuple[np.ndarray, str | None, tuple[np.ndarray, np.ndarray] | None]:
    """R0: the faces without the later copy of each shell listed twice and without shells cancelled by their exact
    inverted copy, with the note (warned); refused when nothing is left.  Called by a stage of
    :func:`~.prepare.prepare_mesh` (the warning names the latter's caller's caller).  The third item: the faces
    kept in place of repeats that count more than once in the winding number, as ``(face_keys (r, 9), counts
    (r,))``, or None (R0 counts a shell listed ``k`` times ``k`` times: :func:`~.multiplicity.shell_multiplicity`)."""
    found = coincident_surfaces(v, f, among, labels)
    if not found.drop.any():
        return f, None, None
    if found.drop.all():
        raise InvalidMeshError(f"{source}: the mesh is a closed surface listed together with its exact inverted copy "
                               f"({len(f) // 2:,} faces each, same corners, opposite winding): they cancel to "
                               "nothing (winding number 0 everywhere, no volume); remove one copy, or reverse it "
                               "if the surface was meant twice")
    note = coincident_message(found, part_size(v, f))
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=5)
    many = found.multiplicity > 1
    repeated = (face_keys(v, f[many]), found.multiplicity[many]) if many.any() else None
    return f[~found.drop], note, repeated


def counted(shells: Shells, *repeated: tuple[np.ndarray, np.ndarray] | None) -> np.ndarray | None:
    """R0: how many times each of ``shells`` was listed, from the records of :func:`leave_out_coincident` (by vertex
    index when the surface was closed, with their own vertices here), or None when every shell counts once or all
    count alike (:func:`~.multiplicity.shell_multiplicity`).  A face in both records counts by the larger."""
    found = [r for r in repeated if r is not None]
    if not found:
        return None
    keys = np.concatenate([r[0] for r in found])
    times = np.concatenate([r[1] for r in found])
    return shell_multiplicity(shells.vertices, shells.faces, shells.labels, shells.n_shells, (keys, times))


def drop_flat(shells: Shells, diag: float, source: str, *, warn: bool = True,
              stacklevel: int = 5) -> tuple[Shells, str | None]:
    """R2: leave out closed shells that enclose no volume; refuse when nothing else is left.  The shells' moments
    and round-off bound (R7) are computed anew when some are left out.  Returns the shells and the note (warned
    when ``warn``, at ``stacklevel``), or None when nothing was left out.

    The flat shells are :func:`flat_pieces`'s (R2's rule, written once: the repair's estimate and the union's
    pieces are judged by it too); one is left out only when that changes the rest's moments by no more than
    round-off (:func:`~.policy.negligible_flat`)."""
    v, f, labels, n_shells, moments, bound = shells
    flat = flat_pieces([s.volume for s in moments], [s.area for s in moments], v, diag, lambda: bound.volume)
    if not flat.any():
        return shells, None
    if flat.all():
        what = "the mesh encloses" if n_shells == 1 else f"all {n_shells} shells enclose"
        raise InvalidMeshError(f"{source}: {what} no volume (flat or collapsed surface); for a sheet or a "
                               "thin-walled part use the shell model with a wall `thickness`")
    flat &= negligible_flat(moments, flat)        # a thin but real solid whose moments count stays
    if not flat.any():
        return shells, None
    dropped_faces = int(np.count_nonzero(flat[labels]))
    f = f[~flat[labels]]
    labels, n_shells = shell_labels(f, len(v))
    n_flat = int(np.count_nonzero(flat))
    note = (f"{n_flat} closed piece{'s' if n_flat > 1 else ''} enclosing no volume ({dropped_faces:,} faces: "
            "zero-thickness walls, coincident opposite faces or flat slivers) left out; they contribute nothing "
            "to the integrals")
    kept = measured(v, f, labels, n_shells)
    if warn:
        warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=stacklevel)
    return kept, note


def flat_pieces(volumes: Sequence[float] | np.ndarray, areas: Sequence[float] | np.ndarray, vertices: np.ndarray,
                diag: float, roundoff: Callable[[], Sequence[float] | np.ndarray]) -> np.ndarray:
    """R2's rule: which closed pieces enclose no volume, (k,) bool.  ``volumes`` (m³, signed) and ``areas`` (m²)
    of the pieces, ``vertices`` (n, 3) m the corners they are made of, ``diag`` the mesh's diagonal (m);
    ``roundoff()`` (k,) m³ the float64 round-off bound of each piece's summed volume (R7,
    :func:`~inertia_tool.integrals.roundoff_bounds`), called only when the scale alone does not decide.

    A piece is flat when ``|V| ≤ FLAT_RTOL · diag³`` while some piece exceeds that: beside a solid such a piece
    is a face and its reverse, a zero-thickness wall or a collapsed sliver (the caller decides whether leaving it
    out is negligible).  When every piece is at most ``FLAT_RTOL · diag³`` the scale says nothing (a needle
    1 µm × 1 µm × 1 m encloses 1e-12 m³ = ``FLAT_RTOL · diag³``, its volume known to 1e-16 of itself: review 12's
    R7), and a piece is flat only when its volume is within its own round-off budget ``b + √3 δ A``: ``b`` from
    ``roundoff()`` and ``√3 δ A`` what rounding the corners of a flat surface of area ``A`` to float64 can
    enclose (``δ`` half the float64 spacing at the largest coordinate; moving each corner by at most ``√3 δ``
    moves a closed surface's volume by at most that times its area, to first order).  Whatever the aspect ratio,
    the mesh as a whole is called flat only when every piece is flat up to rounding."""
    volume = np.abs(np.asarray(volumes, dtype=np.float64)).reshape(-1)
    flat = volume <= FLAT_RTOL * diag ** 3
    if not flat.all():
        return flat
    v = np.asarray(vertices, dtype=np.float64)
    delta = 0.5 * float(np.spacing(np.max(np.abs(v)))) if v.size else 0.0
    budget = np.asarray(roundoff(), dtype=np.float64).reshape(-1) + \
        np.sqrt(3.0) * delta * np.asarray(areas, dtype=np.float64).reshape(-1)
    return np.asarray(~(volume > budget), dtype=bool)


def apply_flips(shells: Shells, flip: np.ndarray, source: str, *, warn: bool = True) -> Shells:
    """Turn the shells marked by R4, with an :class:`InsideOutWarning` naming how many (called by a stage of
    :func:`~.prepare.prepare_mesh`)."""
    if not flip.any():
        return shells
    v, f, labels, n_shells, moments, bound = shells
    face_flip = flip[labels]
    f = f.copy()
    f[face_flip] = f[face_flip][:, ::-1]
    moments = [VolumeMoments(-s.volume, s.centroid, -s.second_moment, s.area, s.zero_area_faces) if flip[k] else s
               for k, s in enumerate(moments)]
    if warn:
        warnings.warn(InsideOutWarning(f"{source}: {flipped_text(int(np.count_nonzero(flip)), n_shells)}"),
                      stacklevel=5)
    return Shells(v, f, labels, n_shells, moments, bound)


def flipped_text(n_flipped: int, n_shells: int) -> str:
    """R4's words for shells turned for their nesting depth (the start of its warning)."""
    what = "the mesh is" if n_shells == 1 or n_flipped == n_shells else f"{n_flipped} of {n_shells} shells are"
    return f"{what} inside out for its nesting depth (a body wound inward or a cavity outward); flipped"


def total(shells: Sequence[VolumeMoments]) -> VolumeMoments:
    """The moments of all shells together (cavities negative): volume, centroid, central second moment."""
    volume = sum(s.volume for s in shells)
    centroid = np.asarray(sum(s.volume * s.centroid for s in shells), dtype=np.float64) / volume
    second = np.asarray(sum(s.second_moment + s.volume * np.outer(s.centroid - centroid, s.centroid - centroid)
                            for s in shells), dtype=np.float64)
    return VolumeMoments(volume=volume, centroid=centroid, second_moment=second, area=sum(s.area for s in shells))
