"""Where the CPU time of ``inertia-tool batch`` goes per file, stage by stage, in one run.

Writes the ``small`` catalogue of ``bench_batch.py`` (default 2,000 binary STL parts of 12-4,800 triangles: boxes,
icospheres, cylinders, tori) and 200 boxes of 12 triangles, then times each stage of the batch's per-file work on
its own, over every file (best of ``--repeat`` passes, CPU time of this process, ``time.process_time``, so the
load of a shared machine inflates it less than wall time; a stage's input is made before it is timed):

=================  ================================================================================================
read               open the file and read its bytes (``open_regular``, one ``read``) — the batch's read-once
hash               SHA-256 of those bytes (the row's ``sha256``, what resuming compares)
parse + weld       ``load_mesh(path, data=bytes)``: the STL parser and the bit-exact weld (C)
census + shells    ``census_and_shells``: edge census and shell labels (C)
face-pair check    ``surface_contacts``: the exact check behind the certificate's ``no-crossing-faces`` (C)
integrals          ``body_volume_moments``: the per-shell volume integrals (C)
rest of checks     the checks as the batch runs them (the clean-part fast path ``prepare_clean``, else
                   ``prepare_mesh``) minus the three above: the policy in Python (degenerate faces, round-off
                   bounds, orientation by depth, nesting, the report and certificate objects)
mass stage         ``mass_properties(raw, fast_path=True).principal`` minus the checks: bodies, ``MassProperties``,
                   principal axes, plausibility checks and warnings
batch row          the batch's work for the file (``analyze_chunk`` without the chunk) minus all of the above:
                   the row's dict, the warnings capture, the error handling
JSON / CSV row     formatting a row for the results file (``format_row``)
write              one ``write`` of a row (``O_APPEND``; an ``fsync`` at most once a second is not counted)
IPC (-j N)         pickling and unpickling a chunk's rows, per row, and an empty task's round trip through a
                   2-process pool divided by the files of a 0.05 s chunk (wall time)
=================  ================================================================================================

Each file goes through every stage in turn (so a change of the machine's load hits all stages alike) and the
differences are taken file by file; the cost of the clock itself (a system call, several µs here) is subtracted.
The sum of the stages is shown beside the batch's work timed whole.  Last, the per-call cost of each C stage
on a 12-triangle box (its fixed cost: a box has nothing to compute) and the engine's time per kind of part.

    python benchmarks/bench_batch_stages.py [--small 2000] [--repeat 3]
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

import hashlib  # noqa: E402

import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from bench_batch import SMALL_KINDS, _write_stl, make_small_meshes  # noqa: E402
from inertia_tool.batch.chunks import POOL_CHUNK_SECONDS  # noqa: E402
from inertia_tool.batch.rows import format_row  # noqa: E402
from inertia_tool.batch.runner import BatchOptions, _analyze, _chunk_context, discover_files  # noqa: E402
from inertia_tool.integrals import body_volume_moments  # noqa: E402
from inertia_tool.mass.pipeline import mass_properties  # noqa: E402
from inertia_tool.mesh import LoadOptions  # noqa: E402
from inertia_tool.mesh.checks import census_and_shells  # noqa: E402
from inertia_tool.mesh.clean_part import prepare_clean  # noqa: E402
from inertia_tool.mesh.intersect import surface_contacts  # noqa: E402
from inertia_tool.mesh.prepare import prepare_mesh  # noqa: E402
from inertia_tool.mesh.read import load_mesh  # noqa: E402
from inertia_tool.mesh.regular import open_regular  # noqa: E402


def _noop(x):
    return x


def _read(path: str) -> bytes:
    with open_regular(path) as fh:
        return fh.read()


def _per_file(fn, items, repeat: int, clock=time.process_time) -> float:
    """µs per item of ``fn`` over ``items``: the best of ``repeat`` passes (one untimed call first)."""
    fn(items[0])
    best = float("inf")
    for _ in range(repeat):
        t0 = clock()
        for item in items:
            fn(item)
        best = min(best, clock() - t0)
    return best / len(items) * 1e6


def _timer_cost(calls: int = 20_000) -> float:
    """CPU seconds that one ``time.process_time()`` call adds to an interval it closes (a system call: several µs
    on a virtual machine), subtracted from each stage below."""
    t0 = time.process_time()
    for _ in range(calls):
        time.process_time()
    return (time.process_time() - t0) / calls


def _stages(files: list[str], options: BatchOptions, repeat: int) -> dict[str, float]:
    """µs of CPU per file of each stage over ``files``.

    Interleaved: each file goes through every stage in turn, each stage timed on its own, so that a change of the
    machine's load hits all stages alike; the differences (rest of checks, mass stage, batch row) are taken file by
    file.  The least total of each stage over ``repeat`` passes is kept."""
    clock = time.process_time
    cost = _timer_cost()
    context = _chunk_context(options, [], options.key(), "bench")
    best: dict[str, float] = {}
    rows = []
    for _ in range(repeat):
        total: dict[str, float] = {}
        rows = []

        def add(name: str, seconds: float) -> None:
            total[name] = total.get(name, 0.0) + max(seconds - cost, 0.0)

        for path in files:
            t0 = clock()
            data = _read(path)
            t1 = clock()
            hashlib.sha256(data).hexdigest()
            t2 = clock()
            raw = load_mesh(path, units="mm", data=data)
            t3 = clock()
            census_and_shells(raw.faces, len(raw.vertices), raw.vertices)
            t4 = clock()
            surface_contacts(raw.vertices, raw.faces)
            t5 = clock()
            prepared = prepare_clean(raw) or prepare_mesh(raw)      # as the batch runs it: the fast path first
            t6 = clock()
            body_volume_moments(prepared.vertices, prepared.faces, prepared.labels, len(prepared.shells))
            t7 = clock()
            _ = mass_properties(raw, density=1240.0, fast_path=True).principal
            t8 = clock()
            row = _analyze(path, None, context)
            t9 = clock()
            rows.append(row)
            read, digest, parse, census, pairs = t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4
            prepare, integrals, engine, whole = t6 - t5, t7 - t6, t8 - t7, t9 - t8
            for name, seconds in (("read", read), ("hash", digest), ("parse + weld", parse),
                                  ("census + shells", census), ("face-pair check", pairs), ("integrals", integrals),
                                  ("rest of checks", prepare - census - pairs - integrals + 3 * cost),
                                  ("mass stage", engine - prepare + cost),
                                  ("batch row", whole - read - digest - parse - engine + 4 * cost),
                                  ("analyze_chunk whole", whole)):
                add(name, seconds)
        for name, seconds in total.items():
            best[name] = min(best.get(name, float("inf")), seconds / len(files) * 1e6)
    out = dict(best)
    out["JSON row"] = _per_file(lambda r: format_row(r, "jsonl"), rows, repeat)
    out["CSV row"] = _per_file(lambda r: format_row(r, "csv"), rows, repeat)
    with tempfile.TemporaryFile() as fh:
        line = format_row(rows[0], "jsonl")
        out["write"] = _per_file(lambda _: os.write(fh.fileno(), line), rows, repeat)
    out["IPC: pickle + unpickle rows"] = _per_file(lambda c: pickle.loads(pickle.dumps(c, protocol=5)), [rows],
                                                   repeat) / len(rows)
    return out


def _pool_round_trip(tasks: int = 300) -> float:
    """Wall µs of an empty task's round trip through a 2-process pool."""
    with cf.ProcessPoolExecutor(2) as pool:
        list(pool.map(_noop, range(10)))
        t0 = time.perf_counter()
        for k in range(tasks):
            pool.submit(_noop, k).result()
        return (time.perf_counter() - t0) / tasks * 1e6


def _c_fixed_costs(repeat: int) -> dict[str, float]:
    """µs of CPU per call of each C stage on a 12-triangle box (1,000 calls)."""
    box = trimesh.creation.box((10.0, 20.0, 30.0))
    v, f = np.asarray(box.vertices, dtype=np.float64), np.asarray(box.faces)
    prepared = prepare_mesh(load_mesh((v, f)))
    calls = list(range(1000))
    return {"census + shells": _per_file(lambda _: census_and_shells(f, len(v), v), calls, repeat),
            "face-pair check": _per_file(lambda _: surface_contacts(v, f), calls, repeat),
            "integrals": _per_file(lambda _: body_volume_moments(prepared.vertices, prepared.faces, prepared.labels,
                                                                 len(prepared.shells)), calls, repeat),
            "whole engine (mass_properties + principal axes)":
                _per_file(lambda _: mass_properties((v, f), density=1240.0).principal, calls, repeat)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    options = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    warnings.simplefilter("ignore")
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        small = os.path.join(tmp, "small")
        os.mkdir(small)
        faces = make_small_meshes(small, args.small)
        box_dir = os.path.join(tmp, "box")
        os.mkdir(box_dir)
        for k in range(200):
            _write_stl(os.path.join(box_dir, f"box{k:03d}.stl"), trimesh.creation.box((10.0 + k, 20.0, 30.0)))
        sets = {"small": discover_files(small), "box": discover_files(box_dir)}
        results = {name: _stages(files, options, args.repeat) for name, files in sets.items()}
        trip = _pool_round_trip()
        per_chunk = {}
        for name in sets:
            seconds = results[name]["analyze_chunk whole"] * 1e-6
            per_chunk[name] = max(1.0, POOL_CHUNK_SECONDS / seconds)
            results[name]["IPC: pool round trip / chunk"] = trip / per_chunk[name]
        print(f"load average before {', '.join(f'{x:.1f}' for x in load_before)}, after "
              f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}; {os.cpu_count()} CPUs; CPU µs per file (best of "
              f"{args.repeat} passes)")
        print(f"small: {len(faces)} files, {min(faces)}-{max(faces)} triangles, median {int(np.median(faces))}; "
              "box: 200 files of 12 triangles")
        print("\n| stage | small | share | box | share |\n|---|---:|---:|---:|---:|")
        order = ["read", "hash", "parse + weld", "census + shells", "face-pair check", "integrals", "rest of checks",
                 "mass stage", "batch row", "JSON row", "write", "IPC: pickle + unpickle rows",
                 "IPC: pool round trip / chunk"]
        totals = {name: sum(results[name][k] for k in order) for name in sets}
        for k in order:
            cells = " | ".join(f"{results[n][k]:.1f} | {results[n][k] / totals[n]:.0%}" for n in sets)
            print(f"| {k} | {cells} |")
        print("| **sum (-j 2 worker + parent)** | " + " | ".join(f"**{totals[n]:.0f}** | 100%" for n in sets) + " |")
        print("| (CSV row instead of JSON) | " + " | ".join(f"{results[n]['CSV row']:.1f} | " for n in sets) + " |")
        print("| (analyze_chunk timed whole) | "
              + " | ".join(f"{results[n]['analyze_chunk whole']:.0f} | " for n in sets) + " |")
        print(f"\n(files per 0.05 s chunk: small {per_chunk['small']:.0f}, box {per_chunk['box']:.0f}; an empty "
              f"task's round trip through a 2-process pool: {trip:.0f} µs wall)")
        print("\nfixed cost per call on a 12-triangle box (CPU µs):")
        for k, v in _c_fixed_costs(args.repeat).items():
            print(f"  {k:50s} {v:8.1f}")
        print(f"\nengine per kind of part of the small catalogue (CPU µs per file; they take turns: "
              f"{', '.join(SMALL_KINDS)}):")
        print(f"{'kind':10s} {'files':>6s} {'triangles':>13s} {'engine':>9s} {'face pairs':>11s} {'share':>6s}")
        raws = [load_mesh(f, units="mm") for f in sets["small"]]
        for k, kind in enumerate(SMALL_KINDS):
            meshes = raws[k::len(SMALL_KINDS)]
            engine = _per_file(lambda r: mass_properties(r, density=1240.0).principal, meshes, args.repeat)
            pairs = _per_file(lambda m: surface_contacts(m.vertices, m.faces), meshes, args.repeat)
            counts = faces[k::len(SMALL_KINDS)]
            print(f"{kind:10s} {len(meshes):6d} {min(counts):6d}-{max(counts):<6d} {engine:9.1f} {pairs:11.1f} "
                  f"{pairs / engine:6.0%}")


if __name__ == "__main__":
    main()
