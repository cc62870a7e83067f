"""The repair pipeline's order (mesh/resolve.py): the edge census is not taken again when orienting turned no face.

A Möbius band cannot be oriented: ``orient_consistently`` turns none of its faces, though the census finds a
manifold edge whose two faces use it the same way.  The faces are then the census's own, so the census is reused
(soup7: "reuse the first when the faces did not change"), and the refusal says what the first census said.
"""

from __future__ import annotations

import numpy as np
import pytest

from inertia_tool.errors import InvalidMeshError
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh import resolve
from inertia_tool.mesh.orient import orient_consistently


def _moebius(k: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """A band of ``k`` quads with a half twist: top rail ``0..k-1``, bottom ``k..2k-1``; the last quad joins
    top to bottom."""
    u = 2 * np.pi * np.arange(k) / k
    rails = []
    for side in (1.0, -1.0):
        w = 0.3 * side
        rails.append(np.stack([(1 + w * np.cos(u / 2)) * np.cos(u), (1 + w * np.cos(u / 2)) * np.sin(u),
                               w * np.sin(u / 2)], axis=1))
    v = np.vstack(rails)
    faces = []
    for i in range(k - 1):
        t0, t1, b0, b1 = i, i + 1, k + i, k + i + 1
        faces += [[t0, b0, t1], [t1, b0, b1]]
    t0, b0 = k - 1, 2 * k - 1
    faces += [[t0, b0, k], [k, b0, 0]]            # the twist: top meets bottom's start, bottom meets top's
    return v, np.array(faces, dtype=np.int64)


def test_moebius_band_turns_nothing_and_the_census_is_taken_once(monkeypatch) -> None:
    v, f = _moebius()
    first = resolve._census(f, len(v))
    assert first.misoriented_pairs >= 1                       # the twist's edge: both faces one way
    assert orient_consistently(f, len(v), v).flipped_faces == 0
    calls = []
    real = resolve._census
    monkeypatch.setattr(resolve, "_census", lambda faces, n: calls.append(len(faces)) or real(faces, n))
    with pytest.raises(InvalidMeshError) as refused:
        resolve.resolve_surface(v, f, diag=3.0, source="band", repair=False, merge_tolerance=0.0,
                                moments=volume_moments)
    assert len(calls) == 1                                    # was 2: again after an orientation that did nothing
    details = refused.value.details
    assert details["boundary_edges"] == first.balance.boundary_edges
    assert details["unbalanced_edges"] == first.balance.unbalanced_edges


def test_loose_faces_never_outnumber_a_third_of_the_net_boundary() -> None:
    """The lemma that lets ``sheets._nothing_to_take`` skip counting valences when the net boundary is short: a
    face sharing no vertex with another puts its three edges in the net boundary, so such faces number at most
    ``len(boundary) / 3``.  Checked on random face lists (shared, repeated and loose faces), and the early exit
    still fires on 4·64 + 1 loose triangles (a soup)."""
    from inertia_tool.mesh import sheets
    from inertia_tool.mesh.rims import boundary_edges

    rng = np.random.default_rng(17)
    for _ in range(200):
        n = int(rng.integers(3, 40))
        f = rng.integers(0, n, (int(rng.integers(1, 30)), 3))
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        if not len(f):
            continue
        loose = int(np.count_nonzero((np.bincount(f.reshape(-1), minlength=n)[f] == 1).all(axis=1)))
        assert 3 * loose <= len(boundary_edges(f, n))
    k = 4 * sheets.MAX_SHEET_PIECES + 1
    tri = rng.normal(size=(k, 3, 3))
    v, f = tri.reshape(-1, 3), np.arange(3 * k).reshape(-1, 3)
    assert sheets._nothing_to_take(v, f, boundary_edges(f, len(v)), 1e-12, sheets.MAX_SHEET_PIECES)
