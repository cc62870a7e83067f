"""The rims of an open surface: its net boundary, the loops it forms, and a ball around each.

Shared by hole patching (:mod:`~.holes`), the winding estimate's caps (:mod:`~.grid_estimate`) and the seam
sealing (:mod:`~.seal`).
"""

from __future__ import annotations

import numpy as np

from .edges import edge_keys

__all__ = ["boundary_edges", "boundary_loops", "enclosing_balls", "enclosing_capsules", "capsule_volumes"]


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


def boundary_loops(edges: np.ndarray, n_vertices: int, faces: np.ndarray | None = None,
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
    cycles = _cycle_labels(nxt)
    if cycles is not None:     # every edge the successor of exactly one: the loops are the cycles
        return cycles
    # scipy only here: its import (0.7 s with csgraph) was a third of a one-hole repair of 1.3M faces
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    if (nxt < 0).any():       # no consistent pairing: components through shared vertices
        graph = coo_matrix((np.ones(k, dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(n, n))
        _, vertex_label = connected_components(graph, directed=False)
        _, label = np.unique(vertex_label[edges[:, 0]], return_inverse=True)
        return label.reshape(-1), int(label.max()) + 1
    graph = coo_matrix((np.ones(k, dtype=np.int8), (np.arange(k), nxt)), shape=(k, k))
    count, label = connected_components(graph, directed=False)
    return label.astype(np.int64), int(count)


def _cycle_labels(nxt: np.ndarray) -> tuple[np.ndarray, int] | None:
    """The cycles of the permutation ``nxt`` (each edge's successor, every edge the successor of exactly one) as
    (k,) int64 labels numbered by their lowest edge, and their count; None when ``nxt`` is not a permutation.

    The same labels as scipy's ``connected_components`` of the graph ``i — nxt[i]`` (components numbered in the
    order of their lowest node), without scipy: by pointer doubling, after ``j`` rounds each edge holds the lowest
    index among its next ``2^j`` successors, so ``⌈log₂ k⌉ + 1`` rounds (bounded) reach round every cycle."""
    k = len(nxt)
    if (nxt < 0).any() or not bool(np.all(np.bincount(nxt, minlength=k) == 1)):
        return None
    lowest = np.arange(k, dtype=np.int64)
    step = nxt.astype(np.int64)
    for rounds in range(64):                         # bounded: 2^64 steps exceed any cycle
        np.minimum(lowest, lowest[step], out=lowest)
        if k <= 1 << (rounds + 1):
            break
        step = step[step]
    root = lowest == np.arange(k)
    rank = np.cumsum(root) - 1
    return rank[lowest].astype(np.int64), int(np.count_nonzero(root))


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
    fan = _components(a, b, len(fi))
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


#: Rounds of :func:`_components`' hooking before it hands the graph to scipy (each round joins every root to its
#: least neighbouring root; a fan of faces round a vertex needs about log₂ of its size).
COMPONENT_ROUNDS = 64


def _components(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    """Connected components of the undirected graph on ``n`` nodes with edges ``a[i] — b[i]``, (n,) int64: each
    node labelled by the lowest node of its component (the same partition as scipy's ``connected_components``,
    whose import was 0.8 s of CPU of a scattered-holes repair of 1.3M faces; only the partition is read here).

    Hooking and pointer jumping: every root takes the least root across its edges, then every node its root
    (pointer jumping, at most 64 halvings).  A node's parent never exceeds it, so the root of a component is its
    lowest node; a round leaves a root only where no neighbouring root is lower.  After
    :data:`COMPONENT_ROUNDS` rounds without settling, scipy's ``connected_components`` decides (its labels
    partition the nodes the same way).
    """
    parent = np.arange(n, dtype=np.int64)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    for _ in range(COMPONENT_ROUNDS):
        pa, pb = parent[a], parent[b]
        differ = pa != pb
        if not differ.any():
            return parent
        np.minimum.at(parent, np.maximum(pa[differ], pb[differ]), np.minimum(pa[differ], pb[differ]))
        for _ in range(64):                                 # path depth ≤ n < 2^64: 64 halvings reach the root
            grand = parent[parent]
            if (grand == parent).all():
                break
            parent = grand
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(n, n))
    label: np.ndarray = connected_components(graph, directed=False)[1].astype(np.int64)
    return label


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
    # Bădoiu–Clarkson on the larger groups only, a block of groups of alike sizes at a time
    for members in _size_classes(size, ~small):          # bounded by log2 of the largest group + 1
        centre[members] = _badoiu_clarkson(p, starts[members], size[members], centre[members], iterations)
    rel = p - centre[g]
    radius = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", rel, rel), starts))
    return centre, radius


def _size_classes(size: np.ndarray, chosen: np.ndarray) -> list[np.ndarray]:
    """The groups ``chosen`` (bool) by size class, each (k,) int ascending: those of at most 4 points, of 5 to 8,
    9 to 16, ... (empty classes left out)."""
    rank = np.zeros(len(size), dtype=np.int64)
    big = chosen & (size > 4)
    rank[big] = np.ceil(np.log2(size[big])).astype(np.int64) - 2         # 5..8 → 1, 9..16 → 2, ...
    classes = []
    for r in np.unique(rank[chosen]):                 # bounded by log2 of the largest group + 1
        classes.append(np.flatnonzero(chosen & (rank == r)))
    return classes


def _badoiu_clarkson(p: np.ndarray, starts: np.ndarray, size: np.ndarray, centre: np.ndarray, iterations: int
                     ) -> np.ndarray:
    """Bădoiu and Clarkson's steps for groups of consecutive points ``p[starts[i] : starts[i] + size[i]]`` from
    ``centre`` (g, 3): step ``k`` moves each centre by ``1/(k+1)`` towards the group's farthest point (the first
    of the farthest, in the points' order).  The groups are laid out as a (g, w) block, ``w`` the largest size,
    short groups padded with copies of their first point (a copy never comes before the point it copies, so the
    first of the farthest is the same point); the squared distances are formed as ``einsum("ij,ij->i")`` of the
    differences, as they were when every group's points were one (k, 3) array (issue 25, soup19: that reading's
    ``reduceat`` passes cost 1.2 ms a step on the 4,376 larger holes of a 1.3M-face sphere)."""
    width = int(size.max())
    column = np.arange(width)
    pick = starts[:, None] + np.where(column[None, :] < size[:, None], column[None, :], 0)
    q = p[pick.reshape(-1)]                                           # (g·w, 3): rows of each group together
    block = q.reshape(len(starts), width, 3)
    rows = np.arange(len(starts))
    c = centre
    diff = np.empty_like(block)                         # (written over at every step: no fresh pages)
    flat = diff.reshape(-1, 3)
    d = np.empty(len(q))
    square = d.reshape(len(starts), width)
    for k in range(1, iterations + 1):
        np.subtract(block, c[:, None, :], out=diff)
        np.einsum("ij,ij->i", flat, flat, out=d)
        far = np.argmax(square, axis=1)             # the first of the largest, as the lowest index reaching it
        c = c + (block[rows, far] - c) / (k + 1)
    return c


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


def enclosing_capsules(points: np.ndarray, group: np.ndarray, n_groups: int
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A capsule enclosing each group of points: segment ends ``(g, 3)``, ``(g, 3)`` m and radii ``(g,)`` m.

    The axis is the group's principal axis (the eigenvector of the largest eigenvalue of its covariance),
    through its mean; ``ρ⊥`` is the largest distance of a point from that line.  With the points at axial
    coordinates ``t_p`` and distances ``d_p`` from the line, each point lies within ``ρ⊥`` of the axial segment
    ``[t_lo, t_hi]`` when ``t_lo = min_p (t_p + s_p)`` and ``t_hi = max_p (t_p − s_p)``, ``s_p = √(ρ⊥² − d_p²)``
    (where ``t_lo > t_hi`` a single point of ``[t_hi, t_lo]`` does: the capsule is a ball, e.g. of radius ``a``
    round a circle of radius ``a``).  The radius is then measured exactly as the largest distance from that
    segment, so every capsule encloses its group whatever round-off did to the axis.  Its volume is
    ``π ρ² L + (4/3) π ρ³`` (a cylinder and two half balls), never more than the ball over the same points
    when the group is long and thin; the caller takes the smaller of the two sets' volumes.
    """
    p = np.asarray(points, dtype=np.float64)
    g = np.asarray(group, dtype=np.int64)
    order = np.argsort(g, kind="stable")
    p, g = p[order], g[order]
    starts = np.searchsorted(g, np.arange(n_groups))
    size = np.maximum(np.bincount(g, minlength=n_groups), 1)
    mean = np.stack([np.bincount(g, weights=p[:, k], minlength=n_groups) for k in range(3)], axis=1) / size[:, None]
    d = p - mean[g]
    cov = np.zeros((n_groups, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            cov[:, i, j] = cov[:, j, i] = np.bincount(g, weights=d[:, i] * d[:, j], minlength=n_groups)
    _, vectors = np.linalg.eigh(cov)
    axis = vectors[:, :, 2]                       # eigh sorts ascending: the last is the principal axis
    t = np.einsum("ij,ij->i", d, axis[g])
    perp = np.sqrt(np.maximum(np.einsum("ij,ij->i", d, d) - t * t, 0.0))
    top = np.maximum.reduceat(perp, starts) if len(p) else np.zeros(n_groups)
    s = np.sqrt(np.maximum(top[g] ** 2 - perp ** 2, 0.0))
    lo = np.minimum.reduceat(t + s, starts) if len(p) else np.zeros(n_groups)
    hi = np.maximum.reduceat(t - s, starts) if len(p) else np.zeros(n_groups)
    mid = 0.5 * (lo + hi)
    lo, hi = np.where(lo <= hi, lo, mid), np.where(lo <= hi, hi, mid)
    start = mean + lo[:, None] * axis
    end = mean + hi[:, None] * axis
    # the exact largest distance of a point from its segment
    ab = end - start
    length2 = np.einsum("ij,ij->i", ab, ab)
    u = np.clip(np.einsum("ij,ij->i", p - start[g], ab[g]) / np.where(length2 > 0, length2, 1.0)[g], 0.0, 1.0)
    gap = p - (start[g] + u[:, None] * ab[g])
    radius = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", gap, gap), starts)) if len(p) else np.zeros(n_groups)
    return start, end, radius


def capsule_volumes(start: np.ndarray, end: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Volume of each capsule (segment ``start–end``, radius ``ρ``), (g,) m³: ``π ρ² L + (4/3) π ρ³``."""
    length = np.linalg.norm(np.asarray(end) - np.asarray(start), axis=1)
    r = np.asarray(radius, dtype=np.float64)
    volume: np.ndarray = np.pi * r ** 2 * length + 4.0 / 3.0 * np.pi * r ** 3
    return volume
