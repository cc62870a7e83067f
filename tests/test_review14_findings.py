"""Session 14's count of issue 21, item 4 (zero silent wrong answers over >= 10,000 generated cases, on seeds
never run before): each silent wrong answer the benchmarks found, reduced to a reproducer.  A plain test where the
fix is in; a strict xfail with the diagnosis where it is not.  The counts are in ``docs/adversarial.md``
("Session 14: the count on new seeds").
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from adversary_solids import certificate_label, torus
from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError


def _torus_and_turned_copy() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``bench_near_copies.py 1405 40`` case 29: a torus 469 m across (16 × 8 segments), 6.9e7 m from the origin,
    and its copy turned by 2.0e-11 rad about its centre (corners moved by at most one ulp there, 7.5e-9 m): the
    copy first, the torus second, as the benchmark lists them.  Returns the two pieces' vertices, their faces, and
    the single torus's vertices."""
    v, f = torus(1.0, 0.3, 16, 8)
    v = np.asarray(v, dtype=np.float64) * 180.2085185579218
    f = np.asarray(f, dtype=np.int64)
    centre = v.mean(axis=0)
    turn = Rotation.from_rotvec([-1.8136667395982158e-11, 8.692561013851273e-12, -4.720258396602072e-13])
    w = centre + (v - centre) @ turn.as_matrix().T
    shift = np.array([-52231262.20575632, -36179685.55451535, -26185595.030930802])
    v, w = v + shift, w + shift
    return np.vstack([w, v]), np.vstack([f, f + len(v)]), v, f


def test_a_union_larger_than_hunters_bound_is_not_certified():
    """manifold3d's union of the torus and its turned copy came back 3,934 m³ (4.3e-4) larger than either piece,
    while its intersection of the two was right to 3e-11: certified ``united`` 9,125,577 m³ for a solid of
    9,121,643.5 m³ (+ at most its area times the 7.5e-9 m the copy moves, 5e-3 m³).  Bonferroni's lower bound
    (``unite._union_lost_volume``) only caught a union too small; for two bodies the union equals
    ``vol A + vol B − vol(A ∩ B)``, and for more, Hunter's spanning-tree bound caps it from above.  Now such a
    union is ``unverified``, with a note naming the volume gained; an answer labelled exact or united is right."""
    vertices, faces, single, single_faces = _torus_and_turned_copy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((vertices, faces), density=1.0)
        one = mass_properties((single, single_faces), density=1.0)
    label = certificate_label(props.mesh)
    # the truth lies between the torus's own volume and that plus its area times the largest move of a corner
    area = float(np.sum(np.linalg.norm(np.cross(single[single_faces[:, 1]] - single[single_faces[:, 0]],
                                                single[single_faces[:, 2]] - single[single_faces[:, 0]]),
                                       axis=1))) / 2
    move = float(np.abs(vertices[:len(single)] - single).max())
    inside = one.mass - 1e-9 * one.mass <= props.mass <= one.mass + area * move + 1e-9 * one.mass
    assert inside or label not in ("exact", "united", "estimate"), (label, props.mass, one.mass)
    if not inside:
        assert any("larger than the bodies' volumes less the volume shared along a spanning tree" in note
                   for note in props.mesh.notes), props.mesh.notes


def test_largest_tree_weight_is_the_maximum_spanning_tree():
    """Kruskal's forest against brute force over every subset of edges that is a forest (small graphs, random
    weights, some pairs left out as weight 0)."""
    from inertia_tool.mesh.unite import _largest_tree_weight
    rng = np.random.default_rng(14)
    for _ in range(60):
        n = int(rng.integers(1, 6))
        i, j = np.triu_indices(n, k=1)
        keep = rng.random(len(i)) < 0.7
        pairs = np.stack([i[keep], j[keep]], axis=1)
        weights = rng.random(len(pairs)) * (rng.random(len(pairs)) < 0.8)
        best = 0.0
        for mask in range(1 << len(pairs)):
            chosen = [k for k in range(len(pairs)) if mask >> k & 1]
            parent = list(range(n))

            def root(a: int) -> int:
                while parent[a] != a:
                    a = parent[a]
                return a

            forest = True
            for k in chosen:
                a, b = root(int(pairs[k][0])), root(int(pairs[k][1]))
                if a == b:
                    forest = False
                    break
                parent[a] = b
            if forest:
                best = max(best, float(sum(weights[chosen])))
        assert abs(_largest_tree_weight(n, pairs, weights) - best) <= 1e-12 * max(1.0, best)


def _kept_cavities_case_118() -> list[tuple[np.ndarray, np.ndarray, int]]:
    """``bench_kept_cavities.py --seed 1418`` case 118, reduced (cells of 0.25 m, ``(lo, hi, sign)``): two outward
    boxes one flush inside the other, a void crossing the inner one's face (so R4c, ``{w ≥ 1}`` as wound, is
    taken), and apart from them an inward box holding an outward box flush inside it."""
    cells = [([-4, 1, 1], [0, 4, 6], 1), ([-4, 0, 1], [1, 4, 6], 1), ([-3, 0, 3], [0, 2, 5], -1),
             ([-1, -4, -2], [2, -2, 0], 1), ([-1, -5, -2], [2, -1, 0], -1)]
    return [(np.array(lo), np.array(hi), sign) for lo, hi, sign in cells]


def _kept_cavities_case_1348() -> list[tuple[np.ndarray, np.ndarray, int]]:
    """``bench_kept_cavities.py --seed 1418`` case 1348: an outward box inside an inward box (flush on three faces),
    and a second inward box crossing the outward one.  The file's winding is at most 0 everywhere (no solid); R4c
    turned the outer inward box and kept the outward one: ``united`` 0.5 m³."""
    cells = [([-4, 0, 1], [-2, 2, 3], 1), ([-4, 0, 0], [-1, 3, 4], -1), ([-3, 0, 1], [-1, 2, 3], -1)]
    return [(np.array(lo), np.array(hi), sign) for lo, hi, sign in cells]


@pytest.mark.parametrize("case", [_kept_cavities_case_118, _kept_cavities_case_1348])
def test_r4c_does_not_turn_an_inward_box_and_keep_the_outward_box_it_holds(case):
    """R4c keeps the file's winding for shells inside others but still turned a body written inside out when it
    stood alone at depth 0; this one holds an outward box, whose own turn (to a cavity, by depth) R4c drops.
    Turning one and not the other united the two (24 cells), which is neither the file's winding (0: the outward
    box cancels the void around it) nor R4's depth reading (12: the box is the turned body's cavity): certified
    ``united`` 1.84375 m³ for ``{w ≥ 1}`` = 1.46875 (case 1348: ``united`` 0.5 m³ where the file has no solid).  Now
    an inward box at depth 0 is not turned while it holds a shell wound against its depth (which R4c keeps as
    wound); it then lies outside every body and R4c refuses, or with ``repair`` gives an estimate."""
    from test_mesh_kept_cavities import _mesh, _readings, _verdict
    boxes = case()
    label, wrong = _verdict(boxes)
    assert wrong is None, wrong
    v, f = _mesh(boxes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((v, f), density=1.0, repair=True)
    label = certificate_label(props.mesh)
    readings = _readings(boxes)
    # case 1348 has no solid as wound (no reading): its repair estimate (0.497 m³ ±12 %, the grid's winding number of
    # the shells as R4 turned them) is not judged here (session 14's report)
    if label in ("exact", "united", "estimate") and readings:
        bound = props.mesh.uncertainty.mass if label == "estimate" else 1e-9
        assert any(abs(props.mass - r[0]) <= bound * r[0] + 1e-12 for r in readings), \
            (label, props.mass, [r[0] for r in readings])


def _boxes(cells) -> list[tuple[np.ndarray, np.ndarray, int]]:
    return [(np.array(lo), np.array(hi), sign) for lo, hi, sign in cells]


def _assert_judged_right(boxes) -> None:
    """The kept-cavities judge (``test_mesh_kept_cavities._verdict``) finds no silent wrong in ``boxes``."""
    from test_mesh_kept_cavities import _verdict
    _, wrong = _verdict(boxes)
    assert wrong is None, wrong


def test_a_cavity_that_fills_its_body_is_refused_not_a_usage_error():
    """``bench_kept_cavities.py --seed 1418`` case 335, reduced: an inward box split exactly into two outward boxes
    inside it, and an outward box crossing them (faces touching up to rounding).  R6's "touching up to rounding"
    gave the summed integral with a body whose cavity is as large as it (0.125 and −0.125 m³), and ``combine``
    raised ``UsageError: Expected a positive total mass, got 0.0`` from ``mass_properties``.  Now a body whose
    shells enclose no material is refused with ``InvalidMeshError`` (one line; with or without ``repair``)."""
    from test_mesh_kept_cavities import _mesh
    boxes = _boxes([([-3, -4, 0], [-1, -2, 2], 1), ([-3, -5, 1], [-1, -1, 2], -1), ([-3, -3, 1], [-1, -1, 2], 1),
                    ([-3, -5, 1], [-1, -3, 2], 1)])
    for repair in (False, True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with pytest.raises(InvalidMeshError, match="enclose no material"):
                mass_properties(_mesh(boxes), density=1.0, repair=repair)


@pytest.mark.xfail(strict=True, reason=(
    "open (session 14, bench_kept_cavities seed 1418 case 327): an inward box V holding three outward boxes that "
    "cross one another. R4 turns V (depth 0, wound inward: a body inside out, InsideOutWarning) and the misread "
    "rule (policy.misread_nesting, certify.misread_reading) gives an estimate (48 cells +-33 %) spanning two "
    "readings that both rest on that turn: the three as one cavity of V (34 cells, R4's depth reading, inside the "
    "bound) or as bodies united with V (48), which its note calls 'read by the file's winding'. The file's own "
    "winding inside V is -1 + 1 = 0 (1 where two of the three overlap): {w >= 1} is 26 cells, outside the bound. "
    "The judge offers R4's depth reading only when no boxes cross. Decide: name the union reading truly and widen "
    "the bound to the file's winding, or refuse as in R4c (classify._holds); not done"))
def test_a_misread_reading_inside_an_inward_box_holds_its_bound():
    _assert_judged_right(_boxes([([1, -4, 1], [4, 0, 3], 1), ([1, 1, -2], [4, 3, 0], 1), ([0, 1, -2], [4, 4, 0], -1),
                                 ([0, 1, -2], [1, 3, -1], 1), ([0, 2, -2], [2, 3, -1], 1)]))


@pytest.mark.xfail(strict=True, reason=(
    "R0's stated policy (session 13: 'a shell with net multiplicity +-2 is counted once'), not the winding rule: "
    "an outward box listed twice flush inside an inward box is counted once (MeshResolvedWarning 'listed twice ... "
    "counted once'), so where the inward box covers it the answer has winding 1 - 1 = 0 while the file's is "
    "1 - 1 + 1 = 1. Certified united/exact 1 cell (1/64 m3) short of {w >= 1} in cases 538, 1180 and 1441 of "
    "bench_kept_cavities seed 1418. A decision for the team (count with multiplicity, or label such answers "
    "unverified), not changed here"))
def test_a_box_listed_twice_inside_a_void_keeps_the_files_winding():
    _assert_judged_right(_boxes([([-2, -4, -4], [3, -2, -1], 1), ([0, -2, -1], [5, 0, 1], 1),
                                 ([-1, -1, -1], [1, 0, 0], -1), ([-1, -1, -1], [0, 0, 0], 1),
                                 ([-1, -1, -1], [0, 0, 0], 1)]))


@pytest.mark.xfail(strict=True, reason=(
    "N5 again (session 14's recount on the final head, bench_kept_cavities seed 1508 case 322, reduced from 4 boxes "
    "to 3): an inward box V (36 cells) holding two outward boxes that cross (8 and 4 cells, 2 shared). R4 turns V "
    "(InsideOutWarning 'flipped') and the misread rule answers estimate 0.5625 m3 +-33 % (V's 36 cells: the two as "
    "bodies united with V, 'read by the file's winding'; or 26 as one cavity). The file's own winding is -1 inside V, "
    "0 in each box and 1 only where the two overlap: {w >= 1} is 2 cells (0.03125 m3), 18 times less, far outside "
    "the bound. Open with N5; not changed"))
def test_a_misread_reading_inside_an_inward_box_two_crossing_boxes():
    _assert_judged_right(_boxes([([-4, -2, 1], [-2, 0, 3], 1), ([-4, -2, -1], [-1, 1, 3], -1),
                                 ([-3, -1, 1], [-2, 1, 3], 1)]))


@pytest.mark.xfail(strict=True, reason=(
    "N8 (session 14's recount on the final head, bench_review11 winding seed 1503 case 289, reduced): a void wound "
    "inward inside a cavity wound inward (depth 2) is flipped to an island body by R4's depth rule and the answer "
    "certified (exact 57 m3 here; united 0.357914119619 m3 in the case, a 0.006 m icosphere void inside a 0.3 m "
    "one), where the file's winding there is 1 - 1 - 1 = -1 and {w >= 1} is 56 m3 (0.357913319675 m3). The depth "
    "reading is R4's stated rule, but the warning only says '1 of 3 shells are inside out ... flipped', while for "
    "an outward shell inside a body (the same rule) it names the file's winding reading and the mass it would give. "
    "Decide: name the reading in this warning too, or label such answers by both readings; not changed"))
def test_an_inward_shell_inside_a_cavity_names_the_files_winding_reading():
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    faces = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                      [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    # a body of 4 m, a cavity of 2 m inside it and a void of 1 m inside the cavity, both wound inward
    shells = [(cube * 4, faces), (cube * 2 + 1, faces[:, ::-1]), (cube + 1.5, faces[:, ::-1])]
    vertices = np.vstack([v for v, _ in shells])
    offsets = np.cumsum([0] + [len(v) for v, _ in shells[:-1]])
    all_faces = np.vstack([f + o for (_, f), o in zip(shells, offsets)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = mass_properties((vertices, all_faces), density=1.0)
    label = certificate_label(props.mesh)
    winding_solid = 64.0 - 8.0     # {w >= 1}: the void inside the cavity has winding -1
    if label in ("exact", "united") and abs(props.mass - winding_solid) > 1e-9 * winding_solid:
        assert any("winding" in str(w.message) for w in caught), [str(w.message)[:200] for w in caught]
