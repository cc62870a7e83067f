"""Stage benchmark: ns per corner of each stage of the validated analysis of a large binary STL, against
``numpy.fromfile`` of the same file, in one process with a warm page cache (issue 25).

For each mesh (a 1M-face torus, the 1.1M-face CAD part of ``bench_intersect.py --shape wheel``, the 5.24M-face
icosphere of ``bench_engine.py``, a 10M-face torus; written
into ``$INERTIA_TOOL_BENCH_OUT``, else ``benchmarks/out/``, when missing; not committed) it reports the median
of ``--repeat`` runs of:

* ``fromfile``: ``numpy.fromfile`` of the whole file (a fresh allocation each time, as the reader's is);
* the stages of :func:`inertia_tool.mass_properties`, called one by one as ``prepare_mesh`` calls them:
  ``read`` (the file's records, chunk by chunk), ``weld`` (``load_mesh`` less ``read``), ``census``
  (``edge_topology``), ``shells`` (``shell_labels``), ``census+shells`` (both from one call,
  ``census_and_shells``, as ``prepare_mesh`` takes them), ``check`` (``surface_contacts``, the face-pair
  self-intersection check), ``integrate`` (``body_volume_moments``), ``precision`` (the float32 storage
  bound of ``warn_storage_precision``), each in ns per corner (3 per face) and in seconds;
* ``total``: ``mass_properties(path, density=1000)`` in-process, and its ratio to ``fromfile`` (wall, and CPU
  time of all threads: on a loaded machine the CPU ratio is the steadier one), median against median and
  best against best (the issue's yardstick: the fastest ``fromfile``, whose own time moves with the page
  faults of its fresh buffer);
* ``peak``: the peak resident memory (VmHWM) of a fresh child that imports the package and runs
  ``mass_properties`` once, as a multiple of the file size (and the same less the child's resident memory
  after the imports).

The machine is shared: wall times are noisy, so compare ratios within one run, and note the load (printed).

The median of each stage is printed, and (``min``) the least CPU time of the runs.

    python benchmarks/bench_stages.py [--sizes 1m cad 5m 10m] [--repeat 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
import warnings
from collections.abc import Callable

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))          # _shapes (benchmarks/ is not a package)

HERE = os.path.dirname(os.path.abspath(__file__))
#: Where the meshes are written (not committed): ``$INERTIA_TOOL_BENCH_OUT`` if set (e.g. /tmp/bench), else
#: ``benchmarks/out``.
OUT = os.environ.get("INERTIA_TOOL_BENCH_OUT") or os.path.join(HERE, "out")
_RECORD = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])


def _write_stl(path: str, triangles: np.ndarray) -> None:
    rec = np.zeros(len(triangles), dtype=_RECORD)
    rec["v"] = triangles
    tmp = path + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(b"bench_stages".ljust(80, b" "))
        fh.write(np.uint32(len(rec)).tobytes())
        rec.tofile(fh)
    os.replace(tmp, path)


def torus(n_major: int, n_minor: int, major: float = 50.0, minor: float = 25.0) -> str:
    """A closed torus of ``2·n_major·n_minor`` faces (float32 corners), written once."""
    path = os.path.join(OUT, f"torus_{n_major}x{n_minor}.stl")
    if os.path.exists(path):
        return path
    os.makedirs(OUT, exist_ok=True)
    u = 2 * np.pi * np.arange(n_major) / n_major
    w = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = major + minor * np.cos(ww)
    pts = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(ww)], axis=-1).astype(np.float32)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    i1, j1 = (i + 1) % n_major, (j + 1) % n_minor
    a, b, c, d = pts[i, j], pts[i1, j], pts[i1, j1], pts[i, j1]
    tri = np.concatenate([np.stack([a, b, c], axis=-2).reshape(-1, 3, 3),
                          np.stack([a, c, d], axis=-2).reshape(-1, 3, 3)])
    _write_stl(path, tri)
    return path


def icosphere(subdivisions: int) -> str:
    """The icosphere of ``bench_engine.py`` (radius 50, float32 corners), written once."""
    path = os.path.join(OUT, f"icosphere_{subdivisions}.stl")
    if os.path.exists(path):
        return path
    import trimesh
    os.makedirs(OUT, exist_ok=True)
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=50.0)
    _write_stl(path, m.vertices.astype(np.float32)[m.faces])
    return path


def cad_part() -> str:
    """The CAD part of ``bench_intersect.py --shape wheel`` (``meshes/unbalanced_wheel.stl`` midpoint-subdivided
    to 1,108,992 faces: flat faces, fan caps, slivers), float32 corners, written once."""
    path = os.path.join(OUT, "wheel_1108992.stl")
    if os.path.exists(path):
        return path
    from _shapes import wheel
    os.makedirs(OUT, exist_ok=True)
    v, f = wheel(1e6)
    _write_stl(path, v.astype(np.float32)[f])
    return path


SIZES: dict[str, Callable[[], str]] = {
    "1m": lambda: torus(1000, 500),          # 1,000,000 faces
    "cad": cad_part,                         # 1,108,992 faces
    "5m": lambda: icosphere(9),              # 5,242,880 faces
    "10m": lambda: torus(3162, 1581),        # 9,998,244 faces
}

_CHILD = r"""
import sys, warnings
def status(field):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field):
                return int(line.split()[1]) * 1024
    return 0
import numpy as np
import inertia_tool
from inertia_tool.mass.pipeline import mass_properties
base = status("VmRSS:")
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    mass_properties(sys.argv[1], density=1000.0)
print(base, status("VmHWM:"))
"""


def _times(fn: Callable[[], object], repeat: int) -> tuple[float, float, float, float]:
    """Median wall, median CPU (all threads of this process), minimum wall and minimum CPU seconds of
    ``repeat`` calls."""
    wall, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return statistics.median(wall), statistics.median(cpu), min(wall), min(cpu)


def measure(path: str, repeat: int) -> dict:
    from inertia_tool.integrals import body_volume_moments
    from inertia_tool.mass.pipeline import mass_properties
    from inertia_tool.mesh.checks import census_and_shells, edge_topology, shell_labels
    from inertia_tool.mesh.intersect import surface_contacts
    from inertia_tool.mesh.precision import volume_rounding_bound
    from inertia_tool.mesh.read import _binary_stl_chunks, load_mesh

    size = os.path.getsize(path)
    n = (size - 84) // 50
    corners = 3 * n
    warnings.simplefilter("ignore")
    raw = load_mesh(path)                                   # warms the page cache and the imports
    v, f = raw.vertices, raw.faces
    labels, n_shells = shell_labels(f, len(v))
    rounding = raw.storage_rounding
    views = _binary_stl_chunks(path, n, padded=False)

    def read() -> None:
        for _ in views():
            pass

    stages: dict[str, Callable[[], object]] = {
        "fromfile": lambda: np.fromfile(path, dtype=np.uint8),
        "read": read,
        "load": lambda: load_mesh(path),
        "census": lambda: edge_topology(f, len(v), v),
        "shells": lambda: shell_labels(f, len(v)),
        "census+shells": lambda: census_and_shells(f, len(v), v),
        "check": lambda: surface_contacts(v, f),
        "integrate": lambda: body_volume_moments(v, f, labels, n_shells),
        "precision": lambda: volume_rounding_bound(v, f, rounding),
        "total": lambda: mass_properties(path, density=1000.0),
    }
    timed = {name: _times(fn, repeat) for name, fn in stages.items()}
    seconds = {name: t[0] for name, t in timed.items()}
    cpu = {name: t[1] for name, t in timed.items()}
    best = {name: t[2] for name, t in timed.items()}
    best_cpu = {name: t[3] for name, t in timed.items()}
    seconds["weld"] = max(seconds.pop("load") - seconds["read"], 0.0)
    cpu["weld"] = max(cpu.pop("load") - cpu["read"], 0.0)
    best_cpu["weld"] = max(best_cpu.pop("load") - best_cpu["read"], 0.0)
    best.pop("load")
    child = subprocess.run([sys.executable, "-c", _CHILD, path], capture_output=True, text=True, check=True,
                           env={**os.environ, "PYTHONPATH": os.path.dirname(HERE)})
    base, peak = (int(x) for x in child.stdout.split()[-2:])
    parts = ("read", "weld", "census", "shells", "census+shells", "check", "integrate", "precision")
    return {
        "file": os.path.basename(path), "faces": n, "file_bytes": size, "seconds": seconds, "cpu_seconds": cpu,
        "ns_per_corner": {k: 1e9 * seconds[k] / corners for k in parts + ("total",)},
        "cpu_ns_per_corner": {k: 1e9 * cpu[k] / corners for k in parts + ("total",)},
        "best_cpu_ns_per_corner": {k: 1e9 * best_cpu[k] / corners for k in parts + ("total",)},
        "check_vs_rest_cpu": cpu["check"] / max(cpu["total"] - cpu["check"], 1e-12),
        "check_vs_rest": seconds["check"] / max(seconds["total"] - seconds["check"], 1e-12),
        "total_vs_fromfile": seconds["total"] / seconds["fromfile"],
        "total_vs_fromfile_cpu": cpu["total"] / max(cpu["fromfile"], 1e-12),
        # best with best (issue 25): the fastest analysis against the fastest fromfile, whose own time moves
        # with the page faults of its fresh buffer far more than the analysis's
        "best_total_vs_fromfile": best["total"] / best["fromfile"],
        "best_total_vs_fromfile_cpu": best_cpu["total"] / max(best_cpu["fromfile"], 1e-12),
        "best_seconds": best, "best_cpu_seconds": best_cpu,
        "peak_bytes": peak, "peak_vs_file": peak / size, "peak_above_imports_vs_file": (peak - base) / size,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", nargs="+", default=["1m", "5m"], choices=sorted(SIZES))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="also write the results here")
    args = ap.parse_args(argv)
    from inertia_tool._native import accel, threads
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; C extension "
          f"{'on' if accel() is not None else 'off'}, {threads()} threads; median of {args.repeat}")
    rows = []
    for key in args.sizes:
        r = measure(SIZES[key](), args.repeat)
        rows.append(r)
        ns = r["ns_per_corner"]
        print(f"\n{r['file']}: {r['faces']:,} faces, {r['file_bytes'] / 1e6:.0f} MB; "
              f"fromfile {r['seconds']['fromfile']:.3f} s, total {r['seconds']['total']:.2f} s "
              f"= {r['total_vs_fromfile']:.1f}x fromfile (medians; best with best {r['best_total_vs_fromfile']:.1f}x "
              f"wall, {r['best_total_vs_fromfile_cpu']:.1f}x CPU); peak {r['peak_bytes'] / 1e6:.0f} MB "
              f"= {r['peak_vs_file']:.2f}x the file ({r['peak_above_imports_vs_file']:.2f}x above the imports); "
              f"check / rest {r['check_vs_rest']:.2f}")
        print("  wall " + "  ".join(f"{k} {ns[k]:.1f}" for k in ns) + "  (ns per corner)")
        cns = r["cpu_ns_per_corner"]
        print("  cpu  " + "  ".join(f"{k} {cns[k]:.1f}" for k in cns) + "  (ns per corner, all threads)"
              f"; check / rest (CPU) {r['check_vs_rest_cpu']:.2f}; total / fromfile (CPU) "
              f"{r['total_vs_fromfile_cpu']:.1f}")
        mns = r["best_cpu_ns_per_corner"]
        print("  min  " + "  ".join(f"{k} {mns[k]:.1f}" for k in mns) + "  (ns per corner, CPU, least of the runs)")
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
