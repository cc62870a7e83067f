"""Same answers from two builds of the face-pair check: every field of ``surface_contacts`` on generated cases.

Draws ``--cases`` meshes (the adversarial compositions of ``tests/adversary_solids.py``: disjoint, touching,
overlapping, nested, walls, slivers, self-crossing tubes, duplicated and inside-out shells; the ``small``
catalogue of ``bench_batch.py``: boxes, icospheres, fan-capped cylinders, tori; random triangle soups; pinched
and folded strips; a jittered sphere), then runs ``surface_contacts`` on each in a child process per tree —
this checkout and ``--baseline DIR`` (e.g. a ``git worktree`` of main, its C extension built) — in several
modes (default; int64 faces; ``_patches=False``; ``_star_faces=0``; a work bound ``max_pairs``; with
``INERTIA_TOOL_CT_POISON=1``, which fills every block the C scan takes with 0xA5 bytes, so that a read before a
write changes the answer; poisoned with the faces across each edge built in three rounds,
``INERTIA_TOOL_CT_TWIN_ROUNDS=3``, which a build without rounds ignores) and compares all fields (the three
pair lists, ``complete``, the counts).  Prints the number of cases and modes compared and every difference;
exit status 1 on any.

    python benchmarks/bench_intersect_agree.py --baseline /path/to/main [--cases 1000] [--big 1e6] [--ignore FIELD]
"""

from __future__ import annotations

import argparse
import os
import pickle
import sys
import tempfile

import numpy as np

from _checkouts import in_turn, run_script

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
FIELDS = ("crossing", "coplanar_opposite", "contact", "complete", "candidate_pairs", "tested_pairs",
          "exact_evaluations", "degenerate_faces")
MODES = ("default", "int64", "unpatched", "unpruned", "bounded", "poison", "rounds")


def _soup(rng, m):
    """m random triangles in a unit cube, some corners shared (random crossings, touches, coplanar pairs)."""
    v = rng.random((m + 3, 3))
    v[rng.random(len(v)) < 0.2, 2] = 0.5                       # a plane many corners lie on exactly
    f = rng.integers(0, len(v), (m, 3))
    return v, f


def _strip(rng, n):
    """A folded or pinched strip of quads (two triangles each) along a random polyline in a plane."""
    t = np.cumsum(rng.normal(size=n + 1))
    x = np.stack([t, np.cumsum(rng.normal(size=n + 1)), np.zeros(n + 1)], 1)
    v = np.concatenate([x, x + [0, 0, 1.0]])
    i = np.arange(n)
    f = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    return v, f


def cases(count: int, seed: int = 7, big: float = 0) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``count`` named meshes (vertices float64, faces int32), reproducible from ``seed``."""
    sys.path.insert(0, os.path.join(ROOT, "tests"))
    import adversary_solids as S
    import trimesh

    out = []
    n_adv = count * 6 // 10
    for i in range(n_adv):
        kind = S.KINDS[i % len(S.KINDS)]
        c = S.make_case(kind, np.random.default_rng([seed, i]))
        out.append((f"adversarial {i} {kind}", np.asarray(c.vertices, float), np.asarray(c.faces)))
    rng = np.random.default_rng(seed)
    i = 0
    while len(out) < count:
        k = i % 7
        if k == 0:
            m = trimesh.creation.box(rng.uniform(5, 80, 3))
        elif k == 1:
            m = trimesh.creation.icosphere(subdivisions=int(rng.integers(1, 4)), radius=float(rng.uniform(5, 50)))
        elif k == 2:
            m = trimesh.creation.cylinder(radius=float(rng.uniform(3, 30)), height=float(rng.uniform(5, 90)),
                                          sections=int(rng.integers(3, 400)))
        elif k == 3:
            m = trimesh.creation.torus(float(rng.uniform(20, 40)), float(rng.uniform(3, 10)),
                                       major_sections=int(rng.integers(3, 65)), minor_sections=int(rng.integers(3, 25)))
        if k < 4:
            m.apply_translation(rng.uniform(-100, 100, 3))
            v, f = np.asarray(m.vertices, float), np.asarray(m.faces)
        elif k == 4:
            v, f = _soup(rng, int(rng.integers(2, 400)))
        elif k == 5:
            v, f = _strip(rng, int(rng.integers(2, 200)))
        else:
            s = trimesh.creation.icosphere(subdivisions=int(rng.integers(1, 4)))
            v = np.asarray(s.vertices, float) * (1 + 1e-3 * rng.normal(size=(len(s.vertices), 1)))
            f = np.asarray(s.faces)
        out.append((f"generated {i} kind {k}", v, f))
        i += 1
    if big:
        import bench_stages
        import trimesh as tm

        m = tm.load(bench_stages.torus(int(np.sqrt(big)), int(np.sqrt(big)) // 2), process=True)
        out.append((f"torus {len(m.faces)}", np.asarray(m.vertices, float), np.asarray(m.faces)))
    return [(name, v, np.ascontiguousarray(f, dtype=np.int32)) for name, v, f in out]


def run_child(path: str, out: str) -> None:
    """Child: every case in every mode (the package the interpreter finds), results pickled to ``out``."""
    from inertia_tool._native import accel
    from inertia_tool.mesh.intersect import surface_contacts

    import inertia_tool

    if accel() is None:
        sys.exit("the C extension did not load in the child")
    print(f"child: inertia_tool from {os.path.dirname(os.path.dirname(inertia_tool.__file__))}", file=sys.stderr)
    with open(path, "rb") as fh:
        todo = pickle.load(fh)
    res = []
    for name, v, f in todo:
        row = {}
        for mode in MODES:
            if mode in ("poison", "rounds"):
                os.environ["INERTIA_TOOL_CT_POISON"] = "1"
            if mode == "rounds":                # a build without rounds ignores it: its default answer
                os.environ["INERTIA_TOOL_CT_TWIN_ROUNDS"] = "3"
            kw = {"unpatched": {"_patches": False}, "unpruned": {"_star_faces": 0},
                  "bounded": {"max_pairs": max(1, len(f) // 3)}}.get(mode, {})
            faces = f.astype(np.int64) if mode == "int64" else f
            try:
                r = surface_contacts(v, faces, **kw)
                row[mode] = tuple(np.asarray(getattr(r, k)).tolist() for k in FIELDS)
            except Exception as exc:          # an error is an answer too: it must be the same one
                row[mode] = (type(exc).__name__, str(exc))
            os.environ.pop("INERTIA_TOOL_CT_POISON", None)
            os.environ.pop("INERTIA_TOOL_CT_TWIN_ROUNDS", None)
        res.append((name, row))
    with open(out, "wb") as fh:
        pickle.dump(res, fh)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=False, help="another checkout (its C extension built)")
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--big", type=float, default=0, help="also a torus of about this many faces")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--ignore", action="append", default=[], choices=FIELDS, metavar="FIELD",
                    help="a field left out of the comparison (repeatable), e.g. exact_evaluations, a count of work "
                         "that a change deciding pairs without the exact stage lowers by design")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        run_child(*args.child)
        return 0
    if not args.baseline:
        ap.error("--baseline DIR is required")
    sys.path.insert(0, HERE)
    todo = cases(args.cases, args.seed, args.big)
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cases.pkl")
        with open(path, "wb") as fh:
            pickle.dump(todo, fh)
        for tree in in_turn((ROOT, os.path.abspath(args.baseline)), 0):
            out = os.path.join(tmp, f"out{len(results)}.pkl")
            run_script(__file__, ["--child", path, out], tree=tree)
            with open(out, "rb") as fh:
                results[tree] = pickle.load(fh)
    mine, base = results[ROOT], results[os.path.abspath(args.baseline)]
    kept = [k for k, field in enumerate(FIELDS) if field not in args.ignore]
    differ = 0
    ignored: dict[str, int] = {field: 0 for field in args.ignore}

    def fields(answer, keep):
        """The answer's fields at the positions keep (an answer of another length, e.g. an error, whole)."""
        return tuple(answer[k] for k in keep) if len(answer) == len(FIELDS) else answer

    for (name, a), (_, b) in zip(mine, base):
        for mode in MODES:
            for field in args.ignore:
                k = FIELDS.index(field)
                ignored[field] += fields(a[mode], [k]) != fields(b[mode], [k])
            if fields(a[mode], kept) != fields(b[mode], kept):
                differ += 1
                print(f"DIFFER {name} mode {mode}: {str(a[mode])[:200]} vs {str(b[mode])[:200]}")
    found = sum(1 for _, a in mine if len(a["default"]) == len(FIELDS) and any(a["default"][:3]))
    print(f"{len(mine)} cases x {len(MODES)} modes ({', '.join(MODES)}) compared, {len(kept)} of {len(FIELDS)} "
          f"fields: {differ} differences; {found} cases with pairs found")
    for field, count in ignored.items():
        print(f"(left out: {field}, which differs in {count} case-modes)")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
