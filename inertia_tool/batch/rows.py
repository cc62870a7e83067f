"""Append-only result files of ``inertia-tool batch``: JSON Lines or CSV, one row per file.

One writer at a time: :func:`open_results` takes an exclusive, non-blocking lock on the file
(``fcntl.flock`` on POSIX, ``msvcrt.locking`` on Windows) and holds it until :meth:`ResultsFile.close`; a
second batch run on the same file is refused with :class:`ResultsFileBusy` ("FILE is being written by
another batch run (pid N)") instead of interleaving its rows with the first run's.  The lock is released by
the operating system when the process dies, so a killed run never leaves a stale lock.

Crash safety: the file is opened with ``O_APPEND`` and each row is written as one complete record in one
``write`` call, so a killed process (``kill -9``, out of memory) leaves every row it wrote and at most one torn
last record: what ``write`` returned from is in the operating system's cache and reaches the disk without
the process.  ``fsync`` (which only matters when the *machine* stops: a power cut, a kernel crash) runs at most
once every ``sync_seconds`` (default 1 s) and on closing, so such a stop loses at most the last second of rows,
which the next run computes again; ``sync_seconds=0`` syncs every row (0.5-1 ms each, as long as analysing a
small mesh).  :func:`open_results`
reads an existing file back (for resuming) under the lock, cuts a torn last record off (the file then ends
with a complete row again; :attr:`ResultsFile.torn_bytes` says how much was cut) and refuses a file that is
not a previous result file of the same kind, so that a run never clobbers unrelated data.

Columns are :data:`inertia_tool.batch.runner.ROW_FIELDS`.  In CSV, empty cells are missing values (``None`` in
JSON); booleans are ``true``/``false``; a cell holding the delimiter, a quote or a line break (a file name
may hold any of them) is quoted as the ``csv`` module does by default (``QUOTE_MINIMAL``), so a record can
span several physical lines.
"""

from __future__ import annotations

import csv
import io
import json
import os
import sys
import time
from dataclasses import dataclass

from .runner import ROW_FIELDS, SCHEMA
from ..errors import UsageError

__all__ = ["ResultsFile", "ResultsFileBusy", "close_inherited", "open_results", "results_format", "FORMATS"]

#: Output formats by file suffix.
FORMATS = {".jsonl": "jsonl", ".ndjson": "jsonl", ".csv": "csv"}

_INT_FIELDS = {"faces", "bodies", "cavities"}
_BOOL_FIELDS = {"watertight", "repaired"}
_TEXT_FIELDS = {"schema", "path", "status", "error_type", "error", "sha256", "options_key", "units",
                "density_source", "warnings", "worker"}


class ResultsFileBusy(UsageError):
    """Another process holds the lock of the results file (a second batch run on the same results file)."""


def results_format(path: str | os.PathLike) -> str:
    """``"jsonl"`` or ``"csv"`` from the suffix of ``path``; :class:`UsageError` otherwise."""
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in FORMATS:
        raise UsageError(f"Expected the results file to end in .jsonl or .csv, got {os.fspath(path)!r}")
    return FORMATS[suffix]


def _csv_value(name: str, text: str):
    if text == "":
        return None
    if name in _TEXT_FIELDS:
        return text
    if name in _BOOL_FIELDS:
        return text == "true"
    if name in _INT_FIELDS:
        return int(text)
    return float(text)


def _csv_cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def format_row(row: dict, fmt: str) -> bytes:
    """One row as the bytes of one complete record, ending in ``\\n`` (JSONL: one line; CSV: quoted cells
    may hold line breaks)."""
    if fmt == "jsonl":
        line = json.dumps({k: row.get(k) for k in ROW_FIELDS}, ensure_ascii=False, allow_nan=False) + "\n"
    else:
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerow([_csv_cell(row.get(k)) for k in ROW_FIELDS])
        line = buf.getvalue()
    return line.encode("utf-8")


# -- reading back ---------------------------------------------------------------------------------------

def _records(data: bytes, fmt: str) -> list[bytes]:
    """Split ``data`` into records, each ending in ``\\n`` except possibly a torn last one.

    JSONL: one record per line.  CSV: a line break inside a quoted cell does not end the record; with
    quotes escaped by doubling, a record ends at the first ``\\n`` after which the count of ``"`` so far
    is even.
    """
    lines = data.splitlines(keepends=True)
    if fmt == "jsonl":
        return lines
    out, pending, quotes = [], b"", 0
    for line in lines:
        pending += line
        quotes += line.count(b'"')
        if quotes % 2 == 0 and line.endswith(b"\n"):
            out.append(pending)
            pending, quotes = b"", 0
    if pending:
        out.append(pending)
    return out


def _parse_record(record: bytes, fmt: str):
    """A row dict, ``"header"`` for the CSV header, or a string saying why ``record`` is not a row."""
    text = record.decode("utf-8", errors="replace")
    if fmt == "jsonl":
        try:
            row = json.loads(text)
        except ValueError:
            return "is not JSON"
        if not isinstance(row, dict) or row.get("schema") != SCHEMA:
            return f"is not a row of schema {SCHEMA}"
        return row
    try:
        cells = next(csv.reader(io.StringIO(text), strict=True), [])
    except csv.Error as exc:
        return f"is not CSV ({exc})"
    if cells == list(ROW_FIELDS):
        return "header"
    if len(cells) != len(ROW_FIELDS) or cells[0] != SCHEMA:
        return f"has {len(cells)} cells, expected {len(ROW_FIELDS)} ({SCHEMA})"
    try:
        return {k: _csv_value(k, v) for k, v in zip(ROW_FIELDS, cells)}
    except ValueError as exc:
        return f"has a bad cell ({exc})"


def read_rows(data: bytes, fmt: str, path: str) -> tuple[list[dict], int]:
    """The rows of a results file's bytes and the length of the torn tail (0 when there is none).

    The last record is torn when it lacks its final ``\\n`` or does not parse (a run killed while writing
    it); any other record that is not a row of :data:`SCHEMA`, or a CSV file whose first record is not the
    header, means the file is not ours: :class:`UsageError`, the file untouched.
    """
    records = _records(data, fmt)
    refuse = "not a results file of inertia-tool batch (refusing to append to it; choose another results file)"
    torn = 0
    if records:
        last = records[-1]
        if not last.endswith(b"\n") or (last.strip() and isinstance(_parse_record(last, fmt), str)):
            torn = len(last)
            records = records[:-1]
            # a file of one torn record has not shown it is ours: it must be the start of what we write
            start = (",".join(ROW_FIELDS) if fmt == "csv" else json.dumps({"schema": SCHEMA})[:-1]).encode()
            if not records and not (start.startswith(last.strip()) or last.startswith(start)):
                raise UsageError(f"{path}: {refuse}")
    if fmt == "csv" and records and _parse_record(records[0], fmt) != "header":
        raise UsageError(f"{path}: its header is not the inertia-tool batch header ({SCHEMA}); {refuse}")
    rows = []
    line = 1
    for k, record in enumerate(records):
        if record.strip() and not (fmt == "csv" and k == 0):
            got = _parse_record(record, fmt)
            if isinstance(got, str):
                raise UsageError(f"{path}: line {line} {got}; {refuse}")
            rows.append(got)
        line += record.count(b"\n")
    return rows, torn


# -- the lock -------------------------------------------------------------------------------------------

def _holder_pid(fd: int) -> int | None:
    """The pid holding a lock on the file of ``fd``, from ``/proc/locks`` (Linux); None elsewhere."""
    try:
        st = os.fstat(fd)
        wanted = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
        with open("/proc/locks", encoding="ascii", errors="replace") as fh:
            for line in fh:
                parts = line.split()
                # "1: FLOCK  ADVISORY  WRITE 12345 08:01:123456 0 EOF" (blocked waiters carry "->")
                if "->" not in parts and len(parts) >= 6 and parts[5] == wanted and parts[4].isdigit():
                    return int(parts[4])
    except (OSError, ValueError, AttributeError):
        pass
    return None


def _lock(fd: int, path: str) -> None:
    """Take the exclusive writer lock of the results file or raise :class:`ResultsFileBusy`."""
    if sys.platform == "win32":                                          # pragma: no cover - Windows
        import msvcrt
        try:
            os.lseek(fd, 0, os.SEEK_SET)
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)                       # the first byte marks the writer
        except OSError:
            raise ResultsFileBusy(f"{path} is being written by another batch run (pid unknown); wait for it "
                                  "or choose another results file") from None
        return
    import fcntl
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        pid = _holder_pid(fd)
        raise ResultsFileBusy(f"{path} is being written by another batch run "
                              f"(pid {pid if pid is not None else 'unknown'}); wait for it or choose another "
                              "results file") from None


# -- the open file --------------------------------------------------------------------------------------

#: Descriptors of the results files open in this process.  A worker process forked while one is open inherits
#: it, and with it the lock: a killed run's workers, until they are gone, would refuse the resume.  The pool
#: workers close their copies at start (:func:`close_inherited`; the lock stays with the parent's).
_OPEN_FDS: set[int] = set()


def close_inherited() -> None:
    """In a freshly forked worker: close the copies of this process's results files (their lock is the
    parent's)."""
    for fd in list(_OPEN_FDS):
        try:
            os.close(fd)
        except OSError:
            pass
    _OPEN_FDS.clear()


@dataclass
class ResultsFile:
    """An open, locked, append-only results file.

    Attributes
    ----------
    path : str
    format : str
        ``"jsonl"`` or ``"csv"``.
    previous_rows : list of dict
        Rows already in the file when it was opened (for resuming).
    torn_bytes : int
        Length of the torn last record (a killed run) cut off on opening; 0 when there was none.
    sync_seconds : float
        ``fsync`` after a row when at least this many seconds have passed since the last one (0: every row);
        always on :meth:`close`.
    """

    path: str
    format: str
    previous_rows: list
    torn_bytes: int = 0
    sync_seconds: float = 1.0
    _fd: int | None = None
    _synced: float = 0.0

    @property
    def repaired_tail(self) -> bool:
        """True when a torn last record was cut off on opening."""
        return self.torn_bytes > 0

    def write_row(self, row: dict) -> None:
        """Append one row as one record in one ``write`` (``O_APPEND``), so that a killed process loses at most
        the row being written; ``fsync`` when :attr:`sync_seconds` have passed since the last one."""
        if self._fd is None:
            raise ValueError(f"{self.path}: the results file is closed")
        _write_all(self._fd, format_row(row, self.format))
        now = time.monotonic()
        if now - self._synced >= self.sync_seconds:
            os.fsync(self._fd)
            self._synced = now

    def sync(self) -> None:
        """``fsync`` the rows written so far to the disk."""
        if self._fd is not None:
            os.fsync(self._fd)
            self._synced = time.monotonic()

    def close(self) -> None:
        """Sync and close the file (which releases the lock)."""
        if self._fd is not None:
            try:
                self.sync()
            finally:
                _OPEN_FDS.discard(self._fd)
                os.close(self._fd)
                self._fd = None

    def __enter__(self) -> "ResultsFile":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _write_all(fd: int, data: bytes) -> None:
    """``os.write`` until every byte is written (a regular file takes it in one call; the loop is bounded by
    the length, each call writing at least one byte or raising)."""
    view = memoryview(data)
    for _ in range(len(data) + 1):
        if not view:
            return
        view = view[os.write(fd, view):]


def open_results(path: str | os.PathLike, *, max_bytes: int = 4 << 30, sync_seconds: float = 1.0) -> ResultsFile:
    """Open ``path`` for appending rows, locked against other writers, reading back what a previous run wrote.

    A new file gets the CSV header (CSV) or nothing (JSONL).  An existing file must be a results file of the
    same format and schema, else :class:`UsageError` (it is left untouched).  A torn last record is cut off.

    Parameters
    ----------
    path : str or path
        ``*.jsonl`` / ``*.ndjson`` or ``*.csv``.
    max_bytes : int
        Refuse to read back a larger existing file.
    sync_seconds : float
        Longest time between two ``fsync`` of the rows, s (0: after every row); see the module's notes.

    Raises
    ------
    ResultsFileBusy
        Another process (a second batch run) is writing the file.
    UsageError
        Not a results file of this kind, not a regular file, too large, or not readable/writable.
    """
    path = os.fspath(path)
    fmt = results_format(path)
    if not sync_seconds >= 0:
        raise UsageError(f"Expected `sync_seconds` >= 0, got {sync_seconds}")
    if os.path.exists(path) and not os.path.isfile(path):
        raise UsageError(f"{path}: exists and is not a regular file")
    flags = os.O_RDWR | os.O_CREAT | os.O_APPEND | getattr(os, "O_BINARY", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        raise UsageError(f"{path}: cannot write the results file ({exc.strerror or exc})") from None
    try:
        _lock(fd, path)
        size = os.fstat(fd).st_size
        if size > max_bytes:
            raise UsageError(f"{path}: {size:,} bytes, more than the {max_bytes:,} a results file may have here")
        data = os.pread(fd, size, 0) if hasattr(os, "pread") else _read_from_start(fd, size)
        rows, torn = read_rows(data, fmt, path)
        if torn:
            os.ftruncate(fd, size - torn)
        if fmt == "csv" and size - torn == 0:
            _write_all(fd, (",".join(ROW_FIELDS) + "\n").encode())
        os.fsync(fd)
    except UsageError:
        os.close(fd)
        raise
    except OSError as exc:
        os.close(fd)
        raise UsageError(f"{path}: cannot use the results file ({exc.strerror or exc})") from None
    _OPEN_FDS.add(fd)
    return ResultsFile(path=path, format=fmt, previous_rows=rows, torn_bytes=torn, sync_seconds=float(sync_seconds),
                       _fd=fd, _synced=time.monotonic())


def _read_from_start(fd: int, size: int) -> bytes:                      # pragma: no cover - Windows
    os.lseek(fd, 0, os.SEEK_SET)
    chunks, left = [], size
    for _ in range(size + 1):
        if left <= 0:
            break
        chunk = os.read(fd, left)
        if not chunk:
            break
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)
