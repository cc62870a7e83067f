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


def _answer(boxes, repair: bool = False):
    """``(label, mass, warnings' texts)`` of the boxes' mesh (``"refused"`` and its message for an
    ``InvalidMeshError``)."""
    from test_mesh_kept_cavities import _mesh
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            props = mass_properties(_mesh(boxes), density=1.0, repair=repair)
        except InvalidMeshError as exc:
            return "refused", str(exc), [str(w.message) for w in caught]
    return certificate_label(props.mesh), props.mass, [str(w.message) for w in caught]


#: Session 14's N5 (``bench_kept_cavities.py --seed 1418`` case 327): an inward box V holding three outward boxes
#: that cross one another.
_N5_THREE = [([1, -4, 1], [4, 0, 3], 1), ([1, 1, -2], [4, 3, 0], 1), ([0, 1, -2], [4, 4, 0], -1),
             ([0, 1, -2], [1, 3, -1], 1), ([0, 2, -2], [2, 3, -1], 1)]
#: N5 again (seed 1508 case 322, reduced to three boxes): an inward box holding two outward boxes that cross.
_N5_TWO = [([-4, -2, 1], [-2, 0, 3], 1), ([-4, -2, -1], [-1, 1, 3], -1), ([-3, -1, 1], [-2, 1, 3], 1)]


@pytest.mark.parametrize("cells", [_N5_THREE, _N5_TWO], ids=["three-crossing-boxes", "two-crossing-boxes"])
@pytest.mark.parametrize("repair", [False, True])
def test_a_misread_reading_resting_on_a_turn_is_refused(cells, repair):
    """N5: R4 turned V (depth 0, wound inward: a body inside out) and the misread rule answered an estimate (48
    cells ±33 %; 36 cells ±33 % for the two) spanning two readings that both rest on that turn (the boxes as V's
    cavity, or as bodies united with V, which its note called "read by the file's winding").  The file's own
    winding inside V is −1 + 1 = 0, 1 only where boxes overlap: ``{w ≥ 1}`` is 26 cells (2 for the two), outside the
    bound.  Now a misread reading inside a shell R4 turned is read by the file's winding as it stands (R4c), which
    leaves V outside every body: refused with one line, with ``repair`` too (the grid's estimate would be of the
    surface turned as a whole, 0.412 m³ ±4.9 % for the two boxes' 0.03125)."""
    boxes = _boxes(cells)
    _assert_judged_right(boxes)
    label, message, _ = _answer(boxes, repair)
    assert label == "refused", (label, message)
    assert "\n" not in message and "does not say which it means" in message, message


def test_a_misread_reading_inside_an_inward_box_holds_its_bound():
    """N5's case as the judge sees it (``bench_kept_cavities.py --seed 1418`` case 327): right or refused."""
    _assert_judged_right(_boxes(_N5_THREE))


def test_a_misread_reading_inside_an_inward_box_two_crossing_boxes():
    """N5 again (seed 1508 case 322, reduced to three boxes), as the judge sees it: right or refused."""
    _assert_judged_right(_boxes(_N5_TWO))


#: Session 14's N6 (``bench_kept_cavities.py --seed 1418`` cases 538, 1180, 1441): an outward box listed twice
#: flush inside an inward box that crosses a body.
_N6 = [([-2, -4, -4], [3, -2, -1], 1), ([0, -2, -1], [5, 0, 1], 1), ([-1, -1, -1], [1, 0, 0], -1),
       ([-1, -1, -1], [0, 0, 0], 1), ([-1, -1, -1], [0, 0, 0], 1)]


def test_a_box_listed_twice_inside_a_void_keeps_the_files_winding():
    """N6: R0 counted the box listed twice once, so where the void covers it the answer had winding 1 − 1 = 0 while
    the file's is 1 − 1 + 1 = 1: ``united`` 49 cells (0.765625 m³), one cell short of ``{w ≥ 1}`` = 50.  The team's
    decision (session 15): a shell listed ``k`` times counts ``k`` times in the winding; R4c forms the solid
    counting it so (``union.winding_solid``).  The answer is now ``{w ≥ 1}`` exactly (labelled ``unverified``:
    the box touches the body beside it along edges only, where manifold3d's output meets itself)."""
    boxes = _boxes(_N6)
    _assert_judged_right(boxes)
    label, mass, _ = _answer(boxes)
    assert label != "refused", mass
    assert abs(mass - 50 * 0.25 ** 3) <= 1e-12, (label, mass)


def test_a_part_listed_twice_as_a_whole_answers_as_listed_once():
    """R0's common case, unchanged by counting with multiplicity: every shell listed twice (a hollow part and a
    second body, exported twice) has winding 2·w, and ``{2w ≥ 1} = {w ≥ 1}``: the same answer and label as the
    part listed once."""
    once = _boxes([([-4, -4, -4], [4, 4, 4], 1), ([-2, -2, -2], [2, 2, 2], -1), ([5, 0, 0], [7, 2, 2], 1)])
    label_once, mass_once, _ = _answer(once)
    label_twice, mass_twice, _ = _answer(once + once)
    assert (label_twice, mass_twice) == (label_once, mass_once)
    assert abs(mass_once - (512 - 64 + 8) * 0.25 ** 3) <= 1e-12


def test_a_box_listed_twice_inside_a_cavity_is_an_island_or_the_named_reading():
    """A box listed twice inside a body's cavity: wound outward, its winding counted twice is 1 − 1 + 2 = 2 and
    counted once 1, the same solid (an island; judged by the cell count).  Wound inward it is R4's void reading
    (N8): depth makes it an island (exact, 456 cells), and the warning names the file's winding reading, the box
    empty (1 − 1 − 2 = −2 there): 448 cells, 7 m³ (the judge's parity reading counts the two copies and leaves the
    box empty too, so it is not asked here)."""
    cells = [([-4, -4, -4], [4, 4, 4], 1), ([-2, -2, -2], [2, 2, 2], -1)]
    island = _boxes(cells + [([-1, -1, -1], [1, 1, 1], 1)] * 2)
    _assert_judged_right(island)
    assert _answer(island)[:2] == ("exact", 456 * 0.25 ** 3)
    label, mass, said = _answer(_boxes(cells + [([-1, -1, -1], [1, 1, 1], -1)] * 2))
    assert (label, mass) == ("exact", 456 * 0.25 ** 3)
    assert sum("the solid where the winding number is at least one: 7 m³" in w for w in said) == 1, said


def test_an_inward_shell_inside_a_cavity_names_the_files_winding_reading():
    """N8 (session 14's recount, ``bench_review11.py winding`` seed 1503 case 289, reduced): a void wound inward inside
    a cavity wound inward (depth 2) is flipped to an island by R4's depth rule and certified (exact 57 m³), where
    the file's winding there is 1 − 1 − 1 = −1 and ``{w ≥ 1}`` is 56 m³; the warning said only "1 of 3 shells are
    inside out ... flipped".  The depth reading is R4's stated rule; now its warning names the file's winding
    reading and its mass, by the same note as an outward shell inside a body (``policy.misread_message``)."""
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
    # as for an outward shell inside a body (R4's misread reading): one warning names the file's winding reading and
    # the mass it gives, the report's notes say the same, and the label is never ``united`` for the depth reading
    named = [str(w.message) for w in caught if "the solid where the winding number is at least one: 56 m³" in
             str(w.message)]
    assert len(named) == 1 and "flipped" in named[0], [str(w.message)[:200] for w in caught]
    assert any("56 m³, 1.75 % less mass" in note for note in props.mesh.notes), props.mesh.notes
    assert label == "exact" and props.mass == 57.0, (label, props.mass)
