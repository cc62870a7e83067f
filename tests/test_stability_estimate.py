"""The spin-stability section of an estimated part (review19): each principal moment's bound (Weyl's inequality on
the repaired part's inertia bound), checked against the closed part, and the classes said to be uncertain where
two moments lie within twice it.  Before review19 a box 100 × 104 × 60 mm with a hole across an edge (inertia
±38.8 %, minor and intermediate moments 6 % apart) was classified "I1 stable, I2 UNSTABLE" with no caveat."""

import warnings

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from inertia_tool import mass_properties, stability  # noqa: E402
from inertia_tool.reports.stability import format_stability, principal_moment_bound  # noqa: E402


def _box_with_hole(extents, hole: str, subdivisions: int = 2):
    """A subdivided box, closed and with ``hole``: ``"corner"`` a patch across the edge x = +, z = +; ``"pair"``
    the two triangles nearest the middle of that edge; ``"one"`` one triangle of the +x face."""
    box = trimesh.creation.box(extents)
    for _ in range(subdivisions):
        box = box.subdivide()
    c = box.triangles_center
    half = np.asarray(extents) / 2
    if hole == "corner":
        lost = (c[:, 0] > 0.7 * half[0]) & (c[:, 2] > 0.6 * half[2]) & (np.abs(c[:, 1]) < 0.4 * half[1])
    elif hole == "pair":
        d = (c[:, 0] - half[0]) ** 2 + (c[:, 2] - half[2]) ** 2 + c[:, 1] ** 2
        lost = np.isin(np.arange(len(c)), np.argsort(d)[:2])
    else:
        lost = np.arange(len(c)) == int(np.argmax(c[:, 0] + 1e-3 * c[:, 1] + 1e-6 * c[:, 2]))
    closed = (np.asarray(box.vertices), np.asarray(box.faces))
    return closed, (closed[0], closed[1][~lost])


@pytest.mark.parametrize("extents, hole, subdivisions, uncertain",
                         [((0.1, 0.104, 0.06), "corner", 2, "I1 and I2, I2 and I3"),     # ±38.8 %: all in doubt
                          ((0.1, 0.2, 0.4), "corner", 2, "I1 and I2, I2 and I3"),
                          ((0.1, 0.3, 0.9), "pair", 3, None),                             # ±0.09 %: classes hold
                          ((0.1, 0.2, 0.4), "one", 2, None)])                             # a flat hole: ~1e-14
def test_estimated_moments_bound_holds_and_the_caveat_names_the_close_pair(extents, hole, subdivisions, uncertain):
    closed, damaged = _box_with_hole(extents, hole, subdivisions)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties(damaged, density=1000.0, repair=True)
        truth = mass_properties(closed, density=1000.0)
    bound = principal_moment_bound(props)
    assert bound is not None and bound > 0
    reported = np.linalg.eigvalsh(props.inertia)
    true = np.linalg.eigvalsh(truth.inertia)
    assert np.all(np.abs(reported - true) <= bound)
    line = format_stability(stability(props), moment_bound=bound)[-1]
    assert "the part is an estimate" in line
    if uncertain:
        assert f"{uncertain} lie within twice that" in line
    else:
        assert "their order and the classes hold" in line


def test_exact_part_has_no_caveat():
    closed, _ = _box_with_hole((0.1, 0.2, 0.4), "one")
    props = mass_properties(closed, density=1000.0)
    assert principal_moment_bound(props) is None
    assert "estimate" not in "\n".join(format_stability(stability(props), moment_bound=None))
