"""Independent exact classifier (rational clipping), used by the tests."""
from fractions import Fraction

NONE, CROSSING, OPPOSITE, CONTACT = 0, 1, 2, 3


def pair_kinds(result):
    """{(i, j): kind} of every pair a ``SurfaceContacts`` found, in the kinds above."""
    out = {}
    for kind, pairs in ((CROSSING, result.crossing), (OPPOSITE, result.coplanar_opposite),
                        (CONTACT, result.contact)):
        for i, j in pairs:
            out[(int(i), int(j))] = kind
    return out


def _sub(p, q):
    return [p[0] - q[0], p[1] - q[1], p[2] - q[2]]


def _cross(p, q):
    return [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]


def _dot(p, q):
    return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]


def _lerp(p, q, dp, dq):
    t = dp / (dp - dq)
    return [p[i] + (q[i] - p[i]) * t for i in range(3)]


def _on_segment(x, a, b):
    if any(_cross(_sub(b, a), _sub(x, a))):
        return False
    t = _dot(_sub(x, a), _sub(b, a))
    return 0 <= t <= _dot(_sub(b, a), _sub(b, a))


def _within_shared(points, shared):
    """All points lie in the element spanned by the shared corners (a vertex or an edge)."""
    if len(shared) == 0:
        return False
    if len(shared) == 1:
        return all(p == shared[0] for p in points)
    if len(shared) == 2:
        return all(_on_segment(p, shared[0], shared[1]) for p in points)
    return True


def _strictly_inside(x, tri, n):
    return all(_dot(n, _cross(_sub(tri[(e + 1) % 3], tri[e]), _sub(x, tri[e]))) > 0 for e in range(3))


def brute_kind(t1, t2, shared_corners):
    """Kind of the pair: NONE/CROSSING/OPPOSITE/CONTACT, or None when a triangle has zero area.

    t1, t2: 3 corners each (float); shared_corners: list of (i, j), corner i of t1 is corner j of t2 by index.
    """
    T1 = [[Fraction(float(c)) for c in p] for p in t1]
    T2 = [[Fraction(float(c)) for c in p] for p in t2]
    n1 = _cross(_sub(T1[1], T1[0]), _sub(T1[2], T1[0]))
    n2 = _cross(_sub(T2[1], T2[0]), _sub(T2[2], T2[0]))
    if not any(n1) or not any(n2):
        return None
    shared = [T1[i] for i, _ in shared_corners]
    dist1 = [_dot(n2, _sub(p, T2[0])) for p in T1]
    dist2 = [_dot(n1, _sub(p, T1[0])) for p in T2]
    if all(d == 0 for d in dist2):
        poly = list(T2)
        for e in range(3):
            p, q = T1[e], T1[(e + 1) % 3]
            g = [_dot(n1, _cross(_sub(q, p), _sub(x, p))) for x in poly]
            out = []
            for k in range(len(poly)):
                a, b, ga, gb = poly[k], poly[(k + 1) % len(poly)], g[k], g[(k + 1) % len(poly)]
                if ga >= 0:
                    out.append(a)
                if (ga > 0 > gb) or (ga < 0 < gb):
                    out.append(_lerp(a, b, ga, gb))
            poly = out
            if not poly:
                return NONE
        area = [Fraction(0)] * 3
        for k in range(1, len(poly) - 1):
            c = _cross(_sub(poly[k], poly[0]), _sub(poly[k + 1], poly[0]))
            area = [area[i] + c[i] for i in range(3)]
        if _dot(area, n1) != 0:
            return CROSSING if _dot(n1, n2) > 0 else OPPOSITE
        return NONE if _within_shared(poly, shared) else CONTACT

    def cut(T, dist):
        pts = [T[i] for i in range(3) if dist[i] == 0]
        for i in range(3):
            j = (i + 1) % 3
            if (dist[i] > 0 > dist[j]) or (dist[i] < 0 < dist[j]):
                pts.append(_lerp(T[i], T[j], dist[i], dist[j]))
        return pts

    s1, s2 = cut(T1, dist1), cut(T2, dist2)
    if not s1 or not s2:
        return NONE
    direction = _cross(n1, n2)
    k1 = sorted(s1, key=lambda x: _dot(direction, x))
    k2 = sorted(s2, key=lambda x: _dot(direction, x))
    lo = max(k1[0], k2[0], key=lambda x: _dot(direction, x))
    hi = min(k1[-1], k2[-1], key=lambda x: _dot(direction, x))
    if _dot(direction, lo) > _dot(direction, hi):
        return NONE
    if _dot(direction, lo) == _dot(direction, hi):
        return NONE if _within_shared([lo], shared) else CONTACT
    mid = [(lo[i] + hi[i]) / 2 for i in range(3)]
    if _strictly_inside(mid, T1, n1) and _strictly_inside(mid, T2, n2):
        return CROSSING
    return NONE if _within_shared([lo, hi], shared) else CONTACT


def edge_twins(faces, n_vertices):
    """The faces across each edge (``_accel.c`` section 8, ``ct_twins``), written out per vertex: (m, 3) int, row
    ``i`` column ``c`` for the edge from corner ``c`` of face ``i`` (at vertex ``v``) to its next corner.

    One rule at every vertex, however many faces it has: -2 for every face of ``v`` when one face holds ``v`` twice;
    otherwise the one face ``j != i`` of ``v`` whose corner before ``v`` is ``i``'s corner after it (running the
    edge the other way) when it is the only one and no other face of ``v`` runs the edge ``i``'s way; -1 when there
    is neither; -2 otherwise (an edge in three faces or more, or run twice one way: no face is *the* one across it,
    and a patch must not be closed through it).  Until issue 21 a vertex of more than 64 faces gave a twin to an
    edge run twice one way.  ``n_vertices`` is unused (the C call takes it)."""
    f = [[int(x) for x in row] for row in faces]
    twin = [[-2, -2, -2] for _ in f]
    listed = {}
    for i, row in enumerate(f):
        for c, x in enumerate(row):
            listed.setdefault(x, []).append((i, c))
    for v, items in listed.items():
        if any(f[i].count(v) != 1 for i, _ in items):
            continue
        nxt = [f[i][(c + 1) % 3] for i, c in items]
        prv = [f[i][(c + 2) % 3] for i, c in items]
        for a, (i, c) in enumerate(items):
            back = [b for b in range(len(items)) if b != a and prv[b] == nxt[a]]
            same = sum(1 for b in range(len(items)) if b != a and nxt[b] == nxt[a])
            twin[i][c] = (-1 if not back and not same else items[back[0]][0] if len(back) == 1 and not same
                          else -2)
    return twin
