"""Results files of ``batch`` (inertia_tool.batch.rows): never a lost row (issue 22, item 4).

Damage before the last record is refused with its line number, never cut; only a torn final record is cut; rows
holding NaN or Infinity are computed again; line length and JSON nesting are bounded; a write error (a full
disk) leaves complete rows only and stops with exit code 2, and the same command then resumes.
"""

import errno
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import write_binary_stl
from inertia_tool.batch import rows as rows_mod
from inertia_tool.batch.rows import (MAX_LINE_BYTES, ResultsFileDamaged, ResultsFileWriteError, format_row,
                                     open_results, read_rows)
from inertia_tool.batch.runner import ROW_FIELDS, SCHEMA, counts_as_done
from inertia_tool.cli import main
from inertia_tool.errors import UsageError

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = {**os.environ, "PYTHONPATH": ROOT}
HEADER = (",".join(ROW_FIELDS) + "\n").encode()


def _row(k, path=None, **extra):
    row = dict.fromkeys(ROW_FIELDS)
    row.update(schema=SCHEMA, path=path if path is not None else f"/parts/p{k}.stl", status="ok",
               sha256=f"{k:064x}", options_key="0123456789abcdef", mesh_length_unit="m", density=1000.0,
               density_source="1000 kg/m³ (default: water, give a density)", mass=1.5 + k, faces=12, bodies=1,
               cavities=0, watertight=True, repaired=False, assumptions="none", seconds=0.001, worker="host:1")
    for name in ("volume", "surface_area", "com_x", "com_y", "com_z", "ixx", "iyy", "izz", "ixy", "ixz", "iyz",
                 "i1", "i2", "i3", *(f"axis{a}_{c}" for a in (1, 2, 3) for c in "xyz")):
        row[name] = 0.25 * k - 1.0
    row.update(extra)
    return row


def _file(rows, fmt):
    return (HEADER if fmt == "csv" else b"") + b"".join(format_row(r, fmt) for r in rows)


def _boxes(directory, n):
    directory.mkdir()
    m = trimesh.creation.box((1, 2, 3))
    for k in range(n):
        write_binary_stl(directory / f"b{k}.stl", np.asarray(m.vertices) * (1 + 0.1 * k), m.faces)
    return directory


def _cli(*args, timeout=300):
    """``inertia-tool ARGS`` in a child process, with a timeout so that a hang fails instead of hanging CI."""
    return subprocess.run([sys.executable, "-m", "inertia_tool.cli", *map(str, args)], env=ENV,
                          capture_output=True, text=True, timeout=timeout)


# -- damage in the middle: refused with its line number, nothing cut ------------------------------------------

@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
@pytest.mark.parametrize("offset", [0, 1, 5, 22, 60, 90, 150, -30, -2])
def test_stray_quote_in_the_middle_is_refused_with_its_line_number_issue22(tmp_path, fmt, offset):
    """Issue 22: one stray quote in a CSV made the reader treat the rest as a torn tail: 1,750 of 2,000 rows cut."""
    rows = [_row(k) for k in range(2000)]
    records = [format_row(r, fmt) for r in rows]
    data = bytearray(_file(rows, fmt))
    start = (len(HEADER) if fmt == "csv" else 0) + sum(map(len, records[:250]))
    at = start + (offset % len(records[250]))
    data[at:at] = b'"'
    out = tmp_path / f"r.{fmt}"
    out.write_bytes(bytes(data))
    line = 251 + (fmt == "csv")
    with pytest.raises(ResultsFileDamaged, match=rf"r\.{fmt}: line {line}\b"):
        open_results(out)
    assert out.read_bytes() == bytes(data)                     # nothing cut, nothing written


@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_cli_refuses_a_damaged_results_file_in_one_line_exit_2(tmp_path, fmt):
    d = _boxes(tmp_path / "parts", 3)
    out = tmp_path / f"r.{fmt}"
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0
    lines = out.read_bytes().splitlines(keepends=True)
    lines[-2] = lines[-2][:40] + b"\n"                           # a torn line in the middle: a row follows it
    damaged = b"".join(lines)
    out.write_bytes(damaged)
    done = _cli("batch", d, "--out", out, "-q")
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and str(out) in err[0] and f"line {len(lines) - 1} " in err[0]
    assert "refusing to resume" in err[0] and "Traceback" not in done.stderr
    assert out.read_bytes() == damaged


@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_torn_final_line_is_still_cut_and_only_it(fmt):
    rows = [_row(k, path=f"/a\nb,\"c\"/{k}.stl") for k in range(5)]
    whole = _file(rows, fmt)
    last = format_row(rows[-1], fmt)
    for cut in range(1, len(last)):
        got, torn = read_rows(whole[:len(whole) - cut], fmt, "r")
        assert got == rows[:-1] and torn == len(last) - cut


def test_a_record_that_never_ends_and_holds_rows_is_refused_not_cut():
    rows = [_row(k) for k in range(50)]
    data = _file(rows[:10], "csv") + b'inertia_tool.batch/1,"/x' + _file(rows[10:], "csv")[len(HEADER):]
    with pytest.raises(ResultsFileDamaged, match=r"line 12 starts a record that never ends .* 39 more row"):
        read_rows(data, "csv", "r.csv")


def test_deep_json_line_is_refused_with_its_line_number_not_an_internal_error(tmp_path):
    """Issue 22: a 100,000-deep JSON line was an internal error (RecursionError)."""
    deep = b'{"schema": "inertia_tool.batch/1", "path": ' + b"[" * 100_000 + b"]" * 100_000 + b"}\n"
    out = tmp_path / "r.jsonl"
    good = _file([_row(0), _row(1)], "jsonl")
    out.write_bytes(good[:len(good) // 2 + 1].split(b"\n")[0] + b"\n" + deep + good)
    with pytest.raises(ResultsFileDamaged, match=r"line 2 is not a flat JSON object"):
        open_results(out)
    done = _cli("batch", _boxes(tmp_path / "parts", 1), "--out", out, "-q")
    assert done.returncode == 2 and "line 2 is not a flat JSON object" in done.stderr
    assert "internal error" not in done.stderr


@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_overlong_line_is_refused_with_its_line_number(fmt):
    data = _file([_row(0)], fmt) + b"x" * (MAX_LINE_BYTES + 1) + b"\n" + _file([_row(1)], fmt)[
        len(HEADER) if fmt == "csv" else 0:]
    line = 2 + (fmt == "csv")
    with pytest.raises(ResultsFileDamaged, match=rf"line {line} holds {MAX_LINE_BYTES + 1:,} bytes"):
        read_rows(data, fmt, "r")


def test_csv_cell_holding_an_unquoted_quote_is_refused():
    record = format_row(_row(3), "csv").replace(b"/parts/p3.stl", b'/parts/p"3.stl')
    with pytest.raises(ResultsFileDamaged, match=r"line 2 is not quoted as inertia-tool writes it"):
        read_rows(HEADER + record + format_row(_row(4), "csv"), "csv", "r.csv")


# -- non-finite values: not done ---------------------------------------------------------------------------

@pytest.mark.parametrize("fmt,nan,inf", [("csv", b"nan", b"inf"), ("jsonl", b"NaN", b"Infinity")])
def test_rows_holding_nan_or_infinity_are_computed_again_issue22(tmp_path, fmt, nan, inf):
    """Issue 22: rows holding NaN or Infinity counted as done forever."""
    d = _boxes(tmp_path / "parts", 4)
    out = tmp_path / f"r.{fmt}"
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0
    before = open_results(out)
    rows = before.previous_rows
    before.close()
    mass = [repr(r["mass"]).encode() for r in rows]
    data = out.read_bytes()
    for k, bad in ((0, nan), (2, inf)):
        assert data.count(mass[k]) == 1
        data = data.replace(mass[k], bad)
    out.write_bytes(data)
    with open_results(out) as r:
        assert [counts_as_done(row) for row in r.previous_rows] == [False, True, False, True]
    done = _cli("batch", d, "--out", out)
    assert done.returncode == 0 and "2 ok, 0 failed in this run; 2 done before" in done.stderr
    with open_results(out) as r:
        fresh = r.previous_rows[4:]
    assert {row["path"]: row["mass"] for row in fresh} == {rows[k]["path"]: rows[k]["mass"] for k in (0, 2)}


def test_counts_as_done_requires_every_number_of_an_ok_row():
    assert counts_as_done(_row(1))
    assert not counts_as_done(_row(1, mass=None))
    assert not counts_as_done(_row(1, ixx="1.0"))
    assert not counts_as_done(_row(1, seconds=float("inf")))
    assert counts_as_done(_row(1, status="error", mass=None))
    assert not counts_as_done(_row(1, status="internal_error"))


# -- hypothesis: a damaged file gives every intact row, or a refusal with a line number ----------------------

_names = st.text(alphabet=st.sampled_from('ab,"\n\r x/é'), min_size=1, max_size=12)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fmt=st.sampled_from(["csv", "jsonl"]), names=st.lists(_names, min_size=1, max_size=8),
       kind=st.sampled_from(["insert", "delete", "truncate"]), where=st.floats(0, 1),
       junk=st.binary(min_size=1, max_size=6) | st.sampled_from([b'"', b"\n", b",", b'""', b"\r\n", b"{", b"["]),
       span=st.integers(1, 40))
def test_damaged_results_file_never_drops_an_intact_row(fmt, names, kind, where, junk, span):
    rows = [_row(k, path=f"/p/{name}/{k}.stl") for k, name in enumerate(names)]
    head = HEADER if fmt == "csv" else b""
    records = [format_row(r, fmt) for r in rows]
    data = head + b"".join(records)
    assert read_rows(data, fmt, "r") == (rows, 0)             # undamaged: every row back
    at = len(head) + int(where * (len(data) - len(head)))
    if kind == "insert":
        damaged, lo, hi = data[:at] + junk + data[at:], at, at
    elif kind == "delete":
        damaged, lo, hi = data[:at] + data[at + span:], at, min(at + span, len(data))
    else:
        damaged, lo, hi = data[:at], at, len(data)
    # a row is intact when the damage is outside its bytes (an insertion on its boundary leaves it whole)
    intact, pos = [], len(head)
    for row, record in zip(rows, records):
        end = pos + len(record)
        if end <= lo or pos >= hi:
            intact.append(row)
        pos = end
    try:
        got, torn = read_rows(damaged, fmt, "r")
    except ResultsFileDamaged as exc:
        assert " line " in str(exc)
        return
    except UsageError as exc:                   # the damage hit the start: not recognisably ours any more
        assert "not a results file" in str(exc) or "header" in str(exc)
        return
    for row in intact:
        assert row in got, f"intact row {row['path']!r} dropped ({kind} at {at}; torn={torn})"
    assert torn <= len(damaged) - len(head)


# -- write errors: complete rows only, exit 2, then resume -----------------------------------------------------

@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_full_disk_while_writing_leaves_complete_rows_and_resumes(tmp_path, monkeypatch, capsys, fmt):
    """Issue 22: a full disk during batch was an internal error (exit 1)."""
    d = _boxes(tmp_path / "parts", 5)
    out = tmp_path / f"r.{fmt}"
    real = rows_mod._write_all
    calls = []

    def disk_fills(fd, data):
        calls.append(len(data))
        if len(calls) == 3 + (fmt == "csv"):         # the third row: half of it lands, then ENOSPC
            os.write(fd, data[:len(data) // 2])
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(fd, data)

    monkeypatch.setattr(rows_mod, "_write_all", disk_fills)
    capsys.readouterr()
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(out) in err[0] and "No space left on device" in err[0]
    assert "run the same command again to resume" in err[0]
    with open_results(out) as r:
        assert len(r.previous_rows) == 2 and r.torn_bytes == 0       # complete rows only: nothing torn
    monkeypatch.setattr(rows_mod, "_write_all", real)
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0
    with open_results(out) as r:
        paths = [row["path"] for row in r.previous_rows]
    assert sorted(paths) == sorted(str(p) for p in d.glob("*.stl"))


def test_failed_fsync_cuts_back_to_the_rows_synced_before(tmp_path, monkeypatch):
    out = tmp_path / "r.jsonl"
    r = open_results(out, sync_seconds=3600)
    r.write_row(_row(0))
    r.sync()
    r.write_row(_row(1))
    r.write_row(_row(2))

    def eio(fd):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(rows_mod.os, "fsync", eio)
    with pytest.raises(ResultsFileWriteError, match="Input/output error"):
        r.close()
    monkeypatch.undo()
    assert read_rows(out.read_bytes(), "jsonl", "r") == ([_row(0)], 0)


_LIMITED_BATCH = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)           # a write past the limit fails with EFBIG instead
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
from inertia_tool.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.skipif(not hasattr(os, "setrlimit") and sys.platform != "linux", reason="needs RLIMIT_FSIZE")
@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_file_size_limit_from_the_kernel_leaves_complete_rows_and_resumes(tmp_path, fmt):
    """A real short write and a real error from the kernel (RLIMIT_FSIZE: EFBIG), not a monkeypatch."""
    d = _boxes(tmp_path / "parts", 6)
    full = tmp_path / f"full.{fmt}"
    assert main(["batch", str(d), "--out", str(full), "-q"]) == 0
    limit = len(full.read_bytes()) // 2                       # the run stops in the middle of a row
    out = tmp_path / f"r.{fmt}"
    script = tmp_path / "limited.py"
    script.write_text(_LIMITED_BATCH)
    done = subprocess.run([sys.executable, str(script), str(limit), "batch", str(d), "--out", str(out), "-q"],
                          env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert "File too large" in done.stderr and "internal error" not in done.stderr
    data = out.read_bytes()
    assert 0 < len(data) <= limit
    got, torn = read_rows(data, fmt, "r")
    assert torn == 0 and 1 <= len(got) < 6
    again = _cli("batch", d, "--out", out)
    assert again.returncode == 0, again.stderr
    assert f"; {len(got)} done before;" in again.stderr
    with open_results(out) as r:
        assert sorted(row["path"] for row in r.previous_rows) == sorted(str(p) for p in d.glob("*.stl"))


def test_json_rows_round_trip_flat_check_accepts_brackets_inside_strings():
    row = _row(7, path='/p/[a]{b}"c"\\d.stl', warnings="x [y] {z}")
    assert read_rows(format_row(row, "jsonl"), "jsonl", "r") == ([row], 0)
    assert json.loads(format_row(row, "jsonl"))["path"] == row["path"]


@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_file_name_with_a_lone_carriage_return_round_trips(tmp_path, fmt):
    """Found by the fuzzing above: Python 3.11's csv writer left a cell holding a lone CR unquoted, and its
    reader then refused the record, so a results file with such a file name could not be resumed."""
    d = tmp_path / "parts"
    d.mkdir()
    m = trimesh.creation.box((1, 2, 3))
    for name in ("a\rb.stl", "c\r.stl", "plain.stl"):
        write_binary_stl(d / name, m.vertices, m.faces)
    out = tmp_path / f"r.{fmt}"
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0
    with open_results(out) as r:
        assert sorted(row["path"] for row in r.previous_rows) == sorted(str(p) for p in d.iterdir())
    done = _cli("batch", d, "--out", out)
    assert done.returncode == 0 and "nothing new; 3 done before" in done.stderr


@pytest.mark.parametrize("dangling", [True, False])
def test_results_path_that_is_a_symbolic_link_is_refused_exit_2(tmp_path, dangling):
    # review of issue 22: `res.jsonl -> elsewhere.jsonl` created (or appended to) the link's target
    target = tmp_path / "elsewhere.jsonl"
    if not dangling:
        target.write_bytes(b"")
    link = tmp_path / "res.jsonl"
    link.symlink_to(target)
    with pytest.raises(UsageError, match="res.jsonl: is a symbolic link"):
        open_results(link)
    d = _boxes(tmp_path / "parts", 1)
    done = _cli("batch", d, "--out", link, "-q")
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and "symbolic link" in err[0] and "Traceback" not in done.stderr
    assert target.exists() != dangling and (dangling or target.read_bytes() == b"")
    assert link.is_symlink()


def _format_row_before(row, fmt, layout=SCHEMA):
    """``format_row`` as it was before its fast paths (a new JSON encoder per row, every cell searched for a
    delimiter): the reference its output must equal byte for byte."""
    from inertia_tool.batch.runner import ROW_FIELDS_V1, ROW_FIELDS_V2, SCHEMA_V1, SCHEMA_V2, downgrade_row
    if layout != SCHEMA:
        row = downgrade_row(row, layout)
    fields = {SCHEMA: ROW_FIELDS, SCHEMA_V2: ROW_FIELDS_V2, SCHEMA_V1: ROW_FIELDS_V1}[layout]
    if fmt == "jsonl":
        line = json.dumps({k: row.get(k) for k in fields}, ensure_ascii=False, allow_nan=False) + "\n"
    else:
        def cell(value):
            if value is None:
                text = ""
            elif isinstance(value, bool):
                text = "true" if value else "false"
            elif isinstance(value, float):
                text = repr(value)
            else:
                text = str(value)
            return '"' + text.replace('"', '""') + '"' if any(c in text for c in ',"\n\r') else text
        line = ",".join(cell(row.get(k)) for k in fields) + "\n"
    return line.encode("utf-8", "backslashreplace")


_cell_values = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                         st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=12))


@given(fmt=st.sampled_from(["csv", "jsonl"]), k=st.integers(0, 50), path=_names,
       cells=st.dictionaries(st.sampled_from(ROW_FIELDS), _cell_values, max_size=12),
       shuffle=st.booleans(), extra=st.booleans(), old_layout=st.sampled_from([None, 1, 2]))
@settings(max_examples=200, deadline=None)
def test_format_row_writes_the_bytes_it_wrote_before(fmt, k, path, cells, shuffle, extra, old_layout):
    """The row formatter's fast paths (one JSON encoder, a row in column order written as it is, numbers never
    searched for a delimiter) write exactly the bytes of the plain formatter, for rows in or out of column
    order, with a missing or an extra key, and in the old CSV layouts."""
    from inertia_tool.batch.runner import SCHEMA_V1, SCHEMA_V2
    row = _row(k, path=path)
    row.update(cells)
    if shuffle:
        row = dict(reversed(list(row.items())))
    if extra:
        row["not_a_column"] = "x"
        row.pop("worker")
    layout = {1: SCHEMA_V1, 2: SCHEMA_V2}.get(old_layout, SCHEMA) if fmt == "csv" else SCHEMA
    assert format_row(row, fmt, layout) == _format_row_before(row, fmt, layout)
