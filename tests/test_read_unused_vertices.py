"""Vertices no face uses (``mesh/read.py``, ``_used_vertices``; review 10's D1).

A point no face uses is not part of the surface: the reader leaves it out, so that no later stage reads an extent
it widens (R2's flatness scale, the units heuristic, the reported box).  Every path that can carry such points
(OBJ, PLY, OFF, arrays through the API; STL cannot: it stores triangles) must give, to the bit, what the same solid
without them gives: the full path, the clean-part fast path and the batch's row alike.  The stray points are drawn
inside the solid, far outside it (up to 1e6 sizes), on its faces and on its corners (coincident, not welded), in
any number from 1 to 50 and at any place in the vertex list.
"""

from __future__ import annotations

import struct
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from adversary_solids import box, cylinder, icosphere, torus
from inertia_tool.batch import BatchOptions, analyze_file
from inertia_tool.errors import InertiaToolError
from inertia_tool.mass.pipeline import mass_properties
from inertia_tool.mesh.read import load_mesh


def _bits(props):
    """The result's numbers and mesh report to the bit (the report's ``source`` aside: files differ in name)."""
    numbers = [props.mass, *props.center_of_mass.tolist(), *props.inertia.ravel().tolist()]
    report = props.mesh
    return (struct.pack(f"<{len(numbers)}d", *numbers), report.vertices, report.faces, report.certificate,
            report.method, report.bbox_min.tobytes(), report.bbox_max.tobytes(), report.notes)


def _outcome(source, fast):
    """``(bits or error, warnings)`` of ``mass_properties(source)``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            outcome = ("ok", _bits(mass_properties(source, density=1.0, fast_path=fast)))
        except InertiaToolError as exc:
            outcome = ("error", type(exc).__name__, str(exc).replace(str(source), "<source>"))
    return outcome, [(w.category.__name__, str(w.message).split(": ", 1)[-1]) for w in caught]


def _solid(rng):
    """A clean closed solid, scaled, turned and moved at random (m)."""
    kind = int(rng.integers(4))
    v, f = (box((1.0, 2.0, 3.0)), icosphere(0.5, 1), cylinder(0.4, 1.0, 12), torus(0.6, 0.2, 12, 6))[kind]
    size = 10.0 ** rng.uniform(-2, 2)
    v = np.asarray(v, dtype=np.float64) * size @ Rotation.random(random_state=int(rng.integers(2 ** 31))).as_matrix().T
    return v + rng.normal(size=3) * size * 10.0 ** rng.uniform(-1, 3), np.asarray(f, dtype=np.int64)


def _with_strays(v, f, rng):
    """``(v, f)`` with 1–50 vertices no face uses, each inside the box of the solid, far outside it, on a face or
    on a corner, inserted at random places (the faces renumbered)."""
    n = int(rng.integers(1, 51))
    lo, hi = v.min(0), v.max(0)
    size = float(np.linalg.norm(hi - lo))
    strays = []
    for _ in range(n):
        where = int(rng.integers(4))
        if where == 0:                                            # within the box (inside the solid or not)
            strays.append(lo + rng.random(3) * (hi - lo))
        elif where == 1:                                          # far out, up to 1e6 sizes
            strays.append(hi + rng.normal(size=3) * size * 10.0 ** rng.uniform(0, 6))
        elif where == 2:                                          # on a face
            w = rng.dirichlet(np.ones(3))
            strays.append(w @ v[f[int(rng.integers(len(f)))]])
        else:                                                     # on a corner, not welded to it
            strays.append(v[int(rng.integers(len(v)))].copy())
    total = len(v) + n
    places = np.sort(rng.choice(total, size=n, replace=False))
    used = np.ones(total, dtype=bool)
    used[places] = False
    out = np.empty((total, 3))
    out[places] = strays
    out[used] = v
    return out, np.flatnonzero(used)[f]


def _write(path, v, f):
    """``v, f`` as an OBJ, PLY (ASCII, double) or OFF file (coordinates by ``repr``: read back bit for bit)."""
    rows = "\n".join(" ".join(repr(float(x)) for x in p) for p in v)
    tris = "\n".join(" ".join(str(int(i)) for i in t) for t in f)
    suffix = path.suffix
    if suffix == ".obj":
        text = "\n".join("v " + line for line in rows.split("\n")) + "\n" + \
            "\n".join("f " + " ".join(str(int(i) + 1) for i in t) for t in f) + "\n"
    elif suffix == ".ply":
        text = (f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n"
                f"{rows}\n" + "\n".join("3 " + line for line in tris.split("\n")) + "\n")
    else:
        text = f"OFF\n{len(v)} {len(f)} 0\n{rows}\n" + "\n".join("3 " + line for line in tris.split("\n")) + "\n"
    path.write_text(text)


def _row_numbers(path):
    row = analyze_file(str(path), BatchOptions())
    return {k: row[k] for k in ("status", "mass", "volume", "com_x", "com_y", "com_z", "certificate", "faces")
            if k in row}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2 ** 31 - 1), suffix=st.sampled_from([".obj", ".ply", ".off"]))
def test_stray_vertices_change_nothing_on_any_path(seed, suffix, tmp_path):
    rng = np.random.default_rng(seed)
    v, f = _solid(rng)
    sv, sf = _with_strays(v, f, rng)
    clean = _outcome((v, f), True)
    assert clean[0][0] == "ok", clean                       # the generator makes solids
    for fast in (True, False):                              # arrays through the API, both paths
        assert _outcome((sv, sf), fast) == clean
    assert len(load_mesh((sv, sf)).vertices) == len(v)
    plain, stray = tmp_path / f"plain{suffix}", tmp_path / f"stray{suffix}"
    _write(plain, v, f)
    _write(stray, sv, sf)
    from_file = _outcome(str(plain), True)
    for fast in (True, False):                              # the file, both paths
        assert _outcome(str(stray), fast) == from_file
    assert _row_numbers(stray) == _row_numbers(plain)       # the batch's row (read once, fast path)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off"])
def test_one_stray_point_far_out_is_no_extent(suffix, tmp_path):
    """Review 10's D1 through each file format: a 0.1 × 0.2 × 0.3 m box with one point no face uses 50 m out read
    the box's extent (no implausible-size warning) and 1e5 m out was not "flat"."""
    v, f = box((0.1, 0.2, 0.3))
    for far in (50.0, 1e5):
        path = tmp_path / f"box{suffix}"
        _write(path, np.vstack([v, [[far, 0.0, 0.0]]]), f)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            props = mass_properties(str(path), density=1.0)
        assert caught == []
        assert props.mass == pytest.approx(0.006, rel=1e-12)
        assert props.mesh.bbox_max.tolist() == pytest.approx([0.05, 0.1, 0.15], rel=1e-15)


def test_the_callers_arrays_are_left_alone():
    """Arrays through the API are the caller's: leaving out a stray point copies them, never changes them."""
    v, f = box((1.0, 2.0, 3.0))
    v = np.vstack([[[7.0, 7.0, 7.0]], v])
    f = np.asarray(f, dtype=np.int64) + 1
    v0, f0 = v.copy(), f.copy()
    raw = load_mesh((v, f))
    assert np.array_equal(v, v0) and np.array_equal(f, f0)
    assert np.array_equal(raw.vertices, v0[1:]) and np.array_equal(raw.faces, f0 - 1)


def test_stl_vertices_are_all_used_so_the_reader_skips_the_pass(tmp_path):
    """The reader leaves out unused vertices on every path but STL's, whose vertices are the weld of the faces'
    corners (so every one is used): the premise checked on the bundled meshes, a binary soup and an ASCII file."""
    from pathlib import Path

    import trimesh

    paths = sorted((Path(__file__).resolve().parents[1] / "meshes").glob("*.stl"))
    v, f = torus(1.0, 0.3, 24, 12)
    soup = trimesh.Trimesh(v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3), process=False)
    for name, kind in (("soup.stl", "stl"), ("ascii.stl", "stl_ascii")):
        data = soup.export(file_type=kind)
        (tmp_path / name).write_bytes(data if isinstance(data, bytes) else data.encode())
        paths.append(tmp_path / name)
    assert len(paths) >= 5
    for path in paths:
        raw = load_mesh(str(path))
        used = np.zeros(len(raw.vertices), dtype=bool)
        used[raw.faces.ravel()] = True
        assert used.all(), path
