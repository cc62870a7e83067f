"""Real files with random damage that keeps the solid, checked against the undamaged file's exact values.

Sources: every STL / OBJ / PLY / OFF file under the folders given (``--roots``; e.g. trimesh's test models, the
Gazebo model library, MuJoCo Menagerie) that inertia_tool reads as one clean closed surface, certified ``exact``
(``coverage.truth_of``, cross-checked against trimesh), of at most ``--max-faces`` faces.  A seeded sample of
``--files`` of them is drawn, and each gets every damage kind once:

- the kinds of ``coverage.py`` (holes, scattered holes, T-junctions, cracks, slivers, an internal wall, a touching
  mirror copy; a third of the cases quantised first), answered with ``repair=True``;
- ``duplicate``: the whole surface listed twice, the copy's faces shuffled and, half the time, its coordinates
  rounded apart ((v + c) − c); truth: the clean file;
- ``flipped``: every face reversed (the shell inside out); truth: the clean file;
- ``flip_patch``: a connected patch of 2–30 % of the faces reversed; truth: the clean file;
- ``touching_translate``: a copy moved by the bounding box's extent along a random axis (interiors disjoint,
  touching where the part has a flat face on that side), vertices welded bit-exactly; truth: both bodies.

A hole that takes a whole shell of a file with several (a small part, a cavity) does not keep the solid: such a
case is counted as skipped.

The closed kinds (T-junctions, slivers, walls, touching copies, duplicates, flips) are also answered without
repair.  The rule is that of ``coverage.py``: an answer certified ``exact``/``united``/``summed`` within 1e-9 of the
truth, an estimate within its bounds (``holds``), ``unverified`` claims nothing, a refusal is allowed; any
other exception is an error.  Prints the count per kind, every failure, and writes JSON.

Run: ``python benchmarks/damage/real_files.py --roots /path/to/models /path/to/gazebo --files 60 --seed 7``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def _coverage_module():
    """``coverage.py`` beside this file, loaded under its own name (a ``coverage`` package may be imported)."""
    import importlib.util

    if "damage_coverage" in sys.modules:
        return sys.modules["damage_coverage"]
    spec = importlib.util.spec_from_file_location("damage_coverage", HERE / "coverage.py")
    if spec is None or spec.loader is None:
        raise ImportError(f"expected {HERE / 'coverage.py'}, found nothing loadable")
    module = importlib.util.module_from_spec(spec)
    sys.modules["damage_coverage"] = module
    spec.loader.exec_module(module)
    return module


cov = _coverage_module()

EXTRA_KINDS = ("duplicate", "flipped", "flip_patch", "touching_translate")
CLOSED_KINDS = ("t_junction", "sliver", "internal_wall", "touching_copy") + EXTRA_KINDS
SUFFIXES = (".stl", ".obj", ".ply", ".off")


def find_sources(roots, max_faces, rng, limit):
    """(name, vertices, faces, truth) of up to ``limit`` clean closed files drawn at random from ``roots``."""
    import trimesh

    paths = sorted(p for root in roots for p in Path(root).rglob("*") if p.suffix.lower() in SUFFIXES)
    rng.shuffle(paths)
    out = []
    for path in paths:                                # bounded by the files found
        if len(out) >= limit:
            break
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mesh = trimesh.load(str(path), process=False, force="mesh")
        except Exception:                             # unreadable by trimesh: not a source
            continue
        if not hasattr(mesh, "faces") or not 8 <= len(mesh.faces) <= max_faces:
            continue
        v, f = cov._weld(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64))
        try:
            truth = cov.truth_of(v, f)
        except ValueError:
            continue
        if truth is None:
            continue
        out.append((str(path), v, f, truth))
    return out


def _evaluate_plain(v, f, truth):
    """:func:`coverage.evaluate` without repair."""
    import inertia_tool as it

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = it.mass_properties((v, f), density=1.0)
    except it.errors.InvalidMeshError as exc:
        return {"status": "refused", "reason": str(exc)[:300]}
    except Exception as exc:                          # a bug: reported, never hidden
        return {"status": "error", "reason": f"{type(exc).__name__}: {exc}"[:300]}
    return _judged(p, truth)


def _judged(p, truth):
    diag = truth["diagonal"]
    err_mass = abs(p.volume - truth["volume"])
    err_com = float(np.linalg.norm(p.center_of_mass - np.asarray(truth["center_of_mass"])))
    inertia = np.asarray(p.inertia)
    err_inertia = float(np.linalg.norm(inertia - np.asarray(truth["inertia"])))
    norm = float(np.linalg.norm(inertia))
    u = p.mesh.uncertainty
    r = cov.ROUND_OFF
    bounds = (r, r * diag, r) if u is None else (u.mass, u.center_of_mass, u.inertia)
    holds = (err_mass <= bounds[0] * p.volume * (1 + r) + r * truth["volume"]
             and err_com <= bounds[1] * (1 + r) + r * diag and err_inertia <= bounds[2] * norm * (1 + r) + r * norm)
    kind = p.mesh.certificate.kind
    return {"status": "answer", "certificate": kind, "holds": None if kind == "unverified" else bool(holds),
            "mass_error": err_mass / truth["volume"], "mass_bound": float(bounds[0]),
            "com_error_of_diag": err_com / diag, "inertia_error": err_inertia / norm}


def damage_extra(kind, v, f, rng, truth):
    """The extra kinds: (vertices, faces, truth, meta)."""
    if kind == "duplicate":
        copy = v
        rounded = bool(rng.random() < 0.5)
        if rounded:
            c = rng.normal(size=3) * float(np.abs(v).max()) * 0.37
            copy = (v + c) - c
        g = (f + len(v))[rng.permutation(len(f))]
        return np.vstack([v, copy]), np.vstack([f, g]), truth, {"rounded_apart": rounded}
    if kind == "flipped":
        return v, f[:, ::-1].copy(), truth, {}
    if kind == "flip_patch":
        n = max(1, int(rng.uniform(0.02, 0.3) * len(f)))
        patch = cov._patch(f, int(rng.integers(len(f))), lambda count, last: count < n)
        g = f.copy()
        g[patch] = g[patch][:, ::-1]
        return v, g, truth, {"faces_flipped": int(len(patch))}
    axis = int(rng.integers(3))
    shift = np.zeros(3)
    shift[axis] = float(v[:, axis].max() - v[:, axis].min()) * (1 if rng.random() < 0.5 else -1)
    moved = v + shift
    both_v, both_f = np.vstack([v, moved]), np.vstack([f, f + len(v)])
    wv, wf = cov._weld(both_v, both_f)
    return wv, wf, cov._moments_truth(both_v, both_f), {"axis": "xyz"[axis], "shared": int(len(both_v) - len(wv))}


def _components(f, n):
    """Connected components of the faces (through shared vertices)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = np.asarray(f, dtype=np.int64)
    if not len(f):
        return 0
    rows = np.repeat(np.arange(len(f)), 3)
    graph = coo_matrix((np.ones(3 * len(f), dtype=np.int8), (rows, f.reshape(-1))), shape=(len(f), n))
    used = np.unique(f)
    both = coo_matrix(graph.T @ graph)
    count, labels = connected_components(both, directed=False)
    return len(np.unique(labels[used]))


def run_case(source, kind, entropy):
    name, v, f, clean = source
    rng = np.random.default_rng(entropy)
    truth, quantum = clean, None
    if rng.random() < cov.QUANTISE_SHARE:
        qv, qf, q = cov._quantised(v, f, rng, clean["diagonal"])
        qt = cov.truth_of(qv, qf)
        if qt is not None:
            v, f, truth, quantum = qv, qf, qt, q
    meta: dict = {}
    if kind in EXTRA_KINDS:
        dv, df, truth, meta = damage_extra(kind, v, f, rng, truth)
    elif kind == "touching_copy":
        dv, df, meta, truth = cov.damage_touching_copy(v, f, rng)
    elif kind == "internal_wall":
        dv, df, meta, cut = cov.damage_internal_wall(v, f, rng)
        truth = cut if cut is not None else truth
    else:
        dv, df, meta = cov.make_case(kind, v, f, rng, truth["diagonal"])
    if _components(df, len(dv)) < _components(f, len(v)) and kind not in EXTRA_KINDS + ("touching_copy",):
        # the damage took a whole shell of a multi-shell file (a small part, a cavity): the solid is not kept
        return [{"source": name, "kind": kind, "entropy": list(entropy), "faces": int(len(df)), "quantum": quantum,
                 "repair": True, "status": "skipped", "reason": "the damage removed a whole shell", **meta}]
    rows = []
    cpu = time.process_time()
    rows.append({"repair": True, **cov.evaluate(dv, df, truth)})
    if kind in CLOSED_KINDS:
        rows.append({"repair": False, **_evaluate_plain(dv, df, truth)})
    cpu = time.process_time() - cpu
    return [{"source": name, "kind": kind, "entropy": list(entropy), "faces": int(len(df)), "quantum": quantum,
             "cpu_seconds": cpu, **meta, **r} for r in rows]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--roots", required=True, nargs="+",
                        help="folders searched for mesh files (several, or comma-separated)")
    parser.add_argument("--files", type=int, default=40)
    parser.add_argument("--max-faces", type=int, default=5000)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--kinds", default=",".join(cov.KINDS + EXTRA_KINDS))
    parser.add_argument("--out", type=Path, default=cov.OUT / "real_files.json")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    sources = find_sources([r for root in args.roots for r in root.split(",") if r], args.max_faces, rng, args.files)
    kinds = args.kinds.split(",")
    print(f"{len(sources)} clean sources, {len(kinds)} kinds, seed {args.seed}", flush=True)
    rows, table = [], Counter()
    t0 = time.process_time()
    for s, source in enumerate(sources):
        for k, kind in enumerate(kinds):
            for row in run_case(source, kind, [args.seed, s, k]):
                rows.append(row)
                verdict = row["status"] if row["status"] != "answer" else (
                    row["certificate"] + ("" if row["holds"] in (True, None) else " WRONG"))
                table[(kind, row["repair"], verdict)] += 1
                if row["status"] == "error" or row.get("holds") is False:
                    print("FAIL", json.dumps(row), flush=True)
    print(f"{len(rows)} answers to {len(rows) and len({(r['source'], r['kind']) for r in rows})} cases, "
          f"CPU {time.process_time() - t0:.0f} s")
    for key, count in sorted(table.items(), key=str):
        print(key, count)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rows, indent=1))
    return 1 if any(r["status"] == "error" or r.get("holds") is False for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
