"""The tolerance weld's term in the certificate (mesh/precision.py ``weld_sweep``, mesh/certify.py; review 12's R4).

A weld that moved no corner keeps ``exact``; one whose moves are bounded within the round-off budget keeps it
with a note that says so; one beyond it gives an estimate within the weld's sweep, or a one-line refusal when
the sweep reaches the whole volume.  The sweep's formula is checked against its closed form on a unit cube.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from adversary_solids import box
from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError
from inertia_tool.mesh.merge import merge_close_vertices
from inertia_tool.mesh.precision import weld_sweep


def _soup(v: np.ndarray, f: np.ndarray, jitter: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Every triangle's corners written apart, each copy moved by ``jitter`` m in a random direction (the first
    copy of each vertex stays, so the weld's representative is the file's corner)."""
    rng = np.random.default_rng(seed)
    tri = v[f].reshape(-1, 3).copy()
    first = np.zeros(len(tri), dtype=bool)
    first[np.unique(f.reshape(-1), return_index=True)[1]] = True
    step = rng.normal(size=tri.shape)
    step *= jitter / np.linalg.norm(step, axis=1, keepdims=True)
    tri[~first] += step[~first]
    return tri, np.arange(len(tri)).reshape(-1, 3)


def test_the_sweep_of_one_moved_corner_is_its_closed_form():
    # unit cube; vertex 0 written twice, the faces [0, 5, 1] and [0, 6, 4] use a copy moved by d
    d = 3e-7
    v, f = box((1.0, 1.0, 1.0))
    copy = v[0] + np.array([0.6, 0.0, 0.8]) * d
    written = np.vstack([v, copy])
    faces = f.copy()
    faces[5, 0] = faces[9, 0] = len(v)
    merged = merge_close_vertices(written, faces, 1e-6)
    assert merged.merged_vertices == 1 and merged.representative is not None
    sweep = weld_sweep(written, faces, merged.faces, merged.representative, 1e-6)
    assert sweep is not None
    # reading (b) dominates: the six faces round vertex 0 (area 1/2, perimeter 2 + √2 each) within d;
    # reading (a) counts only the two faces that used the copy
    r = d * (1 + 1e-12)                            # the moves as stated: their norms' rounding covered
    per_face = 2 * r * 0.5 + 0.5 * math.pi * r * r * (2 + math.sqrt(2)) + 4 / 3 * math.pi * r ** 3
    assert sweep.volume == pytest.approx(3 * 6 * per_face * (1 + 1e-9), rel=1e-12)
    assert sweep.largest_move == pytest.approx(d, rel=1e-9)
    assert sweep.merged == 1
    np.testing.assert_array_equal(sweep.lo, v.min(0))
    assert np.all(sweep.hi >= v.max(0))


def test_a_weld_that_moved_nothing_has_no_sweep():
    v, f = box((1.0, 2.0, 3.0))
    written = np.vstack([v, v[:1]])                # vertex 0 listed twice, bit-identical
    faces = f.copy()
    faces[5, 0] = len(v)
    merged = merge_close_vertices(written, faces, 1e-6)
    assert merged.merged_vertices == 1
    assert weld_sweep(written, faces, merged.faces, merged.representative, 1e-6) is None


def test_a_weld_within_the_roundoff_budget_stays_exact_and_says_so():
    v, f = box((1.0, 1.0, 1.0))
    soup_v, soup_f = _soup(v, f, 4e-16, seed=1)      # copies a few float64 ulps apart
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = mass_properties((soup_v, soup_f), density=1.0)
    assert got.mesh.method == "welded"
    assert got.mesh.certificate.kind == "exact"
    assert any("within the round-off budget" in n for n in got.mesh.notes), got.mesh.notes
    assert got.mass == pytest.approx(1.0, rel=1e-12)


def test_a_weld_beyond_the_budget_is_an_estimate_whose_bound_holds():
    v, f = box((0.2, 0.3, 0.5))
    soup_v, soup_f = _soup(v, f, 2e-8, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = mass_properties((soup_v, soup_f), density=1.0)
    assert got.mesh.method == "welded"
    assert got.mesh.certificate.kind == "estimate"
    u = got.mesh.uncertainty
    assert 1e-10 < u.mass < 1e-5
    # the first copy of each corner stayed: the welded polyhedron is the box as drawn, within any bound
    assert abs(got.mass - 0.03) <= u.mass * 0.03
    assert any("weld's sweep" in n for n in got.mesh.notes)


def test_a_weld_that_collapses_a_thin_plate_is_refused_in_one_line():
    v, f = box((7e-3, 7e-3, 3e-9))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InvalidMeshError) as caught:
            mass_properties((v, np.vstack([f, f[:1]])), density=1.0)
    message = str(caught.value)
    assert "welding corners closer than" in message and "collapses the part" in message
    assert "\n" not in message


def test_a_welded_surface_that_passes_through_itself_is_united_then_bounded():
    # R3's arrangement of a welded soup: the union is of the welded polyhedron, so the weld's sweep still counts
    from solids import figure_eight

    v, f = figure_eight(steps=32, sections=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean = mass_properties((v, f), density=1.0)
        soup_v, soup_f = _soup(np.asarray(v, dtype=float), np.asarray(f), 1e-9, seed=3)
        got = mass_properties((soup_v, soup_f), density=1.0, repair=True)
    assert clean.mesh.certificate.kind == "united"
    assert got.mesh.certificate.kind == "estimate" and got.mesh.method == "welded"
    u = got.mesh.uncertainty
    assert 0 < u.mass < 1e-5
    assert abs(got.mass - clean.mass) <= u.mass * clean.mass
    assert np.linalg.norm(got.center_of_mass - clean.center_of_mass) <= u.center_of_mass
