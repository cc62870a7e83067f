"""Open sheets inside a closed solid (rule R3b): a wall of zero thickness with material on both sides.

A CAD export or a cut-and-rejoin often leaves one sheet of faces inside the part: the cut face of one half kept
when the halves were joined again (its rim welded to the part's surface), or a stray surface free inside the
solid.  The file is then not closed (the sheet's rim edges are used once more in one direction than the other), so
it failed the edge census; yet the solid it describes is not in doubt.

The lemma
---------
Let the file's surface be ``S = R + Σ`` as 2-chains, where ``R`` is closed (every edge used equally often in both
directions, by vertex index) and ``Σ`` is the union of open *sheets*.  Write ``X`` for the relative interior of one
sheet: its open faces and the open edges that only its own faces use (two faces, opposite directions).  If no face
of ``R`` meets a face of the sheet beyond the vertices and edges they share by index (the face-pair check,
:mod:`~.intersect`, exact), then ``X`` does not meet ``R`` (a shared edge is used by a face of ``R`` as well, so
it is not in ``X``), and ``X`` is connected (its faces are joined through those edges).  The winding number
``w_R`` is an integer constant on each connected set off ``R``, so one point of ``X`` gives it on all of ``X``.
When that value puts ``X`` inside the solid of ``R`` (``w_R = 1``, and an odd number of ``R``'s shells around it,
so that the nesting-depth reading of R4 agrees), the sheet lies in the solid except for its rim, which lies on
``R``'s surface or inside the solid.  The material is then on both sides of the sheet: the solid the file
describes is ``{w_R ≥ 1}``, whose volume integrals (Rigid Body Motion, Ch. 4, the volume integrals written as
sums over the boundary's faces) are ``R``'s face sums exactly.  The sheet's own face sums are not the boundary of
anything and are dropped; its volume is zero.  Nothing is moved, so the result is ``exact`` (check
``open-sheets``) without ``repair``: a lone wall inside a closed part is what the user means as the part.

For a planar sheet the generalised winding number agrees: the solid angle of a plane region seen from a point off
it is below 2π, so ``|w_Σ| < 1/2`` and ``{w_S > 1/2} = {w_R ≥ 1}`` (Jacobson, Kavan and Sorkine-Hornung,
"Robust Inside-Outside Segmentation using Generalized Winding Numbers", SIGGRAPH 2013, read the solid that way).

Only flat sheets
----------------
A curved open piece lying inside the solid may be something else: the surface of a cavity with a hole in it
(its void volume would be lost by reading it as a wall), or a dome whose other side is missing.  So only a sheet
whose corners all lie within ``WALL_PLANE_RTOL`` times the largest |coordinate| of one plane is taken (a cut face,
a CAD face left inside): flat, it cannot be the rest of a surface that enclosed a volume, and for an exactly
planar sheet the generalised winding number reads the same solid: the solid angle of a plane region seen from a
point off it is below 2π, so ``|w_Σ| < 1/2`` and ``{w_S > 1/2} = {w_R ≥ 1}`` (the reading of Jacobson, Kavan and
Sorkine-Hornung, "Robust Inside-Outside Segmentation using Generalized Winding Numbers", SIGGRAPH 2013, which the
winding-number estimate uses).  Curved sheets stay on the normal path.

Flat pieces can still enclose a void together: a cavity whose flat facets were cracked apart (their corners
no longer shared) is a set of flat open pieces each inside the solid.  So no two sheets taken may have rim corners
within ``MERGE_TOLERANCE`` of the diagonal of each other (the distance within which the weld would join them);
walls meet nothing but the rest of the part.  Cracked wider, or pushed through one another, such facets are still
several flat sheets that together nearly enclose a point (their solid angles add up to almost 4π, so the
generalised winding number reads a void there): several sheets are therefore taken only when every rim corner
of each is a corner of the rest (walls joined to the part's surface, as a kept cut face is); a free sheet is taken
only alone (:func:`_rim_corners`).

A flat sheet whose point lies outside the solid (``w_R = 0``, an even number of shells around it) is a *fin*: a
surface of zero thickness standing out of the part (or into a cavity).  Its volume is zero too, but it is not this
case: it may be a thin plate meant to have thickness.  It is counted, nothing is taken out, and the refusal
(without ``repair``) names it; ``repair`` goes on as for any open surface (a loose fin is closed flat and left out
by R2).  A sheet that crosses or touches ``R`` beyond the features they share (it pokes through the surface) is
not decided here either: the surface goes on to the normal path.

Finding the sheets
------------------
The faces are split into *pieces* joined through manifold edges (two faces, opposite directions).  The flat open
pieces are taken out, smallest area first, while each one taken out makes the boundary 1-chain shorter, until the
rest balances.  The order is a choice, not a proof: a sheet cut from a part is smaller than either side of the
part it is welded to (the part's surface on one side projects onto the whole cut), and a side of a part is not
flat; what makes the answer exact is the check above, on the pieces actually taken out.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..tolerances import MERGE_TOLERANCE, WALL_PLANE_RTOL
from ..values import frozen_value
from .edges import edge_keys

__all__ = ["OpenSheets", "open_sheets", "MAX_SHEET_PIECES"]

#: Work bound: open pieces tried as sheets (the rest stays on the normal path).
MAX_SHEET_PIECES = 64
#: A winding number whose float value is farther than this from an integer is not trusted (a point too close to
#: the surface for its solid-angle sum).
_WINDING_SLACK = 0.05


@frozen_value
class OpenSheets:
    """Open sheets taken out of a surface (R3b, module docstring).

    Attributes
    ----------
    faces : (k, 3) int64
        The rest ``R``: closed (edge-balanced).  Meant as the solid only when ``fins`` is 0.
    inside : int
        Sheets lying inside the solid of ``R`` (material on both sides).
    fins : int
        Sheets lying outside it (zero-thickness fins: not this rule's case, only counted for the messages).
    inside_faces, fin_faces : int
        Their faces.
    inside_area, fin_area : float
        m², their summed areas (rounded up).
    """

    faces: np.ndarray
    inside: int
    fins: int
    inside_faces: int
    fin_faces: int
    inside_area: float
    fin_area: float

    def describe(self) -> str:
        """One line for the report's notes (the sheets taken out)."""
        return (f"{self.inside:,} open sheet{'s' if self.inside > 1 else ''} ({self.inside_faces:,} faces, "
                f"{self.inside_area:.3g} m²) lying inside the solid (a wall of zero thickness with material on both "
                "sides, its rim on the surface or free inside) left out: it encloses no volume")


def _codes(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(keys, return_inverse=True)`` by one stable sort (numpy's hash-based unique is several times
    slower on the millions of edge keys of a large mesh)."""
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    first = np.r_[True, sorted_keys[1:] != sorted_keys[:-1]]
    inverse = np.empty(len(keys), dtype=np.int64)
    inverse[order] = np.cumsum(first) - 1
    return sorted_keys[first], inverse


def _pieces(f: np.ndarray, n: int) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """Faces joined through manifold edges: ``(piece of each face, pieces, edge of each slot, ±1 of each slot)``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    key, forward = edge_keys(f, n)
    _, edge = _codes(key)
    sign = np.where(forward, 1, -1).astype(np.int64)
    count = np.bincount(edge)
    net = np.bincount(edge, weights=sign).astype(np.int64)
    slots = np.flatnonzero(((count == 2) & (net == 0))[edge])
    slots = slots[np.argsort(edge[slots], kind="stable")]
    m = len(f)
    graph = coo_matrix((np.ones(len(slots) // 2, dtype=np.int8), (slots[0::2] // 3, slots[1::2] // 3)), shape=(m, m))
    n_pieces, piece = connected_components(graph, directed=False)
    return piece.astype(np.int64), int(n_pieces), edge, sign


def _take_out(f: np.ndarray, piece: np.ndarray, n_pieces: int, edge: np.ndarray, sign: np.ndarray,
              area: np.ndarray, max_pieces: int, planar: Callable[[int], bool]) -> np.ndarray | None:
    """The open pieces taken out (module docstring, "Finding the sheets"): of the ``max_pieces`` smallest open
    pieces, those for which ``planar(piece)`` holds; None when the rest does not balance or is empty."""
    n_edges = int(edge.max()) + 1
    total = np.bincount(edge, weights=sign, minlength=n_edges).astype(np.int64)
    if not total.any():
        return None
    owner = piece[np.arange(3 * len(f)) // 3]
    pair, inverse = _codes(owner * n_edges + edge)
    pnet = np.bincount(inverse, weights=sign).astype(np.int64)
    open_rows = np.flatnonzero(pnet != 0)
    if not len(open_rows):
        return None
    row_piece, row_edge, row_net = pair[open_rows] // n_edges, pair[open_rows] % n_edges, pnet[open_rows]
    candidates = row_piece[np.r_[True, row_piece[1:] != row_piece[:-1]]]          # sorted: each once
    if len(candidates) > 4 * max_pieces:
        return None                                   # a soup or a shattered surface: no few sheets close it
    piece_area = np.bincount(piece, weights=area, minlength=n_pieces)
    candidates = candidates[np.argsort(piece_area[candidates], kind="stable")][:max_pieces]
    candidates = candidates[[planar(p) for p in candidates.tolist()]]
    starts = np.searchsorted(row_piece, candidates, side="left")
    stops = np.searchsorted(row_piece, candidates, side="right")
    taken = []
    for p, s0, s1 in zip(candidates.tolist(), starts.tolist(), stops.tolist()):    # bounded by max_pieces
        e, k = row_edge[s0:s1], row_net[s0:s1]
        before = total[e]
        after = before - k
        if int(np.abs(after).sum()) < int(np.abs(before).sum()):
            total[e] = after
            taken.append(p)
            if not total.any():
                break
    if total.any() or len(taken) == n_pieces:
        return None
    return np.array(taken, dtype=np.int64)


def _rims_meet(v: np.ndarray, f: np.ndarray, piece: np.ndarray, taken: np.ndarray, edge: np.ndarray,
               sign: np.ndarray, reach: float) -> bool:
    """Whether a rim corner of one taken sheet lies within ``reach`` of a rim corner of another: flat pieces of a
    surface cracked apart (a cavity whose facets lost their shared corners) would each pass as a sheet inside the
    solid, and together they enclose its void.  Walls meet nothing but the rest."""
    from scipy.spatial import cKDTree

    if len(taken) < 2:
        return False
    sheet_of_piece = np.full(int(piece.max()) + 1, -1, dtype=np.int64)
    sheet_of_piece[taken] = np.arange(len(taken))
    slot_sheet = sheet_of_piece[piece[np.arange(3 * len(f)) // 3]]
    inside = slot_sheet >= 0
    owner_edge = slot_sheet[inside] * (int(edge.max()) + 1) + edge[inside]
    _, inverse, counts = np.unique(owner_edge, return_inverse=True, return_counts=True)
    net = np.bincount(inverse.reshape(-1), weights=sign[inside])
    rim_slot = np.flatnonzero(inside)[net[inverse.reshape(-1)] != 0]
    corners = np.unique(np.stack([f.reshape(-1)[rim_slot], slot_sheet[rim_slot]], axis=1), axis=0)
    pairs = cKDTree(v[corners[:, 0]]).query_pairs(reach, output_type="ndarray")
    return bool(len(pairs) and np.any(corners[pairs[:, 0], 1] != corners[pairs[:, 1], 1]))


def _rim_corners(f: np.ndarray, is_sheet: np.ndarray, edge: np.ndarray, sign: np.ndarray) -> np.ndarray:
    """The corners on the rims of the sheets (the faces ``is_sheet``): ends of their unbalanced edges.

    One flat sheet cannot enclose anything (a plane region subtends less than 2π from any point, so its
    generalised winding number stays within ±1/2), but several can together: the four facets of a tetrahedral
    cavity cracked or pushed apart each pass as a sheet inside the solid, and reading them as walls fills the
    cavity (review of R3b: 0.75 % high on a 4 m box, certified exact).  So several sheets are taken only when
    every rim corner of every sheet is a corner of the rest (walls joined to the part's surface, as a cut face
    kept inside is); a free sheet is taken only alone."""
    slots = np.flatnonzero(np.repeat(is_sheet, 3))
    _, inverse = np.unique(edge[slots], return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=sign[slots])
    rim = slots[net[inverse.reshape(-1)] != 0]
    return np.unique(f.reshape(-1)[rim])


def _any_degenerate(v: np.ndarray, f: np.ndarray) -> bool:
    """Whether a face has zero area exactly (its corners collinear: every coordinate projection's orient2d
    zero).  The face-pair check skips such faces, so a sheet holding one is not proven apart from the rest."""
    from .intersect import orient2d_sign

    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    flat = np.ones(len(f), dtype=bool)
    for keep in ([1, 2], [2, 0], [0, 1]):
        flat &= np.asarray(orient2d_sign(a[:, keep], b[:, keep], c[:, keep])) == 0
    return bool(flat.any())


def _shell_windings(point: np.ndarray, v: np.ndarray, f: np.ndarray, labels: np.ndarray, n_shells: int) -> np.ndarray:
    """Winding number of each shell about ``point`` (n_shells,) float: the signed solid angles of its faces over 4π
    (Van Oosterom and Strackee, IEEE Trans. Biomed. Eng. 30 (1983) 125)."""
    a, b, c = v[f[:, 0]] - point, v[f[:, 1]] - point, v[f[:, 2]] - point
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", a, c) * lb
           + np.einsum("ij,ij->i", b, c) * la)
    return np.bincount(labels, weights=2.0 * np.arctan2(num, den), minlength=n_shells) / (4.0 * np.pi)


def open_sheets(vertices: np.ndarray, faces: np.ndarray, *, max_pieces: int = MAX_SHEET_PIECES,
                plane_rtol: float = WALL_PLANE_RTOL, rim_rtol: float = MERGE_TOLERANCE) -> OpenSheets | None:
    """R3b: the open sheets of an unbalanced surface, taken out when the rest is closed and each sheet lies inside
    or outside its solid without meeting it (module docstring); else None.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        A surface that is not edge-balanced, without repeated corners.
    max_pieces : int
        Open pieces tried as sheets, at most (smallest first).
    plane_rtol : float
        A sheet's corners lie within ``plane_rtol`` times the largest |coordinate| of one plane (module docstring,
        "Only flat sheets").
    rim_rtol : float
        Two sheets whose rims come within ``rim_rtol`` times the bounding-box diagonal of each other are not taken
        (pieces of one surface cracked apart, e.g. a cavity: module docstring, "Only flat sheets").

    Returns
    -------
    OpenSheets or None
        None when no set of open pieces leaves a closed rest, or a sheet meets the rest beyond what they share by
        index, or the rest passes through itself, or a sheet's side cannot be decided.
    """
    from .checks import shell_labels
    from .folds import _distance_bound, _plane
    from .intersect import surface_contacts

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) < 5:                                    # a closed rest and a sheet need at least 4 + 1 faces
        return None
    piece, n_pieces, edge, sign = _pieces(f, len(v))
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    area = 0.5 * np.linalg.norm(normal, axis=1)
    tolerance = plane_rtol * float(np.abs(v).max())
    first = np.full(n_pieces, -1, dtype=np.int64)
    first[piece[::-1]] = np.arange(len(f))[::-1]                 # a face of each piece
    ref = normal[first[piece]]
    size = np.linalg.norm(normal, axis=1) * np.linalg.norm(ref, axis=1)
    parallel = np.abs(np.einsum("ij,ij->i", normal, ref)) >= (1 - 1e-6) * size
    bent = np.bincount(piece, weights=(~parallel | ~(size > 0)).astype(np.float64), minlength=n_pieces) > 0

    def planar(p: int) -> bool:                      # a quick filter on the normals, then the corners' distance
        if bent[p]:
            return False
        members = f[piece == p]
        plane = _plane(v, members)
        return plane is not None and _distance_bound(v, members, *plane) <= tolerance

    taken = _take_out(f, piece, n_pieces, edge, sign, area, max_pieces, planar)
    if taken is None:
        return None
    is_sheet = np.isin(piece, taken)
    rest = f[~is_sheet]
    if len(rest) < 4 or _any_degenerate(v, f[is_sheet]):
        return None                                   # a zero-area face is skipped by the check: not proven apart
    if _rims_meet(v, f, piece, taken, edge, sign, rim_rtol * float(np.linalg.norm(np.ptp(v, axis=0)))):
        return None                                   # flat pieces of one cracked surface (a cavity), not walls
    if len(taken) > 1 and not np.isin(_rim_corners(f, is_sheet, edge, sign), rest).all():
        return None                                   # several sheets, some free: together they may enclose a void
    contacts = surface_contacts(v, f)
    if not contacts.complete:
        return None
    pairs = np.concatenate([np.asarray(p, dtype=np.int64).reshape(-1, 2)
                            for p in (contacts.crossing, contacts.coplanar_opposite, contacts.contact)])
    touches_rest = is_sheet[pairs[:, 0]] != is_sheet[pairs[:, 1]]
    rest_crossing = ~is_sheet[pairs[:, 0]] & ~is_sheet[pairs[:, 1]]
    if touches_rest.any() or np.any(rest_crossing[:len(contacts.crossing)]):
        return None                                   # a sheet pokes through the rest, or the rest crosses itself
    labels, n_shells = shell_labels(rest, len(v))
    inside = fins = inside_faces = fin_faces = 0
    inside_area = fin_area = 0.0
    for p in taken.tolist():                          # bounded by max_pieces
        members = np.flatnonzero(piece == p)
        best = members[int(np.argmax(area[members]))]
        if not area[best] > 0:
            return None
        point = v[f[best]].mean(axis=0)
        w = _shell_windings(point, v, rest, labels, n_shells)
        rounded = np.round(w)
        if np.any(np.abs(w - rounded) > _WINDING_SLACK) or np.any(np.abs(rounded) > 1):
            return None
        depth, total = int(np.count_nonzero(rounded)), int(rounded.sum())
        sheet_area = float(area[members].sum()) * (1 + 1e-12)
        if total == 1 and depth % 2 == 1:
            inside, inside_faces, inside_area = inside + 1, inside_faces + len(members), inside_area + sheet_area
        elif total == 0 and depth % 2 == 0:
            fins, fin_faces, fin_area = fins + 1, fin_faces + len(members), fin_area + sheet_area
        else:
            return None                               # the file's winding and the nesting depth disagree
    return OpenSheets(faces=rest, inside=inside, fins=fins, inside_faces=inside_faces, fin_faces=fin_faces,
                      inside_area=inside_area, fin_area=fin_area)
