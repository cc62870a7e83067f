"""The clean-part fast path (``mesh/clean_part.py``) against the full checks, in one process, on the batch's per-file
work: CPU per file both ways, how many parts take it, and whether the rows are the same.

Writes the ``small`` catalogue of ``bench_batch.py`` (``--small`` binary STL parts of 12-4,800 triangles) and 200
boxes of 12 triangles, then runs ``analyze_chunk`` over each set ``--repeat`` times each way, alternating (the fast
path as the batch runs it, then with ``prepare_clean`` answering None for every part, so that every part takes the
full ``prepare_mesh``), and prints the CPU µs per file (``time.process_time``; least and median of the passes) with
the load average, the parts the fast path took, and the rows compared field by field (``seconds`` and ``worker``
left out).

    python benchmarks/bench_batch_fast_path.py [--small 1000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(1, os.path.dirname(HERE))

import trimesh  # noqa: E402

from bench_batch import _require_c_kernels, _write_stl, make_small_meshes  # noqa: E402
from inertia_tool.batch.runner import BatchOptions, analyze_chunk, discover_files  # noqa: E402
from inertia_tool.mass import pipeline  # noqa: E402
from inertia_tool.mesh import LoadOptions  # noqa: E402

#: Row fields that differ between two runs of the same code.
VOLATILE = ("seconds", "worker")


def _passes(files: list[str], repeat: int) -> dict:
    """CPU seconds per file of each pass both ways, the parts the fast path took, and the rows of each way."""
    options = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    chunk = [(path, None) for path in files]
    real = pipeline.prepare_clean
    taken = []

    def counted(raw):
        got = real(raw)
        taken.append(got is not None)
        return got

    ways = {"fast path": counted, "full checks": lambda raw: None}
    times: dict[str, list[float]] = {name: [] for name in ways}
    rows: dict[str, list[dict]] = {}
    try:
        for r in range(repeat + 1):                     # the first round warms both ways up, untimed
            for name, clean in (ways.items() if r % 2 == 0 else reversed(ways.items())):
                pipeline.prepare_clean = clean          # type: ignore[assignment]
                taken.clear()
                t0 = time.process_time()
                got = analyze_chunk(chunk, options)
                seconds = time.process_time() - t0
                if r:
                    times[name].append(seconds / len(files))
                rows[name] = got
                if name == "fast path":
                    n_taken = sum(taken)
    finally:
        pipeline.prepare_clean = real                   # type: ignore[assignment]
    same = 0
    for a, b in zip(rows["fast path"], rows["full checks"]):
        a, b = dict(a), dict(b)
        for k in VOLATILE:
            a.pop(k), b.pop(k)
        same += a == b
    return {"times": times, "taken": n_taken, "same": same, "rows": len(files)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=1000, help="parts of the small catalogue")
    ap.add_argument("--repeat", type=int, default=5, help="timed passes each way")
    args = ap.parse_args()
    _require_c_kernels()
    warnings.simplefilter("ignore")
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        small, boxes = os.path.join(tmp, "small"), os.path.join(tmp, "box")
        os.mkdir(small)
        os.mkdir(boxes)
        make_small_meshes(small, args.small)
        for k in range(200):
            _write_stl(os.path.join(boxes, f"box{k:03d}.stl"), trimesh.creation.box((10.0 + k, 20.0, 30.0)))
        found = {f"{args.small} parts of the catalogue": _passes(discover_files(small), args.repeat),
                 "200 boxes of 12 triangles": _passes(discover_files(boxes), args.repeat)}
    print(f"load average before {', '.join(f'{x:.1f}' for x in load)}, after "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}; CPU µs per file of analyze_chunk, least / median of "
          f"{args.repeat} passes each way, alternating")
    print("\n| files | full checks | fast path | change (least) | took the fast path | rows identical |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, got in found.items():
        full, fast = got["times"]["full checks"], got["times"]["fast path"]
        print(f"| {name} | {min(full) * 1e6:,.0f} / {statistics.median(full) * 1e6:,.0f} | "
              f"{min(fast) * 1e6:,.0f} / {statistics.median(fast) * 1e6:,.0f} | "
              f"{min(fast) / min(full) - 1:+.0%} | {got['taken']} of {got['rows']} | {got['same']} of {got['rows']} |")


if __name__ == "__main__":
    main()
