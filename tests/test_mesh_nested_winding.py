"""R4 where the file's winding stands (session 16, the team's decision on issue 21): the solid is where the winding
number is at least one, and shells are turned for their nesting depth only where the file's own winding is evidently
wrong (some region of the nest has winding ≤ −1).  Nests of axis-aligned boxes, free inside their container or flush
with it, each box wound either way, judged by exact cell counts that know nothing of the pipeline (the corners lie on
a quarter grid, so the winding number is a sum of box indicators on whole cells: ``test_mesh_kept_cavities``).

The stated rule, per nest (a box inside no other, with every box inside it): where every cell of the nest has
``w ≥ 0`` the solid there is ``{w ≥ 1}``; otherwise R4's depth reading, the cells inside an odd number of boxes.  An
answer labelled ``exact``, ``united`` or ``estimate`` must be that solid (to 1e-9; an estimate within its stated
bounds); where every nest's winding stands and depth would read a box wound outward as a cavity, the answer must be
proven, ``exact`` (``united`` where a cavity kept is flush with its body's face: R6), with the check
``interior-shells`` (the shells with winding at least one on both sides left out), and its warning must give the
depth reading's volume exactly (six digits).  Before session 16, two nested boxes wound outward were the parity
solid, ``exact``.

Session 17 (nest17): the rule per nest.  A nest none of whose shells crosses any shell is decided by the rule even
where other shells of the file cross (before, one crossing pair anywhere kept the depth reading for every nest); the
answer's certificate is the weaker of its parts (a crossing pair united: ``united``).  R0's count with the region
windings decides a body listed twice round a cavity listed once without a boolean (``exact``), and a forced
estimate after a refused boolean names the shells left out.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from adversary_solids import box as solid_box
from adversary_solids import certificate_label, icosphere
from adversary_solids import concat as join
from adversary_solids import flipped as turned_over
from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError
from inertia_tool.mesh import classify, policy
from inertia_tool.mesh.classify import shell_nesting_or_none
from test_mesh_kept_cavities import H, _by_rule, _mesh, _moments, _winding


def _children(rng, lo, hi, depth, boxes):
    """Up to two boxes inside ``[lo, hi)`` (cells; side by side along x with a cell between them), each free or
    flush with the container on any side, never equal to it, and their own children, to depth 3."""
    if depth >= 3 or np.min(hi - lo) < 2:
        return
    count = int(rng.integers(0, 3)) if depth else int(rng.integers(1, 3))
    if count == 2 and hi[0] - lo[0] >= 5:
        mid = lo[0] + (hi[0] - lo[0] - 1) // 2
        parts = [(lo, np.array([mid, hi[1], hi[2]])), (np.array([mid + 1, lo[1], lo[2]]), hi)]
    elif count:
        parts = [(lo, hi)]
    else:
        parts = []
    for plo, phi in parts:
        clo = np.array([int(rng.integers(plo[k], phi[k])) if rng.random() < 0.5 else int(plo[k]) for k in range(3)])
        chi = np.array([int(rng.integers(clo[k] + 1, phi[k] + 1)) if rng.random() < 0.5 else int(phi[k])
                        for k in range(3)])
        if np.array_equal(clo, lo) and np.array_equal(chi, hi):
            continue                                   # a copy of its container is R0's, not a nest
        boxes.append((clo, chi, 1 if rng.random() < 0.5 else -1))
        _children(rng, clo, chi, depth + 1, boxes)


def _draw_nests(rng):
    """``[(lo, hi, sign)]`` in cells: one or two nests apart, each a box with boxes inside it to depth 3."""
    boxes = []
    for x0 in (-10, 3)[:int(rng.integers(1, 3))]:
        lo = np.array([x0, -6, -6]) + rng.integers(0, 2, size=3)
        hi = lo + rng.integers(4, 9, size=3)
        boxes.append((lo, hi, 1 if rng.random() < 0.7 else -1))
        _children(rng, lo, hi, 1, boxes)
    return boxes


def _answer(boxes, mesh=None):
    v, f = _mesh(boxes) if mesh is None else mesh
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            props = mass_properties((v, f), density=1.0)
        except InvalidMeshError:
            return None, []
    return props, [str(w.message) for w in caught]


def _matches(props, truth, diag):
    volume, centroid, inertia = truth
    if certificate_label(props.mesh) == "estimate":
        u = props.mesh.uncertainty
        return (abs(props.mass - volume) <= u.mass * props.mass * (1 + 1e-9)
                and np.linalg.norm(props.center_of_mass - centroid) <= u.center_of_mass + 1e-9 * diag
                and np.linalg.norm(props.inertia - inertia) <= u.inertia * np.linalg.norm(props.inertia) * (1 + 1e-9))
    return (abs(props.mass - volume) <= 1e-9 * volume
            and np.linalg.norm(props.center_of_mass - centroid) <= 1e-9 * diag
            and np.linalg.norm(props.inertia - inertia) <= 1e-8 * np.linalg.norm(inertia))


def _check(boxes, mesh=None):
    """The stated rule on ``boxes`` (cells), the file written as ``mesh`` (default: each box's 12 faces)."""
    solid, parity, stands, misread = _by_rule(boxes)
    truth = _moments(solid)
    props, said = _answer(boxes, mesh)
    if stands and misread:
        assert props is not None, "refused where the file's winding stands"
        # exact; united where a cavity kept is flush with its body's face (touching up to rounding, R6)
        assert certificate_label(props.mesh) in ("exact", "united"), props.mesh.certificate
        assert "interior-shells" in props.mesh.certificate.checks
        named = [re.search(r"read by nesting depth as [^:]*: ([0-9.eE+-]+) m³", s) for s in said]
        named = [float(m.group(1)) for m in named if m]
        assert named, said
        depth_volume = float(np.count_nonzero(parity)) * H ** 3
        assert all(abs(x - depth_volume) <= 1e-5 * depth_volume for x in named), (named, depth_volume)
    if props is None or truth is None or certificate_label(props.mesh) not in ("exact", "united", "estimate"):
        return
    diag = float(np.linalg.norm(np.ptp((_mesh(boxes) if mesh is None else mesh)[0], axis=0)))
    assert _matches(props, truth, diag), (certificate_label(props.mesh), props.mass, truth[0])


def test_two_nested_boxes_wound_outward_are_the_outer_box():
    """The issue's case (trimesh boxes 2 and 1 concatenated, both outward): winding 1 and 2, never below 0, so the
    file's winding stands: the outer box, 8 m³, ``exact`` (before: 7 m³, the parity solid, ``exact``)."""
    boxes = [(np.array([-4, -4, -4]), np.array([4, 4, 4]), 1), (np.array([-2, -2, -2]), np.array([2, 2, 2]), 1)]
    props, said = _answer(boxes)
    assert certificate_label(props.mesh) == "exact"
    assert abs(props.mass - 8.0) <= 1e-12
    assert any("7 m³, 12.5 % less mass" in s for s in said), said
    _check(boxes)


def test_a_hollow_sphere_with_its_outer_shell_inward_is_still_hollow():
    """The issue's hollow sphere whose outer shell is wound inward while its cavity is right: winding −1 and −2,
    evidently wrong, so R4's depth applies as before: the hollow sphere (4/3 π (1 − 0.8³) ≈ 2.04 for true spheres),
    not the outer sphere (≈ 4.18)."""
    outer, inner = icosphere(1.0, 3), icosphere(0.8, 3)
    v, f = join(turned_over(outer), turned_over(inner))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((v, f), density=1.0)
    from adversary_solids import float_moments
    hollow = float_moments(*outer)[0] - float_moments(*inner)[0]
    assert certificate_label(props.mesh) == "exact"
    assert abs(props.volume - hollow) <= 1e-12 * hollow
    assert 2.0 < props.volume < 2.1


def test_each_nest_is_read_by_its_own_rule():
    """Two nests side by side: one wound outward twice (stands: the outer box), one whose outer box is wound inward
    (winding −1: evidently wrong, R4's depth reading). Each nest read by its own rule."""
    boxes = [(np.array([-10, -4, -4]), np.array([-4, 2, 2]), 1), (np.array([-9, -3, -3]), np.array([-6, 0, 0]), 1),
             (np.array([3, -4, -4]), np.array([9, 2, 2]), -1), (np.array([4, -3, -3]), np.array([7, 0, 0]), -1)]
    _check(boxes)
    props, _ = _answer(boxes)
    assert abs(props.mass - (216 + 216 - 27) * H ** 3) <= 1e-12


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_nested_boxes_wound_either_way_follow_the_stated_rule(seed):
    """Nests of boxes, free or flush, wound at random: the answer is the stated rule's solid by exact cell counts
    (or refused / ``unverified``); exact, with the depth reading's volume named, wherever every nest stands and
    depth would misread an outward box."""
    _check(_draw_nests(np.random.default_rng(seed)))


def test_a_body_listed_twice_around_a_cavity_listed_once_is_never_the_cavity_cut():
    """R0 counts a shell listed twice twice (session 15): a 2 m box listed twice around a 0.5 m cavity listed once
    has winding 2 − 1 = 1 in the cavity, material, so {w ≥ 1} is the box whole, 8 m³.  R4c read it so but, no shell
    touching another, the boolean never ran and the summed integral was given: ``exact`` 7.875 m³ (found in session
    16).  Now the boolean forms it (no face crosses, so it is not proven: ``unverified``), or it is proven exact."""
    lo, hi = np.array([-4, -4, -4]), np.array([4, 4, 4])
    outer = _mesh([(lo, hi, 1)])
    cavity = _mesh([(np.array([-1, -1, -1]), np.array([1, 1, 1]), -1)])
    v, f = join(outer, outer, cavity)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((v, f), density=1.0)
    assert abs(props.mass - 8.0) <= 1e-9 * 8.0, (props.mass, props.mesh.certificate)
    # session 17: R0's count and the region windings decide it with no crossing anywhere: exact, no boolean (before:
    # the boolean's union, ``unverified``)
    assert certificate_label(props.mesh) == "exact", props.mesh.certificate
    assert "interior-shells" in props.mesh.certificate.checks
    assert any("7.875 m³, 1.56 % less mass" in n for n in props.mesh.notes), props.mesh.notes


def _crossing_pair(rng):
    """Two boxes wound outward whose faces cross (at x ≥ 3, apart from the nest of :func:`_nest_apart`)."""
    lo = np.array([3, -6, -6]) + rng.integers(0, 2, size=3)
    hi = lo + rng.integers(3, 6, size=3)
    shift = np.array([int(rng.integers(1, hi[0] - lo[0])), int(rng.integers(1, 3)), int(rng.integers(-2, 0))])
    return [(lo, hi, 1), (lo + shift, hi + shift, 1)]


def _nest_apart(rng):
    """One nest at x < 0 (a box with boxes inside it to depth 3, free or flush, each wound either way)."""
    lo = np.array([-11, -6, -6]) + rng.integers(0, 2, size=3)
    hi = lo + rng.integers(4, 9, size=3)
    boxes = [(lo, hi, 1 if rng.random() < 0.7 else -1)]
    _children(rng, lo, hi, 1, boxes)
    return boxes


def _check_beside_crossing(boxes, n_nest):
    """The stated rule beside a crossing pair (``boxes[n_nest:]``): the answer is ``{w ≥ 1}`` where the nest stands,
    its depth reading where it does not (by exact cell counts, :func:`_by_rule`); where the nest stands and depth
    would misread an outward box, ``united`` (the crossing pair's union: the weaker part) with ``interior-shells``,
    and the warning names the depth reading of the nest, the crossing pair as given, exactly."""
    solid, parity, stands, misread = _by_rule(boxes)
    nest_cells = _winding(boxes[:1], [1]) > 0
    props, said = _answer(boxes)
    if stands and misread:
        assert props is not None, "refused where the nest's winding stands"
        assert certificate_label(props.mesh) == "united", props.mesh.certificate
        assert "interior-shells" in props.mesh.certificate.checks
        named = [re.search(r"read by nesting depth as [^:]*: ([0-9.eE+-]+) m³", s) for s in said]
        named = [float(m.group(1)) for m in named if m]
        depth_volume = float(np.count_nonzero(solid & ~nest_cells) + np.count_nonzero(parity & nest_cells)) * H ** 3
        assert named and all(abs(x - depth_volume) <= 1e-5 * depth_volume for x in named), (named, depth_volume)
        assert any(f"the other {len(boxes) - n_nest} shells, in nests with crossing shells" in s for s in said), said
    truth = _moments(solid)
    if props is None or truth is None or certificate_label(props.mesh) not in ("exact", "united", "estimate"):
        return
    diag = float(np.linalg.norm(np.ptp(_mesh(boxes)[0], axis=0)))
    assert _matches(props, truth, diag), (certificate_label(props.mesh), props.mass, truth[0])


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_a_nest_beside_crossing_boxes_follows_the_stated_rule(seed):
    """A nest wound either way, free or flush, beside two outward boxes that cross: the nest is read by its own rule
    (before session 17 the crossing pair kept R4's depth reading for it: the parity solid within a spanning
    estimate), the pair is united, and the whole is labelled by its weaker part."""
    rng = np.random.default_rng(seed)
    nest = _nest_apart(rng)
    _check_beside_crossing(nest + _crossing_pair(rng), len(nest))


def test_two_nested_outward_boxes_beside_crossing_boxes_are_the_outer_box():
    """The issue's nested outward boxes (8 and 1 m³... here 6³ and 3³ cells) beside two crossing outward boxes: the
    outer box and the pair's union, ``united`` with ``interior-shells`` (before: an estimate spanning the parity
    solid and the file's winding)."""
    boxes = [(np.array([-10, -4, -4]), np.array([-4, 2, 2]), 1), (np.array([-9, -3, -3]), np.array([-6, 0, 0]), 1),
             (np.array([3, -4, -4]), np.array([7, 0, 0]), 1), (np.array([5, -2, -2]), np.array([9, 2, 2]), 1)]
    _check_beside_crossing(boxes, 2)
    props, _ = _answer(boxes)
    assert abs(props.mass - (216 + 64 + 64 - 8) * H ** 3) <= 1e-12


def test_a_forced_estimate_names_the_shells_left_out():
    """A nest wound outward twice (the rule leaves the inner box out) beside two crossing outward boxes and an
    inward box crossing both and reaching out of both: R4c's boolean refuses (a void outside every body) and
    ``repair`` forces the winding-number estimate; its notes say which shell was left out and what the depth reading
    gives (before session 17 the estimate's notes did not), and its bounds hold ``{w ≥ 1}`` by exact cells."""
    boxes = [(np.array([-10, -4, -4]), np.array([-2, 4, 4]), 1), (np.array([-8, -2, -2]), np.array([-4, 2, 2]), 1),
             (np.array([2, -2, -2]), np.array([6, 2, 2]), 1), (np.array([4, -1, -1]), np.array([8, 3, 3]), 1),
             (np.array([3, -3, 0]), np.array([7, 4, 1]), -1)]
    v, f = _mesh(boxes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties((v, f), density=1.0, repair=True)
    assert certificate_label(props.mesh) == "estimate"
    assert any("1 shell with winding at least one on both sides left out" in n and "estimate of the shells kept" in n
               for n in props.mesh.notes), props.mesh.notes
    truth = _moments(_winding(boxes, [s for _, _, s in boxes]) >= 1)
    assert _matches(props, truth, float(np.linalg.norm(np.ptp(v, axis=0))))


def _nest_in_crossing_box(rng):
    """An outward box crossing another (at x ≥ 3), with a nest inside its part away from the other (free or flush
    with it, boxes to depth 3 wound either way): a sub-nest inside a nest with crossings (winding 1 just outside)."""
    lo = np.array([-11, -6, -6]) + rng.integers(0, 2, size=3)
    hi = np.array([int(rng.integers(4, 6)), int(lo[1] + rng.integers(5, 9)), int(lo[2] + rng.integers(5, 9))])
    other_lo = np.array([2, lo[1] + 1, lo[2] + 1])
    boxes = [(lo, hi, 1), (other_lo, other_lo + np.array([4, 3, 3]), 1)]
    _children(rng, lo, np.array([1, hi[1], hi[2]]), 1, boxes)
    return boxes


@settings(max_examples=20, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_a_nest_inside_a_crossing_box_follows_the_stated_rule_where_it_stands(seed):
    """A nest inside an outward box that crosses another: where no cell's winding is below 0, the answer is ``{w ≥ 1}``
    by exact cell counts (the sub-nest decided by the rule, the crossing pair united), ``united`` with
    ``interior-shells`` wherever depth would misread an outward box.  Where some cell is below 0 the nest is read by
    the other rules as before (not judged here: :func:`_by_rule` reads a crossing pair's overlap by parity)."""
    boxes = _nest_in_crossing_box(np.random.default_rng(seed))
    w = _winding(boxes, [s for _, _, s in boxes])
    if w.min() < 0:
        return
    solid, _, _, misread = _by_rule(boxes)
    props, _ = _answer(boxes)
    assert props is not None, "refused where the file's winding stands"
    if misread:
        assert certificate_label(props.mesh) == "united", props.mesh.certificate
        assert "interior-shells" in props.mesh.certificate.checks
    if certificate_label(props.mesh) in ("exact", "united", "estimate"):
        diag = float(np.linalg.norm(np.ptp(_mesh(boxes)[0], axis=0)))
        truth = _moments(w >= 1)
        assert _matches(props, truth, diag), (certificate_label(props.mesh), props.mass, truth[0])


def test_a_box_flush_with_its_container_on_five_faces_is_the_container():
    """Both wound outward, the inner box sharing five of its faces' planes with the outer one: every probe of the
    outer box lay on the inner one's surface, so it was undecided and the rule did not apply; R4 read the pair by
    depth, ``exact`` 0.546875 m³ (the container less the box) where ``{w ≥ 1}`` is the container, 3.828125 m³
    (found by session 17's judge beside a crossing pair).  Now the undecided shell is probed again without the shell
    within it: the container, ``exact`` with ``interior-shells``."""
    boxes = [(np.array([-10, -5, -6]), np.array([-3, 2, -1]), 1), (np.array([-10, -5, -6]), np.array([-3, 1, -1]), 1)]
    _check(boxes)
    props, _ = _answer(boxes)
    assert certificate_label(props.mesh) == "exact"
    assert abs(props.mass - 245 * H ** 3) <= 1e-12


# Session 18 (tidy18): a shell left undecided (every probe on another surface) keeps the rule only from the nests it
# may lie in.  The undecided shell drawn here: a slab whose two large faces (each triangle split in four, so that the
# eight probes tried all lie on them) rest flush on a box below and a box above, touching both from outside.

def _sandwich(lo, size, sign=1):
    """``[(lo, hi, sign)]`` in cells: a slab of ``size`` (its height the last) at ``lo`` and a box below and above
    it, each flush with a whole large face of the slab and one cell wider on every side; and the index of the slab."""
    lo, size = np.asarray(lo), np.asarray(size)
    slab = (lo, lo + size, sign)
    wide = np.array([1, 1, 0])
    below = (lo - wide - np.array([0, 0, 2]), lo + size * np.array([1, 1, 0]) + wide, 1)
    above = (lo + size * np.array([0, 0, 1]) - wide, lo + size + wide + np.array([0, 0, 2]), 1)
    return [slab, below, above], 0


def _mesh_with(boxes, split):
    """``_mesh(boxes)`` with the boxes ``split`` (indices) written with every triangle split in four, twice."""
    pieces = []
    for k, (lo, hi, sign) in enumerate(boxes):
        v, f = solid_box((hi - lo) * H, subdivide=2 if k in split else 0)
        piece = (v - v.min(axis=0) + lo * H, f)
        pieces.append(piece if sign > 0 else turned_over(piece))
    return join(*pieces)


def _undecided_shells(mesh):
    from inertia_tool.mesh.checks import shell_labels
    v, f = mesh
    labels, n = shell_labels(f, len(v))
    return np.asarray(shell_nesting_or_none(v, f, labels, n).undecided), labels


def test_the_sandwiched_slab_is_undecided():
    """The generator's premise: the slab's probes all lie on the boxes around it (else the tests below test
    nothing)."""
    sandwich, slab = _sandwich([4, -2, 0], [4, 4, 1])
    mesh = _mesh_with(sandwich, [slab])
    undecided, _ = _undecided_shells(mesh)
    assert undecided.tolist() == [True, False, False]


def test_a_slab_flush_between_two_boxes_inside_an_inward_box_is_a_cavity():
    """Found by this session's generator (draw 261, pre-existing): a slab flush between two boxes, all three wound
    outward inside a box wound inward (winding −1: evidently wrong, so R4's depth reading, the three cavities of a
    body written inside out).  The slab was left undecided (its probes on the boxes it touches from outside), so its
    own sign made it a body: ``united`` 9 cells more than the depth reading (and than any reading).  Now it is
    probed again past the shells it touches from outside, as past crossing partners: the depth reading."""
    sandwich, slab = _sandwich([5, -2, -1], [3, 3, 1])
    boxes = sandwich + [(np.array([2, -6, -6]), np.array([12, 6, 6]), -1)]
    mesh = _mesh_with(boxes, [slab])
    assert _undecided_shells(mesh)[0][slab]
    props, _ = _answer(boxes, mesh)
    parity = _winding(boxes, [1] * len(boxes)) % 2 == 1
    diag = float(np.linalg.norm(np.ptp(mesh[0], axis=0)))
    assert certificate_label(props.mesh) in ("exact", "united")
    assert _matches(props, _moments(parity), diag), (props.mass / H ** 3, np.count_nonzero(parity))


def test_past_max_reprobed_an_undecided_slab_in_an_inward_box_is_not_certified(monkeypatch):
    """The case above with no re-probing, as for the shells past ``MAX_REPROBED`` (16) undecided ones, or a probe that
    stays on a surface past every partner: the slab keeps its own sign (a body) while the box around it is turned
    by depth, 9 cells above the depth reading; before session 18 ``united`` (draws 210 and 245 of this session's
    judge, seed 1818, in that configuration; the same answer on ``efd46cb``).  The slab's box lies within the inward
    box's, so it may lie inside it: the answer rests on an unchecked reading and is ``unverified``, said in a note."""
    monkeypatch.setattr(classify, "MAX_REPROBED", 0)
    sandwich, slab = _sandwich([5, -2, -1], [3, 3, 1])
    boxes = sandwich + [(np.array([2, -6, -6]), np.array([12, 6, 6]), -1)]
    props, said = _answer(boxes, _mesh_with(boxes, [slab]))
    assert certificate_label(props.mesh) == "unverified", props.mesh.certificate
    assert any("1 shell whose probe points all lie on other surfaces may lie inside another shell" in n
               for n in props.mesh.notes), props.mesh.notes


def test_a_nest_beside_an_undecided_shell_follows_the_stated_rule(monkeypatch):
    """Two nested boxes wound outward beside the sandwiched slab: before session 18 the undecided slab kept the rule
    from the nest, and R4's depth reading (the outer box less the inner one) was certified ``exact``, 349 cells for
    the file's ``{w ≥ 1}`` = 376.  The nest's outer box does not hold the slab's box, so the nest is decided by the
    file's winding: ``exact`` with ``interior-shells``, 376 cells.  (The slab is probed again past the boxes it
    touches, up to ``MAX_REPROBED`` shells; none here, as for the shells past that many.)"""
    monkeypatch.setattr(classify, "MAX_REPROBED", 0)
    nest = [(np.array([-10, -2, -2]), np.array([-4, 4, 4]), 1), (np.array([-9, -1, -1]), np.array([-6, 2, 2]), 1)]
    sandwich, slab = _sandwich([4, -2, 0], [4, 4, 1])
    boxes = nest + sandwich
    mesh = _mesh_with(boxes, [len(nest) + slab])
    _check(boxes, mesh)
    props, _ = _answer(boxes, mesh)
    assert certificate_label(props.mesh) == "exact" and "interior-shells" in props.mesh.certificate.checks
    assert abs(props.mass - 376 * H ** 3) <= 1e-12


def test_a_nest_inside_an_undecided_shell_is_left_to_the_other_rules(monkeypatch):
    """An outward box inside a thick sandwiched slab (wound outward): the slab is undecided, so the box's nest is not
    decided by the rule (the other rules may give the slab its own sign, turning the winding round the box): R4's
    depth reading, the slab less the box, as before session 18, its note naming the file's winding (no re-probing,
    as past ``MAX_REPROBED`` undecided shells)."""
    monkeypatch.setattr(classify, "MAX_REPROBED", 0)
    sandwich, slab = _sandwich([2, -3, -1], [6, 6, 3])
    inner = (np.array([4, -1, 0]), np.array([6, 1, 1]), 1)
    boxes = sandwich + [inner]
    mesh = _mesh_with(boxes, [slab])
    undecided, _ = _undecided_shells(mesh)
    assert undecided[slab] and not undecided[3]
    props, said = _answer(boxes, mesh)
    assert "interior-shells" not in props.mesh.certificate.checks
    cells = np.count_nonzero(_winding(boxes, [1, 1, 1, 1]) % 2 == 1)
    assert abs(props.mass - cells * H ** 3) <= 1e-9 * props.mass, (props.mass, cells * H ** 3)
    assert any("wound outward lies wholly inside another body" in s for s in said), said


def _nest_near_sandwich(rng):
    """A nest (:func:`_nest_apart`, x < 0) and a sandwiched slab at x ≥ 3 wound either way, or, one time in three,
    the sandwich inside a large box at depth 0 (the slab then lies in that box's nest, which the rule must leave)."""
    nest = _nest_apart(rng)
    size = np.array([int(rng.integers(2, 5)), int(rng.integers(2, 5)), 1])
    sandwich, slab = _sandwich(np.array([5, -2, -1]) + rng.integers(0, 2, size=3), size,
                               1 if rng.random() < 0.7 else -1)
    boxes = nest + sandwich
    if rng.random() < 1 / 3:
        boxes.append((np.array([2, -6, -6]), np.array([12, 6, 6]), 1 if rng.random() < 0.7 else -1))
    return boxes, len(nest) + slab


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_nests_beside_an_undecided_shell_follow_the_stated_rule(seed):
    """A nest wound either way, free or flush, beside a sandwiched slab (undecided) wound either way: where the slab
    lies apart and no shell of the nest is undecided, the nest is read by the stated rule (exact cell counts,
    :func:`_check`: before session 18 the slab kept the rule from it).  Where the sandwich lies inside another box, or
    a box of the nest is undecided too (flush with others on its large faces), the rule does not decide the nest
    holding it: the answer is the rule's solid, or the depth reading in the box holding the sandwich, or ``{w ≥ 1}``
    of the file as wound (R4c's solid)."""
    rng = np.random.default_rng(seed)
    boxes, slab = _nest_near_sandwich(rng)
    mesh = _mesh_with(boxes, [slab])
    undecided, _ = _undecided_shells(mesh)
    with pytest.MonkeyPatch.context() as mp:
        if rng.random() < 0.5:          # the shells left undecided (as past MAX_REPROBED of them), or probed again
            mp.setattr(classify, "MAX_REPROBED", 0)
        if len(boxes) == slab + 3 and not undecided[:slab].any():   # the sandwich apart: the stated rule everywhere
            _check(boxes, mesh)
            return
        props, _ = _answer(boxes, mesh)
    if props is None or certificate_label(props.mesh) not in ("exact", "united", "estimate"):
        return
    solid, parity, _, _ = _by_rule(boxes)
    held = _winding(boxes[-1:], [1]) > 0 if len(boxes) > slab + 3 else np.zeros_like(solid)
    readings = [solid, (solid & ~held) | (parity & held), _winding(boxes, [s for _, _, s in boxes]) >= 1]
    diag = float(np.linalg.norm(np.ptp(mesh[0], axis=0)))
    truths = [t for t in map(_moments, readings) if t is not None]         # an empty reading matches no answer
    assert any(_matches(props, t, diag) for t in truths), (certificate_label(props.mesh), props.mass)


def _nest_roots_by_loop(shell, other, root):
    """The loop ``winding_stands`` ran before session 18 (the reference for :func:`policy.nest_roots`)."""
    n = len(root)
    found = np.full(n, -1, dtype=np.int64)
    found[np.flatnonzero(root)] = np.flatnonzero(root)
    for s, o in zip(shell.tolist(), other.tolist()):
        if root[o]:
            if found[s] not in (-1, o):
                return None
            found[s] = o
    return found


@settings(max_examples=300, deadline=None, derandomize=True)
@given(parents=st.lists(st.integers(-1, 30), min_size=1, max_size=30), extra=st.lists(
    st.tuples(st.integers(0, 29), st.integers(0, 29)), max_size=4), roots=st.lists(st.booleans(), min_size=30,
                                                                                   max_size=30))
def test_nest_roots_are_the_loops(parents, extra, roots):
    """``policy.nest_roots`` (whole-array) gives what the per-pair loop gave, on random forests of nests (each shell
    inside its parent's containers and its parent; ``-1`` or a later index: a shell at depth 0) with the outer
    shells drawn at random, plus a few stray pairs (a shell inside two outer shells: None from both)."""
    n = len(parents)
    containers = [[] for _ in range(n)]
    for k, p in enumerate(parents):
        if 0 <= p < k:
            containers[k] = containers[p] + [p]
    pairs = [(k, c) for k in range(n) for c in containers[k]] + [(a, b) for a, b in extra if a < n and b < n and a != b]
    rng = np.random.default_rng(len(pairs))
    pairs = [pairs[i] for i in rng.permutation(len(pairs))]
    shell = np.array([a for a, _ in pairs], dtype=np.int64)
    other = np.array([b for _, b in pairs], dtype=np.int64)
    root = np.array(roots[:n], dtype=bool)
    want, got = _nest_roots_by_loop(shell, other, root), policy.nest_roots(shell, other, root)
    assert (want is None and got is None) or np.array_equal(want, got), (want, got)


def test_pairs_without_drops_either_way_round():
    """``policy.pairs_without`` keeps order and drops a pair given either way round (the one helper of R4's crossing
    and copy filters)."""
    pairs = np.array([[0, 1], [2, 0], [1, 3], [3, 4], [0, 1]])
    drop = np.array([[1, 0], [4, 3]])
    assert policy.pairs_without(pairs, drop).tolist() == [[2, 0], [1, 3]]
    assert policy.pairs_without(pairs, np.zeros((0, 2), dtype=np.int64)).tolist() == pairs.tolist()
    assert policy.pairs_without(np.zeros((0, 2), dtype=np.int64), drop).shape == (0, 2)


# Which boxes hold which (R4): ``policy.boxes_holding`` is the one comparison of ``classify._maybe_inside`` and
# ``policy.may_hold_undecided``; the loops they ran before tidy19 are the references.

#: Coordinates with ties, signed zeros and neighbours one ulp apart: the comparison must be exact.
_CORNERS = st.sampled_from([-1.0, -0.0, 0.0, 5e-324, np.nextafter(1.0, 0.0), 1.0, np.nextafter(1.0, 2.0), 2.0])


def _maybe_inside_by_loop(boxes, unplaced, cap):
    """The loop ``classify._maybe_inside`` ran before tidy19: for each of the first ``cap`` undecided shells, is its
    box within another shell's; beyond ``cap``, each counted as inside."""
    lo, hi = boxes[:, 0], boxes[:, 1]
    count = 0
    for u in np.flatnonzero(unplaced)[:cap].tolist():
        held = np.all(lo <= lo[u], axis=1) & np.all(hi >= hi[u], axis=1)
        held[u] = False
        count += int(held.any())
    return count + max(0, int(np.count_nonzero(unplaced)) - cap)


def _may_hold_by_blocks(undecided, shell, other, boxes, block):
    """The numpy blocks ``policy.may_hold_undecided`` ran before tidy19 (a box holding its own shell's counted)."""
    found = undecided.copy()
    found[shell[found[other]]] = True
    lo, hi = boxes[:, 0], boxes[:, 1]
    ids = np.flatnonzero(undecided)
    step = max(1, block // max(1, len(lo)))
    for start in range(0, len(ids), step):
        u = ids[start:start + step]
        holds = np.all(lo[:, None] <= lo[None, u], axis=2) & np.all(hi[:, None] >= hi[None, u], axis=2)
        found |= holds.any(axis=1)
    return found


@st.composite
def _shell_boxes(draw):
    """Boxes of 1 to 12 shells (each an axis-aligned box mesh, possibly flat or a point), each undecided or not, a few
    ``(shell, container)`` pairs that place a shell and a few container pairs of ``may_hold_undecided``."""
    n = draw(st.integers(1, 12))
    corners = draw(st.lists(st.tuples(*[st.tuples(_CORNERS, _CORNERS)] * 3), min_size=n, max_size=n))
    boxes = np.array([[[min(a) for a in c], [max(a) for a in c]] for c in corners], dtype=np.float64)
    undecided = np.array(draw(st.lists(st.booleans(), min_size=n, max_size=n)), dtype=bool)
    pairs = st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=4)
    within = np.array(draw(pairs), dtype=np.int64).reshape(-1, 2)
    inside = np.array(draw(pairs), dtype=np.int64).reshape(-1, 2)
    return boxes, undecided, within, inside


@settings(max_examples=300, deadline=None, derandomize=True)
@given(drawn=_shell_boxes(), cap=st.integers(0, 13), block=st.integers(1, 200))
def test_boxes_holding_is_the_old_loops(drawn, cap, block):
    """``classify._maybe_inside`` and ``policy.may_hold_undecided``, both on ``policy.boxes_holding`` since tidy19,
    give what their own comparisons gave (the bounded loop, with ``MAX_WITHIN_PAIRS`` drawn; the blocks, with the
    block size drawn), on boxes of real box meshes whose corners tie, differ by one ulp or are signed zeros."""
    from unittest import mock

    from inertia_tool.mesh.nesting import Nesting

    boxes, undecided, within, inside = drawn
    n = len(boxes)
    faces = solid_box()[1]                             # corners in the order x, y, z from the lowest
    v = np.array([[b[i, 0], b[j, 1], b[k, 2]] for b in boxes for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    f = np.concatenate([faces + 8 * k for k in range(n)])
    labels = np.repeat(np.arange(n), 12)
    found = classify.shell_boxes(v, f, labels, n)
    assert np.array_equal(found, boxes)             # the corners exactly (no rounding through the centre)
    nest = Nesting(shell=inside[:, 0], other=inside[:, 1], winding=np.ones(len(inside), dtype=np.int64),
                   probes=np.zeros((n, 3)), undecided=undecided)
    unplaced = policy.undecided_shells(nest, within)
    with mock.patch.object(classify, "MAX_WITHIN_PAIRS", cap):
        assert classify._maybe_inside(nest, within, v, f, labels, n) == _maybe_inside_by_loop(boxes, unplaced, cap)
    got = policy.may_hold_undecided(undecided, inside[:, 0], inside[:, 1], boxes, block=block)
    assert np.array_equal(got, _may_hold_by_blocks(undecided, inside[:, 0], inside[:, 1], boxes, block))
    holding, held = policy.boxes_holding(boxes, np.arange(n), block=block)
    by_pair = np.array([[a != b and np.all(boxes[a, 0] <= boxes[b, 0]) and np.all(boxes[a, 1] >= boxes[b, 1])
                         for b in range(n)] for a in range(n)])
    assert np.array_equal(holding, by_pair.any(axis=1)) and np.array_equal(held, by_pair.any(axis=0))
