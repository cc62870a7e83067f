"""Throughput of ``inertia-tool batch``: files/s with 1 process, 2 processes and a Dask LocalCluster(2), in one run.

Two catalogues, each written as binary STL files in a temporary directory, each run three ways into fresh JSONL
files (the real writer: lock, one ``write`` per row, fsync at most once a second):

- ``small``: 1,000 small parts, the typical parts-catalogue mix: boxes (12 triangles), icospheres of
  80-1,280, cylinders of 64-4,800 and tori of 256-3,072 triangles (the script prints the range and median);
- ``mix``: the 200 larger meshes of issue 8 (icospheres of 5,120-20,480 triangles, boxes, tori of 2k-18k,
  cylinders of 1k-4k; 0.6 kB-1 MB).

It prints files/s and the ratio to one process for each (the fastest of ``--repeat`` rounds, each round running every
configuration in turn), with the load average before and after (the machine is shared: other work slows the
parallel runs).  It also prints the CPU time per file of each configuration (this process, the pool's worker
processes, the Dask workers: what chunking, IPC and the scheduler add; the median of the rounds), and of it the
part spent in this process ("of which here": the writer, the pool's threads, or Dask's scheduler, client and
nannies, which a LocalCluster runs here) and the "CPU-bound
ratio" that CPU time allows on two idle cores (one process's CPU time over half the configuration's), which the
load of the machine changes less.  The Dask LocalCluster is started for its runs in each round and closed after
them (its client's event loop would slow the other configurations); its start-up (worker processes, engine
imports) is timed separately, not in files/s.

    python benchmarks/bench_batch.py [--set small|mix|both] [--small 1000] [--files 200] [--repeat 3]
                                     [--baseline DIR]

Run from the repository root (it puts the repository on sys.path).  ``--baseline DIR`` (e.g. a copy of ``main``
with its built extension) runs each round of the same configurations on this checkout and on DIR's
``inertia_tool``, each in a fresh child process, in alternating order, so that before and after meet the same
load and the same conditions; the baseline's rows are marked ``[baseline]`` and their ratios are to its own single
process.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time


def _tree(argv: list[str]) -> str:
    """The checkout whose ``inertia_tool`` is timed: ``--tree DIR`` (how ``--baseline`` runs the other checkout),
    else the one holding this script."""
    if "--tree" in argv[:-1]:
        return os.path.abspath(argv[argv.index("--tree") + 1])
    return os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


sys.path.insert(0, _tree(sys.argv))

import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from inertia_tool.mesh import LoadOptions  # noqa: E402
from inertia_tool.batch.runner import BatchOptions, discover_files, run_batch  # noqa: E402
from inertia_tool.batch.rows import open_results  # noqa: E402

from _checkouts import in_turn, run_script  # noqa: E402


def _require_c_kernels() -> None:
    """Stop unless the C kernels are loaded, or switched off on purpose (``INERTIA_TOOL_NO_ACCEL``): a checkout
    whose ``_accel.c`` changed (a rebase) without a rebuild falls back to numpy with one warning, and its
    numbers would be those of another program."""
    from inertia_tool._native import NO_ACCEL_ENV, accel

    if accel() is None and os.environ.get(NO_ACCEL_ENV, "").strip() in ("", "0"):
        raise SystemExit(f"benchmark: the C kernels of {os.path.dirname(os.path.dirname(accel.__code__.co_filename))}"
                         " are not loaded (a stale or missing build: rebuild the extension), so its numbers would "
                         f"be numpy's; set {NO_ACCEL_ENV}=1 to time numpy on purpose")


def _write_stl(path, mesh):
    tri = np.asarray(mesh.vertices, dtype=np.float32)[np.asarray(mesh.faces)]
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    with open(path, "wb") as fh:
        fh.write(b"bench".ljust(80))
        fh.write(np.uint32(len(tri)).tobytes())
        fh.write(rec.tobytes())


def make_meshes(directory: str, count: int, seed: int = 0) -> list[int]:
    """Write ``count`` meshes of the ``mix`` catalogue; return their numbers of triangles."""
    rng = np.random.default_rng(seed)
    faces = []
    for k in range(count):
        kind = k % 4
        if kind == 0:
            m = trimesh.creation.icosphere(subdivisions=int(rng.integers(4, 6)), radius=float(rng.uniform(5, 50)))
        elif kind == 1:
            m = trimesh.creation.box(rng.uniform(5, 80, 3))
        elif kind == 2:
            m = trimesh.creation.torus(float(rng.uniform(20, 40)), float(rng.uniform(3, 10)),
                                       major_sections=int(rng.integers(64, 192)),
                                       minor_sections=int(rng.integers(16, 48)))
        else:
            m = trimesh.creation.cylinder(radius=float(rng.uniform(3, 30)), height=float(rng.uniform(5, 90)),
                                          sections=int(rng.integers(256, 1024)))
        m.apply_translation(rng.uniform(-100, 100, 3))
        _write_stl(os.path.join(directory, f"part{k:04d}.stl"), m)
        faces.append(len(m.faces))
    return faces


#: The kinds of part of the ``small`` catalogue, in the order they take turns.
SMALL_KINDS = ("box", "icosphere", "cylinder", "torus")


def make_small_meshes(directory: str, count: int, seed: int = 1, kinds: tuple[str, ...] = SMALL_KINDS) -> list[int]:
    """Write ``count`` meshes of the ``small`` catalogue (12-4,800 triangles), taking the ``kinds`` in turn (all
    four by default: the same files as before for the same seed); return their numbers of triangles."""
    rng = np.random.default_rng(seed)
    faces = []
    order = [SMALL_KINDS.index(k) for k in kinds]
    for k in range(count):
        kind = order[k % len(order)]
        if kind == 0:
            m = trimesh.creation.box(rng.uniform(5, 80, 3))
        elif kind == 1:
            m = trimesh.creation.icosphere(subdivisions=int(rng.integers(1, 4)), radius=float(rng.uniform(5, 50)))
        elif kind == 2:
            m = trimesh.creation.cylinder(radius=float(rng.uniform(3, 30)), height=float(rng.uniform(5, 90)),
                                          sections=int(rng.integers(16, 1201)))
        else:
            m = trimesh.creation.torus(float(rng.uniform(20, 40)), float(rng.uniform(3, 10)),
                                       major_sections=int(rng.integers(16, 65)),
                                       minor_sections=int(rng.integers(8, 25)))
        m.apply_translation(rng.uniform(-100, 100, 3))
        _write_stl(os.path.join(directory, f"small{k:04d}.stl"), m)
        faces.append(len(m.faces))
    return faces


def _worker_cpu(client) -> float:
    """CPU seconds used so far by the Dask workers' processes (0 without a client)."""
    return sum(client.run(time.process_time).values()) if client is not None else 0.0


def _run(files, out, **kw):
    """Wall seconds of one batch and the CPU seconds it used in all (this process, the pool's processes, the
    Dask workers)."""
    client = kw.get("client")
    before, workers_before = os.times(), _worker_cpu(client)
    with open_results(out) as r:
        summary = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1240.0), r.write_row, **kw)
    after = os.times()              # the pool's processes are joined by now: their time is in children_*
    cpu = (sum(after[:4]) - sum(before[:4])) + _worker_cpu(client) - workers_before
    parent = sum(after[:2]) - sum(before[:2])      # this process: the writer, the pool's or Dask's threads here
    if summary.ok != len(files):
        raise SystemExit(f"benchmark: {summary.failed} files failed")
    return summary.seconds, cpu, parent


def _catalogue(tmp, name, make, count):
    directory = os.path.join(tmp, name)
    os.mkdir(directory)
    faces = make(directory, count)
    files = discover_files(directory)
    size = sum(os.path.getsize(f) for f in files)
    print(f"{name}: {len(files)} STL files, {sum(faces):,} triangles ({min(faces):,}-{max(faces):,}, median "
          f"{int(np.median(faces)):,} per file), {size / 1e6:.1f} MB")
    return files


def _child_round(args, tree: str) -> list[tuple[str, str, tuple[float, float]]]:
    """One round of every configuration on the checkout ``tree``, in a fresh child process running this script
    with ``--tree``: ``(catalogue, configuration, (seconds, CPU seconds))`` of each (configuration ``"startup"``:
    the Dask cluster's start-up, seconds)."""
    argv = ["--tree", tree, "--repeat", "1", "--json",
            "--set", args.set, "--small", str(args.small), "--files", str(args.files), "--kinds", args.kinds]
    done = run_script(__file__, argv, capture=True)
    rows = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    return [(r["catalogue"], r["configuration"], (r["seconds"], r["cpu"], r.get("parent", float("nan"))))
            for r in rows]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", choices=["small", "mix", "both"], default="both")
    ap.add_argument("--small", type=int, default=1000, help="files of the small catalogue")
    ap.add_argument("--files", type=int, default=200, help="files of the mix catalogue")
    ap.add_argument("--repeat", type=int, default=3, help="rounds of every configuration (the best is reported)")
    ap.add_argument("--baseline", metavar="DIR", help="another checkout (e.g. a copy of main) timed in a child "
                    "process after each round of this one's, in the same run")
    ap.add_argument("--tree", metavar="DIR", help="import inertia_tool from DIR (set by --baseline)")
    ap.add_argument("--json", action="store_true", help="print the results as JSON lines (read by --baseline)")
    ap.add_argument("--kinds", default=",".join(SMALL_KINDS),
                    help="kinds of part of the small catalogue, comma-separated (default all: "
                         f"{','.join(SMALL_KINDS)}); e.g. without cylinder, whose fan-triangulated caps make the "
                         "face-pair check quadratic in the sections (issue 25)")
    args = ap.parse_args()
    kinds = tuple(k.strip() for k in args.kinds.split(",") if k.strip())
    if not kinds or not set(kinds) <= set(SMALL_KINDS):
        ap.error(f"--kinds takes some of {','.join(SMALL_KINDS)}, got {args.kinds!r}")
    _require_c_kernels()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, Python "
          f"{platform.python_version()}; load average before {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    with tempfile.TemporaryDirectory() as tmp:
        catalogues = {}
        if args.set in ("small", "both"):
            catalogues["small"] = _catalogue(tmp, "small", lambda d, n: make_small_meshes(d, n, kinds=kinds),
                                             args.small)
        if args.set in ("mix", "both"):
            catalogues["mix"] = _catalogue(tmp, "mix", make_meshes, args.files)
        try:
            from inertia_tool.batch.cluster import connect_dask
        except ImportError:
            connect_dask = None
            print("(dask.distributed is not installed: no Dask rows)")
        configs = [("1 process (in-process)", dict(jobs=1)), ("2 processes (ProcessPoolExecutor)", dict(jobs=2))]
        if connect_dask is not None:
            configs.append(("Dask LocalCluster(2 workers)", dict(client=None)))
        results: dict = {}
        startups = []
        # rounds of every configuration in turn, so that a change in the machine's load hits all of them; the
        # cluster lives only for its own runs (its client's event loop in this process would slow the others).
        # With --baseline both checkouts run each round in a fresh child process, in alternating order: in one
        # process the rounds after the first ran their single process beside the threads a closed Dask client
        # leaves behind, which the baseline's fresh child did not (0.3-0.6 ms of CPU per file more at load 15)
        for r in range(args.repeat if args.baseline else 0):
            for tree, tag in in_turn([(_tree([]), ""), (args.baseline, "[baseline] ")], r):
                for name, label, got in _child_round(args, tree):
                    if name == "startup":
                        if not tag:
                            startups.append(got[0])
                        continue
                    results.setdefault((name, tag + label), []).append(got)
        for r in range(0 if args.baseline else args.repeat):
            for label, kw in configs:
                cluster = None
                if "client" in kw:
                    t0 = time.perf_counter()
                    cluster = connect_dask("local", 2)
                    startups.append(time.perf_counter() - t0)
                    kw = dict(client=cluster.client)
                try:
                    for name, files in catalogues.items():
                        got = _run(files, os.path.join(tmp, f"{name}_{label[:1]}_{r}.jsonl"), **kw)
                        results.setdefault((name, label), []).append(got)
                finally:
                    if cluster is not None:
                        cluster.close()
        if args.json:
            for (name, label), rounds in results.items():
                for sec, cpu, parent in rounds:
                    print(json.dumps({"catalogue": name, "configuration": label, "seconds": sec, "cpu": cpu,
                                      "parent": parent}))
            for sec in startups:
                print(json.dumps({"catalogue": "startup", "configuration": "startup", "seconds": sec, "cpu": 0.0}))
            return
        startup = min(startups) if startups else None
        if args.baseline:
            print(f"[baseline]: {os.path.abspath(args.baseline)}; each round of both checkouts in a fresh process, "
                  "in alternating order")
        print("seconds and files/s: the fastest round; CPU: the median of the rounds (under load the fastest round in "
              "wall time is not the one of least CPU)")
        print(f"{'catalogue':9s} {'configuration':47s} {'seconds':>8s} {'files/s':>8s} {'ratio':>6s} "
              f"{'CPU ms/file':>11s} {'of which here':>13s} {'CPU-bound ratio':>15s}")

        def best(rounds):
            """The fastest round's seconds, the median CPU seconds and the median CPU of this process."""
            return (min(r[0] for r in rounds), float(np.median([r[1] for r in rounds])),
                    float(np.median([r[2] for r in rounds])))

        for name, files in catalogues.items():
            for (n, label), rounds in results.items():
                if n == name:
                    sec, cpu, here = best(rounds)
                    tree, own = ("[baseline] ", label[11:]) if label.startswith("[baseline] ") else ("", label)
                    base, base_cpu, _ = best(results[name, f"{tree}1 process (in-process)"])
                    # the wall ratio the CPU time allows with both cores to ourselves: the same CPU over 2
                    ideal = base_cpu / (cpu / (1 if own.startswith("1 ") else 2))
                    print(f"{name:9s} {label:47s} {sec:8.2f} {len(files) / sec:8.1f} {base / sec:6.2f} "
                          f"{1e3 * cpu / len(files):11.2f} {1e3 * here / len(files):13.2f} {ideal:15.2f}")
        if startup is not None:
            print(f"(Dask LocalCluster start-up with the workers' warm-up, not included above: {startup:.2f} s, "
                  "the fastest of the rounds)")
        print(f"load average after {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
