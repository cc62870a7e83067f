"""Reading meshes: files (STL natively; OBJ, PLY, OFF, 3MF, ... through trimesh), trimesh objects and arrays.

The reader's only job is bytes → triangles in metres.  It checks what a file claims against what it holds
before allocating anything, never reads a huge ASCII file into memory at once, and reports every problem as
a :class:`~inertia_tool.errors.MeshReadError` naming the file.  Topology checks live in ``checks``.

Binary STL is read directly with numpy in bounded chunks (much faster than a general loader), and shared
corners are welded exactly (bit-identical coordinates) into an indexed mesh on the way, so the triangle
soup never has to exist in float64.  With the C extension (``inertia_tool._native``) the welder reads the
corners straight from each chunk of file records, in one pass.
"""

from __future__ import annotations

import io
import os
import re
import stat
import sys
import warnings
from contextlib import contextmanager
from collections.abc import Callable, Iterator, Sequence
from typing import IO, TYPE_CHECKING, Any, TypeAlias, cast


import numpy as np

from ..values import frozen_value
from ..errors import MalformedTextWarning, MeshReadError, TrailingDataWarning, UsageError
from .._native import accel, threads
from ..units import LENGTH_UNITS, length_scale
from .polygons import clip_polygons, split_quads_along_shorter_diagonal, warn_clipped_polygons, warn_warped_quads
from .options import DEFAULT_MAX_FACES, MAX_SUPPORTED_FACES
from .regular import not_regular_reason, open_regular, regular_file_resolver
from .scene_counts import GLTF_INSTANCE_FACES, check_collada_instances, check_gltf
from .weld import weld_exact, weld_exact_stream

if TYPE_CHECKING:
    from .parts import PartTag
    import zipfile

#: What a header check found: element counts by name (``"vertex"``, ``"face"``) and, for PLY, ``"float32"``
#: (1 when the vertex coordinates are stored as float32).
_Counts: TypeAlias = "dict[str, int]"
#: ``(vertices (n, 3), faces (m, 3), declared (metres per file unit, unit name) or None)`` of a reader.
_Arrays: TypeAlias = "tuple[np.ndarray, np.ndarray, tuple[float, str] | None]"

__all__ = ["RawMesh", "load_mesh", "read_stl", "DEFAULT_MAX_FACES", "MAX_SUPPORTED_FACES", "SUPPORTED_SUFFIXES",
           "os_error_reason", "GLTF_INSTANCE_FACES"]



#: CAD files with an exact B-rep (STEP, IGES), read through OpenCASCADE (:mod:`inertia_tool.mesh.cad`).
BREP_SUFFIXES = (".step", ".stp", ".iges", ".igs")

#: File suffixes handled (STL natively, the rest through trimesh; COLLADA needs pycollada; STEP/IGES are
#: tessellated through OpenCASCADE, ``inertia_tool.mesh.cad``).
SUPPORTED_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".3mf", ".glb", ".gltf", ".dae", ".zae") + BREP_SUFFIXES

#: Compressed single-mesh files: ``part.stl.gz``, ``part.obj.bz2``, or a ``.zip`` holding exactly one mesh.
COMPRESSED_SUFFIXES = (".gz", ".bz2", ".zip")

#: Formats whose files declare their length unit (3MF ``<model unit>``, default millimetre by the 3MF
#: specification; COLLADA ``<asset><unit meter>``; glTF is metres by its specification).  The declared unit
#: wins over the default ``units="m"``; an explicit other ``units`` that contradicts it is refused.
DECLARES_UNITS = (".3mf", ".dae", ".zae", ".glb", ".gltf")

_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
_CHUNK_FACES = 1 << 17


@frozen_value
class RawMesh:
    """An indexed triangle mesh as read, in metres.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes (file coordinates times the unit scale): the vertices some face uses, in the file's order
        (a point no face uses is left out when reading, so that it widens no extent read later).
    faces : (m, 3) int
        Indices into ``vertices``, as wound in the file.
    source : str
        File path or a description of the object it came from (for messages).
    units : str
        Length unit of the file coordinates (the unit the file declares, where its format has one).
    file_faces : int
        Number of triangles the source held (before any cleaning).
    units_assumed : bool
        True when no unit was given and metres were assumed (the size check of
        :func:`inertia_tool.mesh.plausibility.warn_implausible_size` applies only then).
    storage_rounding : float
        m: how far each stored coordinate may lie from the value the exporter meant, because the file stores
        float32 (binary STL, PLY ``float``, glTF/GLB, COLLADA): half the float32 spacing at the largest
        coordinate (:func:`inertia_tool.mesh.precision.float32_rounding`); 0 for text and float64 formats and
        for arrays.  :func:`inertia_tool.mesh.precision.warn_storage_precision` turns it into a volume bound.
    scale_rounding : float
        m: how far the reader's conversion to metres moved a coordinate (each product ``x·scale`` rounded to
        float64: half the spacing at the largest; 0 when no unit was converted or the scale is a power of two).
        R7 (:func:`~inertia_tool.mesh.certify.certify`) counts it: the file's polyhedron is exact, the converted
        one may differ from it by this much (review 12's R6).
    parts : tuple of PartTag
        The parts of a file that names materials per part (:mod:`inertia_tool.mesh.parts`: a 3MF with base
        materials or a slicer's filament assignments, a STEP assembly), each a range of ``faces``; empty for a
        file of one material.
    """

    vertices: np.ndarray
    faces: np.ndarray
    source: str
    units: str = "m"
    file_faces: int = 0
    units_assumed: bool = False
    storage_rounding: float = 0.0
    parts: tuple[PartTag, ...] = ()
    scale_rounding: float = 0.0


def _display(path: str | bytes | os.PathLike[str] | os.PathLike[bytes]) -> str:
    """A printable form of a file name (undecodable bytes of a non-UTF-8 name become U+FFFD)."""
    return os.fsencode(path).decode("utf-8", "replace")


def _fail(path: str | bytes | os.PathLike[str] | os.PathLike[bytes], problem: str) -> MeshReadError:
    return MeshReadError(f"{_display(path)}: {problem}")


def _parse_failure(path: str, exc: Exception) -> MeshReadError:
    """A parser's exception as the one-line read error naming the file (its first line, at most 200 characters)."""
    msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return _fail(path, f"could not be parsed ({msg[:200]})")


@contextmanager
def _parsing(path: str) -> Iterator[None]:
    """Any exception of a third-party parser inside the block becomes :func:`_parse_failure` (our own read errors
    and ``MemoryError`` pass through)."""
    try:
        yield
    except (MeshReadError, MemoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure is a read error with the file named
        raise _parse_failure(path, exc) from None


def _source_bytes(path: str, data: bytes | None) -> IO[bytes]:
    """The file to parse: ``data`` (its bytes, read by the caller) as a file object, else ``path`` opened."""
    return io.BytesIO(data) if data is not None else open_regular(path)


def os_error_reason(exc: OSError, path: str | os.PathLike[str] | None = None) -> str:
    """The operating system's reason for ``exc`` in words, for a one-line message about ``path``.

    ``ENOENT`` of a path that is itself a symbolic link says the link is broken; ``ELOOP`` says "symbolic
    link loop" (not "no such file", which ``os.path.exists`` would suggest); anything else gives its
    ``strerror``.
    """
    import errno
    code = exc.errno
    if code == errno.ENOENT:
        if path is not None and os.path.islink(path):
            return "broken symbolic link (its target does not exist)"
        return "no such file"
    if code == errno.ELOOP:
        return "symbolic link loop (too many levels of symbolic links)"
    if code in (errno.EACCES, errno.EPERM):
        return "permission denied"
    if code == errno.ENOTDIR:
        return "a component of the path is not a directory"
    if code == errno.ENAMETOOLONG:
        return "file name too long"
    return exc.strerror or str(exc) or type(exc).__name__


def _check_face_budget(path: str, n: int, max_faces: int) -> None:
    if n > MAX_SUPPORTED_FACES:
        raise _fail(path, f"holds {n:,} triangles, more than the {MAX_SUPPORTED_FACES:,} this reader supports "
                          "(corner indices must fit 32 bits)")
    if n > max_faces:
        raise _fail(path, f"holds {n:,} triangles, more than `max_faces` ({max_faces:,}) allows")


# -- STL ------------------------------------------------------------------------------------------------

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

#: Bytes read per step when streaming a text file.
_BLOCK_BYTES = 1 << 24
#: Longest text line accepted (a longer one means the file is not the text format it claims to be).
MAX_LINE_BYTES = 1 << 20


def _text_blocks(fh: IO[bytes], path: str, *, block_bytes: int = _BLOCK_BYTES,
                 max_line: int = MAX_LINE_BYTES) -> Iterator[bytes]:
    """Yield the bytes of a text file in blocks of whole lines, every line ending normalised to ``\n``.

    Reads fixed-size byte blocks and splits on any of ``\r\n``, ``\r`` (old Mac) and ``\n`` itself, carrying
    the partial last line into the next block, so memory stays bounded by ``block_bytes + max_line`` however
    the lines end.  A line longer than ``max_line`` is refused (the file is not line-structured text).
    """
    carry = b""
    for _ in range(1 << 40):  # bounded by the file size: each pass consumes up to block_bytes
        chunk = fh.read(block_bytes)
        if not chunk:
            break
        data = carry + chunk
        hold = b""
        if data.endswith(b"\r"):  # may be the first half of a \r\n split across blocks
            data, hold = data[:-1], b"\r"
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
        cut = data.rfind(b"\n")
        if cut < 0:
            carry = data + hold
        else:
            yield data[:cut + 1]
            carry = data[cut + 1:] + hold
        if len(carry) > max_line:
            raise _fail(path, f"a line is longer than {max_line:,} bytes: not a text mesh file")
    carry = carry.replace(b"\r", b"\n")
    if carry:
        yield carry if carry.endswith(b"\n") else carry + b"\n"


def _odd_number(tokens: Sequence[bytes]) -> bytes | None:
    """The first token holding ``_`` or a non-ASCII byte, else None.

    Python's ``float``/``int`` (and numpy's bulk conversion) read ``1_0`` as 10; no mesh format's number
    grammar (:data:`inertia_tool.units.DECIMAL` and its integers) has ``_`` or a non-ASCII digit.  Callers
    look only in blocks where ``_has_odd_bytes`` found one, so the common case costs one scan per block."""
    for tok in tokens:
        if b"_" in tok or not tok.isascii():
            return tok
    return None


def _has_odd_bytes(block: bytes) -> bool:
    return b"_" in block or not block.isascii()


def _bad_line(path: str, block: bytes, first_line: int, pos: int, problem: str) -> MeshReadError:
    """Error naming the line that holds byte ``pos`` of ``block`` (``first_line`` is the block's first line)."""
    start = block.rfind(b"\n", 0, pos) + 1
    stop = block.find(b"\n", pos)
    text = block[start:stop if stop >= 0 else len(block)].strip()[:60].decode("utf-8", "replace")
    line = first_line + block.count(b"\n", 0, start)
    return _fail(path, f"line {line}: {problem}: {text!r}")


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


# -- OBJ ------------------------------------------------------------------------------------------------

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


def _read_obj(path: str, max_faces: int, data: bytes | None = None) -> tuple[np.ndarray, np.ndarray, int]:
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


# -- other formats through trimesh, with their headers checked first ------------------------------------

_PLY_TYPE_BYTES = {b"char": 1, b"int8": 1, b"uchar": 1, b"uint8": 1, b"short": 2, b"int16": 2, b"ushort": 2,
                   b"uint16": 2, b"int": 4, b"int32": 4, b"uint": 4, b"uint32": 4, b"float": 4, b"float32": 4,
                   b"double": 8, b"float64": 8}

#: 3MF (zip) members inflating more than this many times their compressed size are refused as zip bombs
#: (applied to members above ``_ZIP_RATIO_MIN_BYTES``; real 3MF XML compresses about 5–20 : 1).
MAX_ZIP_RATIO = 100
_ZIP_RATIO_MIN_BYTES = 1 << 20
#: Inflated bytes of the 3MF model parts allowed per face of ``max_faces``: a vertex line of a 3MF model is
#: ~55 bytes and a triangle line ~45, so a welded mesh (two triangles per vertex) spends ~75 bytes per
#: triangle and an unwelded corner soup (three vertices per triangle) ~210; 256 covers both.
ZIP_BYTES_PER_FACE = 256
#: Fixed allowance on top (XML header, metadata, a small model's attributes).
ZIP_BYTES_SLACK = 16 << 20
#: Members of a 3MF archive at most (counted from its central directory, before anything is inflated).
MAX_ZIP_MEMBERS = 10_000
#: Largest relationships part read (``*.rels``, a few hundred bytes in practice).
_MAX_RELS_BYTES = 1 << 20


def zip_inflate_limit(max_faces: int) -> int:
    """Bytes the model parts of a 3MF may inflate to: ``ZIP_BYTES_PER_FACE * max_faces + ZIP_BYTES_SLACK``
    (256 B per face + 16 MiB; 12.8 GB at the default 50 million faces)."""
    return ZIP_BYTES_PER_FACE * int(max_faces) + ZIP_BYTES_SLACK


def _header_count(path: str, word: bytes) -> int:
    try:
        n = int(word)
    except ValueError:
        raise _fail(path, f"header count {word[:20].decode('utf-8', 'replace')!r} is not an integer") from None
    if n < 0:
        raise _fail(path, f"header count {n} is negative")
    return n


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


def _relationship_targets(data: bytes) -> list[str]:
    """The ``Target`` of every ``Relationship`` of an OPC relationships part, without a leading ``/``."""
    import xml.etree.ElementTree as ET
    try:
        root = ET.fromstring(data)
    except ET.ParseError:
        return []
    return [r.attrib["Target"].lstrip("/") for r in root.iter() if r.tag.endswith("Relationship")
            and "Target" in r.attrib]


def _model_members(path: str, zf: zipfile.ZipFile,
                   infos: Sequence[zipfile.ZipInfo]) -> list[zipfile.ZipInfo]:
    """The members of a 3MF that hold geometry, the only ones read: the root model (the first
    ``3D/3dmodel.model``, as trimesh takes it), the parts its relationships point at, and any other
    ``*.model`` part (a component's ``path`` may name one).  Thumbnails, textures, metadata and anything
    else are never inflated."""
    roots = [i for i in infos if "3d/3dmodel.model" in i.filename.lower()]
    if not roots:
        raise _fail(path, "3MF archive without a 3D/3dmodel.model part: not a 3MF")
    root = roots[0]
    by_name = {i.filename: i for i in infos}
    head, tail = os.path.split(root.filename)
    wanted = {root.filename}
    rels = by_name.get(f"{head}/_rels/{tail}.rels" if head else f"_rels/{tail}.rels")
    if rels is not None and rels.file_size <= _MAX_RELS_BYTES:
        wanted.update(t for t in _relationship_targets(zf.read(rels)) if t in by_name)
    wanted.update(i.filename for i in infos if i.filename.lower().endswith(".model"))
    return [i for i in infos if i.filename in wanted]


def _check_zip_members(path: str, count: int, members: Sequence[zipfile.ZipInfo], what: str = "") -> None:
    """Refuse, from the central directory, an archive of more than :data:`MAX_ZIP_MEMBERS` members (``count``)
    or one of ``members`` inflating more than :data:`MAX_ZIP_RATIO` : 1; ``what`` prefixes the messages."""
    if count > MAX_ZIP_MEMBERS:
        raise _fail(path, f"{what}archive has {count:,} members, more than the {MAX_ZIP_MEMBERS:,} allowed; "
                          "refused before inflating")
    for i in members:
        if i.flag_bits & 0x1:       # bit 0 of the general purpose flags: the member is encrypted
            raise _fail(path, f"{what}member {i.filename[:60]!r} is encrypted (password-protected): it cannot be "
                              "read")
        if i.file_size > _ZIP_RATIO_MIN_BYTES and i.file_size > MAX_ZIP_RATIO * max(i.compress_size, 1):
            raise _fail(path, f"{what}member {i.filename[:60]!r} would inflate "
                              f"{i.file_size / max(i.compress_size, 1):,.0f}:1 ({i.compress_size:,} → "
                              f"{i.file_size:,} bytes), over the {MAX_ZIP_RATIO}:1 limit: refused as a zip bomb "
                              "before inflating")


def _check_zip(path: str, max_faces: int) -> _Counts:
    """Refuse a zipped mesh (``.zae``) whose members would inflate beyond the limits, from the central
    directory only: :func:`_check_zip_members` and all members together within :func:`zip_inflate_limit`."""
    import zipfile

    try:
        with open_regular(path) as raw, zipfile.ZipFile(raw) as zf:
            infos = zf.infolist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError) as exc:
        raise _fail(path, f"not a valid zip archive ({str(exc)[:100]})") from None
    _check_zip_members(path, len(infos), infos)
    total = sum(i.file_size for i in infos)
    limit = zip_inflate_limit(max_faces)
    if total > limit:
        raise _fail(path, f"archive would inflate to {total:,} bytes, more than the {limit:,} allowed for "
                          f"`max_faces` ({max_faces:,}); refused before inflating")
    return {}


def _read_3mf(path: str, max_faces: int) -> tuple[np.ndarray, np.ndarray, tuple[float, str], tuple[PartTag, ...]]:
    """``(vertices, faces, declared unit, parts)`` of a 3MF, read by the streaming reader :mod:`.threemf`;
    ``parts``: :func:`.parts.threemf_parts` of its materials and slicer volumes (PrusaSlicer's and Bambu Studio's
    ``Metadata/`` configs, :mod:`.slicers`, each read whole, at most :data:`.slicers.MAX_CONFIG_BYTES`).

    Refused from the zip's central directory, before anything is inflated: more than
    :data:`MAX_ZIP_MEMBERS` members, an encrypted model part, a model part inflating more than
    :data:`MAX_ZIP_RATIO` : 1, or model parts inflating to more than :func:`zip_inflate_limit` ``(max_faces)``
    bytes in all.  Python's zipfile never returns more than a member's declared ``file_size`` (it stops there
    and checks the CRC), so limits on the declared sizes bound what is inflated.  Members the model does not
    reference are not read; the parts that are read are streamed (their triangles and vertices counted against
    ``max_faces`` as they come).
    """
    import zipfile
    import zlib

    from .parts import threemf_parts
    from .slicers import CONFIG_MEMBERS, MAX_CONFIG_BYTES, read_slicer_config
    from .threemf import read_3mf
    try:
        with open_regular(path) as raw, zipfile.ZipFile(raw) as zf:
            infos = zf.infolist()
            if len(infos) > MAX_ZIP_MEMBERS:
                _check_zip_members(path, len(infos), (), "3MF ")
            models = _model_members(path, zf, infos)
            _check_zip_members(path, len(infos), models, "3MF ")
            configs = [i for i in infos if i.filename.lower().lstrip("/") in CONFIG_MEMBERS]
            _check_zip_members(path, len(infos), configs, "3MF ")
            for info in configs:
                if info.file_size > MAX_CONFIG_BYTES:
                    raise _fail(path, f"3MF member {info.filename[:60]!r} inflates to {info.file_size:,} bytes, "
                                      f"more than the {MAX_CONFIG_BYTES:,} read for a slicer's settings")
            total = sum(i.file_size for i in models)
            limit = zip_inflate_limit(max_faces)
            if total > limit:
                raise _fail(path, f"3MF model parts would inflate to {total:,} bytes, more than the {limit:,} "
                                  f"allowed for `max_faces` ({max_faces:,}); refused before inflating")
            models.sort(key=lambda i: "3d/3dmodel.model" not in i.filename.lower())     # the root model first
            vertices, faces, declared, placed = read_3mf(path, models, zf, max_faces=max_faces, name=_display(path))
            slicer = read_slicer_config({i.filename.lower().lstrip("/"): zf.read(i) for i in configs}, _display(path))
            return vertices, faces, declared, threemf_parts(placed, slicer, _display(path))
    except RuntimeError as exc:     # zipfile: "File ... is encrypted, password required for extraction"
        raise _fail(path, f"3MF archive member cannot be read ({str(exc)[:100]})") from None
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError, NotImplementedError,
            zlib.error) as exc:
        raise _fail(path, f"not a valid 3MF (zip) archive ({str(exc)[:100]})") from None


_FLOAT_ARRAY = re.compile(rb"<(?:\w+:)?float_array\b[^>]*(?<!/)>(.*?)</(?:\w+:)?float_array\s*>", re.DOTALL)
_NOT_DECIMAL = re.compile(rb"[^0-9eE+\-.\s]")
_BIG_EXPONENT = re.compile(rb"[eE]\+?0*([1-9][0-9]+)")


def _check_collada_floats(name: str, data: bytes) -> None:
    """Refuse a COLLADA document whose ``<float_array>`` text holds anything but decimal numbers.

    pycollada parses each array with ``numpy.fromstring(..., float32)`` and then sets every NaN to 0, so a
    ``nan`` coordinate would silently become the origin (and ``inf``, ``1e999``, become infinity); the text is
    checked here, before it is parsed: only digits, signs, ``.``, exponents and white space may appear.
    """
    for match in _FLOAT_ARRAY.finditer(data):
        big = _BIG_EXPONENT.search(match.group(1))
        if big is not None and int(big.group(1)) >= 38:     # float32 overflows past 3.4e38 (trimesh then drops
            raise MeshReadError(f"{name}: a <float_array> holds a number with exponent {int(big.group(1))}, "
                                "beyond float32 (the COLLADA reader would make it infinite)")   # the faces)
        bad = _NOT_DECIMAL.search(match.group(1))
        if bad is not None:
            start = match.group(1).rfind(b" ", 0, bad.start()) + 1
            token = match.group(1)[start:start + 24].split()[0].decode("utf-8", "replace")
            raise MeshReadError(f"{name}: a <float_array> holds {token!r}, not a finite decimal number "
                                "(NaN and infinity are refused: the COLLADA reader would turn NaN into 0)")


def _check_collada(path: str, size: int, max_faces: int) -> _Counts:
    """A ``.dae`` file: at most :func:`zip_inflate_limit` bytes (the text of ``max_faces`` triangles), and
    its float arrays decimal numbers (:func:`_check_collada_floats`)."""
    limit = zip_inflate_limit(max_faces)
    if size > limit:
        raise _fail(path, f"{size:,} bytes of COLLADA text, more than the {limit:,} allowed for `max_faces` "
                          f"({max_faces:,})")
    with open_regular(path) as fh:
        data = fh.read()
    _check_collada_floats(_display(path), data)
    check_collada_instances(_display(path), data, max_faces)
    return {}


def _check_zipped_collada(path: str, max_faces: int) -> _Counts:
    """A ``.zae`` archive: the inflated-size limits of :func:`_check_zip`, then the float arrays of its
    ``.dae`` members (:func:`_check_collada_floats`)."""
    import zipfile
    counts = _check_zip(path, max_faces)
    try:
        with open_regular(path) as raw, zipfile.ZipFile(raw) as zf:
            for info in zf.infolist():
                if info.filename.lower().endswith(".dae"):
                    data = zf.read(info)
                    _check_collada_floats(f"{_display(path)}:{info.filename[:60]}", data)
                    check_collada_instances(f"{_display(path)}:{info.filename[:60]}", data, max_faces)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError, NotImplementedError,
            RuntimeError, OSError) as exc:
        if isinstance(exc, MeshReadError):
            raise
        raise _fail(path, f"not a valid zip archive ({str(exc)[:100]})") from None
    return counts


_HEADER_CHECKS = {".ply": _check_ply_header, ".off": _check_off_header, ".dae": _check_collada,
                  ".glb": check_gltf, ".gltf": check_gltf}


def _declared_scale(path: str, suffix: str, loaded: object) -> tuple[float, str] | None:
    """Metres per file unit and the unit's name, for formats that declare one (:data:`DECLARES_UNITS`)."""
    if suffix in (".glb", ".gltf"):
        return 1.0, "m"
    units = getattr(loaded, "units", None)
    if suffix not in DECLARES_UNITS or not units:
        return None
    from trimesh.units import unit_conversion
    try:
        scale = float(unit_conversion(str(units), "meters"))
    except Exception:  # noqa: BLE001 - trimesh raises ValueError/KeyError for names it does not know
        raise _fail(path, f"declares an unknown length unit {str(units)[:40]!r}") from None
    return _named_scale(path, scale, str(units))


#: COLLADA elements that say how a surface looks, not where it is: dropped by :func:`_collada_geometry_only`.
_COLLADA_APPEARANCE = ("library_images", "library_effects", "library_materials", "bind_material")


def _collada_geometry_only(path: str) -> IO[bytes]:
    """The COLLADA file ``path`` without images, effects, materials and material bindings (a file object):
    what is not geometry cannot stop the geometry from being read."""
    import io

    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    with open_regular(path) as fh:
        tree = etree.parse(fh, parser)
    for element in list(tree.iter()):
        if isinstance(element.tag, str) and element.tag.rsplit("}", 1)[-1] in _COLLADA_APPEARANCE:
            parent = element.getparent()
            if parent is not None:
                parent.remove(element)
    return io.BytesIO(etree.tostring(tree))


def _read_with_trimesh(path: str, max_faces: int) -> _Arrays:
    """``(vertices, faces, declared unit)`` of a file trimesh reads (see :func:`_read_with_trimesh_rounding`)."""
    vertices, faces, declared, _ = _read_with_trimesh_rounding(path, max_faces)
    return vertices, faces, declared


def _read_collada(path: str) -> tuple[np.ndarray, np.ndarray, tuple[float, str] | None, float]:
    """``(vertices, faces, declared unit, float32 rounding in file units)`` of a ``.dae`` file through pycollada
    (:mod:`.collada`: trimesh's reading of it, without trimesh); a document whose every geometry pycollada drops
    (bound to a material it cannot build: an ``<image>`` without a path, Gazebo's pulley.dae, gear.dae, disk.dae)
    is read again without its appearance (:func:`_collada_geometry_only`)."""
    try:
        import collada  # noqa: F401 - the COLLADA parser
    except ImportError:
        raise _fail(path, "reading COLLADA needs pycollada (pip install pycollada)") from None
    from .collada import collada_triangles
    with _parsing(path), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with open_regular(path) as fh:
            found = collada_triangles(fh)
        if not found.instances:
            found = collada_triangles(_collada_geometry_only(path))
    if not found.instances or found.declared is None:
        raise _fail(path, "contains no triangle mesh (empty scene or only points/lines)")
    return found.vertices, found.faces, _named_scale(path, *found.declared), found.rounding


def _named_scale(path: str, scale: float, spelled: str) -> tuple[float, str]:
    """``(metres per file unit, name)`` of a declared unit: a named unit when within 1e-12 of one, else
    ``"<factor> m"``; refused unless finite and positive (``spelled``: the file's spelling, for the message)."""
    if not (np.isfinite(scale) and scale > 0):
        raise _fail(path, f"declares an invalid length unit {spelled[:40]!r}")
    for name, value in LENGTH_UNITS.items():      # snap "centimeter" → 0.01 exactly (trimesh gives 0.00999…)
        if abs(scale - value) <= 1e-12 * value:
            return value, name
    return scale, f"{scale:g} m"


#: Formats whose coordinates the reader receives as float32 (glTF's POSITION accessor is float32 by the
#: specification; pycollada parses COLLADA arrays as float32).  PLY: when its vertex x is ``float``.
_FLOAT32_FORMATS = (".glb", ".gltf", ".dae", ".zae")


def _scene_rounding(loaded: object) -> float:
    """float32 rounding (file units) of a scene whose geometries are stored as float32 and placed by node
    transforms: each output coordinate is ``Σ_j M_ij x_j + t_i``, so its error is at most ``‖M‖∞ δ`` with ``δ``
    the rounding of the largest stored coordinate and ``‖M‖∞`` the largest row sum of any node's matrix."""
    import trimesh
    if isinstance(loaded, trimesh.Trimesh):
        return _float32_rounding(np.asarray(loaded.vertices))
    if not isinstance(loaded, trimesh.Scene):
        return 0.0                  # a point cloud or lines: refused below
    stored = [np.asarray(g.vertices) for g in loaded.geometry.values() if hasattr(g, "vertices")]
    delta = max((_float32_rounding(v) for v in stored), default=0.0)
    norm = 1.0
    for node in loaded.graph.nodes_geometry:
        matrix, _ = loaded.graph[node]
        norm = max(norm, float(np.abs(np.asarray(matrix)[:3, :3]).sum(axis=1).max()))
    return delta * norm


def _read_with_trimesh_rounding(path: str, max_faces: int,
                                parts_out: list[Any] | None = None) -> tuple[np.ndarray, np.ndarray,
                                                                             tuple[float, str] | None, float]:
    """``(vertices, faces, declared unit, float32 rounding in file units)`` of a file trimesh reads (3MF: of
    the streaming reader :func:`_read_3mf`); a glTF scene whose primitives use named materials appends its
    per-node parts (:func:`.parts.scene_parts`) to ``parts_out``."""
    parts: tuple[PartTag, ...] = ()
    size = os.path.getsize(path)
    suffix = os.path.splitext(path)[1].lower()
    declared: tuple[float, str] | None
    if suffix == ".3mf":
        v, f, declared, _ = _read_3mf(path, max_faces)
        _check_face_budget(path, len(f), max_faces)
        if not np.all(np.isfinite(v)):
            raise _fail(path, "vertices have NaN or infinite coordinates")
        return v, f, declared, 0.0
    if suffix in _HEADER_CHECKS:
        counts = _HEADER_CHECKS[suffix](path, size, max_faces)
    elif suffix == ".zae":
        counts = _check_zipped_collada(path, max_faces)
    else:
        counts = {}
    if suffix == ".dae":
        # pycollada without trimesh: the same triangles, without importing trimesh (~2.5 s of CPU; issue 23)
        v, f, declared, rounding = _read_collada(path)
        return (*_checked_arrays(path, v, f, counts, max_faces), declared, rounding)
    try:
        import trimesh
    except ImportError as exc:  # pragma: no cover - trimesh is a dependency
        raise _fail(path, "reading this format needs trimesh (pip install trimesh)") from exc
    if suffix == ".zae":
        try:
            import collada  # noqa: F401 - trimesh reads COLLADA through pycollada
        except ImportError:
            raise _fail(path, "reading COLLADA needs pycollada (pip install pycollada)") from None
    import logging      # imported on use, like trimesh: only the formats trimesh reads need it
    try:
        quiet = logging.getLogger("trimesh")
        level = quiet.level
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            quiet.setLevel(logging.CRITICAL)      # e.g. a missing texture image, logged with a traceback
            try:
                # glTF: no textures decoded (geometry only; a textured GLB loads up to 50x faster)
                # (unless primitives use named materials: then each node is a part with its material)
                extra: dict[str, Any] = ({"skip_materials": not counts.get("named_materials")}
                                         if suffix in (".glb", ".gltf") else {})
                # the file itself, opened once (regular files only), its side files too
                with open_regular(path) as fh:
                    loaded = trimesh.load(fh, file_type=suffix[1:], process=False, force=None,
                                          resolver=regular_file_resolver(path), **extra)
            finally:
                quiet.setLevel(level)
            declared = _declared_scale(path, suffix, loaded)
            float32 = suffix in _FLOAT32_FORMATS or (suffix == ".ply" and counts.get("float32"))
            rounding = _scene_rounding(loaded) if float32 else 0.0
            if isinstance(loaded, trimesh.Scene):   # dump() applies every node's transform
                geoms = [g for g in loaded.dump() if isinstance(g, trimesh.Trimesh)] if loaded.geometry else []
                if not geoms:
                    raise _fail(path, "contains no triangle mesh (empty scene or only points/lines)")
                if suffix in (".glb", ".gltf") and counts.get("named_materials"):
                    from .parts import scene_parts
                    parts = scene_parts(geoms)
                loaded = trimesh.util.concatenate(geoms) if len(geoms) > 1 else geoms[0]
    except MeshReadError:
        raise
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure is a read error with the file named
        raise _parse_failure(path, exc) from None
    if not isinstance(loaded, trimesh.Trimesh):
        raise _fail(path, f"contains no triangle mesh (found {type(loaded).__name__}: a point cloud or lines)")
    v, f = _checked_arrays(path, np.asarray(loaded.vertices, dtype=np.float64), np.asarray(loaded.faces), counts,
                           max_faces)
    if suffix == ".ply":
        f = _ply_polygons_clipped(path, loaded, v, f)
    if parts_out is not None:
        parts_out.extend(parts)
    return v, f, declared, rounding


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


def _checked_arrays(path: str, v: np.ndarray, f: np.ndarray, counts: _Counts,
                    max_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """``(v, f)`` of a file read whole, refused unless they are triangles in 3-D, indexed in range, finite, and
    as many as its header announced (``counts``)."""
    if len(f) == 0:
        raise _fail(path, "contains no triangles (empty mesh or point cloud)")
    _check_face_budget(path, len(f), max_faces)
    if f.ndim != 2 or f.shape[1] != 3:
        raise _fail(path, f"faces are not triangles (shape {f.shape})")
    if v.ndim != 2 or v.shape[1] != 3:      # e.g. a glTF POSITION naming a SCALAR accessor
        raise _fail(path, f"vertices are not points in 3-D (expected shape (n, 3), got {v.shape})")
    if f.min() < 0 or f.max() >= len(v):
        raise _fail(path, f"face indices out of range (0..{len(v) - 1})")
    if "vertex" in counts and len(v) < counts["vertex"]:
        # more is fine: the reader splits vertices along texture seams (per-face texture coordinates)
        raise _fail(path, f"the header announces {counts['vertex']:,} vertices but only {len(v):,} were read")
    if "face" in counts and len(f) < counts["face"]:
        raise _fail(path, f"the header announces {counts['face']:,} faces but only {len(f):,} triangles were read "
                          "(faces dropped or truncated file)")
    if not np.all(np.isfinite(v)):
        raise _fail(path, "vertices have NaN or infinite coordinates")
    return v, f


#: The suffixes :func:`load_mesh` parses from the ``data`` a caller read (the file is then neither stat'ed nor
#: opened again); other formats are read from the file.
_PARSED_FROM_DATA = (".stl", ".obj")


def load_mesh(source: object, *, units: str | None = None, max_faces: int = DEFAULT_MAX_FACES,
              declared_units_win: bool = False, data: bytes | None = None) -> RawMesh:
    """Read a mesh and convert it to metres.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces) or RawMesh
        A file (format from its suffix; STL and OBJ read natively, streaming), a ``trimesh.Trimesh``, a
        pair of arrays ``vertices (n, 3)`` and ``faces (m, 3)``, or a ``RawMesh`` read before (returned as
        it is: it is already in metres, so ``units`` does not apply to it; the face limit still does).
    units : str or None
        Length unit of the coordinates (``m``, ``cm``, ``mm``, ``um``, ``in``, ``ft``); ``None``: not given,
        metres assumed (``RawMesh.units_assumed`` says so).
    max_faces : int
        Refuse sources with more triangles than this (protects memory).  What a file *announces* (an STL,
        PLY or OFF header, a 3MF's inflated size) is checked against its size and this limit before
        anything is allocated for it.
    declared_units_win : bool
        A file that declares its length unit is read in it even when ``units`` says otherwise (``units`` is
        then for the files without one); default False: the contradiction is refused (:class:`UsageError`).
    data : bytes, optional
        The bytes of the file ``source`` names, when the caller has read them already (``inertia-tool batch``
        reads a file once, to hash it and to parse it, so that the hash is that of the bytes analysed): an STL
        or OBJ file is parsed from them, not stat'ed or read again (the caller opened it as a regular file).
        Other formats read the file; ignored for a source that is not a path.

    Returns
    -------
    RawMesh
        ``source`` is the file name made printable (undecodable bytes replaced).

    Raises
    ------
    MeshReadError
        The file does not exist, is a directory, is empty, truncated, not a mesh, lies about its
        contents, or is too large.
    UsageError
        Bad ``units``, ``max_faces`` or malformed arrays.
    """
    assumed = units is None
    units = "m" if units is None else units
    scale = length_scale(units)
    if not (isinstance(max_faces, (int, np.integer)) and 0 < max_faces <= MAX_SUPPORTED_FACES):
        raise UsageError(f"Expected `max_faces` to be an integer from 1 to {MAX_SUPPORTED_FACES:,} (corner "
                         f"indices must fit 32 bits), got {max_faces!r}")
    if isinstance(source, RawMesh):
        if len(source.faces) > max_faces:
            raise UsageError(f"{source.source}: holds {len(source.faces):,} triangles, more than `max_faces` "
                             f"({max_faces:,}) allows")
        return source
    if isinstance(source, (str, bytes, os.PathLike)):
        path = os.fsdecode(os.fspath(source))
        try:
            suffix = os.path.splitext(path)[1].lower()
            if data is None or suffix not in _PARSED_FROM_DATA:
                # the file is opened here (the bytes given by a caller that read it are not stat'ed again)
                try:
                    st = os.stat(path)
                except OSError as exc:
                    raise _fail(path, os_error_reason(exc, path)) from None
                mode = st.st_mode
                if stat.S_ISDIR(mode):
                    raise _fail(path, "is a directory, not a mesh file")
                reason = not_regular_reason(mode, path)   # a FIFO, a device or a link to one: refused before opening
                if reason is not None:
                    raise _fail(path, reason)
            if suffix in COMPRESSED_SUFFIXES:
                if os.path.getsize(path) == 0:
                    raise _fail(path, "empty file (0 bytes)")
                from .decompress import decompressed
                with decompressed(path, max_bytes=zip_inflate_limit(max_faces),
                                  max_ratio=MAX_ZIP_RATIO, min_ratio_bytes=_ZIP_RATIO_MIN_BYTES,
                                  suffixes=SUPPORTED_SUFFIXES) as (inner, member):
                    try:
                        raw = load_mesh(inner, units=None if assumed else units, max_faces=max_faces,
                                        declared_units_win=declared_units_win)
                    except MeshReadError as exc:
                        raise MeshReadError(str(exc).replace(inner, f"{_display(path)}:{member}", 1)) from None
                return RawMesh(vertices=raw.vertices, faces=raw.faces, source=_display(path), units=raw.units,
                               file_faces=raw.file_faces, units_assumed=raw.units_assumed,
                               storage_rounding=raw.storage_rounding, parts=raw.parts,
                               scale_rounding=raw.scale_rounding)
            if suffix not in SUPPORTED_SUFFIXES:
                raise _fail(path, f"unsupported file type {_display(suffix) or '(no suffix)'!r}; expected one of "
                                  f"{', '.join(SUPPORTED_SUFFIXES + COMPRESSED_SUFFIXES)}")
            if (len(data) if data is not None and suffix in _PARSED_FROM_DATA else st.st_size) == 0:
                raise _fail(path, "empty file (0 bytes)")
            declared = None
            rounding = 0.0                  # file units until scaled below
            parts: tuple[PartTag, ...] = ()
            welded = False
            if suffix == ".stl":
                vertices, faces, n, magnitude = _read_stl(path, max_faces, data)
                welded = True                   # the weld's vertices are the faces' corners: every one is used
                if magnitude is not None:          # binary: float32 coordinates
                    from .precision import float32_rounding
                    rounding = float32_rounding(magnitude)
            elif suffix == ".obj":
                vertices, faces, n = _read_obj(path, max_faces, data)
                if not np.all(np.isfinite(vertices)):
                    raise _fail(path, "vertices have NaN or infinite coordinates")
            elif suffix in BREP_SUFFIXES:
                from .cad import read_cad
                from .parts import cad_parts
                reading = read_cad(path, max_faces=max_faces)
                vertices, faces = reading.vertices, reading.faces
                parts = cad_parts(reading.parts)
                _check_face_budget(path, len(faces), max_faces)
                if not np.all(np.isfinite(vertices)):
                    raise _fail(path, "the tessellation has NaN or infinite coordinates")
                declared = (1.0, "m")           # the CAD reader converts the file's unit to metres
                n = len(faces)
            elif suffix == ".off":
                _check_off_header(path, st.st_size, max_faces)
                vertices, faces, n = _read_off(path, max_faces)
            elif suffix == ".3mf":
                vertices, faces, declared, parts = _read_3mf(path, max_faces)
                _check_face_budget(path, len(faces), max_faces)
                if not np.all(np.isfinite(vertices)):
                    raise _fail(path, "vertices have NaN or infinite coordinates")
                n = len(faces)
            else:
                found: list[PartTag] = []
                vertices, faces, declared, rounding = _read_with_trimesh_rounding(path, max_faces, found)
                parts = tuple(found)
                n = len(faces)
        except PermissionError:
            raise _fail(path, "permission denied") from None
        except IsADirectoryError:
            raise _fail(path, "is a directory, not a mesh file") from None
        except MemoryError:
            raise _fail(path, "too large to read into memory (see `max_faces`)") from None
        except OSError as exc:
            if isinstance(exc, MeshReadError):
                raise
            raise _fail(path, f"cannot be read ({os_error_reason(exc, path)})") from None
        name = _display(path)
        if declared is not None:           # the file says its unit: nothing is assumed
            scale, units = _declared_units_win(name, declared, units, 1.0 if declared_units_win else scale)
            assumed = False
        owned = True                       # arrays this function made: scaled in place (no 2nd copy)
    else:
        vertices, faces, name = _from_object(source)
        n = len(faces)
        _check_face_budget(name, n, max_faces)
        owned = False                      # may be the caller's own array: never modified
        rounding = 0.0
        parts = ()
        welded = False
    if not welded:                         # a pass over every corner, not paid on the STL hot path
        vertices, faces, owned = _used_vertices(vertices, faces, owned)
    converted = 0.0
    if scale != 1.0:
        from .precision import product_rounding
        converted = product_rounding(vertices, scale)
        if owned and vertices.dtype == np.float64 and vertices.flags.writeable:
            vertices *= scale
        else:
            vertices = vertices * scale
    return RawMesh(vertices=vertices, faces=faces, source=name, units=str(units), file_faces=n,
                   units_assumed=assumed, storage_rounding=rounding * abs(scale), parts=parts,
                   scale_rounding=converted)


#: Faces marked or renumbered per pass by :func:`_used_vertices`: its index temporaries stay a few MB at any size.
_USED_CHUNK_FACES = 1 << 18


def _used_vertices(vertices: np.ndarray, faces: np.ndarray, owned: bool) -> tuple[np.ndarray, np.ndarray, bool]:
    """``(vertices, faces, owned)`` with every vertex no face uses left out and the faces renumbered to match.

    A point no face uses is not part of the surface: it encloses nothing and moves no integral, but it would
    widen every extent read from the vertices (R2's flatness scale ``FLAT_RTOL · diagonal³``, the units
    heuristic, the bounding box reported), so a valid solid with one stray point far away read as "flat"
    (review 10, D1).  Leaving it out here, where the mesh is read, makes every later stage (the clean-part fast
    path, :func:`~.surface.close_surface`, the size check) read the same extent.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
        Indices into ``vertices``, all in ``0..n-1``.
    owned : bool
        The arrays are this reader's own (else a caller's: never modified; new arrays are made when needed).

    Returns
    -------
    vertices : (k, 3) float
        The used vertices, in their order (the same array when all are used).
    faces : (m, 3) int
        Renumbered into them, same dtype (the same array when all are used).
    owned : bool
        Whether the arrays returned are this reader's own.
    """
    n = len(vertices)
    used = np.zeros(n, dtype=bool)
    for start in range(0, len(faces), _USED_CHUNK_FACES):          # bounded: len(faces) / chunk passes
        used[faces[start:start + _USED_CHUNK_FACES].ravel()] = True
    if used.all():
        return vertices, faces, owned
    renumber = np.cumsum(used, dtype=np.int64) - 1                # new index of each used vertex
    faces = faces if owned and faces.flags.writeable else faces.copy()
    for start in range(0, len(faces), _USED_CHUNK_FACES):
        block = faces[start:start + _USED_CHUNK_FACES]
        block[...] = renumber[block]
    return vertices[used], faces, True


def _float32_rounding(vertices: np.ndarray) -> float:
    """Per-coordinate rounding of float32 storage for ``vertices`` (file units): :func:`.precision.float32_rounding`
    of the largest magnitude."""
    from .precision import float32_rounding
    return float32_rounding(float(np.max(np.abs(vertices)))) if vertices.size else 0.0


def _declared_units_win(name: str, declared: tuple[float, str], units: str, scale: float) -> tuple[float, str]:
    """The rule of :data:`DECLARES_UNITS`: the file's declared unit replaces the default metres; an explicit
    other ``units`` that disagrees with it is refused (:class:`UsageError`) rather than applied twice."""
    file_scale, file_unit = declared
    if scale != 1.0 and abs(scale - file_scale) > 1e-12 * file_scale:
        raise UsageError(f"{name}: the file declares its length unit as {file_unit} ({file_scale:g} m) but "
                         f"`units` {units!r} was given; the declared unit is used when `units` is left at m")
    return file_scale, file_unit


def _from_object(source: object) -> tuple[np.ndarray, np.ndarray, str]:
    trimesh = sys.modules.get("trimesh")     # a Trimesh exists only once trimesh is imported: arrays never import it
    if trimesh is not None and isinstance(source, trimesh.Trimesh):
        return np.asarray(source.vertices, dtype=np.float64), np.asarray(source.faces), "<trimesh.Trimesh>"
    if isinstance(source, tuple) and len(source) == 2:
        v = np.asarray(source[0], dtype=np.float64)
        f = np.asarray(source[1])
        if v.ndim != 2 or v.shape[1] != 3:
            raise UsageError(f"Expected `vertices` to have shape (n, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
            raise UsageError(f"Expected `faces` to be integers of shape (m, 3), got {f.dtype} {f.shape}")
        if len(f) == 0:
            raise UsageError("Expected at least one face, got an empty `faces` array")
        if f.min() < 0 or f.max() >= len(v):
            raise UsageError(f"Expected face indices in 0..{len(v) - 1}, got {f.min()}..{f.max()}")
        if not np.all(np.isfinite(v)):
            raise UsageError("Expected finite vertex coordinates, got NaN or infinity")
        return v, f, "<arrays>"
    raise UsageError("Expected a file path, a trimesh.Trimesh or a (vertices, faces) pair, "
                     f"got {type(source).__name__}")
