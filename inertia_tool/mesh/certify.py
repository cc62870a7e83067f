"""The last stage of preparing a mesh: the certificate of what the earlier stages did (R7 and the kinds of
:data:`~.policy.CERTIFICATE_KINDS`), and a patched surface's bound.

"exact" is given only when the checks that make it exact ran and passed: the edge census, the exact face-pair
check (complete, nothing crossing), and the float64 round-off of the integrals within ``ROUNDOFF_RTOL`` — with
what a unit conversion's rounding and a tolerance weld's moves may change (``B_w`` of :mod:`.precision`, review
12's R4) counted in it.  A weld whose moves exceed that budget makes the result an estimate within their bound,
or a refusal when the bound is not useful (it collapses a thin part).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..errors import InsideOutWarning, InvalidMeshError
from ..integrals import total_roundoff, total_roundoff_parts
from ..rounding import round_up
from ..tolerances import ESTIMATE_MAX_MASS_RTOL, ROUNDOFF_RTOL
from .policy import Certificate, MisreadNesting, ShellContacts, misread_message
from .shells import Shells, flipped_text, total

if TYPE_CHECKING:
    from .classify import Orientation
    from .precision import RoundedRegion, WeldSweep
    from .resolve import Resolution
    from .uncertainty import Estimate, Uncertainty
    from .unite import United

__all__ = ["Certified", "first_checks", "certify", "misread_reading", "with_weld_doubt", "with_interior_note"]


class Certified(NamedTuple):
    """What :func:`certify` concluded.

    Attributes
    ----------
    certificate : Certificate
    method : str
        How the result was formed (``"patched"`` for a patched surface, ``"union"`` for an arranged one).
    uncertainty : Uncertainty or None
        A patched surface's bound, else None.
    notes : tuple of str
        Why the certificate is weaker than the checks alone say, in words.
    """

    certificate: Certificate
    method: str
    uncertainty: Uncertainty | None
    notes: tuple[str, ...]



#: Why an estimate widened by R4's undecided reading (a shell wound outward inside another) is refused.
_R4_WHY = ("a shell wound outward lies inside another, the file does not say whether it is a body or a cavity, and "
           "the two readings are that far apart; wind the inner shell inward if it is a cavity, or unite the bodies "
           "in a mesh editor if it is a body")

#: What to do when a tolerance weld moved the surface too far to bound the result usefully.
_WELD_WHY = ("the weld moved corners farther than the result can be bounded from; mesh the part with its vertices "
             "shared (or its thin walls thicker than the weld), or lower `merge_tolerance` (0 disables the weld)")


def _weld_refusal(weld: WeldSweep, volume: float, source: str) -> str:
    """One line: a weld whose sweep ``B_w`` reaches the whole volume (it may have collapsed the part)."""
    return (f"{source}: welding corners closer than {round_up(weld.tolerance):.3g} m collapses the part: the weld "
            f"moved corners by up to {round_up(weld.largest_move):.3g} m, and the solid the file's corners bound "
            f"may differ from the welded one by {round_up(weld.volume, 2):.2g} m³, against a welded volume of "
            f"{volume:.3g} m³; " + _WELD_WHY.split("; ", 1)[1])


def with_weld_doubt(forced: Resolution, weld: WeldSweep | None, source: str) -> Resolution:
    """A winding-number estimate forced on a surface the tolerance weld formed (R1b, R3, R6 after step 3 of
    :mod:`.resolve`), with the weld's sweep added to its doubt: the grid bounds its distance from the welded
    solid only (as :func:`~.self_crossing.with_patch_doubt` adds a patched surface's).  Unchanged without a
    sweep; refused when the sum is not useful."""
    if weld is None or forced.estimate is None:
        return forced
    import dataclasses

    from .precision import estimate_with_weld, weld_note
    from .uncertainty import check_useful
    est = estimate_with_weld(forced.estimate, weld)
    check_useful(est.volume, est.uncertainty, source=source,
                 what=f"the surface welded within {round_up(weld.tolerance):.3g} m", why=_WELD_WHY)
    return dataclasses.replace(forced, estimate=est, notes=forced.notes + (weld_note(weld),))


def first_checks(touch: ShellContacts, unverified: str | None) -> tuple[str, list[str]]:
    """The certificate kind and checks before the boolean (R5, R6): exact when the face-pair check finished and no
    self-crossing surface was integrated as it stands (``unverified``: its note); "no-crossing-faces" when, in
    addition, no two faces cross."""
    checks = ["edge-balanced", "consistently-oriented"]
    kind = "exact" if touch.complete and unverified is None else "unverified"
    if touch.complete and not touch.crossing.any() and unverified is None:
        checks.append("no-crossing-faces")
    return kind, checks


def misread_reading(oriented: Orientation, united: United, *, method: str,
                    source: str) -> tuple[United, tuple[float, float] | None]:
    """R4's label for shells the file winds outward that nesting depth reads as cavities (``oriented.misread``):
    the file does not decide between that reading and the union its own winding gives, so the certificate may say
    only what is proven about the reading kept.

    ``exact`` when the parity solid is proven: the surface with those shells turned (as R4 turned them) passes the
    face-pair check with nothing crossing, so its summed integral is that solid's (a body flush with its body's
    floor: after the turn the faces there are coplanar and opposite, a contact).  ``united`` is never given for it
    (the boolean formed a reading, it did not decide one): when the turned surface still has crossing face pairs
    (faces coplanar only to rounding) the result is an estimate whose bound spans both readings (they differ only
    inside those shells: their volume, within their reach of the centroid).  The note, warned, names the other
    reading and its volume.  Groups of crossing shells wound outward at odd depth (``oriented.groups``, kept as
    bodies by the file's winding) have the same two readings and are never proven: an estimate whose bound spans
    both.  Shells the file winds inward inside a cavity that depth reads as bodies (``oriented.voids``, a void
    inside a void read as an island) are labelled the same way, their note naming the file's winding reading (the
    shells empty) and its mass.  Where the file's winding stands (``oriented.interior``: no region's winding below
    0) the shells with winding at least one on both sides were left out and the rest integrated as
    wound; the note names the depth reading and its volume (:func:`_winding_stands`).  Returns the result and, for
    an estimate, ``(volume in doubt, reach)``."""
    united, spread = _depth_readings(oriented, united, method=method, source=source)
    if oriented.interior is not None:
        united = _winding_stands(oriented.interior, united, source=source)
    return united, spread


def _winding_stands(found: MisreadNesting, united: United, *, source: str) -> United:
    """R4 where the file's winding stands (:func:`~.policy.winding_stands`): the shells with winding at least one on
    both sides were left out, and the shells kept bound ``{w ≥ 1}`` as wound.  The label is the kept surface's
    (``exact`` when its checks passed: the summed integral of shells the file writes, as for R0's copies and R2's
    flat pieces, no boolean), with the check ``interior-shells``; the note, warned, names the depth reading (a
    cavity written with the wrong winding) and the volume it gives, exactly."""
    proven = united.forced is None and united.kind in ("exact", "united")
    volume = float(total(united.shells.moments).volume) if proven else None
    note = misread_message(found, volume, proven,
                           kept=f"the file's winding is read as it stands ({united.kind})" if proven else
                           "the solid given is not proven apart from that reading")
    warnings.warn(InsideOutWarning(f"{source}: {note}"), stacklevel=4)
    checks = list(united.checks)
    if proven and "interior-shells" not in checks:
        checks.insert(min(2, len(checks)), "interior-shells")
    return united._replace(notes=(*united.notes, note), checks=checks)


def with_interior_note(forced: Resolution, oriented: Orientation, source: str) -> Resolution:
    """A winding-number estimate forced after the boolean refused (:func:`~.unite.unite_overlaps`), with R4's note
    on the shells left out where the file's winding stands (``oriented.interior``, :func:`_winding_stands`): the
    estimate is of the shells kept, whose ``{w ≥ 1}`` is the file's, and the note says which shells were left out
    and what the depth reading would give (stated against the solid given, not as a total: the estimate is not
    proven to be the file's winding solid).  Unchanged where no shell was left out."""
    if oriented.interior is None:
        return forced
    import dataclasses
    note = misread_message(oriented.interior, None, False,
                           kept="the solid given is an estimate of the shells kept, whose {w ≥ 1} is the file's")
    warnings.warn(InsideOutWarning(f"{source}: {note}"), stacklevel=3)
    return dataclasses.replace(forced, notes=(*forced.notes, note))


def _depth_readings(oriented: Orientation, united: United, *, method: str,
                    source: str) -> tuple[United, tuple[float, float] | None]:
    """:func:`misread_reading` for the readings by nesting depth (``misread``, ``voids``, ``groups``)."""
    from .intersect import surface_contacts

    found, voids, groups = oriented.misread, oriented.voids, oriented.groups
    if found is None and voids is None and groups is None:
        return united, None
    turned = [r for r in (found, voids) if r is not None]          # R4 flipped these without a warning of its own
    if united.forced is not None or united.kind not in ("exact", "united") or oriented.ambiguous:
        # R4 turned those shells without a warning of its own (this is the one): say both readings here too; the
        # result is not known to be the parity solid, so no total is computed from it.  Nor when inward shells
        # cross outward ones or cavities lie in overlapping bodies (``ambiguous``, certified ``unverified``): the
        # two readings would both rest on that unproven cut, and a bound spanning them says nothing of it (review
        # 11's D5 family, fix12: an estimate 0.9375 ±1.7 % for {w ≥ 1} = 0.90625)
        for reading in (r for r in (found, voids, groups) if r is not None):
            note = misread_message(reading, None, proven=False, kept="")
            said = f"{_turned(reading, oriented)}: " if any(reading is r for r in turned) else ""   # said once
            warnings.warn(InsideOutWarning(f"{source}: {said}{note}"), stacklevel=3)
        return united, None
    spread = None
    proven = united.kind == "exact" and groups is None
    if not proven and groups is None:
        as_read = oriented.shells
        again = surface_contacts(as_read.vertices, as_read.faces)
        if again.complete and not len(again.crossing):
            proven = True
            united = united._replace(shells=as_read, owner=oriented.owner, overlaps=0, method=method, kind="exact",
                                     checks=["edge-balanced", "consistently-oriented", "no-crossing-faces"],
                                     cavities=int(np.count_nonzero(oriented.depth % 2 == 1)),
                                     notes=tuple(n for n in united.notes if not n.startswith("touching up to")))
    shells = united.shells
    whole = total(shells.moments)
    notes = []
    if not proven:
        readings = [r for r in (found, voids, groups) if r is not None]
        turned_shells = oriented.shells
        ids = np.concatenate([r.shells for r in readings])
        corners = np.unique(turned_shells.faces[np.isin(turned_shells.labels, ids)])
        reach = float(np.sqrt(np.max(np.sum((turned_shells.vertices[corners] - whole.centroid) ** 2, axis=1))))
        spread = (sum(r.volume for r in readings) * (1 + 1e-9), reach)
    for reading in (r for r in (found, voids, groups) if r is not None):
        notes.append(misread_message(reading, float(whole.volume), proven))
        said = f"{_turned(reading, oriented)}: " if any(reading is r for r in turned) else ""    # said once
        warnings.warn(InsideOutWarning(f"{source}: {said}{notes[-1]}"), stacklevel=3)
    return united._replace(notes=(*united.notes, *notes)), spread


def _plus(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """Two bounds stated as ``(volume relative, centroid m, inertia relative)``, added (triangle inequality)."""
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


def _turned(found: MisreadNesting, oriented: Orientation) -> str:
    """The flip said once (R4 turned these shells without a warning of its own): the start of the one warning."""
    return flipped_text(len(found.shells), oriented.shells.n_shells)


def certify(shells: Shells, *, kind: str, checks: list[str], method: str, patched: Estimate | None,
            arranged: bool, verified: bool, ambiguous: bool, folds: bool, sheets_removed: bool,
            source: str, spread: tuple[float, float] | None = None, scale_rounding: float = 0.0,
            weld: WeldSweep | None = None, arranged_region: RoundedRegion | None = None,
            assumed: tuple[str, ...] = ()) -> Certified:
    """R7 and what each earlier stage implies for the certificate of ``shells``.

    Parameters
    ----------
    shells : Shells
        As integrated, with their round-off bound.
    kind, checks, method
        The certificate kind, checks and method so far (after the boolean).
    patched : Estimate or None
        The estimate of a patched surface (its bound carries over), else None.
    arranged, verified : bool
        A self-crossing or welded surface was arranged (R3, R1b); no crossing was left by rounding its points.
    ambiguous : bool
        An inward-wound shell crosses an outward one (R4's reading, not proven).
    folds, sheets_removed : bool
        Folds enclosing nothing were taken out (R3a); open sheets inside the solid were left out (R3b).
    source : str
        Names the mesh in messages.
    spread : (float, float) or None
        ``(volume in doubt m³, reach m)`` of a reading the file does not decide (:func:`misread_reading`): the
        result is then an estimate whose bounds cover that volume.
    scale_rounding : float
        m: how far the reader's unit conversion moved a coordinate (:attr:`~.read.RawMesh.scale_rounding`): the
        solid integrated may differ from the file's by :func:`~.precision.conversion_bounds`, counted with the
        round-off (review 12's R6: a 47.5 nm plate in mm 1.3e8 m out was 2.3 % off, labelled exact).
    weld : WeldSweep or None
        What a tolerance weld that moved corners may have changed (:func:`~.precision.weld_sweep`; review 12's
        R4: a 3 nm plate welded shut was 33 % low, labelled exact).  Within the round-off budget the label
        stands, with a note; beyond it an ``exact`` or ``united`` result becomes an estimate within the weld's
        bound (added to a patched surface's or R4's doubt), refused when that bound is not useful; an
        ``unverified`` one stays so, with the note.
    arranged_region : RoundedRegion or None
        Where rounding the arrangements' new points (R1b, R3) may change the result, in absolute units
        (:class:`~.precision.RoundedRegion`).  Each arrangement was accepted with it within half the budget of
        the shell it built; it is judged here again against this solid, the one certified: a cavity cut from the
        arranged shell later (R4, R5) makes the same region a larger share, and above half the budget an
        ``exact`` or ``united`` result becomes ``unverified``.  Its shares are added to an estimate's round-off.
    assumed : tuple of str
        The names of the assumptions the user stated (``UserAssumptions.names``); a refusal of holes too large
        to bound suggests ``smooth-holes`` only where the user has not stated it already.
    """
    notes: list[str] = []
    checks = list(checks)
    roundoff = total_roundoff(shells.moments, shells.bound)
    # an arrangement (R1b, R3) was accepted only with its constructed points' rounding within half the budget
    # (:func:`~.arrange.rounded_points_bounds`): the integrals' round-off gets the other half, so that the two
    # together stay within ``ROUNDOFF_RTOL`` (overlay13's note: each was checked against its own share only)
    budget = ROUNDOFF_RTOL / 2 if arranged else ROUNDOFF_RTOL
    converted = (0.0, 0.0, 0.0)
    if scale_rounding > 0:
        from .precision import conversion_bounds
        whole = total(shells.moments)
        converted = conversion_bounds(shells.vertices, shells.faces, scale_rounding, whole.volume, whole.centroid,
                                      whole.second_moment)
    placed = (0.0, 0.0, 0.0)      # the arrangements' rounded points, as shares of the solid certified (R1b, R3)
    if arranged and arranged_region is not None:
        whole = total(shells.moments)
        placed = arranged_region.shares(whole.volume, whole.centroid, whole.second_moment)
    welded = None                 # R4's weld: (volume in doubt m³, reach m) when beyond the round-off budget
    if weld is not None:
        from .precision import weld_note, weld_reach
        from .uncertainty import uncertainty_from
        whole = total(shells.moments)
        reach = weld_reach(weld, whole.centroid)
        share = uncertainty_from(whole.volume, whole.centroid, whole.second_moment, weld.volume, reach)
        relative = max(share.mass, share.inertia)
        if patched is None and roundoff + max(converted[0], converted[2]) + relative <= budget:
            notes.append(weld_note(weld, relative))          # proven within the budget: the label stands
        else:
            welded = (weld.volume, reach)
            notes.append(weld_note(weld))
            if kind in ("exact", "united") and not weld.volume < abs(float(whole.volume)):
                raise InvalidMeshError(_weld_refusal(weld, float(whole.volume), source))
    if patched is None and (welded is None or kind not in ("exact", "united")):   # R7: exact up to round-off
        moved = max(converted[0], converted[2])
        if roundoff + moved > budget and kind in ("exact", "united"):
            kind = "unverified"
            if moved > roundoff:
                notes.append(f"converting the file's unit to metres rounded its coordinates by up to "
                             f"{round_up(scale_rounding, 2):.2g} m, which may change the result by "
                             f"{round_up(moved, 2):.2g} of it (above {budget:g}: a part thin or small "
                             "against its distance from the origin): not verified; give the mesh in metres, or "
                             "nearer the origin, to prove it")
            else:
                notes.append("the float64 round-off of the integrals is bounded only by "
                             f"{round_up(roundoff, 2):.2g} of the result "
                             f"(above {budget:g}: a sliver thinner than its coordinates' rounding, too large "
                             "for exact arithmetic): not verified")
    if max(placed[0], placed[2]) > ROUNDOFF_RTOL / 2 and kind in ("exact", "united"):
        kind = "unverified"
        notes.append(f"rounding the arranged surface's new points to float64 may change the result by "
                     f"{round_up(max(placed[0], placed[2]), 2):.2g} of it (above {ROUNDOFF_RTOL / 2:g}, the half of "
                     "the round-off budget the arrangement has; within it for the shell arranged, a larger share "
                     "of the solid left once a cavity was cut): not verified")
    uncertainty = None
    if patched is not None:
        from .uncertainty import check_useful, uncertainty_from, with_roundoff   # imported on use: repair only
        from .hole_assumptions import ISLAND_HINT, holes_hint
        whole = total(shells.moments)
        doubt, far = patched.uncertainty.volume_in_doubt, patched.far
        if spread is not None:                # R4: the reading the file does not decide is in doubt as well
            doubt, far = doubt + spread[0], max(far, spread[1])
        if welded is not None:                # the weld's sweep as well (triangle inequality)
            doubt, far = doubt + welded[0], max(far, welded[1])
        uncertainty = with_roundoff(uncertainty_from(whole.volume, whole.centroid, whole.second_moment, doubt, far),
                                    _plus(total_roundoff_parts(shells.moments, shells.bound), _plus(converted, placed)))
        what = "the patched surface" + (" and a shell wound outward inside another" if spread is not None else "")
        holes_alone = patched.uncertainty.volume_in_doubt / whole.volume if whole.volume > 0 else np.inf
        if spread is not None and holes_alone <= ESTIMATE_MAX_MASS_RTOL:
            # the holes alone are bounded usefully: the reading the file does not decide is what widens the bound
            check_useful(whole.volume, uncertainty, source=source, what=what,
                         why=_R4_WHY.replace("far apart;", "far apart (the holes alone are bounded within "
                                             f"±{round_up(100 * holes_alone):.3g} % mass);"))
        elif patched.islands:     # islands in a flat face kept their ball: the user may state they lost flat pieces
            check_useful(whole.volume, uncertainty, source=source, what=what,
                         why="the holes are too large to guess what fills them; close them in a mesh editor"
                         + ISLAND_HINT)
        elif way_on := holes_hint(assumed):   # the user may state the lost surface was smooth or faceted (not yet)
            check_useful(whole.volume, uncertainty, source=source, what=what,
                         why="the holes are too large to guess what fills them; close them in a mesh editor"
                         + way_on)
        else:
            check_useful(whole.volume, uncertainty, source=source, what=what)
        # a patched surface whose union could not be verified (R6) keeps "unverified": the patches' bound does
        # not cover what the boolean changed beyond them
        method, kind = "patched", ("unverified" if kind == "unverified" else "estimate")
    elif spread is not None and kind in ("exact", "united"):         # R4: both readings within the bound
        from .uncertainty import uncertainty_from
        whole = total(shells.moments)
        from .uncertainty import check_useful, with_roundoff
        doubt, far = spread
        if welded is not None:                # the weld's sweep as well (triangle inequality)
            doubt, far = doubt + welded[0], max(far, welded[1])
        uncertainty = with_roundoff(uncertainty_from(whole.volume, whole.centroid, whole.second_moment, doubt, far),
                                    _plus(total_roundoff_parts(shells.moments, shells.bound), _plus(converted, placed)))
        # the same ±50 % limit as every estimate (holes6's review: two crossing outward cubes inside a cube were
        # answered at ±61.5 % mass)
        check_useful(whole.volume, uncertainty, source=source, what="the reading by nesting depth", why=_R4_WHY)
        kind, method = "estimate", "nesting"      # a reading by nesting depth, not the surface integral proven
    elif welded is not None and kind in ("exact", "united"):        # R4's weld: the welded solid, bounded
        from .uncertainty import check_useful, uncertainty_from, with_roundoff
        whole = total(shells.moments)
        uncertainty = with_roundoff(uncertainty_from(whole.volume, whole.centroid, whole.second_moment, *welded),
                                    _plus(total_roundoff_parts(shells.moments, shells.bound), _plus(converted, placed)))
        check_useful(whole.volume, uncertainty, source=source,
                     what=f"the surface welded within {round_up(weld.tolerance if weld else 0.0):.3g} m",
                     why=_WELD_WHY)
        kind = "estimate"                     # the welded polyhedron, within the weld's sweep of the file's
    if arranged:                              # R3: the arrangement's surface, checked like any other
        method = "union" if method == "exact" else method
        kind = {"exact": "united"}.get(kind, kind)
        checks.insert(2, "winding-arrangement")
        if not verified:                      # crossings left by rounding: not proven
            kind = "unverified" if kind == "united" else kind
            checks = [c for c in checks if c != "no-crossing-faces"]
    if ambiguous and kind in ("exact", "united"):
        kind = "unverified"                   # R4: a reading of the file's winding, not a proven solid
    if folds and "no-crossing-faces" in checks:
        checks.insert(checks.index("no-crossing-faces"), "zero-volume-folds")      # R3a: what makes it exact
    if sheets_removed and "no-crossing-faces" in checks:
        checks.insert(checks.index("no-crossing-faces"), "open-sheets")            # R3b: what makes it exact
    certificate = Certificate(kind, tuple(checks) if kind != "estimate" else ())
    return Certified(certificate, method, uncertainty, tuple(notes))
