"""PLY: the header checked against the file size before any parser allocates, and polygons of more than four
corners cut as OBJ's (:func:`.polygons.clip_polygons`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .polygons import clip_polygons, warn_clipped_polygons
from .read_base import _check_face_budget, _Counts, _display, _fail, _header_count
from .regular import open_regular

_PLY_TYPE_BYTES = {b"char": 1, b"int8": 1, b"uchar": 1, b"uint8": 1, b"short": 2, b"int16": 2, b"ushort": 2,
                   b"uint16": 2, b"int": 4, b"int32": 4, b"uint": 4, b"uint32": 4, b"float": 4, b"float32": 4,
                   b"double": 8, b"float64": 8}


def _check_ply_header(path: str, size: int, max_faces: int) -> _Counts:
    """Check what a PLY header announces against the file size before any parser allocates for it."""
    with open_regular(path) as fh:
        head = fh.read(1 << 16)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise _fail(path, "not a PLY file (no 'ply' magic, or no 'end_header' within 64 KiB)")
    fmt = None
    vertex_float32 = False
    elements: list[list[Any]] = []          # per element: [name, count, bytes per item]
    # per element and property: (bytes of the property or of a list's count, bytes of a list item)
    layouts: list[list[tuple[int, int]]] = []
    for line in head[:end].replace(b"\r", b"\n").split(b"\n")[1:]:
        parts = line.split()
        if not parts:
            continue
        if parts[0] == b"format" and len(parts) >= 2:
            fmt = parts[1]
        elif parts[0] == b"element":
            if len(parts) != 3:
                raise _fail(path, f"malformed PLY element line {line[:60].decode('utf-8', 'replace')!r}")
            elements.append([parts[1], _header_count(path, parts[2]), 0])
            layouts.append([])
        elif parts[0] == b"property":
            if not elements:
                raise _fail(path, "PLY property before any element")
            kind = parts[2] if parts[1:2] == [b"list"] and len(parts) >= 3 else parts[1:2][0] if len(parts) > 1 else b""
            if kind not in _PLY_TYPE_BYTES:
                raise _fail(path, f"unknown PLY property type {kind[:20].decode('utf-8', 'replace')!r}")
            if elements[-1][0] == b"vertex" and parts[-1:] == [b"x"] and kind in (b"float", b"float32"):
                vertex_float32 = True
            elements[-1][2] += 2 if fmt == b"ascii" else _PLY_TYPE_BYTES[kind]
            is_list = parts[1:2] == [b"list"] and len(parts) >= 4
            item = parts[3] if is_list else b""
            if is_list and item not in _PLY_TYPE_BYTES:
                raise _fail(path, f"unknown PLY property type {item[:20].decode('utf-8', 'replace')!r}")
            layouts[-1].append((_PLY_TYPE_BYTES[kind], _PLY_TYPE_BYTES[item] if is_list else 0))
    if fmt not in (b"ascii", b"binary_little_endian", b"binary_big_endian"):
        raise _fail(path, f"unknown PLY format {fmt!r}")
    body = size - (end + len(b"end_header") + 1)
    need = sum(count * max(per, 1) for _, count, per in elements)
    counts = {name.decode("utf-8", "replace"): count for name, count, _ in elements}
    if need > body:
        claimed = ", ".join(f"{c:,} {n}" for n, c in counts.items())
        raise _fail(path, f"PLY header announces {claimed} (at least {need:,} bytes of data) but the file holds "
                          f"only {max(body, 0):,}: truncated or lying header")
    _check_face_budget(path, counts.get("face", 0), max_faces)
    if counts.get("vertex", 0) > 3 * max_faces + 3:
        raise _fail(path, f"holds {counts['vertex']:,} vertices, more than 3 × `max_faces`")
    if fmt != b"ascii":
        _check_ply_polygons(path, elements, layouts, body, max_faces)
    counts["float32"] = int(vertex_float32)
    return counts


def _check_ply_polygons(path: str, elements: list[list[Any]], layouts: list[list[tuple[int, int]]], body: int,
                        max_faces: int) -> None:
    """Refuse a binary PLY whose polygons may triangulate into more than ``max_faces`` triangles.

    The header gives the number of faces ``n``, not their corners: a face of ``k`` corners becomes ``k − 2``
    triangles, and one of 255 corners costs only ``1 + 4 · 255`` bytes.  When every element before ``face``
    has a fixed record size and ``face`` has the one list property (count of ``c`` bytes, indices of ``s``),
    the bytes left for the faces, ``F``, hold ``Σ k = (F − n c) / s`` corners, so the triangles number at most
    ``(F − n c) / s − 2 n`` (exact when nothing follows the faces).  Checked before any parser allocates.
    """
    skipped = 0
    for (name, count, per), layout in zip(elements, layouts):
        if name == b"face":
            if len(layout) != 1 or layout[0][1] == 0:
                return
            count_bytes, item_bytes = layout[0]
            corners = (body - skipped - count * count_bytes) // item_bytes
            triangles = corners - 2 * count
            if triangles > max_faces:
                raise _fail(path, f"PLY faces ({count:,} polygons in {body - skipped:,} bytes) may hold up to "
                                  f"{triangles:,} triangles, more than `max_faces` ({max_faces:,}) allows; refused "
                                  "before reading")
            return
        if any(item for _, item in layout):
            return                              # a list before the faces: their offset is not known
        skipped += count * per


def _ply_polygons_clipped(path: str, loaded: Any, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``faces`` with the PLY's polygons of more than four corners cut as OBJ's are
    (:func:`.polygons.clip_polygons`) instead of trimesh's first-corner fan, which overlaps itself on a
    non-convex polygon and would read as a surface passing through itself; triangles and quads as trimesh cut
    them.  ``faces`` unchanged when the file has no such polygon or trimesh kept no raw face lists."""
    try:
        raw = loaded.metadata["_ply_raw"]
        lists = raw["face"]["data"]["vertex_indices"]
        if int(raw["vertex"]["length"]) != len(vertices):
            return faces                   # trimesh split or merged vertices: the lists' indices are not ours
    except (KeyError, TypeError, AttributeError, ValueError):
        return faces
    if not isinstance(lists, np.ndarray) or lists.dtype != object:
        return faces                       # one list length for every face: no polygon of mixed size
    sizes = np.fromiter((len(p) for p in lists), dtype=np.int64, count=len(lists))
    if not np.any(sizes > 4) or int(np.sum(np.maximum(sizes - 2, 0))) != len(faces):
        return faces
    rows: list[list[int]] = []
    polygons: list[tuple[int, list[int]]] = []
    for corners in lists:
        idx = [int(i) for i in corners]
        if len(idx) == 4:
            rows += [[idx[0], idx[1], idx[2]], [idx[2], idx[3], idx[0]]]
        else:
            if len(idx) > 4:
                polygons.append((len(rows), idx))
            rows += [[idx[0], idx[j], idx[j + 1]] for j in range(1, len(idx) - 1)]
    cut = np.array(rows, dtype=np.int64)
    if cut.min() < 0 or cut.max() >= len(vertices):
        return faces
    differs, _, between, dropped = clip_polygons(vertices, cut, polygons)
    if differs:
        warn_clipped_polygons(_display(path), vertices, cut, differs, len(polygons), between, dropped)
    return cut.astype(faces.dtype)
