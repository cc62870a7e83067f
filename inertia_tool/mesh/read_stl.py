"""Reading STL natively: binary files with numpy in bounded chunks, ASCII files streamed with their structure
checked.

Binary STL is read directly with numpy in bounded chunks (much faster than a general loader), and shared
corners are welded exactly (bit-identical coordinates) into an indexed mesh on the way, so the triangle
soup never has to exist in float64.  With the C extension (``inertia_tool._native``) the welder reads the
corners straight from each chunk of file records, in one pass.  A binary header's triangle count is checked
against the file size before anything is allocated for it.
"""

from __future__ import annotations

import io
import os
import re
import warnings
from collections.abc import Callable, Iterator
from typing import cast

import numpy as np

from .._native import accel, threads
from ..errors import MalformedTextWarning, MeshReadError, TrailingDataWarning
from .options import DEFAULT_MAX_FACES
from .read_base import (_bad_line, _check_face_budget, _display, _fail, _has_odd_bytes, _odd_number, _source_bytes,
                        _text_blocks)
from .regular import open_regular
from .weld import weld_exact, weld_exact_stream

_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
_CHUNK_FACES = 1 << 17


def _looks_ascii_stl(head: bytes) -> bool:
    text = head.lstrip()
    if not text[:5].lower() == b"solid":
        return False
    # a binary STL may start with "solid" in its header; ASCII has "facet" soon and no NUL bytes
    window = head[:1024]
    return b"\x00" not in window and (b"facet" in window.lower() or b"endsolid" in window.lower()
                                      or len(head) < 84)


def _binary_stl_count(path: str, size: int, max_faces: int, announced: int = -1) -> int:
    """Validate a binary STL's header against its size (before allocating) and return the triangle count
    (``announced``: the header's count when the caller has read it already, else -1 to read it here)."""
    if size < 84:
        raise _fail(path, f"too short for a binary STL ({size} bytes; the header alone is 84)")
    if announced >= 0:
        n = announced
    else:
        with open_regular(path) as fh:
            fh.seek(80)
            n = int(np.frombuffer(fh.read(4), dtype="<u4")[0])
    available = (size - 84) // 50
    if n > available:
        raise _fail(path, f"binary STL header announces {n:,} triangles but the file holds at most "
                          f"{available:,} ({size:,} bytes): truncated or not an STL")
    _check_face_budget(path, n, max_faces)
    extra = size - 84 - 50 * n
    if extra:
        warnings.warn(TrailingDataWarning(f"{_display(path)}: {extra:,} bytes after the {n:,} triangles the "
                                          "header announces were ignored"), stacklevel=4)
    return n


def _binary_stl_chunks(path: str, n: int, *, padded: bool = True,
                       whole: bytes | None = None) -> Callable[[], Iterator[np.ndarray]]:
    """A factory of iterators over the corners of a binary STL, in file order.

    ``padded``: ``(k, 4)`` float32 copies ``(x, y, z, 0)`` checked for NaN and infinity (the layout lets the
    numpy welder hash a corner as two 64-bit words); otherwise ``(k, 3, 3)`` float32 views into the chunk's
    50-byte records, unchecked (the caller checks the welded vertices), each valid only until the next is
    taken: the records of every chunk are read into one buffer (``readinto``; a fresh 6.5 MB array per chunk
    cost its page faults every chunk, a quarter of the read's system time).  Each call re-reads the file in
    bounded chunks (a second read comes from the page cache), so the whole triangle soup is never held in
    memory.  ``whole``: the file's bytes when the caller has read all of them already (a small file), read
    from there instead of opening the file again.
    """
    def views() -> Iterator[np.ndarray]:
        if whole is not None and 84 + 50 * n <= len(whole):
            corners = np.frombuffer(whole, dtype=_STL_RECORD, count=n, offset=84)["v"]
            for first in range(0, n, _CHUNK_FACES):  # in chunks, as from the file: the partition weld's output
                yield corners[first:first + _CHUNK_FACES]    # gathers chunk by chunk on the threads
            return
        buffer = np.empty(min(_CHUNK_FACES, n), dtype=_STL_RECORD)
        with open_regular(path) as opened:
            fh = cast(io.BufferedIOBase, opened)           # open_regular's file is buffered: readinto fills
            fh.seek(84)                                    # the buffer unless the file ends first
            done = 0
            while done < n:
                k = min(_CHUNK_FACES, n - done)
                rec = buffer[:k]
                got = fh.readinto(rec.data.cast("B"))
                if got != rec.nbytes:
                    raise _fail(path, f"ended after {done + (got or 0) // _STL_RECORD.itemsize:,} of {n:,} "
                                      "triangles")
                done += k
                yield rec["v"]

    def chunks() -> Iterator[np.ndarray]:
        for v in views():
            corners = np.zeros((3 * len(v), 4), dtype=np.float32)   # (x, y, z, 0): see weld._hash_rows
            corners[:, :3] = v.reshape(-1, 3)
            if not np.all(np.isfinite(corners)):
                raise _fail(path, "triangles have NaN or infinite coordinates")
            yield corners
    return chunks if padded else views


_VERTEX_RE = re.compile(rb"^[ \t]*vertex[ \t]+(\S+)[ \t]+(\S+)[ \t]+(\S+)[ \t]*$", re.MULTILINE | re.IGNORECASE)
_FIRST_WORD_RE = re.compile(rb"^[ \t]*([^ \t\n]{0,12})", re.MULTILINE)
_STL_KEYWORDS = (b"solid", b"endsolid", b"facet", b"endfacet", b"outer", b"endloop", b"vertex", b"")


def _read_ascii_stl(path: str, size: int, max_faces: int, data: bytes | None = None) -> tuple[np.ndarray, int]:
    """Stream an ASCII STL, checking its structure: exactly three ``vertex`` lines per ``facet``.

    Unknown lines and missing ``outer loop`` / ``endloop`` / ``endfacet`` lines are tolerated with one
    :class:`TrailingDataWarning`-style warning; anything that would change which corners form a triangle
    (a facet with two or four vertices, a vertex outside a facet, an unparsable coordinate) is refused.
    """
    blocks = []
    count = 0
    line_no = 1
    open_count = None        # vertices so far in the facet still open at the end of a block
    facets = 0
    tallies = dict.fromkeys((b"outer", b"endloop", b"endfacet"), 0)
    garbage = 0
    first_garbage = ""
    with _source_bytes(path, data) as fh:
        for block in _text_blocks(fh, path):
            words = np.char.lower(np.array(_FIRST_WORD_RE.findall(block), dtype="S12"))
            is_facet = words == b"facet"
            is_vertex = words == b"vertex"
            known = np.isin(words, np.array(_STL_KEYWORDS, dtype="S12"))
            if not known.all():
                if not garbage:
                    k = int(np.argmax(~known))
                    first_garbage = f" (first: line {line_no + k})"
                garbage += int(np.count_nonzero(~known))
            for key in tallies:
                tallies[key] += int(np.count_nonzero(words == key))
            # vertices per facet: id 0 is the facet left open by the previous block (if any), the last id
            # stays open into the next block; every facet in between is complete and must have 3
            facet_id = np.cumsum(is_facet)
            n_new = int(facet_id[-1]) if len(facet_id) else 0
            per_facet = np.bincount(facet_id[is_vertex], minlength=n_new + 1)
            if open_count is None:
                if per_facet[0]:
                    k = int(np.argmax(is_vertex))
                    raise _fail(path, f"line {line_no + k}: 'vertex' outside a 'facet'")
                complete = per_facet[1:n_new]
                complete_lines = np.flatnonzero(is_facet)[:-1]
            else:
                per_facet[0] += open_count
                complete = per_facet[:n_new]
                complete_lines = np.r_[-1, np.flatnonzero(is_facet)[:-1]] if n_new else np.zeros(0, int)
            bad = np.flatnonzero(complete != 3)
            if len(bad):
                k = int(complete_lines[bad[0]])
                where = f"line {line_no + k}" if k >= 0 else "a facet before this block"
                n_corners = int(complete[bad[0]])
                raise _fail(path, f"{where}: a facet has {n_corners} vert{'ex' if n_corners == 1 else 'ices'} "
                                  "instead of 3")
            if n_new or open_count is not None:
                open_count = int(per_facet[-1])
                if open_count > 3:
                    raise _fail(path, f"line {line_no + len(words) - 1}: a facet has more than 3 vertices")
            facets += int(np.count_nonzero(is_facet))
            found = _VERTEX_RE.findall(block)
            if _has_odd_bytes(block):                    # a name may hold them, a coordinate may not
                for m_pos in _VERTEX_RE.finditer(block):
                    if _odd_number(m_pos.groups()) is not None:
                        raise _bad_line(path, block, line_no, m_pos.start(),
                                        "vertex coordinate is not a decimal number (no '_', ASCII digits only)")
            if len(found) != int(np.count_nonzero(is_vertex)):
                for m_pos in re.finditer(rb"(?im)^[ \t]*vertex\b[^\n]*", block):
                    if not _VERTEX_RE.fullmatch(m_pos.group(0)):
                        raise _bad_line(path, block, line_no, m_pos.start(), "malformed vertex line")
                raise _fail(path, "malformed vertex line")
            if found:
                try:
                    arr = np.array(found, dtype=np.float64)
                except ValueError:
                    for m_pos in _VERTEX_RE.finditer(block):
                        try:
                            [float(x) for x in m_pos.groups()]
                        except ValueError:
                            raise _bad_line(path, block, line_no, m_pos.start(),
                                            "vertex coordinate is not a number") from None
                    raise _fail(path, "vertex coordinates are not numbers") from None
                blocks.append(arr)
                count += len(arr)
                _check_face_budget(path, count // 3, max_faces)
            line_no += block.count(b"\n")
    if count == 0:
        raise _fail(path, "ASCII STL without any 'vertex' line (empty mesh)")
    if open_count not in (None, 3):
        raise _fail(path, f"the last facet has {open_count} vert{'ex' if open_count == 1 else 'ices'} instead of 3 "
                    "(truncated?)")
    missing = [f"{facets - n:,} facets lack '{k.decode()}{' loop' if k == b'outer' else ''}'"
               for k, n in tallies.items() if n < facets]
    if garbage or missing:
        what = ([f"{garbage:,} unrecognised lines were ignored{first_garbage}"] if garbage else []) + missing
        warnings.warn(MalformedTextWarning(f"{_display(path)}: {'; '.join(what)}; read the 'vertex' lines by facet"),
                      stacklevel=4)
    corners = np.concatenate(blocks).reshape(-1, 3, 3)
    return corners, len(corners)


def read_stl(path: str | os.PathLike[str], *, max_faces: int = DEFAULT_MAX_FACES) -> tuple[np.ndarray, np.ndarray, int]:
    """Read an STL file (binary or ASCII) into an exactly welded indexed mesh in file units.

    Returns
    -------
    vertices : (n, 3) float64
    faces : (m, 3) int
    file_faces : int
    """
    vertices, faces, n, _ = _read_stl(os.fsdecode(os.fspath(path)), max_faces)
    return vertices, faces, n


def _read_stl(path: str, max_faces: int,
              data: bytes | None = None) -> tuple[np.ndarray, np.ndarray, int, float | None]:
    """:func:`read_stl`, and for a binary file (float32 coordinates) the largest coordinate magnitude (None for
    an ASCII file); ``data``: the file's bytes if the caller has read them (:func:`load_mesh`), parsed instead
    of reading the file."""
    size = os.path.getsize(path) if data is None else len(data)
    if size == 0:
        raise _fail(path, "empty file (0 bytes)")
    if data is None:
        with open_regular(path) as fh:
            head = fh.read(4096)
    else:
        head = data[:4096]
    announced = int(np.frombuffer(head[80:84], dtype="<u4")[0]) if len(head) >= 84 else -1

    def binary() -> tuple[np.ndarray, np.ndarray, int, float | None]:
        n = _binary_stl_count(path, size, max_faces, announced)
        if n == 0:
            raise _fail(path, "STL holds no triangles (empty mesh)")
        whole = data if data is not None else head if len(head) == size else None    # a small file: read once
        vertices, faces = weld_exact_stream(_binary_stl_chunks(path, n, padded=accel() is None, whole=whole),
                                            3 * n)
        magnitude = _finite_magnitude(vertices)
        if magnitude is None:
            raise _fail(path, "triangles have NaN or infinite coordinates")
        return vertices, faces, n, magnitude

    if (announced >= 0 and 84 + 50 * announced == size) or not _looks_ascii_stl(head):
        return binary()
    try:
        corners, n = _read_ascii_stl(path, size, max_faces, data)
    except MeshReadError as ascii_error:
        # a binary STL whose header starts with "solid" and which carries trailing bytes
        if not 0 < announced <= (size - 84) // 50:
            raise
        try:
            return binary()
        except MeshReadError:
            raise ascii_error from None
    if not np.all(np.isfinite(corners)):
        bad = int(np.count_nonzero(~np.isfinite(corners).all(axis=(1, 2))))
        raise _fail(path, f"{bad:,} triangles have NaN or infinite coordinates")
    vertices, faces = weld_exact(corners)
    return vertices, faces, n, None


def _finite_magnitude(vertices: np.ndarray) -> float | None:
    """The largest coordinate magnitude ``max |v|`` of (k >= 1, 3) vertices, or None when a coordinate is NaN
    or infinite.

    On the C extension one pass over the rows (``bounds``: the column extremes and finiteness), ``max |v|`` being
    ``max(max hi, -min lo)`` exactly; no temporary array (``numpy.abs`` of a 10M-face file's 5M vertices is a
    fresh 120 MB array, whose page faults cost more than the pass itself).
    """
    lib = accel()
    if (lib is not None and len(vertices) and vertices.dtype == np.float64 and vertices.ndim == 2
            and vertices.shape[1] == 3 and vertices.flags.c_contiguous):
        lo, hi, finite = lib.bounds(vertices, threads())
        return abs(max(max(hi), -min(lo))) if finite else None
    if not np.all(np.isfinite(vertices)):
        return None
    return float(np.max(np.abs(vertices))) if vertices.size else 0.0
