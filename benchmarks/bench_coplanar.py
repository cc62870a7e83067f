"""CPU time of the coplanar overlay (``mesh/coplanar.py``): welded bodies sharing a plane.

Two measurements, CPU seconds (``time.process_time``: the machine is shared, so wall time says little)::

    python benchmarks/bench_coplanar.py                 # 40 welded_l_shapes cases, then grid pairs of growing size
    python benchmarks/bench_coplanar.py --cases 100 --seed 22

1. ``mass_properties`` on the adversarial kind ``welded_l_shapes`` (median and total per case);
2. ``arrange_coplanar`` alone on two welded grid bodies crossing on one plane, turned by a random rotation and
   moved 300 m (the faces coplanar only to rounding: every patch label settles faces exactly), for growing sizes.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another
import adversary_solids as S  # noqa: E402


def welded_kind(cases: int, seed: int) -> None:
    from inertia_tool import mass_properties
    from inertia_tool.errors import InvalidMeshError
    first = S.KINDS.index("welded_l_shapes")
    drawn = [S.make_case("welded_l_shapes", np.random.default_rng([seed, i]))
             for i in range(first, first + len(S.KINDS) * cases, len(S.KINDS))]
    cpu, labels = [], {}
    for case in drawn:
        t = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                label = mass_properties((case.vertices, case.faces), density=1.0).mesh.certificate.kind
            except InvalidMeshError:
                label = "refused"
        cpu.append(time.process_time() - t)
        labels[label] = labels.get(label, 0) + 1
    faces = [len(c.faces) for c in drawn]
    print(f"welded_l_shapes, seed {seed}, {cases} cases ({min(faces)}-{max(faces)} faces): {labels}; CPU per case "
          f"median {np.median(cpu) * 1e3:.1f} ms, total {sum(cpu):.2f} s")


def grid_pairs() -> None:
    from inertia_tool.mesh.coplanar import arrange_coplanar
    for length in (12, 24, 48):
        rng = np.random.default_rng(5)
        a = {(i, j, k) for i in range(length) for j in range(4) for k in range(3)}
        b = {(i, j, k) for i in range(6, 10) for j in range(-4, length) for k in range(2)}
        v, f = S._weld_exact(*S.concat(S.cell_body(a, 0.5, rng), S.cell_body(b, 0.5, rng)))
        v = v @ S.random_rotation(rng).T + rng.normal(size=3) * 300
        t = time.process_time()
        done = arrange_coplanar(v, f)
        print(f"two welded grid bodies, {len(f):,} faces: arrange_coplanar {time.process_time() - t:.3f} s CPU "
              f"({done.patches} patches, {done.planes} planes, {done.split_faces} faces split)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--seed", type=int, default=26)
    args = ap.parse_args(argv)
    welded_kind(args.cases, args.seed)
    grid_pairs()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
