"""Handing files to workers in chunks sized by their expected CPU time, and taking results back as they come.

One task per file makes the per-task cost of the executor the bottleneck on small meshes (a process pool pays
~0.2 ms a task in pickling and pipes, a Dask LocalCluster 2-5 ms of CPU), so
:func:`~inertia_tool.batch.runner.run_batch` hands out *chunks*: lists of files analysed one after the other by
one worker, which returns their rows together.  :class:`ChunkSizer` decides which files go into the next chunk.

It sizes chunks by *weight*, a file's bytes plus :data:`FILE_OVERHEAD_BYTES` (the per-file cost of a small part,
in bytes of binary STL), times the CPU seconds per byte of weight: assumed (:data:`PRIOR_SECONDS_PER_BYTE`) until
a chunk comes back, then measured (the workers' CPU time, ``time.process_time``, not their wall time, which the
load of a shared machine inflates: sized by wall time, a loaded machine shrank the last chunks to single files).

- A *short* batch, whose expected work is at most a round of chunks of the target size (two per worker), is
  split at once into chunks of equal weight, two per worker on a process pool (4 tasks for 200 parts on 2
  workers, where probing (1, 2, 4, 8 files) and a shrinking tail made 22) and one per worker on Dask
  (:data:`DASK_SHORT_CHUNKS_PER_WORKER`: each task costs the cluster milliseconds of CPU).
- A longer batch gets chunks of ``target_seconds`` of expected work, and, once what is left is less than a round
  of them, chunks of half a fair share of what is left (so the last chunks spread over every worker), but not
  below ``tail_seconds`` (each chunk costs a round trip of the executor).

:class:`PoolTasks` (any ``concurrent.futures`` executor, by default a process pool of this machine) and
:class:`DaskTasks` (a ``dask.distributed`` client: a LocalCluster or a remote scheduler, the same code) give the
runner one interface: :meth:`submit` a chunk, :meth:`wait` for the next finished ones in order of completion.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
import pickle
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

__all__ = ["ChunkSizer", "PoolTasks", "DaskTasks", "Finished", "POOL_CHUNK_SECONDS", "DASK_CHUNK_SECONDS",
           "POOL_TAIL_SECONDS", "DASK_TAIL_SECONDS", "FILE_OVERHEAD_BYTES", "PRIOR_SECONDS_PER_BYTE",
           "POOL_SHORT_CHUNKS_PER_WORKER", "DASK_SHORT_CHUNKS_PER_WORKER",
           "file_weights", "run_packed"]

#: Seconds of work aimed at per chunk on a local process pool (a killed run loses at most this much work per
#: worker).  Each chunk costs the batch's process ~0.2-0.5 ms (pickling, pipes, its threads' wake-ups) and the
#: batch's process shares the cores with the workers: on 2,000 small parts on ``--jobs 2`` (2026-11-26, load
#: average 22, two alternating runs each) 0.05 s gave 0.085-0.090 ms of CPU per file in the batch's process,
#: 0.2 s 0.060-0.070 (the rows written are the same; the last chunks still shrink, :class:`ChunkSizer`).
POOL_CHUNK_SECONDS = 0.2

#: Seconds of work aimed at per chunk on Dask (the scheduler and its round trip cost a few ms a task).
DASK_CHUNK_SECONDS = 0.5

#: Least work of a chunk near the end of a batch on a process pool, s (a task's round trip is ~0.2-0.6 ms; the
#: last chunks spread over every worker, down to this).
POOL_TAIL_SECONDS = 0.005

#: Least work of a chunk near the end of a batch on Dask, s: above the ~8 ms from ``Client.map`` to a task
#: starting, so that with two chunks in flight per worker the round trip stays hidden behind the running chunk.
DASK_TAIL_SECONDS = 0.02

#: Chunks per worker of a short batch on a process pool: the second lets the pool even out a worker slowed by
#: the load (its task costs ~0.2 ms).
POOL_SHORT_CHUNKS_PER_WORKER = 2

#: Chunks per worker of a short batch on Dask: one.  Each task costs the LocalCluster ~5 ms of CPU in the
#: batch's process (scheduler, client, nannies) and some in the worker; on 200 small parts (~0.35 s of work) on
#: 2 workers, one chunk each instead of two took the batch's process from 31-49 to 20-26 ms and the workers from
#: 356-429 to 339-373 ms of CPU (four paired runs, load average 29), wall 1.56-1.82 -> 1.44-1.57 s.  What it
#: gives up, evening out the two workers, is bounded by the short batch's size (at most the target per worker).
DASK_SHORT_CHUNKS_PER_WORKER = 1

#: What a file costs beyond its bytes, counted in bytes (a file's weight is its size plus this): on the small
#: catalogue of ``benchmarks/bench_batch.py`` a 12-triangle box (684 bytes) takes ~0.7 ms of CPU and the average
#: part (56 kB) ~1.6 ms, about 20 ns per byte of size plus this.
FILE_OVERHEAD_BYTES = 32_768

#: CPU seconds per byte of weight assumed before any chunk has been measured (see :data:`FILE_OVERHEAD_BYTES`;
#: 2026-11-26, the project's 2-core machine).  A wrong prior only misjudges the first chunks: 10x too low makes
#: them 10x the target, never unbounded (:attr:`ChunkSizer.max_files`).
PRIOR_SECONDS_PER_BYTE = 2e-8

#: A finished chunk: ``(chunk, result, None)`` or ``(chunk, None, exception)`` when the task itself failed (its
#: worker died, the cluster lost it); a chunk is a list of ``(path, sha256 or None)``.
Finished = tuple[list, Any, "BaseException | None"]


def file_weights(paths: Sequence[str], overhead: int = FILE_OVERHEAD_BYTES) -> np.ndarray:
    """(n,) float: each file's size in bytes (``os.stat``, which never opens it: a FIFO does not hang) plus
    ``overhead``; a file that cannot be stat'ed weighs ``overhead`` (its worker writes the error row)."""
    out = np.full(len(paths), float(overhead))
    for k, path in enumerate(paths):
        try:
            out[k] += os.stat(path).st_size
        except (OSError, ValueError):
            pass
    return out


class ChunkSizer:
    """Which files go into the next chunk: contiguous runs of files of about the same expected CPU time.

    Parameters
    ----------
    weights : (n,) array_like of float
        The weight of each file of the batch, in order (:func:`file_weights`), all >= 0.
    target_seconds : float
        CPU time aimed at per chunk, s.
    max_files : int
        Upper bound of a chunk (bounds memory and the work a killed run loses).
    tail_seconds : float, optional
        Least CPU time of a chunk at the end of a long batch, s (default a tenth of ``target_seconds``).
    prior_seconds_per_byte : float
        CPU seconds per byte of weight until the first chunk is measured.
    short_chunks_per_worker : int
        Chunks per worker of a short batch (:data:`POOL_SHORT_CHUNKS_PER_WORKER`,
        :data:`DASK_SHORT_CHUNKS_PER_WORKER`).

    Notes
    -----
    The CPU seconds per byte are an exponential moving average (weight ``1/2``) of each finished chunk's, so a
    catalogue sorted from one kind of part to another adapts within a few chunks.  Expected CPU time of a run of
    files is its weight times that rate.  A batch is *short* when its expected work is at most
    ``2 * workers * target_seconds``: its files are split into ``short_chunks_per_worker * workers`` chunks of
    equal weight (the first round hands out all of them); the split is fixed at the first call.
    """

    def __init__(self, weights: Sequence[float] | np.ndarray, target_seconds: float, *, max_files: int = 1000,
                 tail_seconds: float | None = None, prior_seconds_per_byte: float = PRIOR_SECONDS_PER_BYTE,
                 short_chunks_per_worker: int = POOL_SHORT_CHUNKS_PER_WORKER):
        if not (target_seconds > 0 and math.isfinite(target_seconds)):
            raise ValueError(f"Expected `target_seconds` > 0, got {target_seconds}")
        if tail_seconds is None:
            tail_seconds = 0.1 * target_seconds
        if not (0 < tail_seconds <= target_seconds):
            raise ValueError(f"Expected 0 < `tail_seconds` <= `target_seconds` ({target_seconds}), got {tail_seconds}")
        if max_files < 1:
            raise ValueError(f"Expected `max_files` >= 1, got {max_files}")
        if not (prior_seconds_per_byte > 0 and math.isfinite(prior_seconds_per_byte)):
            raise ValueError(f"Expected `prior_seconds_per_byte` > 0, got {prior_seconds_per_byte}")
        if not (isinstance(short_chunks_per_worker, int) and short_chunks_per_worker >= 1):
            raise ValueError(f"Expected an integer `short_chunks_per_worker` >= 1, got {short_chunks_per_worker!r}")
        w = np.asarray(weights, dtype=np.float64).reshape(-1)
        if not (np.isfinite(w).all() and (w >= 0).all()):
            raise ValueError("Expected finite weights >= 0")
        self.target_seconds = float(target_seconds)
        self.max_files = int(max_files)
        self.tail_seconds = float(tail_seconds)
        self.prior_seconds_per_byte = float(prior_seconds_per_byte)
        self.short_chunks_per_worker = short_chunks_per_worker
        self.seconds_per_byte: float | None = None
        self._cumulative = np.concatenate(([0.0], np.cumsum(w)))
        self._short_weight: float | None = None       # the fixed chunk weight of a short batch, once decided
        self._short_start = 0.0                        # the cumulative weight where the short batch's chunks start
        self._decided = False

    @property
    def files(self) -> int:
        """Files of the batch."""
        return len(self._cumulative) - 1

    def observe(self, weight: float, seconds: float) -> None:
        """Record a finished chunk of total ``weight`` that took ``seconds`` of CPU time."""
        if not (weight > 0 and math.isfinite(weight) and math.isfinite(seconds) and seconds >= 0):
            return
        rate = seconds / weight
        self.seconds_per_byte = rate if self.seconds_per_byte is None else 0.5 * (self.seconds_per_byte + rate)

    def weight(self, start: int, stop: int) -> float:
        """Total weight of files ``start .. stop - 1``."""
        return float(self._cumulative[stop] - self._cumulative[start])

    def _chunk_weight(self, position: int, workers: int) -> float:
        rate = max(self.seconds_per_byte if self.seconds_per_byte is not None else self.prior_seconds_per_byte,
                   1e-300)
        left = self.weight(position, self.files)
        round_of_chunks = 2 * max(workers, 1)
        if not self._decided:
            self._decided = True
            if left * rate <= round_of_chunks * self.target_seconds:
                self._short_weight = left / (self.short_chunks_per_worker * max(workers, 1))
                self._short_start = self.weight(0, position)
        if self._short_weight is not None:
            # boundaries at fixed multiples of the chunk weight (not relative to each chunk's start, where the
            # rounding to whole files could drift into one more chunk)
            done = (self.weight(0, position) - self._short_start) / self._short_weight if self._short_weight else 0.0
            return self._short_start + (math.floor(done + 0.5) + 1) * self._short_weight - self.weight(0, position)
        # a long batch: the target, then half a fair share of what is left, not below the tail floor
        return min(self.target_seconds / rate, max(left / round_of_chunks, self.tail_seconds / rate))

    def next_size(self, position: int, workers: int) -> int:
        """Files for the next chunk, which starts at file ``position`` of the batch, given ``workers`` workers:
        the run whose weight is nearest the chunk weight, at least 1 and at most :attr:`max_files`."""
        remaining = self.files - position
        if remaining <= 0:
            return 0
        start = self._cumulative[position]
        goal = start + self._chunk_weight(position, workers)
        end = int(np.searchsorted(self._cumulative, goal, side="left"))     # first boundary at or past the goal
        end = min(end, self.files)
        if end > position + 1 and self._cumulative[end] - goal > goal - self._cumulative[end - 1]:
            end -= 1                                                            # the nearer boundary
        return max(1, min(end - position, remaining, self.max_files))


class PoolTasks:
    """Chunks on a ``concurrent.futures`` executor.

    Parameters
    ----------
    make_pool : callable() -> Executor, optional
        Creates the pool this object owns (and re-creates after a worker died hard, which breaks a
        ``ProcessPoolExecutor``); shut down by :meth:`close`.
    executor : Executor, optional
        A pool owned by the caller instead (not restarted, not shut down).
    workers : int
        Number of workers (sizes the chunks and the tasks in flight).
    """

    def __init__(self, *, make_pool: Callable[[], cf.Executor] | None = None, executor: cf.Executor | None = None,
                 workers: int = 1):
        if executor is not None and make_pool is None:
            pool = executor
        elif make_pool is not None and executor is None:
            pool = make_pool()
        else:
            raise ValueError("Expected exactly one of `make_pool` and `executor`")
        self._make_pool = make_pool
        self._pool: cf.Executor = pool
        self._pending: dict[cf.Future, list] = {}
        self.workers = workers

    def submit(self, fn: Callable, chunk: list, *args: Any) -> None:
        """Start ``fn(chunk, *args)``."""
        try:
            fut = self._pool.submit(fn, chunk, *args)
        except cf.process.BrokenProcessPool:
            if self._make_pool is None:
                raise
            # a worker died hard (e.g. killed for memory): start a fresh pool and go on
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = self._make_pool()
            fut = self._pool.submit(fn, chunk, *args)
        self._pending[fut] = chunk

    def in_flight(self) -> int:
        """Chunks submitted and not yet returned by :meth:`wait`."""
        return len(self._pending)

    def wait(self) -> list[Finished]:
        """Block until at least one chunk has finished; the finished ones, in order of completion."""
        done, _ = cf.wait(list(self._pending), return_when=cf.FIRST_COMPLETED)
        out: list[Finished] = []
        for fut in done:
            chunk = self._pending.pop(fut)
            try:
                out.append((chunk, fut.result(), None))
            except Exception as exc:  # noqa: BLE001 - a dead worker fails its chunk, not the batch
                out.append((chunk, None, exc))
        return out

    def close(self) -> None:
        """Shut down the pool if this object made it (cancelling what has not started)."""
        if self._make_pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)


def run_packed(fn: Callable, chunk: list, *args: Any) -> bytes:
    """``fn(chunk, *args)`` pickled into one ``bytes``: the task :class:`DaskTasks` submits.

    A Dask worker measures (``sizeof``) and serialises a returned list of dicts item by item, on the worker and
    again where the scheduler forwards it; one ``bytes`` object costs it nothing.  On the project's 2-core
    machine this took 0.1-0.15 s of CPU off a batch of 2,000 small parts (about 5 % of the work), in four of four
    paired runs.
    """
    return pickle.dumps(fn(chunk, *args), protocol=pickle.HIGHEST_PROTOCOL)


class DaskTasks:
    """Chunks on a Dask cluster through a ``dask.distributed.Client`` (a LocalCluster's or a remote one's).

    Each chunk runs as :func:`run_packed` (its result comes back as one pickled ``bytes``, unpickled here).
    Chunks submitted between two :meth:`wait` calls reach the scheduler together, in one ``Client.map`` (one
    graph update instead of one per chunk).  Results come back through ``distributed.as_completed`` in order of
    completion, fetched in the background.
    The number of workers is asked of the scheduler at most once a second, so that workers joining or leaving
    a running cluster change the chunks in flight.
    """

    def __init__(self, client: Any):
        from distributed import as_completed

        self.client = client
        self._done = as_completed(with_results=True, raise_errors=False)
        self._pending: dict[Any, list] = {}
        self._queued: list[tuple[Callable, list, tuple]] = []
        self._asked = -math.inf
        self._workers = 1

    @property
    def workers(self) -> int:
        """Worker threads of the cluster (at least 1; re-read at most once a second)."""
        import time

        now = time.monotonic()
        if now - self._asked >= 1.0:
            self._asked = now
            try:
                self._workers = max(1, sum(self.client.nthreads().values()))
            except Exception:  # noqa: BLE001 - keep the last known count if the scheduler is slow to answer
                pass
        return self._workers

    def submit(self, fn: Callable, chunk: list, *args: Any) -> None:
        """Queue ``fn(chunk, *args)`` for some worker; it is sent with the others queued at the next :meth:`wait`
        (``pure=False``: never deduplicated)."""
        self._queued.append((fn, chunk, args))

    def _send(self) -> None:
        """Send the queued chunks to the scheduler in one ``Client.map``."""
        if not self._queued:
            return
        queued, self._queued = self._queued, []
        columns = [list(c) for c in zip(*((fn, chunk, *args) for fn, chunk, args in queued))]
        futures = self.client.map(run_packed, *columns, pure=False)
        for fut, (_, chunk, _) in zip(futures, queued):
            self._pending[fut] = chunk
            self._done.add(fut)

    def in_flight(self) -> int:
        """Chunks submitted and not yet returned by :meth:`wait`."""
        return len(self._pending) + len(self._queued)

    def wait(self) -> list[Finished]:
        """Send what is queued, block until at least one chunk has finished; the finished ones, in order of
        completion."""
        self._send()
        out: list[Finished] = []
        for fut, result in self._done.next_batch(block=True):
            chunk = self._pending.pop(fut)
            if fut.status == "finished":
                out.append((chunk, pickle.loads(result), None))        # our own task's bytes (run_packed)
            else:                                # "error": (type, exception, traceback); "cancelled": the error
                exc = result[1] if isinstance(result, tuple) and len(result) == 3 else result
                out.append((chunk, None, exc if isinstance(exc, BaseException) else RuntimeError(str(exc))))
        return out

    def close(self) -> None:
        """Cancel what is still pending (the client and cluster belong to the caller)."""
        self._queued.clear()
        if self._pending:
            self.client.cancel(list(self._pending))
            self._pending.clear()
