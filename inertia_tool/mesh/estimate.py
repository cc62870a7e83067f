"""A bounded estimate of the solid behind an open or broken surface.

When the file does not define a solid (holes, cracks, leftover fragments), no number is exact; the honest
answer is an estimate with bounds.  Two estimators, each returning moments and an uncertainty:

* :func:`patched_estimate` — close every boundary loop by a cone (a fan of triangles) to the centroid of the
  loop's vertices and integrate the closed result exactly.  The boundary of a triangle 2-chain is a 1-cycle,
  so the cones always close it.  **Assumption: the missing surface of each hole lies within the ball
  enclosing the hole's rim** (:func:`enclosing_balls`, close to the smallest such ball; for a round hole in
  a smooth part this is the ball whose great circle is the rim, which holds any cap up to a hemisphere).
  The cone lies in the rim's convex hull, inside the same ball, so the closed cycle "cone minus missing
  surface" lies in the ball and its winding number — the difference between the patched solid and the true
  one — vanishes outside it.  **Second assumption: the missing surface strays from the plane of a face
  beside the hole no farther than the rim does** (:func:`hole_doubt_volumes`); the cone does too, so each
  ball is cut to that slab, and the volume in doubt is the total volume of the cut balls.  The convex hull of the
  rim is *not* enough (a planar rim has a hull of volume 0, yet a spherical cap over it is far from flat),
  and no hole gets a bound of 0.  **Third assumption, for a hole across one crease of a faceted part: the
  missing surface lies in the two planes that hold its rim** (:func:`crease_fills`): each plane's part of
  the rim is filled in that plane instead of by the cone, and the ball is cut to both slabs.  Seams sealed
  first (cracks, T-junctions; :mod:`~.seal`) add the volume of the parallel bodies of the faces sealing
  touched.
* :func:`winding_estimate` — for soups (no surface with holes to patch): the generalized winding number
  ``w`` (``winding.py``) on a regular grid of cells.  **Assumption: the solid is the set where ``w > 1/2``**
  (Jacobson et al.'s definition for soups); cells with ``w > 1/2`` are material and integrated exactly as
  cubes.  Cells that the surface passes through count as half material, half of their volume in doubt
  (their true share lies between 0 and 1; ``w`` is not evaluated there); cells whose ``w`` is ambiguous
  (between ``w_low`` and ``w_high``, or whose evaluation error bound could cross 1/2) could go either way;
  their volume bounds the discretization error.  With libigl, ``w`` is evaluated only at cells near a hole:
  elsewhere it is the integer winding number of the surface closed by cones over its holes, constant on each
  region of cells no surface crosses, less the cones' share, which a distance bound keeps below the margin
  of every threshold (:func:`_closed_part_numbers`), so those cells are decided as the exact ``w`` would be.

An estimate whose bound is not finite, or whose mass bound exceeds ``ESTIMATE_MAX_MASS_RTOL`` (50 %), or
that encloses no positive volume, is refused (:func:`check_useful`): a printed mass "within ±297 %" helps
no one.

The mass-property bounds (see :class:`Uncertainty`): ``mass`` relative, ``center_of_mass`` as a distance in m,
``inertia`` relative in the Frobenius norm.  With ``δV`` the volume in doubt, ``V`` the estimate, ``D`` the
largest distance from the centre of mass to a point of the doubtful region and ``J = ‖I/ρ‖_F``:
``δm/m = δV/V``, ``δc = δV·D/(V − δV)`` and ``δI/I = (√2 δV D² + (V + δV) δc² · √6) / J`` (a point mass
``δV`` at distance ``D`` has ``‖I‖_F = √2 δV D²``; the shift of the centre adds the parallel-axis term).
The winding estimate sums over its doubtful cells instead (``δV·D → Σ δV_u r_u``, ``δV·D² → Σ δV_u r_u²``,
``r_u`` the distance from the centroid to the farthest point of cell ``u``): the same argument cell by cell,
never wider, and much narrower when most doubt lies near the centre.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import InvalidMeshError
from ..tolerances import ESTIMATE_MAX_MASS_RTOL
from ..values import frozen_value
from .edges import edge_keys
from .seal import Seal
from ..rounding import round_up

__all__ = ["Uncertainty", "Estimate", "boundary_edges", "patched_estimate", "winding_estimate", "uncertainty_from",
           "enclosing_balls", "check_useful", "hole_doubt_volumes", "ball_slab_volume", "crease_fills", "CreaseFill",
           "closed_surface_estimate"]


@frozen_value
class Uncertainty:
    """Bounds on mass properties that are estimated rather than exact.

    Attributes
    ----------
    mass : float
        Relative bound on mass (and volume): the true value lies within ``mass · m`` of the reported ``m``.
    center_of_mass : float
        Bound on the distance between the true and the reported centre of mass, m.
    inertia : float
        Relative bound on the inertia tensor about the centre of mass, Frobenius norm.
    volume_in_doubt : float
        m³ of space that may or may not be material.
    """

    mass: float
    center_of_mass: float
    inertia: float
    volume_in_doubt: float


@frozen_value
class Estimate:
    """Unit-density moments of an estimated solid with their bounds.

    Attributes
    ----------
    volume : float
        m³.
    centroid : (3,) float
        m, mesh axes.
    second_moment : (3, 3) float
        ``∫ (x−c)(x−c)ᵀ dV`` about the centroid, m⁵, mesh axes.
    area : float
        Area of the surface as given (before any patch), m².
    uncertainty : Uncertainty
    method : str
        ``"patched"`` or ``"winding"``.
    detail : str
        One line on what was done (loops patched, grid size).
    vertices, faces : arrays
        The closed surface integrated (the patched mesh), or the input for the winding estimate.
    far : float
        Largest distance from ``centroid`` to the region in doubt, m (enters the bounds).
    """

    volume: float
    centroid: np.ndarray
    second_moment: np.ndarray
    area: float
    uncertainty: Uncertainty
    method: str
    detail: str
    vertices: np.ndarray
    faces: np.ndarray
    far: float = 0.0


def uncertainty_from(volume: float, centroid: np.ndarray, second_moment: np.ndarray, doubt: float,
                     far: float, *, first_doubt: float | None = None,
                     second_doubt: float | None = None) -> Uncertainty:
    """Bounds from ``doubt`` m³ of undecided space lying within ``far`` m of the centroid (formulas above).

    ``first_doubt`` (m⁴) and ``second_doubt`` (m⁵), when given, replace ``doubt · far`` and ``doubt · far²``:
    bounds on ``∫ |x − c| d|ν|`` and ``∫ |x − c|² d|ν|`` for the difference ``ν`` between the true and the
    estimated material, summed cell by cell (never larger than the products, often much smaller).
    """
    if not volume > 0:
        return Uncertainty(np.inf, np.inf, np.inf, float(doubt))
    inertia = np.trace(second_moment) * np.eye(3) - second_moment
    norm = float(np.linalg.norm(inertia))
    rel_mass = doubt / volume
    first = doubt * far if first_doubt is None else min(first_doubt, doubt * far)
    second = doubt * far ** 2 if second_doubt is None else min(second_doubt, doubt * far ** 2)
    shift = first / (volume - doubt) if doubt < volume else np.inf
    rel_inertia = (np.sqrt(2) * second + (volume + doubt) * shift ** 2 * np.sqrt(6)) / norm \
        if norm > 0 else np.inf
    return Uncertainty(mass=float(rel_mass), center_of_mass=float(shift), inertia=float(rel_inertia),
                       volume_in_doubt=float(doubt))


def boundary_edges(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """Net boundary of the surface as directed edges ``a→b`` with multiplicity, (k, 2) int.

    Each undirected edge contributes ``|#(a→b) − #(b→a)|`` copies in its net direction: the boundary 1-chain,
    which is balanced at every vertex (a union of closed loops).
    """
    n = np.int64(max(int(n_vertices), 1))
    key, forward = edge_keys(faces, n_vertices)
    sign = np.where(forward, -1, 1)
    unique, inverse = np.unique(key, return_inverse=True)
    net = np.bincount(inverse.reshape(-1), weights=sign, minlength=len(unique)).astype(np.int64)
    pick = net != 0
    lo, hi, k = unique[pick] // n, unique[pick] % n, net[pick]
    start = np.where(k > 0, lo, hi)
    end = np.where(k > 0, hi, lo)
    reps = np.abs(k)
    return np.stack([np.repeat(start, reps), np.repeat(end, reps)], axis=1)


def _loops(edges: np.ndarray, n_vertices: int, faces: np.ndarray | None = None,
           vertices: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """Loop of each boundary edge: the cycles of the boundary, separated at pinch vertices where ``faces`` tell
    how (else the components of edges connected through shared vertices).

    At a vertex where two holes meet (in-degree 2 or more), the fans of faces around it tell which in-edge
    continues into which out-edge: a fan starts with an out-edge and ends with an in-edge, each next to a
    different hole, so a hole's rim runs from the in-edge of one fan into the out-edge of the next fan around
    the vertex (with two fans, the other one; with more, the next by the angle of their out-edges about the
    vertex normal).  Each cycle then gets its own cone, and two cones never share an edge
    (a shared apex edge would be non-manifold, and send the patched surface to the boolean union).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    k = len(edges)
    if k == 0:
        return np.zeros(0, dtype=np.int64), 0
    n = max(int(n_vertices), 1)
    in_deg = np.bincount(edges[:, 1], minlength=n)
    pinch = in_deg > 1
    nxt = _successors(edges, n)
    if faces is not None and vertices is not None and pinch.any():
        paired = _pinch_successors(edges, faces, n, pinch, vertices)
        if paired is not None:
            nxt = np.where(paired >= 0, paired, nxt)
    if (nxt < 0).any():       # no consistent pairing: components through shared vertices
        graph = coo_matrix((np.ones(k, dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n))
        _, vertex_label = connected_components(graph, directed=False)
        _, label = np.unique(vertex_label[edges[:, 0]], return_inverse=True)
        return label.reshape(-1), int(label.max()) + 1
    graph = coo_matrix((np.ones(k, dtype=np.int8), (np.arange(k), nxt)), shape=(k, k))
    count, label = connected_components(graph, directed=False)
    return label.astype(np.int64), int(count)


def _successors(edges: np.ndarray, n: int) -> np.ndarray:
    """For each edge a→b, an edge leaving b (the only one where b is not a pinch); -1 where none."""
    order = np.argsort(edges[:, 0], kind="stable")
    first = np.searchsorted(edges[order, 0], edges[:, 1])
    ok = (first < len(edges)) & (edges[order[np.minimum(first, len(edges) - 1)], 0] == edges[:, 1])
    return np.where(ok, order[np.minimum(first, len(edges) - 1)], -1)


def _pinch_successors(edges: np.ndarray, faces: np.ndarray, n: int, pinch: np.ndarray,
                      vertices: np.ndarray) -> np.ndarray | None:
    """Successor of each in-edge at a pinch vertex (-1 for the others), from the fans around the vertex; None
    when the fans do not give one in- and one out-edge each (then the caller keeps whole components)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = np.asarray(faces, dtype=np.int64)
    corner_hit = pinch[f]
    fi, ci = np.nonzero(corner_hit)                      # (face, corner) at a pinch vertex
    p = f[fi, ci]
    nxt_v, prv_v = f[fi, (ci + 1) % 3], f[fi, (ci + 2) % 3]   # face = (p, nxt, prv): edges p→nxt, prv→p
    # fans: (p, face) nodes joined through the spokes (p, z) they share
    node = np.arange(len(fi))
    spoke = np.concatenate([p * n + nxt_v, p * n + prv_v])
    owner = np.concatenate([node, node])
    order = np.argsort(spoke, kind="stable")
    same = spoke[order][1:] == spoke[order][:-1]
    a, b = owner[order][:-1][same], owner[order][1:][same]
    graph = coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(len(fi), len(fi)))
    _, fan = connected_components(graph, directed=False)
    # the fan of each boundary edge at a pinch: out-edge p→y lies in the face (p, y, ·); in-edge x→p in (p, ·, x)
    out_key = p * n + nxt_v
    in_key = p * n + prv_v
    e_out = np.flatnonzero(pinch[edges[:, 0]])
    e_in = np.flatnonzero(pinch[edges[:, 1]])
    fan_out = _lookup(out_key, fan, edges[e_out, 0] * n + edges[e_out, 1])
    fan_in = _lookup(in_key, fan, edges[e_in, 1] * n + edges[e_in, 0])
    if fan_out is None or fan_in is None:
        return None
    # fans in turn around the vertex (angle of their out-edge about the vertex normal, the faces' winding
    # sense): a fan runs from its out-edge to its in-edge, then comes a hole, then the next fan's out-edge
    normal = np.zeros((n, 3))
    area = np.cross(vertices[nxt_v] - vertices[p], vertices[prv_v] - vertices[p])
    np.add.at(normal, p, area)
    nrm = normal[edges[e_out, 0]]
    trial = np.where(np.abs(nrm[:, :1]) < 0.9 * np.linalg.norm(nrm, axis=1, keepdims=True), [[1.0, 0, 0]],
                     [[0, 1.0, 0]])
    u = np.cross(nrm, trial)
    w = np.cross(nrm, u)
    d = vertices[edges[e_out, 1]] - vertices[edges[e_out, 0]]
    angle_by_fan = np.zeros(len(fi))
    angle_by_fan[fan_out] = np.arctan2(np.einsum("ij,ij->i", d, w), np.einsum("ij,ij->i", d, u))
    oi = np.lexsort((angle_by_fan[fan_in], edges[e_in, 1]))
    oo = np.lexsort((angle_by_fan[fan_out], edges[e_out, 0]))
    vin, vout = edges[e_in[oi], 1], edges[e_out[oo], 0]
    if len(vin) != len(vout) or (vin != vout).any() or (fan_in[oi] != fan_out[oo]).any():
        return None           # not one in- and one out-edge per fan
    start = np.r_[0, np.flatnonzero(vin[1:] != vin[:-1]) + 1]
    size = np.diff(np.r_[start, len(vin)])
    rank = np.arange(len(vin)) - np.repeat(start, size)
    target = np.repeat(start, size) + (rank + 1) % np.repeat(size, size)
    succ = np.full(len(edges), -1, dtype=np.int64)
    succ[e_in[oi]] = e_out[oo][target]
    return succ


def _lookup(keys: np.ndarray, values: np.ndarray, query: np.ndarray) -> np.ndarray | None:
    """values[i] for the unique i with keys[i] == query (each query once); None if one is missing or repeated."""
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    pos = np.searchsorted(sk, query)
    if len(query) and (pos.max(initial=0) >= len(sk)):
        return None
    if not (sk[pos] == query).all():
        return None
    dup = np.searchsorted(sk, query, side="right") - pos
    if (dup != 1).any():
        return None
    found: np.ndarray = values[order[pos]]
    return found


def enclosing_balls(points: np.ndarray, group: np.ndarray, n_groups: int, *, iterations: int = 400
                    ) -> tuple[np.ndarray, np.ndarray]:
    """A ball enclosing each group of points: centres (g, 3) m and radii (g,) m.

    The centre is found by Bădoiu and Clarkson's iteration (step towards the farthest point by ``1/(k+1)``),
    started at the centre of the group's bounding box and run for ``iterations`` steps on all groups at
    once; the radius is then the exact largest distance from that centre, so every ball encloses its group
    whatever the iteration reached (it converges to the smallest enclosing ball: after ``k`` steps the radius
    is within a factor ``1 + O(1/√k)`` of the smallest).
    """
    p = np.asarray(points, dtype=np.float64)
    g = np.asarray(group, dtype=np.int64)
    order = np.argsort(g, kind="stable")
    p, g = p[order], g[order]
    starts = np.searchsorted(g, np.arange(n_groups))
    size = np.diff(np.r_[starts, len(p)])
    lo = np.minimum.reduceat(p, starts, axis=0)
    hi = np.maximum.reduceat(p, starts, axis=0)
    centre = 0.5 * (lo + hi)
    small = size <= 3
    if small.any():           # one, two or three points: the smallest ball in closed form
        centre[small] = _small_ball_centres(p, starts[small], size[small])
    big = np.flatnonzero(~small)
    if len(big):              # Bădoiu–Clarkson on the larger groups only
        pick = np.repeat(starts[big], size[big]) + (np.arange(int(size[big].sum()))
                                                    - np.repeat(np.cumsum(size[big]) - size[big], size[big]))
        q, local = p[pick], np.repeat(np.arange(len(big)), size[big])
        local_starts = np.r_[0, np.cumsum(size[big])[:-1]]
        c = centre[big]
        index = np.arange(len(q))
        for k in range(1, iterations + 1):
            d = np.einsum("ij,ij->i", q - c[local], q - c[local])
            top = np.maximum.reduceat(d, local_starts)
            far = np.minimum.reduceat(np.where(d >= top[local], index, len(q)), local_starts)
            c = c + (q[far] - c) / (k + 1)
        centre[big] = c
    radius = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", p - centre[g], p - centre[g]), starts))
    return centre, radius


def _small_ball_centres(p: np.ndarray, starts: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Centres of the smallest balls around groups of 1–3 consecutive points of ``p`` (the radius is taken
    afterwards as the largest distance, so round-off here cannot make a ball miss a point)."""
    a = p[starts]
    b = p[starts + np.minimum(size - 1, 1)]
    c = p[starts + np.minimum(size - 1, 2)]
    centre: np.ndarray = 0.5 * (a + b)             # one or two points: the midpoint
    tri = size == 3
    if tri.any():
        a3, b3, c3 = a[tri], b[tri], c[tri]
        sides = np.stack([np.linalg.norm(b3 - c3, axis=1), np.linalg.norm(c3 - a3, axis=1),
                          np.linalg.norm(a3 - b3, axis=1)], axis=1)
        longest = np.argmax(sides, axis=1)
        ends = np.stack([0.5 * (b3 + c3), 0.5 * (c3 + a3), 0.5 * (a3 + b3)], axis=1)
        mid = ends[np.arange(len(a3)), longest]
        # circumcentre (a + (|u|²(v × w)... ) with u = b − a, v = c − a, w = u × v)
        u, v = b3 - a3, c3 - a3
        w = np.cross(u, v)
        ww = np.einsum("ij,ij->i", w, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            circ = a3 + (np.einsum("ij,ij->i", u, u)[:, None] * np.cross(v, w)
                         + np.einsum("ij,ij->i", v, v)[:, None] * np.cross(w, u)) / (2 * ww[:, None])
        la, lb, lc = sides[:, 0] ** 2, sides[:, 1] ** 2, sides[:, 2] ** 2
        obtuse = (la >= lb + lc) | (lb >= la + lc) | (lc >= la + lb) | ~(ww > 0)
        centre[tri] = np.where(obtuse[:, None], mid, circ)
    return centre


def ball_slab_volume(radius: np.ndarray, offset: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """Volume of the part of a ball that lies in a slab, (k,) m³.

    The ball has radius ``r``; the slab is the set of points whose signed distance from a plane lies in
    ``[−t, t]`` (``t = half_width``), and the ball's centre is at signed distance ``s = offset`` from that plane.
    In the ball's own axial coordinate ``z`` the slab is ``[−t − s, t − s]``; clipped to ``[−r, r]`` it is
    ``[a, b]``, and the volume is ``π ∫_a^b (r² − z²) dz = π [r² z − z³/3]_a^b`` (slices of a ball are discs).
    """
    r = np.asarray(radius, dtype=np.float64)
    lo = np.clip(-np.asarray(half_width) - np.asarray(offset), -r, r)
    hi = np.clip(np.asarray(half_width) - np.asarray(offset), -r, r)
    volume: np.ndarray = np.maximum(np.pi * ((r ** 2 * hi - hi ** 3 / 3.0) - (r ** 2 * lo - lo ** 3 / 3.0)), 0.0)
    return volume


def hole_doubt_volumes(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray,
                       n_loops: int, centre: np.ndarray, radius: np.ndarray, vertex_of: np.ndarray,
                       loop_of: np.ndarray) -> np.ndarray:
    """Volume in doubt of each hole (boundary loop), (n_loops,) m³: the ball over its rim, cut to a slab.

    Two assumptions, both about the missing surface ``M`` of the hole (the surface the file lost):

    1. ``M`` lies in the ball enclosing the rim (module docstring), and
    2. ``M`` strays from the plane of a face beside the hole no farther than the rim itself does: of the faces
       sharing an edge with the rim (the *ring*), take the one whose plane the rim is closest to; if every rim
       vertex is within ``e`` of that plane, so is ``M``.  A hole inside a flat face of a part (a missing
       triangle of a CAD face) has ``e`` ≈ 0; a hole in a curved surface has ``e`` of the order of its sagitta
       (for a spherical cap of half-angle α the ring plane is tilted by about α and the rim's far side lies
       ``2r sin α`` from it, more than the cap's height ``r tan(α/2)`` above the rim's own plane); a hole
       across a crease has ``e`` up to its width, and the ball decides.  It fails for a hole that swallowed a
       whole boss or dimple standing on a flat face (the ring is flat, the missing part is not): the stated
       limit of this bound.

    The cone that patches the hole has its apex at the centroid of the rim vertices, so it lies in the rim's
    convex hull, inside both the ball and the slab of half-width ``e`` around the plane (a convex set holding
    every rim vertex).  The patched and the true solid therefore differ only where the cycle "cone minus
    ``M``" winds, which is inside ball ∩ slab: its volume (:func:`ball_slab_volume`) is the hole's volume in
    doubt.  ``e`` carries a round-off margin of 16 ulp of the coordinates, so an exactly flat hole still
    states a (tiny) positive bound.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        The surface with the holes (sealed where seams were sealed).
    edges : (k, 2) int
        Its boundary edges; ``label`` (k,) the loop of each.
    centre, radius : (n_loops, 3), (n_loops,) float
        The ball enclosing each loop's rim (:func:`enclosing_balls`).
    vertex_of, loop_of : (p,) int
        The distinct (vertex, loop) pairs of the rims.
    """
    v = np.asarray(vertices, dtype=np.float64)
    ball: np.ndarray = 4.0 / 3.0 * np.pi * np.asarray(radius, dtype=np.float64) ** 3
    n = len(v)
    nv = np.int64(max(n, 1))
    key, _ = edge_keys(faces, n)
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    order = np.argsort(rim_key, kind="stable")
    sorted_rim = rim_key[order]
    pos = np.searchsorted(sorted_rim, key)
    hit = (pos < len(sorted_rim)) & (sorted_rim[np.minimum(pos, len(sorted_rim) - 1)] == key)
    slot = np.flatnonzero(hit)
    if not len(slot):
        return ball
    ring_face = slot // 3
    ring_loop = label[order[pos[slot]]]
    # one (face, loop) pair per ring face of each loop
    pair = np.unique(np.stack([ring_face, ring_loop], axis=1), axis=0)
    ring_face, ring_loop = pair[:, 0], pair[:, 1]
    a, b, c = (v[faces[ring_face, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    length = np.linalg.norm(normal, axis=1)
    usable = length > 0
    ring_face, ring_loop, a, normal = ring_face[usable], ring_loop[usable], a[usable], normal[usable]
    if not len(ring_face):
        return ball
    unit = normal / length[usable, None]
    # the farthest rim vertex of each loop from each of its ring faces' planes; (ring face, rim vertex)
    # pairs are formed loop by loop (rims are short next to the surface, so this stays small)
    rim_order = np.argsort(loop_of, kind="stable")
    rim_loop, rim_vertex = loop_of[rim_order], vertex_of[rim_order]
    rim_start = np.searchsorted(rim_loop, np.arange(n_loops))
    rim_count = np.diff(np.r_[rim_start, len(rim_loop)])
    per_face = rim_count[ring_loop]
    if int(per_face.sum()) > RING_WORK_LIMIT:
        return ball
    e_face = np.zeros(len(ring_face))
    ends = np.cumsum(per_face)
    lo = 0
    while lo < len(ring_face):          # ring faces in chunks of about RING_CHUNK (face, vertex) pairs
        hi = max(lo + 1, int(np.searchsorted(ends, ends[lo] - per_face[lo] + RING_CHUNK, side="right")))
        hi = min(hi, len(ring_face))
        count = per_face[lo:hi]
        which = lo + np.repeat(np.arange(hi - lo), count)
        offset_in = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        pts = v[rim_vertex[rim_start[ring_loop[which]] + offset_in]]
        dist = np.abs(np.einsum("ij,ij->i", pts - a[which], unit[which]))
        e_face[lo:hi] = np.maximum.reduceat(dist, np.r_[0, np.cumsum(count)[:-1]])
        lo = hi
    best = np.full(n_loops, np.inf)
    np.minimum.at(best, ring_loop, e_face)
    choice = np.full(n_loops, -1, dtype=np.int64)
    is_best = e_face <= best[ring_loop]
    choice[ring_loop[is_best]] = np.flatnonzero(is_best)
    has = choice >= 0
    scale = float(np.max(np.abs(v))) if n else 0.0
    margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
    doubt: np.ndarray = ball.copy()
    k = choice[has]
    offset = np.einsum("ij,ij->i", centre[has] - a[k], unit[k])
    doubt[has] = np.minimum(ball[has], ball_slab_volume(radius[has], offset, best[has] + margin))
    return doubt


@frozen_value
class CreaseFill:
    """A hole across one crease of a faceted part, filled in the two planes that hold its rim.

    Attributes
    ----------
    loop : int
        The boundary loop.
    apexes : (2, 3) float
        The centroid of each planar part of the rim (with the two ends of the crease segment), m.
    caps : (k, 3) int
        The fill's triangles: each rim edge with the apex of its plane (index ``n_vertices + 0`` or ``+ 1`` of
        the caller's numbering, shifted by the caller), and the two triangles over the crease segment.
    doubt : float
        Volume in doubt, m³: the ball over the rim cut to the slab of each plane, summed.
    """

    loop: int
    apexes: np.ndarray
    caps: np.ndarray
    doubt: float


#: Most distinct planes of the faces beside one rim tried in pairs by :func:`crease_fills`.
CREASE_MAX_PLANES = 8
#: Most loops :func:`crease_fills` examines (one at a time, ~0.1 ms each).
CREASE_MAX_LOOPS = 5000


def crease_fills(vertices: np.ndarray, faces: np.ndarray, edges: np.ndarray, label: np.ndarray, n_loops: int,
                 centre: np.ndarray, radius: np.ndarray) -> list[CreaseFill]:
    """Holes across one crease, each filled by two planar fans instead of one cone (the third assumption).

    A hole that took triangles from two flat faces of a faceted part meeting at a crease (a box's edge, a
    cylinder's cap rim) has a rim that no one plane holds, so one slab cannot cut its ball.  It qualifies here
    when two planes of faces beside it (the ring) hold the rim this way: each holds three rim vertices not on
    a line (a two-dimensional part of the rim, not an edge: the octahedron's faces hold only an edge each),
    every rim edge lies in one of them and none in both, and walking the rim the plane changes exactly twice,
    at two vertices ``a`` and ``b`` lying on both (on the crease).  **Assumption: the missing surface lies in
    those two planes** (the hole is a piece of the two faces it crosses), as far from each as the rim part it
    holds (``e₁``, ``e₂``, plus 16 ulp of the coordinates).  Each planar part of the rim, closed by the crease
    segment ``a–b``, is filled by a fan to the centroid of its vertices; the two fans share ``a–b`` with
    opposite windings, so the fill has exactly the rim as boundary.  A 2-chain in a plane is fixed by its
    boundary, so where the assumption holds exactly the fill *is* the missing surface; in general the cycle
    "fill − missing surface" lies in the ball over the rim (assumption 1; the fans lie in the rim's convex hull)
    cut to the union of the two slabs, whose complement is connected (each piece of the ball between the slabs
    reaches its sphere), so the winding number of the cycle vanishes outside it: the volume in doubt is at most
    the sum of the ball's two slab volumes (:func:`ball_slab_volume`).  Loops of at least four edges are tried,
    at most ``CREASE_MAX_LOOPS`` of them (beyond, every hole keeps its cone).

    Returns
    -------
    list of CreaseFill
        The loops that qualify (others keep their cone).
    """
    from itertools import combinations

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    n = len(v)
    scale = float(np.max(np.abs(v))) if n else 0.0
    margin = 16.0 * np.finfo(np.float64).eps * max(scale, 1e-300)
    on_tol = 4.0 * margin                        # a rim vertex "on" a plane: within round-off of it
    candidates = np.flatnonzero(np.bincount(label, minlength=n_loops) >= 4).tolist()
    if not candidates or len(candidates) > CREASE_MAX_LOOPS:
        return []
    nv = np.int64(max(n, 1))
    rim_key = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * nv + np.maximum(edges[:, 0], edges[:, 1])
    key, _ = edge_keys(f, n)
    hit = np.isin(key, rim_key[np.isin(label, candidates)])
    face_loop: dict[int, set[int]] = {}
    rim_lookup = dict(zip(rim_key.tolist(), label.tolist()))
    for slot in np.flatnonzero(hit).tolist():
        face_loop.setdefault(rim_lookup[int(key[slot])], set()).add(slot // 3)
    out = []
    for k in candidates:
        raw = edges[label == k]
        succ = dict(zip(raw[:, 0].tolist(), raw[:, 1].tolist()))
        if len(succ) != len(raw) or len(raw) < 4:
            continue                              # a vertex met twice (a pinch), or too short to cross a crease
        walk = [int(raw[0, 0])]                   # the rim in its own order (one cycle, else skipped)
        while len(walk) <= len(raw) and succ.get(walk[-1], walk[0]) != walk[0]:
            walk.append(succ[walk[-1]])
        if len(walk) != len(raw):
            continue
        loop_edges = np.array([[x, succ[x]] for x in walk], dtype=np.int64)
        ring = np.array(sorted(face_loop.get(k, ())), dtype=np.int64)
        if not len(ring):
            continue
        a0 = v[f[ring, 0]]
        normal = np.cross(v[f[ring, 1]] - a0, v[f[ring, 2]] - a0)
        length = np.linalg.norm(normal, axis=1)
        keep = length > 0
        if not keep.any():
            continue
        unit, a0 = normal[keep] / length[keep, None], a0[keep]
        offset = np.einsum("ij,ij->i", unit, a0)
        rim = np.array(list(succ), dtype=np.int64)
        dist = np.abs(v[rim] @ unit.T - offset[None, :])          # (rim vertex, ring face)
        on = dist <= on_tol
        # distinct planes: ring faces holding the same rim vertices within round-off of one plane
        _, first = np.unique(on.T, axis=0, return_index=True)
        planes = [int(p) for p in first if np.count_nonzero(on[:, p]) >= 3]
        if len(planes) < 2 or len(planes) > CREASE_MAX_PLANES:
            continue
        index = {int(x): i for i, x in enumerate(rim.tolist())}
        found = None
        for p, q in combinations(planes, 2):
            if abs(float(unit[p] @ unit[q])) > 1.0 - 1e-9:
                continue                          # parallel planes meet in no crease
            in_p, in_q = on[:, p], on[:, q]
            if not (in_p | in_q).all():
                continue
            if any(np.linalg.matrix_rank(v[rim[m]][1:] - v[rim[m]][0], tol=on_tol) < 2 for m in (in_p, in_q)):
                continue
            side: list[int] = []
            for start, end in loop_edges.tolist():
                ep = in_p[index[start]] and in_p[index[end]]
                eq = in_q[index[start]] and in_q[index[end]]
                if ep == eq:
                    side = []
                    break                         # an edge in neither plane, or along the crease itself
                side.append(0 if ep else 1)
            if side and sum(side[i] != side[i - 1] for i in range(len(side))) == 2:
                found = (p, q, side)
                break
        if found is None:
            continue
        p, q, side = found
        order = loop_edges.tolist()
        switch = [i for i in range(len(side)) if side[i] != side[i - 1]]
        # the vertex where plane p's chain ends and q's begins (a), and where q's ends and p's begins (b)
        a = next(order[i][0] for i in switch if side[i] == 1)
        b = next(order[i][0] for i in switch if side[i] == 0)
        parts = []
        for which in (0, 1):
            ids = sorted({x for (s0, s1), sd in zip(order, side) if sd == which for x in (s0, s1)})
            parts.append(v[ids].mean(axis=0))
        apexes = np.array(parts)
        caps = [[e1, e0, n + sd] for (e0, e1), sd in zip(order, side)]
        # p's chain runs b → … → a and closes along a → b; q's runs a → … → b and closes along b → a
        caps += [[b, a, n + 0], [a, b, n + 1]]
        doubt = 0.0
        for which, plane in ((0, p), (1, q)):
            chain = [index[x] for (s0, s1), sd in zip(order, side) if sd == which for x in (s0, s1)]
            half = float(dist[chain, plane].max()) + margin
            centre_offset = float(centre[k] @ unit[plane] - offset[plane])
            doubt += float(ball_slab_volume(np.array([radius[k]]), np.array([centre_offset]),
                                            np.array([half]))[0])
        out.append(CreaseFill(loop=int(k), apexes=apexes, caps=np.array(caps, dtype=np.int64), doubt=doubt))
    return out


#: Most (ring face, rim vertex) pairs measured by :func:`hole_doubt_volumes` (a few seconds); beyond it every
#: hole keeps its whole ball (a bound that needs no ring).
RING_WORK_LIMIT = 200_000_000
#: (ring face, rim vertex) pairs measured at once (bounds the memory: ~100 MB).
RING_CHUNK = 2_000_000


def check_useful(estimate_volume: float, unc: Uncertainty, *, source: str, what: str,
                 why: str = "the holes are too large to guess what fills them; close them in a mesh editor",
                 max_mass_rtol: float = ESTIMATE_MAX_MASS_RTOL) -> None:
    """Refuse an estimate that encloses no positive volume or whose bounds say nothing.

    Raises
    ------
    InvalidMeshError
        When ``estimate_volume`` is not positive, a bound is not finite, or the relative mass bound exceeds
        ``max_mass_rtol``; the message says why and what to do.
    """
    if not estimate_volume > 0:
        raise InvalidMeshError(f"{source}: {what} encloses a volume of {estimate_volume:.3g} m³ (expected a "
                               "positive one): the surface does not bound a solid even after repair; close it "
                               "in a mesh editor, or for a sheet use the shell model with a wall `thickness`")
    bounds = (unc.mass, unc.center_of_mass, unc.inertia)
    if not all(np.isfinite(b) for b in bounds) or unc.mass > max_mass_rtol:
        mass = f"±{round_up(100 * unc.mass):.3g} %" if np.isfinite(unc.mass) else "unbounded"
        com = f"within {round_up(unc.center_of_mass):.3g} m" if np.isfinite(unc.center_of_mass) else "unbounded"
        raise InvalidMeshError(f"{source}: {what} cannot be bounded usefully (mass {mass}, centre of mass {com}; "
                               f"an estimate is reported only within ±{100 * max_mass_rtol:g} % mass): {why}",
                               details={"mass_bound": float(unc.mass),
                                        "center_of_mass_bound": float(unc.center_of_mass)})


def patched_estimate(vertices: np.ndarray, faces: np.ndarray, moments: Callable[..., Any], *,
                     seal: Seal | None = None) -> Estimate:
    """Close each boundary loop by a cone to its centroid and integrate; bound by the balls over the rims.

    Assumption (stated in the module docstring): the missing surface of each boundary component lies in the
    ball enclosing its rim (:func:`enclosing_balls`); the cone lies there too, so the patched solid and the
    true one differ only inside those balls; with the second assumption (the missing surface strays from the
    plane of a face beside the hole no farther than the rim does) only inside each ball's slab around that
    plane (:func:`hole_doubt_volumes`), whose total volume is the volume in doubt.  With ``seal``, the seams it
    sealed add their own doubt (:mod:`~.seal`).  Limits: a hole whose missing piece joins two rims (a band
    round a handle) or reaches far outside its rim's ball (a pocket swallowed whole) is not covered.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        Consistently oriented where possible (see ``orient.py``); the sign of the total decides outward.
    moments : callable
        ``moments(vertices, faces) -> VolumeMoments`` (the exact integrator, ``volume.volume_moments``).
    seal : Seal, optional
        How ``faces`` were sealed from the input (their slack enters the bound).

    Returns
    -------
    Estimate
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    edges = seal.boundary if seal is not None else boundary_edges(f, len(v))
    label, n_loops = _loops(edges, len(v), f, v) if len(edges) else (np.zeros(0, dtype=np.int64), 0)
    # the distinct vertices of each loop, grouped: (loop, vertex) pairs sorted by loop
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0) if n_loops \
        else np.zeros((0, 2), dtype=np.int64)
    loop_of, vertex_of = pairs[:, 0], pairs[:, 1]
    size = np.bincount(loop_of, minlength=n_loops)
    apex = np.zeros((n_loops, 3))
    for i in range(3):
        apex[:, i] = np.bincount(loop_of, weights=v[vertex_of, i], minlength=n_loops) / np.maximum(size, 1)
    creases: list[CreaseFill] = []
    if n_loops:
        centre, radius = enclosing_balls(v[vertex_of], loop_of, n_loops)
        hole_doubt = hole_doubt_volumes(v, f, edges, label, n_loops, centre, radius, vertex_of, loop_of)
        creases = crease_fills(v, f, edges, label, n_loops, centre, radius)
    else:
        centre, radius, hole_doubt = np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    cap = np.stack([edges[:, 1], edges[:, 0], len(v) + label], axis=1) if n_loops else np.zeros((0, 3), np.int64)
    extra = np.zeros((0, 3))
    if creases:               # holes across one crease: two planar fans instead of the cone (third assumption)
        crossed = np.zeros(n_loops, dtype=bool)
        fills = []
        for j, fill in enumerate(creases):
            crossed[fill.loop] = True
            hole_doubt[fill.loop] = fill.doubt
            shifted = fill.caps.copy()
            shifted[shifted >= len(v)] += n_loops + 2 * j       # apexes after the cones' (kept for numbering)
            fills.append(shifted)
        cap = np.vstack([cap[~crossed[label]], *fills])
        extra = np.vstack([fill.apexes for fill in creases])
    doubt = float(np.sum(hole_doubt))
    pv = np.vstack([v, apex, extra])
    pf = np.vstack([f, cap])
    closed = moments(pv, pf)
    if closed.volume < 0:
        pf = pf[:, ::-1]
        closed = moments(pv, pf)
    # the surface as given: the closed surface's area less the cones' (no second pass over every face)
    ca, cb, cc = pv[cap[:, 0]], pv[cap[:, 1]], pv[cap[:, 2]]
    area = float(closed.area) - float(0.5 * np.linalg.norm(np.cross(cb - ca, cc - ca), axis=1).sum())
    far = float(np.max(np.linalg.norm(centre - closed.centroid, axis=1) + radius)) if n_loops else 0.0
    sealed = ""
    if seal is not None and (seal.welded or seal.split):
        doubt += seal.doubt(v)
        touched = seal.slack > 0
        if touched.any():
            corners = v[f[touched]]
            reach = np.linalg.norm(corners - closed.centroid, axis=2).max(axis=1) + seal.slack[touched]
            far = max(far, float(reach.max()))
        moved = round_up(float(seal.slack.max(initial=0.0)))
        sealed = (f"seams sealed ({seal.welded:,} crack vertices welded, {seal.split:,} T-junction vertices "
                  f"put on their edges, every corner within {moved:.3g} m of where it was); ")
    unc = uncertainty_from(closed.volume, closed.centroid, closed.second_moment, doubt, far)
    if n_loops:
        detail = (f"{sealed}{n_loops} boundary loop{'s' if n_loops != 1 else ''} ({len(edges):,} edges) "
                  "closed by cones to their centroids; bounded by the balls enclosing their rims, each cut to the "
                  "slab around the plane of the face beside it that the rim strays least from "
                  f"(largest radius {float(radius.max()):.3g} m)")
        if creases:
            detail += (f"; {len(creases)} of them across a crease, filled instead in the two planes that hold "
                       "the rim and bounded by the ball cut to both planes' slabs")
    else:
        detail = f"{sealed}no hole left" if sealed else "no hole"
    return Estimate(volume=closed.volume, centroid=closed.centroid, second_moment=closed.second_moment, area=area,
                    uncertainty=unc, method="patched", detail=detail, vertices=pv, faces=pf, far=far)


#: Grid resolution of the winding estimate without libigl: the numpy treecode costs a few hundred exact
#: solid angles per cell whatever the face count, so 24 cells along the longest side (~17k cells) keeps a
#: repair under a few seconds on two cores; the bounds are about 2.5 times wider than at libigl's 64.
TREECODE_RESOLUTION = 24


def _cube_moments(centres: np.ndarray, h: float,
                  weight: np.ndarray | None = None) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid and central second moment of disjoint cubes of side h, each counted ``weight`` times
    (1 when omitted; a cube counted half is half its material)."""
    wt = np.ones(len(centres)) if weight is None else np.asarray(weight, dtype=np.float64)
    vol = float(wt.sum()) * h ** 3
    c = (wt[:, None] * centres).sum(axis=0) / wt.sum()
    d = centres - c
    second = h ** 3 * ((wt[:, None] * d).T @ d) + vol * h ** 2 / 12.0 * np.eye(3)
    return vol, c, second


def _surface_cells(vertices: np.ndarray, faces: np.ndarray, lo: np.ndarray, h: float, dims: tuple[int, ...],
                   spacing: float = 0.5) -> np.ndarray:
    """(cells,) bool: every cell the surface passes through (and a thin margin around it).

    Each triangle is sampled on a barycentric grid whose sub-triangles have edges of at most
    ``δ = spacing · h``, so every point of the surface lies within ``δ`` of a sample; a cell the surface
    crosses therefore meets the cube of half-side ``δ`` around some sample, and the cells those cubes touch
    are marked (a cube no larger than a cell touches exactly the cells holding its 8 corners).
    """
    v = vertices
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    delta = spacing * h
    if 2 * delta > h:
        raise ValueError(f"expected a sample spacing of at most half a cell, got {spacing}")
    longest = np.max(np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                               np.linalg.norm(a - c, axis=1)]), axis=0)
    steps = np.maximum(1, np.ceil(longest / delta).astype(np.int64))
    limit = np.array(dims) - 1
    # the cell of each cube's lowest corner; the cube (side 2δ ≤ h) reaches at most one cell further along
    # each axis, so marking those cells and then each marked cell's 7 upper neighbours covers every cell
    # the cube touches (a superset only where a cube ends exactly on a cell face)
    low = np.zeros(int(np.prod(dims)), dtype=bool)
    from .._native import accel
    lib = accel()
    if lib is not None and int(steps.max(initial=1)) <= 1 << 20:
        # the same samples and cells in C (_accel.c section 10), without the (triangles, samples, 3) blocks
        origin = lo + delta
        lib.sample_cells(np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(faces, dtype=np.int64),
                         np.ascontiguousarray(steps, dtype=np.int64), tuple(float(x) for x in origin), float(h),
                         tuple(int(d) for d in dims), low.view(np.uint8))
        steps = steps[:0]                   # done: the numpy loop below (the fallback) has no faces left
    for n in np.unique(steps):
        sel = np.flatnonzero(steps == n)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        s, t = (i[keep] / n), (j[keep] / n)
        per = max(1, (1 << 20) // len(s))
        for k in range(0, len(sel), per):
            ids = sel[k:k + per]
            pts = (a[ids, None] * (1 - s - t)[None, :, None] + b[ids, None] * s[None, :, None]
                   + c[ids, None] * t[None, :, None]).reshape(-1, 3)
            idx = np.minimum(np.maximum(np.floor((pts - (lo + delta)) / h).astype(np.int64), 0), limit)
            low[(idx[:, 0] * dims[1] + idx[:, 1]) * dims[2] + idx[:, 2]] = True
    grid = low.reshape(dims)
    for axis in range(3):
        ahead = [slice(None)] * 3
        behind = [slice(None)] * 3
        ahead[axis], behind[axis] = slice(1, None), slice(None, -1)
        grid[tuple(ahead)] |= grid[tuple(behind)]
    marked: np.ndarray = grid.reshape(-1)
    return marked


#: Largest cone cap (triangles) for which :func:`_closed_part_numbers` is tried; beyond it (a soup whose
#: boundary is most of its edges) every free cell is evaluated.
CAP_FACES_LIMIT = 20000
#: Most boundary components for which the cells' distances to every cap are bounded.
CAP_LOOPS_LIMIT = 512
#: Most (cell, cap) pairs bounded one by one; cells beyond it are evaluated instead.
CAP_BOUND_WORK = 20_000_000
#: Most regions whose one winding number each is taken from the bounded treecode (a proven error bound, about
#: 1 ms per point at 8k faces) rather than from libigl's approximation (no proven bound).
BOUNDED_REGION_POINTS = 4096


def _cap_bound(points: np.ndarray, reach: float, ball_centre: np.ndarray, ball_radius: np.ndarray,
               cap_area: np.ndarray) -> np.ndarray:
    """(p,) bound on ``|w_C|`` at every point within ``reach`` m of each of ``points``: Σ over the cones of
    ``A / (4π s²)``, ``s`` the distance from the point to the cone's ball less ``reach`` (∞ where s ≤ 0)."""
    bound = np.zeros(len(points))
    per = max(1, (1 << 22) // max(len(points), 1))
    for k in range(0, len(ball_radius), per):
        delta = points[:, None, :] - ball_centre[None, k:k + per, :]
        gap = np.sqrt(np.einsum("pki,pki->pk", delta, delta)) - ball_radius[None, k:k + per] - reach
        with np.errstate(divide="ignore"):
            share = np.where(gap > 0, cap_area[None, k:k + per] / (4 * np.pi * np.maximum(gap, 1e-300) ** 2),
                             np.inf)
        bound += share.sum(axis=1)
    return bound


def _closed_part_numbers(vertices: np.ndarray, faces: np.ndarray, centres: np.ndarray, crossed: np.ndarray,
                         lo: np.ndarray, h: float, dims: tuple[int, ...], *, fast: bool, margin: float
                         ) -> tuple[np.ndarray, np.ndarray] | None:
    """Winding numbers of the cells far from the surface's holes without evaluating them one by one.

    Close the surface ``S`` by a cone ``C`` over each component of its boundary (apex at the centroid of the
    component's vertices; a component of the net boundary is balanced at every vertex, so the cone over it
    has exactly that boundary, reversed).  ``S + C`` is a cycle, so its winding number is an integer,
    constant on each connected region of space it does not meet, and ``w_S = w_{S+C} − w_C``.  Cells that
    neither ``S`` nor ``C`` crosses are grouped into face-connected regions (two such neighbouring cubes
    form a box that meets neither surface); ``w_{S+C}`` is found once per region, at one cell, from
    ``w_S + w_C`` rounded (refused, returning None, when that is more than 1/4 from an integer, counting the
    error bound of :func:`~.winding.winding_numbers_bounded`, used for ``w_S`` when libigl would be and there
    are at most ``BOUNDED_REGION_POINTS`` regions; ``w_C`` is the exact direct sum).  A triangle
    of area ``a`` at distance at least ``s`` subtends a solid angle of at most ``a/s²``; each cone lies in the
    ball enclosing its rim (:func:`enclosing_balls`: the apex is in the rim's convex hull), so at a cell at
    distance ``s`` from the ball ``|w_C| ≤ A_C / (4π s²)``.  Where the sum of these bounds over the cones is
    below ``margin`` (= ``min(w_low, 1 − w_high)``), the cell's ``w`` lies within ``margin`` of the region's
    integer and every threshold of :func:`winding_estimate` decides it as the exact value would: it is
    *settled* with that integer.  Every other free cell is left to the caller to evaluate.

    Returns
    -------
    settled : (cells,) bool
        Cells given a value here.
    value : (cells,) float
        The integer of each settled cell's region (0 elsewhere).
    None
        When the caps are too large to help or a region's integer is uncertain.
    """
    from scipy import ndimage
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from .winding import winding_numbers, winding_numbers_bounded

    v, f = vertices, faces
    edges = boundary_edges(f, len(v))
    if len(edges) > CAP_FACES_LIMIT:
        return None
    if len(edges):
        n = len(v)
        graph = coo_matrix((np.ones(len(edges), dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n))
        _, vertex_label = connected_components(graph, directed=False)
        _, label = np.unique(vertex_label[edges[:, 0]], return_inverse=True)
        label = label.reshape(-1)
        n_loops = int(label.max()) + 1
        if n_loops > CAP_LOOPS_LIMIT:
            return None
        pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
        size = np.bincount(pairs[:, 0], minlength=n_loops)
        apex = np.stack([np.bincount(pairs[:, 0], weights=v[pairs[:, 1], i], minlength=n_loops)
                         for i in range(3)], axis=1) / size[:, None]
        ball_centre, ball_radius = enclosing_balls(v[pairs[:, 1]], pairs[:, 0], n_loops)
        cap_v = np.vstack([v, apex])
        cap_f = np.stack([edges[:, 1], edges[:, 0], n + label], axis=1)
        ca, cb, cc = cap_v[cap_f[:, 0]], cap_v[cap_f[:, 1]], cap_v[cap_f[:, 2]]
        cap_area = np.bincount(label, weights=0.5 * np.linalg.norm(np.cross(cb - ca, cc - ca), axis=1),
                               minlength=n_loops)
        on_cap = _surface_cells(cap_v, cap_f, lo, h, dims)
    else:
        n_loops, on_cap = 0, np.zeros(len(centres), dtype=bool)
    open_cells = ~crossed & ~on_cap
    region, n_regions = ndimage.label(open_cells.reshape(dims))
    region = region.reshape(-1)
    value = np.zeros(len(centres))
    settled = np.zeros(len(centres), dtype=bool)
    if n_regions == 0:
        return settled, value
    _, first = np.unique(region, return_index=True)
    first = first[1:] if region[first[0]] == 0 else first           # one cell of each region (0 = none)
    if fast and len(first) <= BOUNDED_REGION_POINTS:
        # one point per region: the treecode's proven error bound instead of libigl's unbounded approximation
        w_s, w_err = winding_numbers_bounded(centres[first], v, f)
    else:
        w_s, w_err = winding_numbers(centres[first], v, f, fast=fast), np.zeros(len(first))
    w_c = winding_numbers(centres[first], cap_v, cap_f, fast=False) if n_loops else np.zeros(len(first))
    total = w_s + w_c
    whole = np.round(total)
    if np.any(np.abs(total - whole) + w_err > 0.25):
        return None
    cells = np.flatnonzero(open_cells)
    if n_loops:
        # first per block of 4×4×4 cells (every centre within 1.5·√3·h of the block's), then cell by cell
        # where the block's bound is not enough and the work stays within CAP_BOUND_WORK
        nb = tuple(-(-d // 4) for d in dims)
        blocks = np.stack(np.meshgrid(*[np.arange(m) for m in nb], indexing="ij"), axis=-1).reshape(-1, 3)
        block_bound = _cap_bound(lo + h * (4 * blocks + 2), 1.5 * np.sqrt(3) * h, ball_centre, ball_radius,
                                 cap_area)
        i, j, k = np.unravel_index(cells, dims)
        fine = block_bound[((i // 4) * nb[1] + j // 4) * nb[2] + k // 4] < margin
        rest = np.flatnonzero(~fine)
        if len(rest) * n_loops <= CAP_BOUND_WORK:
            fine[rest] = _cap_bound(centres[cells[rest]], 0.0, ball_centre, ball_radius, cap_area) < margin
        ok = cells[fine]
    else:
        ok = cells
    value[ok] = whole[region[ok] - 1]
    settled[ok] = True
    return settled, value


def winding_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64, w_low: float = 0.1,
                     w_high: float = 0.9, fast: bool | None = None, tolerance: float = 2e-3) -> Estimate:
    """Material where the generalized winding number exceeds 1/2, on a grid, with the doubtful cells as bounds.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    resolution : int
        Cells along the longest side of the bounding box (the grid is padded by one cell); at most
        :data:`TREECODE_RESOLUTION` without libigl.
    w_low, w_high : float
        Cells with ``w_low < w < w_high`` are doubtful, as are cells the surface passes through.
    fast : bool, optional
        libigl's evaluation (default when installed) or, with ``False`` or without libigl, the numpy
        treecode (:func:`~.winding.winding_numbers_bounded`), whose error bound per cell is honoured: a cell
        whose bound could carry its ``w`` across 1/2 from outside the doubtful band is doubtful too.
    tolerance : float
        Error allowed per cluster of the treecode (the per-cell bound is the sum over the clusters used).

    Returns
    -------
    Estimate
    """
    from .winding import fast_available, winding_numbers, winding_numbers_bounded

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    use_igl = fast_available() if fast is None else (fast and fast_available())
    n = int(resolution) if use_igl else min(int(resolution), TREECODE_RESOLUTION)
    h = float(np.max(hi - lo)) / n
    lo = lo - h
    dims = tuple(int(x) for x in np.ceil((hi + h - lo) / h).astype(np.int64))
    axes = [lo[i] + h * (np.arange(dims[i]) + 0.5) for i in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    crossed = _surface_cells(v, f, lo, h, dims)
    w = np.full(len(centres), 0.5)                  # cells the surface crosses: half material, half in doubt
    err = np.zeros(len(centres))
    free = np.flatnonzero(~crossed)
    known = _closed_part_numbers(v, f, centres, crossed, lo, h, dims, fast=use_igl,
                                 margin=min(w_low, 1.0 - w_high)) if use_igl else None
    if known is not None:
        # cells far from every cap take the integer of their component; the others are evaluated
        settled, value = known
        w[free] = value[free]
        ask = free[~settled[free]]
        w[ask] = winding_numbers(centres[ask], v, f, fast=True)
    elif use_igl:
        w[free] = winding_numbers(centres[free], v, f, fast=True)
    else:
        w[free], err[free] = winding_numbers_bounded(centres[free], v, f, tolerance=tolerance)
    if np.sum(w[w > 0.5]) < np.sum(-w[w < -0.5]):
        w = -w                                      # the surface is inside out as a whole
    material = np.where(crossed, 0.5, (w > 0.5).astype(np.float64))
    doubtful = np.where(crossed, 0.5, (((w > w_low) & (w < w_high))
                                       | (err >= min(0.5 - w_low, w_high - 0.5))).astype(np.float64))
    area = float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())
    if not np.any(material[~crossed]):
        zero = np.zeros(3)
        return Estimate(0.0, zero, np.zeros((3, 3)), area, Uncertainty(np.inf, np.inf, np.inf, 0.0), "winding",
                        "no grid cell has a winding number above 1/2", v, f)
    vol, c, second = _cube_moments(centres[material > 0], h, material[material > 0])
    doubt = float(np.sum(doubtful)) * h ** 3
    # each doubtful cell's points lie within its centre's distance + half its diagonal of the centroid; the
    # difference between true and estimated material there is at most its weight (1/2 crossed, 1 ambiguous)
    reach = np.linalg.norm(centres[doubtful > 0] - c, axis=1) + h * np.sqrt(3) / 2
    far = float(np.max(reach)) if doubtful.any() else 0.0
    cell_doubt = doubtful[doubtful > 0] * h ** 3
    unc = uncertainty_from(vol, c, second, doubt, far, first_doubt=float(np.sum(cell_doubt * reach)),
                           second_doubt=float(np.sum(cell_doubt * reach ** 2)))
    how = "libigl fast winding numbers" if use_igl else "winding numbers by a treecode with an error bound"
    detail = (f"winding number > 1/2 on a {dims[0]}×{dims[1]}×{dims[2]} grid of {h:.3g} m cells ({how}); "
              f"{int(np.count_nonzero(crossed)):,} cells crossed by the surface counted half, "
              f"{int(np.count_nonzero(doubtful[~crossed])):,} more undecided")
    return Estimate(volume=vol, centroid=c, second_moment=second, area=area, uncertainty=unc, method="winding",
                    detail=detail, vertices=v, faces=f, far=far)


#: Closed-surface estimate (:func:`closed_surface_estimate`): the mass bound it refines towards, relative.
CLOSED_TARGET_MASS_RTOL = 0.05
#: Finest grid of the closed-surface estimate, cells along the longest side (one refinement pass at most): the
#: dense grid's arrays dominate the cost, ~6 s of CPU for a near-cubic part at 224 (qb_move: 9.7 s at 256).
CLOSED_MAX_RESOLUTION = 224


def closed_surface_estimate(vertices: np.ndarray, faces: np.ndarray, *, resolution: int = 64,
                            target: float = CLOSED_TARGET_MASS_RTOL,
                            max_resolution: int = CLOSED_MAX_RESOLUTION) -> Estimate:
    """The solid ``{w ≥ 1}`` of a closed, edge-balanced surface that passes through itself, on a grid, with an
    assumption-free bound.

    For a surface whose every directed edge is matched by its reverse (a 2-cycle), the winding number ``w``
    is an integer at every point off the surface, constant on each connected region of space the surface
    does not meet.  On a grid of cubes, a cell the surface crosses is *undecided*
    (:func:`_surface_cells` marks a superset of them); the other cells form face-connected regions, each
    given the integer of one of its cells (:func:`_closed_part_numbers`: evaluated there and rounded,
    refused when more than 1/4 from an integer — then every free cell is evaluated and thresholded with
    the margins of :func:`winding_estimate`).  With ``D`` the decided cells with ``w ≥ 1`` and ``U`` the
    undecided ones, the true solid ``S`` satisfies ``D ⊆ S ⊆ D ∪ U`` **with no assumption** on the
    surface.  The estimate is ``D`` plus half of ``U`` (each undecided cell counted half), so its volume is
    within ``|U|/2`` of the truth, and the mass, centre-of-mass and inertia bounds of
    :func:`uncertainty_from` follow from ``δV = |U|/2`` lying within ``far`` of the centroid (the
    difference between truth and estimate is a signed density of at most 1/2 on ``U``).

    The grid has ``resolution`` cells along the longest side; when the mass bound exceeds ``target``, it is
    built once more at ``resolution · bound / target`` cells (the undecided volume of a surface shrinks as
    the cell size), at most ``max_resolution`` (exactly that when no cell was decided inside, a part thinner
    than the cells), and that second grid is the answer (chosen by this rule, not by which bound is smaller).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
        Edge-balanced (closed) surface; the caller checks.
    resolution, target, max_resolution
        As above.

    Returns
    -------
    Estimate
        ``method`` ``"winding"``.
    """
    first = winding_estimate(vertices, faces, resolution=resolution)
    bound = first.uncertainty.mass
    if resolution >= max_resolution or (np.isfinite(bound) and bound <= target):
        return first
    # no cell decided inside (a part thinner than the cells) or no finite bound: the finest grid
    finer = max_resolution if not (np.isfinite(bound) and first.volume > 0) else \
        int(min(max_resolution, np.ceil(resolution * bound / target)))
    if finer <= resolution:
        return first
    second = winding_estimate(vertices, faces, resolution=finer)
    return second if second.detail != first.detail else first
