"""The count of session 15 (issue 21; ``docs/adversarial.md``, "Session 15"): the cases it flagged that are no
known finding.  Every flagged answer of the count on ``3062e66`` was a known open finding (N5, N6: their strict
xfails are in ``tests/test_review14_findings.py``) or an honest label; this file holds the one case where the
judge, not the tool, is wrong, shown by independent code.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
import bench_near_copies  # noqa: E402
from adversary_solids import certificate_label, float_moments, truth_from_manifold  # noqa: E402
from inertia_tool import mass_properties  # noqa: E402


def _near_copies_case(seed: int, index: int):
    """Case ``index`` of ``bench_near_copies.py seed N`` (its cases are drawn in turn from one generator)."""
    rng = np.random.default_rng(seed)
    for _ in range(index):
        bench_near_copies.case(rng)
    return bench_near_copies.case(rng)


def test_near_copies_far_out_manifold_union_is_the_judges_limit():
    """``bench_near_copies.py 1605 1500`` case 1371: a torus 3.3 mm across, 5,473 m from the origin, and its copy
    scaled by 1 + 120 ulp and turned by < 1e-8 rad about its centre.  The judge's truth (manifold3d's union formed
    there, ``adversary_solids.truth_from_manifold``) is 3.60239e-9 m³, 7.3e-4 above the larger piece; the union of
    two pieces whose corresponding corners lie within ``d`` of each other exceeds the larger by at most the
    ``d``-neighbourhood of the surface (Steiner: about ``2 d · area``), 1.7e-8 of it here.  The tool answers
    ``unverified`` 3.5997690322e-9 m³ (an honest label, so no silent wrong either way): inside that bound, and
    equal to 1e-9 to manifold3d's union of the same two pieces moved near the origin by an exact subtraction
    (3.599769032197e-9 m³: the judge's error came from forming the union 1.7e6 sizes out; its truth is now formed
    near the origin, ``bench_near_copies.truth``)."""
    kind, mode, k, v, w, f = _near_copies_case(1605, 1371)
    assert (kind, mode, k) == (3, 2, 120)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((np.vstack([v, w]), np.vstack([f, f + len(v)])), density=1.0)
    assert certificate_label(props.mesh) in ("exact", "united", "unverified")
    larger = max(float_moments(v, f)[0], float_moments(w, f)[0])
    d = float(np.max(np.linalg.norm(v - w, axis=1)))
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())
    steiner = 2 * d * area + 4.2 * d ** 2 * np.sqrt(area) + 4.2 * d ** 3      # generous: every term of the tube
    assert steiner < 1e-5 * larger
    assert larger * (1 - 1e-9) <= props.mass <= (larger + steiner) * (1 + 1e-9)
    # the same union formed near the origin: the pieces moved by one of their corners, exactly (checked)
    origin = v[0].copy()
    vo, wo = v - origin, w - origin
    assert np.array_equal(vo + origin, v) and np.array_equal(wo + origin, w)
    near = truth_from_manifold([(vo, f), (wo, f)]).volume
    assert abs(props.mass - near) <= 1e-9 * near
    # the benchmark's judge now forms its union there too (before: 7.3e-4 off, the case flagged)
    assert abs(props.mass - bench_near_copies.truth(v, w, f)) <= 1e-6 * near
