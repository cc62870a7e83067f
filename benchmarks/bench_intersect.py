"""Cost of the exact face-pair check (``mesh/intersect.py``) against today's whole analysis.

For each size a closed torus grid (``n × n/2`` quads, two triangles each; every quad planar-free, a clean
surface) is built in memory; then, best of ``--repeat`` in this process:

* ``surface_contacts(vertices, faces)``: every pair of faces whose boxes meet, classified exactly;
* ``inertia_tool.mass_properties((vertices, faces))``: the whole analysis of the same arrays (weld, topology,
  shells, integrals, principal axes), as a user calls it.

It prints faces, both times (wall clock and CPU of all threads: on a shared machine the CPU time is the steadier
one), ns per face of the check, and the ratios check / analysis (the issue's target is a ratio of at most 1 at
1e6 faces), plus the candidate pairs per face and the predicate evaluations the float filter left to exact
arithmetic.  ``INERTIA_TOOL_NO_ACCEL=1`` runs both on their numpy paths.

    python benchmarks/bench_intersect.py [--sizes 1e4 1e5 1e6] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def torus(n_faces: float, major: float = 1.0, minor: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """A closed torus grid of about ``n_faces`` triangles (n around the axis, n/2 around the tube)."""
    n = max(8, int(round(np.sqrt(n_faces))))
    k = max(4, n // 2)
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(k) / k + 0.1234      # off the coordinate planes: no accidental symmetry
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = major + minor * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), minor * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    a = i * k + j
    b = ((i + 1) % n) * k + j
    c = ((i + 1) % n) * k + (j + 1) % k
    d = i * k + (j + 1) % k
    f = np.r_[np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    return v, f


def best(fn, repeat: int) -> tuple[float, float, object]:
    """Best wall-clock and best CPU time (all threads of this process) of ``repeat`` calls, and the result."""
    out, t_best, c_best = None, float("inf"), float("inf")
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        t_best = min(t_best, time.perf_counter() - t)
        c_best = min(c_best, time.process_time() - c)
    return t_best, c_best, out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e4, 1e5, 1e6])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    import inertia_tool
    from inertia_tool.mesh.intersect import surface_contacts

    print(f"{'faces':>10} {'check s':>8} {'cpu':>6} {'analysis s':>10} {'cpu':>6} {'ns/face':>8} {'ratio':>6} "
          f"{'cpu ratio':>9} {'pairs/face':>10} {'exact':>7} found")
    for size in args.sizes:
        v, f = torus(size)
        t_check, c_check, res = best(lambda: surface_contacts(v, f), args.repeat)
        t_mass, c_mass, _ = best(lambda: inertia_tool.mass_properties((v, f)), args.repeat)
        found = len(res.crossing) + len(res.coplanar_opposite) + len(res.contact)
        print(f"{len(f):>10,} {t_check:>8.3f} {c_check:>6.2f} {t_mass:>10.3f} {c_mass:>6.2f} "
              f"{t_check / len(f) * 1e9:>8.0f} {t_check / t_mass:>6.1f} {c_check / max(c_mass, 1e-9):>9.1f} "
              f"{res.candidate_pairs / len(f):>10.1f} {res.exact_evaluations:>7} {found}")


if __name__ == "__main__":
    main()
