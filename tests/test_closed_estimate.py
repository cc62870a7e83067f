"""mesh/grid_estimate.py closed_surface_estimate: the solid {w ≥ 1} of a closed surface passing through itself when
the exact arrangement cannot be built (issues 21 and 23).

Truths are independent: manifold3d float64 unions of the closed pieces (boxes in special position: coplanar
overlapping faces, a corner exactly on a crossed face, edges through edges), which the grid never sees.  The
claim tested is the docstring's assumption-free bound: decided-inside ⊆ truth ⊆ decided-inside ∪ undecided,
so the volume, centre of mass and inertia lie within the stated bounds.
"""

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adversary_solids as S
from inertia_tool import mass_properties
from inertia_tool.errors import ArrangementError, InvalidMeshError
from inertia_tool.mesh.grid_estimate import closed_surface_estimate, winding_estimate


def _inertia(second_moment):
    return np.trace(second_moment) * np.eye(3) - second_moment


def _truth_within(est, truth):
    """The truth lies within the estimate's bounds (mass, centre of mass, inertia) and the set bound."""
    unc = est.uncertainty
    assert abs(est.volume - truth.volume) <= unc.mass * est.volume * (1 + 1e-9)
    assert abs(est.volume - truth.volume) <= unc.volume_in_doubt * (1 + 1e-9)
    assert np.linalg.norm(est.centroid - truth.centroid) <= unc.center_of_mass * (1 + 1e-9)
    got = _inertia(est.second_moment)
    assert np.linalg.norm(got - truth.inertia) <= unc.inertia * np.linalg.norm(got) * (1 + 1e-9)


def _special_boxes(offset, extents=(1.0, 0.6, 1.0)):
    a = S.box([1.0, 1.0, 1.0])
    b = S.box(list(extents), offset)
    return [a, b]


@pytest.mark.parametrize("offset", [[0.4, 0.1, 0.0], [0.5, 0.5, 0.2], [0.5, 0.5, 0.5], [0.0, 0.2, 0.0]])
def test_boxes_in_special_position_lie_within_the_bounds(offset):
    """Coplanar overlapping faces, a corner on a face, edges through edges: manifold3d's union lies within."""
    pieces = _special_boxes(offset)
    v, f = S.concat(*pieces)
    est = closed_surface_estimate(v, f)
    assert est.method == "winding"
    _truth_within(est, S.truth_from_manifold(pieces))


def test_corner_exactly_on_a_crossed_face_lies_within_the_bounds():
    """A box turned 45° about z whose edge (two corners) lies exactly in the top plane of the other box, and
    which crosses that box's sides: the degenerate crossing of the issue."""
    a = S.box([1.0, 1.0, 1.0])
    bv, bf = S.box([0.8, 0.8, 0.6], [0.0, 0.0, 0.0])
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    bv = bv @ rot.T + np.array([0.5, 0.0, 0.2])      # top at z = 0.5: the top face of a
    v, f = S.concat(a, (bv, bf))
    est = closed_surface_estimate(v, f)
    _truth_within(est, S.truth_from_manifold([a, (bv, bf)]))


def test_refinement_narrows_the_bound_and_keeps_the_truth():
    """The refined grid is chosen by the rule (bound/target), and its bound is narrower than the coarse one's."""
    pieces = _special_boxes([0.4, 0.1, 0.0])
    v, f = S.concat(*pieces)
    first = winding_estimate(v, f, resolution=16)
    refined = closed_surface_estimate(v, f, resolution=16, target=0.02, max_resolution=64)
    assert refined.uncertainty.mass < first.uncertainty.mass
    assert "×" in refined.detail and refined.detail != first.detail
    truth = S.truth_from_manifold(pieces)
    _truth_within(first, truth)
    _truth_within(refined, truth)


def test_a_part_thinner_than_the_first_grid_is_refined_to_the_finest():
    """A thin figure-eight tube: no cell of a 16-cell grid is decided inside (the first estimate has no volume
    and no bound); the finest grid is built, and the union of the two halves lies within its bounds.  (Radius
    0.1: at 0.2 the 16-cell grid decides cells inside since session 16 marks only the cells the surface
    meets.)"""
    v, f, halves = S.tube_halves(0.1, 0.1, rings=48, sections=8)
    assert winding_estimate(v, f, resolution=16).volume == 0
    est = closed_surface_estimate(v, f, resolution=16, max_resolution=64)
    assert est.volume > 0 and np.isfinite(est.uncertainty.mass)
    _truth_within(est, S.truth_from_manifold(list(halves)))


def test_no_refinement_when_the_first_grid_meets_the_target():
    pieces = _special_boxes([0.4, 0.1, 0.0])
    v, f = S.concat(*pieces)
    assert closed_surface_estimate(v, f, target=1.0).detail == winding_estimate(v, f).detail


@settings(max_examples=20, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), count=st.integers(2, 3))
def test_boxes_on_a_half_unit_grid_lie_within_the_bounds(data, count):
    """Boxes with corners on a half-unit grid (coplanar faces and corners on faces everywhere), some turned
    inward-free and overlapping: the union lies within the bounds of the grid estimate."""
    boxes = []
    for _ in range(count):
        lo = np.array([data.draw(st.integers(0, 3)) for _ in range(3)]) / 2
        size = np.array([data.draw(st.integers(1, 3)) for _ in range(3)]) / 2
        boxes.append(S.box(size, lo + size / 2, subdivide=data.draw(st.integers(0, 1))))
    v, f = S.concat(*boxes)
    est = closed_surface_estimate(v, f, resolution=24, max_resolution=48)
    _truth_within(est, S.truth_from_manifold(boxes))


def test_repair_gives_an_estimate_when_the_arrangement_fails(monkeypatch):
    """Issue 21/23: a shell passing through itself whose arrangement fails is estimated under repair=True, with
    the arrangement's reason in the notes; the union of its two halves lies within the bounds."""
    import inertia_tool.mesh.arrange as arrange

    def fail(*args, **kwargs):
        raise ArrangementError("a corner of a face lies exactly in the plane of a face it crosses")

    monkeypatch.setattr(arrange, "arrange_crossings", fail)
    v, f, halves = S.tube_halves(0.1, 0.2, rings=48, sections=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InvalidMeshError, match="could not be built"):
            mass_properties((v, f), density=1.0)
        props = mass_properties((v, f), density=1.0, repair=True)
    report = props.mesh
    assert report.certificate.kind == "estimate"
    assert any("a corner of a face lies exactly" in n for n in report.notes)
    truth = S.truth_from_manifold(list(halves))
    unc = report.uncertainty
    assert abs(props.volume - truth.volume) <= unc.mass * props.volume
    assert np.linalg.norm(props.center_of_mass - truth.centroid) <= unc.center_of_mass
    assert np.linalg.norm(props.central_inertia - truth.inertia) <= unc.inertia * np.linalg.norm(props.central_inertia)


QB_MOVE = Path("/work/data/menagerie/iit_softfoot/meshes/qb_move_advanced_for_mate.stl")


@pytest.mark.slow
@pytest.mark.skipif(not QB_MOVE.exists(), reason="the Menagerie snapshot is not on this machine")
def test_qb_move_is_estimated_consistently():
    """The Menagerie link refused before (109 degenerate crossing pairs): now an estimate whose two grids agree
    (the finer estimate lies within the coarser one's bounds) and whose bound is useful."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties(str(QB_MOVE), density=1.0, repair=True, units="mm")
    assert props.mesh.certificate.kind == "estimate"
    unc = props.mesh.uncertainty
    assert unc.mass <= 0.5
    # independent: the file's signed integral is ∫ w dV (manifold3d accepts the mesh and returns that sum,
    # 7.4005e-5 m³); with w ≥ 0 it is at least the volume of {w ≥ 1}, so the estimate's lower end lies below it
    import trimesh
    mesh = trimesh.load(str(QB_MOVE), process=False)
    summed = abs(float(mesh.volume)) * 1e-9
    assert props.volume * (1 - unc.mass) <= summed
    # the coarse first grid's interval and the answer's both contain the truth, so they overlap
    from inertia_tool.mesh.grid_estimate import winding_estimate
    mesh.merge_vertices()
    coarse = winding_estimate(np.asarray(mesh.vertices) * 1e-3, np.asarray(mesh.faces))
    lo, hi = coarse.volume * (1 - coarse.uncertainty.mass), coarse.volume * (1 + coarse.uncertainty.mass)
    assert props.volume * (1 - unc.mass) <= hi and props.volume * (1 + unc.mass) >= lo


def test_useless_bound_is_still_refused_with_the_arrangement_reason(monkeypatch):
    """Past the 50 % mass rule the estimate is refused, and the message keeps why the arrangement failed (a
    grid of 24 cells on a thin figure-eight tube: ±97 %)."""
    import inertia_tool.mesh.arrange as arrange
    import inertia_tool.mesh.grid_estimate as estimate

    def fail(*args, **kwargs):
        raise ArrangementError("a corner of a face lies exactly in the plane of a face it crosses")

    monkeypatch.setattr(arrange, "arrange_crossings", fail)
    original = estimate.closed_surface_estimate
    monkeypatch.setattr(estimate, "closed_surface_estimate",
                        lambda v, f, **kw: original(v, f, resolution=24, max_resolution=24))
    v, f, _ = S.tube_halves(0.1, 0.2, rings=48, sections=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InvalidMeshError, match=r"could not be built: a corner of a face.*cannot be bounded "
                                                   r"usefully"):
            mass_properties((v, f), density=1.0, repair=True)


# -- corrected_estimate: the exact signed integral corrected where w may leave {0, 1} (issue 23) ----------------

from inertia_tool.mesh.grid_estimate import corrected_estimate  # noqa: E402


def _thin_cross(thickness=0.004, subdivide=4):
    """Two thin plates (1 × 1 × ``thickness``) crossing at right angles through each other's middle."""
    a = S.box([1.0, 1.0, thickness], subdivide=subdivide)
    b = S.box([1.0, thickness, 1.0], [0.0, 0.0, 0.3], subdivide=subdivide)
    return [a, b]


@pytest.mark.parametrize("resolution", [32, 64])
def test_thin_crossing_plates_are_found_where_the_grid_found_nothing(resolution):
    """Issue 23 (TIAGo ``base.stl``, "encloses a volume of 0 m³"): plates thinner than every cell (no cell
    decided inside: the plain grid encloses nothing) get a positive corrected estimate whose bounds hold
    (manifold3d's union)."""
    pieces = _thin_cross()
    v, f = S.concat(*pieces)
    assert winding_estimate(v, f, resolution=resolution).volume == 0
    est = corrected_estimate(v, f, resolution=resolution)
    assert est is not None and est.volume > 0 and np.isfinite(est.uncertainty.mass)
    assert "signed integral" in est.detail
    _truth_within(est, S.truth_from_manifold(pieces))


def test_closed_surface_estimate_takes_the_corrected_estimate_for_a_thin_part():
    """The rule: the first grid decides nothing inside, so the corrected estimate is built on the finest grid;
    with a bound past the target the plain finest grid is built too and the smaller proven bound is given."""
    pieces = _thin_cross()
    v, f = S.concat(*pieces)
    est = closed_surface_estimate(v, f, resolution=16, max_resolution=48)
    assert est.volume > 0
    _truth_within(est, S.truth_from_manifold(pieces))


def test_corrected_estimate_of_a_closed_solid_without_crossings_is_its_integral():
    """No face meets another: every face separates 0 and 1, nothing but round-off is in doubt, and the estimate is the
    solid's exact integral (a subdivided box)."""
    piece = S.box([0.3, 0.2, 0.01], subdivide=1)
    est = corrected_estimate(*piece, resolution=32)
    assert est is not None and est.uncertainty.volume_in_doubt <= 1e-12 * est.volume   # round-off only
    assert est.volume == pytest.approx(0.3 * 0.2 * 0.01, rel=1e-12)


def test_corrected_estimate_counts_a_region_enclosed_twice_once():
    """A box inside another, both outward (w = 2 in the inner one): the signed integral counts it twice, the
    correction removes it exactly (the inner box's cells are decided)."""
    outer = S.box([1.0, 1.0, 1.0])
    inner = S.box([0.4, 0.4, 0.4])
    v, f = S.concat(outer, inner)
    est = corrected_estimate(v, f, resolution=40)
    assert est is not None
    _truth_within(est, S.truth_from_manifold([outer]))


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), count=st.integers(2, 3))
def test_corrected_bounds_hold_for_overlapping_thin_and_thick_boxes(data, count):
    """Boxes of random size (some thinner than a cell), position and subdivision, overlapping: manifold3d's
    union lies within the corrected estimate's bounds whenever it is built."""
    boxes = []
    for _ in range(count):
        size = np.array([data.draw(st.sampled_from([0.003, 0.02, 0.3, 0.7])) for _ in range(3)])
        centre = np.array([data.draw(st.floats(-0.3, 0.3)) for _ in range(3)])
        boxes.append(S.box(size, centre, subdivide=data.draw(st.integers(0, 1))))
    v, f = S.concat(*boxes)
    est = corrected_estimate(v, f, resolution=data.draw(st.sampled_from([16, 40])))
    if est is None:
        return
    _truth_within(est, S.truth_from_manifold(boxes))


def test_corrected_bounds_hold_for_a_self_crossing_tube():
    """The figure-eight tube (one shell passing through itself): the union of its halves lies within."""
    v, f, halves = S.tube_halves(0.1, 0.2, rings=48, sections=8)
    est = corrected_estimate(v, f, resolution=48)
    assert est is not None
    _truth_within(est, S.truth_from_manifold(list(halves)))


def test_open_self_crossing_thin_part_is_refined_instead_of_enclosing_nothing():
    """Issue 23 (Barkour vb ``upper_leg_right.stl``: "encloses a volume of 0 m³"): an open surface passing through
    itself, thinner than the first grid's cells, is estimated again on the finest grid; the union of the
    closed plates lies within the bounds (one small triangle missing from each)."""
    from inertia_tool.mesh.grid_estimate import open_surface_estimate
    pieces = _thin_cross(thickness=0.03, subdivide=3)
    opened = [(pv, pf[1:]) for pv, pf in pieces]
    v, f = S.concat(*opened)
    assert winding_estimate(v, f, resolution=24).volume == 0
    est = open_surface_estimate(v, f, resolution=24, max_resolution=96)
    assert est.volume > 0 and np.isfinite(est.uncertainty.mass)
    _truth_within(est, S.truth_from_manifold(pieces))


@pytest.mark.parametrize("extent", [(1.0, 1.0, 1.0), (0.2, 0.36, 1.0), (0.01, 1.0, 1.0)])
def test_budget_resolution_keeps_the_grid_within_its_cells(extent):
    """Issue 23 item 2: the finest grid is bounded by cells, not by the longest side: a long or flat part
    goes finer for the same memory, and the padded grid never exceeds the budget."""
    from inertia_tool.mesh.grid_estimate import budget_resolution
    v = np.array([[0.0, 0.0, 0.0], extent])
    n = budget_resolution(v, 226 ** 3)
    share = np.array(extent) / max(extent)
    assert np.prod(np.ceil(share * n) + 2) <= 226 ** 3
    assert n >= 220 and (max(extent) == min(extent) or n > 300)


def test_a_long_thin_closed_part_gets_a_bound_within_the_target_from_the_cell_budget():
    """A long self-crossing figure-eight tube: refined past 224 cells along its length (the cell budget), its
    bound narrows below what a 224-cell grid gives, and the union of its halves stays within it."""
    v, f, halves = S.tube_halves(0.1, 0.2, rings=48, sections=8)
    v = v * np.array([1.0, 1.0, 6.0])
    halves = [(hv * np.array([1.0, 1.0, 6.0]), hf) for hv, hf in halves]
    capped = closed_surface_estimate(v, f, resolution=32, max_resolution=64)
    budget = closed_surface_estimate(v, f, resolution=32, target=1e-3)
    assert budget.uncertainty.mass < capped.uncertainty.mass
    _truth_within(budget, S.truth_from_manifold(list(halves)))


def _counting_grids(monkeypatch):
    import inertia_tool.mesh.grid_estimate as est
    built = []
    real = est.winding_estimate
    monkeypatch.setattr(est, "winding_estimate", lambda *a, **k: built.append(k.get("resolution")) or real(*a, **k))
    return est, built, real


def test_one_grid_is_built_for_a_closed_surface(monkeypatch):
    """Issue 23 item 6 (UR5e `--repair`): the estimate of a closed self-crossing surface builds one winding grid,
    at the resolution predicted from the crossed cells of the coarse grid and the signed volume, not the
    coarse grid in full and then the refined one; its bound is its own and the union lies within it."""
    est, built, real = _counting_grids(monkeypatch)
    pieces = [S.box([1.0, 1.0, 1.0]), S.box([1.0, 0.6, 1.0], [0.95, 0.1, 0.0])]      # a small overlap
    v, f = S.concat(*pieces)
    chosen = est.predicted_resolution(v, f, resolution=16, target=0.2, max_resolution=96)
    got = est.closed_surface_estimate(v, f, resolution=16, target=0.2, max_resolution=96)
    assert built == [chosen] and 16 < chosen < 96
    assert got.uncertainty.mass <= est.CLOSED_PREDICTION_SLACK * 0.2
    _truth_within(got, S.truth_from_manifold(pieces))
    # the prediction is the old rule's (the coarse grid's bound over the target) without building that grid
    coarse = real(v, f, resolution=16)
    assert abs(chosen - 16 * coarse.uncertainty.mass / 0.2) <= 0.1 * chosen
    assert est.predicted_resolution(v, f, resolution=16, target=1.0, max_resolution=64) == 16
    assert est.predicted_resolution(v, f, resolution=64, target=0.02, max_resolution=64) == 64


def test_a_grid_predicted_too_coarse_is_refined_once_by_its_own_bound(monkeypatch):
    """Two boxes overlapping by half: the signed volume counts the overlap twice, the predicted grid misses the
    target by more than the slack, and one more grid is built at its bound over the target (the answer)."""
    est, built, real = _counting_grids(monkeypatch)
    pieces = _special_boxes([0.4, 0.1, 0.0])
    v, f = S.concat(*pieces)
    got = est.closed_surface_estimate(v, f, resolution=16, target=0.2, max_resolution=96)
    assert len(built) == 2 and built[0] < built[1] <= 96
    first = real(v, f, resolution=built[0])
    assert first.uncertainty.mass > est.CLOSED_PREDICTION_SLACK * 0.2
    assert built[1] == min(96, int(np.ceil(built[0] * first.uncertainty.mass / 0.2)))
    assert got.detail == real(v, f, resolution=built[1]).detail
    _truth_within(got, S.truth_from_manifold(pieces))


@settings(max_examples=40, deadline=None, derandomize=True)
@given(shape=st.tuples(st.integers(1, 9), st.integers(1, 9), st.integers(1, 9)), seed=st.integers(0, 2 ** 31),
       h=st.sampled_from([1e-3, 0.25, 3.0]), far=st.sampled_from([0.0, 1e3]))
def test_grid_moments_equal_the_cell_by_cell_sums(shape, seed, h, far):
    """``_grid_moments`` (marginal sums, no per-cell coordinates) against the cubes summed one by one: the
    volume, centroid and second moment about it (each cube ``h²/12`` of its volume about its own centre)."""
    from inertia_tool.mesh.grid_estimate import _grid_moments
    rng = np.random.default_rng(seed)
    weight = rng.integers(0, 3, size=shape).astype(np.uint8)
    if not weight.any():
        weight[0, 0, 0] = 1
    lo = rng.normal(size=3) + far
    idx = np.argwhere(weight > 0)
    wt = 0.5 * weight[tuple(idx.T)].astype(np.float64)
    centres = lo + h * (idx + 0.5)
    vol = wt.sum() * h ** 3
    c = (wt[:, None] * centres).sum(axis=0) / wt.sum()
    d = centres - c
    second = h ** 3 * ((wt[:, None] * d).T @ d) + vol * h ** 2 / 12 * np.eye(3)
    got_vol, got_c, got_second = _grid_moments(weight, lo, h, scale=0.5)
    assert got_vol == pytest.approx(vol, rel=1e-12)
    assert np.allclose(got_c, c, rtol=0, atol=1e-12 * (abs(far) + 1 + h * 10))
    assert np.allclose(got_second, second, rtol=0, atol=1e-11 * np.abs(second).max())


def test_the_winding_grid_holds_no_per_cell_coordinates():
    """Issue 23 item 6 (UR5e: 1.5 GB): the grid's arrays stay near 12 bytes a cell (crossed, w, two codes, the
    region labels), not the 24-byte centres and float64 weights of every cell; numpy's allocations are traced."""
    import tracemalloc
    pieces = _special_boxes([0.4, 0.1, 0.0])
    v, f = S.concat(*pieces)
    winding_estimate(v, f, resolution=16)                     # imports and caches outside the trace
    tracemalloc.start()
    try:
        est = winding_estimate(v, f, resolution=160)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    cells = np.prod([int(x) for x in est.detail.split(" grid")[0].split()[-1].split("×")])
    assert cells > 2_000_000
    assert peak < 40 * cells, (peak, cells)


@pytest.mark.slow
@settings(max_examples=10, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(data=st.data(), count=st.integers(2, 3), holes=st.integers(1, 3))
def test_crossing_boxes_with_holes_lie_within_the_repair_bounds(data, count, holes, monkeypatch):
    """Issue 23 item 6 (robots4): crossing boxes with triangles missing (holes), the boolean union and the
    arrangement made to fail so that `repair=True` patches the holes and takes the one-grid winding estimate (the
    patches' doubt added); the manifold3d union of the undamaged boxes (which the estimate never sees) lies
    within the reported bounds, or the mesh is refused."""
    import inertia_tool.mesh.arrange as arrange
    import inertia_tool.mesh.union as union

    def fail(*args, **kwargs):
        raise ArrangementError("forced: the arrangement is not built in this test")

    def no_union(*args, **kwargs):
        raise union.UnionError("forced: the boolean union is not formed in this test")

    monkeypatch.setattr(arrange, "arrange_crossings", fail)
    monkeypatch.setattr(union, "union_surface", no_union)
    boxes = []
    for _ in range(count):
        size = np.array([data.draw(st.integers(2, 6)) for _ in range(3)]) / 4
        centre = np.array([data.draw(st.integers(-3, 3)) for _ in range(3)]) / 8 + 0.013 * len(boxes)
        boxes.append(S.box(size, centre, subdivide=1))
    v, f = S.concat(*boxes)
    # one triangle missing from `holes` boxes' faces, none sharing an edge with another missing one
    drop: list = []
    for index in data.draw(st.lists(st.integers(0, len(f) - 1), min_size=holes, max_size=holes, unique=True)):
        if all(len(set(f[index]) & set(f[j])) < 2 for j in drop):
            drop.append(index)
    damaged = np.delete(f, drop, axis=0)
    truth = S.truth_from_manifold(boxes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            props = mass_properties((v, damaged), density=1.0, repair=True)
        except InvalidMeshError:
            return                                         # refused: no number, nothing to hold
    unc = props.mesh.uncertainty
    assert props.mesh.certificate.kind == "estimate"
    assert abs(props.volume - truth.volume) <= unc.mass * props.volume * (1 + 1e-9) + 1e-12
    assert np.linalg.norm(props.center_of_mass - truth.centroid) <= unc.center_of_mass * (1 + 1e-9) + 1e-12
    assert np.linalg.norm(props.central_inertia - truth.inertia) <= \
        unc.inertia * np.linalg.norm(props.central_inertia) * (1 + 1e-9) + 1e-12


def test_a_plain_grid_that_misses_the_target_is_weighed_against_the_corrected_estimate():
    """Regression (robots4, found on Menagerie's Barkour vb ``upper_leg_left.stl``: ±48.6 % answered on main,
    ±55.7 % refused by the one-grid rule): the one grid decides cells inside but misses the target, where the old
    coarse grid had found nothing inside and gone to the corrected estimate; now the corrected estimate on the
    finest grid is built too and the narrower proven bound is given.  Two crossing plates 0.04 thick (0.06
    before session 16, whose crossed cells are only those the surface meets: the plain grid's ±83.5 % became
    ±41.6 % at 0.06, within the limit).  Here the plain grid's ±71.5 % is narrower than the corrected estimate's
    ±115 % (before session 16, at 0.06, the corrected ±83.2 % beat the plain ±83.5 %): the rule, not the winner,
    is what is checked."""
    from inertia_tool.mesh.grid_estimate import corrected_estimate
    pieces = _thin_cross(thickness=0.04)
    v, f = S.concat(*pieces)
    plain = winding_estimate(v, f, resolution=48)
    assert plain.volume > 0 and plain.uncertainty.mass > 0.5
    corrected = corrected_estimate(v, f, resolution=48)
    assert corrected is not None
    est = closed_surface_estimate(v, f, resolution=16, max_resolution=48)
    assert est.uncertainty.mass == min(plain.uncertainty.mass, corrected.uncertainty.mass)
    _truth_within(est, S.truth_from_manifold(pieces))
    _truth_within(corrected, S.truth_from_manifold(pieces))


def _plates_meeting_at_an_edge(thickness, overlap, subdivide):
    """A plate 1 × 1 × ``thickness`` and a plate 1 × ``thickness`` × 1 standing on its edge, the two crossing only
    in a small box (``overlap`` × ``thickness`` × ``thickness``) at the first plate's edge: thin parts (the plain
    grid's doubt is all their surface) with a small crossing (the corrected estimate's doubt is near it only)."""
    a = S.box([1.0, 1.0, thickness], subdivide=subdivide)
    b = S.box([1.0, thickness, 1.0], [1.0 - overlap, 0.0, 0.5 - overlap], subdivide=subdivide)
    lo = np.maximum([-0.5, -0.5, -thickness / 2], [0.5 - overlap, -thickness / 2, -overlap])
    hi = np.minimum([0.5, 0.5, thickness / 2], [1.5 - overlap, thickness / 2, 1.0 - overlap])
    # the closed form of the union, by inclusion–exclusion of the three boxes (exact rationals; unsubdivided boxes)
    truth = S.truth_from_pieces([(1, S.box([1.0, 1.0, thickness])),
                                 (1, S.box([1.0, thickness, 1.0], [1.0 - overlap, 0.0, 0.5 - overlap])),
                                 (-1, S.box(hi - lo, (lo + hi) / 2))])
    return S.concat(a, b), truth


@pytest.mark.parametrize("thickness, overlap, subdivide, finest", [(0.06, 0.1, 2, 48), (0.04, 0.05, 3, 64)])
def test_the_corrected_estimate_beats_a_plain_grid_past_the_refusal_bound(thickness, overlap, subdivide, finest,
                                                                         monkeypatch):
    """The branch of closed_surface_estimate where the plain grid decides cells inside but its bound is past the
    refusal's ±50 %, and the corrected estimate's proven bound is narrower: the corrected estimate is the answer,
    and it holds the closed form.  (Found by a search over plates meeting at an edge, tidy17: thickness 0.02-0.06,
    overlap 0.05-0.1, 2-3 subdivisions, finest grids of 32-64 cells; 12 of 36 shapes take this branch.  Since
    session 16's tighter cell marking the crossing plates above no longer reach it: the plain grid wins there.)"""
    from inertia_tool.mesh import grid_estimate
    from inertia_tool.tolerances import ESTIMATE_MAX_MASS_RTOL
    (v, f), truth = _plates_meeting_at_an_edge(thickness, overlap, subdivide)
    grids, corrected = [], []
    plain_grid, plain_corrected = grid_estimate.winding_estimate, grid_estimate.corrected_estimate
    monkeypatch.setattr(grid_estimate, "winding_estimate", lambda *a, **k: grids.append(plain_grid(*a, **k))
                        or grids[-1])
    monkeypatch.setattr(grid_estimate, "corrected_estimate",
                        lambda *a, **k: corrected.append(plain_corrected(*a, **k)) or corrected[-1])
    est = closed_surface_estimate(v, f, resolution=16, max_resolution=finest)
    assert grids and grids[-1].volume > 0                             # the plain grid decided cells inside
    assert grids[-1].uncertainty.mass > ESTIMATE_MAX_MASS_RTOL        # ... and would be refused
    assert len(corrected) == 1 and est is corrected[0]                # the corrected estimate is the answer
    assert est.uncertainty.mass < grids[-1].uncertainty.mass <= 1.0
    assert est.uncertainty.mass < ESTIMATE_MAX_MASS_RTOL              # answered, not refused
    _truth_within(est, truth)
    _truth_within(grids[-1], truth)
