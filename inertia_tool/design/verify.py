"""Is a spin-it design better than the part it came from?  Verified by re-analysis and simulation.

``spin_it`` optimises a cavity on voxels; the hollowed mesh is then re-analysed exactly (``hollow``).  This
stage compares the re-analysed part with the input, and :func:`spin_it_verified` tries again on a finer grid
when the design fails, so that a part is never handed back worse without saying so.

A design **fails** when

* the spin axis ends more than ``max_axis_tilt`` (default 1°) from a principal axis (yo-yo: the nearest
  principal eigenspace of the central tensor, ``hollow.principal_tilt``, so that the arbitrary axes of equal
  moments do not count; top: the pivot → centre-of-mass line) and farther than the input's was (a design that
  brings it closer but not within 1° passes with a note saying so);
* the mode's objective (``design.moments``) of the re-analysed part is worse than the input's;
* yo-yo only: the simulated free spin (Chapter 4, "Rigid Body Motion", §4.4.1, the exact torque-free
  solution) started about the axis, knocked by 0.1°, wobbles more than the input's: the largest angular
  velocity across the axis, relative to the spin, exceeds ``WOBBLE_FACTOR`` times the input's and
  ``WOBBLE_FLOOR`` (1°, ten times the knock).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..errors import DesignRejectedError, NoRoomError
from .limits import MAX_RESOLUTION

__all__ = ["SpinVerdict", "verify_spin_design", "spin_it_verified", "MAX_AXIS_TILT", "WOBBLE_FACTOR", "WOBBLE_FLOOR"]

#: rad: the spin axis may end at most this far from a principal axis (unless the input was farther).
MAX_AXIS_TILT = math.radians(1.0)

#: The after-wobble fails when it exceeds this multiple of the before-wobble *and* ``WOBBLE_FLOOR``: a stable
#: spin knocked by 0.1° stays within a few tenths of a degree (its cone changes a little with the moments); a
#: wobble the original did not have is of order one.
WOBBLE_FACTOR = 2.0

#: rad/rad: ten times the knock (1°); below it a wobble is the knock's own cone, whatever the design.
WOBBLE_FLOOR = 10 * math.radians(0.1)

#: Objective values may grow by this relative amount (round-off of the exact re-analysis) and still count equal.
OBJECTIVE_RTOL = 1e-9

#: Retries on a finer grid: each multiplies the resolution by this factor, up to ``MAX_RESOLUTION``.
RETRY_FACTOR = 1.5
MAX_RETRIES = 2

#: Finer resolutions tried when a thin part leaves no room for a cavity.
MAX_ROOM_TRIES = 3

#: A design whose spin axis ends off principal is tried again at the same resolution with the product penalty
#: (``product_weight`` of ``design.moments``) this many times stiffer, at most ``MAX_STIFFER`` times.  The
#: penalty weighs the products of inertia against ``I33²``, but the tilt they cause is ``|I13| / (I33 − I11)``:
#: as the objective draws the transverse moments towards the axial one, the same penalty tolerates a larger
#: tilt (the bundled cone at resolution 96: 1.2° at 1e4, 0.03° at 1e5).
STIFFER_FACTOR = 10.0
MAX_STIFFER = 2
DEFAULT_PRODUCT_WEIGHT = 1e4

_RATE, _TURNS, _SAMPLES, _KNOCK = 60.0, 12, 40, math.radians(0.1)


@dataclass(frozen=True)
class SpinVerdict:
    """The comparison of a design with its input.

    Attributes
    ----------
    ok : bool
        No failure found.
    reasons : tuple of str
        One sentence per failure (empty when ``ok``).
    notes : tuple of str
        What a passing design still lacks (its spin axis more than ``max_axis_tilt`` off, though closer than
        the input's).
    axis_tilt_before, axis_tilt_after : float
        rad, as ``SpinDesignMetrics.axis_tilt``.
    objective_before, objective_after : float
        The mode's objective, from the exact moments.
    wobble_before, wobble_after : float or None
        Yo-yo: the largest ``|ω⊥| / |ω|`` of the knocked free spin (rad/rad); None for a top.
    resolution : int
        The grid resolution of the design judged.
    product_weight : float
        The product-of-inertia penalty weight it was optimised with (``STIFFER_FACTOR`` times the previous
        attempt's when that one ended off principal).
    """

    ok: bool
    reasons: tuple[str, ...]
    notes: tuple[str, ...]
    axis_tilt_before: float
    axis_tilt_after: float
    objective_before: float
    objective_after: float
    wobble_before: float | None
    wobble_after: float | None
    resolution: int
    product_weight: float = 1e4


def _wobble(props, axis: np.ndarray) -> float:
    """Largest angular velocity across ``axis`` over a knocked free spin, relative to the spin rate."""
    from ..dynamics.simulation import simulate
    from ..rotations import perpendicular_basis
    e1, _ = perpendicular_basis(axis)
    t = np.linspace(0.0, _TURNS * 2 * math.pi / _RATE, _TURNS * _SAMPLES + 1)
    omega0 = _RATE * (math.cos(_KNOCK) * axis + math.sin(_KNOCK) * e1)
    w = simulate(props, omega0, t).angular_velocity
    across = w - np.outer(w @ axis, axis)
    return float(np.max(np.linalg.norm(across, axis=1)) / _RATE)


def verify_spin_design(result, resolution: int, *, max_axis_tilt: float = MAX_AXIS_TILT,
                       wobble_factor: float = WOBBLE_FACTOR, wobble_floor: float = WOBBLE_FLOOR) -> SpinVerdict:
    """Compare a :class:`~inertia_tool.design.hollow.SpinItResult` with its input (see the module text)."""
    before, after = result.metrics_before, result.metrics_after
    reasons, notes = [], []
    tilt_b, tilt_a = before.axis_tilt, after.axis_tilt
    what = "a principal axis" if result.mode == "yoyo" else "the pivot → centre-of-mass line"
    if tilt_a > max_axis_tilt and tilt_a <= tilt_b:
        notes.append(f"the spin axis is still {math.degrees(tilt_a):.3g}° from {what} (the input's was "
                     f"{math.degrees(tilt_b):.3g}°): the part will wobble; a finer --resolution or another "
                     "--through may bring it closer")
    if tilt_a > max_axis_tilt and tilt_a > tilt_b:
        reasons.append(f"the spin axis ends {math.degrees(tilt_a):.3g}° from {what} (the input's was "
                       f"{math.degrees(tilt_b):.3g}°; at most {math.degrees(max_axis_tilt):.3g}° is accepted)")
    if getattr(result, "cavity_volume", None) == 0 and getattr(result, "insert_vertices", None) is None:
        notes.append("no cavity inside the wall improves the objective: the part is handed back as it was")
    rise_b, rise_a = getattr(before, "sleeping_threshold", None), getattr(after, "sleeping_threshold", None)
    if result.mode == "top" and rise_b is not None and rise_a is not None and rise_a > rise_b:
        notes.append(f"the sleeping-top spin rises ({rise_b:.4g} → {rise_a:.4g} rad/s): the objective improved "
                     "through the symmetry terms, so the top must be spun faster to sleep")
    ob, oa = result.objective_before, result.objective_after
    if oa > ob + OBJECTIVE_RTOL * max(abs(ob), 1e-300):
        reasons.append(f"the objective is worse after ({ob:.6g} → {oa:.6g})")
    wb = wa = None
    if result.mode == "yoyo":
        axis = np.asarray(result.axis, dtype=float)
        wb, wa = _wobble(result.before, axis), _wobble(result.after, axis)
        if wa > wobble_factor * wb and wa > wobble_floor:
            reasons.append(f"the simulated free spin wobbles more after: |ω⊥|/|ω| up to {wa:.3g} (before "
                           f"{wb:.3g}), started 0.1° off the axis")
    return SpinVerdict(ok=not reasons, reasons=tuple(reasons), notes=tuple(notes), axis_tilt_before=tilt_b,
                       axis_tilt_after=tilt_a,
                       objective_before=ob, objective_after=oa, wobble_before=wb, wobble_after=wa,
                       resolution=int(resolution))


def _finer_room(source, resolution: int, error: NoRoomError, options: dict):
    """The first of a few finer resolutions at which a thin part has room for a cavity (at most
    ``MAX_ROOM_TRIES`` tries, up to ``MAX_RESOLUTION``); the original error, listing them, when none has."""
    from . import hollow
    candidates = sorted({min(MAX_RESOLUTION, r) for r in (error.suggested or MAX_RESOLUTION,
                                                          int(math.ceil(resolution * 1.5)), resolution * 2,
                                                          MAX_RESOLUTION) if r > resolution})[:MAX_ROOM_TRIES]
    for candidate in candidates:
        try:
            return hollow.spin_it(source, resolution=candidate, **options), candidate
        except NoRoomError:
            continue
    tried = ", ".join(str(c) for c in candidates) or "none (already the largest)"
    raise NoRoomError(f"{error} (finer resolutions tried: {tried}; none left room)") from error


def spin_it_verified(source, *, resolution: int, retries: int = MAX_RETRIES, **options):
    """``spin_it``, verified; on failure tried again: a design off principal first on the same grid with the
    product penalty ``STIFFER_FACTOR`` stiffer (at most ``MAX_STIFFER`` times), then on a grid ``RETRY_FACTOR``
    finer (at most ``retries`` times).

    Returns
    -------
    (SpinItResult, tuple of SpinVerdict)
        The first design that passes and the verdicts of every attempt.

    Raises
    ------
    DesignRejectedError
        When no attempt passes: the message gives every attempt's reasons.  Nothing is written.
    NoRoomError
        When the part is too thin for a cavity at ``resolution`` and at the few finer ones tried
        (``_finer_room``); when a finer one has room it is used, and the verdict's ``notes`` say so.
    PhysicsError, UsageError, InvalidMeshError
        As ``spin_it``.
    """
    from . import hollow
    verdicts: list[SpinVerdict] = []
    current = int(resolution)
    stiffer = 0

    name = str(source) if isinstance(source, (str, bytes)) or hasattr(source, "__fspath__") else "the part"
    thin_note: tuple[str, ...] = ()
    # each attempt's warnings are recorded and said once at the end: those about the input (read once, the pivot
    # checked by every attempt) once, those about a hollowed mesh only for the design handed back
    about_input: list = []
    seen: set = set()
    for _attempt in range(max(int(retries), 0) + 1 + MAX_STIFFER):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = hollow.spin_it(source, resolution=current, **options)
            except NoRoomError as exc:
                if verdicts:          # a finer retry of a rejected design: the earlier rejection stands
                    break
                result, current = _finer_room(source, current, exc, options)
                thin_note = (f"resolution {resolution} left no room for a cavity (the part is thin there); "
                             f"resolution {current} did, and was used",)
        made = [w for w in caught if getattr(w.message, "about_made_mesh", False)]
        about_input.extend(w for w in caught if not getattr(w.message, "about_made_mesh", False))
        # the part is read and checked once: later attempts reuse the first's (the check of a large mesh costs)
        if getattr(result, "loaded", None) is not None:
            options = {**options, "loaded": result.loaded}
        verdict = replace(verify_spin_design(result, current),
                          product_weight=float(options.get("product_weight", DEFAULT_PRODUCT_WEIGHT)))
        if thin_note:
            verdict = replace(verdict, notes=thin_note + verdict.notes)
        verdicts.append(verdict)
        if verdict.ok:
            hollow.replay_warnings(about_input, name, seen=seen)
            hollow.replay_warnings(made, name, seen=seen)
            return result, tuple(verdicts)
        if _tilted(verdict, MAX_AXIS_TILT) and stiffer < MAX_STIFFER:
            stiffer += 1          # the same grid, the products of inertia weighed more
            weight = options.get("product_weight", DEFAULT_PRODUCT_WEIGHT)
            options = {**options, "product_weight": weight * STIFFER_FACTOR}
            continue
        finer = min(MAX_RESOLUTION, int(math.ceil(current * RETRY_FACTOR)))
        if finer == current:
            break
        current = finer
    hollow.replay_warnings(about_input, name, seen=seen)
    raise DesignRejectedError(_rejection(name, verdicts, result))


def _tilted(verdict: SpinVerdict, max_axis_tilt: float) -> bool:
    return verdict.axis_tilt_after > max_axis_tilt and verdict.axis_tilt_after > verdict.axis_tilt_before


def _rejection(name: str, verdicts: list[SpinVerdict], result) -> str:
    """One line: what failed (the last, finest attempt's reasons), what was tried, and what the user can do."""
    last = verdicts[-1]
    tried = ", ".join(dict.fromkeys(str(v.resolution) for v in verdicts))
    count = f"{len(verdicts)} attempt" + ("s" if len(verdicts) != 1 else "")
    head = (f"{name}: spin-it rejected every design it made (resolution {tried}, {count}): "
            + "; ".join(last.reasons))
    before = result.metrics_before
    if result.mode == "yoyo" and before.nearest_principal != "major" and result.metrics_after.moment_ratio < 1:
        from ..dynamics.spin_stability import stability
        major = stability(result.before).major_axis
        signed = major.axis if major.axis @ result.axis >= 0 else -major.axis
        direction = ",".join(f"{c:.4g}" for c in np.where(np.abs(signed) < 1e-9, 0.0, signed))
        which = ("the part's" if before.axis_tilt <= MAX_AXIS_TILT else "nearest the part's")
        hint = (f"the axis is {which} {before.nearest_principal} principal axis (I_axis/I_next "
                f"{before.moment_ratio:.3g}, best design {result.metrics_after.moment_ratio:.3g}) and a yo-yo "
                f"needs the largest moment, which no design inside this wall reached; nothing was written — spin it "
                f"about its major axis (--axis {direction})")
    elif last.resolution >= MAX_RESOLUTION:
        hint = "nothing was written — try another --through or --wall (the resolution is at its maximum)"
    else:
        hint = "nothing was written — try a finer --resolution, another --through or --wall"
    return f"{head}; {hint}"

