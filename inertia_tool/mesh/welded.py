"""R1b of :mod:`~.policy`: bodies welded along their crossing (a shell with non-manifold edges) split apart, and
where coplanar faces of two bodies facing the same way make the split undefined, the shells replaced by the
boundary of their solid {winding number ≥ 1} (:mod:`~.coplanar`), or refused, or estimated (``repair``).

:func:`settle_welded` is the stage :func:`~.prepare.prepare_mesh` runs after the shells are found.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import ArrangementError, InvalidMeshError, MeshRepairedWarning, MeshResolvedWarning
from ..integrals import volume_moments
from .nonmanifold import WeldedBodies, welded_bodies
from .resolve import Resolution, resolve_surface
from .shells import Shells, measured, reshelled

if TYPE_CHECKING:
    from .coplanar import CoplanarArrangement
    from .precision import RoundedRegion

__all__ = ["SettledWelded", "settle_welded"]


class SettledWelded(NamedTuple):
    """What :func:`settle_welded` made of the shells.

    Attributes
    ----------
    shells : Shells
        With welded bodies split (or arranged).
    welded : WeldedBodies or None
        R1b's bodies of ``shells`` (None when R1b does not apply).
    arranged : str or None
        The note of the arrangement of welded coplanar bodies (warned), or None.
    forced : Resolution or None
        The estimate that replaces the result when the bodies could not be split (``repair``), else None.
    region : RoundedRegion or None
        Where rounding the overlay's new points may change the result (:class:`~.precision.RoundedRegion`, judged
        by R7 against the final solid); None when no point was rounded.
    """

    shells: Shells
    welded: WeldedBodies | None
    arranged: str | None
    forced: Resolution | None
    region: RoundedRegion | None = None


def settle_welded(shells: Shells, *, split_welded: bool, overlap: str, repair: bool, diag: float,
                  source: str) -> SettledWelded:
    """R1b (again: R2 relabels) on ``shells`` when ``split_welded`` (``overlap`` and ``repair`` as for
    :func:`~.prepare.prepare_mesh`; ``diag``: m, R2's scale).

    Raises
    ------
    InvalidMeshError
        Welded bodies that cannot be split (and ``repair`` is off).
    """
    if not split_welded:
        return SettledWelded(shells, None, None, None)
    v, f, given, n_shells = shells.vertices, shells.faces, shells.labels, shells.n_shells
    welded = welded_bodies(f, len(v), given, n_shells, v)     # ``welded.ambiguous_shells`` indexes ``given``
    if welded.split:
        shells = measured(v, f, welded.labels, welded.n_shells)
    arranged, failed, region = None, "", None
    if welded.ambiguous and overlap == "union" and welded.ambiguous_shells is not None:   # R1b: {w ≥ 1}
        try:
            shells, arranged, region = _arrange_welded(v, f, given, welded.ambiguous_shells, diag, source)
            # R1b on the new surface: the other shells' welded bodies are split again (R1 joined them)
            welded = welded_bodies(shells.faces, len(shells.vertices), shells.labels, shells.n_shells,
                                   shells.vertices)
            if welded.ambiguous:
                raise ArrangementError("its result still has welded bodies whose faces cannot be paired")
            if welded.split:
                shells = measured(shells.vertices, shells.faces, welded.labels, welded.n_shells)
        except ArrangementError as exc:
            failed = f"; its solid {{winding number ≥ 1}} could not be built: {exc}"
            arranged, region = None, None
    if welded.ambiguous:                # R1b: coplanar faces of two bodies facing the same way
        n_amb = welded.ambiguous
        reason = (f"{n_amb} shell{'s' if n_amb > 1 else ''} with non-manifold edges where coplanar faces of two "
                  "bodies facing the same way meet could not be split into closed bodies (which faces close "
                  "which body is undefined there); the bodies overlap, and the summed integral would count "
                  "their common volume twice" + failed)
        if not repair:
            raise InvalidMeshError(f"{source}: {reason}; `repair=True` gives a bounded estimate of the solid "
                                   "{winding number ≥ 1}")
        forced = resolve_surface(shells.vertices, shells.faces, diag=diag, source=source, repair=True,
                                 merge_tolerance=0.0, moments=volume_moments, force_estimate=True, reason=reason)
        warnings.warn(MeshRepairedWarning(f"{source}: repaired ({forced.method}, an estimate): "
                                          f"{'; '.join(forced.notes)}"), stacklevel=4)
        return SettledWelded(shells, welded, None, forced)
    return SettledWelded(shells, welded, arranged, None, region)


def _arrange_welded(v: np.ndarray, f: np.ndarray, labels: np.ndarray, chosen: np.ndarray, diag: float,
                    source: str) -> tuple[Shells, str, RoundedRegion | None]:
    """R1b: the shells whose welded bodies could not be split replaced by the boundary of their {winding number
    ≥ 1} (:mod:`~.coplanar`), then R1 and R2 again on the new surface.

    Returns the new shells, the note (warned) and where the overlay's points were rounded; raises ArrangementError
    (the result must not cross itself, as R7 needs)."""
    from .coplanar import arrange_coplanar_shells      # imported on use: welded coplanar bodies are rare
    v, f, done = arrange_coplanar_shells(v, f, chosen[labels])
    if done.crossings_left:
        raise ArrangementError(f"{done.crossings_left:,} face pairs of the result cross after rounding the overlay's "
                               "points to float64")
    shells = reshelled(v, f, diag, source)
    note = _arranged_note(done)
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=5)
    return shells, note, done.region


def _arranged_note(done: CoplanarArrangement) -> str:
    """The note of R1b's arrangement, counting what was done: the faces taken out as zero chains (a face with its
    reverse, or coplanar patches that cancel, :func:`~.coplanar._zero_chains`), then the overlay of the faces still
    overlapping in a common plane; where none were left, no overlay ran and no face was split (the surface left is
    integrated as it stands), so no pair or plane is counted (review19: "0 face pairs in 0 planes" after a weld)."""
    n_out = done.cancelled_faces
    out = (f"{n_out:,} face{'s' if n_out != 1 else ''} taken out as zero chains (a face listed with its reverse, or "
           "coplanar patches whose boundaries are each other's reverse: nothing in any integral)")
    if not done.coplanar_pairs:
        what = f"{out}; no faces overlap after that, the rest integrated as it stands (no face split)" if n_out \
            else "no faces overlap, the surface integrated as it stands (no face split)"
        return f"non-manifold edges where faces lie in a common plane (R1b): {what}"
    first = f"; {out} first" if n_out else ""
    return (f"bodies welded along edges where faces overlap in a common plane ({done.coplanar_pairs:,} face pairs "
            f"in {done.planes:,} plane{'s' if done.planes != 1 else ''}{first}): the faces bounding the region of "
            "winding number ≥ 1 kept, split along each other's edges (the common volume counts once)")
