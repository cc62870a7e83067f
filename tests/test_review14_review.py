"""Review 14 (issue 21, "certified answers"): an adversarial review of session 14's new certificates before they
are merged — the vertex star certificates of the face-pair check (``mesh/intersect.py`` "Stars"; the review ran
on a branch that also held small14's convex crease certificate, which was then not merged: the tests below check
the certificates main has), dome14's island rule (``hole_bounds.flat_islands``,
``holes.patched_estimate``) and count14's Hunter witness of a boolean union (``unite._union_witness``,
``_largest_tree_weight``).  Truths are exact rational integrals (``review12_generators.rational_moments``,
``adversary_solids.fraction_moments``) or exact rational unions of axis-aligned boxes (:func:`_box_union_truth`),
never the engine; a silent wrong is an ``exact``/``united`` answer off by more than ``judge_numbers``'
tolerances, or an ``estimate`` whose bounds miss the truth.

Tried (the generators below; larger runs by the same code with more draws), silent wrong found:

* convex crease stars: open stars of 3..9 faces round one vertex (rings going round twice, a ring vertex
  reflected through the centre, coplanar within 1 ulp, a flat cap half next to a vertical side half pushed by
  1e-7, a reversed repeated face), scaled by 1, 1e-3, 1e-6 and moved 0..1e9 from the origin, turned at random:
  3,000 stars (about 800 certified); the same at 1e-280..1e200 (600, also 600 with a face 1e150..1e250 m away in
  the same mesh, past the predicates' range); and fan-capped cylinders of 3..23 sections with 1..3 vertices pushed
  by 1 ulp .. 1.5 (along the axis, radially, onto another vertex, through the axis), faces shuffled, reversed or
  repeated, 0..1e9 out: 800 solids (410 crossing themselves).  The C scan with its certificates, the C scan without
  (``_star_faces=0, _patches=False``) and the numpy twin with and without stars found the same pairs every time:
  0 missed crossings, so 0 silent wrongs from this certificate.
* island rule (``repair=True``): the review 13 grid dome (``z = ±h (1 − r²/rb²)`` taken whole with a ring round
  it), but on a ring that is only nearly flat — a bowl ``c (x² + y²)``, a saddle ``c (x² − y²)`` or a ripple
  ``c sin 7x cos 5y`` with ``c`` 1e-5..1e-1: 7 of 30 draws answered ``estimate`` with bounds that miss the truth
  (3 refused, the rest hold).  The flatness test measures every face at the rim against the plane of the *largest*
  face at the rim (``hole_bounds.rim_evidence``), so a ring curved by 4e-4 already fails it; the hole then fell
  back to ``bend``, which bounded a dome by the gentle slope of the ring.  Fixed by the level-ring rule
  (``hole_bounds.level_rings``: every face at the rim within 1.1° of its plane makes the hole an island); a ring
  visibly curved (slopes 0.04..0.14) still lets ``bend`` miss a steeper dome: the strict xfail below.
  Not found: a dome or dimple taken whole whose removed region reaches the top's border (along an edge or at a
  corner: the rim on the crease) or stops two cells short of it, on rings flat or curved 1e-4..1e-3: 40 draws,
  0 silent (11 refused).
* Hunter witness: three to five boxes (dyadic corners) overlapping as a chain, a star (one box meeting all),
  a cycle, or touching face to face (pairwise intersections of zero volume, in a row or a staircase), subdivided
  or not, axis-aligned or turned at random, 0..6e7 m out (turned ones at most 1e6 m out unless they only touch:
  the rounding of a turned corner 6e7 m out moves a unit box's volume by ~1e-8, beyond the judge's 1e-9):
  300 cases, then 200 more of boxes 1,000 m across (up to 6e7 m out turned) a third with the first box listed
  again turned by 1e-13..1e-10 rad: 0 silent, 0 demoted by the witness (it ran on half of them; largest
  margins 4.7e-12 m³ lost, 8.9e-15 m³ gained) (no ``unverified`` carrying either witness note while the numbers
  held); 79 other needless demotions (``unverified`` while right to 1e-9), all from checks older than the witness:
  manifold3d's union crossing itself by rounding, or the round-off bound of the integrals above 1e-10.
  count14's R4c change (``classify._holds``): 300 fresh draws of ``test_mesh_kept_cavities._draw`` (seeds 100000..
  100299), 0 wrong (281 refused, 17 united, 2 unverified).
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import review12_generators as G
from adversary_solids import box, random_rotation, truth_from_pieces
from conftest import HAVE_ACCEL
from contact_scans import fan_capped_cylinder, run_scan, same_pairs
from test_review13_findings import _heightfield

_SETTINGS = dict(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
needs_accel = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


# ------------------------------------------------------------------------------------- convex crease stars
def _all_scans_agree(v: np.ndarray, f: np.ndarray) -> None:
    """The C scan with its star certificates finds what the C scan without certificates or patches finds, and
    the numpy twin with and without stars (a certificate that skipped a crossing would show here)."""
    fast = run_scan(v, f, True)
    same_pairs(fast, run_scan(v, f, True, _star_faces=0, _patches=False))
    same_pairs(fast, run_scan(v, f, False))
    same_pairs(fast, run_scan(v, f, False, _star_faces=0))


def _placed(rng: np.random.Generator, v: np.ndarray) -> np.ndarray:
    """``v`` scaled by 1, 1e-3 or 1e-6, turned at random (or not) and moved 0..1e9 from the origin."""
    scale = float(rng.choice([1.0, 1e-3, 1e-6]))
    turn = random_rotation(rng) if rng.integers(2) else np.eye(3)
    far = float(rng.choice([0.0, 1e6, 1e8, 1e9])) * rng.choice([-1.0, 1.0], 3)
    return v * scale @ turn.T + far


@needs_accel
@settings(max_examples=120, **_SETTINGS)
@given(seed=st.integers(0, 2 ** 32 - 1), kind=st.sampled_from(["twice", "reflected", "ulp_flat", "rim", "plain"]))
def test_no_star_certificate_hides_a_crossing(seed, kind):
    """One vertex's open or closed fan of 3..9 faces: a ring going round twice, one ring vertex reflected
    through the centre (a fold), coplanar within ±1 ulp, a cylinder rim (flat half next to a side half pushed
    by ~1e-7), or plain random; sometimes with one face repeated reversed; far out with tiny features."""
    rng = np.random.default_rng(seed)
    k, closed = int(rng.integers(3, 10)), bool(rng.integers(2))
    n = k if closed else k + 1
    angle = (np.linspace(0, 4 * np.pi, n, endpoint=False) if kind == "twice"
             else np.sort(rng.uniform(0, 2 * np.pi, n)))
    radius = rng.uniform(0.5, 2, n)
    ring = np.c_[radius * np.cos(angle), radius * np.sin(angle),
                 rng.choice([0.0, 1.0, -1.0], n) * float(rng.choice([0.0, 1e-6, 1e-12, 1.0]))]
    if kind == "reflected":
        ring[int(rng.integers(n)), :2] *= -1
    elif kind == "ulp_flat":
        ring[:, 2] = rng.choice([0.0, 2.0 ** -52, -2.0 ** -52], n)
    elif kind == "rim":
        m = n // 2
        ring[:m, 2] = 0.0
        ring[m:, 2] = -1.0
        ring[m:, :2] = ring[m - 1, :2] * rng.uniform(0.9, 1.1, (n - m, 1)) + rng.normal(0, 1e-7, (n - m, 2))
    v = _placed(rng, np.vstack([np.zeros(3), ring]))
    f = np.array([[0, 1 + i, 1 + (i + 1) % n] for i in range(k)], dtype=np.int64)
    if rng.integers(4) == 0:
        f = np.vstack([f, f[int(rng.integers(k))][::-1]])
    _all_scans_agree(v, f)


@needs_accel
@settings(max_examples=40, **_SETTINGS)
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_no_star_certificate_hides_a_crossing_of_a_damaged_cylinder(seed):
    """A fan-capped cylinder (its rim vertices are the stars the convex certificate is for) with 1..3 vertices
    pushed by 1 ulp..1.5 along the axis, radially, next to another vertex or through the axis; faces shuffled,
    reversed or one repeated; far out."""
    rng = np.random.default_rng(seed)
    v, f = fan_capped_cylinder(int(rng.integers(3, 24)), float(rng.uniform(0.2, 2)), float(rng.uniform(0.01, 3)))
    v = v.copy()
    for _ in range(int(rng.integers(1, 4))):
        j = int(rng.integers(len(v)))
        d = float(rng.choice([2.0 ** -52, 1e-12, 1e-9, 1e-6, 0.3, 1.5]) * rng.choice([-1, 1]))
        mode = int(rng.integers(4))
        if mode == 0:
            v[j, 2] += d
        elif mode == 1:
            v[j, :2] *= 1 + d
        elif mode == 2:
            v[j] = v[int(rng.integers(len(v)))] + d
        else:
            v[j, :2] = -v[j, :2] * abs(d)
    f = f[rng.permutation(len(f))]
    if rng.integers(3) == 0:
        f = f[:, ::-1].copy() if rng.integers(2) else np.vstack([f, f[:1]])
    _all_scans_agree(_placed(rng, v), f)


# ------------------------------------------------------------------------------------- island rule
def _dome_on_a_ring(mode: str, curvature: float, rb: float, depth: float, up: bool, n: int, wider: float) -> str | None:
    """A dome or dimple ``±depth·rb (1 − r²/rb²)`` taken whole (every top face whose centroid is within ``cut``
    of the axis removed: ``rb`` plus a cell and ``wider`` of what is left, or the review's 0.5696 for ``wider``
    0) from a grid surface whose ring round it is a bowl, saddle or ripple of amplitude ``curvature``; judged with
    ``repair=True`` against the exact rational truth: ``None`` when refused or an estimate whose bounds hold."""
    base = {"bowl": lambda x, y: curvature * (x * x + y * y), "saddle": lambda x, y: curvature * (x * x - y * y),
            "ripple": lambda x, y: curvature * np.sin(7 * x) * np.cos(5 * y)}[mode]
    height = (1.0 if up else -1.0) * depth * rb
    cell = 2.0 / n
    cut = 0.5696 if wider == 0.0 else rb + cell + wider * max(0.0, 1.0 - 4.0 * cell - rb)
    v, f, top = _heightfield(lambda x, y: base(x, y) + height * np.clip(1 - (x * x + y * y) / rb ** 2, 0, None), n)
    keep = ~(top & (np.linalg.norm(v[f].mean(1)[:, :2], axis=1) < cut))
    truth = G.rational_moments([tuple(p) for p in v], [list(t) for t in f])
    return G.silent_reason(v, f[keep], truth, repair=True)


@settings(max_examples=6, **_SETTINGS)
@given(mode=st.sampled_from(["bowl", "saddle", "ripple"]), exponent=st.floats(-5.0, -3.0),
       rb=st.floats(0.2, 0.6), depth=st.floats(0.02, 0.8), up=st.booleans(), n=st.integers(10, 20),
       wider=st.floats(0.01, 1.0))
@example(mode="bowl", exponent=float(np.log10(4.24e-4)), rb=0.4166, depth=0.01262 / 0.4166, up=False, n=14,
         wider=0.0)
def test_a_dome_taken_whole_from_a_nearly_flat_ring_keeps_its_bound(mode, exponent, rb, depth, up, n, wider):
    """Review 14's finding, fixed by the level-ring rule (``hole_bounds.flat_islands``, ``level_rings``): a dome
    or dimple taken whole from a ring curved by 1e-5..1e-3 (every face at the rim within 1.1° of the rim's plane,
    though not flat enough for the island test against the largest face's plane) keeps the uncut ball, never
    ``bend``'s or the ``flat`` slab's bound of the ring's near-zero slope.  The example is the review's: a dimple in
    a bowl curved by 4.24e-4, stated ±3.66e-5 of the mass while 8.7e-4 off before the rule; generated draws (log-
    uniform curvature) found 5 of 30 outside their bounds before it, 0 of 60 after."""
    assert _dome_on_a_ring(mode, 10.0 ** exponent, rb, depth, up, n, wider) is None


@pytest.mark.xfail(strict=True, reason=(
    "review14 finding, open (bend's stated limit, hole_assumptions.BEND fails_for): a dome taken whole from a "
    "ring visibly curved (every face at the rim within the level rule's 1.1° fails, so bend speaks) is bounded by "
    "the ring's slope, and the dome is steeper: a dimple 0.76 of its radius deep in a bowl 0.032 (x²+y²) "
    "(ring slope 0.054) was stated ±0.8 % while 6.6 % off; of 60 generated rings curved 1e-5..1e-1 (seeds "
    "100-159, untuned) 6 still missed after the level rule (16 before): 5 under bend with ring slopes 0.04..0.14, "
    "1 under a flat slab beside a quadric fill. The file "
    "cannot tell such a feature from the surface continuing across the hole; the answer names bend."))
@settings(max_examples=4, **_SETTINGS)
@given(mode=st.sampled_from(["bowl", "saddle", "ripple"]), exponent=st.floats(-3.0, -1.5),
       rb=st.floats(0.2, 0.6), depth=st.floats(0.02, 0.8), up=st.booleans(), n=st.integers(10, 20),
       wider=st.floats(0.01, 1.0))
@example(mode="bowl", exponent=float(np.log10(0.03218758983880552)), rb=0.5828712637729698,
         depth=0.7616686335512085, up=False, n=12, wider=0.5983298172038957)
def test_a_dome_taken_whole_from_a_visibly_curved_ring_keeps_its_bound(mode, exponent, rb, depth, up, n, wider):
    """As above on rings curved by 1e-3..3e-2, where some face at the rim stands more than 1.1° off the rim's
    plane: the answer is refused, or an estimate whose bounds hold."""
    assert _dome_on_a_ring(mode, 10.0 ** exponent, rb, depth, up, n, wider) is None


# ------------------------------------------------------------------------------------- Hunter witness
def _box_union_truth(boxes: list[tuple[np.ndarray, np.ndarray]]) -> G.RationalTruth:
    """Exact moments of the union of axis-aligned boxes ``(lo, hi)`` (dyadic corners): the cells of the grid
    of all their planes, each kept when its centre is in some box, integrated in rationals."""
    cuts = [sorted({Fraction(float(b[s][a])) for b in boxes for s in (0, 1)}) for a in range(3)]
    m0, m1 = Fraction(0), [Fraction(0)] * 3
    m2 = [[Fraction(0)] * 3 for _ in range(3)]
    for ix in range(len(cuts[0]) - 1):
        for iy in range(len(cuts[1]) - 1):
            for iz in range(len(cuts[2]) - 1):
                lo = (cuts[0][ix], cuts[1][iy], cuts[2][iz])
                hi = (cuts[0][ix + 1], cuts[1][iy + 1], cuts[2][iz + 1])
                mid = [(a + b) / 2 for a, b in zip(lo, hi)]
                if not any(all(Fraction(float(b[0][a])) <= mid[a] <= Fraction(float(b[1][a])) for a in range(3))
                           for b in boxes):
                    continue
                d = [b - a for a, b in zip(lo, hi)]
                vol = d[0] * d[1] * d[2]
                m0 += vol
                m1 = [m1[a] + vol * mid[a] for a in range(3)]
                m2 = [[m2[a][b] + vol * (mid[a] * mid[b] + (d[a] ** 2 / 12 if a == b else 0)) for b in range(3)]
                      for a in range(3)]
    c = [x / m0 for x in m1]
    cov = [[m2[a][b] - m0 * c[a] * c[b] for b in range(3)] for a in range(3)]
    trace = cov[0][0] + cov[1][1] + cov[2][2]
    inertia = np.array([[float((trace if a == b else 0) - cov[a][b]) for b in range(3)] for a in range(3)])
    return G.RationalTruth(float(m0), np.array([float(x) for x in c]), inertia)


def _boxes(rng: np.random.Generator, shape: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Three to five boxes with corners on a 1/64 grid overlapping as a ``chain``, a ``star`` (one box meeting
    every other), a ``cycle``, or touching face to face (``touch``: a staircase; ``row``: in a row, other
    sizes)."""
    k, q = int(rng.integers(3, 6)), 1 / 64
    boxes = []
    for i in range(k):
        if shape in ("chain", "row"):
            x0 = i * (0.75 if shape == "chain" else 1.0) + (rng.integers(-4, 5) * q if shape == "chain" else 0)
            lo = np.array([x0, rng.integers(-8, 8) * q, rng.integers(-8, 8) * q])
            hi = lo + np.array([1.0, 1 + rng.integers(0, 16) * q, 1 + rng.integers(0, 16) * q])
        elif shape == "star":
            lo, hi = ((np.zeros(3), np.full(3, 2.0)) if i == 0 else
                      (lambda lo: (lo, lo + rng.integers(24, 80, 3) * q))(rng.integers(-48, 112, 3) * q))
            if i and np.all(lo >= 0) and np.all(hi <= 2.0):       # poking out: a box inside is a cavity (R4)
                lo, hi = lo - np.array([lo[0] + 0.25, 0, 0]), hi - np.array([lo[0] + 0.25, 0, 0])
        elif shape == "cycle":
            t = 2 * np.pi * i / k
            c = np.round(np.array([np.cos(t), np.sin(t), 0.0]) * 1.2 / q) * q
            lo, hi = c - 0.75, c + 0.75
        else:
            lo = np.array([i * 1.0, 0, 0]) if i % 2 == 0 else np.array([(i - 1) * 1.0, 1.0, 0])
            hi = lo + 1.0
        boxes.append((np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)))
    return boxes


WITNESS_NOTES = ("spanning tree", "each pair of them")


@settings(max_examples=45, **_SETTINGS)
@given(seed=st.integers(0, 2 ** 32 - 1), shape=st.sampled_from(["chain", "star", "cycle", "touch", "row"]),
       size=st.sampled_from([1.0, 1000.0]), copy=st.booleans())
def test_unions_of_three_or_more_boxes_are_honest_and_not_demoted_by_the_witness(seed, shape, size, copy):
    """Three to five boxes overlapping as a chain, star or cycle, or touching face to face, 1 or 1,000 m across,
    axis-aligned or turned, near or far out (a turned unit box at most 1e6 m out unless the boxes only touch: the
    rounding of its corners 6e7 m out moves its volume by ~1e-8, past the judge); with ``copy`` (overlapping
    shapes) the first box also listed turned by 1e-13..1e-10 rad about its centre (session 14's near copies; the
    union moves by < 1e-10 of its volume): never a silent wrong, and never ``unverified`` by the
    Hunter/Bonferroni witness while the numbers are right (a needless demotion)."""
    from scipy.spatial.transform import Rotation

    from inertia_tool import mass_properties
    from inertia_tool.errors import InertiaToolError

    rng = np.random.default_rng(seed)
    boxes = [(lo * size, hi * size) for lo, hi in _boxes(rng, shape)]
    truth = _box_union_truth(boxes)
    turned = bool(rng.integers(3))
    turn = random_rotation(rng) if turned else np.eye(3)
    touching = shape in ("touch", "row")
    far = [0.0, 1e3, 1e6] + ([6e7] if touching or not turned or size >= 1000 else [])
    shift = float(rng.choice(far)) * rng.choice([-1.0, 1.0], 3) * rng.integers(0, 2, 3)
    pieces = [box(tuple(hi - lo), tuple((lo + hi) / 2), subdivide=int(rng.integers(0, 2))) for lo, hi in boxes]
    if copy and not touching:
        centre = (boxes[0][0] + boxes[0][1]) / 2
        tiny = Rotation.from_rotvec(10 ** rng.uniform(-13, -10) * random_rotation(rng)[0]).as_matrix()
        pieces.append(((pieces[0][0] - centre) @ tiny.T + centre, pieces[0][1]))
    pieces = [(pv @ turn.T + shift, pf) for pv, pf in pieces]
    if turned and touching and size == 1.0:    # interiors apart: the exact sum of the boxes as rounded is the truth
        t = truth_from_pieces([(1, p) for p in pieces])
        truth = G.RationalTruth(t.volume, t.centroid, t.inertia)
    else:
        truth = G.RationalTruth(truth.volume, turn @ truth.centroid + shift, turn @ truth.inertia @ turn.T)
    offsets = np.cumsum([0] + [len(pv) for pv, _ in pieces])
    v = np.concatenate([pv for pv, _ in pieces])
    f = np.concatenate([pf + o for (_, pf), o in zip(pieces, offsets)])
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((v, f), density=1.0)
    except InertiaToolError:
        return                                              # a refusal is honest
    label = props.mesh.certificate.kind if props.mesh.certificate is not None else props.mesh.method
    verdict = G.judge_numbers(label, props.mass, props.center_of_mass, props.inertia, props.mesh.uncertainty,
                              truth, diag)
    assert not verdict.silent, (shape, turned, shift, label, verdict.wrong)
    right = G.judge_numbers("exact", props.mass, props.center_of_mass, props.inertia, None, truth, diag).wrong is None
    witnessed = [note for note in props.mesh.notes if any(w in note for w in WITNESS_NOTES)]
    assert not (right and label == "unverified" and witnessed), (shape, turned, shift, witnessed)
