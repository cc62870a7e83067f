"""Stage benchmark: where the time of the validated analysis of a large binary STL goes, in ns per corner,
against ``numpy.fromfile`` of the same file, in one process with a warm page cache (issue 25).

For each mesh (a 1M-face torus, the 1.1M-face CAD part of ``bench_intersect.py --shape wheel``, the 5.24M-face
icosphere of ``bench_engine.py``, a 10M-face torus; written
into ``$INERTIA_TOOL_BENCH_OUT``, else ``benchmarks/out/``, when missing; not committed) it times, ``--repeat``
times each:

* ``fromfile``: ``numpy.fromfile`` of the whole file (a fresh allocation each time, as the reader's is);
* ``total``: ``mass_properties(path, density=1000)`` in-process, plain;
* the same call under a profile hook (:func:`sys.setprofile`) that charges every interval between two
  call/return events (Python and C functions, generator resumptions included) to the innermost *stage* on the
  call stack (:data:`STAGES`: ``read``, ``weld``, ``census+shells``, ``check``, ``integrate``, ``roundoff``,
  ``precision``, ``bounds``), or to ``other`` when no stage is on the stack (the pipeline's Python glue and
  the small numpy calls between the kernels).  So the rows add up to the profiled total exactly, and the
  largest functions inside ``other`` are listed by name.  The profiled total exceeds the plain one by the
  hook's own cost (printed as ``hook``; a few thousand events, well under 1 ns per corner).

Each stage in ns per corner (3 per face), CPU time of all threads of the process (the C kernels' worker
threads included; on a loaded machine the steadier measure) and wall time: the breakdown of the profiled run
with the least CPU time (its rows sum to its total), and the least of each row over the runs; with the system
(kernel) part of each row's CPU time and its minor page faults (``getrusage``): fresh anonymous pages cost a
fault and a zeroing each, which shows there rather than in the kernels' own loops.  ``total`` and
``fromfile`` are also reported as medians and best with best (the issue's yardstick: the fastest analysis
against the fastest ``fromfile``, whose own time moves with the page faults of its fresh buffer).

``peak``: the peak resident memory (VmHWM) of a fresh child that imports the package and runs
``mass_properties`` once, as a multiple of the file size (and the same less the child's resident memory
after the imports).

The package measured is the one ``import inertia_tool`` finds (``PYTHONPATH``, else the installed one; the
repository holding this script only when neither has it), printed first; the child imports the same one.
The machine is shared: wall times are noisy, so compare ratios within one run, and note the load (printed).
It refuses to run when the C kernels are not loaded (a missing build, or one from another ``_accel.c``: the
package then falls back to numpy with one warning, and the rows would time another program), unless
``INERTIA_TOOL_NO_ACCEL`` asks for numpy on purpose.

    python benchmarks/bench_stages.py [--sizes 1m cad 5m 10m] [--repeat 5] [--json out.json] [--out /tmp/bench]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import warnings
from collections.abc import Callable
from types import CodeType, FrameType
from typing import Any

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _checkouts import this_checkout_first  # noqa: E402  (benchmarks/ is not a package)

# this checkout's inertia_tool, unless PYTHONPATH names another (before, an installed package won: an editable
# install of another checkout was measured instead of the one holding this script)
this_checkout_first()

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
    sys.path.insert(0, HERE)            # _shapes (benchmarks/ is not a package)
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


#: The stages of the analysis: row name -> the Python functions (``module:qualified name``, generators and
#: nested functions included; a C kernel is timed inside the function that calls it) whose time, less that of
#: any stage they call, is the row's.  Whatever runs with none of them on the stack is ``other``.
STAGES: dict[str, tuple[str, ...]] = {
    "read": ("inertia_tool.mesh.read_stl:_binary_stl_chunks.<locals>.views",
             "inertia_tool.mesh.read_stl:_binary_stl_chunks.<locals>.chunks"),
    "weld": ("inertia_tool.mesh.weld:weld_exact_stream",),
    "census+shells": ("inertia_tool.mesh.checks:census_and_shells", "inertia_tool.mesh.checks:edge_topology",
                      "inertia_tool.mesh.checks:shell_labels"),
    "check": ("inertia_tool.mesh.intersect:surface_contacts",),
    "integrate": ("inertia_tool.integrals:_tetra_sums",),
    "roundoff": ("inertia_tool.integrals:roundoff_bounds",),
    "precision": ("inertia_tool.mesh.precision:volume_rounding_bound",),
    "bounds": ("inertia_tool.integrals:bounding_box", "inertia_tool.mesh.read_stl:_finite_magnitude"),
}
OTHER = "other"


def _stage_codes() -> dict[CodeType, str]:
    """The code objects of the stage functions, each with its row.

    Every name must resolve: a stage renamed in the package fails the benchmark instead of falling into
    ``other`` unnoticed."""
    import importlib

    codes: dict[CodeType, str] = {}
    for row, names in STAGES.items():
        for name in names:
            module_name, qualname = name.split(":")
            module = importlib.import_module(module_name)
            outer = getattr(module, qualname.split(".")[0], None)
            if outer is None:
                raise SystemExit(f"bench_stages: expected {name} in the package, found no such function")
            code = outer.__code__
            for part in qualname.split(".<locals>.")[1:]:
                inner = [c for c in code.co_consts if isinstance(c, CodeType) and c.co_name == part]
                if len(inner) != 1:
                    raise SystemExit(f"bench_stages: expected one {part} inside {module_name}.{code.co_name}, "
                                     f"found {len(inner)}")
                code = inner[0]
            codes[code] = row
    return codes


def _kernel_clock() -> tuple[float, int]:
    """System CPU seconds and minor page faults of the process so far (all threads; Linux counts the system
    time by the scheduler's accounting, coarser than ``process_time``)."""
    use = resource.getrusage(resource.RUSAGE_SELF)
    return use.ru_stime, use.ru_minflt


class StageClock:
    """A :func:`sys.setprofile` hook that charges the CPU (all threads) and wall time between consecutive
    events to the stage innermost on the call stack, and, for ``other``, to the innermost function by name.

    Every event pushes or pops one entry, so the stack mirrors the interpreter's; time before the first and
    after the last event (inside :meth:`run`) is charged to ``other``, and the hook's own time to the entry on
    top after it (the rows add up to the clocks' advance over the call).  The clocks are parameters so that a
    test can drive them.
    """

    def __init__(self, cpu_clock: Callable[[], float] = time.process_time,
                 wall_clock: Callable[[], float] = time.perf_counter,
                 kernel_clock: Callable[[], tuple[float, int]] = _kernel_clock) -> None:
        self.codes = _stage_codes()
        self.cpu_clock, self.wall_clock, self.kernel_clock = cpu_clock, wall_clock, kernel_clock
        self.events = 0
        #: of the last run, by row: system CPU seconds (the kernel's share of the CPU time: page faults and the
        #: zeroing of fresh pages, the file's copy out of the page cache) and minor page faults
        self.sys: dict[str, float] = {}
        self.faults: dict[str, int] = {}

    def run(self, fn: Callable[[], object]) -> tuple[dict[str, float], dict[str, float], dict[str, float]]:
        """Run ``fn`` under the hook; CPU and wall seconds by row, and CPU seconds of ``other`` by function."""
        cpu_clock, wall_clock, kernel_clock = self.cpu_clock, self.wall_clock, self.kernel_clock
        codes = self.codes
        cpu: dict[str, float] = dict.fromkeys((*STAGES, OTHER), 0.0)
        wall: dict[str, float] = dict.fromkeys((*STAGES, OTHER), 0.0)
        other: dict[str, float] = {}
        stack: list[tuple[str, str]] = [(OTHER, "run")]
        sys_time: dict[str, float] = dict.fromkeys((*STAGES, OTHER), 0.0)
        faults: dict[str, int] = dict.fromkeys((*STAGES, OTHER), 0)
        last: list[Any] = [cpu_clock(), wall_clock(), *kernel_clock()]
        events = [0]

        def charge() -> None:
            c, w = cpu_clock(), wall_clock()
            k, f = kernel_clock()
            row, where = stack[-1]
            cpu[row] += c - last[0]
            wall[row] += w - last[1]
            sys_time[row] += k - last[2]
            faults[row] += f - last[3]
            if row == OTHER:
                other[where] = other.get(where, 0.0) + c - last[0]
            last[:] = c, w, k, f

        def hook(frame: FrameType, event: str, arg: Any) -> None:
            events[0] += 1
            charge()
            if event == "call":
                code = frame.f_code
                row = codes.get(code)
                name = getattr(code, "co_qualname", code.co_name)        # Python >= 3.11
                stack.append((row, name) if row is not None
                             else (stack[-1][0], f"{os.path.basename(code.co_filename)}:{name}"))
            elif event == "c_call":
                stack.append((stack[-1][0], _c_name(arg)))
            elif len(stack) > 1:        # return, c_return, c_exception
                stack.pop()
            # the hook's own time falls into the next interval, so that the rows add up to the whole

        sys.setprofile(hook)
        try:
            fn()
        finally:
            sys.setprofile(None)
            charge()
        self.events = events[0]
        self.sys, self.faults = sys_time, faults
        return cpu, wall, other


def _c_name(fn: Any) -> str:
    """``module.function`` of a C function, ``Type.method`` of a C method."""
    owner = getattr(fn, "__self__", None)
    qualname = getattr(fn, "__qualname__", repr(fn))
    if owner is None or isinstance(owner, type(sys)):
        return f"{getattr(fn, '__module__', None) or getattr(owner, '__name__', '?')}.{qualname}"
    return qualname


def _times(fn: Callable[[], object], repeat: int) -> tuple[list[float], list[float]]:
    """Wall and CPU (all threads of this process) seconds of ``repeat`` calls."""
    wall, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return wall, cpu


def _package_root() -> str:
    import inertia_tool
    return os.path.dirname(os.path.dirname(os.path.abspath(inertia_tool.__file__)))


def require_c_kernels() -> None:
    """Stop unless the C kernels are loaded, or switched off on purpose (``INERTIA_TOOL_NO_ACCEL``): a checkout
    whose ``_accel.c`` changed (a rebase) without a rebuild falls back to numpy with one warning, and its
    numbers would be numpy's."""
    from inertia_tool._native import NO_ACCEL_ENV, accel

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # the stale-build warning: said below, in one line
        loaded = accel() is not None
    if not loaded and os.environ.get(NO_ACCEL_ENV, "").strip() in ("", "0"):
        raise SystemExit(f"bench_stages: expected the C kernels of {_package_root()} loaded, found them missing or "
                         "built from another _accel.c (rebuild the extension); its numbers would be numpy's. Set "
                         f"{NO_ACCEL_ENV}=1 to time the numpy path on purpose")


def measure(path: str, repeat: int) -> dict:
    from inertia_tool.mass.pipeline import mass_properties

    size = os.path.getsize(path)
    n = (size - 84) // 50
    corners = 3 * n
    warnings.simplefilter("ignore")
    mass_properties(path, density=1000.0)                    # warms the page cache and the imports
    clock = StageClock()
    ns = 1e9 / corners
    fromfile_wall, fromfile_cpu = _times(lambda: np.fromfile(path, dtype=np.uint8), repeat)
    total_wall, total_cpu = [], []
    runs = []
    for _ in range(repeat):        # plain and profiled runs interleaved, so that a burst of load hits both
        w, c = _times(lambda: mass_properties(path, density=1000.0), 1)
        total_wall += w
        total_cpu += c
        runs.append((*clock.run(lambda: mass_properties(path, density=1000.0)), clock.sys, clock.faults))
    best = min(range(repeat), key=lambda i: sum(runs[i][0].values()))
    rows = (*STAGES, OTHER)
    cpu_best_run = {k: runs[best][0][k] * ns for k in rows}
    wall_best_run = {k: runs[best][1][k] * ns for k in rows}
    cpu_min = {k: min(r[0][k] for r in runs) * ns for k in rows}
    cpu_median = {k: statistics.median(r[0][k] for r in runs) * ns for k in rows}
    profiled_cpu = sum(runs[best][0].values())
    other = sorted(runs[best][2].items(), key=lambda kv: -kv[1])[:8]
    sys_best_run = {k: runs[best][3][k] * ns for k in rows}
    faults_best_run = {k: runs[best][4][k] / corners * 1e3 for k in rows}
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (_package_root(), os.environ.get("PYTHONPATH")) if p)
    # cwd: a ``-c`` child puts its working directory first on sys.path, ahead of PYTHONPATH
    child = subprocess.run([sys.executable, "-c", _CHILD, path], capture_output=True, text=True, check=True,
                           env=env, cwd=_package_root())
    base, peak = (int(x) for x in child.stdout.split()[-2:])
    med = statistics.median
    return {
        "file": os.path.basename(path), "faces": n, "file_bytes": size, "profile_events": clock.events,
        "cpu_ns_per_corner": cpu_best_run, "wall_ns_per_corner": wall_best_run, "cpu_ns_per_corner_min": cpu_min,
        "cpu_ns_per_corner_median": cpu_median,
        "sys_ns_per_corner": sys_best_run, "faults_per_1000_corners": faults_best_run,
        "other_cpu_ns_per_corner": {k: v * ns for k, v in other},
        "profiled_total_cpu_ns_per_corner": profiled_cpu * ns,
        "total_cpu_ns_per_corner": min(total_cpu) * ns, "total_wall_ns_per_corner": min(total_wall) * ns,
        "hook_cpu_ns_per_corner": (profiled_cpu - min(total_cpu)) * ns,
        "fromfile_seconds": {"median": med(fromfile_wall), "best": min(fromfile_wall),
                             "cpu_median": med(fromfile_cpu), "cpu_best": min(fromfile_cpu)},
        "total_seconds": {"median": med(total_wall), "best": min(total_wall),
                          "cpu_median": med(total_cpu), "cpu_best": min(total_cpu)},
        "total_vs_fromfile": med(total_wall) / med(fromfile_wall),
        "total_vs_fromfile_cpu": med(total_cpu) / max(med(fromfile_cpu), 1e-12),
        # best with best (issue 25): the fastest analysis against the fastest fromfile, whose own time moves
        # with the page faults of its fresh buffer far more than the analysis's
        "best_total_vs_fromfile": min(total_wall) / min(fromfile_wall),
        "best_total_vs_fromfile_cpu": min(total_cpu) / max(min(fromfile_cpu), 1e-12),
        "peak_bytes": peak, "peak_vs_file": peak / size, "peak_above_imports_vs_file": (peak - base) / size,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", nargs="+", default=["1m", "5m"], choices=sorted(SIZES))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", help="also write the results here")
    ap.add_argument("--out", help="where the meshes are written or found (default: $INERTIA_TOOL_BENCH_OUT, else "
                    "benchmarks/out); e.g. /tmp/bench, outside the repository")
    args = ap.parse_args(argv)
    if args.out:
        global OUT
        OUT = args.out
    require_c_kernels()
    from inertia_tool._native import accel, threads
    print(f"inertia_tool from {_package_root()}")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; C extension "
          f"{'on' if accel() is not None else 'off'}, {threads()} threads; {args.repeat} runs each")
    results = []
    for key in args.sizes:
        r = measure(SIZES[key](), args.repeat)
        results.append(r)
        t, f = r["total_seconds"], r["fromfile_seconds"]
        print(f"\n{r['file']}: {r['faces']:,} faces, {r['file_bytes'] / 1e6:.0f} MB; fromfile {f['best']:.3f} s "
              f"(CPU {f['cpu_best']:.3f}), total {t['best']:.2f} s (CPU {t['cpu_best']:.2f}) at best: "
              f"{r['best_total_vs_fromfile']:.1f}x fromfile wall, {r['best_total_vs_fromfile_cpu']:.1f}x CPU "
              f"(medians {r['total_vs_fromfile']:.1f}x, {r['total_vs_fromfile_cpu']:.1f}x); "
              f"peak {r['peak_bytes'] / 1e6:.0f} MB = {r['peak_vs_file']:.2f}x the file "
              f"({r['peak_above_imports_vs_file']:.2f}x above the imports)")
        cpu, wall, low = r["cpu_ns_per_corner"], r["wall_ns_per_corner"], r["cpu_ns_per_corner_min"]
        mid = r["cpu_ns_per_corner_median"]
        kernel, faults = r["sys_ns_per_corner"], r["faults_per_1000_corners"]
        print(f"  {'ns per corner':<15}{'CPU':>8}{'wall':>8}{'CPU min':>9}{'CPU median':>12}{'of CPU: sys':>13}"
              f"{'faults/1k':>11}   (the profiled run with the least CPU; CPU min, median: each row's least and "
              "median over the runs; sys: the kernel's share of CPU, mostly zeroing fresh pages; faults per 1,000 "
              "corners)")
        for k in cpu:
            print(f"  {k:<15}{cpu[k]:8.1f}{wall[k]:8.1f}{low[k]:9.1f}{mid[k]:12.1f}{kernel[k]:13.1f}"
                  f"{faults[k]:11.2f}")
        print(f"  {'sum':<15}{sum(cpu.values()):8.1f}{sum(wall.values()):8.1f}{'':21}{sum(kernel.values()):13.1f}"
              f"{sum(faults.values()):11.2f}")
        print(f"  plain total    {r['total_cpu_ns_per_corner']:8.1f}{r['total_wall_ns_per_corner']:8.1f}"
              f"   (least of the unprofiled runs; hook {r['hook_cpu_ns_per_corner']:+.1f} ns CPU, "
              f"{r['profile_events']:,} events)")
        print("  largest in other (CPU ns per corner): "
              + ", ".join(f"{k} {v:.2f}" for k, v in r["other_cpu_ns_per_corner"].items()))
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
