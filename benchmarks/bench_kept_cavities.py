"""Review 11's D5 family at scale (fix12): outward boxes, voids wound inward that cross a body's face and reach
outside every body, and boxes flush inside a void wound either way, on a quarter grid; the truth is the grid-cell
winding count of ``tests/test_mesh_kept_cavities.py`` (``{w ≥ 1}`` as wound, with the inward boxes that meet no body
turned, or R4's depth reading when no two boxes cross), which knows nothing of the pipeline.

Run: ``python benchmarks/bench_kept_cavities.py --cases 800 --seed 1241`` (``--repair``: answered with
``repair=True``, session 15): the count of each certificate label, the silent wrong answers (labelled exact,
united or estimate and matching no reading, or a warning naming a union that is no reading) and the crashes
(any exception but ``InvalidMeshError``) with the boxes that make them.  Case ``i`` is drawn from
``numpy.random.default_rng([seed, i])``.
"""
from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another
from test_mesh_kept_cavities import _draw, _verdict  # noqa: E402
from test_grid_mixed_winding import repaired_verdict  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=800)
    ap.add_argument("--seed", type=int, default=1241)
    ap.add_argument("--repair", action="store_true",
                    help="answer with repair=True (the grid estimate where the plain path refuses); estimates judged "
                         "by their bounds as stated, relative to the estimate")
    args = ap.parse_args(argv)
    counts: Counter = Counter()
    wrong = []
    t0 = time.process_time()
    for i in range(args.cases):
        boxes = _draw(np.random.default_rng([args.seed, i]))
        started = time.process_time()
        try:
            label, why = repaired_verdict(boxes) if args.repair else _verdict(boxes)
        except Exception as exc:  # noqa: BLE001 - any other exception is a crash, counted and shown
            label, why = "crashed", f"{type(exc).__name__}: {exc}"
        spent = time.process_time() - started
        if spent > 10:                     # issue 21: a case over 10 s CPU is named, whatever its verdict
            cells = [(lo.tolist(), hi.tolist(), s) for lo, hi, s in boxes]
            print(f"  slow: case {i} {spent:.1f} s CPU, {label}: {cells}", flush=True)
        counts[label] += 1
        if label == "crashed":
            wrong.append((i, why, [(lo.tolist(), hi.tolist(), s) for lo, hi, s in boxes]))
        elif why is not None:
            counts["silent wrong"] += 1
            wrong.append((i, why, [(lo.tolist(), hi.tolist(), s) for lo, hi, s in boxes]))
    print(f"{args.cases} cases, seed {args.seed}{', repair' if args.repair else ''}, "
          f"{time.process_time() - t0:.1f} s CPU")
    print(" ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for i, why, boxes in wrong:
        print(f"case {i}: {why}\n    boxes (lo, hi, sign) in cells of 0.25 m: {boxes}")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
