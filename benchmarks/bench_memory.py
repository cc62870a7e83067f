"""Peak memory of ``inertia-tool analyze`` as a function of the number of triangles: the bound the face limit
(``--max-faces``) puts on the memory of a run.

Writes icospheres of 82k to 5.2M triangles as binary STL (and, smaller, as 3MF), runs
``inertia-tool analyze FILE --json`` on each in a fresh process (the child's own VmHWM, as in
``bench_engine.py``), on the C extension and on the numpy path, and fits ``peak = a + b × faces`` by least
squares per path.  Since a file is refused above ``--max-faces``, ``a + b × max_faces`` bounds the peak of any
accepted file of that format.

Usage::

    python benchmarks/bench_memory.py [--largest 9]      # icosphere subdivisions 6..largest
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from bench_engine import CHILD_OURS, OUT, run_child, write_icosphere  # noqa: E402

_MIB = 1 << 20


def write_3mf(subdivisions: int) -> str:
    import trimesh
    path = os.path.join(OUT, f"icosphere_{subdivisions}.3mf")
    if not os.path.exists(path):
        os.makedirs(OUT, exist_ok=True)
        trimesh.creation.icosphere(subdivisions=subdivisions, radius=50.0).export(path)
    return path


def fit(points):
    """Least-squares ``peak = a + b × faces``; returns ``(a bytes, b bytes per face)``."""
    f = np.array([p[0] for p in points], dtype=float)
    m = np.array([p[1] for p in points], dtype=float)
    b, a = np.polyfit(f, m, 1)
    return a, b


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--largest", type=int, default=9, help="largest icosphere subdivision (9: 5.2M faces)")
    ap.add_argument("--largest-3mf", type=int, default=7, help="largest 3MF subdivision (7: 328k faces)")
    args = ap.parse_args()
    runs = {}
    for label, env, writer, largest in (("STL, C extension", "", write_icosphere, args.largest),
                                        ("STL, numpy path", "1", write_icosphere, args.largest),
                                        ("3MF (trimesh parser), C extension", "", write_3mf, args.largest_3mf)):
        os.environ["INERTIA_TOOL_NO_ACCEL"] = env
        points = []
        for sub in range(5, largest + 1):
            path = writer(sub)
            faces = 20 * 4 ** sub
            seconds, peak = run_child(CHILD_OURS, path)
            points.append((faces, peak))
            print(f"{label:36s} {faces:>10,} faces  {os.path.getsize(path) / _MIB:8.1f} MiB file  "
                  f"{seconds:6.2f} s  peak {peak / _MIB:8.1f} MiB", flush=True)
        runs[label] = points
    os.environ.pop("INERTIA_TOOL_NO_ACCEL", None)
    print()
    print("| path | peak memory ≈ a + b × faces | at 1M faces | at the default --max-faces (50M) |")
    print("|---|---|---|---|")
    for label, points in runs.items():
        a, b = fit(points)
        print(f"| {label} | {a / _MIB:.0f} MiB + {b:.0f} B × faces | {(a + b * 1e6) / _MIB:,.0f} MiB | "
              f"{(a + b * 5e7) / (1 << 30):,.1f} GiB |")


if __name__ == "__main__":
    main()
