"""Batch engine (inertia_tool.batch.runner), result files (reports.rows) and the ``batch`` command."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import trimesh

from conftest import kill_after_lines, write_binary_stl
from inertia_tool.mesh import LoadOptions
from inertia_tool.batch import runner as batch_mod
from inertia_tool import mass_properties
from inertia_tool.batch.runner import (ROW_FIELDS, SCHEMA, BatchOptions, analyze_file, discover_files, file_sha256,
                                run_batch)
from inertia_tool.cli import main
from inertia_tool.errors import UsageError
from inertia_tool.batch.rows import open_results

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _box_file(path, extents, center=(0.0, 0.0, 0.0)):
    m = trimesh.creation.box(extents)
    write_binary_stl(path, np.asarray(m.vertices) + np.asarray(center), m.faces)
    return str(path)


@pytest.fixture
def parts(tmp_path):
    """Four boxes (mm) with closed-form properties and one corrupt file."""
    d = tmp_path / "parts"
    d.mkdir()
    boxes = {}
    for k, ext in enumerate([(10, 20, 30), (5, 5, 5), (40, 10, 2), (8, 16, 4)]):
        boxes[_box_file(d / f"box{k}.stl", ext, center=(k, 2 * k, 0))] = ext
    bad = d / "sub" / "corrupt.stl"
    bad.parent.mkdir()
    bad.write_bytes(b"\x00" * 80 + (1000).to_bytes(4, "little") + b"\x01" * 100)   # claims 1000 faces, holds 2
    (d / "notes.txt").write_text("not a mesh")
    return d, boxes, str(bad)


def _box_inertia(mass, a, b, c):
    return mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def _rows(path):
    with open_results(path) as r:
        return r.previous_rows


def test_discover_files_recurses_filters_suffixes_and_sorts(parts):
    d, boxes, bad = parts
    found = discover_files(d)
    assert found == sorted(list(boxes) + [bad])
    assert discover_files(str(d / "box*.stl")) == sorted(boxes)
    with pytest.raises(UsageError):
        discover_files(str(d / "*.nothing"))


def test_analyze_file_box_closed_form(parts):
    d, boxes, _ = parts
    path = next(iter(boxes))
    a, b, c = (x * 1e-3 for x in boxes[path])
    row = analyze_file(path, BatchOptions(load=LoadOptions(units="mm"), density=1240.0))
    assert set(row) == set(ROW_FIELDS)
    assert row["status"] == "ok" and row["schema"] == SCHEMA
    mass = 1240.0 * a * b * c
    assert row["mass"] == pytest.approx(mass, rel=1e-6)       # float32 STL coordinates
    np.testing.assert_allclose([row["ixx"], row["iyy"], row["izz"]], _box_inertia(mass, a, b, c), rtol=1e-5)
    np.testing.assert_allclose(sorted([row["ixx"], row["iyy"], row["izz"]]), [row["i1"], row["i2"], row["i3"]],
                               rtol=1e-9)
    np.testing.assert_allclose([row["com_x"], row["com_y"], row["com_z"]], [0, 0, 0], atol=1e-9)
    assert row["sha256"] == file_sha256(path)
    assert row["faces"] == 12 and row["watertight"] is True


def test_corrupt_file_is_an_error_row_and_the_batch_goes_on(parts):
    d, boxes, bad = parts
    rows = []
    summary = run_batch(discover_files(d), BatchOptions(load=LoadOptions(units="mm")), rows.append)
    assert summary.ok == 4 and summary.failed == 1 and summary.skipped == 0
    by_path = {r["path"]: r for r in rows}
    assert by_path[bad]["status"] == "error" and by_path[bad]["error_type"] == "MeshReadError"
    assert "1,000" in by_path[bad]["error"] or "1000" in by_path[bad]["error"]
    assert by_path[bad]["mass"] is None
    expected = sum(1000.0 * np.prod(np.array(e) * 1e-3) for e in boxes.values())
    assert summary.total_mass == pytest.approx(expected, rel=1e-6)


def test_unexpected_exception_becomes_internal_error_row(parts, monkeypatch):
    d, boxes, _ = parts

    def explode(*a, **k):
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(batch_mod, "mass_properties", explode)
    rows = []
    summary = run_batch(sorted(boxes), BatchOptions(), rows.append)
    assert summary.failed == 4
    assert all(r["status"] == "internal_error" and r["error"] == "boom second line" for r in rows)


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_resume_skips_done_files_by_hash_and_options(parts, tmp_path, suffix):
    d, boxes, bad = parts
    out = tmp_path / f"results.{suffix}"
    files = discover_files(d)
    opts = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    with open_results(out) as r:
        first = run_batch(files, opts, r.write_row, previous_rows=r.previous_rows)
    assert (first.ok, first.failed, first.skipped) == (4, 1, 0)
    with open_results(out) as r:
        second = run_batch(files, opts, r.write_row, previous_rows=r.previous_rows)
    assert (second.ok, second.failed, second.skipped, second.skipped_failed) == (0, 0, 5, 1)
    assert second.total_mass == pytest.approx(first.total_mass, rel=1e-12)
    # change one file's content (same path): only it is recomputed
    changed = sorted(boxes)[1]
    _box_file(changed, (6, 6, 6))
    with open_results(out) as r:
        third = run_batch(files, opts, r.write_row, previous_rows=r.previous_rows)
    assert (third.ok, third.skipped) == (1, 4)
    # a changed option that affects the numbers recomputes everything
    with open_results(out) as r:
        fourth = run_batch(files, BatchOptions(load=LoadOptions(units="mm"), density=7850.0), r.write_row,
                           previous_rows=r.previous_rows)
    assert (fourth.ok, fourth.failed, fourth.skipped) == (4, 1, 0)
    rows = _rows(out)
    assert len(rows) == 5 + 1 + 5
    latest = [r for r in rows if r["path"] == changed and r["density"] == 1240.0][-1]
    assert latest["mass"] == pytest.approx(1240.0 * 0.006 ** 3, rel=1e-6)


def test_internal_error_rows_are_retried(parts, tmp_path, monkeypatch):
    d, boxes, _ = parts
    out = tmp_path / "r.jsonl"
    files = sorted(boxes)
    original = batch_mod.mass_properties
    monkeypatch.setattr(batch_mod, "mass_properties", lambda *a, **k: (_ for _ in ()).throw(MemoryError()))
    with open_results(out) as r:
        assert run_batch(files, BatchOptions(), r.write_row, previous_rows=r.previous_rows).failed == 4
    monkeypatch.setattr(batch_mod, "mass_properties", original)
    with open_results(out) as r:
        again = run_batch(files, BatchOptions(), r.write_row, previous_rows=r.previous_rows)
    assert (again.ok, again.skipped) == (4, 0)


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_round_trip_keeps_every_value(parts, tmp_path, suffix):
    d, boxes, _ = parts
    out = tmp_path / f"r.{suffix}"
    rows = []
    with open_results(out) as r:
        def write(row):
            rows.append(row)
            r.write_row(row)
        run_batch(discover_files(d), BatchOptions(load=LoadOptions(units="mm"), material="pla"), write)
    back = _rows(out)
    assert back == rows          # floats written with repr(): bit-exact


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_torn_last_line_is_cut_and_the_run_completes(parts, tmp_path, suffix):
    d, boxes, _ = parts
    out = tmp_path / f"r.{suffix}"
    files = sorted(boxes)
    with open_results(out) as r:
        run_batch(files[:2], BatchOptions(), r.write_row)
    whole = out.read_bytes()
    # simulate a kill in the middle of writing the third row
    row3 = analyze_file(files[2], BatchOptions())
    with open_results(tmp_path / f"tmp.{suffix}") as t:
        t.write_row(row3)
    line = (tmp_path / f"tmp.{suffix}").read_bytes().splitlines(keepends=True)[-1]
    out.write_bytes(whole + line[: len(line) // 2])
    with open_results(out) as r:
        assert r.repaired_tail and len(r.previous_rows) == 2
        summary = run_batch(files, BatchOptions(), r.write_row, previous_rows=r.previous_rows)
    assert (summary.ok, summary.skipped) == (2, 2)
    rows = _rows(out)
    assert sorted(r["path"] for r in rows) == files
    assert out.read_bytes().startswith(whole) and out.read_bytes().endswith(b"\n")


def test_jsonl_torn_block_ending_in_newline_is_cut(tmp_path, parts):
    d, boxes, _ = parts
    out = tmp_path / "r.jsonl"
    with open_results(out) as r:
        run_batch(sorted(boxes)[:1], BatchOptions(), r.write_row)
    out.write_bytes(out.read_bytes() + b'{"schema": "inertia_tool.ba\n')
    with open_results(out) as r:
        assert r.repaired_tail and len(r.previous_rows) == 1


@pytest.mark.parametrize("name,content", [
    ("other.jsonl", b'{"name": "not ours"}\n'),
    ("other.jsonl", b"hello world\n"),
    ("other.csv", b"a,b,c\n1,2,3\n"),
    ("other.csv", b"x"),
])
def test_refuses_a_file_that_is_not_a_results_file(tmp_path, name, content):
    out = tmp_path / name
    out.write_bytes(content)
    with pytest.raises(UsageError, match="refusing|not a results file"):
        open_results(out)
    assert out.read_bytes() == content


def test_refuses_the_other_format_and_unknown_suffix(tmp_path, parts):
    d, boxes, _ = parts
    csv_named_jsonl = tmp_path / "r.jsonl"
    with open_results(tmp_path / "r.csv") as r:
        run_batch(sorted(boxes)[:1], BatchOptions(), r.write_row)
    csv_named_jsonl.write_bytes((tmp_path / "r.csv").read_bytes())
    with pytest.raises(UsageError):
        open_results(csv_named_jsonl)
    with pytest.raises(UsageError, match=".jsonl or .csv"):
        open_results(tmp_path / "r.txt")


def test_process_pool_gives_the_same_rows_as_in_process(parts):
    d, boxes, _ = parts
    files = discover_files(d)
    one, two = [], []
    s1 = run_batch(files, BatchOptions(load=LoadOptions(units="mm")), one.append, jobs=1)
    s2 = run_batch(files, BatchOptions(load=LoadOptions(units="mm")), two.append, jobs=2, max_in_flight=2)
    assert (s1.ok, s1.failed) == (s2.ok, s2.failed) == (4, 1)
    strip = lambda r: {k: v for k, v in r.items() if k not in ("seconds", "worker")}  # noqa: E731
    assert sorted(map(json.dumps, map(strip, one))) == sorted(map(json.dumps, map(strip, two)))
    assert len({r["worker"] for r in two}) >= 1


def test_row_numbers_match_mass_properties(parts):
    d, boxes, _ = parts
    path = sorted(boxes)[3]
    row = analyze_file(path, BatchOptions(load=LoadOptions(units="mm"), mass=0.25))
    props = mass_properties(path, units="mm", mass=0.25)
    assert row["mass"] == pytest.approx(0.25, rel=1e-12)
    np.testing.assert_allclose(np.array([[row[f"axis{k}_{c}"] for k in (1, 2, 3)] for c in "xyz"]),
                               props.principal.axes, atol=1e-12)


def test_cli_batch_summary_exit_codes_and_resume(parts, tmp_path, capsys):
    d, boxes, bad = parts
    out = tmp_path / "res.csv"
    code = main(["batch", str(d), "--units", "mm", "--density", "1240", "--out", str(out), "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 3
    assert "5 files: 4 ok, 1 failed in this run;" in err and "files/s" in err and "corrupt.stl" in err
    code = main(["batch", str(d / "box*.stl"), "--units", "mm", "--density", "1240", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 0 and "4 files: nothing new; 4 done before" in err
    assert main(["batch", str(d), "--out", str(tmp_path / "x.txt")]) == 2
    assert main(["batch", str(d), "--out", str(out), "--jobs", "0"]) == 2


def test_progress_plain_lines_when_not_a_terminal():
    import io

    from inertia_tool.cli.batch import Progress
    buf = io.StringIO()
    p = Progress(buf, interval=3600)
    for k in range(1, 11):
        p(k, 10, k, 0)
    p.close()
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("batch: 1/10") and lines[-1].startswith("batch: 10/10 files (10 ok, 0 failed)")
    assert len(lines) == 2 and "\r" not in buf.getvalue()


@pytest.mark.slow
def test_killed_run_leaves_a_valid_file_and_resume_completes(tmp_path):
    d = tmp_path / "many"
    d.mkdir()
    sphere = trimesh.creation.icosphere(subdivisions=5)       # 20,480 triangles: ~10 ms a file
    for k in range(40):
        write_binary_stl(d / f"s{k:02d}.stl", np.asarray(sphere.vertices) * (1 + k), sphere.faces)
    out = tmp_path / "r.jsonl"
    env = {**os.environ, "PYTHONPATH": ROOT}
    cmd = [sys.executable, "-m", "inertia_tool.cli", "batch", str(d), "--out", str(out), "-q"]
    kill_after_lines(cmd, out, 3, env=env, poll=0.1)                  # up to 60 s for the first rows
    with open_results(out) as r:
        before = len(r.previous_rows)
    assert before >= 3
    print(f"killed after {before} of 40 rows")
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = _rows(out)
    assert sorted(r["path"] for r in rows) == discover_files(d)    # one row per file, none twice
    assert f"; {before} done before;" in done.stderr


# -- issue 11: one writer, quoted names, torn tails, workers that die with the batch --------------------------

def _children(pid):
    """Pids whose parent is ``pid`` (Linux /proc)."""
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    stat = fh.read()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry))
    return out


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


_SLOW_BATCH = """
import sys, time
import inertia_tool.batch.runner as b
real = b._analyze
def slow(*args):
    time.sleep(float(sys.argv[1]))
    return real(*args)
b._analyze = slow
from inertia_tool.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _slow_batch(tmp_path, seconds, *args):
    script = tmp_path / "slow_batch.py"
    script.write_text(_SLOW_BATCH)
    env = {**os.environ, "PYTHONPATH": ROOT}
    return subprocess.Popen([sys.executable, str(script), str(seconds), "batch", *map(str, args)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killed_parent_takes_its_pool_workers_with_it(parts, tmp_path):
    d, boxes, _ = parts
    proc = _slow_batch(tmp_path, 60, d, "--out", tmp_path / "r.jsonl", "-j", "2", "-q")
    try:
        workers = []
        for _ in range(300):                                   # up to 30 s for the pool to start
            workers = _children(proc.pid)
            if len(workers) >= 2:
                break
            time.sleep(0.1)
        assert len(workers) >= 2, proc.stderr.read() if proc.poll() is not None else "no workers"
    finally:
        proc.kill()
        proc.wait()
    for _ in range(50):                                        # 5 s
        if not any(_alive(w) for w in workers):
            break
        time.sleep(0.1)
    left = [w for w in workers if _alive(w)]
    for w in left:
        os.kill(w, signal.SIGKILL)
    assert not left, f"pool workers {left} outlived their killed parent"


def test_watchdog_exits_a_worker_whose_parent_is_gone(tmp_path):
    """The portable fallback (no prctl): the watchdog thread alone ends an orphaned worker."""
    if not hasattr(os, "fork"):
        pytest.skip("needs fork")
    # a middle process forks the worker, lets the worker register it as the parent, then dies
    middle = ("import os, sys, time\n"
              "import inertia_tool.batch.runner as b\n"
              "b.sys.platform = 'other'\n"
              "parent = os.getpid()\n"
              "pid = os.fork()\n"
              "if pid == 0:\n"
              "    b._exit_with_parent(parent)\n"
              "    time.sleep(30)\n"
              "    os._exit(0)\n"
              "print(pid, flush=True)\n"
              "time.sleep(1.0)\n")                              # the worker's watchdog is running; exit now
    env = {**os.environ, "PYTHONPATH": ROOT}
    done = subprocess.run([sys.executable, "-c", middle], env=env, capture_output=True, text=True, timeout=30)
    worker = int(done.stdout.split()[0])
    for _ in range(50):
        if not _alive(worker):
            break
        time.sleep(0.1)
    alive = _alive(worker)
    if alive:
        os.kill(worker, signal.SIGKILL)
    assert not alive, "the watchdog did not end the orphaned worker"


_GATED_BATCH = """
import os, sys, time
import inertia_tool.batch.runner as b
real = b._analyze
gate = sys.argv[1]
calls = []
def gated(*args):
    if calls:                               # every file after the first waits until the test opens the gate
        for _ in range(6000):               # a bound (10 min), not a timing assumption: the test opens it
            if os.path.exists(gate):
                break
            time.sleep(0.1)
    calls.append(1)
    return real(*args)
b._analyze = gated
from inertia_tool.cli import main
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_second_batch_on_the_same_results_file_is_refused_and_nothing_is_lost(parts, tmp_path, suffix):
    """Two runs on one results file: the second is refused (exit 2, one line naming the first's pid), the
    file has no corrupt line, and a resume completes every file once.

    Deterministic on a loaded machine: the first run writes its first row and then waits at a gate (a file the
    test creates only after the second run has ended), so it is certainly running, and holding the lock, while
    the second run tries."""
    d, boxes, bad = parts
    out = tmp_path / f"r.{suffix}"
    gate = tmp_path / "gate"
    script = tmp_path / "gated_batch.py"
    script.write_text(_GATED_BATCH)
    env = {**os.environ, "PYTHONPATH": ROOT}
    first = subprocess.Popen([sys.executable, str(script), str(gate), "batch", str(d), "--out", str(out), "-q"],
                             env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        header = 1 if suffix == "csv" else 0
        for _ in range(6000):                             # until the first row is written (a bound, not a timing)
            if out.exists() and out.read_bytes().count(b"\n") > header or first.poll() is not None:
                break
            time.sleep(0.05)
        assert first.poll() is None, "the first run ended before its gate was opened: " + first.stderr.read()
        before = out.read_bytes()
        second = subprocess.run([sys.executable, "-m", "inertia_tool.cli", "batch", str(d), "--out", str(out)],
                                env=env, capture_output=True, text=True, timeout=300)
        assert second.returncode == 2, second.stderr
        lines = second.stderr.strip().splitlines()
        assert len(lines) == 1 and f"is being written by another batch run (pid {first.pid})" in lines[0]
        assert out.read_bytes() == before                 # the refused run wrote nothing
    finally:
        gate.write_bytes(b"")
        first.communicate(timeout=300)
    assert first.returncode == 3                   # the corrupt file
    rows = _rows(out)                              # parses every record: no corrupt line
    assert sorted(r["path"] for r in rows) == discover_files(d)
    again = main(["batch", str(d), "--out", str(out), "-q"])
    assert again == 3 and len(_rows(out)) == len(rows)


def test_results_file_lock_is_released_on_close(tmp_path):
    from inertia_tool.batch.rows import ResultsFileBusy
    out = tmp_path / "r.jsonl"
    with open_results(out):
        with pytest.raises(ResultsFileBusy, match=r"being written by another batch run \(pid \d+\)"):
            open_results(out)              # a second open file description conflicts, even in one process
    with open_results(out) as r:
        assert r.previous_rows == []


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_file_names_with_newlines_quotes_and_commas_round_trip(tmp_path, suffix):
    d = tmp_path / "odd"
    d.mkdir()
    m = trimesh.creation.box((1, 2, 3))
    names = ['a\nb.stl', 'c,"d".stl', 'e\r\nf.stl', "plain.stl"]
    for n in names:
        write_binary_stl(d / n, m.vertices, m.faces)
    out = tmp_path / f"r.{suffix}"
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0
    rows = _rows(out)
    assert sorted(r["path"] for r in rows) == discover_files(d) and all(r["status"] == "ok" for r in rows)
    if suffix == "csv":
        import csv
        with open(out, newline="", encoding="utf-8") as fh:
            table = list(csv.reader(fh))
        assert len(table) == 1 + len(names) and {len(r) for r in table} == {len(ROW_FIELDS)}
    assert main(["batch", str(d), "--out", str(out), "-q"]) == 0      # resume reads them back: all skipped
    assert len(_rows(out)) == len(names)


@pytest.mark.parametrize("suffix", ["jsonl", "csv"])
def test_torn_last_line_is_reported_not_refused(parts, tmp_path, suffix, capsys):
    d, boxes, _ = parts
    out = tmp_path / f"r.{suffix}"
    assert main(["batch", str(d / "box*.stl"), "--out", str(out), "-q"]) == 0
    whole = out.read_bytes()
    last = whole.splitlines(keepends=True)[-1]
    torn = last[: len(last) // 2] + b"\n"                                  # row cut, then a newline
    out.write_bytes(whole[: len(whole) - len(last)] + torn)
    capsys.readouterr()
    assert main(["batch", str(d / "box*.stl"), "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert f"ignored a torn last line ({len(torn)} bytes) — the previous run was interrupted" in err
    assert "1 ok" in err and len(_rows(out)) == 4 and out.read_bytes().startswith(whole[: len(whole) - len(last)])


def test_csv_record_torn_inside_a_quoted_line_break(tmp_path):
    from inertia_tool.batch.rows import format_row, read_rows
    row = dict.fromkeys(ROW_FIELDS)
    row.update(schema=SCHEMA, path="x\ny.stl", status="ok", mass=1.5, faces=12, watertight=True)
    header = (",".join(ROW_FIELDS) + "\n").encode()
    record = format_row(row, "csv")
    assert record.count(b"\n") == 2
    rows, torn = read_rows(header + record, "csv", "r.csv")
    assert torn == 0 and rows[0]["path"] == "x\ny.stl" and rows[0]["mass"] == 1.5
    cut = record[: record.index(b"\n") + 1]                       # ends in the quoted line break
    rows, torn = read_rows(header + record + cut, "csv", "r.csv")
    assert len(rows) == 1 and torn == len(cut)


def test_progress_bar_on_a_terminal_is_redrawn_at_most_every_redraw_seconds():
    """A redraw per file cost a write and a flush per small part: the bar is drawn first, then at most every
    ``redraw`` seconds, and always in its final state."""
    import io

    from inertia_tool.cli.batch import Progress

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    buf = Terminal()
    p = Progress(buf, redraw=3600)
    for k in range(1, 1001):
        p(k, 1000, k, 0)
    p.close()
    draws = buf.getvalue().split("\r")[1:]
    assert len(draws) == 2
    assert draws[0].startswith("[") and "1/1000 files" in draws[0]
    assert "1000/1000 files (1000 ok, 0 failed)" in draws[1] and buf.getvalue().endswith("\n")
    every = Terminal()
    p = Progress(every, redraw=0)
    for k in range(1, 6):
        p(k, 5, k, 0)
    assert every.getvalue().count("\r") == 5



def test_pool_workers_import_the_writer_only_when_the_parent_had():
    """A worker closes the results file it inherited; a parent that never imported the writer has none open,
    and its workers need not import it (7 ms of CPU each).  In a fresh interpreter, so that this test session's
    imports do not decide it."""
    code = ("import sys\n"
            "from inertia_tool.batch.runner import _process_pool\n"
            "def _writer_imported(_):\n"
            "    return 'inertia_tool.batch.rows' in sys.modules\n"
            "def run():\n"
            "    with _process_pool(2) as pool:\n"
            "        return list(pool.map(_writer_imported, range(4)))\n"
            "if __name__ == '__main__':\n"
            "    before = any(run())\n"
            "    import inertia_tool.batch.rows\n"
            "    print(before, all(run()))\n")
    env = {**os.environ, "PYTHONPATH": ROOT}
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["False", "True"]
