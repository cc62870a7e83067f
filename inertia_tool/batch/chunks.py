"""Handing files to workers in chunks sized from a measured per-file time, and taking results back as they come.

One task per file makes the per-task cost of the executor the bottleneck on small meshes (a process pool pays
~0.2 ms a task in pickling and pipes, a Dask scheduler a few ms), so :func:`~inertia_tool.batch.runner.run_batch`
hands out *chunks*: lists of files analysed one after the other by one worker, which returns their rows
together.  :class:`ChunkSizer` decides how many files go into the next chunk from the analysis time the workers
measured (the rows' ``seconds``): the first chunks hold 1, 2, 4, then 8 files (nothing is measured yet), later ones
hold ``target_seconds / seconds_per_file`` files, growing at most fourfold per chunk, and no more than half a
fair share of the files left (so that the last chunks spread over every worker) unless that is less than the
tail floor (:data:`POOL_TAIL_SECONDS`, :data:`DASK_TAIL_SECONDS`: a few of the executor's round trips).

:class:`PoolTasks` (any ``concurrent.futures`` executor, by default a process pool of this machine) and
:class:`DaskTasks` (a ``dask.distributed`` client: a LocalCluster or a remote scheduler, the same code) give the
runner one interface: :meth:`submit` a chunk, :meth:`wait` for the next finished ones in order of completion.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import pickle
from collections.abc import Callable
from typing import Any

__all__ = ["ChunkSizer", "PoolTasks", "DaskTasks", "Finished", "POOL_CHUNK_SECONDS", "DASK_CHUNK_SECONDS",
           "POOL_TAIL_SECONDS", "DASK_TAIL_SECONDS", "run_packed"]

#: Seconds of work aimed at per chunk on a local process pool (task cost ~0.2 ms: 0.05 s makes it < 1 %,
#: and a killed run loses at most this much work per worker).
POOL_CHUNK_SECONDS = 0.05

#: Seconds of work aimed at per chunk on Dask (the scheduler and its round trip cost a few ms a task).
DASK_CHUNK_SECONDS = 0.5

#: Least work of a chunk near the end of a batch on a process pool, s (a tenth of the target; a task's round
#: trip is ~0.2-0.6 ms).
POOL_TAIL_SECONDS = 0.005

#: Least work of a chunk near the end of a batch on Dask, s: above the ~8 ms from ``Client.map`` to a task
#: starting, so that with two chunks in flight per worker the round trip stays hidden behind the running chunk.
#: The last chunks bound how long one worker may wait for the other at the end: by a tenth of the target (0.05 s)
#: before, a third of a 200-part batch's 0.15 s of work per worker; now by this.
DASK_TAIL_SECONDS = 0.02

#: A finished chunk: ``(chunk, rows, None)`` or ``(chunk, None, exception)`` when the task itself failed (its
#: worker died, the cluster lost it); a chunk is a list of ``(path, sha256 or None)``.
Finished = tuple[list, "list[dict] | None", "BaseException | None"]


class ChunkSizer:
    """How many files to put in the next chunk, from the measured per-file analysis time.

    Parameters
    ----------
    target_seconds : float
        Work aimed at per chunk, s.
    max_files : int
        Upper bound of a chunk (bounds memory and the work a killed run loses).
    growth : float
        A chunk holds at most this many times the files of the largest one so far (a few fast first files
        must not make the next chunk huge).
    tail_seconds : float, optional
        Least work of a chunk when the tail rule (half a fair share of what is left) would make it smaller, s
        (default a tenth of ``target_seconds``): each chunk costs a round trip of the executor.

    Notes
    -----
    The per-file time is an exponential moving average (weight ``1/2``) of each finished chunk's mean time per
    file, so a catalogue sorted from small to large parts adapts within a few chunks.
    """

    def __init__(self, target_seconds: float, *, max_files: int = 1000, growth: float = 4.0,
                 tail_seconds: float | None = None):
        if not (target_seconds > 0 and math.isfinite(target_seconds)):
            raise ValueError(f"Expected `target_seconds` > 0, got {target_seconds}")
        if tail_seconds is None:
            tail_seconds = 0.1 * target_seconds
        if not (0 < tail_seconds <= target_seconds):
            raise ValueError(f"Expected 0 < `tail_seconds` <= `target_seconds` ({target_seconds}), got {tail_seconds}")
        if max_files < 1:
            raise ValueError(f"Expected `max_files` >= 1, got {max_files}")
        self.target_seconds = float(target_seconds)
        self.max_files = int(max_files)
        self.growth = float(growth)
        self.tail_seconds = float(tail_seconds)
        self.seconds_per_file: float | None = None
        self.largest = 1
        self._probes = 0

    def observe(self, files: int, seconds: float) -> None:
        """Record a finished chunk of ``files`` files that took ``seconds`` of analysis in all."""
        if files < 1 or not math.isfinite(seconds) or seconds < 0:
            return
        mean = seconds / files
        self.seconds_per_file = mean if self.seconds_per_file is None else 0.5 * (self.seconds_per_file + mean)

    def next_size(self, remaining: int, workers: int) -> int:
        """Files for the next chunk, given ``remaining`` files not yet handed out and ``workers`` workers."""
        if remaining <= 0:
            return 0
        if self.seconds_per_file is None:
            # nothing measured yet: 1, 2, 4, 8 files, so that the workers have work during the first round trip
            size = 2 ** min(self._probes, 3)
            self._probes += 1
        else:
            per_file = max(self.seconds_per_file, 1e-9)
            size = int(min(self.target_seconds / per_file, self.growth * self.largest, self.max_files))
            # the tail: at most half of a fair share of what is left, so that every worker gets some of the
            # last files, but not below the tail floor (each chunk costs a round trip)
            share = remaining // (2 * max(workers, 1))
            size = min(size, max(share, int(self.tail_seconds / per_file)))
        size = max(1, min(size, remaining))
        self.largest = max(self.largest, size)
        return size


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
