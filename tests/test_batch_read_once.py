"""The batch's per-file work reads each file once (inertia_tool.batch.runner._read_once and the reader's ``data``):
one open per file, the row's hash that of the bytes analysed, and rows equal to ``analyze --json`` of the file."""

import contextlib
import hashlib
import io
import json
import os
import tempfile
import warnings

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import write_ascii_stl, write_binary_stl
from inertia_tool.batch import runner as batch_mod
from inertia_tool.batch.runner import BatchOptions, analyze_chunk, analyze_file
from inertia_tool.cli import main
from inertia_tool.mesh import LoadOptions
from inertia_tool.mesh.read import load_mesh

OPTIONS = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)


def _write_obj(path, vertices, faces):
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, dtype=float).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces).tolist()]
    path.write_text("\n".join(lines) + "\n")


def _write(path, mesh, kind):
    if kind == "binary":
        write_binary_stl(path, mesh.vertices, mesh.faces)
    elif kind == "ascii":
        write_ascii_stl(path, mesh.vertices, mesh.faces)
    else:
        _write_obj(path, mesh.vertices, mesh.faces)
    return str(path)


@pytest.fixture
def files(tmp_path):
    """A small binary STL (one 4 kB read of the reader held all of it), a larger one, an ASCII STL, an OBJ."""
    small = trimesh.creation.box((10.0, 20.0, 30.0))
    large = trimesh.creation.icosphere(3, radius=20.0)           # 1,280 faces: 64 kB
    return [_write(tmp_path / "small.stl", small, "binary"), _write(tmp_path / "large.stl", large, "binary"),
            _write(tmp_path / "ascii.stl", large, "ascii"), _write(tmp_path / "part.obj", large, "obj")]


def test_each_file_is_opened_once_and_hashed_from_the_bytes_analysed(files, monkeypatch):
    """Regression (issue 25 item 6): the batch opened a file for its hash and the reader opened it again (an STL
    above 4 kB three times); a file changed in between got the hash of other bytes than the ones analysed."""
    opened = []
    real_open = os.open

    def counting_open(path, *args, **kwargs):
        opened.append(os.fsdecode(path))
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", counting_open)
    rows = analyze_chunk([(f, None) for f in files], OPTIONS)
    assert [r["status"] for r in rows] == ["ok"] * 4
    assert sorted(opened) == sorted(files)                                 # each once
    for f, r in zip(files, rows):
        with open(f, "rb") as fh:
            assert r["sha256"] == hashlib.sha256(fh.read()).hexdigest()
    # a hash handed in by the caller (computed before) is replaced by that of the bytes read now
    row = analyze_file(files[1], OPTIONS, sha256="0" * 64)
    assert row["sha256"] == rows[1]["sha256"]


def test_a_file_above_the_read_once_limit_is_hashed_and_streamed(files, monkeypatch):
    with open(files[1], "rb") as fh:
        real = hashlib.sha256(fh.read()).hexdigest()
    data, digest = batch_mod._read_once(files[1], limit=1000)
    assert data is None and digest == real
    assert batch_mod._read_once(files[1], limit=1000, known="0" * 64) == (None, "0" * 64)   # not read again
    small, digest = batch_mod._read_once(files[0], limit=1 << 20, known="0" * 64)
    with open(files[0], "rb") as fh:
        assert small == fh.read() and digest == hashlib.sha256(small).hexdigest()        # the bytes' own hash
    # the rows of streamed files are those of files read once
    once = analyze_chunk([(f, None) for f in files], OPTIONS)
    monkeypatch.setattr(batch_mod, "READ_ONCE_BYTES", 1000)
    streamed = analyze_chunk([(f, None) for f in files], OPTIONS)
    strip = lambda r: {k: v for k, v in r.items() if k not in ("seconds", "worker")}  # noqa: E731
    assert list(map(strip, streamed)) == list(map(strip, once))
    assert analyze_file(files[1], OPTIONS, sha256="0" * 64)["sha256"] == "0" * 64   # too large to hold: kept


@pytest.mark.parametrize("k", range(4))
def test_reader_gives_the_same_mesh_from_the_bytes_as_from_the_file(files, k):
    with open(files[k], "rb") as fh:
        data = fh.read()
    a = load_mesh(files[k], units="mm")
    b = load_mesh(files[k], units="mm", data=data)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    assert (a.source, a.units, a.file_faces, a.storage_rounding) == (b.source, b.units, b.file_faces,
                                                                    b.storage_rounding)


def test_bytes_of_a_broken_file_give_the_reader_s_error(tmp_path):
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"\x00" * 80 + (1000).to_bytes(4, "little") + b"\x01" * 100)   # claims 1000 faces, holds 2
    row = analyze_file(str(bad), OPTIONS)
    assert row["status"] == "error" and row["error_type"] == "MeshReadError" and "1,000" in row["error"]
    empty = tmp_path / "empty.obj"
    empty.write_bytes(b"")
    row = analyze_file(str(empty), OPTIONS)
    assert row["status"] == "error" and "empty file" in row["error"]


def _analyze_json(path):
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["analyze", path, "--units", "mm", "--density", "1240", "--json"])
    assert code == 0
    return json.loads(out.getvalue())


def _random_mesh(kind, size, seed):
    rng = np.random.default_rng(seed)
    if kind == "box":
        m = trimesh.creation.box(rng.uniform(0.5, 2.0, 3) * size)
    elif kind == "icosphere":
        m = trimesh.creation.icosphere(int(rng.integers(0, 3)), radius=size)
    elif kind == "cylinder":
        m = trimesh.creation.cylinder(radius=size, height=size * rng.uniform(0.2, 3.0),
                                      sections=int(rng.integers(3, 40)))
    else:                                               # a random convex polyhedron
        m = trimesh.convex.convex_hull(rng.normal(size=(int(rng.integers(4, 40)), 3)) * size)
    m.apply_transform(trimesh.transformations.random_rotation_matrix(rng.random(3)))
    m.apply_translation(rng.uniform(-3, 3, 3) * size)
    return m


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kinds=st.lists(st.sampled_from(["box", "icosphere", "cylinder", "hull"]), min_size=1, max_size=4),
       formats=st.lists(st.sampled_from(["binary", "ascii", "obj"]), min_size=4, max_size=4),
       size=st.floats(1.0, 500.0), seed=st.integers(0, 2**32 - 1))
def test_batch_rows_equal_analyze_json_on_random_small_meshes(kinds, formats, size, seed):
    """Every number of a batch row (read once, from the bytes) is the one ``analyze --json`` prints for the file
    (read from the path), bit for bit; so are the mesh report's counts, method and certificate."""
    with tempfile.TemporaryDirectory() as tmp:
        from pathlib import Path

        paths = []
        for k, kind in enumerate(kinds):
            fmt = formats[k]
            suffix = ".obj" if fmt == "obj" else ".stl"
            paths.append(_write(Path(tmp) / f"p{k}{suffix}", _random_mesh(kind, size, seed + k), fmt))
        rows = analyze_chunk([(p, None) for p in paths], OPTIONS)
        for path, row in zip(paths, rows):
            ref = _analyze_json(path)
            assert row["status"] == "ok", row["error"]
            assert [row["mass"], row["volume"], row["surface_area"], row["density"]] == \
                [ref["mass"], ref["volume"], ref["surface_area"], ref["density"]]
            assert [row["com_x"], row["com_y"], row["com_z"]] == ref["center_of_mass"]
            tensor = ref["inertia"]
            assert [row["ixx"], row["iyy"], row["izz"], row["ixy"], row["ixz"], row["iyz"]] == \
                [tensor[0][0], tensor[1][1], tensor[2][2], tensor[0][1], tensor[0][2], tensor[1][2]]
            assert [row["i1"], row["i2"], row["i3"]] == ref["principal_moments"]
            assert [[row[f"axis{k}_{c}"] for c in "xyz"] for k in (1, 2, 3)] == ref["principal_axes"]
            mesh = ref["mesh"]
            assert (row["faces"], row["bodies"], row["cavities"], row["watertight"], row["repaired"]) == \
                (mesh["faces"], mesh["bodies"], mesh["cavities"], mesh["watertight"], mesh["repaired"])
            assert (row["method"], row["certificate"], row["density_source"]) == \
                (ref["method"], ref["certificate"]["kind"], ref["density_source"])
