"""Does the hole bound's assumption hold, and are refused holes' patched answers any good?

For every case of the hole kinds of ``coverage.py`` (same seeds, sources, damage and truth), besides what
``repair=True`` answers, this records

- whether the *stated assumption* holds: every corner and centroid of the faces the damage removed lies in the
  region the bound assumes for some hole of the case (:func:`examine`: the ball over its rim, cut to the slab
  around its ring plane unless the slab is withdrawn, to a crease fill's two slabs, to the capsule where it is
  taken, to the prism over the rim's projected hull as high as the bend bound states where that is taken (a
  superset of the bend assumption's region); or the convex polytope,
  :func:`~inertia_tool.mesh.holes.convex_hole_bound`);
- what the surface beside each hole says (:func:`~inertia_tool.mesh.holes.rim_evidence`);
- for a refused case, the patched answer the refusal withheld, checked against the truth (within 1 % volume,
  1 % of the diagonal, 2 % inertia).

Run: ``python benchmarks/damage/hole_assumptions.py --seeds 13,14,15`` (writes ``benchmarks/out/holes.json``).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import coverage as cov  # noqa: E402

HOLE_KINDS = ("hole", "holes_scattered", "t_junction_hole", "crack_hole")


def _damaged(kind, v, f, rng, diag):
    """As ``coverage.make_case``, with the surface just before the faces were removed."""
    if kind == "t_junction_hole":
        v, f, _ = cov.damage_t_junction(v, f, rng)
    if kind == "crack_hole":
        v, f, _ = cov.damage_crack(v, f, rng, diag)
    before = f
    if kind == "holes_scattered":
        v, f, _ = cov.damage_scattered(v, f, rng)
    else:
        v, f, _ = cov.damage_hole(v, f, rng)
    return v, before, f


def _removed(before, after):
    """Rows of ``before`` not in ``after`` (``np.delete`` keeps the others unchanged)."""
    key_b = {tuple(r) for r in after.tolist()}
    return before[[tuple(r) not in key_b for r in before.tolist()]]


def examine(v, f_before, f_after, truth):
    """The hole regions, evidence and the patched answer of one damaged surface.

    Each hole's region is the one :func:`~inertia_tool.mesh.holes.patched_estimate` states: the ball over its rim
    (first assumption), cut to the slab of its ring plane (second) unless the slab is withdrawn (a bare rim vertex,
    :func:`~inertia_tool.mesh.hole_bounds.slab_contradicted`, or a ball holding the whole surface: ``_engulfing``);
    for a crease fill whose rim the file does not contradict (``CreaseFill.narrow``), the ball cut to the union of
    its two planes' slabs (third); and, where the capsule is taken (the hole's ball meets no other's, holds not the
    whole surface and is no larger than the solid patched), also the capsule round the rim.  Where the answer is
    bounded by the convex polytope instead (fourth assumption), the region of every hole is that polytope.  A
    crease fill withdrawn because it lies over faces of the file (``_crease_contradicted``, read on the patched
    surface) is read here as narrow: stricter than stated."""
    from scipy.spatial import Delaunay, QhullError

    from inertia_tool.integrals import volume_moments
    from inertia_tool.mesh.hole_bounds import bend_doubt_volumes
    from inertia_tool.mesh.holes import (_alone, _engulfing, bare_vertices, convex_hole_bound, crease_fills,
                                         hole_doubt_volumes, patched_estimate, rim_evidence, slab_contradicted)
    from inertia_tool.mesh.rims import boundary_loops, capsule_volumes, enclosing_balls, enclosing_capsules
    from inertia_tool.mesh.seal import seal_seams
    from inertia_tool.tolerances import SEAM_GAP_RTOL

    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    seal = seal_seams(v, f_after, SEAM_GAP_RTOL * diag)
    edges = seal.boundary
    if not len(edges):
        return {"loops": 0}
    sf = seal.faces
    label, n_loops = boundary_loops(edges, len(v), sf, v)
    pairs = np.unique(np.stack([np.repeat(label, 2), edges.reshape(-1)], axis=1), axis=0)
    loop_of, vertex_of = pairs[:, 0], pairs[:, 1]
    centre, radius = enclosing_balls(v[vertex_of], loop_of, n_loops)
    slabs: dict = {}
    hole_doubt_volumes(v, sf, edges, label, n_loops, centre, radius, vertex_of, loop_of, slabs=slabs)
    bare = bare_vertices(v, sf, edges)
    evidence = rim_evidence(v, sf, edges, label, n_loops, radius, bare=bare)
    contradicted = (slab_contradicted(v, sf, edges, label, n_loops, slabs, radius) if slabs
                    else np.zeros(n_loops, dtype=bool))
    engulfed = _engulfing(v, sf, centre, radius)
    withdrawn = (evidence.bare > 0) | contradicted | engulfed
    fills = {c.loop: c for c in crease_fills(v, sf, edges, label, n_loops, centre, radius, bare=bare)}
    est = patched_estimate(v, sf, volume_moments, seal=seal)
    start, end, thick = enclosing_capsules(v[vertex_of], loop_of, n_loops)
    capsule = _alone(centre, radius) & ~engulfed & (4.0 / 3.0 * np.pi * radius ** 3 <= abs(float(est.volume)))
    convex = "convex" in est.detail
    # the bend bound (fifth assumption), where patched_estimate takes it: narrower than the ball, slab or capsule,
    # no crease fill, no ball holding everything (a fill bent onto a quadric is not told apart here: rare)
    size = np.bincount(loop_of, minlength=n_loops)
    apex = np.stack([np.bincount(loop_of, weights=v[vertex_of, i], minlength=n_loops) / np.maximum(size, 1)
                     for i in range(3)], axis=1)
    bend, bend_height = bend_doubt_volumes(v, sf, edges, label, n_loops, apex)
    ball_volume = 4.0 / 3.0 * np.pi * radius ** 3
    other = np.where(withdrawn, ball_volume,
                     hole_doubt_volumes(v, sf, edges, label, n_loops, centre, radius, vertex_of, loop_of))
    other = np.where(capsule, np.minimum(other, capsule_volumes(start, end, thick)), other)
    crossed = np.array([k in fills for k in range(n_loops)], dtype=bool)
    took_bend = np.isfinite(bend) & ~engulfed & ~crossed & (bend < other) & ("bend" in est.assumptions)
    flatness = (np.asarray(slabs["half_width"]) / radius).tolist() if "half_width" in slabs else [1.0] * n_loops
    gone = _removed(f_before, f_after)
    pts = np.vstack([v[gone].reshape(-1, 3), v[gone].mean(axis=1)]) if len(gone) else np.zeros((0, 3))
    inside = np.zeros(len(pts), dtype=bool)
    in_ball = np.zeros(len(pts), dtype=bool)
    slack = 1e-12 * diag
    for k in range(n_loops):
        ball = np.linalg.norm(pts - centre[k], axis=1) <= radius[k] * (1 + 1e-9) + slack
        in_ball |= ball
        region = ball.copy()
        if k in fills:
            fill = fills[k]
            if fill.narrow:                    # the two planes: each part of the rim within its own slab
                near = np.zeros(len(pts), dtype=bool)
                for which in (0, 1):
                    chain = v[np.unique(fill.caps[fill.caps[:, 2] == len(v) + which][:, :2])]
                    normal, half = _plane_of(chain)
                    near |= np.abs((pts - chain.mean(axis=0)) @ normal) <= half + slack
                region &= near
        elif slabs.get("has") is not None and slabs["has"][k] and not withdrawn[k]:
            region &= np.abs((pts - slabs["origin"][k]) @ slabs["normal"][k]) <= slabs["half_width"][k] + slack
        if took_bend[k]:                       # the prism over the projected rim, as high as the bend bound states
            rim_k = v[vertex_of[loop_of == k]]
            e = edges[label == k]
            normal = np.cross(v[e[:, 0]] - apex[k], v[e[:, 1]] - apex[k]).sum(axis=0)
            normal /= np.linalg.norm(normal)
            u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
            u /= np.linalg.norm(u)
            w = np.cross(normal, u)
            flat_rim = np.stack([(rim_k - apex[k]) @ u, (rim_k - apex[k]) @ w], axis=1)
            flat_pts = np.stack([(pts - apex[k]) @ u, (pts - apex[k]) @ w], axis=1)
            try:                                 # (a superset of the stated region: the rim's hull, not its polygon)
                over = Delaunay(flat_rim).find_simplex(flat_pts, tol=1e-9) >= 0
            except (QhullError, ValueError):
                over = np.ones(len(pts), dtype=bool)
            region &= over & (np.abs((pts - apex[k]) @ normal) <= bend_height[k] + slack)
        elif capsule[k]:
            seg = end[k] - start[k]
            t = np.clip((pts - start[k]) @ seg / max(float(seg @ seg), 1e-300), 0.0, 1.0)
            region &= np.linalg.norm(pts - (start[k] + t[:, None] * seg), axis=1) <= thick[k] * (1 + 1e-9) + slack
        inside |= region
    if convex and len(pts):
        bound = convex_hole_bound(est.vertices, est.faces[:len(sf)], float(est.volume))
        inside = (Delaunay(bound[1]).find_simplex(pts, tol=1e-9) >= 0) if bound is not None else inside
    inertia = np.trace(est.second_moment) * np.eye(3) - est.second_moment
    true_inertia = np.asarray(truth["inertia"])
    err_mass = abs(est.volume - truth["volume"])
    err_com = np.linalg.norm(est.centroid - np.asarray(truth["center_of_mass"]))
    err_inertia = np.linalg.norm(inertia - true_inertia)
    within = (err_mass <= cov.VOLUME_RTOL * truth["volume"] and err_com <= cov.COM_DTOL * truth["diagonal"]
              and err_inertia <= cov.INERTIA_RTOL * np.linalg.norm(true_inertia))
    return {"loops": int(n_loops), "assumption": bool(inside.all()), "in_balls": bool(in_ball.all()),
            "outside_share": float(1 - inside.mean()) if len(pts) else 0.0,
            "footprints": int(np.count_nonzero(evidence.flat_all_round & (evidence.bare > 0))),
            "patched_unbounded": bool(est.unbounded), "convex": bool(convex),
            "per_loop": {"bare": evidence.bare.tolist(), "flat": evidence.flat_all_round.tolist(),
                         "slab_contradicted": contradicted.tolist(), "engulfed": engulfed.tolist(),
                         "capsule": capsule.tolist(), "flatness": flatness, "bend": took_bend.tolist(),
                         "crease": [k in fills for k in range(n_loops)],
                         "crease_narrow": [bool(k in fills and fills[k].narrow) for k in range(n_loops)],
                         "radius": radius.tolist()},
            "patched_within": bool(within), "patched_mass_error": abs(est.volume - truth["volume"]) / truth["volume"],
            "patched_mass_bound": float(est.uncertainty.mass)}


def _plane_of(points):
    """Unit normal of the least-squares plane of ``points`` (one plane's part of a crease fill's rim) and their
    largest distance from it (that slab's half-width, as the fill states it up to round-off)."""
    centred = points - points.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    return axes[-1], float(np.abs(centred @ axes[-1]).max())


def run_case(args):
    case_id, source, kind, entropy, (name, v, f, clean_truth) = args
    rng = np.random.default_rng(entropy)
    truth = clean_truth
    if rng.random() < cov.QUANTISE_SHARE:
        qv, qf, _ = cov._quantised(v, f, rng, clean_truth["diagonal"])
        qt = cov.truth_of(qv, qf)
        if qt is not None:
            v, f, truth = qv, qf, qt
    dv, before, df = _damaged(kind, v, f, rng, truth["diagonal"])
    start = time.process_time()
    result = cov.evaluate(dv, df, truth)
    result["cpu_seconds"] = time.process_time() - start
    try:
        extra = examine(dv, before, df, truth)
    except Exception as exc:      # reported, never hidden
        extra = {"examine_error": f"{type(exc).__name__}: {exc}"[:200]}
    return {"id": case_id, "source": name, "kind": kind, **result, **extra}


def report(rows):
    answered = [r for r in rows if r["status"] == "answer" and r.get("loops")]
    certified = [r for r in answered if r.get("holds") is not None]
    refused = [r for r in rows if r["status"] == "refused"]
    ball_refused = [r for r in refused if "cannot be bounded usefully" in r["reason"]]
    lines = [f"cases {len(rows)}, answered {sum(r['status'] == 'answer' for r in rows)}, "
             f"refused {len(refused)}, errors {sum(r['status'] == 'error' for r in rows)}",
             f"answered with holes left: {len(answered)}; assumption holds {sum(r['assumption'] for r in answered)}"
             f" (in the balls: {sum(r['in_balls'] for r in answered)}); bounds hold "
             f"{sum(bool(r['holds']) for r in certified)}/{len(certified)}; assumption false but bound held "
             f"{sum((not r['assumption']) and bool(r['holds']) for r in certified)}",
             f"within tolerance: {sum(r['within'] for r in rows if r['status'] == 'answer')} of {len(rows)}",
             f"refused 'cannot be bounded usefully': {len(ball_refused)}; their patched answer within tolerance: "
             f"{sum(bool(r.get('patched_within')) for r in ball_refused)}",
             f"answered under the convex bound: {sum(bool(r.get('convex')) for r in answered)} (assumption holds "
             f"{sum(bool(r.get('convex')) and r['assumption'] for r in answered)}); holes whose slab was withdrawn by "
             f"slab_contradicted: {sum(sum(r['per_loop']['slab_contradicted']) for r in answered)}, by a ball holding "
             f"the whole surface: {sum(sum(r['per_loop']['engulfed']) for r in answered)}; holes under a capsule: "
             f"{sum(sum(r['per_loop']['capsule']) for r in answered)}; under the bend bound: "
             f"{sum(sum(r['per_loop'].get('bend', [])) for r in answered)}; narrow crease fills: "
             f"{sum(sum(r['per_loop']['crease_narrow']) for r in answered)}",
             "bounds that fail: " + ", ".join(f"{r['id']} ({r['source']})" for r in certified if not r["holds"]),
             "assumption false (answered): " + ", ".join(f"{r['id']} ({r['source']})" for r in answered
                                                          if not r["assumption"])]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", default="13,14,15")
    parser.add_argument("--sources", default="generated,repo,robots")
    parser.add_argument("--kinds", default=",".join(HOLE_KINDS))
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", type=Path, default=cov.OUT / "holes.json")
    args = parser.parse_args(argv)
    sources = cov.load_sources(args.sources.split(","))
    seeds = [int(s) for s in args.seeds.split(",")]
    kinds = tuple(args.kinds.split(","))
    tasks = [(cid, s, kind, ent, sources[s]) for cid, s, kind, ent in cov.cases(sources, seeds, 1, kinds)]
    print(f"{len(tasks)} cases from {len(sources)} sources, seeds {seeds}", flush=True)
    with mp.get_context("spawn").Pool(args.workers) as pool:
        rows = list(pool.imap(run_case, tasks, chunksize=2))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"rows": rows}, indent=1))
    print(report(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
