"""Reading PLY: the header checked against the file size before anything is allocated, binary files read natively
(any list count and index types, either byte order, other properties and elements skipped), ASCII files through
trimesh; polygons of more than four corners cut as OBJ's (:func:`.polygons.clip_polygons`), in both.

A binary body is read with one structured numpy dtype per element when every record has the same size (a mesh of
triangles: each face record is the count and three indices), and walked record by record only when a list's
length varies (mixed polygons); the face lists then become triangles through :func:`_cut_face_lists`, which the
ASCII path uses on trimesh's raw face lists too.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any

import numpy as np

from .polygons import clip_polygons, warn_clipped_polygons
from .read_base import _check_face_budget, _Counts, _display, _fail, _header_count
from .regular import open_regular

_PLY_TYPE_BYTES = {b"char": 1, b"int8": 1, b"uchar": 1, b"uint8": 1, b"short": 2, b"int16": 2, b"ushort": 2,
                   b"uint16": 2, b"int": 4, b"int32": 4, b"uint": 4, b"uint32": 4, b"float": 4, b"float32": 4,
                   b"double": 8, b"float64": 8}
#: numpy's code of each PLY type (the byte order is added per file).
_PLY_NUMPY = {b"char": "i1", b"int8": "i1", b"uchar": "u1", b"uint8": "u1", b"short": "i2", b"int16": "i2",
              b"ushort": "u2", b"uint16": "u2", b"int": "i4", b"int32": "i4", b"uint": "u4", b"uint32": "u4",
              b"float": "f4", b"float32": "f4", b"double": "f8", b"float64": "f8"}
#: The names exporters give the face element's list of corner indices (trimesh reads the same two).
_INDEX_NAMES = (b"vertex_indices", b"vertex_index")


@dataclass(frozen=True)
class _PlyProperty:
    """One property of a PLY element: ``kind`` its type (a list's item type), ``count`` a list's count type or
    ``None`` for a scalar (both PLY type names, as the header spells them)."""

    name: bytes
    kind: bytes
    count: bytes | None = None


@dataclass(frozen=True)
class _PlyElement:
    """One element of a PLY header: its name, record count and properties in file order."""

    name: bytes
    count: int
    properties: tuple[_PlyProperty, ...]


@dataclass(frozen=True)
class _PlyHeader:
    """What a PLY header declares: ``fmt`` (``ascii``, ``binary_little_endian``, ``binary_big_endian``), the
    byte offset where the body starts, and the elements in file order."""

    fmt: bytes
    body_start: int
    elements: tuple[_PlyElement, ...]


def _parse_ply_header(path: str, head: bytes) -> _PlyHeader:
    """The header at the start of ``head`` (the file's first 64 KiB), each type checked against the PLY names."""
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise _fail(path, "not a PLY file (no 'ply' magic, or no 'end_header' within 64 KiB)")
    fmt = None
    elements: list[tuple[bytes, int, list[_PlyProperty]]] = []
    for line in head[:end].replace(b"\r", b"\n").split(b"\n")[1:]:
        parts = line.split()
        if not parts:
            continue
        if parts[0] == b"format" and len(parts) >= 2:
            fmt = parts[1]
        elif parts[0] == b"element":
            if len(parts) != 3:
                raise _fail(path, f"malformed PLY element line {line[:60].decode('utf-8', 'replace')!r}")
            elements.append((parts[1], _header_count(path, parts[2]), []))
        elif parts[0] == b"property":
            if not elements:
                raise _fail(path, "PLY property before any element")
            is_list = parts[1:2] == [b"list"]
            types = parts[2:4] if is_list else parts[1:2]
            for kind in types or [b""]:
                if kind not in _PLY_TYPE_BYTES:
                    raise _fail(path, f"unknown PLY property type {kind[:20].decode('utf-8', 'replace')!r}")
            if len(parts) != (5 if is_list else 3):
                raise _fail(path, f"malformed PLY property line {line[:60].decode('utf-8', 'replace')!r}")
            elements[-1][2].append(_PlyProperty(parts[-1], types[-1], types[0] if is_list else None))
    if fmt not in (b"ascii", b"binary_little_endian", b"binary_big_endian"):
        raise _fail(path, f"unknown PLY format {fmt!r}")
    body_start = end + len(b"end_header") + 1
    if head[body_start - 1:body_start + 1] == b"\r\n":
        body_start += 1                         # a CR LF after end_header (written on Windows)
    return _PlyHeader(fmt, body_start, tuple(_PlyElement(n, c, tuple(p)) for n, c, p in elements))


def _check_ply_header(path: str, size: int, max_faces: int) -> _Counts:
    """Check what a PLY header announces against the file size before any parser allocates for it."""
    with open_regular(path) as fh:
        header = _parse_ply_header(path, fh.read(1 << 16))
    ascii_ = header.fmt == b"ascii"
    # per element: [name, count, bytes per item]; per element and property: (bytes of the property or of a
    # list's count, bytes of a list item)
    elements: list[list[Any]] = [[e.name, e.count, sum(2 if ascii_ else _PLY_TYPE_BYTES[p.count or p.kind]
                                                       for p in e.properties)] for e in header.elements]
    layouts = [[(_PLY_TYPE_BYTES[p.count or p.kind], _PLY_TYPE_BYTES[p.kind] if p.count else 0)
                for p in e.properties] for e in header.elements]
    vertex_float32 = any(e.name == b"vertex" and p.name == b"x" and p.count is None and p.kind in (b"float", b"float32")
                         for e in header.elements for p in e.properties)
    body = size - header.body_start
    need = sum(count * max(per, 1) for _, count, per in elements)
    counts = {name.decode("utf-8", "replace"): count for name, count, _ in elements}
    if need > body:
        claimed = ", ".join(f"{c:,} {n}" for n, c in counts.items())
        raise _fail(path, f"PLY header announces {claimed} (at least {need:,} bytes of data) but the file holds "
                          f"only {max(body, 0):,}: truncated or lying header")
    _check_face_budget(path, counts.get("face", 0), max_faces)
    if counts.get("vertex", 0) > 3 * max_faces + 3:
        raise _fail(path, f"holds {counts['vertex']:,} vertices, more than 3 × `max_faces`")
    if not ascii_:
        _check_ply_polygons(path, elements, layouts, body, max_faces)
    counts["float32"] = int(vertex_float32)
    counts["binary"] = int(not ascii_)
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
    """``faces`` of an ASCII PLY read by trimesh, cut again from trimesh's raw face lists by
    :func:`_cut_face_lists` when some list has more than four corners (trimesh fans those from the first corner,
    which overlaps itself on a non-convex polygon and would read as a surface passing through itself).
    ``faces`` unchanged when the file has no such polygon or trimesh kept no raw face lists."""
    try:
        raw = loaded.metadata["_ply_raw"]
        lists = raw["face"]["data"]["vertex_indices"]
        if int(raw["vertex"]["length"]) != len(vertices):
            return faces                   # trimesh split or merged vertices: the lists' indices are not ours
    except (KeyError, TypeError, AttributeError, ValueError):
        return faces
    if not isinstance(lists, np.ndarray):
        return faces
    if lists.dtype == object:
        sizes = np.fromiter((len(p) for p in lists), dtype=np.int64, count=len(lists))
        flat = np.concatenate([np.asarray(p, dtype=np.int64).ravel() for p in lists]) if len(lists) else sizes
    elif lists.ndim == 2:                  # one list length for every face
        sizes = np.full(len(lists), lists.shape[1], dtype=np.int64)
        flat = lists.astype(np.int64).ravel()
    else:
        return faces
    if not np.any(sizes > 4) or int(np.sum(np.maximum(sizes - 2, 0))) != len(faces):
        return faces
    if len(flat) != int(sizes.sum()) or flat.min() < 0 or flat.max() >= len(vertices):
        return faces
    return _cut_face_lists(path, vertices, sizes, flat).astype(faces.dtype)


def _cut_face_lists(path: str, vertices: np.ndarray, sizes: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """Triangles ``(m, 3)`` int64 of PLY face lists, in file order: a triangle as it is, a quadrilateral ``abcd``
    as ``abc, cda`` (as trimesh cuts it), a polygon of more corners as an OBJ's (:func:`.polygons.clip_polygons`,
    with its warning when the cut changes the solid); a list of fewer than three corners encloses nothing and
    gives no triangle.

    Parameters
    ----------
    vertices : (n, 3) float64
    sizes : (p,) int
        Corners of each face list.
    flat : (sizes.sum(),) int
        The lists' indices one after another, each in ``0..n-1`` (checked by the caller).
    """
    if len(sizes) and int(sizes.min()) == int(sizes.max()) == 3:
        return flat.reshape(-1, 3).astype(np.int64, copy=False)
    sizes = sizes.astype(np.int64)
    starts = np.cumsum(sizes) - sizes
    keep = sizes >= 3
    sizes, starts = sizes[keep], starts[keep]
    per = sizes - 2
    owner = np.repeat(np.arange(len(sizes)), per)                    # the face list of each triangle
    first_row = np.cumsum(per) - per
    j = np.arange(int(per.sum())) - first_row[owner] + 1               # 1 .. k-2 within its list
    base = starts[owner]
    cut = np.stack([flat[base], flat[base + j], flat[base + j + 1]], axis=1).astype(np.int64)
    quads = first_row[sizes == 4] + 1                                  # the fan's a c d -> c d a
    cut[quads] = cut[quads][:, [1, 2, 0]]
    large = np.flatnonzero(sizes > 4)
    polygons = [(int(first_row[i]), flat[starts[i]:starts[i] + sizes[i]].tolist())
                for i in large[~_fan_is_a_cut(vertices, cut, first_row[large], per[large])]]
    if polygons:
        differs, _, between, dropped = clip_polygons(vertices, cut, polygons)
        if differs:
            warn_clipped_polygons(_display(path), vertices, cut, differs, len(polygons), between, dropped)
    return cut


def _fan_is_a_cut(vertices: np.ndarray, fans: np.ndarray, first_row: np.ndarray, per: np.ndarray) -> np.ndarray:
    """Per polygon (its first-corner fan: rows ``first_row .. first_row + per − 1`` of ``fans``): whether the fan
    already cuts it into triangles that do not overlap, so that clipping it (:func:`.polygons.clip_polygons`,
    ~0.4 ms a hexagon in Python) would only give another cut of the same planar region.

    True only when every corner lies exactly (in float64) on the plane through the first corner normal to
    ``n = Σ (p_j − p_0) × (p_{j+1} − p_0)`` (the planarity test :func:`.polygons.clip_polygons` makes) and every
    fan triangle faces along ``n`` (the test it applies to its own triangles, ``polygons._overlapping``): the
    triangles are then sectors about the first corner in increasing angle, disjoint, covering the polygon (their
    signed areas sum to its area), and any other cut of it bounds the same solid.  A polygon in a tilted plane
    rarely passes the exact test and is clipped as before."""
    if not len(per):
        return np.zeros(0, dtype=bool)
    rows = np.repeat(first_row, per) + (np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per))
    origin = vertices[fans[rows, 0]]
    cross = np.cross(vertices[fans[rows, 1]] - origin, vertices[fans[rows, 2]] - origin)
    normal = np.add.reduceat(cross, np.cumsum(per) - per, axis=0)
    along = np.einsum("ij,ij->i", cross, np.repeat(normal, per, axis=0)) > 0
    planar = np.einsum("ij,ij->i", vertices[fans[rows, 2]] - origin, np.repeat(normal, per, axis=0)) == 0
    first = np.cumsum(per) - per
    second_on_plane = np.einsum("ij,ij->i", vertices[fans[first_row, 1]] - vertices[fans[first_row, 0]], normal) == 0
    cut: np.ndarray = np.logical_and.reduceat(along & planar, first) & second_on_plane
    return cut


def _read_binary_ply(path: str) -> tuple[np.ndarray, np.ndarray] | None:
    """``(vertices (n, 3) float64, faces (m, 3) int64)`` of a binary PLY (its header already checked by
    :func:`_check_ply_header`), or None when its layout is not a mesh this reader knows (no ``vertex`` element
    with scalar ``x y z``, no ``face`` element with a list of corner indices): trimesh reads those.

    Each element is read with one structured dtype when its records have one size: an element without lists,
    or one whose every list has the length of its first record's (a mesh of triangles: one ``frombuffer`` of
    the faces).  Otherwise its records are walked one by one (:func:`_walk_lists`).  Faces are cut by
    :func:`_cut_face_lists`; indices are checked in range here, coordinates by the caller.
    """
    with open_regular(path) as fh:
        data = fh.read()
    header = _parse_ply_header(path, data[:1 << 16])
    order = "<" if header.fmt == b"binary_little_endian" else ">"
    by_name = {e.name: e for e in header.elements}
    vertex, face = by_name.get(b"vertex"), by_name.get(b"face")
    if (vertex is None or face is None or any(p.count for p in vertex.properties)
            or len(by_name) != len(header.elements)):
        return None
    names = [p.name for p in vertex.properties]
    lists = [p for p in face.properties if p.count]
    index = next((p for n in _INDEX_NAMES for p in lists if p.name == n), lists[0] if len(lists) == 1 else None)
    if any(n not in names for n in (b"x", b"y", b"z")) or index is None:
        return None
    if _PLY_NUMPY[index.kind][0] == "f" or (index.count is not None and _PLY_NUMPY[index.count][0] == "f"):
        raise _fail(path, "PLY face lists must hold integers (declared "
                          f"list {(index.count or b'').decode()} {index.kind.decode()})")
    vertices = faces = None
    offset = header.body_start
    for element in header.elements:
        if element.name == b"vertex":
            records, offset = _fixed_records(path, data, offset, element, order)
            vertices = np.stack([records[n].astype(np.float64) for n in ("x", "y", "z")], axis=1)
        elif element.name == b"face":
            sizes, flat, offset = _face_lists(path, data, offset, element, index, order)
            if len(flat) and (int(flat.min()) < 0 or int(flat.max()) >= vertex.count):
                raise _fail(path, f"face indices out of range (0..{vertex.count - 1})")
            faces = (sizes, flat)
        else:
            offset = _skip_element(path, data, offset, element, order)
        if vertices is not None and faces is not None:
            break
    if vertices is None or faces is None:       # not reached: both elements are in the header, read above
        return None
    return vertices, _cut_face_lists(path, vertices, *faces)


def _numpy_type(order: str, kind: bytes) -> np.dtype[Any]:
    return np.dtype(order + _PLY_NUMPY[kind])


def _record_dtype(element: _PlyElement, order: str, lengths: list[int]) -> np.dtype[Any]:
    """The structured dtype of ``element``'s records when its lists hold ``lengths`` items (in list order)."""
    fields: list[tuple[str, Any] | tuple[str, Any, tuple[int, ...]]] = []
    it = iter(lengths)
    for k, p in enumerate(element.properties):
        name = f"{p.name.decode('utf-8', 'replace')}#{k}" if p.count else p.name.decode("utf-8", "replace")
        if p.count:
            fields.append((f"{name}:count", _numpy_type(order, p.count)))
            fields.append((name, _numpy_type(order, p.kind), (next(it),)))
        elif name not in [f[0] for f in fields]:
            fields.append((name, _numpy_type(order, p.kind)))
        else:                                   # a repeated name: kept apart (never read)
            fields.append((f"{name}#{k}", _numpy_type(order, p.kind)))
    return np.dtype(fields)


def _fixed_records(path: str, data: bytes, offset: int, element: _PlyElement,
                   order: str, lengths: list[int] | None = None) -> tuple[np.ndarray, int]:
    """The records of ``element`` from ``offset`` as one structured array, and the offset after them."""
    dtype = _record_dtype(element, order, lengths or [])
    end = offset + element.count * dtype.itemsize
    if end > len(data):
        raise _fail(path, f"ended inside the PLY element {element.name.decode('utf-8', 'replace')!r} (truncated)")
    return np.frombuffer(data, dtype=dtype, count=element.count, offset=offset), end


def _first_lengths(path: str, data: bytes, offset: int, element: _PlyElement, order: str) -> list[int]:
    """The lengths of the lists of ``element``'s first record."""
    lengths = []
    for p in element.properties:
        if p.count:
            count_type = _numpy_type(order, p.count)
            if offset + count_type.itemsize > len(data):
                raise _fail(path, f"ended inside the PLY element {element.name.decode('utf-8', 'replace')!r} "
                                  "(truncated)")
            n = int(np.frombuffer(data, dtype=count_type, count=1, offset=offset)[0])
            lengths.append(max(n, 0))
            offset += count_type.itemsize + max(n, 0) * _PLY_TYPE_BYTES[p.kind]
        else:
            offset += _PLY_TYPE_BYTES[p.kind]
    return lengths


def _uniform_records(path: str, data: bytes, offset: int, element: _PlyElement,
                     order: str) -> tuple[np.ndarray, int] | None:
    """:func:`_fixed_records` of an element with lists when every record's lists have the first record's
    lengths (checked on every count), else None."""
    if element.count == 0:
        return _fixed_records(path, data, offset, element, order, [0] * sum(1 for p in element.properties if p.count))
    lengths = _first_lengths(path, data, offset, element, order)
    dtype = _record_dtype(element, order, lengths)
    if offset + element.count * dtype.itemsize > len(data):
        return None
    records, end = _fixed_records(path, data, offset, element, order, lengths)
    counts = [f for f in dtype.names or () if f.endswith(":count")]
    if all(np.all(records[f] == n) for f, n in zip(counts, lengths)):
        return records, end
    return None


def _walk_lists(path: str, data: bytes, offset: int, element: _PlyElement, order: str,
                want: _PlyProperty | None) -> tuple[np.ndarray, np.ndarray, int]:
    """Walk ``element``'s records one by one (their lists differ in length): ``(lengths, item offsets, end)``
    of the list ``want`` (empty arrays when None).  Bounded by the element's count; every count is checked to
    be non-negative and every record to end inside the file."""
    # per property: (struct of a list's count or None for a scalar, bytes of the scalar or a list item, wanted)
    steps: list[tuple[struct.Struct | None, int, bool]] = []
    for p in element.properties:
        if p.count:
            code = _numpy_type(order, p.count)
            steps.append((struct.Struct(order + code.char), _PLY_TYPE_BYTES[p.kind], p is want))
        else:
            steps.append((None, _PLY_TYPE_BYTES[p.kind], False))
    lengths: list[int] = []
    starts: list[int] = []
    size = len(data)
    name = element.name.decode("utf-8", "replace")
    for _ in range(element.count):
        for count, item, wanted in steps:
            if count is None:
                offset += item
                continue
            try:
                n = count.unpack_from(data, offset)[0]
            except struct.error:
                raise _fail(path, f"ended inside the PLY element {name!r} (truncated)") from None
            if n < 0:
                raise _fail(path, f"a list of the PLY element {name!r} has a negative length ({n})")
            offset += count.size
            if wanted:
                lengths.append(n)
                starts.append(offset)
            offset += n * item
        if offset > size:
            raise _fail(path, f"ended inside the PLY element {name!r} (truncated)")
    return np.array(lengths, dtype=np.int64), np.array(starts, dtype=np.int64), offset


def _face_lists(path: str, data: bytes, offset: int, element: _PlyElement, index: _PlyProperty,
                order: str) -> tuple[np.ndarray, np.ndarray, int]:
    """``(lengths (p,), indices (Σ lengths,) int64, end offset)`` of the face element's list ``index``."""
    uniform = _uniform_records(path, data, offset, element, order)
    if uniform is not None:
        records, end = uniform
        k = element.properties.index(index)
        field = f"{index.name.decode('utf-8', 'replace')}#{k}"
        items = records[field]
        return (np.full(len(records), items.shape[1], dtype=np.int64), items.astype(np.int64).ravel(), end)
    lengths, starts, end = _walk_lists(path, data, offset, element, order, index)
    item = _numpy_type(order, index.kind)
    first = np.repeat(starts, lengths)
    within = np.arange(len(first)) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    at = first + within * item.itemsize
    raw = np.frombuffer(data, dtype=np.uint8)
    flat = raw[at[:, None] + np.arange(item.itemsize)].copy().view(item).ravel()
    return lengths, flat.astype(np.int64), end


def _skip_element(path: str, data: bytes, offset: int, element: _PlyElement, order: str) -> int:
    """The offset after an element this reader does not use."""
    if not any(p.count for p in element.properties):
        return _fixed_records(path, data, offset, element, order)[1]
    uniform = _uniform_records(path, data, offset, element, order)
    return uniform[1] if uniform is not None else _walk_lists(path, data, offset, element, order, None)[2]
