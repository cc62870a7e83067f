"""Why the coverage benchmark's refusals under ``faceted-holes`` are refused: each refused case made again and run
with the two readings of that assumption watched.

For every case a ``coverage.py`` run (``--assume faceted-holes``) refused, the case is made again from its id (the
same random numbers) and ``mass_properties(..., repair=True, assume=("faceted-holes",))`` is run with
:func:`~inertia_tool.mesh.hole_facets.faceted_doubt` and :func:`~inertia_tool.mesh.hole_wraps.wrapped_reading`
recorded (the benchmark's measurement only: the library is not changed).  The cause of a refusal for a too-large
ball is read off the hole with the widest rim ball among those the assumption was tried on:

- ``faceted: read, still too wide`` — the graph reading (``faceted_doubt``) bounded it, and the bound stayed past
  ±50 % (or no narrower than the one it had);
- ``wrapped: read, still too wide`` — likewise for the reading round an edge (``wrapped_reading``);
- ``wrapped: <key>`` — the first check that declined the reading round an edge
  (:data:`~inertia_tool.mesh.hole_wraps.WRAP_DECLINED`: ``open`` where the planes round the rim do not meet
  beyond the cone, ``not convex``, ``planes`` past the limit on curved tessellations, ``file inside``, ...);
- ``not tried`` — no hole was handed to the assumption (across a crease, an island in a flat face, or the
  convex bound taken).

Footprints of features taken whole and winding-number refusals keep the benchmark's cause.

Run: ``python benchmarks/damage/refusal_causes.py benchmarks/out/coverage.json`` (the JSON of a run with
``--assume faceted-holes``; a few minutes of CPU for 150 refusals).
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def _coverage():
    sys.path.insert(0, str(HERE))
    try:
        import coverage
    finally:
        sys.path.remove(str(HERE))
    return coverage


def _rebuild(cov, sources, case_id):
    """The damaged surface and its truth of the case ``case_id`` (``SEED-NN-KIND-R``), drawn as ``run_case`` draws
    it."""
    seed, index, rest = case_id.split("-", 2)
    kind, repeat = rest.rsplit("-", 1)
    name, v, f, truth = sources[int(index)]
    rng = np.random.default_rng([int(seed), int(index), cov.KINDS.index(kind), int(repeat)])
    if rng.random() < cov.QUANTISE_SHARE:
        qv, qf, _ = cov._quantised(v, f, rng, truth["diagonal"])
        qt = cov.truth_of(qv, qf)
        if qt is not None:
            v, f, truth = qv, qf, qt
    dv, df, _ = cov.make_case(kind, v, f, rng, truth["diagonal"])
    return name, dv, df, truth


def watched_run(dv, df, assume):
    """Run ``repair=True`` with ``assume``, recording each hole's readings: (message or None, records)."""
    import inertia_tool as it
    import inertia_tool.mesh.holes as holes
    from inertia_tool.mesh.hole_wraps import WrappedRegion, wrapped_reading

    records = []
    faceted, wrapped = holes.faceted_doubt, holes.wrapped_doubt

    def faceted_watch(v, f, rim_edges, apex, radius, **kw):
        region = faceted(v, f, rim_edges, apex, radius, **kw)
        records.append({"radius": float(radius), "rim": int(len(rim_edges)), "faceted": None if region is None
                        else float(region.doubt)})
        return region

    def wrapped_watch(v, f, rim_edges, radius, **kw):
        reading = wrapped_reading(v, f, rim_edges, radius, **kw)
        records[-1]["wrapped"] = float(reading.doubt) if isinstance(reading, WrappedRegion) else reading
        return reading if isinstance(reading, WrappedRegion) else None

    holes.faceted_doubt, holes.wrapped_doubt = faceted_watch, wrapped_watch
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            it.mass_properties((dv, df), density=1.0, repair=True, assume=tuple(assume))
        message = None
    except it.errors.InvalidMeshError as exc:
        message = str(exc)
    finally:
        holes.faceted_doubt, holes.wrapped_doubt = faceted, wrapped
    return message, records


def cause_of(records):
    """The cause of a ball refusal, read off the widest hole the assumption was tried on."""
    if not records:
        return "not tried"
    widest = max(records, key=lambda r: r["radius"])
    if widest["faceted"] is not None:
        return "faceted: read, still too wide"
    reading = widest.get("wrapped")
    if isinstance(reading, float):
        return "wrapped: read, still too wide"
    return f"wrapped: {reading}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("json", type=Path, help="a coverage.py results file of a run with --assume")
    parser.add_argument("--assume", action="append", default=None, metavar="NAME",
                        help="the assumptions to run with (default: the run's own)")
    parser.add_argument("--out", type=Path, default=None, help="write the rows (JSON) here")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    cov = _coverage()
    data = json.loads(args.json.read_text())
    assume = tuple(args.assume or data.get("assumed") or ())
    rows = cov.assumed_rows(data["rows"])
    refused = [r for r in rows if r["status"] == "refused"]
    groups = sorted({r["source"].split("/")[0] for r in data["rows"]}, key=("generated", "repo", "robots").index)
    sources = cov.load_sources(groups)
    out = []
    for row in refused:
        cause = cov.refusal_cause(row["reason"])
        name, dv, df, _ = _rebuild(cov, sources, row["id"])
        if name != row["source"]:
            raise SystemExit(f"{row['id']}: made {name}, the run had {row['source']} (other sources?)")
        if cause == cov.BALL_CAUSE:
            message, records = watched_run(dv, df, assume)
            if message is None or cov.refusal_cause(message) != cause:
                raise SystemExit(f"{row['id']}: not refused the same way again ({message})")
            cause = "ball, " + cause_of(records)
        out.append({"id": row["id"], "source": row["source"], "kind": row["kind"], "cause": cause})
    counts = collections.Counter((r["cause"], r["source"].split("/")[0]) for r in out)
    causes = sorted({c for c, _ in counts})
    print(f"{len(out)} refusals of {len(rows)} cases ({', '.join(assume) or 'no assumption'})")
    print("| cause | " + " | ".join(groups) + " | all |")
    print("|---|" + "---:|" * (len(groups) + 1))
    for cause in causes:
        per = [counts[(cause, g)] for g in groups]
        print(f"| {cause} | " + " | ".join(map(str, per)) + f" | {sum(per)} |")
    by_source = collections.Counter((r["cause"], r["source"].split("/")[-1]) for r in out)
    print("\nby source (largest first):")
    for (cause, source), n in by_source.most_common():
        print(f"  {n:3d}  {cause}: {source}")
    if args.out:
        args.out.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
