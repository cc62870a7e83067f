"""The deterministic work budget of the winding-number estimate (issue 23 item 3: ALOHA's
``vx300s_7_gripper_prop.stl`` took 49 s of CPU under ``--repair``, 1.18M libigl evaluations, and was then refused).

The work is the number of grid cells whose winding number is evaluated one by one; it is counted before any is
evaluated and refused past :data:`~inertia_tool.mesh.grid_estimate.WINDING_EVALUATION_BUDGET` with a one-line
:class:`~inertia_tool.errors.WorkBudgetError` (never a clock: the same answer on every machine), and the
refinements choose their grid within it.  Checked on generated open spheres (a cap cut off: cells near the hole
are evaluated) against the count the estimate reports, with libigl's evaluations intercepted.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("igl")

import inertia_tool.mesh.grid_estimate as grid_estimate  # noqa: E402
import inertia_tool.mesh.winding as winding  # noqa: E402
from inertia_tool.errors import InvalidMeshError, WorkBudgetError  # noqa: E402
from inertia_tool.mesh.grid_estimate import (WINDING_EVALUATION_BUDGET, _grid_shape, _winding_grid,  # noqa: E402
                                             affordable_resolution, open_surface_estimate, winding_estimate)


def _open_sphere(rings: int = 24, sectors: int = 48, cut: float = 0.55, radius: float = 0.02):
    """A UV sphere (outward) without the cap above ``z = cut · radius``: an open surface with one large hole."""
    theta = np.linspace(0, np.pi, rings + 1)
    phi = np.linspace(0, 2 * np.pi, sectors, endpoint=False)
    pts = [np.array([0.0, 0.0, radius])]
    for t in theta[1:-1]:
        for p in phi:
            pts.append(radius * np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)]))
    pts.append(np.array([0.0, 0.0, -radius]))
    v = np.array(pts)
    faces = []

    def ring(i: int, j: int) -> int:
        return 1 + (i - 1) * sectors + j % sectors
    for j in range(sectors):
        faces.append((0, ring(1, j), ring(1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(sectors):
            a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
            faces += [(a, b, c), (a, c, d)]
    last = len(v) - 1
    for j in range(sectors):
        faces.append((ring(rings - 1, j), last, ring(rings - 1, j + 1)))
    f = np.array(faces, dtype=np.int64)
    keep = v[f].mean(axis=1)[:, 2] < cut * radius
    return v, f[keep]


@pytest.fixture
def evaluations(monkeypatch):
    """Every call of libigl's evaluation (through :func:`~inertia_tool.mesh.winding.winding_numbers`): its
    number of points."""
    calls: list[int] = []
    real = winding.winding_numbers

    def counted(points, vertices, faces, *, fast=None):
        if fast is not False:
            calls.append(len(points))
        return real(points, vertices, faces, fast=fast)
    monkeypatch.setattr(winding, "winding_numbers", counted)
    return calls


def test_the_count_is_exact_and_refused_before_any_cell_is_evaluated(evaluations):
    v, f = _open_sphere()
    done = _winding_grid(v, f, resolution=48)
    n = done.evaluated
    assert n > 1000 and max(evaluations) == n            # the cells of the grid, evaluated in one call
    evaluations.clear()
    with pytest.raises(WorkBudgetError) as refused:
        winding_estimate(v, f, resolution=48, max_evaluations=n - 1)
    assert refused.value.details["evaluations"] == n and refused.value.details["budget"] == n - 1
    assert all(k < n for k in evaluations)                # no grid evaluation was started
    message = str(refused.value)
    assert "\n" not in message and f"{n:,} grid cells" in message and f"{n - 1:,} evaluations" in message
    assert isinstance(refused.value, InvalidMeshError) and isinstance(refused.value, ValueError)
    again = winding_estimate(v, f, resolution=48, max_evaluations=n)     # exactly at the budget: done, the same
    assert again.volume == done.estimate.volume and again.uncertainty == done.estimate.uncertainty


def test_a_64_cell_grid_never_reaches_the_default_budget():
    """The padded grid of 64 cells along the longest side has at most 66³ cells, below the budget, so the
    default estimate of a soup (resolution 64) is never refused by it."""
    assert 66 ** 3 < WINDING_EVALUATION_BUDGET
    for extent in ([1, 1, 1], [1, 0.999, 0.998], [1, 1e-3, 1e-3]):
        v = np.array([[0, 0, 0], extent], dtype=float)
        assert np.prod(_grid_shape(v, 64)[2]) <= 66 ** 3


def test_the_refinement_of_an_open_surface_stays_within_the_budget(evaluations):
    """The first grid's bound misses a tight target, so the rule asks for the finest grid: with a budget, the
    second grid is the one :func:`affordable_resolution` expects to fit, and no evaluation exceeds the budget."""
    v, f = _open_sphere()
    first = _winding_grid(v, f, resolution=32)
    budget = 4 * first.evaluated
    evaluations.clear()
    got = open_surface_estimate(v, f, resolution=32, target=1e-4, max_resolution=400, max_evaluations=budget)
    assert evaluations and max(evaluations) <= budget
    n = affordable_resolution(v, 32, first.evaluated, first.crossed, budget)
    assert 32 < n < 400
    assert got.detail == winding_estimate(v, f, resolution=n, max_evaluations=budget).detail
    # without the budget, the rule would have built the finest grid, several times the work
    dims = _grid_shape(v, 400)[2]
    assert float(np.prod(dims)) > 10 * budget


def test_a_refinement_that_would_still_exceed_its_budget_leaves_the_first_grid(evaluations, monkeypatch):
    """When the grid chosen by the expectation still counts more cells than the budget, the first grid is the
    answer (decided by the count): forced here by an expectation that promises too much."""
    v, f = _open_sphere()
    first = _winding_grid(v, f, resolution=32)
    budget = 2 * first.evaluated
    monkeypatch.setattr(grid_estimate, "affordable_resolution", lambda *a, **k: 96)
    evaluations.clear()
    got = open_surface_estimate(v, f, resolution=32, target=1e-4, max_resolution=96, max_evaluations=budget)
    assert got.detail == first.estimate.detail and got.volume == first.estimate.volume
    assert max(evaluations) <= budget


def test_the_first_grid_over_the_budget_is_refused():
    v, f = _open_sphere()
    first = _winding_grid(v, f, resolution=32)
    with pytest.raises(WorkBudgetError, match="more than its budget"):
        open_surface_estimate(v, f, resolution=32, max_evaluations=first.evaluated - 1)


def test_the_expectation_over_estimates_on_generated_open_spheres():
    """The stated expectation (evaluated + crossed cells, scaled by the cell count) is at least the cells a
    finer grid evaluates, on open spheres with caps of several sizes (not the case it was written for)."""
    for cut in (-0.6, 0.3, 0.8):
        v, f = _open_sphere(cut=cut)
        coarse = _winding_grid(v, f, resolution=24)
        for fine in (36, 52):
            expected = (coarse.evaluated + coarse.crossed) * np.prod(_grid_shape(v, fine)[2]) / np.prod(
                _grid_shape(v, 24)[2])
            assert _winding_grid(v, f, resolution=fine).evaluated <= expected


def test_the_forced_estimate_of_the_repair_names_the_file(monkeypatch):
    """Under ``repair`` a surface that passes through itself goes to :func:`~inertia_tool.mesh.resolve.
    resolve_surface` with ``force_estimate``; an open one to :func:`open_surface_estimate`.  Over the budget (read
    at the call, so a test can lower it) it is refused with one line naming the source."""
    from inertia_tool.integrals import volume_moments
    from inertia_tool.mesh.resolve import resolve_surface
    v, f = _open_sphere()
    monkeypatch.setattr(grid_estimate, "WINDING_EVALUATION_BUDGET", 50)
    with pytest.raises(WorkBudgetError) as refused:
        resolve_surface(v, f, diag=0.07, source="part.stl", repair=True, merge_tolerance=0.0,
                        moments=volume_moments, force_estimate=True, reason="the surface passes through itself")
    message = str(refused.value)
    assert "\n" not in message and message.startswith("part.stl: the winding-number estimate would evaluate ")
    assert message.endswith("more than its budget of 50 evaluations; close the holes or the crossings in a mesh "
                            "editor")
    assert refused.value.details["budget"] == 50 and refused.value.details["evaluations"] > 50
