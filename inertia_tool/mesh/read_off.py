"""Reading OFF natively: the header's counts checked against the file size, quads and larger polygons cut."""

from __future__ import annotations

import numpy as np

from .polygons import clip_polygons, warn_clipped_polygons
from .read_base import _check_face_budget, _Counts, _display, _fail, _header_count
from .regular import open_regular


def _check_off_header(path: str, size: int, max_faces: int) -> _Counts:
    """Check the vertex and face counts of an OFF header against the file size."""
    with open_regular(path) as fh:
        head = fh.read(1 << 16)
    words = []
    for line in head.replace(b"\r", b"\n").split(b"\n")[:1000]:
        words += line.split(b"#", 1)[0].split()
        if len(words) >= 4:
            break
    if words and b"OFF" in words[0] and words[0].index(b"OFF") + 3 < len(words[0]) \
            and words[0][words[0].index(b"OFF") + 3:].isdigit():
        # "OFF8 6 12": the keyword run into the vertex count, which readers accept
        cut = words[0].index(b"OFF") + 3
        words = [words[0][:cut], words[0][cut:]] + words[1:]
    if not words or not words[0].endswith(b"OFF"):
        raise _fail(path, "not an OFF file (no 'OFF' keyword at the start)")
    if len(words) < 3:
        raise _fail(path, "OFF header without vertex and face counts")
    nv, nf = _header_count(path, words[1]), _header_count(path, words[2])
    if 6 * nv + 8 * nf > size:
        raise _fail(path, f"OFF header announces {nv:,} vertices and {nf:,} faces but the file has only {size:,} "
                          "bytes: truncated or lying header")
    _check_face_budget(path, nf, max_faces)
    return {"vertex": nv, "face": nf}


def _off_ints(path: str, tokens: list[bytes], what: str) -> list[int]:
    try:
        return [int(t) for t in tokens]
    except ValueError:
        found = b' '.join(tokens)[:60].decode(errors='replace')
        raise _fail(path, f"{what}: expected integers, found {found!r}") from None


def _read_off(path: str, max_faces: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Read an OFF file (``[C|N|ST…]OFF``, the counts on the keyword's line or the next, ``#`` comments, blank
    lines, colours after a vertex's three coordinates or a face's corners ignored).

    Faces of three corners are triangles; a quadrilateral ``abcd`` is cut ``abc, cda`` (as trimesh cut it, which
    read OFF here before); a polygon of more corners is cut as an OBJ polygon (:func:`.polygons.clip_polygons`),
    so a planar one, convex or not, gives triangles that do not overlap.  Indices are 0-based; one outside
    ``0..n−1`` is refused with the face named.  Returns ``vertices (n, 3)``, ``faces (m, 3)`` and the number of
    faces in the file.  (trimesh 5.2's reader fails on polygons of five or more corners under numpy 2.)
    """
    with open_regular(path) as fh:
        text = fh.read()
    lines = []
    for raw in text.replace(b"\r", b"\n").split(b"\n"):
        words = raw.split(b"#", 1)[0].split()
        if words:
            lines.append(words)
    if not lines or b"OFF" not in lines[0][0]:
        raise _fail(path, "not an OFF file (no 'OFF' keyword at the start)")
    head = lines[0]
    rest = head[0][head[0].index(b"OFF") + 3:]
    counts_words = ([rest] if rest else []) + head[1:]
    body = 1
    if not counts_words:
        if len(lines) < 2:
            raise _fail(path, "OFF header without vertex and face counts")
        counts_words, body = lines[1], 2
    counts = _off_ints(path, counts_words[:2], "OFF header counts")
    if len(counts) < 2:
        raise _fail(path, "OFF header without vertex and face counts")
    nv, nf = counts
    _check_face_budget(path, nf, max_faces)
    if len(lines) < body + nv + nf:
        raise _fail(path, f"OFF header announces {nv:,} vertices and {nf:,} faces but the file has only "
                          f"{max(len(lines) - body, 0):,} data lines: truncated or lying header")
    rows = lines[body:body + nv]
    if any(len(r) < 3 for r in rows):
        raise _fail(path, "a vertex line has fewer than three coordinates")
    try:
        vertices = np.array([[float(x) for x in r[:3]] for r in rows], dtype=np.float64).reshape(-1, 3)
    except ValueError:
        raise _fail(path, "a vertex coordinate is not a number") from None
    tri: list[int] = []
    polygons: list[tuple[int, list[int]]] = []
    for j, words in enumerate(lines[body + nv:body + nv + nf]):
        k = _off_ints(path, words[:1], f"face {j}")[0]
        if k < 3 or len(words) < k + 1:
            raise _fail(path, f"face {j} has {k} corners" + ("" if k < 3 else f" but lists {len(words) - 1}"))
        idx = _off_ints(path, words[1:k + 1], f"face {j}")
        if min(idx) < 0 or max(idx) >= nv:
            raise _fail(path, f"face {j} has a vertex index outside 0..{nv - 1}")
        if k == 4:
            idx = [idx[0], idx[1], idx[2], idx[2], idx[3], idx[0]]
        elif k > 4:
            polygons.append((len(tri) // 3, idx))
            idx = [c for i in range(1, k - 1) for c in (idx[0], idx[i], idx[i + 1])]
        tri += idx
    if not tri:
        raise _fail(path, "contains no triangles (empty mesh or point cloud)")
    faces = np.array(tri, dtype=np.int64).reshape(-1, 3)
    _check_face_budget(path, len(faces), max_faces)
    if polygons:
        differs, _, between, dropped = clip_polygons(vertices, faces, polygons)
        if differs:
            warn_clipped_polygons(_display(path), vertices, faces, differs, len(polygons), between, dropped)
    if not np.all(np.isfinite(vertices)):
        raise _fail(path, "vertices have NaN or infinite coordinates")
    return vertices, faces, nf
