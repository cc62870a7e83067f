"""Weld benchmark: ns per corner of each step of the radix-partition weld (``_accel.PartWelder``) against the
one-table ``Welder``, on the large binary STL files of ``bench_stages.py``, in one process, warm page cache.

For each file and each thread count it reports, as minimum and median over ``--repeat`` rounds (the rounds
interleave the variants, so a burst of load on the shared machine hits all of them):

* ``read``: the file's records chunk by chunk (what both welders are fed from);
* ``welder``: the one-table ``Welder`` fed the same chunks, read included;
* ``feed``: ``PartWelder.feed`` of every chunk (recent-point cache, histogram and staging, scatter), read
  included;
* ``finish``: the buckets welded in their tables, first corners marked, each corner given its vertex's first;
* ``output``: every corner's number gathered in file order, each vertex written at its first corner;
* ``total``: feed + finish + output, read included.

Wall and CPU time (all threads of the process), ns per corner (three per face); every round checks that both
welders give the same vertices and ids.  The machine is shared: note the load average (printed).

    python benchmarks/bench_weld.py [--sizes 1m 5m 10m] [--threads 1 2] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

# bench_stages (imported in main) puts this checkout on sys.path only when no inertia_tool is importable:
# a PYTHONPATH or an installed package is the one measured
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def measure(path: str, threads: list[int], repeat: int) -> dict[str, list[tuple[float, float]]]:
    from inertia_tool._native import accel
    from inertia_tool.mesh.read_stl import _binary_stl_chunks

    lib = accel()
    if lib is None:
        raise SystemExit("the C extension is not built (or INERTIA_TOOL_NO_ACCEL is set)")
    n = (os.path.getsize(path) - 84) // 50
    corners = 3 * n
    views = _binary_stl_chunks(path, n, padded=False)
    times: dict[str, list[tuple[float, float]]] = {}

    def add(key: str, t0: tuple[float, float], t1: tuple[float, float]) -> None:
        times.setdefault(key, []).append(((t1[0] - t0[0]) * 1e9 / corners, (t1[1] - t0[1]) * 1e9 / corners))

    for _ in range(repeat):
        t = _clock()
        for _v in views():
            pass
        add("read", t, _clock())
        t = _clock()
        welder = lib.Welder("float32", corners // 6)
        ref_ids = np.empty(corners, np.int32)
        s = 0
        for v in views():
            k = v.size // 3
            welder.feed(v, ref_ids[s:s + k])
            s += k
        ref_vertices = np.empty((welder.count, 3))
        welder.vertices_into(ref_vertices)
        add("welder", t, _clock())
        del welder
        for nt in threads:
            t0 = _clock()
            ids = np.empty(corners, np.int32)
            part = lib.PartWelder(ids, nt)
            for v in views():
                part.feed(v)
            t1 = _clock()
            count = part.finish()
            t2 = _clock()
            vertices = np.empty((count, 3))
            part.output(vertices)
            t3 = _clock()
            if not (np.array_equal(ids, ref_ids) and np.array_equal(vertices, ref_vertices)):
                raise SystemExit(f"{path}: PartWelder({nt} threads) differs from Welder")
            add(f"feed {nt}", t0, t1)
            add(f"finish {nt}", t1, t2)
            add(f"output {nt}", t2, t3)
            add(f"total {nt}", t0, t3)
            del part, ids, vertices
    return times


def main(argv: list[str] | None = None) -> int:
    import bench_stages

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", nargs="+", default=["1m", "5m", "10m"], choices=sorted(bench_stages.SIZES))
    ap.add_argument("--threads", nargs="+", type=int, default=[1, 2])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; min / median of {args.repeat}, "
          f"ns per corner")
    for key in args.sizes:
        path = bench_stages.SIZES[key]()
        times = measure(path, args.threads, args.repeat)
        print(f"\n{os.path.basename(path)} ({(os.path.getsize(path) - 84) // 50:,} faces)")
        for name, runs in times.items():
            wall = sorted(w for w, _ in runs)
            cpu = sorted(c for _, c in runs)
            print(f"  {name:10s} wall {wall[0]:6.1f} / {statistics.median(wall):6.1f}   "
                  f"cpu {cpu[0]:6.1f} / {statistics.median(cpu):6.1f}")
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
