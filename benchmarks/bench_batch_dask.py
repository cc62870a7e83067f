"""Where a short batch's time goes on Dask, against one process: the task stream, the CPU of each side, and
chunking (one or two chunks per worker) in the same run.

Writes the ``small`` catalogue of ``bench_batch.py`` (``--small`` binary STL parts), starts one LocalCluster of two
workers (``inertia_tool.batch.cluster.connect_dask``, kept up for the whole run: its start-up is not measured here)
and runs, in each of ``--repeat`` rounds and in turn (the order reversed every other round), the batch in this
process and on Dask with each of ``--chunks`` chunks per worker of a short batch
(``inertia_tool.batch.runner.DASK_SHORT_CHUNKS_PER_WORKER``, set for the run).  For each configuration it prints
medians over the rounds of:

- the wall time and the wall ratio (one process's wall over Dask's, in the same round);
- CPU ms per file: all of it (this process and the workers), of which this process (the client, the scheduler
  and the nannies of a LocalCluster run here), and the CPU-bound ratio (one process's CPU over half of Dask's: the
  wall ratio two idle cores would give);
- from the Dask task stream (``distributed.get_task_stream``): when the first chunk started computing after the
  batch began, the compute span of each chunk (least and most: their difference is the imbalance one worker waits
  for), and the tail from the last chunk's end to the batch's return (rows back, unpickled, handed over).

    python benchmarks/bench_batch_dask.py [--small 200] [--repeat 5] [--chunks 1,2]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _checkouts import this_checkout_first  # noqa: E402

this_checkout_first()


def _one_process(files, options) -> dict:
    from inertia_tool.batch.runner import run_batch

    c0, w0 = time.process_time(), time.perf_counter()
    run_batch(files, options, lambda row: None)
    return {"wall": time.perf_counter() - w0, "cpu": time.process_time() - c0, "here": time.process_time() - c0}


def _dask(files, options, client, per_worker: int) -> dict:
    from distributed import get_task_stream

    import inertia_tool.batch.runner as runner

    saved = runner.DASK_SHORT_CHUNKS_PER_WORKER
    runner.DASK_SHORT_CHUNKS_PER_WORKER = per_worker
    try:
        workers0 = sum(client.run(time.process_time).values())
        with get_task_stream(client=client) as stream:
            c0, t0, w0 = time.process_time(), time.time(), time.perf_counter()
            runner.run_batch(files, options, lambda row: None, client=client)
            wall, here = time.perf_counter() - w0, time.process_time() - c0
        workers = sum(client.run(time.process_time).values()) - workers0
    finally:
        runner.DASK_SHORT_CHUNKS_PER_WORKER = saved
    spans = [(s["start"] - t0, s["stop"] - t0) for task in stream.data for s in task["startstops"]
             if s["action"] == "compute"]
    return {"wall": wall, "cpu": here + workers, "here": here, "tasks": len(spans),
            "first": min(a for a, _ in spans), "least": min(b - a for a, b in spans),
            "most": max(b - a for a, b in spans), "tail": wall - max(b for _, b in spans)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=200, help="files of the small catalogue")
    ap.add_argument("--repeat", type=int, default=5, help="rounds of every configuration (medians are printed)")
    ap.add_argument("--chunks", default="1,2", help="chunks per worker of a short batch to compare, comma-separated")
    args = ap.parse_args()
    per_worker = [int(x) for x in args.chunks.split(",") if x.strip()]
    if not per_worker or min(per_worker) < 1:
        ap.error(f"--chunks takes integers >= 1, got {args.chunks!r}")

    from bench_batch import _require_c_kernels, make_small_meshes

    from inertia_tool.batch.cluster import connect_dask
    from inertia_tool.batch.runner import BatchOptions, discover_files, run_batch
    from inertia_tool.mesh import LoadOptions

    _require_c_kernels()
    warnings.simplefilter("ignore")
    options = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        make_small_meshes(tmp, args.small)
        files = discover_files(tmp)
        run_batch(files[:20], options, lambda row: None)               # this process: imports, first calls
        with connect_dask("local", 2) as cluster:
            run_batch(files[:20], options, lambda row: None, client=cluster.client)
            configs = ["1 process"] + [f"Dask, {k} chunk(s) per worker" for k in per_worker]
            results: dict[str, list[dict]] = {c: [] for c in configs}
            ratios: dict[str, list[float]] = {c: [] for c in configs[1:]}
            for r in range(args.repeat):
                order = configs if r % 2 == 0 else configs[::-1]
                got = {}
                for config in order:
                    if config == "1 process":
                        got[config] = _one_process(files, options)
                    else:
                        got[config] = _dask(files, options, cluster.client, per_worker[configs.index(config) - 1])
                for config in configs:
                    results[config].append(got[config])
                for config in configs[1:]:
                    ratios[config].append(got["1 process"]["wall"] / got[config]["wall"])
    n = len(files)
    print(f"{n} files of the small catalogue; {args.repeat} rounds; load average {load_before[0]:.1f} before, "
          f"{os.getloadavg()[0]:.1f} after (medians over the rounds; CPU-bound ratio: one process's CPU over half "
          "the configuration's)")
    print(f"{'configuration':30s} {'wall s':>7s} {'wall ratio':>10s} {'CPU ms/file':>11s} {'here':>6s} "
          f"{'CPU-bound':>9s} {'tasks':>5s} {'1st start':>9s} {'chunk min':>9s} {'chunk max':>9s} {'tail':>6s}")
    single = statistics.median(x["cpu"] for x in results["1 process"])
    for config in configs:
        rows = results[config]

        def med(key: str) -> float:
            return statistics.median(x[key] for x in rows)

        line = (f"{config:30s} {med('wall'):7.3f} "
                f"{statistics.median(ratios[config]) if config in ratios else 1.0:10.2f} "
                f"{1e3 * med('cpu') / n:11.2f} {1e3 * med('here') / n:6.2f} "
                f"{single / (med('cpu') / (1 if config == '1 process' else 2)):9.2f}")
        if config != "1 process":
            line += (f" {med('tasks'):5.0f} {med('first'):9.3f} {med('least'):9.3f} {med('most'):9.3f} "
                     f"{med('tail'):6.3f}")
        print(line)


if __name__ == "__main__":
    main()
