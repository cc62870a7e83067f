"""Throughput of ``inertia-tool batch``: files/s with 1 process, 2 processes and a Dask LocalCluster(2).

Generates N binary STL files (default 200: icospheres of 5,120-20,480 triangles, boxes, tori of 2k-18k,
cylinders of 1k-4k; 0.6 kB-1 MB)
in a temporary directory, then runs the same batch three ways, each into a fresh JSONL file, and prints files/s
and the speed-up over one process.  The Dask cluster's start-up is timed separately (not in files/s).

    python benchmarks/bench_batch.py [--files 200] [--repeat 1]

Run from the repository root (it puts the repository on sys.path).  The machine it ran on matters: the README
numbers are from the project's 2-core machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from inertia_tool.mesh import LoadOptions
from inertia_tool.batch.runner import BatchOptions, discover_files, run_batch  # noqa: E402
from inertia_tool.batch.rows import open_results  # noqa: E402


def _write_stl(path, mesh):
    tri = np.asarray(mesh.vertices, dtype=np.float32)[np.asarray(mesh.faces)]
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    with open(path, "wb") as fh:
        fh.write(b"bench".ljust(80))
        fh.write(np.uint32(len(tri)).tobytes())
        fh.write(rec.tobytes())


def make_meshes(directory: str, count: int, seed: int = 0) -> int:
    """Write ``count`` meshes; return the total number of triangles."""
    rng = np.random.default_rng(seed)
    faces = 0
    for k in range(count):
        kind = k % 4
        if kind == 0:
            m = trimesh.creation.icosphere(subdivisions=int(rng.integers(4, 6)), radius=float(rng.uniform(5, 50)))
        elif kind == 1:
            m = trimesh.creation.box(rng.uniform(5, 80, 3))
        elif kind == 2:
            m = trimesh.creation.torus(float(rng.uniform(20, 40)), float(rng.uniform(3, 10)),
                                       major_sections=int(rng.integers(64, 192)),
                                       minor_sections=int(rng.integers(16, 48)))
        else:
            m = trimesh.creation.cylinder(radius=float(rng.uniform(3, 30)), height=float(rng.uniform(5, 90)),
                                          sections=int(rng.integers(256, 1024)))
        m.apply_translation(rng.uniform(-100, 100, 3))
        _write_stl(os.path.join(directory, f"part{k:04d}.stl"), m)
        faces += len(m.faces)
    return faces


def _run(files, out, **kw):
    with open_results(out) as r:
        summary = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1240.0), r.write_row, **kw)
    if summary.ok != len(files):
        raise SystemExit(f"benchmark: {summary.failed} files failed")
    return summary.seconds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=1, help="runs of each configuration (best is reported)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        mesh_dir = os.path.join(tmp, "meshes")
        os.mkdir(mesh_dir)
        faces = make_meshes(mesh_dir, args.files)
        files = discover_files(mesh_dir)
        size = sum(os.path.getsize(f) for f in files)
        print(f"{len(files)} STL files, {faces:,} triangles, {size / 1e6:.1f} MB; "
              f"{platform.processor() or platform.machine()}, "
              f"{os.cpu_count()} CPUs, Python {platform.python_version()}, load average before "
              f"{os.getloadavg()[0]:.2f} (other work on the machine slows the parallel runs)")
        results = {}
        for label, kw in [("1 process (in-process)", dict(jobs=1)),
                          ("2 processes (ProcessPoolExecutor)", dict(jobs=2))]:
            results[label] = min(_run(files, os.path.join(tmp, f"{label[:1]}_{r}.jsonl"), **kw)
                                 for r in range(args.repeat))
        try:
            from inertia_tool.cli.batch import dask_executor
            t0 = time.perf_counter()
            executor, shutdown = dask_executor("local", 2)
            startup = time.perf_counter() - t0
            try:
                results["Dask LocalCluster(2 workers)"] = min(
                    _run(files, os.path.join(tmp, f"d_{r}.jsonl"), jobs=2, executor=executor)
                    for r in range(args.repeat))
            finally:
                shutdown()
        except ImportError:
            startup = None
        base = results["1 process (in-process)"]
        print(f"{'configuration':36s} {'seconds':>8s} {'files/s':>8s} {'speed-up':>8s}")
        for label, sec in results.items():
            print(f"{label:36s} {sec:8.2f} {len(files) / sec:8.1f} {base / sec:8.2f}")
        if startup is not None:
            print(f"(Dask LocalCluster start-up, not included above: {startup:.2f} s)")


if __name__ == "__main__":
    main()
