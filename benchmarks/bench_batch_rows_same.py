"""Every batch row field the same on this checkout and on another (e.g. ``main``): the check that a change to the
batch's per-file path changed its speed only.

Writes the ``small`` catalogue of ``bench_batch.py`` (binary STL), the repository's ``meshes/*.stl`` and, from one or
more folders written by ``benchmarks/damage/make_cases.py`` (``--damage DIR``, repeatable), every damaged case as an
OBJ file (coordinates printed with 17 significant digits: the float64 values exactly) and every fourth also as a
binary STL (float32, the STL path's own welding), plus a few bad files (empty, truncated, not a mesh, a directory
named like a mesh, a FIFO).  Then each checkout, in a fresh child process, runs the batch's per-file work
(``analyze_chunk``) over all of them, once with the default options and once with ``repair=True``, and this script
compares the rows field by field; ``seconds`` and ``worker`` (the time taken and the process) are left out.

    python benchmarks/bench_batch_rows_same.py --baseline DIR [--small 2000] [--damage DIR ...]

Exit status 0 when every row is identical, 1 otherwise (the first differences are printed).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: Row fields that may differ between two runs of the same code.
VOLATILE = ("seconds", "worker")


def _child(tree: str, listing: str, out: str) -> None:
    """In a child process: import ``inertia_tool`` from ``tree``, analyse the files of ``listing`` with both
    option sets, and write the rows as JSON lines to ``out``."""
    sys.path.insert(0, tree)
    import warnings

    from inertia_tool.batch.runner import BatchOptions, analyze_chunk
    from inertia_tool.mesh import LoadOptions

    sys.path.insert(0, HERE)
    from bench_batch import _require_c_kernels

    _require_c_kernels()
    warnings.simplefilter("ignore")
    with open(listing) as fh:
        files = [line.rstrip("\n") for line in fh if line.strip()]
    with open(out, "w") as fh:
        for label, options in (("default", BatchOptions(load=LoadOptions(units="mm"), density=1240.0)),
                               ("repair", BatchOptions(load=LoadOptions(units="mm", repair=True), material="steel"))):
            for row in analyze_chunk([(path, None) for path in files], options):
                fh.write(json.dumps({"options": label, **row}, sort_keys=True) + "\n")


def _write_obj(path: str, vertices, faces) -> None:
    with open(path, "w") as fh:
        fh.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices.tolist())
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces.tolist())


def _files(tmp: str, small: int, damage: list[str]) -> tuple[list[str], dict[str, int]]:
    import glob

    import numpy as np

    sys.path.insert(0, HERE)
    from bench_batch import _write_stl, make_small_meshes

    class _Mesh:                                  # what _write_stl reads
        def __init__(self, vertices, faces):
            self.vertices, self.faces = vertices, faces

    counts: dict[str, int] = {}
    files: list[str] = []
    if small:
        folder = os.path.join(tmp, "small")
        os.mkdir(folder)
        make_small_meshes(folder, small)
        found = sorted(glob.glob(os.path.join(folder, "*.stl")))
        files += found
        counts["small catalogue (binary STL)"] = len(found)
    found = sorted(glob.glob(os.path.join(ROOT, "meshes", "*.stl")))
    files += found
    counts["meshes/*.stl"] = len(found)
    folder = os.path.join(tmp, "damage")
    os.mkdir(folder)
    n_obj = n_stl = 0
    for d, source in enumerate(damage):
        for k, case in enumerate(sorted(glob.glob(os.path.join(source, "cases", "*.npz")))):
            with np.load(case) as z:
                v, f = z["vertices"], z["faces"]
            stem = os.path.join(folder, f"{d}-{os.path.basename(case)[:-4]}")
            _write_obj(stem + ".obj", v, f)
            files.append(stem + ".obj")
            n_obj += 1
            if k % 4 == 0:
                _write_stl(stem + ".stl", _Mesh(v, f))
                files.append(stem + ".stl")
                n_stl += 1
    counts["damaged cases (OBJ, float64 exact)"] = n_obj
    counts["damaged cases (binary STL)"] = n_stl
    bad = os.path.join(tmp, "bad")
    os.mkdir(bad)
    with open(os.path.join(bad, "empty.stl"), "wb"):
        pass
    if files:
        with open(files[0], "rb") as fh:
            head = fh.read(300)
        with open(os.path.join(bad, "truncated.stl"), "wb") as fh:
            fh.write(head)
    with open(os.path.join(bad, "text.obj"), "w") as fh:
        fh.write("this is not a mesh\n")
    os.mkdir(os.path.join(bad, "folder.stl"))
    names = ["empty.stl", "truncated.stl", "text.obj", "folder.stl", "missing.stl"]
    if hasattr(os, "mkfifo"):
        os.mkfifo(os.path.join(bad, "pipe.stl"))
        names.append("pipe.stl")
    files += [os.path.join(bad, n) for n in names]
    counts["bad files"] = len(names)
    return files, counts


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", metavar="DIR", help="the other checkout (its inertia_tool and built extension)")
    ap.add_argument("--small", type=int, default=2000, help="parts of the small catalogue")
    ap.add_argument("--damage", action="append", default=[], metavar="DIR",
                    help="a folder written by benchmarks/damage/make_cases.py (--out); repeatable")
    ap.add_argument("--child", nargs=3, metavar=("TREE", "LISTING", "OUT"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        _child(*args.child)
        return 0
    if not args.baseline:
        ap.error("--baseline DIR is required")
    with tempfile.TemporaryDirectory() as tmp:
        files, counts = _files(tmp, args.small, args.damage)
        listing = os.path.join(tmp, "files.txt")
        with open(listing, "w") as fh:
            fh.writelines(f"{f}\n" for f in files)
        rows = {}
        for tag, tree in (("this checkout", ROOT), ("baseline", os.path.abspath(args.baseline))):
            out = os.path.join(tmp, f"{tag[:4]}.jsonl")
            subprocess.run([sys.executable, os.path.abspath(__file__), "--child", tree, listing, out], check=True,
                           env={**os.environ, "PYTHONPATH": tree})
            with open(out) as fh:
                rows[tag] = [json.loads(line) for line in fh]
    mine, theirs = rows["this checkout"], rows["baseline"]
    print("files: " + "; ".join(f"{n} {what}" for what, n in counts.items()) + f"; {len(files)} in all, "
          "each with the default options and with repair=True")
    if len(mine) != len(theirs):
        print(f"DIFFERENT: {len(mine)} rows here, {len(theirs)} in the baseline")
        return 1
    statuses: dict[tuple[str, str], int] = {}
    different = []
    for a, b in zip(mine, theirs):
        statuses[a["options"], a["status"]] = statuses.get((a["options"], a["status"]), 0) + 1
        for k in sorted(set(a) | set(b)):
            if k not in VOLATILE and a.get(k) != b.get(k):
                different.append((a["options"], a["path"], k, a.get(k), b.get(k)))
    fields = len(mine[0]) - len(VOLATILE) if mine else 0
    print(f"{len(mine)} rows of {fields} fields compared (all but {', '.join(VOLATILE)}); statuses: "
          + ", ".join(f"{o} {s} {n}" for (o, s), n in sorted(statuses.items())))
    if different:
        print(f"DIFFERENT: {len(different)} fields, the first:")
        for d in different[:20]:
            print("  ", d)
        return 1
    print("identical: every field of every row")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
