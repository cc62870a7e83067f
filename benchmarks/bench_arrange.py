"""Cost of the mesh arrangement (``mesh/arrange.py``) of a shell that passes through itself.

For each size, the figure-eight tube of ``tests/adversary_solids.py`` (lifted lemniscate, lift 0.1, radius
0.2: thinner than its bends, so only the two branches cross) is built with about that many faces; then,
``--repeat`` times each in this process:

* ``mass_properties((vertices, faces))``: the whole analysis (edge census, face-pair check, the arrangement of
  {winding number ≥ 1}, its checks, the integrals), certified ``united``;
* ``arrange_crossings(vertices, faces, crossing)`` alone (given the crossing pairs), and the face-pair check
  ``surface_contacts`` alone, for the split.

It prints faces, crossing pairs, the medians of CPU time (all threads of this process; the steadier figure on
a shared machine) and wall time, and the arrangement's share of the analysis.

    python benchmarks/bench_arrange.py [--sizes 1e4 1e5] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another


def figure_eight(n_faces: float) -> tuple[np.ndarray, np.ndarray]:
    """The lifted figure-eight tube with about ``n_faces`` triangles (rings ≈ 8 × sections)."""
    import adversary_solids as S
    sections = max(6, int(round(np.sqrt(n_faces / 16))))
    rings = max(24, int(round(n_faces / (2 * sections))))
    v, f, _ = S.tube_slabs(0.1, 0.2, rings=rings, sections=sections)
    return v, f


def _timed(fn) -> tuple[float, float, object]:
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return time.process_time() - c0, time.perf_counter() - w0, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    from inertia_tool import mass_properties
    from inertia_tool.mesh.arrange import arrange_crossings
    from inertia_tool.mesh.intersect import surface_contacts
    print(f"{'faces':>8} {'pairs':>6} {'analysis cpu/wall s':>20} {'arrange cpu/wall s':>19} "
          f"{'check cpu s':>11} {'arrange/analysis':>16}  certificate")
    for size in args.sizes:
        v, f = figure_eight(size)
        rows = []
        for _ in range(args.repeat):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                a_cpu, a_wall, props = _timed(lambda: mass_properties((v, f)))
            c_cpu, _, contacts = _timed(lambda: surface_contacts(v, f))
            r_cpu, r_wall, arranged = _timed(lambda: arrange_crossings(v, f, contacts.crossing))
            rows.append((a_cpu, a_wall, r_cpu, r_wall, c_cpu))
        med = [statistics.median(c) for c in zip(*rows)]
        print(f"{len(f):>8,} {arranged.crossing_pairs:>6,} {med[0]:>9.2f} / {med[1]:>7.2f} {med[2]:>8.2f} / "
              f"{med[3]:>7.2f} {med[4]:>11.2f} {med[2] / med[0]:>16.2f}  {props.mesh.certificate.describe()}")


if __name__ == "__main__":
    main()
