"""A Dask cluster for :func:`~inertia_tool.batch.runner.run_batch`: a LocalCluster here or a remote scheduler.

Both give a ``dask.distributed.Client`` and the batch then runs the same code on either
(:class:`~inertia_tool.batch.chunks.DaskTasks`): chunks of files submitted with ``Client.submit``, rows
streamed back with ``distributed.as_completed``.  Needs the ``dask`` extra (``dask[distributed]``).
"""

from __future__ import annotations

from typing import Any

from ..errors import UsageError

__all__ = ["DaskCluster", "LOCAL_CLUSTER_CONFIG", "connect_dask", "check_workers_read"]


def _warm_up() -> int:
    """Run on every worker when connecting: import the engine and analyse a cube from arrays, so that the
    first chunk does not pay the imports (the batch's throughput would count them)."""
    import os
    import warnings

    import numpy as np

    from ..mass.pipeline import mass_properties

    vertices = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                     # a cube's equal moments are no news
        mass_properties((vertices, faces), density=1000.0, units="m")
    return os.getpid()


#: Dask settings of the LocalCluster :func:`connect_dask` starts (a remote cluster keeps its own; see
#: ``docs/batch.md``).
LOCAL_CLUSTER_CONFIG = {
    # Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536 in its workers' environment, to give freed memory back to the
    # system at once.  Any such variable also freezes glibc's mmap threshold at 128 kB, so every array above
    # 128 kB (a 4,800-triangle part's corners) is a fresh mmap and its pages fault in again: on 2,000 small parts
    # 28x the page faults and 8-20 % more CPU per file.  Unset, glibc's adaptive thresholds apply (a worker
    # keeps at most some tens of MB of freed heap).
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    # no dashboard: the workers' statistical profiler (a stack sample every 10 ms) and a system monitor every
    # 0.5 s only feed it; the event loop's 20 ms tick only measures how blocked the loop is
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.tick.interval": "1s",
    # each worker and each nanny (the nannies run in the batch's process) read the worker's memory every 100 ms
    # by default, for the spill, pause and terminate thresholds: about half of an idle cluster's CPU (idle, 12 ms
    # of CPU per second in the two workers and 12-17 in the batch's process; 6 and 7 with 1 s).  A batch holds
    # one part at a time per worker, bounded by --max-faces; a second is soon enough to see it grow.
    "distributed.worker.memory.monitor-interval": "1s",
}


class DaskCluster:
    """A connected Dask client, and the LocalCluster behind it when this object started one.

    Attributes
    ----------
    client : dask.distributed.Client
        Pass it to ``run_batch(..., client=...)``.
    address : str
        ``"local"`` or the scheduler address connected to.
    """

    def __init__(self, client: Any, cluster: Any, address: str):
        self.client = client
        self._cluster = cluster
        self.address = address

    @property
    def workers(self) -> int:
        """Worker threads the scheduler knows of now."""
        return sum(self.client.nthreads().values())

    def close(self) -> None:
        """Close the client, and the LocalCluster if this object started it (a remote cluster stays up)."""
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()

    def __enter__(self) -> "DaskCluster":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def connect_dask(address: str, workers: int = 2, *, timeout: float = 20.0) -> DaskCluster:
    """Start a LocalCluster (``address="local"``) or connect to a running scheduler, and warm its workers up.

    Parameters
    ----------
    address : str
        ``"local"``: a ``LocalCluster`` of ``workers`` single-threaded worker processes on this machine, without a
        dashboard, with :data:`LOCAL_CLUSTER_CONFIG`. Anything else is a scheduler address
        (``"tcp://host:8786"``); the workers must see the mesh files at the same absolute paths (a shared file
        system) and have inertia_tool installed.
    workers : int
        Worker processes of a LocalCluster (ignored for a remote scheduler: its workers are what they are).  Their
        C kernels share the cores (``INERTIA_TOOL_THREADS``, unless set, is the cores divided by ``workers``).
    timeout : float
        Seconds to wait for a remote scheduler.

    Raises
    ------
    UsageError
        ``dask.distributed`` is not installed, or no scheduler answers at ``address``.
    """
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise UsageError('Running on Dask needs dask.distributed: pip install "inertia-tool[dask]" '
                         '(or "dask[distributed]")') from None
    if workers < 1:
        raise UsageError(f"Expected `workers` >= 1, got {workers}")
    if address == "local":
        from .._native import THREADS_ENV
        from .runner import kernel_threads_per_worker

        import dask

        with dask.config.set(LOCAL_CLUSTER_CONFIG):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                                   env={THREADS_ENV: str(kernel_threads_per_worker(workers))})
        client = Client(cluster)
    else:
        cluster = None
        try:
            client = Client(address, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise UsageError(f"Cannot connect to a Dask scheduler at {address} ({exc})") from None
    connected = DaskCluster(client, cluster, address)
    try:
        client.run(_warm_up)
    except BaseException:
        connected.close()
        raise
    return connected


def _unreadable(paths: list[str]) -> list[str]:
    """Run on a worker: the ones of ``paths`` it cannot open for reading."""
    import os

    return [p for p in paths if not os.access(p, os.R_OK)]


def check_workers_read(client: Any, paths: list[str]) -> None:
    """Refuse to start a batch that some worker of ``client``'s cluster would read differently from this process.

    The workers of a cluster of several machines must see the mesh files at the same absolute paths (a shared
    file system mounted alike).  A worker that cannot would write an ``error`` row for each file it is given,
    and ``error`` rows count as done on resume (a bad file stays bad), so the mistake would outlive the run.
    Each worker is asked whether it can read ``paths`` (a sample: the first and last file of the batch).

    Raises
    ------
    UsageError
        A worker cannot read one of ``paths`` (the message names the worker and the file), or the workers
        cannot be asked.
    """
    if not paths:
        return
    try:
        answers = client.run(_unreadable, list(paths))
    except (OSError, TimeoutError) as exc:
        raise UsageError(f"the Dask workers did not answer whether they can read the files ({exc})") from None
    for worker, missing in sorted(answers.items()):
        if missing:
            raise UsageError(f"the Dask worker {worker} cannot read {missing[0]} (expected every worker to see the "
                             "files at the same absolute paths as this machine: a shared file system mounted "
                             "alike; see docs/batch.md, 'Running on several machines')")

