"""Double walls whose rim turns round a corner or an edge of the part (issue 21, item 1; R3a in mesh/folds.py).

A closed part is cut in two by manifold3d (a plane through a random point near a corner or an edge of the part,
so that the cut's rim turns round the part's corners; or a wedge, so that the wall itself is bent round the
wedge's edge), and both halves are written face to face, welded where their corners are bit-identical: two
sheets of opposite orientation over the cut, each half's rim with corners the other lacks.

Truths are independent of the pipeline: the halves' own integrals added (closed pieces with disjoint interiors),
in rational arithmetic (``adversary_solids.fraction_moments``, exact) for pieces of at most 600 faces, and the
volume of manifold3d's union of the halves as a second witness.  Every answer labelled ``exact`` or ``united``
must match the truth to 1e-9; a refusal must be one line naming the mesh; nothing may raise anything else.

The so101 upper arm cases of the damage benchmark (``9-33``/``23-33``, refused before: 1,078-1,251 face pairs
crossing) run when the benchmark's robot wheel is present (``benchmarks/out/pkgs``), else are skipped.
"""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import inertia_tool as it
from adversary_solids import box, part, random_rotation, to_manifold, truth_from_pieces
from test_mesh_sheets import _halves

ROOT = Path(__file__).resolve().parents[1]
SETTINGS = settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
#: What an answer labelled exact or united must match (relative; the truth is exact or manifold3d's).
RTOL = 1e-9


def _welded(pieces):
    """The pieces written as one surface, corners welded where bit-identical."""
    v = np.vstack([p[0] for p in pieces])
    offsets = np.cumsum([0] + [len(p[0]) for p in pieces[:-1]])
    f = np.vstack([p[1] + o for p, o in zip(pieces, offsets)])
    uniq, inverse = np.unique(v, axis=0, return_inverse=True)
    return uniq, inverse.reshape(-1)[f]


def _shape(kind, rng):
    """A closed outward part: a subdivided box (axis-aligned or turned), or a repository part."""
    if kind == "box":
        v, f = box(rng.uniform(0.3, 2.0, size=3), subdivide=int(rng.integers(1, 4)))
    elif kind == "turned box":
        v, f = box(rng.uniform(0.3, 2.0, size=3), subdivide=int(rng.integers(1, 4)))
        v = v @ random_rotation(rng).T
    elif kind in REAL_PARTS:
        v, f = _real_part(kind)
    else:
        v, f = part(kind)
    return v, f


#: Real parts in tests/data (see its README), closed, two-manifold and clean.
REAL_PARTS = {"panda link3": "robots/example-robot-data/robots/panda_description/meshes/collision/link3.stl",
              "tiago arm link": "tiago_pro_arm_7_link_collision.stl",
              "xyz cube": "real_parts/20mm-xyz-cube.stl"}
_REAL_CACHE: dict = {}


def _real_part(kind):
    """A part of tests/data as read (welded by trimesh), wound outward (the tiago link is written inside out)."""
    if kind not in _REAL_CACHE:
        import trimesh
        mesh = trimesh.load(ROOT / "tests" / "data" / REAL_PARTS[kind], force="mesh")
        v = np.asarray(mesh.vertices, dtype=np.float64)
        f = np.asarray(mesh.faces, dtype=np.int64)
        if float(to_manifold((v, f)).volume()) < 0:
            f = f[:, ::-1].copy()
        _REAL_CACHE[kind] = (v, f)
    v, f = _REAL_CACHE[kind]
    return v.copy(), f.copy()


def _near_corner_point(v, rng):
    """A point between the part's centre and a random corner (or edge midpoint) of its bounding box, so that a
    plane through it cuts off a corner or an edge of the part."""
    lo, hi = v.min(axis=0), v.max(axis=0)
    target = np.where(rng.random(3) < 0.5, lo, hi)
    if rng.random() < 0.4:                                     # an edge of the box: one coordinate mid-way
        k = int(rng.integers(3))
        target[k] = rng.uniform(lo[k], hi[k])
    return (lo + hi) / 2 + rng.uniform(0.3, 0.9) * (target - (lo + hi) / 2)


def _plane_cut(v, f, rng):
    """The two halves of a cut by a plane through a point near a corner or edge; None when one is empty."""
    normal = rng.normal(size=3)
    if rng.random() < 0.3:                                     # a plane parallel to a face of the box
        normal = np.eye(3)[int(rng.integers(3))] + 1e-3 * rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    point = _near_corner_point(v, rng)
    halves = _halves(v, f, normal, float(normal @ point))
    if len(halves) != 2 or not all(len(h[1]) for h in halves):
        return None
    return halves


def _wedge_cut(v, f, rng):
    """The part split by a wedge (two half-spaces meeting along a line through a point near a corner): the piece
    inside the wedge and the rest (manifold3d booleans), whose common wall is bent round the wedge's edge."""
    import manifold3d as m3d

    solid = to_manifold((v, f))
    point = _near_corner_point(v, rng)
    size = 4 * float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))) + 1.0
    wedge = m3d.Manifold.cube((size, size, size))              # the octant x, y, z ≥ 0, turned, its corner at point
    rot = random_rotation(rng)
    matrix = np.c_[rot, point].tolist()
    wedge = wedge.transform(matrix)
    pieces = []
    for piece in (solid ^ wedge, solid - wedge):
        mesh = piece.to_mesh64()
        pv = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3].copy()
        pf = np.asarray(mesh.tri_verts, dtype=np.int64)
        if not len(pf):
            return None
        pieces.append((pv, pf))
    return pieces


def _union_volume(pieces):
    import manifold3d as m3d
    union = m3d.Manifold.batch_boolean([to_manifold(p) for p in pieces], m3d.OpType.Add)
    return float(union.volume())


def _check(pieces, name="<arrays>"):
    """Analyse the welded pieces and hold the answer to the truth; returns the certificate kind or 'refused'."""
    truth = truth_from_pieces([(1, p) for p in pieces])
    assert abs(_union_volume(pieces) - truth.volume) <= 1e-9 * truth.volume     # the halves' interiors are disjoint
    v, f = _welded(pieces)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = it.mass_properties((v, f), density=1.0)
    except it.errors.InvalidMeshError as exc:
        message = str(exc)
        assert "\n" not in message and message.startswith(name)
        return "refused"
    kind = p.mesh.certificate.kind
    scale = truth.volume ** (1 / 3) + float(np.abs(truth.centroid).max())
    if kind in ("exact", "united"):
        assert abs(p.volume - truth.volume) <= RTOL * truth.volume, (kind, p.volume, truth.volume)
        assert np.max(np.abs(p.center_of_mass - truth.centroid)) <= RTOL * scale
        assert np.max(np.abs(p.inertia - truth.inertia)) <= RTOL * np.max(np.abs(truth.inertia))
    else:
        u = p.mesh.uncertainty
        assert kind == "unverified" or u is not None
        if u is not None:
            assert abs(p.volume - truth.volume) <= u.mass * p.volume * (1 + 1e-9) + 1e-12 * truth.volume
    return kind


@pytest.mark.slow
@pytest.mark.usefixtures("engine_path")
@SETTINGS
@given(seed=st.integers(0, 2 ** 32 - 1), kind=st.sampled_from(["box", "turned box", "t_handle.stl", "washer.stl",
                                                                *REAL_PARTS]))
def test_a_part_cut_near_a_corner_and_written_face_to_face_is_right(seed, kind):
    """A plane cut through a point near a corner or an edge of the part: the rim turns round the part's
    corners.  Exact or united answers match the truth; on the boxes (grid-meshed sides, so that the halves' rims
    carry different corners) the answer is exact."""
    rng = np.random.default_rng(seed)
    v, f = _shape(kind, rng)
    halves = _plane_cut(v, f, rng)
    if halves is None:
        return
    got = _check(halves)
    if kind in ("box", "turned box"):
        assert got == "exact"                      # 150/150 and 139/139 of seeds 0-149 (1 % and 9 % refused before)


@pytest.mark.slow
@pytest.mark.usefixtures("engine_path")
@SETTINGS
@given(seed=st.integers(0, 2 ** 32 - 1), kind=st.sampled_from(["box", "turned box", "t_handle.stl", *REAL_PARTS]))
def test_a_part_split_by_a_wedge_with_a_bent_wall_is_right(seed, kind):
    """A wall bent round the wedge's edge (two planes meeting inside the part): never a wrong number labelled
    exact or united."""
    rng = np.random.default_rng(seed)
    v, f = _shape(kind, rng)
    pieces = _wedge_cut(v, f, rng)
    if pieces is None:
        return
    _check(pieces)


# -- the so101 upper arm (damage benchmark) ------------------------------------------------------------------

def _coverage():
    spec = importlib.util.spec_from_file_location("damage_coverage", ROOT / "benchmarks" / "damage" / "coverage.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _so101_case(case_id):
    cov = _coverage()
    make_cases = cov._make_cases()
    if not (cov.OUT / "pkgs" / make_cases.WHEEL).exists():
        pytest.skip("the damage benchmark's robot wheel is not downloaded (benchmarks/damage/make_cases.py)")
    sources = cov.load_sources(("generated", "repo", "robots"))
    for cid, s, _kind, entropy in cov.cases(sources, [int(case_id.split("-")[0])], 1, ("internal_wall",)):
        if cid != case_id:
            continue
        name, v, f, truth = sources[s]
        rng = np.random.default_rng(entropy)
        if rng.random() < cov.QUANTISE_SHARE:
            qv, qf, _ = cov._quantised(v, f, rng, truth["diagonal"])
            qt = cov.truth_of(qv, qf)
            if qt is not None:
                v, f, truth = qv, qf, qt
        dv, df, meta, cut_truth = cov.damage_internal_wall(v, f, rng)
        return name, dv, df, meta, cut_truth
    raise AssertionError(f"case {case_id} not drawn")


@pytest.mark.slow
@pytest.mark.parametrize("case_id", ["9-33-internal_wall-0", "23-33-internal_wall-0"])
def test_the_so101_upper_arm_cut_round_its_corner_is_exact(case_id):
    """Refused before ("passes through itself at 1,251 / 1,078 face pairs"): a small piece of the wall, where
    the rim runs along the arm's flat side y = 0, crossed that side's faces by rounding, and the crossing pairs
    joined the two planes into one group that was no wall.  Now exact, right to rounding.  Run on the default
    engine only: the numpy path's float64 integrals of this 27k-face part are bounded only to 9e-9 and too large
    for its exact arithmetic, so it says ``unverified`` there, whatever the walls."""
    name, v, f, meta, truth = _so101_case(case_id)
    assert name.endswith("upper_arm_so101_v1.stl") and meta["wall"] == "double"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = it.mass_properties((v, f), density=1.0)
    assert p.mesh.certificate.kind == "exact"
    assert "zero-volume-folds" in p.mesh.certificate.checks
    assert abs(p.volume - truth["volume"]) <= 1e-12 * truth["volume"]
    inertia = np.asarray(truth["inertia"])
    assert np.max(np.abs(p.inertia - inertia)) <= 1e-11 * np.max(np.abs(inertia))


def test_an_edge_of_many_faces_seeds_no_quadratic_work():
    """The facing pairs at four-face edges seed the wall search; an edge of 400 faces (a fan of slivers around
    one edge) is past the work bound and seeds nothing, at once."""
    from inertia_tool.mesh.folds import MAX_FOLD_VALENCE, _facing_at_folded_edges

    k = 400
    angle = np.linspace(0, 2 * np.pi, k, endpoint=False)
    v = np.vstack([[0, 0, 0], [0, 0, 1], np.stack([np.cos(angle), np.sin(angle), np.full(k, 0.5)], axis=1)])
    f = np.array([[0, 1, 2 + i] if i % 2 else [1, 0, 2 + i] for i in range(k)], dtype=np.int64)
    assert len(_facing_at_folded_edges(v, f)) == 0 and MAX_FOLD_VALENCE < k
    # four faces: a wall's two sheets (opposite ways, opposite normals) and two faces of the part
    v4 = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 1, 0], [0.5, 0, 1], [0.5, 0, -1]], dtype=float)
    f4 = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]], dtype=np.int64)
    pairs = {tuple(sorted(p)) for p in _facing_at_folded_edges(v4, f4).tolist()}
    assert (0, 1) in pairs
