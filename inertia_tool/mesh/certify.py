"""The last stage of preparing a mesh: the certificate of what the earlier stages did (R7 and the kinds of
:data:`~.policy.CERTIFICATE_KINDS`), and a patched surface's bound.

"exact" is given only when the checks that make it exact ran and passed: the edge census, the exact face-pair
check (complete, nothing crossing), and the float64 round-off of the integrals within ``ROUNDOFF_RTOL``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from ..integrals import total_roundoff
from ..rounding import round_up
from ..tolerances import ROUNDOFF_RTOL
from .policy import Certificate, ShellContacts
from .shells import Shells, total

if TYPE_CHECKING:
    from .uncertainty import Estimate, Uncertainty

__all__ = ["Certified", "first_checks", "certify"]


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


def first_checks(touch: ShellContacts, unverified: str | None) -> tuple[str, list[str]]:
    """The certificate kind and checks before the boolean (R5, R6): exact when the face-pair check finished and no
    self-crossing surface was integrated as it stands (``unverified``: its note); "no-crossing-faces" when, in
    addition, no two faces cross."""
    checks = ["edge-balanced", "consistently-oriented"]
    kind = "exact" if touch.complete and unverified is None else "unverified"
    if touch.complete and not touch.crossing.any() and unverified is None:
        checks.append("no-crossing-faces")
    return kind, checks


def certify(shells: Shells, *, kind: str, checks: list[str], method: str, patched: Estimate | None,
            arranged: bool, verified: bool, ambiguous: bool, folds: bool, sheets_removed: bool,
            source: str) -> Certified:
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
    """
    notes: list[str] = []
    checks = list(checks)
    roundoff = total_roundoff(shells.moments, shells.bound)
    if patched is None:                                                          # R7: exact up to round-off
        if roundoff > ROUNDOFF_RTOL and kind in ("exact", "united"):
            kind = "unverified"
            notes.append("the float64 round-off of the integrals is bounded only by "
                         f"{round_up(roundoff, 2):.2g} of the result "
                         f"(above {ROUNDOFF_RTOL:g}: a sliver thinner than its coordinates' rounding, too large for "
                         "exact arithmetic): not verified")
    uncertainty = None
    if patched is not None:
        from .uncertainty import check_useful, uncertainty_from     # imported on use: repair only
        whole = total(shells.moments)
        uncertainty = uncertainty_from(whole.volume, whole.centroid, whole.second_moment,
                                       patched.uncertainty.volume_in_doubt, patched.far)
        check_useful(whole.volume, uncertainty, source=source, what="the patched surface")
        # a patched surface whose union could not be verified (R6) keeps "unverified": the patches' bound does
        # not cover what the boolean changed beyond them
        method, kind = "patched", ("unverified" if kind == "unverified" else "estimate")
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
