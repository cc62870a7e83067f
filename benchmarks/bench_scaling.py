"""Scaling of ``inertia-tool analyze`` from 1e3 to 1e7 triangles against a bare read of the file and trimesh.

For each size a closed torus is written as binary STL into benchmarks/out/ (not committed); its triangles come
row by row, as a CAD exporter writes a surface patch by patch.  Each of these then runs in a fresh process, best
of ``--repeat`` (warm page cache; the file is read once before timing):

* ``cat FILE > /dev/null``: the bare read, the physical floor (the issue's yardstick);
* ``numpy.fromfile``: the file read into memory by Python (interpreter and numpy start-up included);
* ``inertia-tool analyze FILE --json``: the whole job, interpreter start-up, imports and full watertight
  validation included, on the C extension with its threads (``INERTIA_TOOL_THREADS`` to change);
* trimesh: ``trimesh.load(FILE)`` + ``mass_properties`` (skipped above ``--trimesh-max`` faces).

It prints a table of times, peak resident memory (VmHWM of each child) and the ratios ``analyze / cat``,
``analyze / fromfile`` and ``trimesh / analyze``, measured in the same run, and draws
``docs/img/scaling.png`` (time and peak memory against faces, log-log, all four on the same axes).

    python benchmarks/bench_scaling.py [--sizes 1e3 1e4 1e5 1e6 1e7] [--repeat 3] [--plot docs/img/scaling.png]
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import resource
import subprocess
import sys
import time


HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out")
sys.path.insert(0, HERE)

from _shapes import ring_torus, write_binary_stl  # noqa: E402
from bench_engine import _PEAK, CHILD_TRIMESH  # noqa: E402

_MIB = 1 << 20

CHILD_READ = _PEAK + r"""
t = time.perf_counter()
import numpy as np
a = np.fromfile(sys.argv[1], dtype=np.uint8)
dt = time.perf_counter() - t
print(0, dt, peak())
"""

CHILD_ANALYZE = _PEAK + r"""
import io, contextlib
t = time.perf_counter()
from inertia_tool.cli import main
buf = io.StringIO()
with contextlib.redirect_stdout(buf):
    rc = main(["analyze", sys.argv[1], "--json", "--units", "mm"])
dt = time.perf_counter() - t
print(rc, dt, peak())
"""



def torus_faces_for(target: int) -> tuple[int, int]:
    """(nu, nv) with 2·nu·nv close to ``target`` triangles and nu ≈ 4 nv (a ring, like a part's outline)."""
    nv = max(3, int(round((target / 8) ** 0.5)))
    nu = max(3, int(round(target / (2 * nv))))
    return nu, nv


def write_torus(target: int) -> tuple[str, int]:
    """A closed torus (major radius 40 mm, minor 10 mm) of about ``target`` triangles as binary STL."""
    nu, nv = torus_faces_for(target)
    m = 2 * nu * nv
    path = os.path.join(OUT, f"torus_{m}.stl")
    if os.path.exists(path):
        return path, m
    os.makedirs(OUT, exist_ok=True)
    pts, faces = ring_torus(nu, nv)
    write_binary_stl(path, pts, faces, header=b"inertia_tool benchmark torus")
    return path, m


def run_child(code: str, path: str, repeat: int) -> tuple[float, int, float]:
    """Best wall seconds of the child's work (after the interpreter started), its peak memory, and the least CPU
    seconds of the whole child process (interpreter start-up and imports included: user + system, all threads),
    which the load of a shared machine inflates less than wall time."""
    # as an installed package runs: bytecode cached (a checkout under PYTHONDONTWRITEBYTECODE=1 would compile
    # the package in every child), and one untimed warm-up run writes the cache
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = ROOT
    subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True, env=env)
    best = (float("inf"), 0)
    best_cpu = float("inf")
    for _ in range(repeat):
        c = _children_cpu()
        r = subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True, env=env)
        best_cpu = min(best_cpu, _children_cpu() - c)
        if r.returncode != 0:
            raise RuntimeError(f"child failed on {path}: {r.stderr[-2000:]}")
        rc, dt, rss = r.stdout.split()[-3:]
        if int(rc) != 0:
            raise RuntimeError(f"analyze failed on {path}: {r.stderr[-2000:]}")
        if float(dt) < best[0]:
            best = (float(dt), int(rss))
    return best[0], best[1], best_cpu


def _children_cpu() -> float:
    """CPU seconds (user + system) of the waited-for children of this process so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def time_cat(path: str, repeat: int) -> tuple[float, float]:
    """Best wall and best CPU seconds of ``cat FILE > /dev/null``."""
    best, best_cpu = float("inf"), float("inf")
    for _ in range(repeat):
        t, c = time.perf_counter(), _children_cpu()
        with open(os.devnull, "wb") as null:
            subprocess.run(["cat", path], stdout=null, check=True)
        best = min(best, time.perf_counter() - t)
        best_cpu = min(best_cpu, _children_cpu() - c)
    return best, best_cpu


def plot(rows, out: str, caption: str = "") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    faces = [r["faces"] for r in rows]
    fig, (ax_t, ax_c, ax_m) = plt.subplots(1, 3, figsize=(15, 4.8))
    series = (("inertia-tool analyze", "analyze", "C0", "o-"),
              ("trimesh load + mass_properties", "trimesh", "C3", "s-"),
              ("Python + numpy.fromfile", "fromfile", "C2", "^--"),
              ("cat > /dev/null", "cat", "0.4", "v:"))
    for label, key, colour, style in series:
        pts = [(r["faces"], r[f"{key}_s"]) for r in rows if r.get(f"{key}_s") is not None]
        if pts:
            ax_t.loglog(*zip(*pts), style, color=colour, label=label)
        cpu = [(r["faces"], r[f"{key}_cpu"]) for r in rows if r.get(f"{key}_cpu") is not None]
        if cpu:
            ax_c.loglog(*zip(*cpu), style, color=colour, label=label)
        mem = [(r["faces"], r[f"{key}_mb"]) for r in rows if r.get(f"{key}_mb") is not None]
        if mem:
            ax_m.loglog(*zip(*mem), style, color=colour, label=label)
    ax_m.loglog(faces, [r["file_mb"] for r in rows], "k-", lw=0.8, label="file size")
    ax_t.set(xlabel="triangles", ylabel="wall time, s (best of runs, fresh process)", title="Time")
    ax_c.set(xlabel="triangles", ylabel="CPU time, s (whole process, least of runs)", title="CPU time")
    ax_m.set(xlabel="triangles", ylabel="peak resident memory, MiB", title="Peak memory")
    for ax in (ax_t, ax_c, ax_m):
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Binary STL tori, warm page cache, one run: analyze vs a bare read and trimesh"
                 + (f"\n{caption}" if caption else ""), fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e3, 1e4, 1e5, 1e6, 1e7])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--trimesh-max", type=float, default=1.1e7, help="skip trimesh above this many faces")
    ap.add_argument("--plot", default=os.path.join(ROOT, "docs", "img", "scaling.png"))
    ap.add_argument("--json", help="write the rows here (after every size)")
    ap.add_argument("--from-json", help="print the table and draw the plot from rows written by --json (no runs)")
    args = ap.parse_args()
    if args.from_json:
        with open(args.from_json) as fh:
            saved = json.load(fh)
        report(saved["rows"], saved["load"], saved["caption"], args.plot)
        return
    load_before = os.getloadavg()[0]
    caption = run_caption("bench_scaling.py", sys.argv[1:])
    rows = []
    for target in args.sizes:
        path, m = write_torus(int(target))
        with open(path, "rb") as fh:      # warm the page cache
            while fh.read(1 << 24):
                pass
        row = dict(faces=m, file_mb=os.path.getsize(path) / _MIB)
        row["cat_s"], row["cat_cpu"] = time_cat(path, args.repeat)
        row["fromfile_s"], rss, row["fromfile_cpu"] = run_child(CHILD_READ, path, args.repeat)
        row["fromfile_mb"] = rss / _MIB
        row["analyze_s"], rss, row["analyze_cpu"] = run_child(CHILD_ANALYZE, path, args.repeat)
        row["analyze_mb"] = rss / _MIB
        if m <= args.trimesh_max:
            row["trimesh_s"], rss, row["trimesh_cpu"] = run_child(CHILD_TRIMESH, path, 1 if m > 2e6 else args.repeat)
            row["trimesh_mb"] = rss / _MIB
        rows.append(row)
        print(json.dumps(row), flush=True)
        if args.json:
            with open(args.json, "w") as fh:
                json.dump({"rows": rows, "load": [load_before, os.getloadavg()[0]], "caption": caption}, fh, indent=1)
    report(rows, [load_before, os.getloadavg()[0]], caption, args.plot)


def run_caption(script: str, argv: list[str]) -> str:
    """What produced a figure: the command, the date (UTC), the commit of the checkout timed and the load."""
    try:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown commit"
    day = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    kept, skip = [], False                     # where the output went is not part of what was measured
    for arg in argv:
        if skip:
            skip = False
        elif arg in ("--json", "--plot"):
            skip = True
        elif not arg.startswith(("--json=", "--plot=")):
            kept.append(arg)
    return f"python benchmarks/{script} {' '.join(kept)}".rstrip() + f", {day}, code at {commit}"


def report(rows: list[dict], load: list[float], caption: str, plot_to: str | None) -> None:
    """Print the table (wall and CPU time, memory, ratios) and draw the plot."""
    print()
    print(f"{caption}; CPUs: {os.cpu_count()}, load average {load[0]:.2f} before, {load[1]:.2f} after")
    print("| faces | file MB | cat s | fromfile s | analyze s | trimesh s | analyze / cat | analyze / fromfile "
          "| trimesh / analyze | analyze peak MB | peak / file |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        tm = r.get("trimesh_s")
        tm_s = "—" if tm is None else f"{tm:.2f}"
        tm_ratio = "—" if tm is None else f"{tm / r['analyze_s']:.1f}"
        print(f"| {r['faces']:,} | {r['file_mb']:.1f} | {r['cat_s']:.3f} | {r['fromfile_s']:.3f} | "
              f"{r['analyze_s']:.3f} | {tm_s} | {r['analyze_s'] / r['cat_s']:.1f} | "
              f"{r['analyze_s'] / r['fromfile_s']:.1f} | {tm_ratio} | "
              f"{r['analyze_mb']:.0f} | {r['analyze_mb'] / r['file_mb']:.2f} |")
    print()
    print("CPU time of the whole process (user + system, all threads; least of the runs):")
    print("| faces | cat | numpy read | analyze | trimesh | trimesh / analyze |")
    print("|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        tm = r.get("trimesh_cpu")
        print(f"| {r['faces']:,} | {r['cat_cpu']:.3f} s | {r['fromfile_cpu']:.3f} s | {r['analyze_cpu']:.3f} s | "
              + ("— | — |" if tm is None else f"{tm:.2f} s | {tm / r['analyze_cpu']:.1f} |"))
    if plot_to:
        plot(rows, plot_to, f"{caption}; load average {load[0]:.1f} before, {load[1]:.1f} after, "
                            f"{os.cpu_count()} CPUs")
        print(f"wrote {plot_to}")


if __name__ == "__main__":
    main()
