"""Cost of the exact face-pair check (``mesh/intersect.py``) against today's whole analysis.

For each size a closed torus grid (``n × n/2`` quads, two triangles each; a clean surface whose quads are
exactly planar isosceles trapezoids, so each quad's diagonal joins two coplanar faces, as the flat regions of
CAD meshes do) is built in memory; then, ``--repeat`` times each in this process:

* ``surface_contacts(vertices, faces)``: every pair of faces whose boxes meet, classified exactly;
* ``inertia_tool.mass_properties((vertices, faces))``: the whole analysis of the same arrays (weld, topology,
  shells, this check, integrals, principal axes), as a user calls it; the time it spends inside
  ``surface_contacts`` is measured too, and "rest" is the analysis without it.

It prints faces, the medians of both times side by side (CPU of all threads of this process, and wall clock: on
a shared machine the CPU time is the steadier one, the wall time shows what other processes took), the ratios
check / analysis of each (the issue's target is a CPU ratio of at most 1 at 1e6 faces), ns of CPU per face of
the check, the candidate pairs per face and the predicate evaluations the float filter left to exact
arithmetic.  ``INERTIA_TOOL_NO_ACCEL=1`` runs both on their numpy paths; ``INERTIA_TOOL_THREADS`` sets the
C kernels' threads.

``--shape cylinder`` builds instead a closed cylinder of about ``size`` triangles (``size/4`` sections) with
fan-triangulated caps around a centre vertex, as CAD exports them: every cap face shares the centre, so the
unpruned scan has about ``size²/16`` candidate pairs; ``--unpruned`` runs the check without the certified-star
pruning (``_star_faces=0``, module docstring of ``mesh/intersect.py``, "Stars"), the scan as it was before.

    python benchmarks/bench_intersect.py [--sizes 1e4 1e5 1e6] [--repeat 5] [--shape cylinder] [--unpruned]
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

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


def cylinder(n_faces: float, radius: float = 1.0, height: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder of about ``n_faces`` triangles (``n_faces/4`` sections), fan caps round a centre."""
    n = max(8, int(round(n_faces / 4)))
    t = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    v = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    i = np.arange(n)
    j = (i + 1) % n
    bottom, top = np.full(n, 2 * n), np.full(n, 2 * n + 1)
    f = np.concatenate([np.stack([bottom, j, i], 1), np.stack([top, n + i, n + j], 1),
                        np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
    return v, f


def medians(fn, repeat: int) -> tuple[float, float, object]:
    """Median CPU time (all threads of this process) and median wall-clock time of ``repeat`` calls, and the
    result."""
    out, walls, cpus = None, [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
    return statistics.median(cpus), statistics.median(walls), out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e4, 1e5, 1e6])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--shape", choices=["torus", "cylinder"], default="torus")
    parser.add_argument("--unpruned", action="store_true", help="no certified-star pruning (the scan before it)")
    args = parser.parse_args(argv)
    import functools

    import inertia_tool
    from inertia_tool.mesh import prepare
    from inertia_tool.mesh.intersect import surface_contacts

    if args.unpruned:
        surface_contacts = functools.partial(surface_contacts, _star_faces=0)

    inside = [0.0, 0.0]                                  # CPU and wall time spent in the check by the analysis

    def timed(*args, **kwargs):
        t, c = time.perf_counter(), time.process_time()
        try:
            return surface_contacts(*args, **kwargs)
        finally:
            inside[0] += time.process_time() - c
            inside[1] += time.perf_counter() - t

    def analysis():
        inside[0] = inside[1] = 0.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")              # two equal principal moments
            inertia_tool.mass_properties((v, f))
        return tuple(inside)

    prepare.surface_contacts = timed                     # type: ignore[attr-defined]
    print(f"{'faces':>10} | {'check cpu':>9} {'wall':>6} | {'analysis cpu':>12} {'wall':>6} | {'rest cpu':>8} "
          f"{'wall':>6} | {'ratio cpu':>9} {'wall':>5} | {'ns/face':>7} {'pairs/face':>10} {'exact':>6} found")
    for size in args.sizes:
        v, f = (torus if args.shape == "torus" else cylinder)(size)
        c_check, t_check, res = medians(lambda: surface_contacts(v, f), args.repeat)
        cpus, walls, rest_c, rest_t = [], [], [], []
        for _ in range(args.repeat):
            t, c = time.perf_counter(), time.process_time()
            in_c, in_t = analysis()
            cpus.append(time.process_time() - c)
            walls.append(time.perf_counter() - t)
            rest_c.append(cpus[-1] - in_c)
            rest_t.append(walls[-1] - in_t)
        c_mass, t_mass = statistics.median(cpus), statistics.median(walls)
        c_rest, t_rest = statistics.median(rest_c), statistics.median(rest_t)
        found = len(res.crossing) + len(res.coplanar_opposite) + len(res.contact)
        print(f"{len(f):>10,} | {c_check:>9.3f} {t_check:>6.3f} | {c_mass:>12.3f} {t_mass:>6.3f} | "
              f"{c_rest:>8.3f} {t_rest:>6.3f} | {c_check / max(c_rest, 1e-9):>9.1f} "
              f"{t_check / max(t_rest, 1e-9):>5.1f} | "
              f"{c_check / len(f) * 1e9:>7.0f} {res.candidate_pairs / len(f):>10.1f} {res.exact_evaluations:>6} "
              f"{found}")

if __name__ == "__main__":
    main()
