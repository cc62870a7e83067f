"""The face-pair check's certified patches on real files: the same pairs with and without them.

For every mesh file under the folders given (STL, OBJ, PLY, OFF; read by ``load_mesh``, so welded as the analysis
welds), :func:`~inertia_tool.mesh.intersect.surface_contacts` runs on the C scan as the analysis runs it (patches
on), without patches (``_patches=False``) and, for meshes of at most ``--numpy-faces`` faces, on the numpy twin
(``INERTIA_TOOL_NO_ACCEL=1``); the three pair lists (``crossing``, ``coplanar_opposite``, ``contact``) must be
identical.  Prints one line per difference or error, then the totals: files, meshes compared, meshes with pairs
found, differences, candidate pairs and CPU seconds of the check with and without patches.

    python benchmarks/bench_patches_agree.py FOLDER [FOLDER ...] [--numpy-faces 5000]
"""

from __future__ import annotations

import argparse
import glob
import os
import sys
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _checkouts import this_checkout_first  # noqa: E402  (benchmarks/ is not a package)

this_checkout_first()                  # this checkout's inertia_tool, unless PYTHONPATH names another

import numpy as np  # noqa: E402

from inertia_tool import _native  # noqa: E402
from inertia_tool.mesh.intersect import SurfaceContacts, surface_contacts  # noqa: E402
from inertia_tool.mesh.read import load_mesh  # noqa: E402

FIELDS = ("crossing", "coplanar_opposite", "contact")
SUFFIXES = (".stl", ".obj", ".ply", ".off")


def _same(a: SurfaceContacts, b: SurfaceContacts) -> bool:
    return a.complete and b.complete and all(np.array_equal(getattr(a, k), getattr(b, k)) for k in FIELDS)


def _numpy_twin(v: np.ndarray, f: np.ndarray) -> SurfaceContacts:
    before = os.environ.get(_native.NO_ACCEL_ENV)
    os.environ[_native.NO_ACCEL_ENV] = "1"
    try:
        return surface_contacts(v, f)
    finally:
        if before is None:
            del os.environ[_native.NO_ACCEL_ENV]
        else:
            os.environ[_native.NO_ACCEL_ENV] = before


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", help="folders searched recursively for mesh files")
    parser.add_argument("--numpy-faces", type=int, default=5000,
                        help="also compare the numpy twin on meshes of at most this many faces")
    parser.add_argument("--each", action="store_true", help="also print one line per mesh compared")
    args = parser.parse_args(argv)
    files = sorted({p for d in args.folders for p in glob.glob(os.path.join(d, "**", "*"), recursive=True)
                    if p.lower().endswith(SUFFIXES) and os.path.isfile(p)})
    compared = unread = found = differ = twin = 0
    cand = [0, 0]
    cpu = [0.0, 0.0]
    for path in files:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mesh = load_mesh(path)
            v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        except Exception:                      # noqa: BLE001  (files the reader refuses are not this check's)
            unread += 1
            continue
        if len(f) == 0:
            unread += 1
            continue
        try:
            t0 = time.process_time()
            patched = surface_contacts(v, f)
            t1 = time.process_time()
            plain = surface_contacts(v, f, _patches=False)
            t2 = time.process_time()
            same = _same(patched, plain)
            if same and len(f) <= args.numpy_faces:
                same = _same(patched, _numpy_twin(v, f))
                twin += 1
        except Exception as exc:               # noqa: BLE001  (reported, counted as a difference)
            print(f"error {path} ({len(f):,} faces): {type(exc).__name__}: {exc}", flush=True)
            differ += 1
            continue
        compared += 1
        cand[0] += patched.candidate_pairs
        cand[1] += plain.candidate_pairs
        cpu[0] += t1 - t0
        cpu[1] += t2 - t1
        found += sum(len(getattr(patched, k)) for k in FIELDS) > 0
        if not same:
            differ += 1
            print(f"differ {path} ({len(f):,} faces)", flush=True)
        elif args.each:
            print(f"same {path} ({len(f):,} faces, candidate pairs {patched.candidate_pairs:,} / "
                  f"{plain.candidate_pairs:,})", flush=True)
    print(f"{len(files):,} files, {compared:,} meshes compared ({twin:,} also with the numpy twin), {unread:,} not "
          f"read; pairs found in {found:,}; differences {differ:,}")
    print(f"candidate pairs with patches {cand[0]:,}, without {cand[1]:,}; check CPU with patches {cpu[0]:.2f} s, "
          f"without {cpu[1]:.2f} s")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
