"""The winding-number treecode in C (``_accel.c`` section 13) against its numpy reference, on a mesh file.

Points of three kinds on the mesh's surface (uniform in its box, pushed 1e-9…1e-3 of its size off a face along the
normal, on a face): CPU seconds of ``winding._treecode`` (the C kernel, one thread) and of
``winding._treecode_numpy``, alternating, at each tolerance, and whether values and bounds are equal bit for bit.

    python benchmarks/bench_winding_tree.py MESH [--points 300] [--repeat 2] [--tolerance 1e-4 1e-3]

Measured 2026-11-27 (corpus13) on Menagerie's agilex_piper ``link2.stl`` (71,916 faces), 650 points, load 11:
4.1 → 0.72 s at 1e-4, 2.0 → 0.42 s at 1e-3, every value and bound bit-identical.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from inertia_tool.mesh import winding  # noqa: E402


def _points(v: np.ndarray, f: np.ndarray, count: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = v.min(axis=0), v.max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    box = rng.uniform(lo, hi, size=(count, 3))
    pick = rng.integers(0, len(f), count)
    on = np.einsum("pk,pki->pi", rng.dirichlet([1.0, 1.0, 1.0], count), v[f[pick]])
    normal = np.cross(v[f[pick, 1]] - v[f[pick, 0]], v[f[pick, 2]] - v[f[pick, 0]])
    unit = normal / np.maximum(np.linalg.norm(normal, axis=1), np.finfo(float).tiny)[:, None]
    near = on + unit * (size * 10.0 ** rng.uniform(-9, -3, count) * rng.choice([-1.0, 1.0], count))[:, None]
    return np.vstack([box, near, on[: count // 6]])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh")
    parser.add_argument("--points", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--tolerance", type=float, nargs="+", default=[1e-4, 1e-3])
    args = parser.parse_args(argv)
    os.environ["INERTIA_TOOL_THREADS"] = "1"
    import trimesh
    mesh = trimesh.load(args.mesh, force="mesh", process=False)
    v, f = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    points = _points(v, f, args.points)
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    tree = winding._Tree(v - centre, f, winding.INTEGER_LEAF)
    print(f"{args.mesh}: {len(f):,} faces, {len(points)} points, load {os.getloadavg()[0]:.1f}")
    for tolerance in args.tolerance:
        for _ in range(args.repeat):
            t = time.process_time()
            w_c, e_c = winding._treecode(points - centre, v - centre, f, tolerance=tolerance,
                                         leaf=winding.INTEGER_LEAF, tree=tree)
            c_time = time.process_time() - t
            t = time.process_time()
            w_n, e_n = winding._treecode_numpy(points - centre, tree, tolerance=tolerance)
            n_time = time.process_time() - t
            same = np.array_equal(w_c.view(np.int64), w_n.view(np.int64)) and np.array_equal(
                e_c.view(np.int64), e_n.view(np.int64))
            print(f"tolerance {tolerance:g}: C {c_time:.3f} s, numpy {n_time:.3f} s CPU "
                  f"({n_time / max(c_time, 1e-9):.1f}x); bit-identical: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
