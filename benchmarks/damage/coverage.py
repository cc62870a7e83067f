"""Do repair's bounds hold?  Randomized damaged meshes with known answers, checked against what ``repair=True`` states.

Sources (each a closed, consistently wound mesh whose exact integral is the truth, cross-checked against
trimesh's independent ``mass_properties`` to 1e-9):

- ``repo``: the meshes of the repository's ``meshes/`` folder;
- ``generated``: trimesh's bundled models are not shipped in its wheel, so shapes from ``trimesh.creation``
  (icosphere, capsule, cylinder, cone, annulus, torus, a subdivided box);
- ``robots``: the 25 robot parts of ``make_cases.py`` (example-robot-data 6.0.0, SHA-256 checked) when its
  wheel is in ``benchmarks/out/pkgs`` (``make_cases.py`` downloads it); skipped otherwise.

Damage kinds, each drawn at random from the case's seed:

==================  =========================================================================================
``hole``            a connected patch of faces removed, its area log-uniform from one face to a fifth of the
                    surface
``holes_scattered`` 0.5–5 % of the faces removed one by one
``t_junction``      a connected patch of 2–30 % of the faces split 1→4 at edge midpoints (T-junctions all
                    around its border; the polyhedron is unchanged)
``crack``           a patch of 2–20 % of the faces cut free, its border corners moved by 1e-7…5e-5 of the
                    diagonal (log-uniform)
``t_junction_hole`` ``t_junction`` then ``hole``
``crack_hole``      ``crack`` then ``hole``
``sliver``          a patch of 2–20 % of the faces each split at a point of one edge (a hair from its end to the
                    middle, log-uniform) into a zero-area sliver and two triangles: closed, unchanged solid
``internal_wall``   the part cut in two by a random plane (manifold3d) and joined again with the cut face kept
                    inside, once (a sheet inside the solid) or twice wound both ways (two halves face to face)
``touching_copy``   the mirror image across a bounding-box plane, welded where they meet; truth: both bodies
==================  =========================================================================================

In a third of the cases the clean mesh is first quantised (coordinates rounded to 1e-6…1e-4 of the diagonal;
the truth is then the quantised closed mesh, skipped if rounding broke it).

For each case ``mass_properties((vertices, faces), density=1, repair=True)`` either refuses
(``InvalidMeshError``: counted as refused, never as wrong, with its cause in a second table) or answers.
An answer certified ``unverified`` states no bound and is counted apart (``unverified``).  Any other answer's
bounds *hold* when
``|m − m*| ≤ u_m·m``, ``|c − c*| ≤ u_c`` and ``‖I − I*‖_F ≤ u_I·‖I‖_F`` (an answer without bounds claims to be
exact: round-off of 1e-9 allowed); it is *within tolerance* when the volume is within 1 %, the centre of mass
within 1 % of the diagonal and the inertia within 2 %.  Any other exception is an error (a bug).  A case whose
damage removed every face of one shell of a multi-shell source (``hollow_sphere.stl``'s cavity) does not keep
the solid: it is counted as ``skipped``, apart from the cases (:func:`_shell_removed`).

Seeds 0–2 were used while developing; the report uses other seeds (``--seeds``).

Run: ``python benchmarks/damage/coverage.py --seeds 3,4,5,6,7`` (two worker processes); ``--subset`` is the
fast set of the CI test (``tests/test_repair_coverage.py``).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks" / "out"
KINDS = ("hole", "holes_scattered", "t_junction", "crack", "t_junction_hole", "crack_hole", "sliver", "internal_wall",
         "touching_copy")
VOLUME_RTOL, COM_DTOL, INERTIA_RTOL = 0.01, 0.01, 0.02
ROUND_OFF = 1e-9
MAX_HOLE_SHARE = 0.2          # of the surface area
QUANTISE_SHARE = 1 / 3


# ------------------------------------------------------------------------------------------------ sources

def _weld(v, f):
    unique, inverse = np.unique(np.asarray(v, dtype=np.float64), axis=0, return_inverse=True)
    g = inverse.reshape(-1)[np.asarray(f, dtype=np.int64)]
    keep = (g[:, 0] != g[:, 1]) & (g[:, 1] != g[:, 2]) & (g[:, 2] != g[:, 0])
    return unique, g[keep]


def generated_sources():
    """(name, vertices, faces) of closed shapes made by trimesh.creation."""
    import trimesh
    import trimesh.creation as c

    box = c.box(extents=(1.0, 2.0, 0.5))
    for _ in range(3):
        box = box.subdivide()
    shapes = [("icosphere", c.icosphere(3)), ("capsule", c.capsule(height=2.0, radius=0.5, count=[24, 24])),
              ("cylinder", c.cylinder(radius=1.0, height=3.0, sections=48)),
              ("cone", c.cone(radius=1.0, height=2.0, sections=48)),
              ("annulus", c.annulus(r_min=0.5, r_max=1.0, height=0.4, sections=48)),
              ("box", box)]
    if hasattr(c, "torus"):
        shapes.append(("torus", c.torus(major_radius=1.0, minor_radius=0.3, major_sections=48, minor_sections=24)))
    out = []
    for name, mesh in shapes:
        if not isinstance(mesh, trimesh.Trimesh):
            continue
        v, f = _weld(mesh.vertices, mesh.faces)
        out.append((f"generated/{name}", v, f))
    return out


def repo_sources():
    import trimesh

    out = []
    for path in sorted((ROOT / "meshes").glob("*.stl")):
        mesh = trimesh.load(str(path), process=False, force="mesh")
        v, f = _weld(mesh.vertices, mesh.faces)
        out.append((f"repo/{path.name}", v, f))
    return out


def _make_cases():
    """``make_cases.py`` beside this file (its robot parts and the touching pair are shared)."""
    here = str(Path(__file__).resolve().parent)
    if here not in sys.path:
        sys.path.insert(0, here)
    import make_cases
    return make_cases


def robot_sources():
    make_cases = _make_cases()
    wheel = OUT / "pkgs" / make_cases.WHEEL
    if not wheel.exists():
        print(f"robots: skipped, {wheel.relative_to(ROOT)} is missing (run make_cases.py, or copy the wheel there)",
              file=sys.stderr, flush=True)
        return []
    dest = OUT / "damage" / "source"
    out = []
    for (rel, _, _), path in zip(make_cases.MESHES, make_cases.extract_meshes(wheel, dest)):
        v, f = make_cases.load_clean(path)
        out.append((f"robots/{rel}", v, f))
    return out


def truth_of(v, f):
    """Exact unit-density properties of a closed mesh, or None when inertia_tool does not call it clean;
    cross-checked against trimesh's integrals."""
    import inertia_tool as it
    import trimesh

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            p = it.mass_properties((v, f), density=1.0, merge_tolerance=0)
        except it.errors.InertiaToolError:
            return None
    notes = (it.errors.NearlyEqualMomentsWarning, it.errors.ImplausibleSizeWarning)
    if any(not issubclass(w.category, notes) for w in caught) or p.mesh.method != "exact":
        return None
    other = trimesh.Trimesh(vertices=v, faces=f, process=False).mass_properties
    if abs(other.volume - p.volume) > 1e-9 * p.volume:
        raise ValueError(f"trimesh's volume {other.volume} disagrees with {p.volume}")
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    return {"volume": float(p.volume), "center_of_mass": p.center_of_mass.tolist(), "inertia": p.inertia.tolist(),
            "diagonal": diag}


# ------------------------------------------------------------------------------------------------- damage

def _adjacency(f):
    edges = np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    owner = np.repeat(np.arange(len(f)), 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    e, o = edges[order], owner[order]
    same = np.all(e[1:] == e[:-1], axis=1)
    a, b = o[:-1][same], o[1:][same]
    nb = [[] for _ in range(len(f))]
    for x, y in zip(a.tolist(), b.tolist()):
        nb[x].append(y)
        nb[y].append(x)
    return nb


def _patch(f, start, keep_going):
    """Faces grown breadth-first from ``start`` while ``keep_going(count, last_face)`` holds."""
    nb = _adjacency(f)
    seen, queue, head = {start}, [start], 0
    while head < len(queue) and keep_going(len(queue), queue[-1]):
        for n in nb[queue[head]]:
            if n not in seen and keep_going(len(queue), queue[-1]):
                seen.add(n)
                queue.append(n)
        head += 1
    return np.array(sorted(seen), dtype=np.int64)


def _areas(v, f):
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def damage_hole(v, f, rng):
    area = _areas(v, f)
    one_face = max(float(np.median(area)), float(area.max()) * 1e-6) / area.sum()
    share = float(np.exp(rng.uniform(np.log(min(one_face, MAX_HOLE_SHARE)), np.log(MAX_HOLE_SHARE))))
    target = share * area.sum()
    taken = [0.0]

    def more(count, last):
        taken[0] = float(area[last]) + (taken[0] if count > 1 else 0.0)
        return taken[0] < target

    gone = _patch(f, int(rng.integers(len(f))), more)
    return v, np.delete(f, gone, axis=0), {"hole_area_share": float(area[gone].sum() / area.sum())}


def damage_scattered(v, f, rng):
    k = max(1, int(rng.uniform(0.005, 0.05) * len(f)))
    gone = rng.choice(len(f), k, replace=False)
    return v, np.delete(f, gone, axis=0), {"faces_removed": k}


def damage_t_junction(v, f, rng):
    share = rng.uniform(0.02, 0.3)
    n = max(1, int(share * len(f)))
    patch = _patch(f, int(rng.integers(len(f))), lambda count, last: count < n)
    pf = f[patch]
    edges = np.sort(pf[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])
    m = (len(v) + inverse.reshape(-1, 3))
    a, b, c = pf[:, 0], pf[:, 1], pf[:, 2]
    ab, bc, ca = m[:, 0], m[:, 1], m[:, 2]
    fine = np.concatenate([np.c_[a, ab, ca], np.c_[ab, b, bc], np.c_[ca, bc, c], np.c_[ab, bc, ca]])
    keep = np.ones(len(f), dtype=bool)
    keep[patch] = False
    return np.vstack([v, mid]), np.vstack([f[keep], fine]), {"faces_split": int(len(patch))}


def damage_crack(v, f, rng, diag):
    n = max(10, int(rng.uniform(0.02, 0.2) * len(f)))
    patch = _patch(f, int(rng.integers(len(f))), lambda count, last: count < n)
    inside = np.zeros(len(f), dtype=bool)
    inside[patch] = True
    border = np.intersect1d(np.unique(f[patch]), np.unique(f[~inside]))
    remap = np.arange(len(v))
    remap[border] = np.arange(len(v), len(v) + len(border))
    f = f.copy()
    f[patch] = remap[f[patch]]
    width = float(np.exp(rng.uniform(np.log(1e-7), np.log(5e-5))))
    d = rng.normal(size=3)
    moved = v[border] + width * diag * d / np.linalg.norm(d)
    return np.vstack([v, moved]), f, {"faces_cut_free": int(len(patch)), "width": width}


def damage_sliver(v, f, rng):
    """A patch of 2–20 % of the faces, each split at a point of one of its edges into a zero-area sliver and two
    triangles: the polyhedron is unchanged and still closed, with needles and flat faces in it."""
    n = max(1, int(rng.uniform(0.02, 0.2) * len(f)))
    patch = _patch(f, int(rng.integers(len(f))), lambda count, last: count < n)
    side = rng.integers(3, size=len(patch))
    pf = np.take_along_axis(f[patch], (side[:, None] + np.arange(3)) % 3, axis=1)    # rotated: keeps winding
    a, b, c = pf[:, 0], pf[:, 1], pf[:, 2]
    # the point along a→b: anywhere from a hair off a (a needle) to the middle, log-uniform
    t = np.exp(rng.uniform(np.log(1e-6), np.log(0.5), size=len(patch)))
    p = v[a] + t[:, None] * (v[b] - v[a])
    m = np.arange(len(v), len(v) + len(patch))
    new = np.concatenate([np.c_[a, b, m], np.c_[b, c, m], np.c_[c, a, m]])
    keep = np.ones(len(f), dtype=bool)
    keep[patch] = False
    return np.vstack([v, p]), np.vstack([f[keep], new]), {"faces_slivered": int(len(patch))}


def _split_by_plane(v, f, normal, offset):
    """The two closed halves of the mesh on either side of a plane, by manifold3d (float64), or None."""
    import manifold3d as m3d

    solid = m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                                    tri_verts=np.ascontiguousarray(f, dtype=np.uint64)))
    if solid.status() != m3d.Error.NoError:
        return None
    halves = []
    for half in solid.split_by_plane(tuple(float(x) for x in normal), float(offset)):
        mesh = half.to_mesh64()
        hv = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
        hf = np.asarray(mesh.tri_verts, dtype=np.int64)
        if not len(hf):
            return None
        halves.append((hv, hf))
    return halves


def damage_internal_wall(v, f, rng):
    """The part cut in two by a plane through a random interior point (manifold3d), the halves joined again
    with the cut face kept as a wall inside: once (a single sheet inside the solid, its rim on three faces) or
    twice, wound both ways (two bodies touching face to face).  The solid is unchanged (to round-off of the
    cut points, 1e-16 of the size)."""
    lo, hi = v.min(axis=0), v.max(axis=0)
    for _ in range(8):
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        point = lo + rng.uniform(0.3, 0.7, size=3) * (hi - lo)
        halves = _split_by_plane(v, f, normal, float(normal @ point))
        if halves is None:
            continue
        (av, af), (bv, bf) = halves
        offset = float(normal @ point)
        scale = float(np.abs(v).max())

        def on_plane(hv, hf):
            d = np.abs(hv[hf] @ normal - offset)
            return np.all(d <= 1e-12 * scale, axis=1)

        wall_a, wall_b = on_plane(av, af), on_plane(bv, bf)
        if not wall_a.any() or not wall_b.any():
            continue
        double = bool(rng.random() < 0.5)
        keep_b = bf if double else bf[~wall_b]
        both_v = np.vstack([av, bv])
        # truth: the two closed halves as manifold3d made them (its cut may move points by its own tolerance,
        # so the clean part is not the truth to 1e-9)
        truth = _moments_truth(both_v, np.vstack([af, bf + len(av)]))
        wv, wf = _weld(both_v, np.vstack([af, keep_b + len(av)]))
        return wv, wf, {"wall_faces": int(wall_a.sum()), "wall": "double" if double else "single"}, truth
    return v, f, {"wall": "none (no cut found)"}, None


def _moments_truth(v, f):
    """Unit-density truth of a union of closed shells with disjoint interiors: the exact integral of all faces
    (integrals add over shells), no classification asked."""
    from inertia_tool.integrals import volume_moments

    m = volume_moments(v, f)
    inertia = np.trace(m.second_moment) * np.eye(3) - m.second_moment
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    return {"volume": float(m.volume), "center_of_mass": m.centroid.tolist(), "inertia": inertia.tolist(),
            "diagonal": diag}


def damage_touching_copy(v, f, rng):
    """The mirror image across one of the six bounding-box planes, joined to the part by exact vertex weld
    where they meet (shared faces where the part has a flat face on that plane, else an edge or a point).
    Truth: both bodies (the exact integral of the two closed shells before welding)."""
    both_v, both_f, axis, _ = _make_cases().mirror_pair(v, f, rng)
    truth = _moments_truth(both_v, both_f)
    wv, wf = _weld(both_v, both_f)
    return wv, wf, {"axis": "xyz"[axis], "shared_vertices": int(len(both_v) - len(wv))}, truth


def make_case(kind, v, f, rng, diag):
    meta = {}
    if kind in ("t_junction", "t_junction_hole"):
        v, f, m = damage_t_junction(v, f, rng)
        meta.update(m)
    if kind in ("crack", "crack_hole"):
        v, f, m = damage_crack(v, f, rng, diag)
        meta.update(m)
    if kind in ("hole", "t_junction_hole", "crack_hole"):
        v, f, m = damage_hole(v, f, rng)
        meta.update(m)
    if kind == "holes_scattered":
        v, f, m = damage_scattered(v, f, rng)
        meta.update(m)
    if kind == "sliver":
        v, f, m = damage_sliver(v, f, rng)
        meta.update(m)
    return v, f, meta


# --------------------------------------------------------------------------------------------- evaluation

def evaluate(v, f, truth, assume=()):
    """What repair=True says about a damaged mesh, checked against the truth (``assume``: the user's assumptions,
    ``LoadOptions.assume``)."""
    import inertia_tool as it

    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = it.mass_properties((v, f), density=1.0, repair=True, assume=tuple(assume))
    except it.errors.InvalidMeshError as exc:
        return {"status": "refused", "seconds": time.perf_counter() - start, "reason": str(exc)[:300]}
    except Exception as exc:       # a bug: reported, never hidden
        return {"status": "error", "seconds": time.perf_counter() - start,
                "reason": f"{type(exc).__name__}: {exc}"[:300]}
    seconds = time.perf_counter() - start
    diag = truth["diagonal"]
    inertia, true_inertia = np.asarray(p.inertia), np.asarray(truth["inertia"])
    err_mass = abs(p.volume - truth["volume"])
    err_com = float(np.linalg.norm(p.center_of_mass - np.asarray(truth["center_of_mass"])))
    err_inertia = float(np.linalg.norm(inertia - true_inertia))
    norm = float(np.linalg.norm(inertia))
    u = p.mesh.uncertainty
    bounds = (ROUND_OFF, ROUND_OFF * diag, ROUND_OFF) if u is None else (u.mass, u.center_of_mass, u.inertia)
    holds = (err_mass <= bounds[0] * p.volume * (1 + ROUND_OFF) + ROUND_OFF * truth["volume"]
             and err_com <= bounds[1] * (1 + ROUND_OFF) + ROUND_OFF * diag
             and err_inertia <= bounds[2] * norm * (1 + ROUND_OFF) + ROUND_OFF * norm)
    within = (err_mass <= VOLUME_RTOL * truth["volume"] and err_com <= COM_DTOL * diag
              and err_inertia <= INERTIA_RTOL * float(np.linalg.norm(true_inertia)))
    certificate = p.mesh.certificate.kind
    # an "unverified" answer claims no bound (its certificate says so): counted apart, never as holding
    return {"status": "answer", "seconds": seconds, "method": p.mesh.method, "certificate": certificate,
            "assumptions": list(p.mesh.certificate.assumptions),
            "holds": None if certificate == "unverified" else bool(holds),
            "within": bool(within), "mass_bound": float(bounds[0]), "com_bound_of_diag": float(bounds[1] / diag),
            "inertia_bound": float(bounds[2]), "mass_error": err_mass / truth["volume"],
            "com_error_of_diag": err_com / diag, "inertia_error": err_inertia / float(np.linalg.norm(true_inertia))}


def _quantised(v, f, rng, diag):
    q = diag * 10.0 ** -rng.uniform(4, 6)
    qv, qf = _weld(np.round(v / q) * q, f)
    return qv, qf, q


def cases(sources, seeds, repeats=1, kinds=KINDS):
    """(case id, source, kind, seed, rng state) of every case, in a fixed order (``kinds``: a subset)."""
    for seed in seeds:
        for s in range(len(sources)):
            for k, kind in enumerate(KINDS):
                if kind not in kinds:
                    continue
                for r in range(repeats):
                    yield f"{seed}-{s:02d}-{kind}-{r}", s, kind, [seed, s, k, r]


def run_case(args):
    case_id, source, kind, entropy, (name, v, f, clean_truth) = args[:5]
    assume = tuple(args[5]) if len(args) > 5 else ()
    rng = np.random.default_rng(entropy)
    truth, quantum = clean_truth, None
    if rng.random() < QUANTISE_SHARE:
        qv, qf, q = _quantised(v, f, rng, clean_truth["diagonal"])
        qt = truth_of(qv, qf)
        if qt is not None:
            v, f, truth, quantum = qv, qf, qt, q
    if kind == "touching_copy":
        dv, df, meta, truth = damage_touching_copy(v, f, rng)
    elif kind == "internal_wall":
        dv, df, meta, cut_truth = damage_internal_wall(v, f, rng)
        truth = cut_truth if cut_truth is not None else truth
    else:
        dv, df, meta = make_case(kind, v, f, rng, truth["diagonal"])
    if kind not in ("touching_copy", "internal_wall") and _shell_removed(v, f, dv, df):
        # the damage took a whole shell of a multi-shell source (a cavity, a small part): the solid is not kept,
        # so the truth is not the answer's (review7 found it in real_files.py; here hollow_sphere.stl's cavity)
        return {"id": case_id, "source": name, "kind": kind, "faces": int(len(df)), "quantum": quantum, **meta,
                "status": "skipped", "reason": "the damage removed a whole shell"}
    cpu = time.process_time()
    result = evaluate(dv, df, truth)
    result["cpu_seconds"] = time.process_time() - cpu
    result["area_lost_share"] = _area_lost(v, f, dv, df)
    if result["status"] == "refused" and refusal_cause(result["reason"]) == BALL_CAUSE:
        result["bypassed"] = bypassed(dv, df, truth)
    if assume:
        # the same case with the user's assumptions stated (``--assume``): reported beside the default answer
        cpu = time.process_time()
        result["assumed"] = evaluate(dv, df, truth, assume)
        result["assumed"]["cpu_seconds"] = time.process_time() - cpu
    return {"id": case_id, "source": name, "kind": kind, "faces": int(len(df)), "quantum": quantum, **meta, **result}


def _shell_removed(v, f, dv, df):
    """Whether the damaged surface ``(dv, df)`` lost every face of some shell (connected component) of the clean
    ``(v, f)``.  Each vertex the damaged faces use is matched to the nearest clean vertex (holes keep the clean
    vertices, T-junctions add points on clean edges, cracks move corners by at most 5e-5 of the diagonal); a
    shell none of whose vertices is matched is gone."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    f = np.asarray(f, dtype=np.int64)
    rows = np.repeat(np.arange(len(f)), 3)
    graph = coo_matrix((np.ones(3 * len(f), dtype=np.int8), (rows, f.reshape(-1))), shape=(len(f), len(v)))
    count, label = connected_components(coo_matrix(graph.T @ graph), directed=False)
    used = np.unique(f)
    shells = np.unique(label[used])
    if len(shells) < 2:
        return len(np.asarray(df)) == 0
    kept_points = np.asarray(dv, dtype=np.float64)[np.unique(np.asarray(df, dtype=np.int64))]
    if not len(kept_points):
        return True
    _, nearest = cKDTree(np.asarray(v, dtype=np.float64)[used]).query(kept_points)
    return bool(len(np.setdiff1d(shells, np.unique(label[used][nearest]))))


def _area_lost(v, f, dv, df):
    """Share of the clean surface's area the damaged surface lacks (the holes; 0 for damage that keeps it)."""
    whole = float(_areas(v, f).sum())
    return max(whole - float(_areas(dv, df).sum()), 0.0) / whole if whole > 0 else 0.0


#: The refusal :func:`bypassed` looks behind (the patched estimate's mass bound above the limit).
BALL_CAUSE = "patched: ball over a hole too large"


def bypassed(v, f, truth):
    """What ``repair=True`` would have answered had the mass-bound limit not refused it: the same pipeline with
    ``check_useful`` skipped (the benchmark's measurement only; the library keeps refusing), with the
    rims' count and the true errors, so the refusals can be judged (would the answer have been within
    tolerance? how loose is the bound?)."""
    import inertia_tool.mesh.uncertainty as unc_module

    original = unc_module.check_useful

    def lifted(*args, **kwargs):
        return None                    # no limit at all: a bound above 100 % leaves the centre of mass unbounded

    unc_module.check_useful = lifted
    try:
        row = evaluate(v, f, truth)
    finally:
        unc_module.check_useful = original
    row.pop("seconds", None)
    row["loops"] = _loop_count(v, f)
    return row


def _loop_count(v, f):
    """Boundary loops of the damaged surface as given (before any seam is sealed)."""
    from inertia_tool.mesh.rims import boundary_edges, boundary_loops

    edges = boundary_edges(np.asarray(f, dtype=np.int64), len(v))
    return int(boundary_loops(edges, len(v), np.asarray(f, dtype=np.int64), np.asarray(v))[1]) if len(edges) else 0


def summarise(rows):
    skipped = [r for r in rows if r["status"] == "skipped"]
    rows = [r for r in rows if r["status"] != "skipped"]
    answered = [r for r in rows if r["status"] == "answer"]
    refused = [r for r in rows if r["status"] == "refused"]
    errors = [r for r in rows if r["status"] == "error"]
    certified = [r for r in answered if r.get("holds") is not None]
    held = sum(bool(r["holds"]) for r in certified)
    within = sum(r["within"] for r in answered)
    bound = [r["mass_bound"] for r in certified]
    return {"cases": len(rows), "skipped": len(skipped), "answered": len(answered), "refused": len(refused),
            "errors": len(errors),
            "unverified": len(answered) - len(certified), "certified": len(certified),
            "bounds_hold": held, "coverage": held / len(certified) if certified else float("nan"),
            "within_tolerance": within,
            "within_share_of_answered": within / len(answered) if answered else float("nan"),
            "within_share_of_all": within / len(rows) if rows else float("nan"),
            "refused_share": len(refused) / len(rows) if rows else float("nan"),
            "refused_by_cause": {cause: sum(1 for r in refused if refusal_cause(r["reason"]) == cause)
                                 for cause in sorted({refusal_cause(r["reason"]) for r in refused})},
            "median_mass_bound": float(np.median(bound)) if bound else float("nan"),
            "median_com_bound_of_diag": float(np.median([r["com_bound_of_diag"] for r in certified]))
            if certified else float("nan"),
            "median_estimate_mass_bound": float(np.median(est)) if (est := [r["mass_bound"] for r in certified
                                                                          if r["certificate"] == "estimate"])
            else float("nan"),
            "cpu_seconds": float(sum(r.get("cpu_seconds", 0.0) for r in rows)),
            "slowest_seconds": max((r.get("seconds", 0.0) for r in rows), default=0.0)}


def table(rows):
    lines = ["| kind | cases | answered | bounds hold (of certified) | unverified | within 1 %/1 %/2 % (of all) "
             "| within (of answered) | refused | errors | median mass bound (all certified / estimates) | CPU (s) "
             "| slowest (s) | skipped |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for kind in (*KINDS, "all"):
        sel = rows if kind == "all" else [r for r in rows if r["kind"] == kind]
        if not sel:
            continue
        s = summarise(sel)
        lines.append(f"| {kind} | {s['cases']} | {s['answered']} | {s['bounds_hold']}/{s['certified']} "
                     f"({100 * s['coverage']:.1f} %) | {s['unverified']} "
                     f"| {s['within_tolerance']} ({100 * s['within_share_of_all']:.1f} %) "
                     f"| {s['within_tolerance']}/{s['answered']} ({100 * s['within_share_of_answered']:.1f} %) "
                     f"| {s['refused']} ({100 * s['refused_share']:.1f} %) | {s['errors']} "
                     f"| {100 * s['median_mass_bound']:.2g} % / {100 * s['median_estimate_mass_bound']:.2g} % "
                     f"| {s['cpu_seconds']:.2f} | {s['slowest_seconds']:.2f} | {s['skipped']} |")
    return "\n".join(lines)


#: The target share of cases within tolerance (issue 21 item 3: "answers within 1 % / 1 % of the diagonal / 2 % in
#: >= 95 %") and of certified answers whose bounds hold (">= 99 %").
WITHIN_TARGET, HOLD_TARGET = 0.95, 0.99


def readings(rows):
    """The two readings of the 95 % target, one line each (within tolerance among all cases, refusals counted as
    not within; among the answered cases, refusals counted apart with their rate and causes), and the bounds'
    99 % (markdown)."""
    s = summarise(rows)

    def met(share, target):
        return "met" if share >= target else "NOT met"

    causes = ", ".join(f"{cause} {count}" for cause, count in s["refused_by_cause"].items()) or "none"
    return "\n".join([
        f"- within 1 %/1 %/2 % among all cases: {s['within_tolerance']}/{s['cases']} "
        f"({100 * s['within_share_of_all']:.1f} %): 95 % {met(s['within_share_of_all'], WITHIN_TARGET)}",
        f"- within 1 %/1 %/2 % among answered cases: {s['within_tolerance']}/{s['answered']} "
        f"({100 * s['within_share_of_answered']:.1f} %): 95 % {met(s['within_share_of_answered'], WITHIN_TARGET)}; "
        f"refused {s['refused']}/{s['cases']} ({100 * s['refused_share']:.1f} %): {causes}",
        f"- bounds hold: {s['bounds_hold']}/{s['certified']} ({100 * s['coverage']:.1f} %): 99 % "
        f"{met(s['coverage'], HOLD_TARGET)}; median mass bound {100 * s['median_mass_bound']:.3g} % (all certified), "
        f"{100 * s['median_estimate_mass_bound']:.3g} % (estimates)"])


#: Refusal messages grouped by their cause (first match wins).
REFUSAL_CAUSES = (
    ("patched: ball over a hole too large", "the patched surface cannot be bounded usefully"),
    ("patched: body or cavity undecided", "the file does not say whether it is a body or a cavity"),
    ("patched: winding estimate past ±50 %", "the patched surface's winding-number estimate cannot be bounded"),
    ("patched: footprint of a feature taken whole", "footprint of a feature"),
    ("winding: passes through itself", "passes through itself"),
    ("winding: union not formed", "union could not be formed"),
    ("winding: loose triangles", "the loose triangles"),
    ("encloses no volume", "encloses no volume"),
    ("encloses no volume", "encloses a volume of"),
)


def refusal_cause(reason):
    return next((cause for cause, text in REFUSAL_CAUSES if text in reason), "other: " + reason[:80])


def refusal_table(rows):
    """Refusals by damage kind and cause (markdown)."""
    refused = [r for r in rows if r["status"] == "refused"]
    causes = sorted({refusal_cause(r["reason"]) for r in refused})
    kinds = [k for k in KINDS if any(r["kind"] == k for r in refused)]
    lines = ["| cause | " + " | ".join(kinds) + " | all |", "|---|" + "---:|" * (len(kinds) + 1)]
    for cause in causes:
        counts = [sum(1 for r in refused if r["kind"] == k and refusal_cause(r["reason"]) == cause) for k in kinds]
        lines.append(f"| {cause} | " + " | ".join(str(c) for c in counts) + f" | {sum(counts)} |")
    return "\n".join(lines)


def bypass_table(rows):
    """The refusals for a too-large ball, answered anyway (:func:`bypassed`), by damage kind and source group
    (markdown): how many would have been within tolerance, and how far the bound is from the true error."""
    refused = [r for r in rows if r.get("bypassed")]
    groups = sorted({(r["kind"], r["source"].split("/")[0]) for r in refused})
    lines = ["| kind | source | cases | loops (median) | area lost % (median) | mass bound % (median) "
             "| true mass error % (median) | bound / error (median) | would be within 1 %/1 %/2 % "
             "| bound holds (of certified) |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for kind, group in [*groups, ("all", "all")]:
        sel = [r for r in refused if kind == "all" or (r["kind"] == kind and r["source"].startswith(group + "/"))]
        answered = [r["bypassed"] for r in sel if r["bypassed"]["status"] == "answer"]
        if not sel:
            continue
        med = (lambda xs: float(np.median(xs)) if xs else float("nan"))
        ratio = [b["mass_bound"] / max(b["mass_error"], 1e-12) for b in answered]
        lines.append(f"| {kind} | {group} | {len(sel)} | {med([r['bypassed']['loops'] for r in sel]):.0f} "
                     f"| {100 * med([r['area_lost_share'] for r in sel]):.2g} "
                     f"| {100 * med([b['mass_bound'] for b in answered]):.3g} "
                     f"| {100 * med([b['mass_error'] for b in answered]):.2g} | {med(ratio):.3g} "
                     f"| {sum(b['within'] for b in answered)}/{len(sel)} "
                     f"| {sum(b['holds'] is True for b in answered)}/{sum(b['holds'] is not None for b in answered)} |")
    return "\n".join(lines)


def assumed_rows(rows):
    """The rows as answered with ``--assume`` (each row's ``assumed`` result in place of its default one)."""
    return [{**r, **r["assumed"]} if "assumed" in r else r for r in rows]


def load_sources(names):
    out = []
    for group in names:
        out += {"generated": generated_sources, "repo": repo_sources, "robots": robot_sources}[group]()
    with_truth = []
    for name, v, f in out:
        t = truth_of(v, f)
        if t is not None:
            with_truth.append((name, v, f, t))
    return with_truth


def subset(seed=11, limit=30):
    """The fast CI subset: generated and repo sources only, ``limit`` cases of one seed, in a fixed order."""
    sources = load_sources(("generated", "repo"))
    tasks = {(s, kind): (cid, s, kind, ent, sources[s]) for cid, s, kind, ent in cases(sources, [seed])}
    # case i: source i mod (sources), kind i mod (kinds): every source and every kind, in varied pairs
    return [run_case(tasks[(i % len(sources), KINDS[i % len(KINDS)])]) for i in range(limit)]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", default="3,4,5,6,7")
    parser.add_argument("--sources", default="generated,repo,robots")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--kinds", default=",".join(KINDS), help="damage kinds to run (default: all)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=OUT / "coverage.json",
                        help="the results file (JSON); a folder given here gets coverage.json in it")
    parser.add_argument("--subset", action="store_true", help="the CI subset only")
    parser.add_argument("--assume", action="append", default=[], metavar="NAME",
                        help="also answer every case with this user's assumption stated (LoadOptions.assume) and "
                             "report both")
    args = parser.parse_args(argv)
    if args.out.is_dir():             # a folder: its coverage.json (a run of minutes must not end unable to write)
        args.out = args.out / "coverage.json"
    sys.path.insert(0, str(ROOT))
    if args.subset:
        rows = subset()
    else:
        sources = load_sources(args.sources.split(","))
        seeds = [int(s) for s in args.seeds.split(",")]
        kinds = tuple(args.kinds.split(","))
        tasks = [(cid, s, kind, ent, sources[s], tuple(args.assume))
                 for cid, s, kind, ent in cases(sources, seeds, args.repeats, kinds)]
        print(f"{len(tasks)} cases from {len(sources)} sources, seeds {seeds}", flush=True)
        with mp.get_context("spawn").Pool(args.workers) as pool:
            rows = []
            for i, row in enumerate(pool.imap(run_case, tasks, chunksize=4)):
                rows.append(row)
                if row["status"] == "error" or (row["status"] == "answer" and row["holds"] is False):
                    print(f"  {row['id']} {row['source']} {row['kind']}: {row}", flush=True)
                if (i + 1) % 100 == 0:
                    print(f"{i + 1}/{len(tasks)}", flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    summary = {"summary": summarise(rows)}
    if args.assume:
        summary["summary_assumed"] = summarise(assumed_rows(rows))
        summary["assumed"] = list(args.assume)
    args.out.write_text(json.dumps({**summary, "rows": rows}, indent=1))
    print(table(rows))
    print()
    print(readings(rows))
    print()
    print(refusal_table(rows))
    if any(r.get("bypassed") for r in rows):
        print()
        print(bypass_table(rows))
    print(json.dumps(summarise(rows), indent=1))
    if args.assume:
        with_assumption = assumed_rows(rows)
        print(f"\nWith --assume {' --assume '.join(args.assume)}:")
        print(table(with_assumption))
        print()
        print(readings(with_assumption))
        print()
        print(refusal_table(with_assumption))
        print(json.dumps(summarise(with_assumption), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
