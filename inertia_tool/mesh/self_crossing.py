"""R3 of :mod:`~.policy`: a shell that passes through itself.  Replaced by the boundary of its solid {winding
number ≥ 1} (:mod:`~.arrange`), integrated as it stands and certified ``unverified`` (``self_crossing``
"unverified"), refused, or estimated (``repair``).

:func:`settle_self_crossing` is the stage :func:`~.prepare.prepare_mesh` runs once the contacts are known.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import (ArrangementError, InternalInvariantError, InvalidMeshError, MeshRepairedWarning,
                      MeshResolvedWarning)
from ..integrals import volume_moments
from .intersect import SurfaceContacts, surface_contacts
from .policy import ShellContacts, self_crossing_message, shell_contacts
from .precision import RoundedRegion, combined_regions
from .resolve import Resolution, resolve_surface
from .shells import Shells, reshelled

if TYPE_CHECKING:       # imported on use at run time (below)
    from .uncertainty import Estimate

__all__ = ["SettledCrossing", "settle_self_crossing"]


class SettledCrossing(NamedTuple):
    """What :func:`settle_self_crossing` made of the shells.

    Attributes
    ----------
    shells : Shells
        Arranged where a shell passed through itself.
    contacts : SurfaceContacts
        Their face pairs that meet.
    touch : ShellContacts
        Those pairs by shell (crossings left by rounding an arrangement's points taken out).
    arranged : str or None
        The note of the last arrangement made (R3 here, else R1b's passed in), or None.
    verified : bool
        No crossing was left by rounding the arrangement's points (meaningful when ``arranged`` is set).
    unverified : str or None
        The note when a self-crossing surface is integrated as it stands (``self_crossing`` "unverified").
    forced : Resolution or None
        The estimate that replaces the result (``repair``), else None.
    region : RoundedRegion or None
        Where rounding the new points of the arrangements made (R1b's passed in, then R3's) may change the result
        (:class:`~.precision.RoundedRegion`, judged by R7 against the final solid); None when no point was rounded.
    """

    shells: Shells
    contacts: SurfaceContacts
    touch: ShellContacts
    arranged: str | None
    verified: bool
    unverified: str | None
    forced: Resolution | None
    region: RoundedRegion | None = None


def settle_self_crossing(shells: Shells, contacts: SurfaceContacts, *, arranged: str | None, self_crossing: str,
                         overlap: str, repair: bool, patched: Estimate | None, diag: float,
                         source: str, region: RoundedRegion | None = None) -> SettledCrossing:
    """R3 on ``shells`` and their ``contacts`` (``self_crossing``, ``overlap`` and ``repair`` as for
    :func:`~.prepare.prepare_mesh`; ``arranged``: the note of R1b's arrangement, if one was made; ``patched``: the
    estimate of a patched surface, whose crossings are not arranged and whose doubt an estimate carries on;
    ``region``: where R1b's arrangement rounded its points, carried on with R3's).

    Raises
    ------
    InvalidMeshError
        A shell passes through itself (``self_crossing`` "refuse", ``repair`` off) and could not be arranged.
    """
    touch = shell_contacts(contacts, shells.labels, shells.n_shells)
    arrange_failed, verified = "", arranged is not None
    if touch.self_crossing.any() and self_crossing == "refuse" and overlap == "union" and patched is None:   # R3
        try:
            before = arranged
            shells, contacts, touch, arranged, verified, made = _arrange_self_crossing(shells, contacts, diag,
                                                                                        source)
            region = combined_regions(region, made)
            if before is not None:               # R1b's note stays: both arrangements reach the report
                arranged = f"{before}; then {arranged}"
        except ArrangementError as exc:
            arrange_failed = f"; its solid {{winding number ≥ 1}} could not be built: {exc}"
    if touch.self_crossing.any() and self_crossing == "unverified" and not repair:
        note = (f"the surface passes through itself at {touch.self_crossing_pairs:,} face pairs: "
                "integrated as it stands (a crossed region counts twice), not verified")
        warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=4)
        return SettledCrossing(shells, contacts, touch, arranged, verified, note, None, region)
    if touch.self_crossing.any():                                                 # R3
        v, f = shells.vertices, shells.faces
        message = self_crossing_message(source, touch, v, f, contacts.crossing, shells.labels) + arrange_failed
        if not repair:
            raise InvalidMeshError(message, details={"self_crossing_face_pairs": touch.self_crossing_pairs})
        # the patches' doubt is added to the grid's below: a grid that already shows the sum refused is not refined
        # (issue 23: ALOHA's gripper_prop, 12 s for a refusal)
        forced = resolve_surface(v, f, diag=diag, source=source, repair=True, merge_tolerance=0.0,
                                 moments=volume_moments, force_estimate=True,
                                 reason=f"the surface passes through itself at {touch.self_crossing_pairs:,} "
                                        f"face pairs{arrange_failed}",
                                 added_doubt=patched.uncertainty.volume_in_doubt if patched is not None else 0.0)
        if patched is not None:
            forced = with_patch_doubt(forced, patched, source)
        warnings.warn(MeshRepairedWarning(f"{source}: repaired ({forced.method}, an estimate): "
                                          f"{'; '.join(forced.notes)}"), stacklevel=4)
        return SettledCrossing(shells, contacts, touch, arranged, verified, None, forced, region)
    return SettledCrossing(shells, contacts, touch, arranged, verified, None, None, region)


def _arrange_self_crossing(shells: Shells, contacts: SurfaceContacts, diag: float,
                           source: str) -> tuple[Shells, SurfaceContacts, ShellContacts, str, bool,
                                                 RoundedRegion | None]:
    """R3: every shell passing through itself replaced by the boundary of its {winding number ≥ 1}
    (:mod:`~.arrange`), then the stages after R1 run again on the new surface.

    Returns ``(shells, contacts, touch, note, verified, region)`` (``region``: where the new points' rounding may
    change the result, :class:`~.precision.RoundedRegion`); raises ArrangementError.
    Crossings left by rounding the new points (``verified`` False) are taken out of ``touch`` (the result is
    then certified ``unverified``)."""
    from .arrange import arrange_shells      # imported on use: self-crossing shells are rare
    done = arrange_shells(shells.vertices, shells.faces, shells.labels, contacts.crossing)
    shells = reshelled(done.vertices, done.faces, diag, source)
    contacts = surface_contacts(shells.vertices, shells.faces)
    touch = shell_contacts(contacts, shells.labels, shells.n_shells)
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
    warnings.warn(MeshResolvedWarning(f"{source}: {note}"), stacklevel=5)
    return shells, contacts, touch, note, not done.crossings_left, done.region


def with_patch_doubt(forced: Resolution, patched: Estimate, source: str) -> Resolution:
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
    if est is None:
        raise InternalInvariantError(f"{source}: the forced winding-number resolution was expected to carry its "
                                     f"estimate; found none (method {forced.method!r})")
    doubt = est.uncertainty.volume_in_doubt + patched.uncertainty.volume_in_doubt
    far = max(est.far, patched.far + float(np.linalg.norm(np.asarray(est.centroid) - patched.centroid)))
    unc = uncertainty_from(est.volume, est.centroid, est.second_moment, doubt, far)
    check_useful(est.volume, unc, source=source, what="the patched surface's winding-number estimate")
    note = (f"the holes' patches add their own {patched.uncertainty.volume_in_doubt:.3g} m³ in doubt to the "
            "grid's")
    return dataclasses.replace(forced, estimate=dataclasses.replace(est, uncertainty=unc),
                               notes=forced.notes + (note,))
