"""Every batch row field the same on this checkout and on another (e.g. ``main``): the check that a change to the
batch's per-file path changed its speed only.

Writes the ``small`` catalogue of ``bench_batch.py`` (binary STL), the repository's ``meshes/*.stl`` and, from one or
more folders written by ``benchmarks/damage/make_cases.py`` (``--damage DIR``, repeatable), every damaged case as an
OBJ file (coordinates printed with 17 significant digits: the float64 values exactly) and every fourth also as a
binary STL (float32, the STL path's own welding), plus a few bad files (empty, truncated, not a mesh, a directory
named like a mesh, a FIFO).  Then each checkout, in a fresh child process, runs the batch's per-file work
(``analyze_chunk``) over all of them, once with the default options and once with ``repair=True``, and this script
compares the rows as the batch writes them: each row's bytes in both formats of the results file (JSONL and CSV,
each checkout's own writer, ``inertia_tool.batch.rows.format_row``), and each field by its JSON text, so that a
change Python's ``==`` cannot see is a difference (``-0.0`` for ``0.0``, ``1`` or ``True`` for ``1.0``: different
bytes in the file).  ``seconds`` and ``worker`` (the time taken and the process) are blanked in both.

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
    from inertia_tool.batch.rows import format_row

    with open(out, "w") as fh:
        for label, options in (("default", BatchOptions(load=LoadOptions(units="mm"), density=1240.0)),
                               ("repair", BatchOptions(load=LoadOptions(units="mm", repair=True), material="steel"))):
            for row in analyze_chunk([(path, None) for path in files], options):
                row.update(dict.fromkeys(VOLATILE))
                written = {fmt: format_row(row, fmt).decode("utf-8") for fmt in ("jsonl", "csv")}
                fh.write(json.dumps({"options": label, "row": row, "written": written}) + "\n")


def _text(value) -> str:
    """A field's value as JSON text: what tells ``-0.0`` from ``0.0`` and ``1`` or ``True`` from ``1.0``."""
    return json.dumps(value)


def compare_rows(mine: list[dict], theirs: list[dict]) -> tuple[dict[tuple[str, str], int], list[tuple]]:
    """Compare two checkouts' records (``{"options", "row", "written"}``, as :func:`_child` writes them), in order.

    Returns
    -------
    statuses : dict
        ``(options, status) -> rows`` of ``mine``.
    different : list of tuple
        ``(options, path, what, here, baseline)`` for each field whose JSON text differs (``what`` its name), each
        written form whose bytes differ (``what`` ``"written jsonl"`` or ``"written csv"``), and one ``"rows"``
        entry when the numbers of rows differ; empty when every row is the same.  ``seconds`` and ``worker``
        are not compared.
    """
    statuses: dict[tuple[str, str], int] = {}
    different: list[tuple] = []
    if len(mine) != len(theirs):
        different.append(("", "", "rows", len(mine), len(theirs)))
    for a, b in zip(mine, theirs):
        ra, rb = a["row"], b["row"]
        statuses[a["options"], ra.get("status")] = statuses.get((a["options"], ra.get("status")), 0) + 1
        where = (a["options"], ra.get("path"))
        if a["options"] != b["options"]:
            different.append((*where, "options", a["options"], b["options"]))
        for k in sorted(set(ra) | set(rb)):
            if k not in VOLATILE and (k not in ra or k not in rb or _text(ra[k]) != _text(rb[k])):
                different.append((*where, k, ra.get(k, "(absent)"), rb.get(k, "(absent)")))
        for fmt in sorted(set(a["written"]) | set(b["written"])):
            if a["written"].get(fmt) != b["written"].get(fmt):
                different.append((*where, f"written {fmt}", a["written"].get(fmt), b["written"].get(fmt)))
    return statuses, different


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
    statuses, different = compare_rows(mine, theirs)
    fields = len(mine[0]["row"]) - len(VOLATILE) if mine else 0
    print(f"{len(mine)} rows of {fields} fields compared by their JSON text, and as written (JSONL and CSV bytes; "
          f"{', '.join(VOLATILE)} blanked); statuses: "
          + ", ".join(f"{o} {s} {n}" for (o, s), n in sorted(statuses.items())))
    if different:
        print(f"DIFFERENT: {len(different)} fields or written rows, the first:")
        for d in different[:20]:
            print("  ", d)
        return 1
    print("identical: every field of every row, and every row as written in both formats")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
