"""mesh/unite.py and mesh/union.py: the pieces' manifold3d solids are built once.

:func:`~inertia_tool.mesh.union.union_surface` builds a ``Manifold`` of every closed piece; Bonferroni's witness
(``unite._union_lost_volume``, through :func:`~inertia_tool.mesh.union.common_volumes`) used to build the solid of
every shell again.  It now reuses the pieces that are whole shells wound outward.  Checked here: the witness
builds no solid the union built (and still builds those it did not: a shell of two closed pieces), and every
result is bit for bit what building them anew gives (the witness's lost volume, and the whole analysis).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import adversary_solids as S
import inertia_tool as it
from inertia_tool.mesh import union, unite

pytest.importorskip("manifold3d")


def _analyse(v, f):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return it.mass_properties((v, f), density=1.0)


def _overlapping_boxes(rng, count):
    """``count`` boxes of random extents crossing one another, turned and moved by one random rigid motion."""
    pieces = []
    for k in range(count):
        centre = rng.uniform(-0.3, 0.3, size=3) + [0.4 * k, 0.0, 0.0]
        pieces.append(S.box(rng.uniform(0.6, 1.4, size=3), centre, subdivide=int(rng.integers(0, 2))))
    rot, shift = S.random_rotation(rng), rng.normal(size=3)
    return S.concat(*(S.moved(p, rot, shift) for p in pieces))


class _Builds:
    """Counts the solids built (``union._manifold``) inside the witness's calls of ``common_volumes`` (those given
    ``solids``), and can make those calls build everything anew (``reuse`` False: the code before the change)."""

    def __init__(self, monkeypatch, reuse=True):
        self.in_witness = 0
        self.built_in_witness = 0
        self.witness_calls = 0
        real_manifold, real_common = union._manifold, union.common_volumes

        def manifold(*args, **kwargs):
            self.built_in_witness += self.in_witness
            return real_manifold(*args, **kwargs)

        def common(*args, solids=None, **kwargs):
            if solids is None:                          # R4's within-test (classify.py): not the witness
                return real_common(*args, **kwargs)
            self.witness_calls += 1
            self.in_witness = 1
            try:
                return real_common(*args, solids=solids if reuse else None, **kwargs)
            finally:
                self.in_witness = 0

        monkeypatch.setattr(union, "_manifold", manifold)
        monkeypatch.setattr(union, "common_volumes", common)


def _same_analysis(a, b):
    assert a.volume == b.volume and a.mass == b.mass
    np.testing.assert_array_equal(a.center_of_mass, b.center_of_mass)
    np.testing.assert_array_equal(a.inertia, b.inertia)
    assert a.mesh.certificate == b.mesh.certificate and a.mesh.notes == b.mesh.notes


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), count=st.integers(2, 3))
def test_crossing_boxes_build_each_solid_once_and_answer_as_before(seed, count):
    """Crossing boxes (united by the boolean, the witness run): no solid is built again inside the witness, and
    the answer is bit for bit the one with every shell's solid built anew."""
    v, f = _overlapping_boxes(np.random.default_rng(seed), count)
    with pytest.MonkeyPatch.context() as mp:
        fresh_builds = _Builds(mp, reuse=False)
        fresh = _analyse(v, f)
    with pytest.MonkeyPatch.context() as mp:
        builds = _Builds(mp)
        reused = _analyse(v, f)
    assert builds.witness_calls == fresh_builds.witness_calls
    if builds.witness_calls:
        assert fresh_builds.built_in_witness >= 2 and builds.built_in_witness == 0
    _same_analysis(reused, fresh)


def test_the_witness_is_run_on_crossing_boxes():
    """The case above is not vacuous: two crossing unit boxes are united and the witness runs once."""
    v, f = S.concat(S.box((1.0, 1.0, 1.0)), S.box((1.0, 1.0, 1.0), (0.5, 0.25, 0.125)))
    with pytest.MonkeyPatch.context() as mp:
        builds = _Builds(mp)
        p = _analyse(v, f)
    assert builds.witness_calls == 1 and builds.built_in_witness == 0
    assert p.mesh.certificate.kind == "united"
    assert p.volume == pytest.approx(2.0 - 0.5 * 0.75 * 0.875, rel=1e-12)


def test_lost_volume_is_identical_with_and_without_the_union_solids():
    """``_union_lost_volume`` given the union's solids against building them all: the same float, bit for bit,
    on review 8's turned touching boxes (where it finds volume lost) and on three crossing boxes."""
    from test_review8_union import _turned_touching_boxes

    for v, f in (S.concat(*_turned_touching_boxes()), _overlapping_boxes(np.random.default_rng(11), 3)):
        shells = _shells(v, f)
        labels = shells.labels
        _, built = unite._unite(shells.vertices, shells.faces, labels, np.zeros(shells.n_shells, dtype=np.int64),
                                "test", repair=False)
        assert built is not None and sorted(built.solids) == list(range(shells.n_shells))
        summed = sum(m.volume for m in shells.moments)
        for volume in (summed, summed - 1e-3):
            assert unite._union_lost_volume(shells, volume, built) == unite._union_lost_volume(shells, volume)


def test_a_shell_of_two_closed_pieces_is_built_by_the_witness():
    """A shell that is two closed pieces to the union (two boxes welded along an edge, one shell by index) has
    no single solid of the union: the witness builds it, and its answer is the same as building all anew."""
    a = S.box((1.0, 1.0, 1.0))
    b = S.box((1.0, 1.0, 1.0), (1.0, 1.0, 0.0))
    v, f = S.concat(a, b)
    # weld b's edge x = y = 0.5 onto a's (same coordinates): the two boxes are one shell joined at that edge
    keys = {tuple(p): i for i, p in enumerate(v[:8].tolist())}
    remap = np.arange(len(v))
    for i in range(8, 16):
        remap[i] = keys.get(tuple(v[i].tolist()), i)
    f = remap[f]
    third = S.box((1.0, 1.0, 1.0), (0.25, 0.25, 0.25))
    v, f = S.concat((v, f), third)
    shells = _shells(v, f)
    owner = np.zeros(shells.n_shells, dtype=np.int64)
    united, built = unite._unite(shells.vertices, shells.faces, shells.labels, owner, "test", repair=False)
    counts = np.bincount(shells.labels)
    assert united is not None and shells.n_shells == 2
    welded = int(np.argmax(counts))                       # 24 faces: the two boxes joined at the edge
    assert counts[welded] == 24 and welded not in built.solids and len(built.solids) == 1
    summed = sum(m.volume for m in shells.moments)
    assert unite._union_lost_volume(shells, summed, built) == unite._union_lost_volume(shells, summed)


def _shells(v, f):
    """The surface's shells as the pipeline reads them (R1, R2), every one wound outward here."""
    from inertia_tool.mesh.shells import reshelled

    shells = reshelled(np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64),
                       float(np.linalg.norm(np.ptp(v, axis=0))), "test")
    assert all(m.volume > 0 for m in shells.moments)
    return shells
