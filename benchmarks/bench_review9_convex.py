"""Review 9: overlapping convex pieces judged against inclusion–exclusion over qhull's intersections.

The union witness of R5/R6 (``mesh/unite.py``: Bonferroni's lower bound from manifold3d's own pairwise
intersections) is not independent of manifold3d.  Here the truth is: for convex polyhedra ``A_1..A_k`` (boxes,
icospheres, polygon prisms), every intersection ``A_S`` is convex and is computed as a half-space intersection
by qhull (``scipy.spatial.HalfspaceIntersection``, interior point from a Chebyshev-centre linear program), its
moments integrated over its convex hull; the union's volume, first and second moments are the
inclusion–exclusion sums ``Σ_S (−1)^{|S|+1} M(A_S)`` (all three are measures).  Where one of two pieces lies
wholly inside the other (libigl winding numbers of its corners), R4's depth reading (the inner one a cavity) is
accepted as well.  An intersection whose Chebyshev
radius is below 1e-13 of the piece size is taken as empty; its volume is at most radius × surface (a convex body
lies within its inradius of a face... times its surface), added to the stated error of the truth.

Adversarial compositions (``MODES``): random overlaps; a copy turned by a tiny angle (1e-12..1e-3 rad) about a
point on the surface; a copy shifted by 1..8 ulps or by 1e-12..1e-6 of its size along a face normal; a slab
overlap 1e-9..1e-4 thick; a copy with every coordinate nudged by a few ulps (near copies, ``policy.py``'s R0);
three pieces.  Each case is also placed far from the origin (1e3..1e7 sizes) or scaled to millimetres at random.
Far placements round the pieces' corners (by ``delta``); the truth is the union of the unrounded pieces, and
the two differ within the ``delta``-neighbourhood of the surfaces, whose volume (Steiner) is added to every
tolerance (so a far case fails only beyond what the rounding of its input allows).  An ``exact`` answer is
held to ``tolerances.ROUNDOFF_RTOL`` (R7's round-off claim; other labels to 1e-9).

Run: ``python benchmarks/bench_review9_convex.py --cases 2000 --seed 901 [--repair]``.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another
import adversary_solids as S  # noqa: E402
from inertia_tool.tolerances import ROUNDOFF_RTOL  # noqa: E402

MODES = ("random", "tiny_turn", "ulp_shift", "tiny_shift", "slab", "nudged_copy", "three", "hollow_pair",
         "hollow_turn")


def halfspaces(v, f):
    """(m, 4) rows [n, -n·p0] with n the unit outward normal of each non-degenerate face."""
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    norm = np.linalg.norm(n, axis=1)
    keep = norm > 0
    n = n[keep] / norm[keep, None]
    # offset from the face's centroid (a better-conditioned plane than one corner)
    c = (p0[keep] + p1[keep] + p2[keep]) / 3
    return np.c_[n, -np.einsum("ij,ij->i", n, c)]


def chebyshev(hs):
    """(centre (3,), radius) of the largest ball inside {x: A x + b <= 0}, or (None, 0)."""
    a, b = hs[:, :3], hs[:, 3]
    norm = np.linalg.norm(a, axis=1)
    res = linprog(c=[0, 0, 0, -1], A_ub=np.c_[a, norm], b_ub=-b, bounds=[(None, None)] * 3 + [(0, None)],
                  method="highs")
    if not res.success:
        return None, 0.0
    return res.x[:3], float(res.x[3])


def convex_moments(points):
    """(volume, first (3,), second (3, 3)) of the convex hull of ``points``, about the origin, in float64
    (about the hull's mean, shifted back exactly in the algebra)."""
    hull = ConvexHull(points)
    ref = points[hull.vertices].mean(0)
    p = points - ref
    tri = hull.simplices.copy()
    # wind each triangle outward (qhull's facet normals)
    n = np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]])
    flip = np.einsum("ij,ij->i", n, hull.equations[:, :3]) < 0
    tri[flip] = tri[flip][:, ::-1]
    vol, cen, central = S.float_moments(p, tri)
    # float_moments recentres at the vertex mean of p, returns centroid in p's frame
    cen = cen + ref
    second = central + vol * np.outer(cen, cen)
    return vol, vol * cen, second


def intersection_moments(pieces, size):
    """Moments of ∩ pieces (convex), and an error bound on its volume (m³) when taken as empty."""
    hs = np.vstack([halfspaces(v, f) for v, f in pieces])
    centre, radius = chebyshev(hs)
    area = min(_area(v, f) for v, f in pieces)
    if centre is None or radius <= 1e-13 * size:
        return 0.0, np.zeros(3), np.zeros((3, 3)), radius * area
    inter = HalfspaceIntersection(hs, centre)
    vol, first, second = convex_moments(inter.intersections)
    return vol, first, second, 0.0


def _area(v, f):
    return float(np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum() / 2)


def union_truth(pieces, size):
    """Inclusion–exclusion over every subset: S.Truth of the union, and the volume error bound."""
    vol, first, second, err = 0.0, np.zeros(3), np.zeros((3, 3)), 0.0
    for k in range(1, len(pieces) + 1):
        sign = 1.0 if k % 2 else -1.0
        for sub in itertools.combinations(range(len(pieces)), k):
            if k == 1:
                v, f = pieces[sub[0]]
                pv, cen, central = S.float_moments(v, f)
                pf, ps, e = pv * cen, central + pv * np.outer(cen, cen), 0.0
            else:
                pv, pf, ps, e = intersection_moments([pieces[i] for i in sub], size)
            vol += sign * pv
            first = first + sign * np.asarray(pf)
            second = second + sign * ps
            err += e
    cen = first / vol
    central = second - vol * np.outer(cen, cen)
    return S.Truth(vol, cen, S._inertia(central), "qhull-incl-excl"), err


def _moments(piece):
    vol, cen, central = S.float_moments(*piece)
    return vol, vol * cen, central + vol * np.outer(cen, cen), 0.0


def hollow_truth(a, ca, b, cb, size):
    """(A − Ca) ∪ (B − Cb) for convex A ⊃ Ca, B ⊃ Cb: M(A) − M(Ca) + M(B) − M(Cb) − M(X ∩ Y) with
    X ∩ Y = A∩B − A∩B∩Ca − A∩B∩Cb + A∩B∩Ca∩Cb (inclusion–exclusion; every term convex)."""
    terms = [(1, _moments(a)), (-1, _moments(ca)), (1, _moments(b)), (-1, _moments(cb)),
             (-1, intersection_moments([a, b], size)), (1, intersection_moments([a, b, ca], size)),
             (1, intersection_moments([a, b, cb], size)), (-1, intersection_moments([a, b, ca, cb], size))]
    vol = sum(sg * t[0] for sg, t in terms)
    first = sum(sg * np.asarray(t[1]) for sg, t in terms)
    second = sum(sg * t[2] for sg, t in terms)
    err = sum(t[3] for _, t in terms)
    cen = first / vol
    return S.Truth(vol, cen, S._inertia(second - vol * np.outer(cen, cen)), "qhull-incl-excl"), err


def _shrunk(piece, factor):
    v, f = piece
    c = v.mean(0)
    return (c + (v - c) * factor, f.copy())


def convex_piece(rng):
    choice = rng.integers(3)
    if choice == 0:
        ext = rng.uniform(0.3, 1.0, size=3)
        sub = int(rng.integers(0, 2))
        return f"box{S._t(np.round(ext, 3))}/sub{sub}", S.box(ext, subdivide=sub)
    if choice == 1:
        r = float(rng.uniform(0.3, 0.6))
        return f"icosphere(r={r:.3g})", S.icosphere(r, int(rng.integers(0, 2)))
    r, h, n = float(rng.uniform(0.2, 0.5)), float(rng.uniform(0.4, 1.0)), int(rng.integers(5, 17))
    return f"cylinder(r={r:.3g},h={h:.3g},n={n})", S.cylinder(r, h, n)


def make(mode, rng):
    """(pieces [(v, f)], recipe) near the origin, size about 1."""
    name, a = convex_piece(rng)
    a = S.moved(a, S.random_rotation(rng), np.zeros(3))
    va, fa = a
    if mode == "random" or mode == "three":
        k = 3 if mode == "three" else 2
        pieces, names = [a], [name]
        for _ in range(k - 1):
            nm, p = convex_piece(rng)
            pieces.append(S.moved(p, S.random_rotation(rng), rng.normal(size=3) * 0.3))
            names.append(nm)
        return pieces, " ∪ ".join(names)
    if mode in ("hollow_pair", "hollow_turn"):
        ca = _shrunk(a, float(rng.uniform(0.3, 0.7)))
        if mode == "hollow_pair":
            nm, b = convex_piece(rng)
            b = S.moved(b, S.random_rotation(rng), rng.normal(size=3) * 0.3)
            recipe = f"{name} and {nm}, each hollow (a shrunk copy wound inward), overlapping"
        else:
            angle = float(10.0 ** rng.uniform(-9, -2))
            rot = S._axis_rotation(rng.normal(size=3), angle)
            p = va[rng.integers(len(va))]
            b = ((va - p) @ rot.T + p, fa.copy())
            nm, recipe = name, f"{name}, hollow, and a copy turned {angle:.3g} rad about a corner"
        cb = _shrunk(b, float(rng.uniform(0.3, 0.7)))
        return [a, ca, b, cb], recipe
    if mode == "tiny_turn":
        angle = float(10.0 ** rng.uniform(-12, -3))
        p = va[rng.integers(len(va))] if rng.random() < 0.5 else va.mean(0)
        rot = S._axis_rotation(rng.normal(size=3), angle)
        return [a, ((va - p) @ rot.T + p, fa.copy())], f"{name} and a copy turned {angle:.3g} rad"
    if mode in ("ulp_shift", "tiny_shift"):
        i = int(rng.integers(len(fa)))
        n = np.cross(va[fa[i, 1]] - va[fa[i, 0]], va[fa[i, 2]] - va[fa[i, 0]])
        n /= np.linalg.norm(n)
        if mode == "ulp_shift":
            k = int(rng.integers(1, 9)) * (1 if rng.random() < 0.5 else -1)
            vb = va.copy()
            for _ in range(abs(k)):
                vb = np.nextafter(vb, vb + np.sign(k) * n * 1e300)
            return [a, (vb, fa.copy())], f"{name} and a copy {k} ulps along face {i}'s normal"
        d = float(10.0 ** rng.uniform(-12, -6)) * (1 if rng.random() < 0.5 else -1)
        return [a, (va + d * n, fa.copy())], f"{name} and a copy shifted {d:.3g} along face {i}'s normal"
    if mode == "slab":
        nm, b = convex_piece(rng)
        b = S.moved(b, S.random_rotation(rng), np.zeros(3))
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        reach_a = float((va @ direction).max())
        reach_b = float(-(b[0] @ direction).min())
        depth = float(10.0 ** rng.uniform(-9, -4))
        shift = direction * (reach_a + reach_b - depth)
        return [a, (b[0] + shift, b[1])], f"{name} and {nm} overlapping by a slab {depth:.3g} deep"
    if mode == "nudged_copy":
        vb = va.copy()
        mask = rng.random(vb.shape) < 0.5
        steps = rng.integers(1, 4, size=vb.shape)
        for s in range(1, 4):
            m = mask & (steps >= s)
            vb[m] = np.nextafter(vb[m], np.where(rng.random(m.sum()) < 0.5, np.inf, -np.inf))
        return [a, (vb, fa[rng.permutation(len(fa))].copy())], f"{name} and a copy with coordinates nudged 1..3 ulps"
    raise ValueError(mode)


def place(pieces, rng):
    """Scale (m or mm) and a far placement: (pieces as given, the same pieces before rounding to the far
    coordinates, shift, recipe).  The truth is the union of the unrounded pieces (each exactly convex up to
    its own rounding near the origin); the pieces as given differ from them by at most ``delta`` per corner, so
    the two unions differ only within the ``delta``-neighbourhood of the surfaces (Steiner: ``2·delta·area``
    to first order), which the caller adds to the tolerance."""
    scale = 1e-3 if rng.random() < 0.3 else 1.0
    pieces = [(v * scale, f) for v, f in pieces]
    if rng.random() < 0.4:
        shift = np.zeros(3)
    else:
        far = 10.0 ** rng.uniform(3, 7) * scale
        shift = np.round(rng.normal(size=3) * far / scale) * scale
    given = [(v + shift, f) for v, f in pieces]
    return given, pieces, shift, f"scale {scale:g}, shift {np.round(shift, 3).tolist()}"


def judged(case, truth, bound_rel, repair):
    """S.judge_truth's rule with the truth's own relative error ``bound_rel`` added to each tolerance."""
    import warnings

    from inertia_tool import mass_properties
    from inertia_tool.errors import InvalidMeshError
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((case.vertices, case.faces), density=1.0, repair=repair)
    except InvalidMeshError as exc:
        return S.Verdict("refused", message=str(exc).splitlines()[0])
    except Exception as exc:
        return S.Verdict("crashed", wrong=f"{type(exc).__name__}: {exc}"[:300])
    label = S.certificate_label(props.mesh)
    diag = float(np.linalg.norm(np.ptp(case.vertices, axis=0)))
    dvol, dcom, din = S.compare(props, truth)
    numbers = (f"volume {props.mass:.12g} vs {truth.volume:.12g}; rel {dvol:.2e}, com {dcom / diag:.2e}·diag, "
               f"inertia rel {din:.2e} (truth ±{bound_rel:.1e})")
    if label == "estimate":
        u = props.mesh.uncertainty
        ok = u is not None and dvol <= u.mass + 1e-9 + bound_rel and \
            dcom <= u.center_of_mass + (1e-9 + 2 * bound_rel) * diag and din <= u.inertia + 1e-9 + 4 * bound_rel
        return S.Verdict(label, wrong=None if ok else "outside its bounds: " + numbers)
    # "exact" claims the polyhedron's integrals to within R7's round-off bound (at most ROUNDOFF_RTOL of the
    # result): judged at that, not at the boolean's 1e-9 (an exact answer 5e-10 off would have passed)
    rtol = ROUNDOFF_RTOL if label == "exact" else 1e-9
    if dvol > rtol + bound_rel or dcom > (rtol + 2 * bound_rel) * diag or din > 10 * rtol + 4 * bound_rel:
        return S.Verdict(label, wrong=numbers)
    return S.Verdict(label, message=numbers)


def _depth_reading_of_three(local, size, shift):
    """R4's reading of three pieces of which one lies wholly inside one other (libigl winding numbers of its
    corners) and meets the third in no volume (qhull): the inner one is a cavity, so the truth is the union of
    the other two minus it (review 11: seed 133 case 240 is this reading, which the two-piece rule alone did not
    accept); None for any other arrangement."""
    inside = S._contained(local)
    if inside.sum() != 1:
        return None
    k = int(np.flatnonzero(inside)[0])
    rest = [p for j, p in enumerate(local) if j != k]
    for p in rest:
        both, _ = union_truth([local[k], p], size)
        alone = S.float_moments(*local[k])[0] + S.float_moments(*p)[0] - both.volume
        contains = S._contained([local[k], p])[0]
        if not contains and abs(alone) > 1e-12 * size ** 3:
            return None                             # the inner piece also crosses the third: not this reading
    outer, _ = union_truth(rest, size)
    vi, ci, si = S.float_moments(*local[k])
    vol = outer.volume - vi
    first = outer.volume * (outer.centroid) - vi * ci
    second_outer = _second_about_origin(outer)
    second = second_outer - (si + vi * np.outer(ci, ci))
    cen = first / vol
    return S.Truth(vol, cen + shift, S._inertia(second - vol * np.outer(cen, cen)), "depth reading of three")


def _second_about_origin(truth):
    """``∫ x xᵀ dV`` of a truth (volume, centroid, tensor about the centroid), from its tensor: the central
    second moment is ``tr(I)/2·1 − I``."""
    central = 0.5 * np.trace(truth.inertia) * np.eye(3) - truth.inertia
    return central + truth.volume * np.outer(truth.centroid, truth.centroid)


def run(mode, seed, i, repair):
    rng = np.random.default_rng([seed, i])
    pieces, recipe = make(mode, rng)
    given, local, shift, where = place(pieces, rng)
    size = float(np.linalg.norm(np.ptp(np.vstack([v for v, _ in local]), axis=0)))
    if mode.startswith("hollow"):
        truth, err = hollow_truth(*local, size)
        given = [given[0], S.flipped(given[1]), given[2], S.flipped(given[3])]
    else:
        truth, err = union_truth(local, size)
    err += rounding_allowance(given, local, shift)
    truth = S.Truth(truth.volume, truth.centroid + shift, truth.inertia, truth.source)
    v, f = S.concat(*given)
    case = S.Case(mode, v, f, truth, f"{recipe}; {where}")
    bound_rel = err / abs(truth.volume)
    verdict = judged(case, truth, bound_rel, repair)
    inside = S._contained(local) if verdict.wrong is not None and len(local) == 2 else np.zeros(0, dtype=bool)
    if verdict.wrong is not None and len(local) == 3:
        alt3 = _depth_reading_of_three(local, size, shift)
        if alt3 is not None:
            other = judged(case, alt3, bound_rel, repair)
            if other.wrong is None:
                return case, other, bound_rel
            case.recipe += "; one piece wholly inside another (the depth reading misses too)"
    if inside.any() and not inside.all():
        # R4's reading (issue 21: orient by nesting depth): a piece wholly inside the other is its cavity
        outer, inner = (local[1], local[0]) if inside[0] else (local[0], local[1])
        (vo, co, so), (vi, ci, si) = S.float_moments(*outer), S.float_moments(*inner)
        vol = vo - vi
        first = vo * co - vi * ci
        second = (so + vo * np.outer(co, co)) - (si + vi * np.outer(ci, ci))
        cen = first / vol
        alt = S.Truth(vol, cen + shift, S._inertia(second - vol * np.outer(cen, cen)), "depth reading")
        other = judged(case, alt, bound_rel, repair)
        if other.wrong is None:
            return case, other, bound_rel
        case.recipe += "; one piece wholly inside the other (the depth reading misses too)"
    return case, verdict, bound_rel


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=700)
    ap.add_argument("--seed", type=int, default=901)
    ap.add_argument("--repair", action="store_true")
    ap.add_argument("--case", type=int, default=None)
    args = ap.parse_args(argv)
    if args.case is not None:
        mode = MODES[args.case % len(MODES)]
        case, verdict, err = run(mode, args.seed, args.case, args.repair)
        print(mode, case.recipe, verdict, f"truth err {err:.2g}", case.truth.volume)
        return 0
    table: dict[str, Counter] = defaultdict(Counter)
    fails = []
    t0 = time.time()
    for i in range(args.cases):
        mode = MODES[i % len(MODES)]
        started = time.process_time()
        try:
            case, verdict, err = run(mode, args.seed, i, args.repair)
        except Exception as exc:           # the truth failed (qhull): skipped, counted
            table[mode]["truth failed"] += 1
            fails.append((i, mode, f"truth failed: {type(exc).__name__}: {str(exc)[:120]}"))
            continue
        spent = time.process_time() - started
        if spent > 10:                     # issue 21: a case over 10 s CPU is named, whatever its verdict
            print(f"  slow: case {i} ({mode}) {spent:.1f} s CPU, {verdict.label}: {case.recipe}", flush=True)
        row = table[mode]
        row["cases"] += 1
        row[verdict.label] += 1
        if verdict.wrong is not None:
            row["silent wrong" if S.silent(verdict) else "wrong (honest label)"] += 1
            fails.append((i, mode, f"{verdict.label}: {verdict.wrong} | {case.recipe}"))
    cols = ("cases", "exact", "united", "estimate", "summed", "unverified", "refused", "crashed", "silent wrong",
            "wrong (honest label)", "truth failed")
    print(f"{args.cases} cases, seed {args.seed}, repair={args.repair}, {time.time() - t0:.0f} s")
    print_table(table, MODES, cols, fails)
    return 0


def print_table(table, modes, cols, fails):
    """The counts per mode (and all) as a Markdown table, then one line per failed case."""
    print("| mode | " + " | ".join(cols) + " |")
    print("|---|" + "---:|" * len(cols))
    tot: Counter = Counter()
    for mode in modes:
        tot.update(table[mode])
        print(f"| {mode} | " + " | ".join(str(table[mode][c]) for c in cols) + " |")
    print("| all | " + " | ".join(str(tot[c]) for c in cols) + " |")
    for i, mode, text in fails:
        print(f"- case {i} ({mode}): {text}")


def rounding_allowance(given, local, shift):
    """m³: the δ-neighbourhood of every piece's surface (Steiner, with room for the δ² and δ³ terms), δ the
    largest move rounding made when the pieces were placed (``given`` less ``shift`` against ``local``)."""
    delta = max(float(np.abs((vg - shift) - vl).max()) for (vg, _), (vl, _) in zip(given, local))
    return sum(2.5 * delta * _area(v, f) for v, f in local)


if __name__ == "__main__":
    sys.exit(main())
