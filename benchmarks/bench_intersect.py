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

``--shape wheel`` analyses instead a real-ish CAD part, ``meshes/unbalanced_wheel.stl`` midpoint-subdivided to
at least ``size`` faces (4,332 · 4^k: 1.1M for 1e6; flat faces, fan caps, slivers).  ``--shape cylinder`` builds
instead a closed cylinder of about ``size`` triangles (``size/4`` sections) with
fan-triangulated caps around a centre vertex, as CAD exports them: every cap face shares the centre, so the
unpruned scan has about ``size²/16`` candidate pairs; ``--unpruned`` runs the check without the certified-star
pruning (``_star_faces=0``, module docstring of ``mesh/intersect.py``, "Stars"), the scan as it was before;
``--unpatched`` runs the C scan without its certified patches (``_patches=False``, "Patches"), as it was before
them (the same pairs found; the counts of the numpy twin).

The builders are in ``benchmarks/_shapes.py``.  ``INERTIA_TOOL_CT_PROFILE=1`` makes the C scan print the CPU
time of its stages (Morton codes, sort, preparation, stars, hierarchy, traversal) to stderr.

    python benchmarks/bench_intersect.py [--sizes 1e4 1e5 1e6] [--repeat 5] [--shape cylinder|wheel] [--unpruned]
        [--unpatched]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another

from _shapes import SHAPES  # noqa: E402  (benchmarks/ is not a package)


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
    parser.add_argument("--shape", choices=sorted(SHAPES), default="torus")
    parser.add_argument("--unpruned", action="store_true", help="no certified-star pruning (the scan before it)")
    parser.add_argument("--unpatched", action="store_true", help="no certified patches (the C scan before them)")
    args = parser.parse_args(argv)
    import functools

    import inertia_tool
    from inertia_tool.mesh.intersect import surface_contacts

    if args.unpruned:
        surface_contacts = functools.partial(surface_contacts, _star_faces=0)
    if args.unpatched:
        surface_contacts = functools.partial(surface_contacts, _patches=False)

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

    # every module of the package that took the check by name (the stage modules of mesh/prepare.py and those
    # importing it inside a function, through mesh/intersect.py itself) calls the timed one
    import inertia_tool.mass.pipeline  # noqa: F401  (loads the stages the analysis runs)
    from inertia_tool.mesh import intersect
    original = intersect.surface_contacts
    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("inertia_tool.") \
                and getattr(module, "surface_contacts", None) is original:
            module.surface_contacts = timed              # type: ignore[attr-defined]
    print(f"{'faces':>10} | {'check cpu':>9} {'wall':>6} | {'analysis cpu':>12} {'wall':>6} | {'rest cpu':>8} "
          f"{'wall':>6} | {'ratio cpu':>9} {'wall':>5} | {'ns/face':>7} {'pairs/face':>10} {'exact':>6} found")
    for size in args.sizes:
        v, f = SHAPES[args.shape](size)
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
