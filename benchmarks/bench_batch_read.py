"""The batch's read of a small file: the five system calls of ``_read_once`` against the buffered read it replaced.

Writes the ``small`` catalogue of ``bench_batch.py`` and times, in one process, alternating pass by pass over the
same files (so that both meet the same load and the same page cache):

- **before**: ``open_regular`` (``stat``, ``open``, ``fstat``, an ``ioctl`` clearing ``O_NONBLOCK``, the buffered
  file object's ``fstat``, terminal test and ``seek``), ``read(size + 1)`` through it (three ``read`` calls),
  ``close``, the SHA-256, and the ``stat`` the reader made of the file again: what the batch did per file before
  2026-11-26's seventh pass;
- **after**: ``inertia_tool.batch.runner._read_once`` (``stat``, ``open``, ``fstat``, one ``read``, ``close``)
  and its SHA-256; the reader makes no call of its own for the bytes it is given.

It prints the CPU µs per file of each (``time.process_time``, the least and the median of ``--repeat`` passes) and,
with ``strace`` installed, the system calls of one file each way.

    python benchmarks/bench_batch_read.py [--small 2000] [--repeat 9]
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(1, ROOT)

from bench_batch import make_small_meshes  # noqa: E402
from inertia_tool.batch.runner import _read_once  # noqa: E402
from inertia_tool.mesh.regular import open_regular  # noqa: E402


def before(path: str) -> tuple[bytes | None, str]:
    """The batch's read of a file up to 16 MiB before the seventh pass, and the reader's ``stat``."""
    with open_regular(path) as fh:
        size = os.fstat(fh.fileno()).st_size
        data = fh.read(size + 1)
    os.stat(path)                           # load_mesh's own check of the file it was given the bytes of
    return data, hashlib.sha256(data).hexdigest()


def after(path: str) -> tuple[bytes | None, str]:
    return _read_once(path)


_CHILD = """
import os, sys
sys.path.insert(0, {here!r}); sys.path.insert(1, {root!r})
import bench_batch_read as b
path, how = sys.argv[1], sys.argv[2]
fn = b.before if how == "before" else b.after
fn(path)
os.write(2, b"=====\\n")
fn(path)
os.write(2, b"=====\\n")
"""


def _syscalls(path: str, how: str) -> list[str]:
    """The system calls of the second read of ``path`` in a child under ``strace`` (the first warms imports)."""
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "trace")
        subprocess.run(["strace", "-f", "-o", log, sys.executable, "-c", _CHILD.format(here=HERE, root=ROOT), path,
                        how], check=True, capture_output=True)
        with open(log) as fh:
            lines = fh.read().splitlines()
    marks = [k for k, line in enumerate(lines) if "=====" in line]
    inside = lines[marks[0] + 1:marks[1]] if len(marks) >= 2 else []
    return [line.split(None, 1)[1].split("(", 1)[0] for line in inside if "(" in line]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=2000, help="parts of the small catalogue")
    ap.add_argument("--repeat", type=int, default=9, help="passes each way, alternating")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        make_small_meshes(tmp, args.small)
        files = sorted(os.path.join(tmp, n) for n in os.listdir(tmp))
        for path in files:                          # the same bytes and hashes both ways
            if before(path) != after(path):
                raise SystemExit(f"benchmark: the two reads of {path} differ")
        times: dict[str, list[float]] = {"before": [], "after": []}
        for k in range(2 * args.repeat):
            how = ("before", "after")[k % 2] if (k // 2) % 2 == 0 else ("after", "before")[k % 2]
            fn = before if how == "before" else after
            start = time.process_time()
            for path in files:
                fn(path)
            times[how].append((time.process_time() - start) / len(files) * 1e6)
        load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
        print(f"{len(files)} files of the small catalogue; load average {load}")
        for how, got in times.items():
            print(f"  {how:6s} CPU µs per file: least {min(got):7.1f}, median {statistics.median(got):7.1f} "
                  f"({args.repeat} passes)")
        if shutil.which("strace"):
            for how in ("before", "after"):
                calls = _syscalls(files[len(files) // 2], how)
                print(f"  {how:6s} system calls per file: {len(calls)} ({', '.join(calls)})")


if __name__ == "__main__":
    main()
