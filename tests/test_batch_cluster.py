"""The multi-machine recipe of ``docs/batch.md`` ("Running on several machines"), on this machine: a ``dask
scheduler`` and two ``dask worker`` processes started as the recipe starts them (subprocesses, ports chosen free
by the scheduler, torn down whatever happens), and ``inertia-tool batch --dask tcp://...`` through them.  The
results file must hold the rows of a single-process run, row by row (only ``seconds`` and ``worker`` differ),
and the rows must come from the two workers, not from this process."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh

from conftest import write_binary_stl
from inertia_tool.cli import main
from inertia_tool.cli.batch import EXIT_SOME_FAILED

pytest.importorskip("dask.distributed", reason="the 'dask' extra is not installed")

ROOT = Path(__file__).resolve().parents[1]

#: Seconds to wait for the scheduler to write its address and for both workers to register.
START_TIMEOUT = 90.0


def _dask_command(*args: str) -> list[str]:
    """``dask ARGS`` (the recipe's command) run by this interpreter, so its environment and this checkout."""
    return [sys.executable, "-m", "dask", *args]


def _stop(process: subprocess.Popen) -> None:
    """End a process this test started and the children it made (its own session): SIGTERM, then SIGKILL."""
    if process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGTERM)
        process.wait(timeout=10)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait(timeout=10)


@pytest.fixture(scope="module")
def scheduler_and_two_workers(tmp_path_factory):
    """``(address, worker pids)`` of a scheduler and two single-threaded workers, as in the docs' recipe."""
    from distributed import Client

    where = tmp_path_factory.mktemp("cluster")
    scheduler_file = where / "scheduler.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
           "INERTIA_TOOL_THREADS": "1", "DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED": "False",
           "DASK_DISTRIBUTED__WORKER__MEMORY__MONITOR_INTERVAL": "1s"}
    started: list[subprocess.Popen] = []

    def start(*args: str, log: str) -> None:
        with open(where / log, "wb") as out:
            started.append(subprocess.Popen(_dask_command(*args), cwd=where, env=env, stdout=out,
                                            stderr=subprocess.STDOUT, start_new_session=True))

    try:
        # port 0: the scheduler takes a free port and writes its address to the scheduler file
        start("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
              "--scheduler-file", str(scheduler_file), log="scheduler.log")
        deadline = time.monotonic() + START_TIMEOUT
        while not scheduler_file.exists() or not scheduler_file.read_text().strip():
            if started[0].poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"the scheduler did not start: {(where / 'scheduler.log').read_text()[-2000:]}")
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        for k in (1, 2):
            start("worker", address, "--nthreads", "1", "--no-dashboard", "--name", f"worker-{k}",
                  "--host", "127.0.0.1", log=f"worker-{k}.log")
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=START_TIMEOUT)
            pids = set(client.run(os.getpid).values())
        yield address, pids
    finally:
        for process in reversed(started):          # the workers first, then the scheduler
            _stop(process)


def _catalogue(directory: Path) -> Path:
    """Twelve small parts (boxes, icospheres, a torus) and a file that is not a mesh."""
    directory.mkdir()
    rng = np.random.default_rng(25)
    for k in range(12):
        if k % 3 == 0:
            m = trimesh.creation.box(rng.uniform(5, 50, 3))
        elif k % 3 == 1:
            m = trimesh.creation.icosphere(subdivisions=2, radius=float(rng.uniform(5, 30)))
        else:
            m = trimesh.creation.torus(30.0, 6.0, major_sections=24, minor_sections=12)
        m.apply_translation(rng.uniform(-50, 50, 3))
        write_binary_stl(directory / f"part{k:02d}.stl", m.vertices, m.faces)
    (directory / "broken.stl").write_bytes(b"solid broken\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\n")
    return directory


def _rows(path: Path) -> list[dict]:
    """The rows of a JSONL results file, sorted by path, without the columns that differ between runs."""
    rows = [json.loads(line) for line in path.read_text().splitlines()]
    return sorted(({k: v for k, v in r.items() if k not in ("seconds", "worker")} for r in rows),
                  key=lambda r: r["path"])


@pytest.mark.slow
def test_batch_on_a_scheduler_and_two_workers_writes_the_single_process_rows(scheduler_and_two_workers, tmp_path,
                                                                              capsys):
    address, worker_pids = scheduler_and_two_workers
    parts = _catalogue(tmp_path / "parts")
    single, on_cluster = tmp_path / "single.jsonl", tmp_path / "cluster.jsonl"
    common = [str(parts), "--units", "mm", "--material", "pla", "-q"]
    assert main(["batch", *common, "--out", str(single)]) == EXIT_SOME_FAILED          # broken.stl
    assert main(["batch", *common, "--out", str(on_cluster), "--dask", address]) == EXIT_SOME_FAILED
    assert f"on Dask ({address})" in capsys.readouterr().err
    expected, got = _rows(single), _rows(on_cluster)
    assert len(got) == len(expected) == 13
    for mine, theirs in zip(got, expected):                    # row by row: numbers bit for bit, the error alike
        assert mine == theirs
    assert [r["status"] for r in got].count("ok") == 12
    workers = {int(json.loads(line)["worker"].rsplit(":", 1)[1]) for line in on_cluster.read_text().splitlines()}
    assert workers <= worker_pids and os.getpid() not in workers                 # computed on the workers

    # the recipe's resume: the same command again computes nothing and appends nothing
    before = on_cluster.read_bytes()
    assert main(["batch", *common, "--out", str(on_cluster), "--dask", address]) == EXIT_SOME_FAILED
    assert "nothing new" in capsys.readouterr().err
    assert on_cluster.read_bytes() == before


@pytest.mark.slow
def test_a_worker_that_cannot_read_the_files_stops_the_batch_before_any_row(scheduler_and_two_workers, tmp_path):
    """A worker without the shared file system would write an ``error`` row per file, and error rows count as
    done on resume: the batch is refused before it starts, naming a worker and the file."""
    from distributed import Client

    from inertia_tool.batch.cluster import check_workers_read
    from inertia_tool.errors import UsageError

    address, _ = scheduler_and_two_workers
    parts = _catalogue(tmp_path / "parts")
    with Client(address, timeout="30s") as client:
        check_workers_read(client, [str(parts / "part00.stl")])                 # both see it: no complaint
        with pytest.raises(UsageError, match=r"the Dask worker tcp://127\.0\.0\.1:\d+ cannot read .*nowhere\.stl"):
            check_workers_read(client, [str(parts / "part00.stl"), str(tmp_path / "nowhere.stl")])
