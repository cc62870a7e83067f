"""The judge of ``benchmarks/bench_real_motions.py`` (count16): R4's depth reading is offered exactly where one
piece lies wholly inside the other, and it is the larger piece less the smaller (closed forms of boxes).

Seed 1911 of the bench flagged 19 of 300 answers before the judge offered it: every one an outward part wholly
inside another, answered ``exact`` for the larger less the smaller with R4's warning (``docs/adversarial.md``,
count16)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
pytest.importorskip("manifold3d")

import bench_real_motions as R  # noqa: E402
from adversary_solids import box, random_rotation  # noqa: E402


@settings(max_examples=25, deadline=None)
@given(outer=st.tuples(*(st.floats(1.0, 1e3),) * 3), share=st.floats(0.05, 0.9),
       far=st.floats(-1e6, 1e6), seed=st.integers(0, 2**32 - 1))
def test_depth_reading_is_the_outer_less_the_inner(outer, share, far, seed):
    rot = random_rotation(np.random.default_rng(seed))
    outer_box = box(outer)
    inner_box = box(tuple(share * e for e in outer))
    a = (np.asarray(outer_box[0]) @ rot.T + far, np.asarray(outer_box[1]))
    b = (np.asarray(inner_box[0]) @ rot.T + far, np.asarray(inner_box[1]))
    t = R._depth_reading(b, a)                    # either order
    assert t is not None and t.source == "depth reading"
    expected = np.prod(outer) * (1 - share ** 3)
    assert t.volume == pytest.approx(expected, rel=1e-9)
    assert np.allclose(t.centroid, far, atol=1e-9 * max(outer) + 1e-9 * abs(far))


@settings(max_examples=25, deadline=None)
@given(shift=st.floats(0.3, 0.7), axis=st.integers(0, 2))
def test_no_depth_reading_where_the_pieces_cross(shift, axis):
    a = tuple(np.asarray(x) for x in box((1.0, 1.0, 1.0)))
    offset = np.zeros(3)
    offset[axis] = shift
    b = (a[0] * 0.5 + offset, a[1])               # half the size (±0.25), sticking out of the face at +axis
    assert R._depth_reading(a, b) is None


def test_root_is_required_and_named_in_the_help(monkeypatch, capsys):
    """The bench reads the Menagerie only from a folder the user names (before: a default of one machine's path,
    read silently wherever the bench ran)."""
    asked = []
    monkeypatch.setattr(R, "pool", lambda root, max_faces: asked.append(root) or [])
    with pytest.raises(SystemExit) as stop:
        R.main(["--cases", "0"])
    assert stop.value.code == 2 and not asked
    assert "--root" in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:
        R.main(["--root", str(Path(__file__).parent / "no such folder"), "--cases", "0"])
    assert stop.value.code == 2 and not asked
    assert "expected the folder of a MuJoCo Menagerie checkout" in capsys.readouterr().err
    assert R.main(["--root", str(Path(__file__).parent), "--cases", "0"]) == 0
    assert asked == [Path(__file__).parent]
    help_text = R._parser().format_help()
    assert "--root MENAGERIE" in help_text and "required" in help_text
