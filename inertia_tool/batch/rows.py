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
not a previous result file of the same kind, so that a run never clobbers unrelated data.  Only the last record
can be torn; damage before it (a stray quote, a torn line followed by rows, an overlong or nested line) is
refused with its line number (:class:`ResultsFileDamaged`, :func:`read_rows`), never cut.

Write errors (a full disk): a row that cannot be written, or an ``fsync`` that fails, cuts the file back to its
last complete row (to the last synced one after a failed ``fsync``) and raises :class:`ResultsFileWriteError`;
the file then resumes like one of a killed run.

Columns are :data:`inertia_tool.batch.runner.ROW_FIELDS`.  In CSV, empty cells are missing values (``None`` in
JSON); booleans are ``true``/``false``; a cell holding the delimiter, a quote or a line break (a file name
may hold any of them) is quoted as the ``csv`` module does by default (``QUOTE_MINIMAL``), so a record can
span several physical lines.

Rows of an older layout (:data:`~inertia_tool.batch.runner.SCHEMA_V2`, ``SCHEMA_V1``) are read back with the
current columns (:func:`~inertia_tool.batch.runner.upgrade_row`), so an old results file resumes without
re-running its files: a column they lack is ``None``, *not recorded* (their ``assumptions`` too: unknown, never
``"none"``, which an ``ok`` row of this layout writes when its result rests on no assumption of the user's,
:data:`~inertia_tool.batch.runner.NO_ASSUMPTIONS`); a CSV file with an old header goes on receiving rows of its
own layout (its header is never rewritten).
"""

from __future__ import annotations

import csv
import json
import os
import re
import stat
import sys
import time
from dataclasses import dataclass

from .runner import ROW_FIELDS, ROW_FIELDS_V1, ROW_FIELDS_V2, SCHEMA, SCHEMA_V1, SCHEMA_V2, downgrade_row, upgrade_row
from ..errors import UsageError

__all__ = ["ResultsFile", "ResultsFileBusy", "ResultsFileDamaged", "ResultsFileWriteError", "read_rows",
           "close_inherited", "open_results", "results_format", "FORMATS"]

#: Output formats by file suffix.
FORMATS = {".jsonl": "jsonl", ".ndjson": "jsonl", ".csv": "csv"}

_INT_FIELDS = {"faces", "bodies", "cavities"}
_BOOL_FIELDS = {"watertight", "repaired"}
_TEXT_FIELDS = {"schema", "path", "status", "error_type", "error", "sha256", "options_key", "units",
                "mesh_length_unit", "method",
                "density_source", "warnings", "worker", "certificate", "assumptions"}
#: The columns of each row layout, by the ``schema`` value that starts its rows.
_LAYOUTS = {SCHEMA: ROW_FIELDS, SCHEMA_V2: ROW_FIELDS_V2, SCHEMA_V1: ROW_FIELDS_V1}


class ResultsFileBusy(UsageError):
    """Another process holds the lock of the results file (a second batch run on the same results file)."""


class ResultsFileWriteError(UsageError):
    """A row could not be written to the results file (a full disk, a quota, an I/O error).  The file was cut
    back to its last complete row before this was raised, so the same command resumes once the cause is gone."""


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


def _csv_quoted(cell: str) -> str:
    """A CSV cell as the ``csv`` module's ``QUOTE_MINIMAL`` writes it, except that a carriage return alone also
    quotes it (Python 3.11's writer leaves ``a\\rb`` bare with ``lineterminator="\\n"``, and its reader then
    refuses the record: a file name holding one made the results file unreadable)."""
    if any(c in cell for c in ',"\n\r'):
        return '"' + cell.replace('"', '""') + '"'
    return cell


def _csv_field(value) -> str:
    """``_csv_quoted(_csv_cell(value))``, with the cells that never need quotes (empty, numbers, booleans) not
    searched for a delimiter: a row has some forty numbers."""
    if value is None:
        return ""
    kind = type(value)
    if kind is float:
        return repr(value)                     # digits, '.', 'e', '-', 'inf'/'nan' (never written): no quotes
    if kind is bool:
        return "true" if value else "false"
    if kind is int:
        return str(value)
    return _csv_quoted(_csv_cell(value))


#: The JSON writer of the rows (one, made once: ``json.dumps`` with options builds a new encoder per call).
_JSON_ROW = json.JSONEncoder(ensure_ascii=False, allow_nan=False)


def format_row(row: dict, fmt: str, layout: str = SCHEMA) -> bytes:
    """One row as the bytes of one complete record, ending in ``\\n`` (JSONL: one line; CSV: quoted cells
    may hold line breaks).  ``layout``: :data:`SCHEMA`, or ``SCHEMA_V2`` / ``SCHEMA_V1`` for an old CSV file's
    own layout."""
    if layout != SCHEMA:
        row = downgrade_row(row, layout)
    fields = _LAYOUTS[layout]
    if fmt == "jsonl":
        # a row made by the runner holds exactly the columns, in order: written as it is
        ordered = row if tuple(row) == fields else {k: row.get(k) for k in fields}
        line = _JSON_ROW.encode(ordered) + "\n"
    else:
        line = ",".join([_csv_field(row.get(k)) for k in fields]) + "\n"
    return line.encode("utf-8", "backslashreplace")     # a lone surrogate left in a message: never an error


# -- reading back ---------------------------------------------------------------------------------------

#: Longest physical line of a results file read back, bytes.  A row is a few KiB (a path of at most 4 KiB, an
#: error of at most 500 characters, its warnings); a longer line is not one we wrote and is refused (with its
#: line number) before any parser sees it.
MAX_LINE_BYTES = 1 << 20

#: JSON strings of a line (the grammar of RFC 8259 §7), removed before counting brackets: what is left of a
#: flat row object is one ``{`` and one ``}``.
_JSON_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)

#: How a row of :data:`SCHEMA` starts in CSV: a record that does not end and runs over lines starting like
#: this holds more than one row, so it is damage in the middle, not a torn last row.
_CSV_ROW_START = tuple((schema + ",").encode() for schema in _LAYOUTS)


@dataclass(frozen=True)
class _Record:
    """One record of a results file: physical lines ``first`` to ``end - 1`` (0-based), what it parses to (a row
    dict, ``"header"``, or a string saying why it is not a row) and whether its last line ends in ``\\n``."""

    first: int
    end: int
    parsed: object
    terminated: bool
    short: bool = False
    """True when the record looks cut short (a JSON object without its end, fewer CSV cells than a row)."""


def _parse_json_line(line: bytes):
    """A row dict or a string saying why ``line`` is not one (a flat object: nesting refused before parsing)."""
    if line.count(b"{") != 1 or line.count(b"}") != 1 or b"[" in line or b"]" in line:
        # brackets inside strings are fine: count those outside them (a line of one "{" and one "}" and no
        # "[" or "]" nests at most one deep however its quotes fall, so the common case skips this)
        rest = _JSON_STRING.sub(b'""', line)
        if rest.count(b"{") > 1 or rest.count(b"}") > 1 or b"[" in rest or b"]" in rest:
            return "is not a flat JSON object (a row holds no arrays or nested objects)"
    if not line.rstrip().endswith(b"}"):
        return "is not a JSON object"
    try:
        row = json.loads(line.decode("utf-8", errors="replace"))
    except ValueError:
        return "is not JSON"
    if not isinstance(row, dict) or row.get("schema") not in _LAYOUTS:
        return f"is not a row of schema {SCHEMA}"
    return upgrade_row(row)


def _parse_csv_cells(cells: list[str], text: str):
    """A row dict, ``"header"``, or a string saying why the cells of ``text`` are not a row."""
    if any(cells == list(fields) for fields in _LAYOUTS.values()):
        return "header"
    fields = _LAYOUTS.get(cells[0], ROW_FIELDS)
    if len(cells) != len(fields):
        return f"has {len(cells)} cells, expected {len(fields)} ({cells[0] if cells[0] in _LAYOUTS else SCHEMA})"
    if cells[0] not in _LAYOUTS:
        return f"starts with {cells[0][:40]!r}, expected the schema {SCHEMA}"
    for cell in cells:
        # the csv module reads `a"b` as a cell, but the writer quotes any cell holding a quote: a stray quote
        if '"' in cell and '"' + cell.replace('"', '""') + '"' not in text:
            return "is not quoted as inertia-tool writes it (a stray quote?)"
    try:
        return upgrade_row({k: _csv_value(k, v) for k, v in zip(fields, cells)})
    except ValueError as exc:
        return f"has a bad cell ({exc})"


def _jsonl_records(lines: list[bytes], ends_with_newline: bool) -> list[_Record]:
    last = len(lines) - 1
    records = []
    for k, line in enumerate(lines):
        if line.strip():
            parsed = _parse_json_line(line)
            records.append(_Record(k, k + 1, parsed, k < last or ends_with_newline,
                                   short=parsed in ("is not a JSON object", "is not JSON")))
    return records


def _csv_records(lines: list[bytes], ends_with_newline: bool) -> list[_Record]:
    """The records of a CSV results file, read with the ``csv`` module (strict: a quote ends a quoted cell
    only before a delimiter or a line break); a line break inside a quoted cell does not end a record.  A
    record the module refuses (a stray quote) runs to the end: nothing after it can be trusted to start a
    record."""
    texts = [line.decode("utf-8", errors="replace") + "\n" for line in lines]
    if texts and not ends_with_newline:
        texts[-1] = texts[-1][:-1]
    reader = csv.reader(iter(texts), strict=True)
    records: list[_Record] = []
    first = 0
    for _ in range(len(texts) + 1):                      # each pass reads at least one line or stops
        try:
            cells = next(reader)
        except StopIteration:
            break
        except csv.Error as exc:
            at_end = reader.line_num >= len(texts)
            records.append(_Record(first, len(texts), f"is not CSV ({exc})", ends_with_newline and at_end,
                                   short=at_end and "unexpected end of data" in str(exc)))
            break
        end = reader.line_num
        if cells:
            text = "".join(texts[first:end])
            records.append(_Record(first, end, _parse_csv_cells(cells, text), end < len(texts) or ends_with_newline,
                                   short=0 < len(cells) < len(_LAYOUTS.get(cells[0], ROW_FIELDS))))
        first = end
    return records


class ResultsFileDamaged(UsageError):
    """A results file has a damaged record before its last one (a stray quote, a torn line in the middle, a
    line too long): refused with the line number, never cut (every row after it would be lost)."""


def read_rows(data: bytes, fmt: str, path: str) -> tuple[list[dict], int]:
    """The rows of a results file's bytes and the length of the torn tail (0 when there is none).

    Only the last record may be torn (a run killed while writing it): one that does not end in ``\\n`` or does
    not parse, holding at most the start of one row.  It is left out and its length returned, for the caller
    to cut.  Any other record that is not a row of :data:`SCHEMA` — a stray quote, a torn line in the middle,
    a line longer than :data:`MAX_LINE_BYTES`, a nested JSON object — is refused with its line number
    (:class:`ResultsFileDamaged`), as is a file that is not ours (a CSV whose first record is not the header):
    the file is never cut in the middle, so no complete row is ever dropped.

    Raises
    ------
    ResultsFileDamaged
        A record before the last one is not a row, or a line is too long.
    UsageError
        The file is not a results file of this format and schema.
    """
    lines = data.split(b"\n")
    ends_with_newline = lines[-1] == b""
    if ends_with_newline:
        lines.pop()
    refuse = "not a results file of inertia-tool batch (refusing to append to it; choose another results file)"
    damaged = ("refusing to resume from it: nothing was cut or written (repair or remove that line, or choose "
               "another results file)")
    for k, line in enumerate(lines):
        if len(line) > MAX_LINE_BYTES:
            raise ResultsFileDamaged(f"{path}: line {k + 1} holds {len(line):,} bytes, more than the "
                                     f"{MAX_LINE_BYTES:,} of any row; {damaged}")
    records = _jsonl_records(lines, ends_with_newline) if fmt == "jsonl" else _csv_records(lines, ends_with_newline)
    torn = 0
    if records and (not records[-1].terminated or records[-1].short):
        tail = records.pop()
        more = sum(line.startswith(_CSV_ROW_START) for line in lines[tail.first + 1:tail.end])
        if more:
            raise ResultsFileDamaged(
                f"{path}: line {tail.first + 1} starts a record that never ends (a stray quote?) and runs over "
                f"{tail.end - tail.first} lines holding {more} more row(s) to the end of the file; {damaged}")
        torn = sum(len(line) + 1 for line in lines[tail.first:]) - (0 if ends_with_newline else 1)
        text = data[len(data) - torn:]
        # a torn record is the start of one we write (a row; the header in a file of nothing else); anything
        # else there is damage, or, in a file of nothing else, not ours
        starts = list(_CSV_ROW_START) if fmt == "csv" else \
            [json.dumps({"schema": schema})[:-1].encode() for schema in _LAYOUTS]
        if not records and fmt == "csv":
            starts.append(",".join(ROW_FIELDS).encode())
        cut = text.rstrip(b"\r\n")
        if not any(cut[:len(start)] == start[:len(cut)] for start in starts):
            if not records:
                raise UsageError(f"{path}: {refuse}")
            raise ResultsFileDamaged(f"{path}: line {tail.first + 1} is not a row, nor the start of one cut short "
                                     f"({tail.parsed if isinstance(tail.parsed, str) else 'no line break'}); "
                                     f"{damaged}")
    if fmt == "csv" and records and records[0].parsed != "header":
        raise UsageError(f"{path}: its header is not the inertia-tool batch header ({SCHEMA}); {refuse}")
    rows = []
    for k, record in enumerate(records):
        if fmt == "csv" and k == 0:
            continue
        if not isinstance(record.parsed, dict):
            problem = "is a second header" if record.parsed == "header" else str(record.parsed)
            if k == 0 and not any(isinstance(r.parsed, dict) for r in records[1:]):    # no row at all: not ours
                raise UsageError(f"{path}: line {record.first + 1} {problem}; {refuse}")
            raise ResultsFileDamaged(f"{path}: line {record.first + 1} {problem}; {damaged}")
        rows.append(record.parsed)
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
    layout : str
        The ``schema`` of the rows written: :data:`SCHEMA`, or ``SCHEMA_V2`` / ``SCHEMA_V1`` for a CSV file
        with an old header.
    sync_seconds : float
        ``fsync`` after a row when at least this many seconds have passed since the last one (0: every row);
        always on :meth:`close`.
    """

    path: str
    format: str
    previous_rows: list
    torn_bytes: int = 0
    sync_seconds: float = 1.0
    layout: str = SCHEMA
    _fd: int | None = None
    _synced: float = 0.0
    _size: int = 0               # bytes of complete rows written (what the file is cut back to if a write fails)
    _synced_size: int = 0        # bytes known to be on the disk (what it is cut back to if an fsync fails)
    _failed: bool = False

    @property
    def repaired_tail(self) -> bool:
        """True when a torn last record was cut off on opening."""
        return self.torn_bytes > 0

    def write_row(self, row: dict) -> None:
        """Append one row as one record in one ``write`` (``O_APPEND``), so that a killed process loses at most
        the row being written; ``fsync`` when :attr:`sync_seconds` have passed since the last one."""
        if self._fd is None or self._failed:
            raise ValueError(f"{self.path}: the results file is closed")
        record = format_row(row, self.format, self.layout)
        try:
            _write_all(self._fd, record)
        except OSError as exc:
            raise self._fail(exc, self._size) from None
        self._size += len(record)
        now = time.monotonic()
        if now - self._synced >= self.sync_seconds:
            self.sync()

    def sync(self) -> None:
        """``fsync`` the rows written so far to the disk.

        Raises
        ------
        ResultsFileWriteError
            The disk refused them (the file is cut back to the rows synced before).
        """
        if self._fd is not None and not self._failed:
            try:
                os.fsync(self._fd)
            except OSError as exc:
                # after a failed fsync the kernel may have dropped the unsynced pages: keep only what was synced
                raise self._fail(exc, self._synced_size) from None
            self._synced = time.monotonic()
            self._synced_size = self._size

    def _fail(self, exc: OSError, keep: int) -> ResultsFileWriteError:
        """Cut the file back to ``keep`` bytes of complete rows and the error to raise (no more rows are taken)."""
        self._failed = True
        cut = ""
        if self._fd is not None:
            try:
                os.ftruncate(self._fd, keep)             # shrinking needs no space
                os.fsync(self._fd)
            except OSError as again:
                cut = f"; cutting it back to its last complete row failed too ({again.strerror or again})"
        reason = exc.strerror or str(exc) or type(exc).__name__
        return ResultsFileWriteError(
            f"{self.path}: cannot write the results file ({reason}); it keeps the complete rows written before"
            f"{cut} — free space (or fix the cause) and run the same command again to resume")

    def close(self) -> None:
        """Sync and close the file (which releases the lock).

        Raises
        ------
        ResultsFileWriteError
            The final ``fsync`` failed (the file is cut back to the rows synced before).
        """
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
        Not a results file of this kind, not a regular file, a symbolic link, too large, or not
        readable/writable.
    """
    path = os.fspath(path)
    fmt = results_format(path)
    if not sync_seconds >= 0:
        raise UsageError(f"Expected `sync_seconds` >= 0, got {sync_seconds}")
    if os.path.islink(path):                             # even a dangling one: it would create its target
        raise UsageError(f"{path}: is a symbolic link; refusing to write results through it (name the file it "
                         "points to)")
    if os.path.exists(path) and not os.path.isfile(path):
        raise UsageError(f"{path}: exists and is not a regular file")
    flags = (os.O_RDWR | os.O_CREAT | os.O_APPEND | getattr(os, "O_BINARY", 0) | getattr(os, "O_CLOEXEC", 0)
             | getattr(os, "O_NOFOLLOW", 0))
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        if os.path.islink(path):                         # made a link between the check above and the open
            raise UsageError(f"{path}: is a symbolic link; refusing to write results through it") from None
        raise UsageError(f"{path}: cannot write the results file ({exc.strerror or exc})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):                 # replaced between the check above and the open
            raise UsageError(f"{path}: exists and is not a regular file")
        _lock(fd, path)
        size = os.fstat(fd).st_size
        if size > max_bytes:
            raise UsageError(f"{path}: {size:,} bytes, more than the {max_bytes:,} a results file may have here")
        data = os.pread(fd, size, 0) if hasattr(os, "pread") else _read_from_start(fd, size)
        rows, torn = read_rows(data, fmt, path)
        if torn:
            os.ftruncate(fd, size - torn)
        if fmt == "csv" and size - torn == 0:
            try:
                _write_all(fd, (",".join(ROW_FIELDS) + "\n").encode())
                os.fsync(fd)
            except OSError:
                os.ftruncate(fd, 0)                      # no half header left behind
                raise
        os.fsync(fd)
        end = os.fstat(fd).st_size
        layout = SCHEMA
        for schema, fields in ((SCHEMA_V2, ROW_FIELDS_V2), (SCHEMA_V1, ROW_FIELDS_V1)):
            old_header = (",".join(fields) + "\n").encode()
            if fmt == "csv" and data[:len(old_header)] == old_header:
                layout = schema
    except UsageError:
        os.close(fd)
        raise
    except OSError as exc:
        os.close(fd)
        raise UsageError(f"{path}: cannot use the results file ({exc.strerror or exc})") from None
    _OPEN_FDS.add(fd)
    return ResultsFile(path=path, format=fmt, previous_rows=rows, torn_bytes=torn, sync_seconds=float(sync_seconds),
                       layout=layout, _fd=fd, _synced=time.monotonic(), _size=end, _synced_size=end)


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
