"""The ``assumptions`` column of batch rows: ``"none"`` written when a result rests on no assumption of the user's,
empty (``None``) only when it is not recorded (a failed row, a row of an ``inertia_tool.batch/2`` file read back).

Before session 17 an ``ok`` row with no assumption left the cell empty, exactly as a ``batch/2`` row read back on
resume: "no assumption" and "unknown" looked alike (only the ``schema`` column told them apart).
"""

from __future__ import annotations

import csv
import io
import json
import os

import pytest

from inertia_tool.batch.rows import format_row, open_results, read_rows
from inertia_tool.batch.runner import NO_ASSUMPTIONS, ROW_FIELDS, ROW_FIELDS_V2, SCHEMA, SCHEMA_V2

BOX = os.path.join(os.path.dirname(__file__), os.pardir, "meshes", "box.stl")


@pytest.mark.parametrize("fmt", ["jsonl", "csv"])
def test_rows_written_now_say_none_and_failed_rows_stay_empty(tmp_path, fmt):
    from inertia_tool.cli import main
    from inertia_tool.reports.serialize import output_schema
    bad = tmp_path / "not_a_mesh.stl"
    bad.write_bytes(b"solid nothing\nendsolid nothing\n")
    out = tmp_path / f"rows.{fmt}"
    main(["batch", BOX, str(bad), "--units", "mm", "--out", str(out), "-q"])
    text = out.read_text()
    if fmt == "jsonl":
        written = {json.loads(line)["status"]: json.loads(line)["assumptions"] for line in text.splitlines()}
        assert written == {"ok": "none", "error": None}
    else:
        table = list(csv.reader(io.StringIO(text)))
        assert table[0] == list(ROW_FIELDS)
        at = ROW_FIELDS.index("assumptions")
        assert sorted(c[at] for c in table[1:]) == ["", "none"]
    with open_results(out) as results:
        rows = {r["status"]: r for r in results.previous_rows}
    assert rows["ok"]["assumptions"] == NO_ASSUMPTIONS == "none"
    assert rows["error"]["assumptions"] is None
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(output_schema())
    for row in rows.values():
        assert list(validator.iter_errors(row)) == []


def _row(schema: str, status: str, assumptions=None) -> dict:
    row = dict.fromkeys(ROW_FIELDS)
    row.update(schema=schema, path=f"{schema}-{status}-{assumptions}.stl", status=status, options_key="0" * 16,
               assumptions=assumptions)
    if status != "ok":
        row.update(error_type="MeshReadError", error="unreadable")
    return row


@pytest.mark.parametrize("fmt", ["jsonl", "csv"])
def test_rows_read_back_tell_unknown_from_none(fmt):
    """A batch/2 row has no column: read back as None (not recorded), never "none"; a batch/3 ``ok`` row of the
    session-16 writer (empty for none taken) reads "none"; a failed row and a named assumption read as written."""
    rows = [_row(SCHEMA_V2, "ok"), _row(SCHEMA_V2, "error"), _row(SCHEMA, "ok", None), _row(SCHEMA, "error"),
            _row(SCHEMA, "ok", "none"), _row(SCHEMA, "ok", "flat-islands"),
            _row(SCHEMA, "ok", "flat-islands,smooth-holes")]
    if fmt == "jsonl":                      # one file, each line in its own layout
        back = read_rows(b"".join(format_row(r, fmt, r["schema"]) for r in rows), fmt, "rows.jsonl")[0]
    else:                                   # one CSV file holds one layout: the v2 rows in a file of their own
        v2 = (",".join(ROW_FIELDS_V2) + "\n").encode() + b"".join(format_row(r, fmt, SCHEMA_V2) for r in rows[:2])
        v3 = (",".join(ROW_FIELDS) + "\n").encode() + b"".join(format_row(r, fmt) for r in rows[2:])
        back = read_rows(v2, fmt, "old.csv")[0] + read_rows(v3, fmt, "new.csv")[0]
    got = [(r["schema"], r["status"], r["assumptions"]) for r in back]
    assert got == [(SCHEMA_V2, "ok", None), (SCHEMA_V2, "error", None), (SCHEMA, "ok", "none"),
                   (SCHEMA, "error", None), (SCHEMA, "ok", "none"), (SCHEMA, "ok", "flat-islands"),
                   (SCHEMA, "ok", "flat-islands,smooth-holes")]
    assert all(set(r) == set(ROW_FIELDS) for r in back)
