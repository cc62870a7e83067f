"""Every row of ``inertia-tool batch`` says what ``inertia-tool analyze FILE`` says about the same file.

Two independent routes through the command line: ``analyze FILE --json`` (one process per file, its JSON and exit
code) and ``batch DIR --out FILE.jsonl`` (chunks, in this process or on a pool of two), compared file by file on
generated catalogues of good parts (closed forms checked too) and bad files: each bad file gets its own row, with
``analyze``'s message and an ``error_type`` whose exit code (``cli.EXIT_CODES``, the table of docs/batch.md) is the
one ``analyze`` returns.  Hypothesis damages a part's bytes (cuts, overwritten bytes) and the two must still agree,
whatever the damage makes of the file.
"""

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import write_ascii_stl, write_binary_stl
from inertia_tool import errors
from inertia_tool.batch.rows import open_results
from inertia_tool.cli import EXIT_CODES, EXIT_MESH, EXIT_OK, main

#: Relative agreement of numbers between a batch row and ``analyze --json`` (the same engine: equal in practice;
#: the JSON writer rounds nothing, so this only allows for a different summation order if one ever appears).
RTOL = 1e-12


def _analyze(path, capsys) -> tuple[int, dict | None, str]:
    """Exit code, parsed JSON (None on failure) and stderr of ``inertia-tool analyze FILE --json``."""
    capsys.readouterr()
    code = main(["analyze", str(path), "--json", "--units", "mm", "--density", "1240"])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if code == EXIT_OK else None), err


def _batch(directory, out, jobs, capsys) -> dict:
    """The rows of ``inertia-tool batch DIR`` by path."""
    main(["batch", str(directory), "--units", "mm", "--density", "1240", "--out", str(out), "--jobs", str(jobs)])
    capsys.readouterr()
    with open_results(out) as results:
        return {r["path"]: r for r in results.previous_rows}


def _words(message: str) -> str:
    """A message with its whitespace collapsed and option dashes dropped."""
    return " ".join(message.replace("--", "").split())


def _row_exit_code(row: dict) -> int:
    """The exit code ``analyze`` gives for the error of a row: its ``error_type`` looked up in ``cli.EXIT_CODES``
    through the class's ancestors (as ``cli.exit_code`` does for the exception itself)."""
    cls = getattr(errors, row["error_type"])
    return next(EXIT_CODES[c] for c in cls.__mro__ if c in EXIT_CODES)


def _assert_agree(row: dict, code: int, report: dict | None, err: str, path) -> None:
    if code == EXIT_OK:
        assert row["status"] == "ok", (path, row["error"])
        assert row["mass"] == pytest.approx(report["mass"], rel=RTOL)
        assert row["volume"] == pytest.approx(report["volume"], rel=RTOL)
        com = [row[f"com_{c}"] for c in "xyz"]
        np.testing.assert_allclose(com, report["center_of_mass"], rtol=RTOL, atol=RTOL * max(map(abs, com)))
        tensor = np.array(report["inertia"])
        scale = np.abs(tensor).max()
        got = [row[k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")]
        want = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]
        np.testing.assert_allclose(got, want, rtol=RTOL, atol=RTOL * scale)
        np.testing.assert_allclose([row["i1"], row["i2"], row["i3"]], report["principal_moments"], rtol=RTOL,
                                   atol=RTOL * scale)
        assert row["certificate"] == report["certificate"]["kind"]
        assert row["method"] == report["method"]
    else:
        assert row["status"] == "error", (path, code, err)
        assert _row_exit_code(row) == code, (path, row["error_type"], code)
        # analyze prints "inertia-tool: error: MESSAGE" on one line; the row holds MESSAGE on one line, naming the
        # options of `batch` (which has no --thickness: analyze's "wall --thickness" is the row's "wall thickness")
        assert err.strip().startswith("inertia-tool: error: ")
        assert "`" not in row["error"], row["error"]
        assert _words(row["error"]) in _words(err), (row["error"], err)


def _box(path, extents, centre):
    m = trimesh.creation.box(extents)
    write_binary_stl(path, np.asarray(m.vertices) + np.asarray(centre), m.faces)


@pytest.fixture(scope="module")
def catalogue(tmp_path_factory):
    """Good parts of every kind of the benchmark's catalogue, far from the origin too, an ASCII STL and an OBJ,
    and bad files of every kind a catalogue holds: their expected exit code, or None for a good part."""
    d = tmp_path_factory.mktemp("catalogue")
    expected = {}
    rng = np.random.default_rng(25)
    for k in range(4):
        # whole millimetres and quarter-millimetre centres: every corner is exact in float32
        extents = rng.integers(5, 80, 3).astype(float)
        centre = np.round(4 * rng.uniform(-1e4, 1e4, 3) if k == 3 else 4 * rng.uniform(-100, 100, 3)) / 4
        path = d / f"box{k}.stl"
        _box(path, extents, centre)
        expected[path] = ("box", extents)
    shapes = {"sphere.stl": trimesh.creation.icosphere(subdivisions=2, radius=12.0),
              "torus.stl": trimesh.creation.torus(30.0, 6.0, major_sections=48, minor_sections=16),
              "cylinder.stl": trimesh.creation.cylinder(radius=9.0, height=40.0, sections=300)}
    for name, m in shapes.items():
        write_binary_stl(d / name, m.vertices, m.faces)
        expected[d / name] = (None, None)
    m = trimesh.creation.box((3.0, 4.0, 5.0))
    write_ascii_stl(d / "ascii.stl", m.vertices, m.faces)
    expected[d / "ascii.stl"] = ("box", (3.0, 4.0, 5.0))
    with open(d / "part.obj", "w") as fh:
        fh.writelines(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in m.vertices)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in m.faces)
    expected[d / "part.obj"] = ("box", (3.0, 4.0, 5.0))
    # bad files
    (d / "empty.stl").write_bytes(b"")
    (d / "text.stl").write_text("this is not a mesh\n")
    (d / "lying_header.stl").write_bytes(b"\0" * 80 + (1000).to_bytes(4, "little") + b"\1" * 100)
    good = (d / "box0.stl").read_bytes()
    (d / "truncated.stl").write_bytes(good[: len(good) - 30])
    write_binary_stl(d / "open.stl", m.vertices, m.faces[:-1])
    v = np.array(m.vertices, dtype=float)
    v[0] = np.nan
    write_binary_stl(d / "nan.stl", v, m.faces)
    write_binary_stl(d / "flat.stl", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2],
                                                                                      [0, 2, 1], [1, 2, 3]])
    (d / "gz.stl.gz").write_bytes(b"\x1f\x8b not really gzip")
    for name in ("empty.stl", "text.stl", "lying_header.stl", "truncated.stl", "open.stl", "nan.stl", "flat.stl",
                 "gz.stl.gz"):
        expected[d / name] = ("bad", None)
    return d, expected


@pytest.mark.parametrize("jobs", [1, 2])
def test_every_row_agrees_with_analyze(catalogue, tmp_path, capsys, jobs):
    d, expected = catalogue
    rows = _batch(d, tmp_path / "rows.jsonl", jobs, capsys)
    assert len(rows) == len(expected)                        # one row per file, bad ones included
    bad = 0
    for path, (kind, extents) in expected.items():
        row = rows[str(path)]
        code, report, err = _analyze(path, capsys)
        _assert_agree(row, code, report, err, path)
        if kind == "bad":
            bad += 1
            assert code == EXIT_MESH, (path, err)           # every kind of bad file here is a mesh problem
        if kind == "box":                                   # and the numbers are right, not only equal
            a, b, c = np.asarray(extents) * 1e-3
            mass = 1240.0 * a * b * c
            assert row["mass"] == pytest.approx(mass, rel=1e-9)
            np.testing.assert_allclose(sorted([row["ixx"], row["iyy"], row["izz"]]),
                                       sorted(mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])),
                                       rtol=1e-7)
    assert bad == 8 and sum(r["status"] == "error" for r in rows.values()) == 8
    # regression: the row said "`repair=True` gives a bounded estimate" (the API's words) where analyze says
    # "--repair gives a bounded estimate"
    assert "--repair gives a bounded estimate" in rows[str(d / "open.stl")]["error"]


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.one_of(st.none(), st.integers(0, 684)),
       writes=st.lists(st.tuples(st.integers(0, 683), st.binary(min_size=1, max_size=8)), max_size=3),
       twelve=st.booleans())
def test_damaged_part_row_agrees_with_analyze(tmp_path, capsys, cut, writes, twelve):
    """Whatever a cut or a few overwritten bytes make of a binary STL box (still fine, refused as truncated, open,
    NaN, crossing itself...), its batch row says what ``analyze`` says."""
    m = trimesh.creation.box((10.0, 20.0, 30.0))
    directory = Path(tempfile.mkdtemp(dir=tmp_path))      # tmp_path is shared by the examples: one directory each
    path = directory / "part.stl"
    write_binary_stl(path, m.vertices, m.faces if twelve else m.faces[:11])
    data = bytearray(path.read_bytes())
    for offset, chunk in writes:
        data[offset:offset + len(chunk)] = chunk
    if cut is not None:
        data = data[:cut]
    path.write_bytes(bytes(data))
    rows = _batch(directory, directory / "rows.jsonl", 1, capsys)
    assert list(rows) == [str(path)]
    code, report, err = _analyze(path, capsys)
    _assert_agree(rows[str(path)], code, report, err, path)
