"""Near copies (review 10's D2, fix11): a piece and its copy scaled by 1 + k ulp (k 1..300) about its centre, turned
by a small angle (~1e-15..1e-8 rad), or both; pieces 1e-3..1e3 m, axis-aligned or turned, at the origin or up to
1e7 sizes out; listed in either order.  Truth: the union of the two, by manifold3d, integrated in float64
(``adversary_solids.truth_from_manifold``, code apart from the pipeline's); an answer is right within 1e-6.

Run: ``python benchmarks/bench_near_copies.py 121 240`` (seed, cases): counts by label and verdict, then the wrong
cases with their warnings.  Session 11 (seed 121, 240 cases): 13 `unverified` answers off by ~100 % before the
nested-copy rule, 0 after.
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another
from adversary_solids import box, certificate_label, cylinder, icosphere, torus, truth_from_manifold  # noqa: E402
from inertia_tool.errors import InvalidMeshError  # noqa: E402
from inertia_tool.mass.pipeline import mass_properties  # noqa: E402

_PIECES = (lambda: box((1.0, 2.0, 3.0)), lambda: icosphere(0.5, 1), lambda: cylinder(0.5, 1.0, 16),
           lambda: torus(1.0, 0.3, 16, 8))


def case(rng):
    """``(kind, mode, k, piece, copy, faces)``; mode 0 scaled, 1 turned, 2 both."""
    kind = int(rng.integers(4))
    v, f = _PIECES[kind]()
    v, f = np.asarray(v, float), np.asarray(f, np.int64)
    size = 10.0 ** rng.uniform(-3, 3)
    v = v * size
    if rng.random() < 0.5:
        v = v @ Rotation.random(random_state=int(rng.integers(2**31))).as_matrix().T
    else:
        rng.integers(2**31)
    mode = int(rng.integers(3))
    k = int(rng.integers(1, 301))
    c = v.mean(0)
    w = v.copy()
    if mode in (0, 2):
        w = c + (w - c) * (1 + k * 2.0 ** -52)
    if mode in (1, 2):
        ang = 10.0 ** rng.uniform(-15, -8)
        axis = Rotation.random(random_state=int(rng.integers(2**31))).as_rotvec()
        axis = axis / np.linalg.norm(Rotation.random(random_state=1).as_rotvec())    # (not unit: scales the angle)
        w = c + (w - c) @ Rotation.from_rotvec(ang * axis).as_matrix().T
    shift = rng.normal(size=3) * size * 10.0 ** rng.uniform(-2, 7) * (rng.random() < 0.8)
    v, w = v + shift, w + shift
    if rng.random() < 0.5:
        v, w = w, v
    return kind, mode, k, v, w, f


def truth(v, w, f) -> float:
    """Volume of the union of the piece ``(v, f)`` and its copy ``(w, f)`` by manifold3d, formed with both moved by
    the piece's first corner (the volume does not change; manifold3d's union formed 1e6 sizes out was 7.3e-4 too
    large, seed 1605 case 1371, ``tests/test_count15_findings.py``)."""
    origin = v[0].copy()
    return truth_from_manifold([(v - origin, f), (w - origin, f)]).volume


def run(seed, n):
    rng = np.random.default_rng(seed)
    counts: dict = {}
    bad = []
    for i in range(n):
        kind, mode, k, v, w, f = case(rng)
        started = time.process_time()
        try:
            truth_volume = truth(v, w, f)
        except Exception:  # noqa: BLE001 - a truth manifold3d refuses is counted, not judged
            counts["truth failed"] = counts.get("truth failed", 0) + 1
            continue
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                p = mass_properties((np.vstack([v, w]), np.vstack([f, f + len(v)])), density=1.0)
            label = certificate_label(p.mesh)
            ok = abs(p.mass - truth_volume) / truth_volume < 1e-6
            key = (label, "right" if ok else "wrong")
            if not ok:
                bad.append((i, kind, mode, k, label, p.mass, truth_volume, [str(x.message)[:400] for x in caught]))
        except InvalidMeshError as e:
            key = ("refused", str(e)[:80])
        spent = time.process_time() - started
        if spent > 10:                     # issue 21: a case over 10 s CPU is named, whatever its verdict
            print(f"  slow: case {i} (piece {kind}, mode {mode}, k {k}) {spent:.1f} s CPU, {key}", flush=True)
        counts[key] = counts.get(key, 0) + 1
    return counts, bad


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seed", type=int, nargs="?", default=121, help="the cases are drawn in turn from default_rng(seed)")
    ap.add_argument("cases", type=int, nargs="?", default=240, help="how many cases")
    args = ap.parse_args(argv)
    t = time.process_time()
    counts, bad = run(args.seed, args.cases)
    for key, c in sorted(counts.items(), key=str):
        print(c, key)
    for b in bad[:40]:
        print(b[:7])
        for m in b[7]:
            print("   ", m)
    print("cpu", time.process_time() - t)
    return 0


if __name__ == "__main__":
    sys.exit(main())
