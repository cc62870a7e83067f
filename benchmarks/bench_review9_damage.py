"""Review 9: the damage benchmark's kinds on parts turned at random, moved far from the origin or given in mm.

``damage/coverage.py`` damages parts where they were modelled (near the origin, metres).  Here each generated and
repository source is first turned by a random rotation, scaled by 1e-3 (a part drawn in metres read as if in
mm: the same file, 1,000 times smaller) in a third of the cases, and moved 10³–10⁶ diagonals from the origin in
half of them; its truth is the clean transformed mesh's exact integral (``coverage.truth_of``, cross-checked
against trimesh with ``process=False``).  Then every damage kind of ``coverage.py`` runs on it with
``repair=True`` and the same rule: certified exact/united/summed within 1e-9, an estimate within its bounds.

Run: ``python benchmarks/bench_review9_damage.py --seeds 71,72 [--kinds hole,crack_hole]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "damage"))
sys.path.insert(0, str(HERE.parent / "tests"))
import adversary_solids as S  # noqa: E402
import real_files  # noqa: E402

cov = real_files._coverage_module()


def transformed(name, v, f, rng):
    rot = S.random_rotation(rng)
    diag = float(np.linalg.norm(np.ptp(v, axis=0)))
    scale = 1e-3 if rng.random() < 1 / 3 else 1.0
    v = (v - v.mean(0)) @ rot.T * scale
    shift = np.zeros(3)
    if rng.random() < 0.5:
        shift = np.round(rng.normal(size=3) * 10.0 ** rng.uniform(3, 6) * diag) * scale
    return f"{name} (scale {scale:g}, shift {np.round(shift, 3).tolist()})", v + shift, f


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="71")
    ap.add_argument("--kinds", default=",".join(k for k in cov.KINDS if k not in ("touching_copy",)))
    ap.add_argument("--max-faces", type=int, default=6000)
    args = ap.parse_args(argv)
    kinds = args.kinds.split(",")
    base = [s for s in cov.generated_sources() + cov.repo_sources() if len(s[2]) <= args.max_faces]
    counts: Counter = Counter()
    failures = []
    t0 = time.time()
    for seed in map(int, args.seeds.split(",")):
        for s, (name, v, f) in enumerate(base):
            rng = np.random.default_rng([seed, s])
            tname, tv, tf = transformed(name, v, f, rng)
            truth = cov.truth_of(tv, tf)
            if truth is None:
                counts["source not clean after transform"] += 1
                continue
            for k, kind in enumerate(kinds):
                row = cov.run_case((f"{seed}-{s:02d}-{kind}", 0, kind, [seed, s, k, 9], (tname, tv, tf, truth)))
                key = (kind, row["status"], row.get("certificate"), row.get("holds"))
                counts[key] += 1
                bad = row["status"] == "error" or (row["status"] == "answer" and row.get("holds") is False)
                if bad:
                    failures.append(row)
    print(f"seeds {args.seeds}, {len(base)} sources, {time.time() - t0:.0f} s")
    for key, n in sorted(counts.items(), key=str):
        print(key, n)
    print(f"{len(failures)} failures")
    for row in failures:
        print({k: row.get(k) for k in ("id", "source", "kind", "status", "certificate", "mass_bound", "mass_error",
                                       "com_bound_of_diag", "com_error_of_diag", "inertia_bound", "inertia_error",
                                       "reason")})
    return 0


if __name__ == "__main__":
    sys.exit(main())
