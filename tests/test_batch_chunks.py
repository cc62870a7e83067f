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
from inertia_tool.batch.chunks import ChunkSizer, file_weights
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

def _drive(sizer, workers, seconds_of):
    """Hand out every file as run_batch does, telling the sizer each chunk's CPU time ``seconds_of(start, stop)``
    at once; the chunk sizes."""
    sizes, position = [], 0
    for _ in range(sizer.files + 1):
        size = sizer.next_size(position, workers)
        if size == 0:
            break
        sizes.append(size)
        sizer.observe(sizer.weight(position, position + size), seconds_of(position, position + size))
        position += size
    assert position == sizer.files
    return sizes


def test_short_batch_is_split_into_two_equal_chunks_per_worker():
    """200 equal parts whose expected work (200 x 1 ms) is under a round of 0.5 s chunks: 4 chunks of 50 on 2
    workers (the old sizer probed 1, 2, 4, 8 files and then shrank the tail: 22 tasks on a loaded machine)."""
    s = ChunkSizer([50_000.0] * 200, 0.5, tail_seconds=0.02, prior_seconds_per_byte=2e-8)
    assert _drive(s, 2, lambda a, b: (b - a) * 1e-3) == [50, 50, 50, 50]
    s = ChunkSizer([50_000.0] * 30, 0.5, prior_seconds_per_byte=2e-8)
    sizes = _drive(s, 4, lambda a, b: (b - a) * 1e-3)
    assert len(sizes) == 8 and set(sizes) == {3, 4}                    # 30 / 8: 8 chunks, no 9th of rounding
    # unequal files: equal weight per chunk (100 light files and 24 heavy ones, then 25-26 heavy), not equal counts
    s = ChunkSizer([1_000.0] * 100 + [99_000.0] * 100, 1.0, prior_seconds_per_byte=2e-8)
    assert _drive(s, 2, lambda a, b: 0.0) == [124, 25, 26, 25]        # boundaries nearest 2.5, 5, 7.5 MB


def test_long_batch_follows_the_measured_cpu_time_then_spreads_the_tail():
    s = ChunkSizer([10_000.0] * 100_000, 0.5, max_files=10_000, tail_seconds=0.02, prior_seconds_per_byte=1e-8)
    assert s.next_size(0, 2) == 5_000                                  # 0.5 s / (10 kB x 10 ns): the prior
    s.observe(s.weight(0, 5_000), 5_000 * 1e-3)                        # measured: 1 ms a file (100 ns a byte)
    assert s.next_size(5_000, 2) == 500                                # replaces the prior: 0.5 s of 1 ms files
    s.observe(s.weight(0, 100), 100 * 3e-3)                            # 3 ms a file: the average, 2 ms
    assert s.next_size(10_000, 2) == 250
    s.observe(s.weight(0, 100), 100 * 1e-3)                            # back to 1.5 ms
    s.observe(s.weight(0, 100), 100 * 1e-3)                            # 1.25 ms
    assert s.next_size(90_000, 2) == 400
    assert s.next_size(99_000, 2) == 250                               # half a fair share of 1,000 over 2 workers
    assert s.next_size(99_900, 2) == 25                                # ... of 100
    assert s.next_size(99_950, 2) == 16                                # share 12.5 < floor 0.02 s / 1.25 ms = 16
    assert s.next_size(99_990, 2) == 10                                # never more than what is left
    assert s.next_size(100_000, 2) == 0


def test_sizer_settings_are_checked():
    for bad in (dict(tail_seconds=0.6), dict(tail_seconds=0.0), dict(max_files=0), dict(prior_seconds_per_byte=0.0)):
        with pytest.raises(ValueError):
            ChunkSizer([1.0], 0.5, **bad)
    with pytest.raises(ValueError):
        ChunkSizer([1.0], 0.0)
    with pytest.raises(ValueError):
        ChunkSizer([1.0, -1.0], 0.5)


def test_file_weights_are_sizes_plus_the_overhead_and_never_open_a_fifo(tmp_path):
    (tmp_path / "a").write_bytes(b"x" * 100)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    w = file_weights([str(tmp_path / "a"), str(tmp_path / "missing"), str(fifo)], overhead=1000)
    assert w.tolist() == [1100.0, 1000.0, 1000.0]


def _makespan(weights, seconds_per_byte: float, workers: int, sizer: ChunkSizer) -> tuple[float, int]:
    """When the last file is done and how many chunks it took, on ``workers`` workers fed as ``_run_chunks``
    feeds a Dask cluster (two chunks in flight per worker, the next queued chunk going to the first idle worker,
    the sizer told of each chunk's CPU time as it comes back), with no round-trip time: a model of where the end
    of a batch waits."""
    import heapq

    queue, running, done_at = [], [], 0.0            # running: heap of (finish time, start, stop)
    position = chunks = 0
    idle = [0.0] * workers                           # when each worker is free
    now = 0.0
    n = len(weights)
    for _ in range(4 * n + 4):
        while len(queue) + len(running) < 2 * workers and position < n:
            size = sizer.next_size(position, workers)
            queue.append((position, position + size))
            position += size
            chunks += 1
        while queue and min(idle) <= now:             # idle workers take the queued chunks, in order
            k = idle.index(min(idle))
            a, b = queue.pop(0)
            idle[k] = now + sizer.weight(a, b) * seconds_per_byte
            heapq.heappush(running, (idle[k], a, b))
        if not running:
            return done_at, chunks
        now, a, b = heapq.heappop(running)
        done_at = max(done_at, now)
        sizer.observe(sizer.weight(a, b), sizer.weight(a, b) * seconds_per_byte)
    raise AssertionError("the model did not finish")


@settings(max_examples=40, deadline=None)
@given(files=st.integers(1, 3000), per_file=st.sampled_from([0.0005, 0.0015, 0.004, 0.03]),
       spread=st.floats(0.0, 3.0), seed=st.integers(0, 2**16), prior=st.sampled_from([0.1, 1.0, 10.0]))
def test_dask_chunks_bound_the_last_wait_and_the_tasks(files, per_file, spread, seed, prior):
    """Files of random sizes on two workers, in the model of ``_makespan``, with a prior off by 10x either way:
    the end of the batch waits (beyond the ideal half of the work) at most the larger of a short batch's chunk
    and the tail floor, plus one file; and a short batch takes 4 chunks, plus one for each file heavier than a
    chunk (a chunk holds at least one file)."""
    from inertia_tool.batch.chunks import DASK_CHUNK_SECONDS, DASK_TAIL_SECONDS

    rng = np.random.default_rng(seed)
    weights = 33_000.0 * np.exp(spread * rng.standard_normal(files))
    rate = per_file / 33_000.0
    sizer = ChunkSizer(weights, DASK_CHUNK_SECONDS, tail_seconds=DASK_TAIL_SECONDS,
                       prior_seconds_per_byte=rate * prior)
    total = float(weights.sum()) * rate
    makespan, chunks = _makespan(weights, rate, 2, sizer)
    largest = float(weights.max()) * rate
    short = total * prior <= 4 * DASK_CHUNK_SECONDS
    assert makespan >= total / 2 - 1e-9
    if short:
        heavy = int(np.count_nonzero(weights > weights.sum() / 4))
        assert chunks <= min(4 + heavy, files) and makespan - total / 2 <= total / 4 + 2 * largest + 1e-9
    else:
        assert makespan - total / 2 <= max(DASK_TAIL_SECONDS, DASK_CHUNK_SECONDS / prior) + 2 * largest + 1e-9


def test_sizer_bounds():
    s = ChunkSizer([1.0] * 10**6, 1.0, max_files=7)
    assert s.next_size(0, 1) == 7
    s2 = ChunkSizer([1.0] * 100, 0.05, prior_seconds_per_byte=3.0)     # a file longer than the target
    assert s2.next_size(0, 2) == 1


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 3000), workers=st.integers(1, 8),
       times=st.lists(st.floats(1e-9, 2e-6), min_size=1, max_size=50),
       sizes=st.lists(st.floats(0.0, 1e7), min_size=1, max_size=50))
def test_sizer_hands_out_every_file_once(n, workers, times, sizes):
    """Driving the sizer as run_batch does hands out exactly n files, each chunk non-empty, in a bounded number
    of chunks, whatever the weights (zero ones too) and the measured times."""
    weights = [sizes[k % len(sizes)] for k in range(n)]
    s = ChunkSizer(weights, 0.05)
    position = chunks = 0
    while position < n:
        size = s.next_size(position, workers)
        assert 1 <= size <= n - position
        s.observe(s.weight(position, position + size), s.weight(position, position + size) * times[chunks % len(times)])
        position += size
        chunks += 1
        assert chunks <= n
    assert position == n and s.next_size(n, workers) == 0


def test_chunks_are_measured_in_cpu_time_not_wall_time(many, monkeypatch):
    """Regression (issue 25 item 6): the sizer was fed the rows' wall time, which a loaded machine inflates, so
    the last chunks of a Dask run shrank to single files (22 tasks for 200 parts). A chunk's task now returns the
    worker's CPU time: here 0.15 s of sleeping (no CPU) is not counted."""
    import time

    real = batch_mod._analyze
    monkeypatch.setattr(batch_mod, "_analyze", lambda *args: (time.sleep(0.05), real(*args))[1])
    start = time.perf_counter()
    rows, cpu = batch_mod._analyze_chunk_timed([(p, None) for p in many[:3]], OPTIONS)
    wall = time.perf_counter() - start
    assert [r["status"] for r in rows] == ["ok"] * 3 and wall >= 0.15
    assert 0 < cpu < wall - 0.1


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

    # 40 equal boxes, a short batch on 2 workers: 4 chunks of 10, the slow file in the first
    def write(row):
        order.append(row["path"])
        if len(order) == len(many) - 10:               # every other chunk is written: let the slow file finish
            release.set()

    with cf.ThreadPoolExecutor(2) as pool:
        run_batch(many, OPTIONS, write, jobs=2, executor=pool, chunk_seconds=100.0)
    assert order[-10] == slow and sorted(order[-10:]) == many[:10] and sorted(order) == many


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
