"""The clean-part fast path of :func:`~.prepare.prepare_mesh`: one closed, consistently wound, edge-manifold shell
of positive volume whose faces meet nowhere but where they share corners by index.

Most parts of a catalogue are such a shell, and for them the eight stages of :func:`~.prepare.prepare_mesh` decide
nothing: R0 (copies), R1b (welded bodies), R2 (flat shells), R3a (folds), R3 (self-crossing), R4 (nesting, flips),
R5 and R6 (the boolean) have one shell and no face pair to act on.  :func:`prepare_clean` runs the checks that make
the answer exact, in the order of the full path and with the same functions (so the same arithmetic, bit for bit):

1. the bounding box and the coordinates' safe range, no triangle with a repeated corner, a positive extent;
2. the edge census and the shells from one adjacency (:func:`~.checks.census_and_shells`): every edge shared by
   exactly two faces in opposite directions (closed, consistently oriented), one edge-connected shell;
3. the shell's moments about the bounding-box centre and their round-off bound (R7: what
   :func:`~inertia_tool.integrals.body_volume_moments`, :func:`~inertia_tool.integrals.accurate_shells` and
   :func:`~inertia_tool.integrals.total_roundoff` give, in one call, :func:`~inertia_tool.integrals.one_shell_moments`;
   a sliver that R7 would integrate again, or one within a margin of it, goes to the full path); a shell enclosing
   volume above R2's flatness, wound outward;
4. the exact face-pair check (the C kernel of :func:`~.intersect.surface_contacts`, with the same arguments):
   complete, no pair crossing, no pair coplanar and facing opposite ways (contacts of a shell with itself at a
   vertex or along an edge change nothing here, as in the full path);
5. R7 of :func:`~.certify.certify`: the round-off bound of the total within ``ROUNDOFF_RTOL`` (by a margin), so
   the certificate is ``exact`` with ``edge-balanced``, ``consistently-oriented`` and ``no-crossing-faces`` (beyond
   it, the full path certifies ``unverified`` with its note).

Whenever any of these does not hold, :func:`prepare_clean` returns None *before* saying anything (no warning is
issued, nothing is refused): the caller then runs the full :func:`~.prepare.prepare_mesh`, which decides, warns and
refuses as it always did.  On a part it accepts, the :class:`~.prepare.PreparedMesh` is the full path's, field for
field (``tests/test_batch7_fast_path.py`` compares them on generated and adversarial meshes).

Only the face-pair check's diagnostic counters differ: the full path's :class:`~.intersect.SurfaceContacts`
(``candidate_pairs``, ``tested_pairs``) is kept by neither path's result, and here only the kinds of the pairs the
kernel found and ``complete`` are read.
"""

from __future__ import annotations

import math

import numpy as np

from .._native import accel, faces_for_c, threads
from ..errors import InvalidMeshError
from ..integrals import bounding_box, one_shell_moments
from ..tolerances import FLAT_RTOL, ROUNDOFF_RTOL
from .checks import MeshReport, census_and_shells
from .intersect import STAR_MIN_FACES, surface_contacts
from .policy import Certificate
from .prepare import PreparedMesh
from .read import RawMesh
from .surface import check_magnitude

__all__ = ["prepare_clean", "CLEAN_MAX_FACES", "CLEAN_CHECKS"]

#: Largest part (faces) the fast path takes: above it the stages' own cost dwarfs what the fast path saves, and
#: the full path's memory management (chunked passes, released scratch) is the one tuned for it.
CLEAN_MAX_FACES = 1 << 17

#: The share of ``ROUNDOFF_RTOL`` the fast path leaves to a unit conversion's rounding (R7 counts both: the
#: round-off is held within the rest, so a part the fast path takes is one the full path certifies exact too).
_CONVERSION_SHARE = 0.25

#: The checks of the certificate of a clean part (the full path's ``first_checks`` for one shell, nothing crossing).
CLEAN_CHECKS = ("edge-balanced", "consistently-oriented", "no-crossing-faces")

#: The certificate of every part the fast path takes (a frozen value: one object serves them all); what
#: :func:`~.certify.certify` gives a clean shell whose round-off bound is within ``ROUNDOFF_RTOL``.
_EXACT = Certificate("exact", CLEAN_CHECKS)

#: Nonzero coordinate magnitudes within which the C face-pair kernel's floating-point filters are valid (those of
#: :func:`~.intersect.surface_contacts`, which scales other coordinates first: the fast path leaves them to it).
_SAFE_SMALLEST, _SAFE_LARGEST = 2.0 ** -240, 2.0 ** 299

#: The kind the C face-pair kernel gives a pair that meets only on the boundary of one face (``intersect``'s
#: ``_CONTACT``): the only kind a clean part may have (a crossing or a coplanar opposite pair sends it to the
#: full path, as does a pair the kernel left undecided, kind < 0).
_CONTACT_KIND = 3


def prepare_clean(raw: RawMesh, *, max_faces: int = CLEAN_MAX_FACES) -> PreparedMesh | None:
    """The :class:`~.prepare.PreparedMesh` of a clean one-shell part, or None when the part is anything else.

    Parameters
    ----------
    raw : RawMesh
        Vertices in metres and faces, from :func:`~inertia_tool.mesh.read.load_mesh`.
    max_faces : int
        Parts with more faces go to the full path (:data:`CLEAN_MAX_FACES`).

    Returns
    -------
    PreparedMesh or None
        What ``prepare_mesh(raw)`` returns, for any ``repair``, ``merge_tolerance``, ``overlap`` and
        ``self_crossing`` (none of them acts on such a part); None (nothing warned, nothing raised) when one of the
        conditions of the module docstring fails.
    """
    v, f = raw.vertices, raw.faces
    m = len(f)
    if m == 0 or m > max_faces:
        return None
    source = raw.source
    lo, hi = bounding_box(v)
    try:
        check_magnitude(lo, hi, source)
    except InvalidMeshError:
        return None                                              # the full path refuses it, in its words
    if ((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])).any():
        return None                                              # degenerate triangles: warned by the full path
    extent = hi - lo
    diag = math.sqrt(float(extent.dot(extent)))                  # np.linalg.norm(extent), without its checks
    if not diag > 0:
        return None
    topo, labels, n_shells = census_and_shells(f, len(v), v)
    if n_shells != 1 or not topo.oriented:
        return None
    centre = 0.5 * (lo + hi)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):     # a flat shell's bound is inf or NaN
        found = one_shell_moments(v, f, centre, (lo, hi),
                                  rtol=ROUNDOFF_RTOL * (1.0 - _CONVERSION_SHARE if raw.scale_rounding > 0 else 1.0))
    if found is None:
        return None                                              # a sliver R7 integrates again, or no C extension
    shell, within = found
    volume = shell.volume
    if not (volume > 0 and abs(volume) > FLAT_RTOL * diag ** 3):
        return None                                              # inside out, flat or NaN: the full path decides
    if not _meet_only_in_contacts(v, f, lo, hi):
        return None
    if not within:
        return None                                              # R7 may say "unverified", with its note
    if raw.scale_rounding > 0:                                   # R7 counts the unit conversion's rounding too
        from .precision import conversion_bounds
        moved = conversion_bounds(v, f, raw.scale_rounding, volume, shell.centroid, shell.second_moment)
        if max(moved[0], moved[2]) > _CONVERSION_SHARE * ROUNDOFF_RTOL:
            return None                                          # the full path decides, with its note
    report = MeshReport(vertices=len(v), faces=m, zero_area_faces=shell.zero_area_faces, bodies=1, cavities=0,
                        flipped_shells=0, overlapping_shells=0, repaired=False, repair_actions=(),
                        repair_volume_change=None, bbox_min=lo, bbox_max=hi, method="exact", uncertainty=None,
                        notes=(), certificate=_EXACT, source=source, units=raw.units, file_faces=raw.file_faces,
                        degenerate_faces=0, watertight=True, welded_tolerance=None, flipped_faces=0,
                        nonmanifold_edges=0)
    return PreparedMesh(vertices=v, faces=f, labels=labels, shells=(shell,), owner=np.arange(1), report=report)


def _meet_only_in_contacts(v: np.ndarray, f: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the exact face-pair check finds no pair crossing and none coplanar facing opposite ways (contacts
    only, or nothing), complete.

    The C kernel of :func:`~.intersect.surface_contacts` (``contact_scan``, no work bound, its certified stars
    and patches) called directly on coordinates in its safe range, without the wrapper's views, masks and
    :class:`~.intersect.SurfaceContacts`: this part needs only the kinds of the pairs found.  Anything else (no
    C extension, coordinates outside the range, a kernel that answers otherwise) asks
    :func:`~.intersect.surface_contacts` itself.
    """
    lib = accel()
    if lib is not None:
        corners = lo.tolist() + hi.tolist()
        largest = max(abs(x) for x in corners)
        magnitude = np.abs(v.reshape(-1))
        nonzero = magnitude[magnitude > 0]          # (np.min with where= is slower at every size, 24 to 30,000)
        smallest = float(nonzero.min()) if len(nonzero) else np.inf
        if largest <= _SAFE_LARGEST and smallest >= _SAFE_SMALLEST and f.min() >= 0 and f.max() < len(v):
            try:
                _, _, kinds, _, _, _, complete, _, _ = lib.contact_scan(
                    np.ascontiguousarray(v, dtype=np.float64), faces_for_c(f), -1, threads(), STAR_MIN_FACES, True)
            except (TypeError, ValueError):         # a kernel of another signature: the wrapper knows it
                pass
            else:
                kind = np.frombuffer(kinds, dtype=np.int8)
                return bool(complete) and not (kind != _CONTACT_KIND).any()
    contacts = surface_contacts(v, f)
    return bool(contacts.complete) and not len(contacts.crossing) and not len(contacts.coplanar_opposite)
