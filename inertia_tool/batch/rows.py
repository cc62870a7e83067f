"""Append-only result files of ``inertia-tool batch``: JSON Lines or CSV, one row per file.

Crash safety: each row is written as one complete line, then flushed and ``fsync``'d, so a killed run leaves
at most one torn last line.  :func:`open_results` reads an existing file back (for resuming), cuts a torn
last line off (the file then ends with a complete row again) and refuses a file that is not a previous
result file of the same kind, so that ``--out`` never clobbers unrelated data.

Columns are :data:`inertia_tool.batch.runner.ROW_FIELDS`.  In CSV, empty cells are missing values (``None`` in
JSON); booleans are ``true``/``false``; text is kept on one line by the batch engine.
"""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass
from typing import BinaryIO

from .runner import ROW_FIELDS, SCHEMA
from ..errors import UsageError

__all__ = ["ResultsFile", "open_results", "results_format", "FORMATS"]

#: Output formats by file suffix.
FORMATS = {".jsonl": "jsonl", ".ndjson": "jsonl", ".csv": "csv"}

_INT_FIELDS = {"faces", "bodies", "cavities"}
_BOOL_FIELDS = {"watertight", "repaired"}
_TEXT_FIELDS = {"schema", "path", "status", "error_type", "error", "sha256", "options_key", "units",
                "density_source", "warnings", "worker"}


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


def _parse_jsonl(lines: list[bytes], path: str) -> list[dict]:
    rows = []
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except ValueError:
            raise UsageError(f"{path}: line {n} is not JSON; not a results file of inertia-tool batch "
                             "(refusing to append to it; choose another results file)") from None
        if not isinstance(row, dict) or row.get("schema") != SCHEMA:
            raise UsageError(f"{path}: line {n} is not a row of schema {SCHEMA}; not a results file of "
                             "inertia-tool batch (refusing to append to it; choose another results file)")
        rows.append(row)
    return rows


def _parse_csv(lines: list[bytes], path: str) -> list[dict]:
    if not lines:
        return []
    text = b"".join(lines).decode("utf-8", errors="replace")
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    if header != list(ROW_FIELDS):
        raise UsageError(f"{path}: its header is not the inertia-tool batch header ({SCHEMA}); not a results "
                         "file of this kind (refusing to append to it; choose another results file)")
    rows = []
    for n, cells in enumerate(reader, 2):
        if not cells:
            continue
        if len(cells) != len(ROW_FIELDS) or cells[0] != SCHEMA:
            raise UsageError(f"{path}: line {n} has {len(cells)} cells, expected {len(ROW_FIELDS)} "
                             f"({SCHEMA}); refusing to append to it")
        try:
            rows.append({k: _csv_value(k, v) for k, v in zip(ROW_FIELDS, cells)})
        except ValueError as exc:
            raise UsageError(f"{path}: line {n}: {exc}; refusing to append to it") from None
    return rows


def _complete_lines(path: str, data: bytes, fmt: str) -> tuple[list[bytes], int, bool]:
    """Split into complete lines; return them, the byte length they cover, and whether a torn tail was cut.

    A last line without its newline is torn (rows are written with their newline in one call).  So is a
    JSONL last line that does not parse even though it ends in a newline (a partly flushed block).
    """
    keep = data.rfind(b"\n") + 1
    torn = keep < len(data)
    lines = data[:keep].splitlines(keepends=True)
    if fmt == "jsonl" and lines:
        last = lines[-1]
        try:
            json.loads(last)
        except ValueError:
            if len(lines) > 1 or not last.strip():
                keep -= len(last)
                lines = lines[:-1]
                torn = True
    return lines, keep, torn


@dataclass
class ResultsFile:
    """An open, append-only results file.

    Attributes
    ----------
    path : str
    format : str
        ``"jsonl"`` or ``"csv"``.
    previous_rows : list of dict
        Rows already in the file when it was opened (for resuming).
    repaired_tail : bool
        True when a torn last line (a killed run) was cut off on opening.
    """

    path: str
    format: str
    previous_rows: list
    repaired_tail: bool
    _fh: BinaryIO | None = None

    def write_row(self, row: dict) -> None:
        """Append one row as one line, flush and fsync (so a crash loses at most the row being written)."""
        if self.format == "jsonl":
            line = json.dumps({k: row.get(k) for k in ROW_FIELDS}, ensure_ascii=False, allow_nan=False)
        else:
            buf = io.StringIO()
            csv.writer(buf, lineterminator="").writerow([_csv_cell(row.get(k)) for k in ROW_FIELDS])
            line = buf.getvalue()
        if self._fh is None:
            raise ValueError(f"{self.path}: the results file is closed")
        self._fh.write((line + "\n").encode("utf-8"))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self) -> None:
        """Close the file."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def __enter__(self) -> "ResultsFile":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def open_results(path: str | os.PathLike, *, max_bytes: int = 4 << 30) -> ResultsFile:
    """Open ``path`` for appending rows, reading back what a previous run wrote.

    A new file gets the CSV header (CSV) or nothing (JSONL).  An existing file must be a results file of the
    same format and schema, else :class:`UsageError` (it is left untouched).  A torn last line is cut off.

    Parameters
    ----------
    path : str or path
        ``*.jsonl`` / ``*.ndjson`` or ``*.csv``.
    max_bytes : int
        Refuse to read back a larger existing file.
    """
    path = os.fspath(path)
    fmt = results_format(path)
    data = b""
    if os.path.exists(path):
        if not os.path.isfile(path):
            raise UsageError(f"{path}: exists and is not a regular file")
        size = os.path.getsize(path)
        if size > max_bytes:
            raise UsageError(f"{path}: {size:,} bytes, more than the {max_bytes:,} a results file may have here")
        try:
            with open(path, "rb") as existing:
                data = existing.read()
        except OSError as exc:
            raise UsageError(f"{path}: cannot read the results file ({exc.strerror or exc})") from None
    lines, keep, torn = _complete_lines(path, data, fmt)
    rows = _parse_jsonl(lines, path) if fmt == "jsonl" else _parse_csv(lines, path)
    if fmt == "csv" and data and not lines:
        # only a torn header: nothing of ours to keep, but it must look like the start of our header
        if not ",".join(ROW_FIELDS).encode().startswith(data.strip()):
            raise UsageError(f"{path}: not a results file of inertia-tool batch; refusing to append to it")
    try:
        fh: BinaryIO = open(path, "r+b" if data else "wb")
    except OSError as exc:
        raise UsageError(f"{path}: cannot write the results file ({exc.strerror or exc})") from None
    try:
        if torn:
            fh.truncate(keep)
        fh.seek(keep)
        if fmt == "csv" and keep == 0:
            fh.write((",".join(ROW_FIELDS) + "\n").encode())
            fh.flush()
            os.fsync(fh.fileno())
    except OSError as exc:
        fh.close()
        raise UsageError(f"{path}: cannot write the results file ({exc.strerror or exc})") from None
    return ResultsFile(path=path, format=fmt, previous_rows=rows, repaired_tail=torn, _fh=fh)
