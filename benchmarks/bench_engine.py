"""Engine benchmark: `inertia-tool analyze` vs trimesh on large binary STL icospheres, side by side in one run.

Writes binary STL icospheres of 1.3M and 5.2M faces into benchmarks/out/ (not committed), then for each runs,
in fresh subprocesses (imports included, as a user would see it):

* ``inertia-tool analyze FILE --json`` (full watertight validation, shells, cavities, integration), and
* ``trimesh.load(FILE)`` + ``mesh.mass_properties`` (trimesh's own loader and integrator),

and reports wall time and peak resident memory of each (VmHWM of the child's own address space: ru_maxrss
would also count the benchmark process's memory at the fork, which exec inherits on Linux), the ratio, and the
file size.  Also times
the integration kernels alone on the same indexed mesh (in-process, best of 3).

    python benchmarks/bench_engine.py [--sizes 8 9] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time


sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from _shapes import write_binary_stl  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out")

# every child reports its own peak resident memory (VmHWM; ru_maxrss would include the parent's at the fork)
_PEAK = r"""
import resource, sys, time
def peak():
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
"""

CHILD_OURS = _PEAK + r"""
import io, contextlib
t = time.perf_counter()
from inertia_tool.cli import main
buf = io.StringIO()
with contextlib.redirect_stdout(buf):
    rc = main(["analyze", sys.argv[1], "--json"])
dt = time.perf_counter() - t
print(rc, dt, peak())
"""

CHILD_TRIMESH = _PEAK + r"""
t = time.perf_counter()
import trimesh
m = trimesh.load(sys.argv[1])
mp = m.mass_properties
_ = (mp["volume"], mp["center_mass"], mp["inertia"])
dt = time.perf_counter() - t
print(0, dt, peak())
"""


def write_icosphere(subdivisions: int) -> str:
    import trimesh
    path = os.path.join(OUT, f"icosphere_{subdivisions}.stl")
    if os.path.exists(path):
        return path
    os.makedirs(OUT, exist_ok=True)
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=50.0)
    write_binary_stl(path, m.vertices, m.faces, header=b"inertia_tool benchmark icosphere")
    return path


def run_child(code: str, path: str):
    env = {**os.environ, "PYTHONPATH": ROOT}
    r = subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True, env=env, check=True)
    rc, dt, rss = r.stdout.split()[-3:]
    if int(rc) != 0:
        raise RuntimeError(f"analyze failed on {path}: {r.stderr}")
    return float(dt), int(rss)


def kernel_times(path: str, repeat: int):
    import trimesh
    from inertia_tool.mesh.read import load_mesh
    from inertia_tool.integrals import volume_moments
    raw = load_mesh(path)
    best_ours = min(_timed(lambda: volume_moments(raw.vertices, raw.faces)) for _ in range(repeat))
    tm = trimesh.Trimesh(raw.vertices, raw.faces, process=False)

    def trimesh_integral():
        tm._cache.clear()
        return tm.mass_properties["inertia"]
    best_tm = min(_timed(trimesh_integral) for _ in range(repeat))
    return best_ours, best_tm


def _timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 9],
                    help="icosphere subdivisions (8: 1.3M, 9: 5.2M faces)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    rows = []
    for s in args.sizes:
        path = write_icosphere(s)
        size = os.path.getsize(path)
        faces = (size - 84) // 50
        ours = min((run_child(CHILD_OURS, path) for _ in range(args.repeat)), key=lambda x: x[0])
        theirs = min((run_child(CHILD_TRIMESH, path) for _ in range(args.repeat)), key=lambda x: x[0])
        k_ours, k_tm = kernel_times(path, args.repeat)
        rows.append(dict(faces=faces, file_mb=size / 2**20, ours_s=ours[0], trimesh_s=theirs[0],
                         speedup=theirs[0] / ours[0], ours_peak_mb=ours[1] / 2**20, trimesh_peak_mb=theirs[1] / 2**20,
                         peak_over_file=ours[1] / size, kernel_ours_s=k_ours, kernel_trimesh_s=k_tm,
                         kernel_speedup=k_tm / k_ours))
    print(f"{'faces':>10} {'file MB':>8} {'ours s':>8} {'trimesh s':>9} {'ratio':>6} {'ours MB':>8} "
          f"{'trim MB':>8} {'peak/file':>9} {'kern ours':>9} {'kern trim':>9} {'k ratio':>7}")
    for r in rows:
        print(f"{r['faces']:>10,} {r['file_mb']:8.1f} {r['ours_s']:8.2f} {r['trimesh_s']:9.2f} {r['speedup']:6.1f} "
              f"{r['ours_peak_mb']:8.0f} {r['trimesh_peak_mb']:8.0f} {r['peak_over_file']:9.2f} "
              f"{r['kernel_ours_s']:9.3f} {r['kernel_trimesh_s']:9.3f} {r['kernel_speedup']:7.2f}")
    print(json.dumps(rows))


if __name__ == "__main__":
    main()
