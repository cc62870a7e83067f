"""The repair benchmark's own accounting (benchmarks/bench_repair.py, issue 25): a soup is judged against its
welded surface, not the unperturbed base 1e-7 away, and a checkout without its C kernels is refused, not timed."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks"))

import bench_repair  # noqa: E402


def _cube():
    v = np.array([[x, y, z] for x in (0.0, 2.0) for y in (0.0, 3.0) for z in (0.0, 5.0)])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def test_welded_volume_of_an_unmoved_soup_is_the_base_volume():
    v, f = _cube()
    assert bench_repair.welded_volume(v[f], f) == pytest.approx(30.0, rel=1e-15)
    assert bench_repair.clean_volume(v, f) == pytest.approx(30.0, rel=1e-15)


def test_welded_volume_keeps_the_first_copy_of_each_vertex():
    # every copy but the first of each vertex moved far: the welded surface is the cube's whatever they did
    v, f = _cube()
    tri = v[f].copy()
    seen = set()
    for i in range(len(f)):
        for j in range(3):
            if f[i, j] in seen:
                tri[i, j] += 0.25 * (j + 1)
            seen.add(int(f[i, j]))
    assert bench_repair.welded_volume(tri, f) == pytest.approx(30.0, rel=1e-15)
    # and moving a first copy moves the welded surface: vertex 0 (first seen in face 0) pulled out along -x
    tri[0, 0] = [-1.0, 0.0, 0.0]
    moved = v.copy()
    moved[0] = [-1.0, 0.0, 0.0]
    assert bench_repair.welded_volume(tri, f) == pytest.approx(bench_repair._volume(moved[f]), rel=1e-15)
    assert bench_repair.welded_volume(tri, f) > 30.0


def test_soup_case_truth_is_the_welded_surface(tmp_path, monkeypatch):
    # the bug: the soup's truth was the unperturbed base, so "vol err" compared with a surface 1e-7 away
    monkeypatch.setitem(bench_repair.BASES, "torus", lambda: bench_repair.ring_torus(24, 12))    # 576 faces
    cases = bench_repair.build(["torus"], ["soup", "hole"], 0, str(tmp_path))
    soup = next(c for c in cases if c["case"] == "torus_soup")
    hole = next(c for c in cases if c["case"] == "torus_hole")
    v, f = bench_repair.BASES["torus"]()
    rng = np.random.default_rng([0, bench_repair.KINDS.index("soup"), len(f)])
    tri = bench_repair.damage("soup", v, f, rng)
    assert soup["truth_mm3"] == bench_repair.welded_volume(tri, f)
    assert hole["truth_mm3"] == bench_repair.clean_volume(v, f)
    assert soup["truth_mm3"] != hole["truth_mm3"]
    assert abs(soup["truth_mm3"] / hole["truth_mm3"] - 1) < 1e-6
    assert all(os.path.dirname(c["path"]) == str(tmp_path) for c in cases)


def test_a_checkout_without_its_c_kernels_is_refused(tmp_path, monkeypatch):
    # a package whose _native says the kernels are not loaded (what a stale build does)
    pkg = tmp_path / "inertia_tool"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "_native.py").write_text("def accel():\n    return None\n")
    monkeypatch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
    with pytest.raises(SystemExit, match="C kernels .* are not loaded"):
        bench_repair.require_c_kernels(str(tmp_path))
    monkeypatch.setenv("INERTIA_TOOL_NO_ACCEL", "1")         # numpy on purpose: timed
    bench_repair.require_c_kernels(str(tmp_path))

