"""CPU time of R3a's internal walls and of R3b's seamed-sheet search (issue 21, walls4).

Two measurements, each the median CPU time (``time.process_time``) of ``--repeat`` runs in this process:

* ``walls``: ``inertia_tool.mass_properties`` on grid boxes cut by a plane near a corner and written face to face
  (both cut faces kept, welded: ``tests/test_mesh_walls_corner.py``'s generator), with the certificate and the
  volume error against the halves' summed integral;
* ``seams``: ``mesh.sheets._seamed_sheet`` on a subdivided box with a planar hole in its top (it finds nothing:
  the cost the seamed path adds to every holed part whose rim is flat), with and without the net boundary the
  caller passes.

    python benchmarks/bench_walls.py [--cases 20] [--subdivide 7] [--repeat 5]

The machine's load average is printed (timings on a shared machine are noisy: compare CPU times, or ratios
within one run).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another


def _cpu(fn, repeat):
    times = []
    out = None
    for _ in range(repeat):
        start = time.process_time()
        out = fn()
        times.append(time.process_time() - start)
    return float(np.median(times)), out


def walls(cases: int, repeat: int) -> None:
    import inertia_tool as it
    from adversary_solids import truth_from_pieces
    from test_mesh_walls_corner import _plane_cut, _shape, _welded

    print("| seed | shape | faces | certificate | volume error | CPU (s) |\n|---:|---|---:|---|---:|---:|")
    for seed in range(cases):
        for kind in ("box", "turned box"):
            rng = np.random.default_rng(seed)
            v, f = _shape(kind, rng)
            halves = _plane_cut(v, f, rng)
            if halves is None:
                continue
            truth = truth_from_pieces([(1, p) for p in halves]).volume
            wv, wf = _welded(halves)

            def run():
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    return it.mass_properties((wv, wf), density=1.0)
            cpu, p = _cpu(run, repeat)
            print(f"| {seed} | {kind} | {len(wf):,} | {p.mesh.certificate.kind} | "
                  f"{abs(p.volume - truth) / truth:.1e} | {cpu:.3f} |")


def seams(subdivide: int, repeat: int) -> None:
    from adversary_solids import box
    from inertia_tool.mesh.rims import boundary_edges
    from inertia_tool.mesh.sheets import _seamed_sheet
    from inertia_tool.tolerances import MERGE_TOLERANCE, ROUNDOFF_RTOL, WALL_PLANE_RTOL

    v, f = box((1.0, 2.0, 0.5), subdivide=subdivide)
    centre = v[f].mean(axis=1)
    hole = (np.abs(centre[:, 2] - 0.25) < 1e-12) & (np.linalg.norm(centre[:, :2], axis=1) < 0.3)
    g = f[~hole]
    b = boundary_edges(g, len(v))
    args = (v, g, 64, WALL_PLANE_RTOL, MERGE_TOLERANCE, ROUNDOFF_RTOL)
    without, _ = _cpu(lambda: _seamed_sheet(*args), repeat)
    given, found = _cpu(lambda: _seamed_sheet(*args, b), repeat)
    print(f"seamed-sheet search, {len(g):,}-face box with a planar hole (finds {found}): "
          f"{without:.3f} s CPU without the boundary, {given:.3f} s with it")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--subdivide", type=int, default=7)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.1f} (1 min) on {os.cpu_count()} cores")
    walls(args.cases, args.repeat)
    seams(args.subdivide, args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
