"""Where the time of ``inertia-tool batch`` goes per file: each stage timed on its own, in one run.

Writes the ``small`` catalogue of ``bench_batch.py`` (default 1,000 parts of 12-4,800 triangles) and a 12-triangle
box, then times per file: the SHA-256 of the file, reading it, what the batch does instead (one open and read that
hashes the bytes, then the reader parsing those bytes), the whole engine (``mass_properties`` with the
principal axes) and within it the face-pair check (``surface_contacts`` on the welded mesh), the batch's per-file
work (``analyze_chunk``: engine, hash, row), formatting a row, one ``write`` of it, one ``fsync``, pickling a
chunk's rows, and the round trip of an empty task through a 2-process pool (what one task per file paid on top of
the work). CPU seconds per file of this process (``time.process_time``) except the fsync and the pool round trip
(wall time), so the load of a shared machine matters less. Last, the engine's time per kind of part of the small
catalogue, with the face-pair check's share.

    python benchmarks/bench_batch_stages.py [--small 1000]
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import os
import pickle
import sys
import tempfile
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from bench_batch import SMALL_KINDS, _write_stl, make_small_meshes  # noqa: E402
from inertia_tool.batch.rows import format_row  # noqa: E402
from inertia_tool.batch.runner import BatchOptions, _read_once, analyze_chunk, discover_files, file_sha256  # noqa: E402
from inertia_tool.mass.pipeline import mass_properties  # noqa: E402
from inertia_tool.mesh import LoadOptions  # noqa: E402
from inertia_tool.mesh.intersect import surface_contacts  # noqa: E402
from inertia_tool.mesh.read import load_mesh  # noqa: E402


def _noop(x):
    return x


def _per_file(fn, items, clock=time.process_time) -> float:
    fn(items[0])                                            # first call: imports, caches
    t0 = clock()
    for item in items:
        fn(item)
    return (clock() - t0) / len(items) * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=1000)
    args = ap.parse_args()
    options = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        small = os.path.join(tmp, "small")
        os.mkdir(small)
        faces = make_small_meshes(small, args.small)
        box_dir = os.path.join(tmp, "box")
        os.mkdir(box_dir)
        for k in range(200):
            _write_stl(os.path.join(box_dir, f"box{k:03d}.stl"), trimesh.creation.box((10.0 + k, 20.0, 30.0)))
        print(f"load average {os.getloadavg()[0]:.2f}; CPU µs per file (process time) unless marked wall")
        print(f"{'stage':52s} {'small':>9s} {'box':>9s}")
        sets = {"small": discover_files(small), "box": discover_files(box_dir)}
        rows = {name: analyze_chunk([(f, None) for f in files], options) for name, files in sets.items()}
        out = os.path.join(tmp, "rows.jsonl")
        fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_APPEND)
        line = format_row(rows["small"][0], "jsonl")
        welded = {name: [load_mesh(f, units="mm") for f in files] for name, files in sets.items()}
        stages = [
            ("sha256 of the file", lambda name: _per_file(file_sha256, sets[name])),
            ("read (load_mesh)", lambda name: _per_file(lambda f: load_mesh(f, units="mm"), sets[name])),
            ("batch: read once (open, read, hash)", lambda name: _per_file(_read_once, sets[name])),
            ("batch: read once + load_mesh of the bytes",
             lambda name: _per_file(lambda f: load_mesh(f, units="mm", data=_read_once(f)[0]), sets[name])),
            ("engine (mass_properties + principal axes)",
             lambda name: _per_file(lambda f: mass_properties(f, density=1240.0, units="mm").principal, sets[name])),
            ("  of which the face-pair check (surface_contacts)",
             lambda name: _per_file(lambda m: surface_contacts(m.vertices, m.faces), welded[name])),
            ("batch work per file (analyze_chunk: hash, engine, row)",
             lambda name: _per_file(lambda c: analyze_chunk(c, options), [[(f, None)] for f in sets[name]])),
            ("format a row (JSONL)", lambda name: _per_file(lambda r: format_row(r, "jsonl"), rows[name])),
            ("format a row (CSV)", lambda name: _per_file(lambda r: format_row(r, "csv"), rows[name])),
            ("one write of a row", lambda name: _per_file(lambda r: os.write(fd, line), rows[name])),
            ("pickle a chunk's rows, per row", lambda name: _per_file(pickle.dumps, [rows[name]]) / len(rows[name])),
        ]
        for label, measure in stages:
            print(f"{label:52s} {measure('small'):9.1f} {measure('box'):9.1f}")
        fsync = _per_file(lambda _: (os.write(fd, line), os.fsync(fd)), list(range(200)), clock=time.perf_counter)
        print(f"{'one write + fsync (wall)':52s} {fsync:9.1f}")
        os.close(fd)
        with cf.ProcessPoolExecutor(2) as pool:
            list(pool.map(_noop, range(10)))
            t0 = time.perf_counter()
            for k in range(500):
                pool.submit(_noop, k).result()
            trip = (time.perf_counter() - t0) / 500 * 1e6
        print(f"{'round trip of one empty task, 2-process pool (wall)':52s} {trip:9.1f}")
        print(f"small: {len(faces)} files, {min(faces)}-{max(faces)} triangles, median {int(np.median(faces))}; "
              "box: 200 files of 12 triangles")
        print(f"\nengine per kind of part of the small catalogue (CPU µs per file; they take turns: "
              f"{', '.join(SMALL_KINDS)}):")
        print(f"{'kind':10s} {'files':>6s} {'triangles':>13s} {'engine':>9s} {'face pairs':>11s} {'share':>6s}")
        for k, kind in enumerate(SMALL_KINDS):
            files = sets["small"][k::len(SMALL_KINDS)]
            meshes = welded["small"][k::len(SMALL_KINDS)]
            engine = _per_file(lambda f: mass_properties(f, density=1240.0, units="mm").principal, files)
            pairs = _per_file(lambda m: surface_contacts(m.vertices, m.faces), meshes)
            counts = faces[k::len(SMALL_KINDS)]
            print(f"{kind:10s} {len(files):6d} {min(counts):6d}-{max(counts):<6d} {engine:9.1f} {pairs:11.1f} "
                  f"{pairs / engine:6.0%}")


if __name__ == "__main__":
    main()
