"""Two builds of the C face-pair kernel (``contact_scan``) on the small catalogue, in one process, alternating.

A change to ``_accel.c``'s scan must find the same pairs with the same counts; its speed on small parts is below
what a whole batch run shows on a shared machine.  This script loads two built extensions side by side (each
under its own module object, neither registered in ``sys.modules``), writes the ``small`` catalogue of
``bench_batch.py`` (boxes, icospheres, fan-capped cylinders, tori), checks that every output of ``contact_scan``
(pairs, kinds, candidates, tested, exact, complete, axes, degenerate flags) is the same from both builds on every
part, with the patches on and off, then times the scan of each kind with each build in alternating order (the
least of 3 passes per round, CPU time) and prints the medians of the rounds and their ratio.

    python benchmarks/bench_scan_builds.py OLD.so NEW.so [--small 400] [--rounds 6] [--kinds box,cylinder]

Build the old one from a copy of the tree (``bash /work/notes/build_accel.sh DIR`` or ``pip install -e DIR``) and
pass its ``inertia_tool/_accel*.so``.  Run from the repository root.
"""

from __future__ import annotations

import argparse
import glob
import importlib.machinery
import importlib.util
import os
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(1, os.path.dirname(HERE))

from bench_batch import SMALL_KINDS, make_small_meshes  # noqa: E402
from inertia_tool.mesh.intersect import STAR_MIN_FACES  # noqa: E402
from inertia_tool.mesh.read import load_mesh  # noqa: E402


def _load(path: str):
    """The extension module built at ``path``, loaded under its own module object."""
    loader = importlib.machinery.ExtensionFileLoader("inertia_tool._accel", path)
    spec = importlib.util.spec_from_file_location("inertia_tool._accel", path, loader=loader)
    if spec is None:
        raise SystemExit(f"{path}: not an extension module")
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def _pass(module, raws, passes: int = 3) -> float:
    """CPU µs per part of scanning ``raws`` with ``module`` (patches on, as the analysis calls it), least of
    ``passes``."""
    best = float("inf")
    for _ in range(passes):
        start = time.process_time()
        for raw in raws:
            module.contact_scan(raw.vertices, raw.faces, -1, 1, STAR_MIN_FACES, True)
        best = min(best, time.process_time() - start)
    return best / len(raws) * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old", help="the built extension before the change")
    ap.add_argument("new", help="the built extension after it")
    ap.add_argument("--small", type=int, default=400, help="parts of the small catalogue")
    ap.add_argument("--rounds", type=int, default=6, help="alternating rounds per kind (medians are printed)")
    ap.add_argument("--kinds", default=",".join(SMALL_KINDS), help="kinds to time, comma-separated")
    args = ap.parse_args()
    old, new = _load(os.path.abspath(args.old)), _load(os.path.abspath(args.new))
    with tempfile.TemporaryDirectory() as tmp:
        make_small_meshes(tmp, args.small)
        files = sorted(glob.glob(os.path.join(tmp, "*.stl")))
        raws = [load_mesh(p, units="mm") for p in files]
    for raw in raws:
        for patches in (True, False):
            a = old.contact_scan(raw.vertices, raw.faces, -1, 1, STAR_MIN_FACES, patches)
            b = new.contact_scan(raw.vertices, raw.faces, -1, 1, STAR_MIN_FACES, patches)
            if a != b:
                raise SystemExit(f"{raw.source}: the builds' outputs differ (patches {patches})")
    print(f"identical outputs on {len(raws)} parts, patches on and off; load average {os.getloadavg()[0]:.1f}")
    for kind in args.kinds.split(","):
        k = SMALL_KINDS.index(kind)
        chosen = raws[k::len(SMALL_KINDS)]
        times: dict[str, list[float]] = {"old": [], "new": []}
        for r in range(args.rounds):
            order = (("old", old), ("new", new)) if r % 2 == 0 else (("new", new), ("old", old))
            for name, module in order:
                times[name].append(_pass(module, chosen))
        before, after = statistics.median(times["old"]), statistics.median(times["new"])
        print(f"{kind:10s} {len(chosen):4d} parts  old {before:8.0f} µs  new {after:8.0f} µs  "
              f"new/old {after / before:.3f}")
    print(f"load average after {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
