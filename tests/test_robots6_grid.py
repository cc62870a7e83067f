"""The winding grid's faster paths give the grid of before, bit for bit (issue 23: UR5e ``--geometry visual
--repair`` under 5 s).

* ``_accel.label_cells`` (section 11) numbers the regions of free cells as ``scipy.ndimage.label`` does (its
  default, face-connected structure; regions in the order of their first cells), with each region's first cell
  and size: checked against scipy and a brute-force first cell on hypothesis-generated grids.
* ``_first_cells`` (scipy's labels without the kernel): the running-maximum shortcut, and the scatter it falls
  back to when labels are not in first-cell order, against a brute force.
* ``_accel.surface_cells`` (session 16; before, ``sample_cells``, which skipped a division per sample) marks the
  cells numpy marks with vertices on the cell boundaries themselves (lattice coordinates, where rounding
  decides which side a corner is on).
* A grid whose free cells are all settled by their regions takes its codes from the regions
  (``_region_codes``); the estimate equals, field for field and bit for bit, the one built from every cell's
  winding number (``_cell_codes``) on closed self-crossing solids, inside out, and nested (winding number 2).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import inertia_tool.mesh.grid_estimate as est
from conftest import HAVE_ACCEL
from solids import box, uv_sphere

scipy_ndimage = pytest.importorskip("scipy.ndimage")


def _grids():
    return st.tuples(st.integers(1, 7), st.integers(1, 7), st.integers(1, 7), st.integers(0, 2 ** 32 - 1),
                     st.floats(0.05, 0.95))


def _mask(dims, seed, share):
    return np.random.default_rng(seed).random(dims) < share


@pytest.mark.skipif(not HAVE_ACCEL, reason="C extension not built")
@settings(max_examples=40, deadline=None, derandomize=True)
@given(grid=_grids())
def test_label_cells_numbers_regions_as_scipy_with_first_cells_and_sizes(grid):
    from inertia_tool._native import accel
    *dims, seed, share = grid
    mask = _mask(tuple(dims), seed, share)
    out = np.empty(mask.size, dtype=np.int32)
    count, first, sizes = accel().label_cells(mask.reshape(-1).view(np.uint8), tuple(dims), out)
    truth, n = scipy_ndimage.label(mask)
    truth = truth.reshape(-1)
    assert count == n
    assert np.array_equal(out, truth)
    brute_first = [int(np.flatnonzero(truth == k)[0]) for k in range(1, n + 1)]
    assert np.frombuffer(first, dtype=np.int64).tolist() == brute_first
    assert np.frombuffer(sizes, dtype=np.int64).tolist() == [int(np.sum(truth == k)) for k in range(1, n + 1)]


@pytest.mark.skipif(not HAVE_ACCEL, reason="C extension not built")
@pytest.mark.parametrize("dims", [(1, 1, 1), (1, 1, 9), (3, 1, 1), (4, 4, 4)])
@pytest.mark.parametrize("fill", [0, 1])
def test_label_cells_on_empty_and_full_grids(dims, fill):
    from inertia_tool._native import accel
    mask = np.full(dims, bool(fill))
    out = np.full(mask.size, -7, dtype=np.int32)
    count, first, sizes = accel().label_cells(mask.reshape(-1).view(np.uint8), dims, out)
    assert count == fill
    assert np.all(out == fill)
    assert np.frombuffer(first, dtype=np.int64).tolist() == ([0] if fill else [])
    assert np.frombuffer(sizes, dtype=np.int64).tolist() == ([mask.size] if fill else [])


@pytest.mark.skipif(not HAVE_ACCEL, reason="C extension not built")
def test_label_cells_refuses_a_wrong_buffer():
    from inertia_tool._native import accel
    mask = np.ones(8, dtype=np.uint8)
    with pytest.raises(ValueError, match="int32"):
        accel().label_cells(mask, (2, 2, 2), np.empty(8, dtype=np.int64))
    with pytest.raises(ValueError, match="prod"):
        accel().label_cells(mask, (2, 2, 3), np.empty(12, dtype=np.int32))


@settings(max_examples=40, deadline=None, derandomize=True)
@given(grid=_grids(), shuffle=st.booleans())
def test_first_cells_by_the_running_maximum_or_the_scatter(grid, shuffle):
    *dims, seed, share = grid
    labels, n = scipy_ndimage.label(_mask(tuple(dims), seed, share))
    labels = labels.reshape(-1)
    if shuffle and n > 1:                   # labels out of first-cell order: the shortcut must notice
        perm = np.concatenate([[0], 1 + np.random.default_rng(seed).permutation(n)]).astype(labels.dtype)
        labels = perm[labels]
    brute = [int(np.flatnonzero(labels == k)[0]) for k in range(1, n + 1)]
    assert est._first_cells(labels, n).tolist() == brute


def test_label_regions_without_the_kernel_is_scipy(monkeypatch):
    import inertia_tool._native as native
    mask = _mask((5, 6, 7), 3, 0.6)
    with_kernel = est._label_regions(mask.reshape(-1), (5, 6, 7))
    monkeypatch.setattr(native, "accel", lambda: None)
    labels, n, first, sizes = est._label_regions(mask.reshape(-1), (5, 6, 7))
    assert first is None and sizes is None
    truth, m = scipy_ndimage.label(mask)
    assert n == m and np.array_equal(labels, truth.reshape(-1))
    if HAVE_ACCEL:
        assert with_kernel[1] == n and np.array_equal(with_kernel[0], labels)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(1, 30), cells=st.integers(2, 12),
       offset=st.sampled_from([0.0, 3.0, -250.0]))
def test_sample_cells_on_cell_boundaries_marks_the_cells_numpy_marks(seed, n, cells, offset):
    """Vertices on the lattice of cell corners (and halfway), so samples fall on or within round-off of cell
    faces, where ``floor(d * (1/h))`` and ``floor(d / h)`` can differ: the kernel must take the quotient there."""
    rng = np.random.default_rng(seed)
    h = float(rng.choice([0.1, 0.3, 1.0 / 3.0, 0.07]))
    lo = np.full(3, offset * h)
    dims = (cells, cells + 1, cells + 2)
    corners = lo + h * rng.integers(-1, cells + 2, size=(3 * n, 3)) * rng.choice([1.0, 0.5], size=(3 * n, 1))
    v = corners.astype(np.float64)
    f = np.arange(3 * n, dtype=np.int64).reshape(n, 3)
    with pytest.MonkeyPatch.context() as patch:
        patch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
        fast = est._surface_cells(v, f, lo, h, dims)
        patch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
        slow = est._surface_cells(v, f, lo, h, dims)
    assert np.array_equal(fast, slow)


def _per_cell_codes(regions, w_low, w_high):
    """The codes from every cell's winding number, as the grid forms them without the regions' shortcut."""
    w = np.where(regions.region > 0, regions.whole[regions.region], 0.5)
    crossed = regions.region == 0
    return est._cell_codes(w, None, crossed, w_low, w_high)


def _solids():
    a = box((1.0, 0.6, 0.5))
    b = box((0.4, 1.3, 0.45), center=(0.2, 0.1, 0.05))
    s = uv_sphere(0.35, center=(-0.3, 0.0, 0.1), segments=16, rings=8)
    crossing = (np.vstack([a[0], b[0], s[0]]),
                np.vstack([a[1], b[1] + len(a[0]), s[1] + len(a[0]) + len(b[0])]))
    inside_out = (crossing[0], crossing[1][:, ::-1].copy())
    inner = box((0.3, 0.3, 0.3))
    nested = (np.vstack([a[0], inner[0]]), np.vstack([a[1], inner[1] + len(a[0])]))   # w = 2 inside the inner box
    return {"crossing": crossing, "inside_out": inside_out, "nested": nested}


@pytest.mark.parametrize("name", ["crossing", "inside_out", "nested"])
def test_codes_from_regions_equal_the_codes_from_every_cell(name, monkeypatch):
    from inertia_tool.mesh.winding import fast_available
    if not fast_available():
        pytest.skip("the regions' shortcut needs libigl")
    v, f = _solids()[name]
    used = []
    real = est._region_codes

    def spy(regions, w_low, w_high):
        used.append(True)
        return real(regions, w_low, w_high)
    monkeypatch.setattr(est, "_region_codes", spy)
    fast = est.winding_estimate(v, f, resolution=40)
    assert used, "the grid did not take its codes from the regions"
    monkeypatch.setattr(est, "_region_codes", _per_cell_codes)
    slow = est.winding_estimate(v, f, resolution=40)
    assert fast.volume == slow.volume and fast.detail == slow.detail
    assert np.array_equal(fast.centroid, slow.centroid)
    assert np.array_equal(fast.second_moment, slow.second_moment)
    assert fast.uncertainty == slow.uncertainty and fast.far == slow.far
    assert fast.volume > 0
    if name == "nested":                    # the inner box counts once: {w > 1/2} is the outer box
        assert fast.volume == pytest.approx(0.3, rel=0.2)


# -- a refusal the first grid already proves (issue 23: ALOHA's gripper_prop refined for 10 s, then refused) ----

def _open_crossing(seed):
    """Two crossing spheres, one with a band of faces missing (open and self-crossing: the open estimate)."""
    rng = np.random.default_rng(seed)
    a = uv_sphere(0.5, segments=12, rings=6)
    b = uv_sphere(0.35, center=tuple(rng.uniform(-0.3, 0.3, 3)), segments=10, rings=5)
    fa = a[1][rng.random(len(a[1])) > 0.08]                   # scattered holes
    return np.vstack([a[0], b[0]]), np.vstack([fa, b[1] + len(a[0])])


@pytest.mark.parametrize("kind, seed", [("closed", 0), ("closed", 1), ("closed", 2), ("open", 0), ("open", 3)])
def test_a_finer_grid_never_escapes_a_refusal_the_coarse_grid_proves(kind, seed):
    """``refusal_proven``'s claim: once the added doubt exceeds half the coarse grid's ``V + δ`` (its cap on the
    solid), every finer grid's bound with that doubt is past ±50 %: ``V' − δ' ≤ |S| ≤ V + δ`` (closed surfaces
    without assumption, open ones under the grid's own)."""
    from inertia_tool.mesh.winding import fast_available
    if not fast_available():
        pytest.skip("libigl grids")
    rng = np.random.default_rng(seed)
    if kind == "closed":
        a = box((1.0, 0.6, 0.5))
        b = box(tuple(rng.uniform(0.3, 1.2, 3)), center=tuple(rng.uniform(-0.3, 0.3, 3)))
        v, f = np.vstack([a[0], b[0]]), np.vstack([a[1], b[1] + len(a[0])])
    else:
        v, f = _open_crossing(seed)
    coarse = est.winding_estimate(v, f, resolution=12)
    cap = coarse.volume + coarse.uncertainty.volume_in_doubt
    added = 0.5 * cap * (1 + 1e-9)
    assert est.refusal_proven(coarse, added) == (coarse.uncertainty.mass <= 0.5)
    assert not est.refusal_proven(coarse, 0.5 * cap * (1 - 1e-9))
    for n in (16, 28):
        fine = est.winding_estimate(v, f, resolution=n)
        assert (added + fine.uncertainty.volume_in_doubt) / fine.volume > 0.5, n


def test_the_open_estimate_is_not_refined_when_the_added_doubt_refuses_it(monkeypatch):
    from inertia_tool.mesh.winding import fast_available
    if not fast_available():
        pytest.skip("libigl grids")
    v, f = _open_crossing(4)
    built = []
    real = est._winding_grid

    def count(*args, **kwargs):
        built.append(kwargs["resolution"])
        return real(*args, **kwargs)
    monkeypatch.setattr(est, "_winding_grid", count)
    plain = est.open_surface_estimate(v, f, resolution=32, target=1e-3, max_resolution=40)
    assert built == [32, 40]                            # refined: the bound misses a target this small
    coarse = est.winding_estimate(v, f, resolution=32)
    assert coarse.uncertainty.mass <= 0.5
    added = 0.5 * (coarse.volume + coarse.uncertainty.volume_in_doubt) * (1 + 1e-9)
    built.clear()
    first = est.open_surface_estimate(v, f, resolution=32, target=1e-3, max_resolution=40, added_doubt=added)
    assert built == [32]
    assert first.volume == coarse.volume
    assert (added + first.uncertainty.volume_in_doubt) / first.volume > 0.5
    assert (added + plain.uncertainty.volume_in_doubt) / plain.volume > 0.5     # the refined one refused as well
    built.clear()
    est.open_surface_estimate(v, f, resolution=32, target=1e-3, max_resolution=40, added_doubt=0.999 * added)
    assert built == [32, 40]                            # not proven: refined as before


def test_summed_winding_numbers_are_within_their_round_off_of_the_exact_integers_and_the_treecode():
    """The regions' one point each takes the exact sum over every face when that is cheap; on a closed sphere far
    from the origin its value is the integer within its stated round-off bound, and within the treecode's bound
    of the treecode's value."""
    from inertia_tool.mesh.winding import winding_numbers_bounded, winding_numbers_summed
    v, f = uv_sphere(0.5, center=(300.0, -20.0, 7.0), segments=24, rings=12)
    points = np.array([[300.0, -20.0, 7.0], [300.2, -20.1, 7.1], [301.0, -20.0, 7.0], [299.4, -20.0, 7.0]])
    w, err = winding_numbers_summed(points, v, f)
    assert np.all(err > 0) and np.all(err < 1e-9)
    assert np.all(np.abs(w - [1, 1, 0, 0]) <= err)
    tree, tree_err = winding_numbers_bounded(points, v, f)
    assert np.all(np.abs(w - tree) <= tree_err + err)
