"""CPU time of the numpy path's tetrahedron sums (``INERTIA_TOOL_NO_ACCEL=1``) against the number of shells.

``integrals.body_volume_moments`` without the C extension, on ``N`` closed boxes of 12 faces each (``N`` = 1,
100, 10⁴, 10⁵ by default: a fastener catalogue or a voxel export is 10⁴–10⁵ shells) and on one torus of about
200,000 faces (one shell): ``sums`` times ``integrals._tetra_sums`` alone (what session 17 changed), ``call`` the
whole ``body_volume_moments`` (the bounding box, the sums and each shell's result object).  Each case is timed by
``time.process_time`` in a fresh child process per checkout and round (the machine is shared: CPU time, not wall),
repeated until it has taken ``--min-cpu`` seconds; the table gives the median over rounds of CPU seconds per call.
With ``--baseline DIR`` (a copy of another checkout: the numpy path needs no C build) the checkouts take turns, in
alternating order each round (``_checkouts.in_turn``), and the ratio is this checkout's over the baseline's.  Run::

    python benchmarks/bench_numpy_sums.py --baseline ../main --rounds 3
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _checkouts import in_turn, run_script, this_checkout_first  # noqa: E402

DEFAULT_SHELLS = (1, 100, 10_000, 100_000)


def _boxes(n: int):
    """``(vertices, faces, labels)`` of ``n`` unit boxes on a grid 2 apart, 12 outward faces each."""
    import numpy as np
    import trimesh

    box = trimesh.creation.box((1.0, 1.0, 1.0))
    bv, bf = np.asarray(box.vertices), np.asarray(box.faces)
    side = int(np.ceil(n ** (1 / 3)))
    idx = np.arange(n)
    offsets = 2.0 * np.stack([idx % side, (idx // side) % side, idx // (side * side)], axis=1)
    v = (bv[None] + offsets[:, None]).reshape(-1, 3)
    f = (bf[None] + (len(bv) * idx)[:, None, None]).reshape(-1, 3)
    labels = np.repeat(idx, len(bf))
    return v, f, labels


def child(shells: list[int], faces: float, min_cpu: float) -> None:
    """Time each case in this process (its checkout on ``sys.path``) and print one JSON line per case."""
    os.environ["INERTIA_TOOL_NO_ACCEL"] = "1"
    this_checkout_first()
    import numpy as np
    from _shapes import torus
    from inertia_tool import integrals

    cases = [(f"{n} shells ({12 * n} faces)", *_boxes(n), n) for n in shells]
    tv, tf = torus(faces)
    cases.append((f"1 torus ({len(tf)} faces)", tv, tf, np.zeros(len(tf), dtype=np.intp), 1))
    for name, v, f, labels, n in cases:
        o = integrals.reference_point(v)
        # the sums alone (what the numpy path changed), and the whole call (bounding box, sums, each shell's result)
        runs = {"sums": lambda: integrals._tetra_sums(v, f, o, 1 << 15, labels=None if n == 1 else labels, n_labels=n),
                "call": lambda: integrals.body_volume_moments(v, f, labels, n)}
        for what, run in runs.items():
            calls, spent = 0, 0.0
            while spent < min_cpu and calls < 10_000:         # bounded: at most 10,000 calls
                t0 = time.process_time()
                run()
                spent += time.process_time() - t0
                calls += 1
            print(json.dumps({"case": f"{name} {what}", "cpu": spent / calls, "calls": calls}), flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default=None, help="another checkout to compare with (its inertia_tool)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--shells", type=int, nargs="+", default=list(DEFAULT_SHELLS))
    ap.add_argument("--faces", type=float, default=2e5, help="faces of the one-shell torus")
    ap.add_argument("--min-cpu", type=float, default=0.5, help="CPU seconds each case is repeated for")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args.shells, args.faces, args.min_cpu)
        return 0
    here = os.path.dirname(HERE)
    trees = [("this", here)] + ([("baseline", os.path.abspath(args.baseline))] if args.baseline else [])
    results: dict[tuple[str, str], list[float]] = {}
    load = []
    for round_ in range(args.rounds):
        for label, tree in in_turn(trees, round_):
            load.append(os.getloadavg()[0])
            out = run_script(__file__, ["--child", "--shells", *map(str, args.shells), "--faces", str(args.faces),
                                        "--min-cpu", str(args.min_cpu)], tree=tree, capture=True)
            for line in out.stdout.splitlines():
                row = json.loads(line)
                results.setdefault((label, row["case"]), []).append(row["cpu"])
    cases = list(dict.fromkeys(case for _, case in results))
    print(f"numpy path, CPU s per call, median of {args.rounds} rounds (load {min(load):.1f}-{max(load):.1f})")
    for case in cases:
        this = statistics.median(results[("this", case)])
        line = f"{case:>34}: this {this:.4g} s"
        if args.baseline:
            base = statistics.median(results[("baseline", case)])
            line += f", baseline {base:.4g} s, this/baseline {this / base:.3f}"
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
