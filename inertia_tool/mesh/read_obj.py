"""Reading Wavefront OBJ natively, streamed in bounded blocks: ``v`` lines and ``f`` polygons (quads and larger
polygons cut as MuJoCo's loader cuts them, :mod:`.polygons`)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import MalformedTextWarning
from .polygons import clip_polygons, split_quads_along_shorter_diagonal, warn_clipped_polygons, warn_warped_quads
from .options import MAX_SUPPORTED_FACES
from .read_base import (MAX_LINE_BYTES, _check_face_budget, _display, _fail, _has_odd_bytes, _odd_number, _source_bytes,
                        _text_blocks)

#: OBJ statements that carry nothing for a solid's mass properties (texture, normals, groups, materials,
#: free-form geometry); they are skipped silently.  Anything else unknown is counted and warned about.
_OBJ_SKIPPED = frozenset(b"vt vn vp o g s usemtl mtllib cstype deg bmat step curv curv2 surf parm trim hole "
                         b"scrv sp end con mg bevel c_interp d_interp lod maplib usemap shadow_obj trace_obj "
                         b"ctech stech call csh".split())


def _obj_vertex_block(path: str, tokens: list[bytes], lines: list[int]) -> np.ndarray:
    """The ``(n, 3)`` coordinates of one block's ``v`` statements; ``lines[i]``: the line of vertex ``i``, named
    when one of its coordinates is not a number."""
    try:
        return np.array(tokens, dtype=np.float64).reshape(-1, 3)
    except ValueError:
        for k, tok in enumerate(tokens):
            try:
                float(tok)
            except ValueError:
                raise _fail(path, f"line {lines[k // 3]}: vertex coordinate "
                                  f"{tok[:40].decode('utf-8', 'replace')!r} is not a number") from None
        raise _fail(path, f"vertex coordinates on lines {lines[0]} to {lines[-1]} are not numbers") from None


#: Bytes that end a word in :func:`_read_obj`'s ``bytes.split()`` and that :func:`_plain_block` takes as gaps
#: (space, tab, newline); a line holding another whitespace byte (``\v``, ``\f``) is left to the line loop.
_GAP = np.zeros(256, dtype=bool)
_GAP[[32, 9, 10]] = True
#: Bytes a plain face line may hold once its corners' ``/`` tails are cut: digits and gaps.
_INDEX_BYTE = _GAP.copy()
_INDEX_BYTE[48:58] = True


def _tokens_per_line(chars: np.ndarray) -> np.ndarray:
    """``(lines,)`` int: the words (runs of bytes other than space, tab and newline) on each line of ``chars``
    (the bytes of whole lines, each ending with a newline)."""
    gap = _GAP[chars]
    starts = ~gap
    starts[1:] &= gap[:-1]
    line_starts = np.concatenate(([0], np.flatnonzero(chars == 10)[:-1] + 1))
    return np.add.reduceat(starts, line_starts, dtype=np.int64)


@dataclass(frozen=True)
class _PlainBlock:
    """What :func:`_plain_block` read of one block: the arrays and counts :func:`_read_obj`'s line loop builds for
    the same block."""

    #: (k, 3) float: the ``v`` lines' coordinates, in the file's units; None: no ``v`` line.
    coordinates: np.ndarray | None
    #: (t, 3) int: the ``f`` lines' triangles, 0-based vertex indices of the file, a quad ``a b c d`` as ``a b c,
    #: a c d`` (not split yet); None: no ``f`` line.
    triangles: np.ndarray | None
    #: (q,) int: the first of each quad's two triangles in ``triangles``; None: no ``f`` line.
    quads: np.ndarray | None
    #: ``v`` lines read (``k``).
    vertices: int
    #: ``f`` lines read (polygons).
    polygons: int
    #: Triangles read (``t``).
    triangle_count: int
    #: ``l`` and ``p`` lines (polylines and points: no solid; counted for a warning).
    loose: int


def _plain_block(block: bytes, nv: int, max_vertices: int, faces_left: int) -> _PlainBlock | None:
    """One block of an OBJ file read without a Python loop over its ``v`` and ``f`` lines, when every line is
    plain: ``v`` then a space or tab and exactly three coordinates, ``f`` then a space or tab and three or four
    corners with positive vertex indices (digits only) up to ``max_vertices``; any other line a comment, a blank
    line, a statement of :data:`_OBJ_SKIPPED` or an ``l``/``p`` line (each looked at as the line loop looks at
    it); no ``_`` or non-ASCII byte in a ``v`` or ``f`` line, no continued line, at most ``faces_left``
    triangles and ``max_vertices − nv`` vertices.  Returns what :func:`_read_obj`'s line loop builds for the
    same block (:class:`_PlainBlock`), or None for any other block (the loop then reads it, and says what is
    wrong where it is).

    Both read the same words with the same conversions (``np.array(..., float64)`` of the coordinates, the
    digits before a corner's first ``/`` as the index), in the file's order, so their arrays are equal; a quad
    ``a b c d`` is the triangles ``a b c, a c d`` before :func:`~.polygons.split_quads_along_shorter_diagonal`,
    as in the loop."""
    if b"\\\n" in block or not block.endswith(b"\n"):
        return None
    chars = np.frombuffer(block, dtype=np.uint8)
    ends = np.flatnonzero(chars == 10)
    starts = np.concatenate(([0], ends[:-1] + 1))
    length = ends - starts
    first = chars[starts]
    second = chars[np.minimum(starts + 1, len(chars) - 1)]
    spaced = (length >= 2) & ((second == 32) | (second == 9))
    is_v = spaced & (first == ord("v"))
    is_f = spaced & (first == ord("f"))
    loose = 0
    others = np.flatnonzero(~(is_v | is_f))
    # a ``vn``/``vt`` line is skipped by the loop: told apart here without looking at it in Python
    tex = (length >= 3) & (first == ord("v")) & ((second == ord("n")) | (second == ord("t")))
    third = chars[np.minimum(starts + 2, len(chars) - 1)]
    tex &= (third == 32) | (third == 9)
    for line in others[~tex[others]]:
        parts = block[starts[line]:ends[line]].split()
        if not parts or parts[0][:1] == b"#" or parts[0] in _OBJ_SKIPPED:
            continue
        if parts[0] in (b"l", b"p"):
            loose += 1
            continue
        return None
    n_v, n_f = int(np.count_nonzero(is_v)), int(np.count_nonzero(is_f))
    if nv + n_v > max_vertices:
        return None
    keyword = np.zeros(len(chars), dtype=bool)
    keyword[starts] = True                                      # the 'v' or 'f' itself
    coords = None
    if n_v:
        text = chars[np.repeat(is_v, length + 1) & ~keyword]
        if not text.tobytes().isascii() or np.any(text == ord("_")) \
                or np.any(_tokens_per_line(text) != 3):
            return None
        try:
            coords = np.array(text.tobytes().split(), dtype=np.float64).reshape(-1, 3)
        except ValueError:
            return None
    if not n_f:
        return _PlainBlock(coordinates=coords, triangles=None, quads=None, vertices=n_v, polygons=0, triangle_count=0,
                           loose=loose)
    text = chars[np.repeat(is_f, length + 1) & ~keyword]
    gap = _GAP[text]
    word_start = ~gap
    word_start[1:] &= gap[:-1]
    slash = text == ord("/")
    if np.any(word_start & slash):                              # a corner without a vertex index
        return None
    at = np.arange(len(text))
    tail = np.maximum.accumulate(np.where(slash, at, -1)) > np.maximum.accumulate(np.where(gap, at, -1))
    text = text[~tail]                                          # each corner's vertex index, its '/...' cut
    if not np.all(_INDEX_BYTE[text]):
        return None
    corners = _tokens_per_line(text)
    if corners.min() < 3 or corners.max() > 4:
        return None
    n_tri = int(np.sum(corners)) - 2 * n_f
    if n_tri > faces_left:
        return None
    try:
        index = np.array(text.tobytes().split(), dtype=np.int64)
    except OverflowError:                                      # past int64: the loop says it is past any vertex
        return None
    if index.min() < 1 or index.max() > max_vertices:
        return None
    index -= 1
    first_corner = np.cumsum(corners) - corners
    per_line = corners - 2                                     # each line's triangles
    first_triangle = np.cumsum(per_line) - per_line
    line = np.repeat(np.arange(n_f), per_line)
    second_of = np.arange(n_tri) - first_triangle[line]        # 0, or 1 for a quad's second triangle
    base = first_corner[line]
    tri = np.stack([index[base], index[base + 1 + second_of], index[base + 2 + second_of]], axis=1)
    return _PlainBlock(coordinates=coords, triangles=tri, quads=first_triangle[corners == 4], vertices=n_v,
                       polygons=n_f, triangle_count=n_tri, loose=loose)


def _read_obj(path: str, max_faces: int, data: bytes | None = None,
              plain_blocks: bool = True) -> tuple[np.ndarray, np.ndarray, int]:
    """Stream a Wavefront OBJ: ``v`` lines and ``f`` polygons (1-based or negative relative indices).

    A quadrilateral is split along its shorter diagonal (corners ``a b c d``: ``abc, acd`` when
    ``|ac| ≤ |bd|``, else ``abd, bcd``), the rule of MuJoCo's OBJ loader (checked against ``mujoco`` 4.0 on
    Menagerie's meshes): for a quad that is not planar the two splits bound different solids, and this one is
    the solid a simulator reading the same file integrates.  Polygons with more than four corners are
    ear-clipped as MuJoCo's loader clips them (:func:`~.polygons.clip_polygon_as_mujoco`; any triangulation of a planar
    polygon gives the same solid, so this matters for non-planar ones only).  Index 0, a relative index before the
    first vertex, or an index past the last vertex is refused with the line named, never dropped: a dropped face
    would silently change the volume.

    Returns ``vertices (n, 3)``, ``faces (m, 3)`` and the number of polygons in the file.  ``data``: the file's
    bytes if the caller has read them (:func:`load_mesh`), parsed instead of reading the file.
    ``plain_blocks``: read a block whose every line is plain without the loop over its lines
    (:func:`_plain_block`: the same arrays; issue 25, the Menagerie corpus read 191 OBJ files); False: every
    block line by line (the tests compare the two).
    """
    vertex_blocks: list[np.ndarray] = []
    face_blocks: list[np.ndarray] = []
    quad_blocks: list[tuple[int, np.ndarray]] = []       # (face block, first of its two triangles) per quad
    # (face block, [(first triangle, corners)]) per polygon of more than four corners
    polygon_blocks: list[tuple[int, list[tuple[int, list[int]]]]] = []
    nv = n_tri = n_poly = loose = garbage = 0
    first_garbage = ""
    line_no = 0
    pending = b""
    max_vertices = 3 * max_faces + 3
    with _source_bytes(path, data) as fh:
        for block in _text_blocks(fh, path):
            faces_left = min(max_faces, MAX_SUPPORTED_FACES) - n_tri
            plain = _plain_block(block, nv, max_vertices, faces_left) if plain_blocks and not pending else None
            if plain is not None:
                line_no += block.count(b"\n")
                if plain.coordinates is not None:
                    vertex_blocks.append(plain.coordinates)
                if plain.triangles is not None:
                    face_blocks.append(plain.triangles)
                    if plain.quads is not None and len(plain.quads):
                        quad_blocks.append((len(face_blocks) - 1, plain.quads))
                nv, n_poly, n_tri, loose = nv + plain.vertices, n_poly + plain.polygons, \
                    n_tri + plain.triangle_count, loose + plain.loose
                continue
            coords: list[bytes] = []
            coord_lines: list[int] = []                 # the line of each vertex, for an error message
            tri: list[int] = []
            quads: list[int] = []
            polygons: list[tuple[int, list[int]]] = []
            odd = _has_odd_bytes(block)                  # names and comments may hold '_'; numbers may not
            lines = block.split(b"\n")
            lines.pop()  # every block ends with a newline
            for raw in lines:
                line_no += 1
                if pending:
                    raw, pending = pending + raw, b""
                if raw.endswith(b"\\"):
                    pending = raw[:-1] + b" "
                    if len(pending) > MAX_LINE_BYTES:
                        raise _fail(path, f"line {line_no}: continued line longer than {MAX_LINE_BYTES:,} bytes")
                    continue
                parts = raw.split()
                if not parts or parts[0][:1] == b"#":
                    continue
                key = parts[0]
                if key == b"v":
                    if len(parts) < 4:
                        raise _fail(path, f"line {line_no}: a vertex needs 3 coordinates, found {len(parts) - 1}")
                    if odd and (bad := _odd_number(parts[1:4])) is not None:
                        raise _fail(path, f"line {line_no}: vertex coordinate "
                                          f"{bad[:40].decode('utf-8', 'replace')!r} is not a decimal number "
                                          "(no '_', ASCII digits only)")
                    coords.extend(parts[1:4])
                    coord_lines.append(line_no)
                    nv += 1
                    if nv > max_vertices:
                        raise _fail(path, f"holds more than {max_vertices:,} vertices (3 × `max_faces`)")
                elif key == b"f":
                    k = len(parts) - 1
                    if k < 3:
                        raise _fail(path, f"line {line_no}: a face needs at least 3 vertices, found {k}")
                    if odd and (bad := _odd_number([t.split(b"/", 1)[0] for t in parts[1:]])) is not None:
                        raise _fail(path, f"line {line_no}: face index {bad[:40].decode('utf-8', 'replace')!r} "
                                          "is not an integer (no '_', ASCII digits only)")
                    idx = []
                    for tok in parts[1:]:
                        try:
                            i = int(tok.split(b"/", 1)[0])
                        except ValueError:
                            raise _fail(path, f"line {line_no}: face index "
                                              f"{tok[:40].decode('utf-8', 'replace')!r} is not an integer") from None
                        if 0 < i <= max_vertices:
                            idx.append(i - 1)
                        elif i > 0:
                            raise _fail(path, f"line {line_no}: face index {str(i)[:24]} is past any vertex "
                                              f"this file may hold ({max_vertices:,} = 3 × `max_faces`)")
                        elif i < 0 and -i <= nv:
                            idx.append(nv + i)
                        elif i < 0:
                            raise _fail(path, f"line {line_no}: relative face index {i} points before the first "
                                              f"vertex ({nv:,} defined so far)")
                        else:
                            raise _fail(path, f"line {line_no}: face index 0 (OBJ indices start at 1)")
                    if k == 3:
                        tri.extend(idx)
                    elif k == 4:
                        quads.append(len(tri))          # split once the coordinates are known
                        tri.extend((idx[0], idx[1], idx[2], idx[0], idx[2], idx[3]))
                    else:                               # clipped as MuJoCo does once coordinates are known
                        polygons.append((len(tri) // 3, idx))
                        first = idx[0]
                        for j in range(1, k - 1):
                            tri.extend((first, idx[j], idx[j + 1]))
                    n_poly += 1
                    n_tri += k - 2
                    _check_face_budget(path, n_tri, max_faces)
                elif key in (b"l", b"p"):
                    loose += 1
                elif key not in _OBJ_SKIPPED:
                    if not garbage:
                        first_garbage = f" (first: line {line_no})"
                    garbage += 1
            if coords:
                vertex_blocks.append(_obj_vertex_block(path, coords, coord_lines))
            if tri:
                face_blocks.append(np.array(tri, dtype=np.int64).reshape(-1, 3))
                if quads:
                    quad_blocks.append((len(face_blocks) - 1, np.array(quads, dtype=np.int64) // 3))
                if polygons:
                    polygon_blocks.append((len(face_blocks) - 1, polygons))
    if not face_blocks:
        if nv == 0:
            raise _fail(path, "no vertices and no faces (empty mesh)")
        what = "points and lines only" if loose else "vertices only"
        raise _fail(path, f"contains no faces ({nv:,} vertices, {what}: a point cloud, not a solid)")
    vertices = np.concatenate(vertex_blocks) if vertex_blocks else np.zeros((0, 3))
    top = max(int(block.max()) for block in face_blocks)
    if top >= nv:
        raise _fail(path, f"face index {top + 1:,} is past the last vertex ({nv:,} defined)")
    warped, between = 0, 0.0
    for block_index, rows in quad_blocks:
        w, v6 = split_quads_along_shorter_diagonal(vertices, face_blocks[block_index], rows)
        warped, between = warped + w, between + v6
    differs = dropped = 0
    polygon_between = 0.0
    for block_index, polygons in polygon_blocks:
        d, _, v6, lost = clip_polygons(vertices, face_blocks[block_index], polygons)
        differs, polygon_between, dropped = differs + d, polygon_between + v6, dropped + lost
    faces = np.concatenate(face_blocks)
    if warped:
        warn_warped_quads(_display(path), vertices, faces, warped, sum(len(rows) for _, rows in quad_blocks), between)
    if differs:
        warn_clipped_polygons(_display(path), vertices, faces, differs, sum(len(p) for _, p in polygon_blocks),
                               polygon_between, dropped)
    if garbage:
        warnings.warn(MalformedTextWarning(f"{_display(path)}: {garbage:,} unrecognised lines were ignored"
                                           f"{first_garbage}"), stacklevel=4)
    faces = faces.astype(np.int32) if nv < 2**31 - 1 else faces
    return vertices, faces, n_poly
