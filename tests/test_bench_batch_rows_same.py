"""The batch's row-identity check (``benchmarks/bench_batch_rows_same.py``, issue 25): what a speed change to the
batch's per-file path is judged by ("every row the same on main and on the change").

Its comparison must see every change that alters the results file, including those Python's ``==`` cannot see
(``-0.0`` for ``0.0``, ``1`` or ``True`` for ``1.0``, which are different bytes in a JSONL or CSV row), and must
pass two runs of the same code; ``seconds`` and ``worker`` (time taken, process) are never compared.
"""

import json
import math
import os
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from bench_batch_rows_same import VOLATILE, compare_rows  # noqa: E402

from inertia_tool.batch.rows import format_row  # noqa: E402
from inertia_tool.batch.runner import ROW_FIELDS  # noqa: E402

_VALUES = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                    st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=12))


def _record(row: dict, options: str = "default") -> dict:
    """What the script's child writes for a row (through JSON, as the script reads it back)."""
    row = {**row, **dict.fromkeys(VOLATILE)}
    written = {fmt: format_row(row, fmt).decode("utf-8") for fmt in ("jsonl", "csv")}
    return json.loads(json.dumps({"options": options, "row": row, "written": written}))


def _look_alike(value):
    """A value Python compares equal to ``value`` (or nearly) but the results file writes differently."""
    if isinstance(value, bool):
        return int(value)                                   # True -> 1 (== True)
    if isinstance(value, int):
        return float(value)                                 # 3 -> 3.0 (== 3)
    if isinstance(value, float):
        if value == 0.0:
            return -value                                   # 0.0 <-> -0.0 (== each other)
        return math.nextafter(value, 0.0)                   # one unit in the last place (finite: toward 0)
    if value is None:
        return ""
    return value + "x"


@settings(max_examples=60, deadline=None)
@given(values=st.lists(_VALUES, min_size=len(ROW_FIELDS), max_size=len(ROW_FIELDS)),
       field=st.sampled_from([f for f in ROW_FIELDS if f not in VOLATILE]), change=st.booleans())
def test_every_written_change_is_found_and_nothing_else(values, field, change):
    row = dict(zip(ROW_FIELDS, values))
    other = dict(row)
    if change:
        other[field] = _look_alike(row[field])
    statuses, different = compare_rows([_record(row)], [_record(other)])
    assert statuses == {("default", row["status"]): 1}
    if change:
        # the field is named, by its JSON text, whatever == says of the two values
        assert [d[2] for d in different if not d[2].startswith("written")] == [field]
        assert any(d[2] == "written jsonl" for d in different)
    else:
        assert different == []


@pytest.mark.parametrize("before, after", [(0.0, -0.0), (1.0, 1), (1.0, True), (2.5, math.nextafter(2.5, 0.0))])
def test_changes_that_compare_equal_in_python_are_differences(before, after):
    # the rule the script had before (a.get(k) != b.get(k) on values read back) passed the first three
    row = dict.fromkeys(ROW_FIELDS)
    row.update(status="ok", path="a.stl", mass=before)
    _, different = compare_rows([_record(row)], [_record({**row, "mass": after})])
    found = [d for d in different if d[2] == "mass"]
    assert [(d[0], d[1], json.dumps(d[3]), json.dumps(d[4])) for d in found] == \
        [("default", "a.stl", json.dumps(before), json.dumps(after))]


def test_time_and_worker_are_not_compared_and_row_counts_are():
    row = dict.fromkeys(ROW_FIELDS)
    row.update(status="ok", path="a.stl", mass=1.0)
    mine = _record({**row, "seconds": 0.1, "worker": "here:1"})
    theirs = _record({**row, "seconds": 9.9, "worker": "there:2"})
    assert compare_rows([mine], [theirs])[1] == []
    assert compare_rows([mine, mine], [theirs])[1] == [("", "", "rows", 2, 1)]


def test_the_script_finds_this_checkout_identical_to_itself(tmp_path):
    # end to end: both children import this checkout; a few catalogue parts, meshes/*.stl and the bad files, with
    # the default options and repair=True
    done = subprocess.run([sys.executable, os.path.join(ROOT, "benchmarks", "bench_batch_rows_same.py"),
                           "--baseline", ROOT, "--small", "4"], capture_output=True, text=True, timeout=600,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "identical: every field of every row" in done.stdout
    assert "default ok" in done.stdout and "default error" in done.stdout
