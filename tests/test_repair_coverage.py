"""The fast subset of the repair coverage benchmark (``benchmarks/damage/coverage.py``): randomized holes,
scattered holes, T-junctions, cracks, slivers, internal walls and touching copies on the repository's meshes
and trimesh-generated shapes, some with quantised coordinates.  Every bound ``repair=True`` states must
contain the truth (the clean mesh's exact integral, cross-checked against trimesh); refusals are allowed, other
exceptions are bugs."""

import importlib.util
from pathlib import Path

import numpy as np

from damage_cases import damaged

ROOT = Path(__file__).resolve().parents[1]


def _coverage_module():
    spec = importlib.util.spec_from_file_location("damage_coverage", ROOT / "benchmarks" / "damage" / "coverage.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_repair_bounds_hold_on_the_ci_subset():
    cov = _coverage_module()
    rows = cov.subset(seed=11, limit=30)
    summary = cov.summarise(rows)
    assert summary["cases"] >= 30
    assert summary["errors"] == 0, [r for r in rows if r["status"] == "error"]
    assert summary["answered"] >= 15                # most cases get an answer, not a refusal
    failed = [r for r in rows if r["status"] == "answer" and r["holds"] is False]
    # every answer but an "unverified" one states a bound (exact: round-off), and it holds
    assert summary["bounds_hold"] >= 0.99 * summary["certified"], failed
    assert summary["certified"] >= 15
    # an estimate never claims a bound of 0; only answers labelled exact do
    assert all(r["mass_bound"] > 0 for r in rows if r["status"] == "answer" and r["method"] in ("patched", "winding"))
    # the refusal causes are named (the table of the benchmark groups them)
    assert all(not cov.refusal_cause(r["reason"]).startswith("other") for r in rows if r["status"] == "refused")
    assert {r["kind"] for r in rows} == set(cov.KINDS)
    assert np.isfinite(summary["median_mass_bound"])
    # both readings of the 95 % target are reported, with the refusals' rate and causes (issue 21 item 3)
    assert summary["within_share_of_all"] <= summary["within_share_of_answered"]
    assert sum(summary["refused_by_cause"].values()) == summary["refused"]
    lines = cov.readings(rows).splitlines()
    assert "among all cases" in lines[0] and "among answered cases" in lines[1] and "bounds hold" in lines[2]
    assert f"{summary['within_tolerance']}/{summary['answered']}" in lines[1]


def test_patched_surface_whose_union_is_not_verified_is_not_the_union():
    """Benchmark case 10-04-hole (an annulus with a hole of its own): the patched surface goes through the
    boolean union, which R6 cannot verify.  It was certified "estimate", with the patches' bound, which does not
    cover what the boolean changed (talos arm_1 with an internal wall: 1.59e-6 off with ±1.56e-6 stated); then
    "unverified", the union's number without a bound.  The piece handed to the boolean has non-manifold edges
    (manifold3d assumes manifold input; issue 21 item 3), so that union is no answer: the winding-number estimate,
    whose bound holds."""
    import warnings

    import inertia_tool as it

    cov = _coverage_module()
    sources = cov.load_sources(("generated",))
    case = next(c for c in cov.cases(sources, [10]) if c[0] == "10-04-hole-0")
    cid, s, kind, entropy = case
    name, v, f, truth = sources[s]
    assert name == "generated/annulus"
    dv, df, truth = damaged(cov, kind, v, f, truth, np.random.default_rng(entropy))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = it.mass_properties((dv, df), density=1.0, repair=True)
    assert p.mesh.method == "winding"
    assert p.mesh.certificate.kind == "estimate"
    assert abs(p.volume - truth["volume"]) <= p.mesh.uncertainty.mass * p.volume
