"""OBJ blocks read without the loop over their lines (``read_obj._plain_block``, issue 25: the Menagerie corpus)
give what the line loop gives: the same vertices, faces, polygon count, warnings and errors, on generated files
that mix plain lines with every kind the fast path must hand back to the loop."""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool.mesh.read_obj import _plain_block, _read_obj


def _read(data: bytes, plain: bool, max_faces: int = 10_000):
    """``(vertices, faces, polygons)`` or the error's text, and the warnings' texts."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = _read_obj("gen.obj", max_faces, data, plain_blocks=plain)
        except Exception as exc:                       # the loop's refusal must be the fast path's too
            out = f"{type(exc).__name__}: {exc}"
    return out, [f"{w.category.__name__}: {w.message}" for w in caught]


def _same(data: bytes, max_faces: int = 10_000) -> None:
    (a, wa), (b, wb) = _read(data, False, max_faces), _read(data, True, max_faces)
    assert wa == wb
    if isinstance(a, str) or isinstance(b, str):
        assert a == b
        return
    for x, y in zip(a[:2], b[:2]):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert np.array_equal(x, y)
    assert a[2] == b[2]


_COORD = st.one_of(st.floats(-1e3, 1e3, allow_nan=False).map(lambda x: f"{x!r}"),
                   st.sampled_from(["1e-3", "-0", "+2.5", "7", "1_0", "nan", "x", "1.5e400", "٣"]))


def _corner(n_vertices: int):
    index = st.one_of(st.integers(1, max(n_vertices, 1)).map(str),
                      st.sampled_from(["0", "-1", "-2", "99999", "+3", "1_1", "99999999999999999999999", "007"]))
    tail = st.sampled_from(["", "/1", "//2", "/3/4", "/", "/x_y"])
    return st.tuples(index, tail).map("".join) | st.sampled_from(["/5", "a"])


@st.composite
def _obj_text(draw):
    n_vertices = draw(st.integers(0, 12))
    lines = []
    for _ in range(n_vertices):
        coords = draw(st.lists(_COORD, min_size=3, max_size=3))
        if draw(st.integers(0, 15)) == 0:
            coords = coords[:draw(st.integers(0, 4))] + draw(st.lists(_COORD, max_size=2))
        lines.append(draw(st.sampled_from(["v ", "v\t", "v  ", " v ", "v\x0b"])) + " ".join(coords))
    for _ in range(draw(st.integers(0, 10))):
        k = draw(st.integers(2, 6)) if draw(st.integers(0, 6)) == 0 else draw(st.integers(3, 4))
        corners = draw(st.lists(_corner(n_vertices), min_size=k, max_size=k))
        gap = draw(st.sampled_from([" ", "\t", "  "]))
        lines.append(draw(st.sampled_from(["f ", "f\t", " f ", "f  "])) + gap.join(corners))
    for _ in range(draw(st.integers(0, 6))):
        lines.append(draw(st.sampled_from(
            ["# a comment", "#", "", "   ", "\t# x", "o part_1", "g", "usemtl steel_2", "s off", "vn 0 0 1",
             "vt 0.5 0.5", "vt\t1 1", "mtllib a.mtl", "l 1 2", "p 1", "l", "bogus 1 2", "vnx 1", "v", "f",
             "fo 1 2 3", "v 1 2 \\", "\x0c", "é", "vp 1"])))
    order = draw(st.permutations(range(len(lines))))
    text = "\n".join(lines[i] for i in order)
    ending = draw(st.sampled_from(["\n", "", "\r\n", "\n\n"]))
    return (text + ending).replace("\n", draw(st.sampled_from(["\n", "\r\n"]))).encode("utf-8")


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=_obj_text(), max_faces=st.sampled_from([10_000, 3, 1]))
def test_plain_blocks_read_as_the_line_loop(data, max_faces):
    _same(data, max_faces)


def test_a_plain_block_is_read_without_the_loop():
    """The comparison above is not vacuous: plain text takes the fast path, and it equals the loop's."""
    block = (b"# cube\no cube_1\nusemtl steel_2\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n"
             b"f 1/1/1 2/1/1 3/1/1\nf 1//1 3//1 4//1 2\ns off\n\nl 1 2\n")
    plain = _plain_block(block, 0, 100, 100)
    assert plain is not None
    assert plain.coordinates is not None and plain.triangles is not None and plain.quads is not None
    assert plain.coordinates.tolist() == [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    assert plain.triangles.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 1]] and plain.quads.tolist() == [1]
    assert (plain.vertices, plain.polygons, plain.triangle_count, plain.loose) == (4, 2, 3, 1)
    _same(block)


@pytest.mark.parametrize("line", [b"f 1 2 -1", b"f 1 2 0", b"f 1 2 3 4 1", b"f /1 2 3", b"v 1 2", b"v 1 2 3 4",
                                  b"bogus", b" v 1 2 3", b"f 1 2 3 \\", b"v 1_0 2 3", b"f 1 2 999"])
def test_a_line_the_fast_path_does_not_take_sends_the_block_to_the_loop(line):
    block = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n" + line + b"\n"
    assert _plain_block(block, 0, 100, 100) is None
    _same(block)
