"""Adversarial solids: generated compositions checked against independent truths (tests/adversary_solids.py).

The rule: zero silent wrong answers.  Every result is within tolerance of the truth of the solid people mean
(volume 1e-9, centre of mass 1e-9 of the diagonal, inertia 1e-8, relative) when it is certified ``exact`` or
``united``, within its stated bounds when it is an ``estimate``, or refused with an ``InvalidMeshError``.
``benchmarks/bench_adversarial.py`` runs the same generator over ≥ 10,000 cases.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import adversary_solids as S


# ------------------------------------------------------------------------------------------ the oracles agree
@pytest.mark.parametrize("kind", ["disjoint", "touching_faces", "internal_wall", "nested", "shared_vertex_touch"])
def test_rational_truth_matches_manifold_union(kind):
    """Where the intended solid is a set of disjoint pieces, the exact rational integral and manifold3d's
    boolean of the same pieces agree (two independent truths)."""
    for seed in range(4):
        case = S.make_case(kind, np.random.default_rng([7, seed]))
        assert case.truth.source in ("fraction", "float")
    # build one disjoint pair and one nested pair directly so the pieces are at hand
    a = S.box([0.5, 0.75, 1.0])
    b = S.icosphere(0.3, 1)
    b = (b[0] + [2.0, 0, 0], b[1])
    exact = S.truth_from_pieces([(1, a), (1, b)])
    union = S.truth_from_manifold([a, b])
    assert abs(exact.volume - union.volume) <= 1e-12 * exact.volume
    assert np.allclose(exact.centroid, union.centroid, rtol=0, atol=1e-12)
    assert np.linalg.norm(exact.inertia - union.inertia) <= 1e-12 * np.linalg.norm(exact.inertia)
    inner = S.box([0.25, 0.25, 0.25])
    exact = S.truth_from_pieces([(1, a), (-1, inner)])
    hollow = S.truth_from_manifold([a], [inner])
    assert abs(exact.volume - hollow.volume) <= 1e-12 * exact.volume


def test_fraction_moments_of_a_box_closed_form():
    """A 1 × 2 × 4 box moved to (3, 5, 7): V = 8, centroid exact, Iₓₓ = V (b² + c²)/12."""
    from fractions import Fraction
    v, f = S.box([1.0, 2.0, 4.0], [3.0, 5.0, 7.0])
    t = S.truth_from_pieces([(1, (v, f))])
    assert t.volume == 8.0 and t.centroid.tolist() == [3.0, 5.0, 7.0]
    assert t.inertia[0, 0] == float(Fraction(8) * 20 / 12)
    assert t.inertia[1, 1] == float(Fraction(8) * 17 / 12) and t.inertia[0, 1] == 0.0


@pytest.mark.parametrize("height", [0.05, 0.2, 0.5])
def test_tube_truth_matches_monte_carlo(height):
    """The figure-eight's truth (surface integral less the halves' overlap formed by manifold3d) agrees with
    Monte Carlo over libigl's winding numbers within 5 standard errors; where the tube passes clear of itself
    it is the surface integral."""
    v, f, halves = S.tube_halves(height, 0.25, rings=32, sections=6)
    truth = S.truth_of_tube(v, f, halves)
    mc = S.monte_carlo(v, f, np.random.default_rng(3), 200_000)
    assert abs(truth.volume - mc.volume) <= 5 * mc.sigma_volume
    assert np.linalg.norm(truth.centroid - mc.centroid) <= 5 * np.sqrt(3) * mc.sigma_centroid
    surface = S.float_moments(v, f)[0]
    if height > 0.25:
        assert abs(truth.volume - surface) <= 1e-12 * surface
    else:
        assert surface > truth.volume * (1 + 1e-3)        # the crossing is counted twice by the surface integral


@pytest.mark.parametrize("kind", S.KINDS)
def test_generated_surfaces_are_closed(kind):
    """Every generated mesh is edge-balanced (each directed edge matched by its reverse): the cases test what
    the surface means, not whether it is closed."""
    for seed in range(3):
        case = S.make_case(kind, np.random.default_rng([11, seed]))
        e = np.concatenate([case.faces[:, [0, 1]], case.faces[:, [1, 2]], case.faces[:, [2, 0]]])
        key = e[:, 0] * (len(case.vertices) + 1) + e[:, 1]
        rev = e[:, 1] * (len(case.vertices) + 1) + e[:, 0]
        assert np.array_equal(np.sort(key), np.sort(rev)), case.recipe


# ------------------------------------------------------------------------------------------------ the rule
def _assert_honest(case, repair=False):
    verdict = S.judge(case, repair=repair)
    assert verdict.label != "crashed", f"{case.kind}: {case.recipe}\n  {verdict.wrong}"
    assert not S.silent(verdict), (f"silent wrong answer ({verdict.label}) on {case.kind}: {case.recipe}\n"
                                   f"  {verdict.wrong}")
    return verdict


#: Failure classes found by the generator and not fixed yet (each routed to the mesh-to-solid stage, each with
#: a strict-xfail reproducer below, which fails the suite as soon as the class is fixed so that it is removed
#: from here): name → (what of the recipe identifies a case of the class, what goes wrong).
OPEN_CLASSES: dict[str, tuple[str, str]] = {
}


def _open_class(case):
    return next((name for name, (mark, _) in OPEN_CLASSES.items() if mark in case.recipe), None)


@settings(max_examples=200, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(S.KINDS), seed=st.integers(0, 2 ** 32 - 1))
def test_no_silent_wrong_answer(kind, seed):
    """200 generated compositions (fixed sequence): each answer is proven and right, an estimate whose bounds
    hold, or a refusal.  A case of an open class (:data:`OPEN_CLASSES`) is held to the rule only when it is not
    wrong in the known way: its reproducer carries the failure."""
    case = S.make_case(kind, np.random.default_rng(seed))
    verdict = S.judge(case)
    assert verdict.label != "crashed", f"{case.kind}: {case.recipe}\n  {verdict.wrong}"
    if S.silent(verdict) and _open_class(case) is not None:
        return
    assert not S.silent(verdict), (f"silent wrong answer ({verdict.label}) on {case.kind}: {case.recipe}\n"
                                   f"  {verdict.wrong}")


# ------------------------------------------------------------------------ minimal reproducers (issue 21)
def _cube_and_turned_cube():
    """The issue's case: a unit cube and the same cube turned 30° about its body diagonal through the corner
    they share by index."""
    a = S.box([1.0, 1.0, 1.0], [0.5, 0.5, 0.5])
    rot = S._axis_rotation([1, 1, 1], np.pi / 6)
    b = (a[0] @ rot.T, a[1].copy())
    ia = int(np.argmin(a[0].sum(1)))        # the corner at the origin, on the axis
    b[0][ia] = a[0][ia]
    return S.Case("shared_vertex_overlap", *S._share(a, b, ia, ia), S.truth_from_manifold([a, b]),
                  "unit cube ∪ cube turned 30° about its diagonal, corner shared")


def _figure_eight():
    v, f, halves = S.tube_halves(0.05, 0.2, rings=32, sections=6)       # thinner than its bends: no local fold
    return S.Case("figure_eight", v, f, S.truth_of_tube(v, f, halves), "figure-eight tube crossing itself")


def test_tube_halves_are_the_tube():
    """The two halves are closed, and together have the tube's volume (their caps cancel)."""
    v, f, halves = S.tube_halves(0.1, 0.2, rings=36, sections=7)
    total = sum(S.float_moments(*h)[0] for h in halves)
    assert abs(total - S.float_moments(v, f)[0]) <= 1e-13 * total
    for h in halves:
        S.to_manifold(h)           # a valid manifold: closed, consistently wound


def _hollow_sphere(outer_outward, cavity_inward):
    """A hollow sphere wound four ways.  The solid by the rules (R4, session 16): where every region's winding is
    ≥ 0 the file's winding stands (both outward: winding 1 and 2, the outer sphere whole), else the depth reading
    (outer inward: winding −1 somewhere, the hollow sphere, as for the issue's inside-out skin)."""
    outer = S.icosphere(1.0, 2)
    inner = S.icosphere(0.6, 1)
    levels = [(1, outer), (-1, inner)]
    truth = S.truth_from_pieces(S.nest_pieces(levels, [outer_outward, not cavity_inward]))
    mesh = S.concat(outer if outer_outward else S.flipped(outer), S.flipped(inner) if cavity_inward else inner)
    return S.Case("nested", *mesh, truth, f"hollow sphere, outer {'out' if outer_outward else 'in'}ward, "
                                          f"cavity {'in' if cavity_inward else 'out'}ward")


def _duplicated_box():
    v, f = S.box([1.0, 1.0, 1.0])
    return S.Case("duplicated", v, np.concatenate([f, f]), S.truth_from_pieces([(1, (v, f))]),
                  "a box whose 12 faces appear twice (same vertex indices)")


def _touching_copies():
    a = S.box([1.0, 1.0, 1.0])
    b = S.box([1.0, 1.0, 1.0], [1.0, 0.25, 0.0], subdivide=1)
    return S.Case("touching_faces", *S.concat(a, b), S.truth_from_pieces([(1, a), (1, b)]),
                  "two unit boxes face to face, offset, one subdivided")


def _internal_wall():
    a = S.box([0.5, 1.0, 1.0], [-0.25, 0, 0])
    b = S.box([0.5, 1.0, 1.0], [0.25, 0, 0])
    return S.Case("internal_wall", *S.concat(a, b), S.truth_from_pieces([(1, a), (1, b)]),
                  "a unit box as two halves with a zero-thickness wall")


def _duplicated_hollow_box():
    outer = S.box([1.0, 1.0, 1.0])
    inner = S.box([0.5, 0.5, 0.5])
    truth = S.truth_from_pieces([(1, outer), (-1, inner)])
    one = S.concat(outer, S.flipped(inner))
    return S.Case("duplicated", *S.concat(one, one), truth,
                  "a hollow box (outward) with its cavity (inward), the whole twice (new vertex indices)")


def _flush_cavity():
    outer = S.box([1.0, 1.0, 1.0])
    cavity = S.box([0.5, 0.5, 0.5], [0.25, 0.0, 0.0])      # its +x face lies in the outer +x face
    return S.Case("flush_cavity", *S.concat(outer, S.flipped(cavity)), S.truth_from_manifold([outer], [cavity]),
                  "a unit box with a cavity (inward) flush with its +x face: a notch")


def _cavity_through_face(shift):
    outer = S.box([1.0, 1.0, 1.0])
    cavity = S.box([0.5, 0.5, 0.5], [shift, 0.0, 0.0])
    return S.Case("flush_cavity", *S.concat(outer, S.flipped(cavity)), S.truth_from_manifold([outer], [cavity]),
                  f"a unit box with a cavity (inward) centred at x = {shift}, poking through its +x face")


def _resting_core():
    outer = S.box([1.0, 1.0, 1.0])
    cavity = S.box([0.5, 0.5, 0.5])
    core = S.box([0.25, 0.25, 0.125], [0.0, 0.0, -0.1875])      # its bottom face on the cavity's floor
    rot = S._axis_rotation([1.0, 2.0, 3.0], 0.7)                  # turned: the contact is coplanar only to rounding
    outer, cavity, core = (S.moved(p, rot, np.zeros(3)) for p in (outer, cavity, core))
    return S.Case("flush_cavity", *S.concat(outer, S.flipped(cavity), core),
                  S.truth_from_pieces([(1, outer), (-1, cavity), (1, core)]),
                  "a unit box with a cube cavity, a small box resting on the cavity's floor, all turned 0.7 rad "
                  "about (1, 2, 3)")


def _far_thin_tetrahedron():
    body = S.box([1.0, 1.0, 1.0])
    length, thick = 50.0, 1e-9
    tet = np.array([[0, 0, 0], [0, length, 0], [0, 0, length], [thick, length / 3, length / 3]]) + [length, 0, 0]
    tf = S._outward_exactly(tet, np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]))
    return S.Case("sliver", *S.concat(body, (tet, tf)), S.truth_from_pieces([(1, body), (1, (tet, tf))]),
                  "a unit box and a closed tetrahedron 50 m across and 1e-9 m thin, 50 m away (volume 4e-7 m³)")


def _generated(kind, index, seed=21, n_kinds=15):
    """Case ``index`` of ``benchmarks/bench_adversarial.py --seed`` ``seed`` when the table had ``n_kinds`` kinds
    (its kind must be ``kind``; the case itself depends only on the kind, the seed and the index)."""
    case = S.make_case(kind, np.random.default_rng([seed, index]))
    assert S.KINDS[index % n_kinds] == kind
    return case


REPRODUCERS = {
    "overlap_box_sphere_washer": lambda: _generated("overlapping", 3290),
    "duplicated_torus_new_indices": lambda: _generated("duplicated", 3386),
    "cavity_floor_resting_core": _resting_core,
    "far_thin_tetrahedron": _far_thin_tetrahedron,
    "cavity_pokes_through_face": lambda: _cavity_through_face(0.3),
    "cavity_flush_but_rounded_out": lambda: _cavity_through_face(0.25 + 1e-12),
    "flush_cavity_notch": _flush_cavity,
    "duplicated_hollow_box": _duplicated_hollow_box,
    "cube_turned_about_diagonal_shares_corner": _cube_and_turned_cube,
    "figure_eight_tube": _figure_eight,
    "hollow_sphere_outer_inward": lambda: _hollow_sphere(False, True),
    "hollow_sphere_cavity_outward": lambda: _hollow_sphere(True, False),
    "hollow_sphere_both_wrong": lambda: _hollow_sphere(False, False),
    "duplicated_shell_same_indices": _duplicated_box,
    "touching_copies_offset": _touching_copies,
    "internal_wall": _internal_wall,
}


#: Reproducers of the open classes: name → class of OPEN_CLASSES.
OPEN_REPRODUCERS: dict[str, str] = {
}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(
    strict=True, reason=f"open: {OPEN_CLASSES[OPEN_REPRODUCERS[n]][1]}")) if n in OPEN_REPRODUCERS else n
    for n in sorted(REPRODUCERS)])
def test_reproducer(name):
    """The minimal cases of each failure class the generator found (and the issue's own)."""
    _assert_honest(REPRODUCERS[name]())


# ------------------------------------------------------------------------- R0: shells listed twice (issue 21)
def _props(v, f):
    import warnings
    from inertia_tool import mass_properties
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = mass_properties((v, f), density=1.0)
    return p, [str(w.message) for w in caught]


@settings(max_examples=15, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), same_indices=st.booleans(), copy_first=st.booleans(),
       shuffle=st.booleans())
def test_shell_listed_twice_is_counted_once(seed, same_indices, copy_first, shuffle):
    """A shell (or a whole nest) listed twice, with its own vertices or the same ones, the copy first or last,
    faces in any order: the same solid once, certified exact, with a note that counts the faces left out."""
    rng = np.random.default_rng(seed)
    case = S.make_case(("single", "nested", "disjoint")[seed % 3], rng)
    v, f = case.vertices, case.faces
    copy = f if same_indices else f + len(v)
    verts = v if same_indices else np.vstack([v, v])
    faces = np.concatenate([copy, f] if copy_first else [f, copy])
    if shuffle:
        faces = faces[rng.permutation(len(faces))]
    alone, _ = _props(v, f)
    twice, said = _props(verts, faces)
    assert twice.mesh.certificate.kind == alone.mesh.certificate.kind
    assert abs(twice.mass - alone.mass) <= 1e-12 * alone.mass
    assert np.allclose(twice.inertia, alone.inertia, rtol=0, atol=1e-12 * np.abs(alone.inertia).max())
    assert any(f"({len(f):,} faces repeating others corner for corner) counted once" in w for w in said), said


@pytest.mark.parametrize("same_indices", [False, True])
def test_shell_and_its_inverted_copy_cancel(same_indices):
    """A closed surface with its exact inverted copy: winding number 0 everywhere.  Alone it is refused with that
    reason (not "no outward-wound piece"); beside another body both are left out and the body stays exact."""
    from inertia_tool.errors import InvalidMeshError
    t = S.torus(1.0, 0.3)
    v, f = (t[0], np.concatenate([t[1], t[1][:, ::-1]])) if same_indices else S.concat(t, S.flipped(t))
    with pytest.raises(InvalidMeshError, match="exact inverted copy .* cancel to nothing"):
        _props(v, f)
    other = S.box([1.0, 2.0, 3.0], [5.0, 0.0, 0.0])
    both, said = _props(*S.concat((v, f), other))
    alone, _ = _props(*other)
    assert both.mesh.certificate.kind == "exact"
    assert abs(both.mass - alone.mass) <= 1e-12 * alone.mass
    assert any("exact inverted copy (512 faces in all)" in w for w in said), said


def test_core_filling_its_cavity_exactly_cancels():
    """A cavity (inward) filled by a core of exactly its surface (outward): the pair cancels and the body is
    whole (winding number 1 everywhere inside), exact."""
    outer = S.box([2.0, 2.0, 2.0])
    hole = S.box([1.0, 1.0, 1.0])
    p, said = _props(*S.concat(outer, S.flipped(hole), hole))
    assert p.mesh.certificate.kind == "exact" and abs(p.mass - 8.0) <= 1e-12


# -------------------------------------------------- R4: a shell within another up to its boundary (issue 21)
@settings(max_examples=30, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), cavity_inward=st.booleans(), turned=st.booleans())
def test_flush_cavity_is_a_cavity_however_turned(seed, cavity_inward, turned):
    """A cavity flush with its body's face, wound either way, axis-aligned or under a random rotation (so the
    contact is coplanar exactly, or only to rounding): one rule, the depth of the closed solid, places it within
    the box; wound inward the answer is the notched box (rational truth), wound outward the file's winding stands
    (1 and 2, never below 0: R4, session 16) and the answer is the box whole, or a label that says it is not
    proven; never ``united`` for the outward one (the depth reading is named, not formed by a boolean)."""
    rng = np.random.default_rng(seed)
    ea = rng.integers(4, 9, size=3) * 0.125
    ec = np.minimum(rng.integers(1, 4, size=3) * 0.125, ea - 0.25)
    outer = S.box(ea)
    cavity = S.box(ec, [(ea[0] - ec[0]) / 2, 0.0, 0.0])
    rot = S.random_rotation(rng) if turned else S.right_angle_rotation(rng)
    shift = rng.normal(size=3)
    outer, cavity = S.moved(outer, rot, shift), S.moved(cavity, rot, shift)
    mesh = S.concat(outer, S.flipped(cavity) if cavity_inward else cavity)
    # wound outward, the file's winding (1 and 2) stands: the box whole (R4, session 16; before, the notched box)
    truth = S.truth_from_pieces([(1, outer), (-1, cavity)] if cavity_inward else [(1, outer)])
    case = S.Case("flush_cavity", *mesh, truth, "flush cavity")
    verdict = _assert_honest(case)
    assert verdict.label in ("exact", "united", "unverified", "estimate")
    assert not (verdict.label == "united" and not cavity_inward)     # issue 21 item 3: never united for R4's reading
    if not turned:
        assert verdict.wrong is None and verdict.label in ("exact", "united")


def test_box_standing_inside_another_reads_like_a_flush_cavity():
    """The same geometry two ways: a small box standing on the floor inside a big one, wound outward and wound
    inward.  Both are a shell within another touching its boundary, placed by one rule (R4); wound inward it is a
    cavity (1 − 0.25³), wound outward the file's winding (1 and 2) stands and it is part of the body (1: session
    16; before, the cavity's volume both ways)."""
    big = S.box([1.0, 1.0, 1.0])
    small = S.box([0.25, 0.25, 0.25], [0.0, 0.0, -0.375])            # on the floor z = -0.5, from inside
    for inner, volume in ((small, 1.0), (S.flipped(small), 1.0 - 0.25 ** 3)):
        p, said = _props(*S.concat(big, inner))
        assert p.mesh.certificate.kind in ("exact", "united")
        assert abs(p.mass - volume) <= 1e-12


# ------------------------------------------------------- R7: "exact" up to a derived round-off bound (issue 21)
def _thin_far_tetrahedron(rng):
    length = float(10 ** rng.uniform(0, 2))
    thick = length * float(10 ** rng.uniform(-16, -6))
    tet = np.array([[0, 0, 0], [0, length, 0], [0, 0, length], [thick, length / 3, length / 3]])
    tet = tet @ S.random_rotation(rng).T + rng.normal(size=3) * length * float(10 ** rng.uniform(0, 2))
    return tet, S._outward_exactly(tet, np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]))


@settings(max_examples=25, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_exact_integer_moments_match_rationals(seed):
    """exact_volume_moments (integers over a power of two) against the rational integral of the harness, on
    thin tetrahedra far from the origin and on small pieces: equal to one rounding."""
    from unittest import mock

    from inertia_tool.integrals import exact_volume_moments
    rng = np.random.default_rng(seed)
    v, f = _thin_far_tetrahedron(rng) if seed % 2 else S.random_piece(rng, small=True)[1]
    got = exact_volume_moments(v, f)
    # the truth in rationals whatever the size (a part of more than FRACTION_MAX_FACES faces, the washer or the
    # spinning top, would otherwise be integrated in float64, ~1e-17 m off a centroid coordinate that is 0)
    with mock.patch.object(S, "FRACTION_MAX_FACES", len(f)):
        want = S.truth_from_pieces([(1, (v, f))])
    assert want.source == "fraction"
    assert abs(got.volume - want.volume) <= 2 ** -52 * abs(want.volume)
    # each side rounded once from the same rational: one ulp of the coordinate, absolute (a coordinate that is
    # 0 exactly has no relative error to speak of), within 2⁻⁵² of the largest |coordinate|
    scale = float(np.abs(v).max())
    assert np.allclose(got.centroid, want.centroid, rtol=2 ** -52, atol=2 ** -52 * scale)
    inertia = np.trace(got.second_moment) * np.eye(3) - got.second_moment
    assert np.linalg.norm(inertia - want.inertia) <= 1e-15 * np.linalg.norm(want.inertia)


@settings(max_examples=40, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_roundoff_bound_holds(seed):
    """The derived float64 bound of roundoff_bounds contains the actual error of body_volume_moments (against
    exact integer moments) for every shell: a body, a thin tetrahedron and a far piece about a common origin."""
    from inertia_tool.integrals import body_volume_moments, exact_volume_moments, reference_point, roundoff_bounds
    rng = np.random.default_rng(seed)
    body = S.random_piece(rng)[1]
    far = S.random_piece(rng, small=True)[1]
    far = (far[0] + rng.normal(size=3) * float(10 ** rng.uniform(0, 3)), far[1])
    v, f = S.concat(body, _thin_far_tetrahedron(rng), far)
    labels = np.repeat([0, 1, 2], [len(body[1]), 4, len(far[1])])
    o = reference_point(v)
    shells = body_volume_moments(v, f, labels, 3, origin=o)
    bound = roundoff_bounds(v, f, labels, shells, o)
    for k in range(3):
        truth = exact_volume_moments(v, f[labels == k])
        assert abs(shells[k].volume - truth.volume) <= bound.volume[k] + 2 ** -53 * abs(truth.volume)
        if truth.volume == 0:
            # the thin tetrahedron moved far can round flat: its exact volume is 0, its centroid undefined (NaN)
            # and its central second moment not defined either; the volume bound above is all there is to check
            continue
        if np.isfinite(bound.centroid[k]):
            assert np.linalg.norm(shells[k].centroid - truth.centroid) <= bound.centroid[k] * (1 + 1e-6)
            assert np.linalg.norm(shells[k].second_moment - truth.second_moment) <= \
                bound.second_moment[k] * (1 + 1e-6) + 1e-15 * np.linalg.norm(truth.second_moment)


@settings(max_examples=25, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_far_thin_solid_beside_a_part_is_exact(seed):
    """A part and a closed tetrahedron 1e-16…1e-6 of its length thin, up to 100 lengths away (the harness's
    far-sliver class, 3e-7 off in inertia while labelled exact before): exact to 1e-12 against rationals, or
    not labelled exact."""
    rng = np.random.default_rng(seed)
    body = S.random_piece(rng)[1]
    tet = _thin_far_tetrahedron(rng)
    case = S.Case("sliver", *S.concat(body, tet), S.truth_from_pieces([(1, body), (1, tet)]), "far thin")
    try:
        p, _ = _props(case.vertices, case.faces)
    except Exception as exc:             # a refusal is honest (flat everywhere, or beyond float64's range)
        from inertia_tool.errors import InvalidMeshError
        assert isinstance(exc, InvalidMeshError)
        return
    if p.mesh.certificate.kind in ("exact", "united"):
        # "exact" promises the polyhedron's moments within ROUNDOFF_RTOL (R7, by the derived float64 bound), not
        # to 1e-12: at hypothesis seed 72 example 139 (an icosphere and a tetrahedron 6e-16 m³ far away) the
        # inertia is 1.06e-12 off, a hundred times inside the promise
        from inertia_tool.tolerances import ROUNDOFF_RTOL
        dvol, dcom, din = S.compare(p, case.truth)
        assert dvol <= ROUNDOFF_RTOL and din <= ROUNDOFF_RTOL, (dvol, din)


# ------------------------------------ bodies crossing exactly along shared edges (issue 21 item 2: Go1's mechanism)
def _edge_crossing_pieces(seed, prism):
    """The pieces (unmoved) and the inclusion–exclusion terms of one shared-edge crossing."""
    rng = np.random.default_rng(seed)
    for _ in range(100):
        made = S.prism_through_box(rng) if prism else S.boxes_on_shared_grid(rng, int(rng.integers(2, 4)))
        if made is not None:
            return ([made[0], made[1]], made[2]) if prism else (made[0], made[1])
    raise AssertionError("no crossing drawn")


@pytest.mark.parametrize("prism", [False, True])
def test_shared_edge_crossing_truths_agree_and_no_face_pair_crosses(prism):
    """The kind's two truths agree (rational inclusion–exclusion and manifold3d's union, 1e-12), and the mechanism
    is the one it claims: where no two boxes share a plane, no face pair of different shells crosses transversally,
    yet the shells share volume (the surfaces cross only along edges of both)."""
    from inertia_tool.mesh.intersect import surface_contacts
    checked = 0
    for seed in range(12):
        pieces, signed = _edge_crossing_pieces([3, seed], prism)
        exact, union = S.truth_from_pieces(signed), S.truth_from_manifold(pieces)
        assert abs(exact.volume - union.volume) <= 1e-12 * exact.volume
        assert np.linalg.norm(exact.inertia - union.inertia) <= 1e-12 * np.linalg.norm(exact.inertia)
        assert exact.volume < sum(S.float_moments(*p)[0] for p in pieces) * (1 - 1e-6)     # they do overlap
        v, f = S.concat(*pieces)
        shells = np.repeat(np.arange(len(pieces)), [len(p[1]) for p in pieces])
        planes = [{(k, float(p[0][:, k].min())), (k, float(p[0][:, k].max()))} for p in pieces for k in range(3)]
        coplanar = not prism and any(planes[3 * i + k] & planes[3 * j + k] for i in range(len(pieces))
                                     for j in range(i + 1, len(pieces)) for k in range(3))
        crossing = np.asarray(surface_contacts(v, f).crossing).reshape(-1, 2)
        if not coplanar:
            assert not np.any(shells[crossing[:, 0]] != shells[crossing[:, 1]])
            checked += 1
    assert checked >= 3


@settings(max_examples=30, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_shared_edge_crossing_is_never_a_silent_wrong_answer(seed):
    """Generated shared-edge crossings (half of them welded, as an STL reads, so that every crossing edge is used
    by four faces) under rigid motions: the union, or a label that says it is not proven.  Welded, the bodies were
    one edge-connected shell whose balanced edges made the sum look exact: 272 of 300 certified exact and wrong
    (up to 41 %)."""
    case = S.make_case("shared_edge_crossing", np.random.default_rng(seed))
    verdict = _assert_honest(case)
    assert verdict.label != "exact"        # the bodies share volume: the summed integral is never the solid


def _welded_prism_through_box():
    """A unit box and a hexagonal prism through its top and bottom faces, the hexagon drawn in both faces'
    triangulation, the vertices welded (each crossing edge used by four faces)."""
    for seed in range(100):
        made = S.prism_through_box(np.random.default_rng([5, seed]))
        if made is not None and "through it" in made[3]:
            box, prism, signed, recipe = made
            return S.Case("shared_edge_crossing", *S._weld_exact(*S.concat(box, prism)), S.truth_from_pieces(signed),
                          recipe + "; welded")
    raise AssertionError("no prism through the box drawn")


def _welded_boxes_crossing():
    """Two boxes on a shared grid crossing like beams, each cut along the other's planes, vertices welded."""
    from test_mesh_touching_shells import _boxes_on_shared_grid
    lo_a, hi_a, lo_b, hi_b = (0.0, 0.0, 0.0), (2.0, 2.0, 2.0), (0.5, 0.5, 0.5), (3.0, 1.5, 1.5)
    a, b = _boxes_on_shared_grid(lo_a, hi_a, lo_b, hi_b)
    common = S.box([1.5, 1.0, 1.0], [1.25, 1.0, 1.0])
    return S.Case("shared_edge_crossing", *S._weld_exact(*S.concat(a, b)),
                  S.truth_from_pieces([(1, a), (1, b), (-1, common)]), "two boxes crossing along shared edges, welded")


REPRODUCERS["welded_prism_through_box"] = _welded_prism_through_box
REPRODUCERS["welded_boxes_crossing_like_beams"] = _welded_boxes_crossing


def test_welded_crossing_bodies_are_split_into_the_bodies_not_union_and_core():
    """R1b pairs the faces at each non-manifold edge first in, first out: the two boxes come back as themselves
    (8 and 2.5 m³), not as the boundary of their union around the boundary of their common part (9 and 1.5 m³,
    which R4 would read as a body with a cavity)."""
    from inertia_tool.mesh.checks import shell_labels
    from inertia_tool.mesh.nonmanifold import welded_bodies
    case = _welded_boxes_crossing()
    v, f = case.vertices, case.faces
    labels, n = shell_labels(f, len(v))
    assert n == 1
    found = welded_bodies(f, len(v), labels, n, v)
    assert found.split == 1 and found.n_shells == 2 and found.ambiguous == 0 and len(found.contact)
    volumes = sorted(S.float_moments(v, f[found.labels == k])[0] for k in range(2))
    assert volumes == pytest.approx([2.5, 8.0], rel=1e-14)
    p, said = _props(v, f)
    assert p.mesh.certificate.kind == "united" and p.mass == pytest.approx(9.0, rel=1e-12)


def test_welded_internal_wall_stays_exact():
    """The other side of R1b: a box welded to its neighbour face to face (a zero-thickness wall) splits into two
    boxes that only touch, and stays exact (faces at one angle facing opposite ways: leave one, enter the other)."""
    a = S.box([0.5, 1.0, 1.0], [-0.25, 0, 0])
    b = S.box([0.5, 1.0, 1.0], [0.25, 0, 0])
    p, _ = _props(*S._weld_exact(*S.concat(a, b)))
    assert p.mesh.certificate.kind == "exact" and p.mass == pytest.approx(1.0, rel=1e-14)


def test_crossing_bodies_read_from_an_stl(tmp_path):
    """The real path: a box and a prism through it written to an STL (no indices: the reader welds the crossing
    edges' corners, bit-identical) read back as their union, certified united (was: the sum, exact)."""
    case = _welded_prism_through_box()
    tri = case.vertices[case.faces]
    lines = ["solid x"]
    for t in tri:
        corners = [f"vertex {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}" for p in t]
        lines += ["facet normal 0 0 0", "outer loop", *corners, "endloop", "endfacet"]
    path = tmp_path / "crossing.stl"
    path.write_text("\n".join(lines + ["endsolid x"]) + "\n")
    from inertia_tool import mass_properties
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = mass_properties(str(path), density=1.0)
    dvol, dcom, din = S.compare(p, case.truth)
    assert p.mesh.certificate.kind == "united"
    assert dvol <= 1e-12 and din <= 1e-12


# ----------------------------------------- touching up to rounding, copies rounded apart (issue 21 item 4)
@settings(max_examples=12, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_touching_copies_turned_at_random_are_united_up_to_rounding(seed):
    """Two boxes face to face, turned by a random rotation: faces coplanar only to rounding cross or gap by
    ~1e-16.  Where a pair crosses, the solid is ambiguous at that level: the answer is the summed integral, right
    to 1e-12 against rationals, certified united with the check and a note that say "touching up to rounding";
    where none crosses it stays exact.  Never unverified, never "overlapping bodies ... shared volume"."""
    rng = np.random.default_rng(seed)
    a = S.box([1.0, 1.0, 1.0])
    b = S.box([1.0, 1.0, 1.0], [1.0, 0.25, 0.0], subdivide=int(rng.integers(0, 2)))
    rot, shift = S.random_rotation(rng), rng.normal(size=3)
    a, b = S.moved(a, rot, shift), S.moved(b, rot, shift)
    p, said = _props(*S.concat(a, b))
    truth = S.truth_from_pieces([(1, a), (1, b)])
    dvol, dcom, din = S.compare(p, truth)
    assert dvol <= 1e-12 and din <= 1e-12
    cert = p.mesh.certificate
    assert cert.kind in ("exact", "united")
    assert not any("shared volume" in w for w in said), said
    if cert.kind == "united":
        assert "touching-up-to-rounding" in cert.checks
        assert any(n.startswith("touching up to rounding") for n in p.mesh.notes)


@settings(max_examples=12, derandomize=True, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), far=st.booleans())
def test_copy_rounded_apart_is_counted_once_exactly(seed, far):
    """A shell listed twice whose copy's coordinates were computed apart ((v + c) − c: equal up to a few ulp), faces
    shuffled: counted once, exact, with the note; its answer matches manifold3d's union of the two to 1e-12."""
    rng = np.random.default_rng(seed)
    name, piece = S.random_piece(rng)
    v, f = S.moved(piece, S.random_rotation(rng), rng.normal(size=3) * (1000.0 if far else 1.0))
    c = rng.normal(size=3) * float(np.abs(v).max()) * 0.37
    copy = (v + c) - c
    assume(np.any(copy != v))
    p, said = _props(np.vstack([v, copy]), np.concatenate([f, (f + len(v))[rng.permutation(len(f))]]))
    union = S.truth_from_manifold([(v, f), (copy, f)])
    dvol, dcom, din = S.compare(p, union)
    assert p.mesh.certificate.kind == "exact", (name, p.mesh.notes)
    # the tool promises the copy adds at most ROUNDOFF_RTOL (R0 up to rounding, R7); the manifold3d truth is a
    # float64 union integrated in float64 about its vertex mean, each coordinate carrying its rounding (2⁻⁵³ of
    # the largest |coordinate|, up to ~3,000 m when far) relative to the part's size: 64 such units cover it
    # (at hypothesis seed 52 a part 1,000 m out was 1.4e-12 off manifold3d in inertia)
    from inertia_tool.tolerances import ROUNDOFF_RTOL
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    float_error = 64 * 2.0 ** -53 * float(np.abs(v).max()) / diag
    assert dvol <= ROUNDOFF_RTOL + float_error and din <= ROUNDOFF_RTOL + float_error, (dvol, din, float_error)
    exact = S.truth_from_pieces([(1, (v, f))])
    assert S.compare(p, exact)[0] <= ROUNDOFF_RTOL and S.compare(p, exact)[2] <= ROUNDOFF_RTOL
    assert any("repeating another corner for corner within" in w for w in said), said


def test_copy_moved_beyond_rounding_is_not_merged():
    """A copy 1e-9 m off (far beyond 64 ulp) is not a copy up to rounding: it overlaps, and is united."""
    v, f = S.icosphere(0.5, 1)
    p, said = _props(*S.concat((v, f), (v + 1e-9, f)))
    assert p.mesh.certificate.kind in ("united", "unverified")
    assert not any("repeating another corner for corner within" in w for w in said)
    union = S.truth_from_manifold([(v, f), (v + 1e-9, f)])
    assert abs(p.mass - union.volume) <= 1e-9 * union.volume


def test_nest_copied_rounded_apart_then_welded_is_counted_once():
    """A hollow sphere with a core (three nested icospheres) listed twice, the copy's coordinates rounded apart and
    the whole welded bit-exactly (as an STL reads): the corners that rounded alike are shared, so each copy is
    welded to its original at a few non-manifold edges.  R1b splits them, R0 up to rounding counts each once:
    exact (the harness's case, duplicated kind, rng [31, 31], welded).  Before the split ran ahead of R0 the two
    halves of a welded pair were read as nested shells: united, 10 % high.  Where the shared corners make
    coplanar faces of the two copies overlap at a welded edge, the pairing is undefined: refused or unverified,
    never a wrong number certified."""
    from inertia_tool.errors import InvalidMeshError
    case = S.make_case("duplicated", np.random.default_rng([31, 31]))
    assert "rounded apart" in case.recipe and "nested" in case.recipe
    welded = S.Case(case.kind, *S._weld_exact(case.vertices, case.faces), case.truth, case.recipe + "; welded")
    assert len(welded.vertices) < len(case.vertices)
    assert _assert_honest(welded).label == "exact"
    rng = np.random.default_rng(4)
    outer, cavity, core = S.icosphere(0.7, 1), S.icosphere(0.5, 0), S.icosphere(0.3, 0)
    v, f = S.concat(outer, S.flipped(cavity), core)
    truth = S.truth_from_pieces([(1, outer), (-1, cavity), (1, core)])
    for _ in range(5):
        copy = (v + rng.normal(size=3)) - 0.0
        copy = copy - (copy - v)            # rounded apart: equal to v up to a few ulp, some corners bit-equal
        mesh = S._weld_exact(np.vstack([v, copy]), np.concatenate([f, f + len(v)]))
        try:
            p, _ = _props(*mesh)
        except InvalidMeshError:
            continue
        dvol, dcom, din = S.compare(p, truth)
        assert p.mesh.certificate.kind not in ("exact", "united") or (dvol <= 1e-12 and din <= 1e-12)


def test_welded_bodies_with_coplanar_faces_at_a_crossing_edge_are_united():
    """Three boxes on a shared grid, some planes shared, welded: at a crossing edge coplanar faces of two bodies
    face the same way, so the order around the edge (which face closes which body) is undefined.  The bodies
    overlap there and the sum would count it twice (was: the sum, certified unverified, 4 % high; then refused
    with that reason).  The solid {winding number ≥ 1} does not depend on the order: formed by the coplanar
    overlay (mesh/coplanar.py), certified united, and right; with ``repair`` the same."""
    case = _generated("shared_edge_crossing", 319, n_kinds=16)
    assert "welded" in case.recipe and "planes shared" in case.recipe
    p, _ = _props(case.vertices, case.faces)
    assert p.mesh.certificate.kind == "united" and "winding-arrangement" in p.mesh.certificate.checks
    verdict = _assert_honest(case)
    assert verdict.label == "united" and verdict.wrong is None
    verdict = _assert_honest(case, repair=True)
    assert verdict.wrong is None


def test_welded_l_shapes_on_one_plane_truth_agrees_with_manifold3d():
    """The ``welded_l_shapes`` truth (the union's cells in rationals) against manifold3d's union of the two
    prisms (independent code), before welding."""
    for seed in range(3):
        rng = np.random.default_rng([5, seed])
        a = S._l_cells(3, 2, 1, 2, 0, (0, 0))
        b = S._l_cells(2, 4, 2, 1, int(rng.integers(4)), (1, -1))
        pa, pb = S.cell_body(a, 0.5, rng), S.cell_body(b, 0.5, rng)
        cells = S.truth_from_pieces([(1, S.box((0.5,) * 3, (np.asarray(c, dtype=float) + 0.5) * 0.5))
                                     for c in sorted(a | b)])
        union = S.truth_from_manifold([pa, pb])
        assert cells.volume == pytest.approx(0.125 * len(a | b), rel=1e-15)
        assert union.volume == pytest.approx(cells.volume, rel=1e-12)
        assert np.allclose(union.centroid, cells.centroid, atol=1e-12)


def test_welded_l_shapes_on_one_plane_are_united_never_wrong():
    """Issue 21: two L-shaped prisms standing on one plane, crossing, welded bit-exactly.  At the crossing
    edges on the shared plane two coplanar faces of different bodies face the same way; which of them closes
    which body is not fixed by the surface (both lie in one half-plane of the edge, so no angle orders them).
    Breaking the tie by face order was tried: on ``make_case("shared_edge_crossing", rng([22, 69]))`` (two
    boxes sharing planes, welded) it grouped the faces into other closed bodies and certified the sum exact,
    6 % high.  The solid {winding number ≥ 1} does not depend on the pairing: the coplanar overlay
    (mesh/coplanar.py) forms it, certified united, and it matches the union's cells (was: refused, exit 3)."""
    labels = []
    for seed in range(4):
        case = S.make_case("welded_l_shapes", np.random.default_rng([22, seed]))
        assert "coplanar bottoms facing the same way" in case.recipe
        verdict = _assert_honest(case)
        assert verdict.label in ("united", "refused")
        labels.append(verdict.label)
    assert "united" in labels


def test_welded_grid_of_touching_cubes_is_left_whole_and_exact():
    """R1b splits only shells where surfaces cross at a welded edge (the winding number around it spans two):
    4 × 4 × 2 unit cubes welded face to face (zero-thickness walls, edges of up to eight faces) stay one shell
    whose sum is exact, as before R1b.  Reading the faces' direction along the edge the wrong way made every wall a
    crossing: 32 shells, united, 10× the CPU time."""
    from inertia_tool.mesh.checks import shell_labels
    from inertia_tool.mesh.nonmanifold import welded_bodies
    cubes = [S.box([1, 1, 1], [i, j, k]) for i in range(4) for j in range(4) for k in range(2)]
    v, f = S._weld_exact(*S.concat(*cubes))
    labels, n = shell_labels(f, len(v))
    found = welded_bodies(f, len(v), labels, n, v)
    assert n == 1 and found.split == 0 and found.ambiguous == 0
    p, _ = _props(v, f)
    assert p.mesh.certificate.kind == "exact" and p.mass == pytest.approx(32.0, rel=1e-14)
