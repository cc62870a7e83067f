"""``batch --dask local``: the same rows from a Dask LocalCluster of 2 worker processes, in chunks streamed back
as they complete (the code path of a remote scheduler too: only the Client differs)."""

import json
import os

import numpy as np
import pytest
import trimesh

from conftest import write_binary_stl
from inertia_tool.mesh import LoadOptions
from inertia_tool.batch.runner import BatchOptions, discover_files, run_batch
from inertia_tool.cli import main
from inertia_tool.batch.rows import open_results

distributed = pytest.importorskip("dask.distributed", reason="the 'dask' extra is not installed")


@pytest.fixture
def meshes(tmp_path):
    d = tmp_path / "m"
    d.mkdir()
    for k in range(6):
        m = trimesh.creation.box([1 + k, 2, 3]) if k % 2 else trimesh.creation.icosphere(2, radius=1 + k)
        write_binary_stl(d / f"part{k}.stl", m.vertices, m.faces)
    (d / "broken.stl").write_bytes(b"solid broken\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\n")
    return d


def _strip(rows):
    return sorted(json.dumps({k: v for k, v in r.items() if k not in ("seconds", "worker")}) for r in rows)


def _scaled_boxes(directory, count):
    """``count`` unit cubes scaled by 1, 2, ... (b00.stl, b01.stl, ...) in ``directory``; their sorted paths."""
    directory.mkdir()
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    for k in range(count):
        write_binary_stl(directory / f"b{k:02d}.stl", np.asarray(box.vertices) * (1 + k), box.faces)
    return discover_files(directory)


@pytest.fixture(scope="module")
def cluster():
    from inertia_tool.batch.cluster import connect_dask

    with connect_dask("local", 2) as c:
        yield c


@pytest.mark.slow
def test_local_cluster_matches_in_process_rows(meshes, cluster):
    files = discover_files(meshes)
    local_rows, dask_rows = [], []
    run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1240.0), local_rows.append)
    summary = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1240.0), dask_rows.append,
                        client=cluster.client)
    assert (summary.ok, summary.failed) == (6, 1)
    assert _strip(dask_rows) == _strip(local_rows)
    workers = {r["worker"] for r in dask_rows}
    assert 1 <= len(workers) <= 2 and all(not w.endswith(f":{os.getpid()}") for w in workers)  # ran on workers
    box = [r for r in dask_rows if r["path"].endswith("part1.stl")][0]
    mass = 1240.0 * 2e-3 * 2e-3 * 3e-3
    assert box["mass"] == pytest.approx(mass, rel=1e-6)
    assert box["izz"] == pytest.approx(mass / 12 * (4e-6 + 4e-6), rel=1e-5)


@pytest.mark.slow
def test_cli_dask_local_resumes_a_process_pool_run(meshes, tmp_path, capsys):
    out = tmp_path / "r.jsonl"
    assert main(["batch", str(meshes / "part*.stl"), "--out", str(out), "--jobs", "2"]) == 0
    capsys.readouterr()
    code = main(["batch", str(meshes), "--out", str(out), "--jobs", "2", "--dask", "local"])
    err = capsys.readouterr().err
    assert code == 3                  # broken.stl failed
    assert "0 ok, 1 failed in this run; 6 done before;" in err and "Dask (local)" in err
    with open_results(out) as r:
        rows = r.previous_rows
    assert len(rows) == 7 and np.isfinite([r["mass"] for r in rows if r["status"] == "ok"]).all()


@pytest.mark.slow
def test_dask_chunks_every_file_once_on_both_workers(tmp_path, cluster, monkeypatch):
    """60 boxes in chunks (a tiny target so that the batch is not short: chunks of the target, then a tail):
    every file exactly once, chunks of more than one file, both workers used, the numbers right."""
    import inertia_tool.batch.chunks as chunks_mod

    files = _scaled_boxes(tmp_path / "boxes", 60)
    sizes = []
    real_submit = chunks_mod.DaskTasks.submit
    monkeypatch.setattr(chunks_mod.DaskTasks, "submit",
                        lambda self, fn, chunk, *a: (sizes.append(len(chunk)), real_submit(self, fn, chunk, *a)))
    rows = []
    summary = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1000.0), rows.append,
                        client=cluster.client, chunk_seconds=0.002)
    assert summary.ok == 60 and sorted(r["path"] for r in rows) == files
    assert sum(sizes) == 60 and max(sizes) > 1 and len(sizes) > 4
    assert len({r["worker"] for r in rows}) == 2
    from inertia_tool._native import THREADS_ENV
    from inertia_tool.batch.runner import kernel_threads_per_worker
    seen = cluster.client.run(lambda: os.environ.get(THREADS_ENV))           # evaluated on each worker
    assert set(seen.values()) == {str(kernel_threads_per_worker(2))}
    for r in rows:
        side = (1 + int(os.path.basename(r["path"])[1:3])) * 1e-3
        assert r["mass"] == pytest.approx(1000.0 * side ** 3, rel=1e-9)


def test_connect_refuses_an_address_without_a_scheduler():
    from inertia_tool.batch.cluster import connect_dask
    from inertia_tool.errors import UsageError

    with pytest.raises(UsageError, match="Cannot connect to a Dask scheduler at tcp://127.0.0.1:9"):
        connect_dask("tcp://127.0.0.1:9", timeout=1.0)


@pytest.mark.slow
def test_local_cluster_workers_run_without_the_profiler(cluster):
    import dask

    seen = cluster.client.run(lambda: dask.config.get("distributed.worker.profile.enabled"))
    assert set(seen.values()) == {False}
    seen = cluster.client.run(lambda: dask.config.get("distributed.worker.memory.monitor-interval"))
    assert set(seen.values()) == {"1s"}                                      # not every 100 ms
    assert dask.config.get("distributed.worker.profile.enabled") is True       # this process's config untouched


@pytest.mark.slow
def test_local_cluster_workers_keep_glibc_adaptive_malloc(cluster):
    """Dask's nanny would set MALLOC_TRIM_THRESHOLD_=65536 in its workers, which freezes glibc's mmap threshold
    at 128 kB (every larger array a fresh mmap: 28x the page faults on small parts); our LocalCluster unsets it
    unless the user's own environment has it."""
    if "MALLOC_TRIM_THRESHOLD_" in os.environ:
        pytest.skip("MALLOC_TRIM_THRESHOLD_ is set in this environment (the workers inherit it, as they should)")
    seen = cluster.client.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_"))
    assert set(seen.values()) == {None}
    import dask

    assert dask.config.get("distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_") == 65536  # ours untouched


@pytest.mark.slow
def test_dask_chunks_queued_together_reach_the_scheduler_in_one_map(tmp_path, cluster, monkeypatch):
    """The chunks submitted before a wait go to the scheduler as one Client.map (one graph update); every chunk's
    rows come back unpickled from run_packed's bytes.  A short batch (30 boxes) is the first round: one chunk
    per worker of equal weight (two before batch5: each task costs the cluster ~5 ms of CPU), all in the first
    map (the sizer probed 1, 2, 4, 8 files before)."""
    files = _scaled_boxes(tmp_path / "boxes", 30)
    calls = []
    real_map = cluster.client.map
    monkeypatch.setattr(cluster.client, "map", lambda fn, *cols, **kw: (calls.append([len(c) for c in cols[1]]),
                                                                        real_map(fn, *cols, **kw))[1])
    rows = []
    summary = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=1000.0), rows.append,
                        client=cluster.client, chunk_seconds=0.01)
    assert summary.ok == 30 and sorted(r["path"] for r in rows) == files
    assert calls == [[15, 15]]                    # the whole short batch: two chunks (1 per worker) in one map
    assert all(isinstance(r, dict) and r["status"] == "ok" for r in rows)
