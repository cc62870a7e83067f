"""Chunked batches (inertia_tool.batch.chunks and the chunk loop of run_batch): every file exactly once, chunks
sized from the measured time, whole-chunk failures split, rows streamed in order of completion, the fsync
policy of the results file, and a run killed in the middle of a chunk resumed."""

import concurrent.futures as cf
import multiprocessing
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import kill_after_lines, write_binary_stl
from inertia_tool.batch import rows as rows_mod
from inertia_tool.batch import runner as batch_mod
from inertia_tool.batch.chunks import ChunkSizer
from inertia_tool.batch.rows import open_results
from inertia_tool.batch.runner import BatchOptions, analyze_chunk, discover_files, file_sha256, run_batch
from inertia_tool.mesh import LoadOptions

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OPTIONS = BatchOptions(load=LoadOptions(units="mm"), density=1000.0)


@pytest.fixture(scope="module")
def many(tmp_path_factory):
    """40 boxes of different sizes (mm): the mass of each is known in closed form."""
    d = tmp_path_factory.mktemp("many")
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    for k in range(40):
        write_binary_stl(d / f"b{k:02d}.stl", np.asarray(box.vertices) * (1 + k), box.faces)
    return discover_files(d)


def _mass(path):
    side = (1 + int(os.path.basename(path)[1:3])) * 1e-3
    return 1000.0 * side ** 3


# -- the sizer -------------------------------------------------------------------------------------------

def test_sizer_starts_with_one_file_then_follows_the_measured_time():
    s = ChunkSizer(0.5)
    assert s.next_size(1000, 2) == 1                      # nothing measured yet
    s.observe(1, 0.001)                                   # 1 ms a file: 500 files wanted ...
    assert s.next_size(1000, 2) == 4                      # ... but at most 4x the largest chunk so far
    assert [s.next_size(10_000, 2) for _ in range(4)] == [16, 64, 256, 500]
    s.observe(100, 1.0)                                   # now 10 ms a file on average with the 1 ms: 5.5 ms
    assert s.next_size(10_000, 2) == int(0.5 / (0.5 * (0.001 + 0.01)))


def test_sizer_tail_spreads_the_last_files_but_keeps_a_tenth_of_the_target():
    s = ChunkSizer(0.5, max_files=10_000)
    s.observe(10, 0.01)
    s.largest = 10_000
    assert s.next_size(400, 2) == 100                     # half a fair share of 400 over 2 workers
    assert s.next_size(120, 2) == 50                      # share 30 < floor 0.05 s / 1 ms = 50
    assert s.next_size(20, 2) == 20                       # never more than what is left
    assert s.next_size(0, 2) == 0


def test_sizer_tail_floor_is_its_own_setting():
    s = ChunkSizer(0.5, max_files=10_000, tail_seconds=0.02)             # Dask's target and tail floor
    s.observe(10, 0.01)
    s.largest = 10_000
    assert s.next_size(120, 2) == 30                      # half a fair share: 30 > floor 0.02 s / 1 ms = 20
    assert s.next_size(40, 2) == 20                       # share 10 < floor 20
    with pytest.raises(ValueError):
        ChunkSizer(0.5, tail_seconds=0.6)
    with pytest.raises(ValueError):
        ChunkSizer(0.5, tail_seconds=0.0)


def _makespan(files: int, seconds_per_file: float, workers: int, sizer: ChunkSizer) -> float:
    """When the last of ``files`` equal files is done, on ``workers`` workers fed as ``_run_chunks`` feeds a Dask
    cluster (two chunks in flight per worker, the next queued chunk going to the first idle worker, the sizer
    told of each chunk as it comes back), with no round-trip time: a model of where the end of a batch waits."""
    import heapq

    queue, running, done_at = [], [], 0.0            # running: heap of (finish time, files)
    handed = 0
    idle = [0.0] * workers                           # when each worker is free
    now = 0.0
    for _ in range(4 * files + 4):
        while len(queue) + len(running) < 2 * workers and handed < files:
            size = sizer.next_size(files - handed, workers)
            queue.append(size)
            handed += size
        while queue and min(idle) <= now:             # idle workers take the queued chunks, in order
            k = idle.index(min(idle))
            size = queue.pop(0)
            idle[k] = now + size * seconds_per_file
            heapq.heappush(running, (idle[k], size))
        if not running:
            return done_at
        now, size = heapq.heappop(running)
        done_at = max(done_at, now)
        sizer.observe(size, size * seconds_per_file)
    raise AssertionError("the model did not finish")


def test_dask_tail_floor_bounds_the_last_wait():
    """Equal files on two workers, in the model of ``_makespan``: the end of the batch waits (beyond the ideal
    half of the work) at most the tail floor and one file, over a sweep of batch sizes and times per file; with
    the floor of before (a tenth of the 0.5 s target) the bound was 0.05 s, and the waits summed over the sweep
    are no shorter."""
    from inertia_tool.batch.chunks import DASK_CHUNK_SECONDS, DASK_TAIL_SECONDS

    new_total = old_total = 0.0
    for files in (200, 333, 500, 1000, 2000):
        for per_file in (0.0005, 0.0015, 0.004):
            ideal = files * per_file / 2
            new = _makespan(files, per_file, 2, ChunkSizer(DASK_CHUNK_SECONDS, tail_seconds=DASK_TAIL_SECONDS))
            old = _makespan(files, per_file, 2, ChunkSizer(DASK_CHUNK_SECONDS))
            assert -1e-12 <= new - ideal <= DASK_TAIL_SECONDS + per_file, (files, per_file)
            new_total += new - ideal
            old_total += old - ideal
    assert new_total <= old_total


def test_sizer_bounds():
    s = ChunkSizer(1.0, max_files=7)
    s.observe(1, 1e-6)
    s.largest = 100
    assert s.next_size(10**6, 1) == 7
    s2 = ChunkSizer(0.05)
    s2.observe(1, 3.0)                                    # a file longer than the target: one file a chunk
    assert s2.next_size(100, 2) == 1
    with pytest.raises(ValueError):
        ChunkSizer(0.0)


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 3000), workers=st.integers(1, 8),
       times=st.lists(st.floats(1e-5, 2.0), min_size=1, max_size=50))
def test_sizer_hands_out_every_file_once(n, workers, times):
    """Driving the sizer as run_batch does hands out exactly n files, each chunk non-empty, in a bounded number
    of chunks."""
    s = ChunkSizer(0.05)
    position = chunks = 0
    while position < n:
        size = s.next_size(n - position, workers)
        assert 1 <= size <= n - position
        position += size
        s.observe(size, size * times[chunks % len(times)])
        chunks += 1
        assert chunks <= n
    assert position == n and s.next_size(0, workers) == 0


# -- the chunk loop ----------------------------------------------------------------------------------------

def test_analyze_chunk_rows_in_chunk_order_with_hashes(many):
    chunk = [(p, None) for p in many[:5]]
    rows = analyze_chunk(chunk, OPTIONS)
    assert [r["path"] for r in rows] == many[:5]
    assert [r["sha256"] for r in rows] == [file_sha256(p) for p in many[:5]]      # hashed in the worker
    assert len({r["worker"] for r in rows}) == 1 and len({r["options_key"] for r in rows}) == 1
    assert rows[3]["mass"] == pytest.approx(_mass(many[3]), rel=1e-9)


@pytest.mark.parametrize("chunk_seconds", [1e-9, 0.05, 100.0])
def test_process_pool_chunks_give_every_file_exactly_once(many, chunk_seconds):
    got = []
    summary = run_batch(many, OPTIONS, got.append, jobs=2, chunk_seconds=chunk_seconds)
    assert summary.ok == len(many) and summary.failed == 0
    assert sorted(r["path"] for r in got) == many                     # each once, none lost, none twice
    assert summary.total_mass == pytest.approx(sum(map(_mass, many)), rel=1e-9)
    for r in got:
        assert r["mass"] == pytest.approx(_mass(r["path"]), rel=1e-9)
        assert r["sha256"] == file_sha256(r["path"])


class _FailingChunks(cf.ThreadPoolExecutor):
    """Threads whose task fails as a whole (as when its worker process dies) when the chunk holds ``poison``."""

    def __init__(self, poison):
        super().__init__(max_workers=2)
        self.poison = poison
        self.sizes = []

    def submit(self, fn, chunk, *args):
        self.sizes.append(len(chunk))
        if any(path == self.poison for path, _ in chunk):
            fut = cf.Future()
            fut.set_exception(cf.process.BrokenProcessPool("worker died"))
            return fut
        return super().submit(fn, chunk, *args)


def test_a_chunk_that_fails_whole_is_split_and_only_the_bad_file_fails(many):
    poison = many[17]
    pool = _FailingChunks(poison)
    got = []
    with pool:
        summary = run_batch(many, OPTIONS, got.append, jobs=2, executor=pool, chunk_seconds=100.0)
    assert sorted(r["path"] for r in got) == many
    bad = [r for r in got if r["status"] != "ok"]
    assert [r["path"] for r in bad] == [poison] and bad[0]["status"] == "internal_error"
    assert bad[0]["error_type"] == "BrokenProcessPool" and bad[0]["sha256"] is None
    assert (summary.ok, summary.failed) == (len(many) - 1, 1)
    assert max(pool.sizes) > 1 and pool.sizes.count(1) >= 2      # chunks were used, the failed one split


def _before_analysing(monkeypatch, target, action):
    """Patch the per-file work so that ``action()`` runs before the file ``target`` is analysed (forked pool
    workers inherit the patch)."""
    real = batch_mod._analyze

    def patched(path, *args):
        if path == target:
            action()
        return real(path, *args)

    monkeypatch.setattr(batch_mod, "_analyze", patched)


@pytest.mark.skipif(multiprocessing.get_start_method() != "fork", reason="patches the worker through fork")
def test_a_worker_that_dies_hard_costs_only_its_file(many, monkeypatch):
    """A real dead worker (os._exit in the middle of a chunk) breaks the pool: run_batch restarts it, splits the
    chunks that were lost, and every file ends with exactly one row."""
    poison = many[9]
    _before_analysing(monkeypatch, poison, lambda: os._exit(13))
    got = []
    summary = run_batch(many, OPTIONS, got.append, jobs=2, chunk_seconds=100.0)
    assert sorted(r["path"] for r in got) == many
    by_path = {r["path"]: r for r in got}
    assert by_path[poison]["status"] == "internal_error"
    # the files running beside it when it broke the pool the second time (alone) may fail with it: at most
    # the other chunks in flight (two per worker)
    failed = [r for r in got if r["status"] != "ok"]
    assert all(r["status"] == "internal_error" and r["error_type"] == "BrokenProcessPool" for r in failed)
    assert summary.ok >= len(many) - 4


def test_rows_stream_back_in_order_of_completion(many, monkeypatch):
    """A slow chunk does not hold back the rows of the chunks that finish before it."""
    slow = many[0]
    release = threading.Event()
    _before_analysing(monkeypatch, slow, lambda: release.wait(30))
    order = []

    def write(row):
        order.append(row["path"])
        if len(order) == len(many) - 1:                # everything else is written: let the slow file finish
            release.set()

    with cf.ThreadPoolExecutor(2) as pool:
        run_batch(many, OPTIONS, write, jobs=2, executor=pool, chunk_seconds=100.0)
    assert order[-1] == slow and sorted(order) == many


# -- the results file: fsync at most once per sync_seconds, every row written at once -----------------------

def test_rows_are_written_at_once_and_fsynced_at_most_every_sync_seconds(tmp_path, monkeypatch, many):
    syncs = []
    real_fsync = os.fsync
    monkeypatch.setattr(rows_mod.os, "fsync", lambda fd: (syncs.append(fd), real_fsync(fd)))
    rows = analyze_chunk([(p, None) for p in many[:20]], OPTIONS)
    out = tmp_path / "r.jsonl"
    with open_results(out, sync_seconds=3600) as r:
        opened = len(syncs)
        for row in rows:
            r.write_row(row)
            # a kill -9 now keeps the row: it is in the file (the OS cache) without any fsync
            assert out.read_bytes().count(b"\n") == rows.index(row) + 1
        assert len(syncs) == opened
    assert len(syncs) == opened + 1                                        # on closing
    syncs.clear()
    with open_results(tmp_path / "every.jsonl", sync_seconds=0) as r:
        for row in rows:
            r.write_row(row)
    assert len(syncs) >= len(rows)
    with open_results(out) as r:
        assert [x["path"] for x in r.previous_rows] == many[:20]


# -- killed in the middle of a chunk ------------------------------------------------------------------------

_CHUNKED_SLOW_BATCH = """
import sys, time
import inertia_tool.batch.runner as b
real = b._analyze
def slow(*args):
    time.sleep(0.1)
    return real(*args)
b._analyze = slow
b.POOL_CHUNK_SECONDS = 2.0                     # ~20 files a chunk: a kill lands in the middle of one
from inertia_tool.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.slow
@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_run_killed_in_the_middle_of_a_chunk_resumes_every_file_once(many, tmp_path, suffix):
    script = tmp_path / "slow_batch.py"
    script.write_text(_CHUNKED_SLOW_BATCH)
    out = tmp_path / f"r.{suffix}"
    env = {**os.environ, "PYTHONPATH": ROOT}
    cmd = [sys.executable, str(script), "batch", *many, "--units", "mm", "--out", str(out), "-j", "2", "-q"]
    header = 1 if suffix == "csv" else 0
    kill_after_lines(cmd, out, header + 8, env=env, seconds=30.0)   # the first chunks (1, 2, 4, ... files)
    with open_results(out) as r:
        before = len(r.previous_rows)
    assert 8 <= before < len(many), f"killed after {before} rows: not in the middle of the batch"
    done = subprocess.run([sys.executable, "-m", "inertia_tool.cli", *cmd[2:]], env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert f"; {before} done before;" in done.stderr
    with open_results(out) as r:
        paths = [x["path"] for x in r.previous_rows]
    assert sorted(paths) == many                                  # every file exactly once


# -- the C kernels' threads in the workers ------------------------------------------------------------------

def _environment(name):
    return os.environ.get(name)


@pytest.mark.parametrize("user", [None, "3"])
def test_pool_workers_share_the_cores_between_their_kernels(monkeypatch, user):
    """N pool workers give their C kernels the cores divided by N (at least 1), unless the user set
    INERTIA_TOOL_THREADS, which wins."""
    from inertia_tool._native import THREADS_ENV, threads

    if user is None:
        monkeypatch.delenv(THREADS_ENV, raising=False)
        expected = str(max(1, threads() // 2))
    else:
        monkeypatch.setenv(THREADS_ENV, user)
        expected = user
    assert batch_mod.kernel_threads_per_worker(2) == int(expected)
    pool = batch_mod._process_pool(2)
    try:
        seen = {pool.submit(_environment, THREADS_ENV).result(timeout=60) for _ in range(4)}
    finally:
        pool.shutdown()
    assert seen == {expected}
