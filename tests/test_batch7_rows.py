"""Batch rows with the clean-part fast path (issue 25 item 6) are the rows of the full checks: every column but
``seconds`` and ``worker``, on clean parts and on files the fast path hands back (two shells, open, inside out,
passing through itself, not a mesh)."""

from __future__ import annotations

import numpy as np
import pytest

from adversary_solids import box, torus
from inertia_tool.batch.runner import BatchOptions, analyze_chunk
from inertia_tool.mass import pipeline
from inertia_tool.mesh import LoadOptions


def _write_stl(path, v, f):
    tri = np.asarray(v, dtype=np.float32)[np.asarray(f)]
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    path.write_bytes(b"batch7".ljust(80) + np.uint32(len(tri)).tobytes() + rec.tobytes())


def _files(tmp_path):
    v, f = box((10.0, 20.0, 30.0), subdivide=1)
    top = int(np.flatnonzero((np.abs(v[:, 0]) < 1e-9) & (np.abs(v[:, 1]) < 1e-9) & (v[:, 2] > 0))[0])
    through = v.copy()
    through[top, 2] = -20.0                                   # pushed out through the bottom: crosses itself
    rot = np.array([[0.6, -0.8, 0.0], [0.8, 0.6, 0.0], [0.0, 0.0, 1.0]])
    meshes = {"box": (v, f), "torus": (torus(30.0, 8.0, 24, 12)[0] @ rot.T + 5.0, torus(30.0, 8.0, 24, 12)[1]),
              "two": (np.vstack([v, v + 100.0]), np.vstack([f, f + len(v)])), "open": (v, f[1:]),
              "inward": (v, f[:, ::-1]), "through": (through, f)}
    paths = []
    for name, (mv, mf) in meshes.items():
        p = tmp_path / f"{name}.stl"
        _write_stl(p, mv, mf)
        paths.append(str(p))
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"solid nothing\nendsolid\n")
    return paths + [str(bad)]


@pytest.mark.parametrize("repair", [False, True])
def test_rows_with_and_without_the_fast_path(tmp_path, monkeypatch, repair):
    files = [(p, None) for p in _files(tmp_path)]
    if repair:                                                # the clean parts and the repaired ones
        files = [item for item in files if item[0].endswith(("box.stl", "torus.stl", "open.stl", "bad.stl"))]
    options = BatchOptions(load=LoadOptions(units="mm", repair=repair), density=1240.0)
    taken = []
    real = pipeline.prepare_clean

    def counted(raw):
        got = real(raw)
        taken.append(got is not None)
        return got

    monkeypatch.setattr(pipeline, "prepare_clean", counted)
    fast = analyze_chunk(files, options)
    monkeypatch.setattr(pipeline, "prepare_clean", lambda raw: None)
    full = analyze_chunk(files, options)
    assert sum(taken) == 2                                    # the box and the torus
    for a, b in zip(fast, full):
        for row in (a, b):
            row.pop("seconds")
            row.pop("worker")
        assert a == b
    assert [r["status"] for r in fast][:2] == ["ok", "ok"] and fast[-1]["status"] == "error"
