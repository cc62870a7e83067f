"""Reading meshes: files (STL natively; OBJ, PLY, OFF, 3MF, ... through trimesh), trimesh objects and arrays.

The reader's only job is bytes → triangles in metres.  It checks what a file claims against what it holds
before allocating anything, never reads a huge ASCII file into memory at once, and reports every problem as
a :class:`~inertia_tool.errors.MeshReadError` naming the file.  Topology checks live in ``checks``.

Binary STL is read directly with numpy in bounded chunks (much faster than a general loader), and shared
corners are welded exactly (bit-identical coordinates) into an indexed mesh on the way, so the triangle
soup never has to exist in float64.
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import MeshReadError, TrailingDataWarning, UsageError
from .units import length_scale
from .weld import weld_exact, weld_exact_stream

__all__ = ["RawMesh", "load_mesh", "read_stl", "DEFAULT_MAX_FACES", "SUPPORTED_SUFFIXES"]

#: Default guard on the number of triangles a file may hold (about 5 GB of working memory at the limit).
DEFAULT_MAX_FACES = 50_000_000

#: File suffixes handled (STL natively, the rest through trimesh).
SUPPORTED_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".3mf", ".glb", ".gltf")

_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
_CHUNK_FACES = 1 << 17


@dataclass(frozen=True)
class RawMesh:
    """An indexed triangle mesh as read, in metres.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes (file coordinates times the unit scale).
    faces : (m, 3) int
        Indices into ``vertices``, as wound in the file.
    source : str
        File path or a description of the object it came from (for messages).
    units : str
        Length unit of the file coordinates.
    file_faces : int
        Number of triangles the source held (before any cleaning).
    """

    vertices: np.ndarray
    faces: np.ndarray
    source: str
    units: str = "m"
    file_faces: int = 0


def _fail(path: str, problem: str) -> MeshReadError:
    return MeshReadError(f"{path}: {problem}")


def _check_face_budget(path: str, n: int, max_faces: int) -> None:
    if n > max_faces:
        raise _fail(path, f"holds {n:,} triangles, more than --max-faces {max_faces:,} allows")


# -- STL ------------------------------------------------------------------------------------------------

def _looks_ascii_stl(head: bytes) -> bool:
    text = head.lstrip()
    if not text[:5].lower() == b"solid":
        return False
    # a binary STL may start with "solid" in its header; ASCII has "facet" soon and no NUL bytes
    window = head[:1024]
    return b"\x00" not in window and (b"facet" in window.lower() or b"endsolid" in window.lower()
                                      or len(head) < 84)


def _binary_stl_count(path: str, size: int, max_faces: int) -> int:
    """Validate a binary STL's header against its size (before allocating) and return the triangle count."""
    if size < 84:
        raise _fail(path, f"too short for a binary STL ({size} bytes; the header alone is 84)")
    with open(path, "rb") as fh:
        fh.seek(80)
        n = int(np.frombuffer(fh.read(4), dtype="<u4")[0])
    available = (size - 84) // 50
    if n > available:
        raise _fail(path, f"binary STL header announces {n:,} triangles but the file holds at most "
                          f"{available:,} ({size:,} bytes): truncated or not an STL")
    _check_face_budget(path, n, max_faces)
    extra = size - 84 - 50 * n
    if extra:
        warnings.warn(TrailingDataWarning(f"{path}: {extra:,} bytes after the {n:,} triangles the header "
                                          "announces were ignored"), stacklevel=4)
    return n


def _binary_stl_chunks(path: str, n: int):
    """A factory of iterators over the corners of a binary STL, ``(k, 4)`` float32 chunks ``(x, y, z, 0)``
    in file order (the padded layout lets ``weld`` hash a corner as two 64-bit words).

    Each call re-reads the file in bounded chunks (the second read comes from the page cache), so the whole
    triangle soup is never held in memory.
    """
    def chunks():
        with open(path, "rb") as fh:
            fh.seek(84)
            done = 0
            while done < n:
                k = min(_CHUNK_FACES, n - done)
                rec = np.fromfile(fh, dtype=_STL_RECORD, count=k)
                if len(rec) != k:
                    raise _fail(path, f"ended after {done + len(rec):,} of {n:,} triangles")
                corners = np.zeros((3 * k, 4), dtype=np.float32)   # (x, y, z, 0): see weld._hash_rows
                corners[:, :3] = rec["v"].reshape(-1, 3)
                if not np.all(np.isfinite(corners)):
                    raise _fail(path, "triangles have NaN or infinite coordinates")
                done += k
                yield corners
    return chunks


_VERTEX_RE = re.compile(rb"^\s*vertex\s+(\S+)\s+(\S+)\s+(\S+)\s*$", re.MULTILINE | re.IGNORECASE)


def _read_ascii_stl(path: str, size: int, max_faces: int) -> tuple[np.ndarray, int]:
    """Stream an ASCII STL; only ``vertex`` lines carry data, in groups of three per facet."""
    # a vertex line has at least ~20 bytes: bound the corner count by the file size before allocating
    _check_face_budget(path, size // 60, max_faces) if size // 60 > max_faces else None
    blocks = []
    count = 0
    line_no = 0
    with open(path, "rb") as fh:
        while True:
            lines = fh.readlines(1 << 24)
            if not lines:
                break
            data = b"".join(lines).replace(b"\r\n", b"\n").replace(b"\r", b"\n")
            lines = data.split(b"\n")
            found = _VERTEX_RE.findall(data)
            n_vertex_words = len(re.findall(rb"\bvertex\b", data, re.IGNORECASE))
            if n_vertex_words != len(found):
                # locate the first malformed vertex line for the message
                for i, line in enumerate(lines):
                    if re.search(rb"\bvertex\b", line, re.IGNORECASE) and not _VERTEX_RE.match(line):
                        raise _fail(path, f"line {line_no + i + 1}: malformed vertex line "
                                          f"{line.strip()[:60].decode('latin-1')!r}")
            if found:
                try:
                    arr = np.array(found, dtype=np.float64)
                except ValueError:
                    for i, line in enumerate(lines):
                        m = _VERTEX_RE.match(line)
                        if m:
                            try:
                                [float(x) for x in m.groups()]
                            except ValueError:
                                raise _fail(path, f"line {line_no + i + 1}: vertex coordinate is not a number: "
                                                  f"{line.strip()[:60].decode('latin-1')!r}") from None
                    raise _fail(path, "vertex coordinates are not numbers") from None
                blocks.append(arr)
                count += len(arr)
                _check_face_budget(path, count // 3, max_faces)
            line_no += len(lines)
    if count == 0:
        raise _fail(path, "ASCII STL without any 'vertex' line (empty mesh)")
    if count % 3:
        raise _fail(path, f"ASCII STL has {count:,} vertex lines, not a multiple of 3")
    corners = np.concatenate(blocks).reshape(-1, 3, 3)
    return corners, len(corners)


def read_stl(path, *, max_faces: int = DEFAULT_MAX_FACES) -> tuple[np.ndarray, np.ndarray, int]:
    """Read an STL file (binary or ASCII) into an exactly welded indexed mesh in file units.

    Returns
    -------
    vertices : (n, 3) float64
    faces : (m, 3) int
    file_faces : int
    """
    path = os.fspath(path)
    size = os.path.getsize(path)
    if size == 0:
        raise _fail(path, "empty file (0 bytes)")
    with open(path, "rb") as fh:
        head = fh.read(4096)
    binary_size_matches = False
    if size >= 84:
        n = int(np.frombuffer(head[80:84], dtype="<u4")[0]) if len(head) >= 84 else -1
        binary_size_matches = n >= 0 and 84 + 50 * n == size
    if binary_size_matches or not _looks_ascii_stl(head):
        n = _binary_stl_count(path, size, max_faces)
        if n == 0:
            raise _fail(path, "STL holds no triangles (empty mesh)")
        vertices, faces = weld_exact_stream(_binary_stl_chunks(path, n), 3 * n)
        return vertices, faces, n
    corners, n = _read_ascii_stl(path, size, max_faces)
    if not np.all(np.isfinite(corners)):
        bad = int(np.count_nonzero(~np.isfinite(corners).all(axis=(1, 2))))
        raise _fail(path, f"{bad:,} triangles have NaN or infinite coordinates")
    vertices, faces = weld_exact(corners)
    return vertices, faces, n


# -- other formats through trimesh ----------------------------------------------------------------------

def _read_with_trimesh(path: str, max_faces: int):
    try:
        import trimesh
    except ImportError as exc:  # pragma: no cover - trimesh is a dependency
        raise _fail(path, "reading this format needs trimesh (pip install trimesh)") from exc
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            loaded = trimesh.load(path, process=False, force=None)
    except MeshReadError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure is a read error with the file named
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise _fail(path, f"could not be parsed ({msg[:200]})") from None
    if isinstance(loaded, trimesh.Scene):
        geoms = [g for g in loaded.dump() if isinstance(g, trimesh.Trimesh)] if loaded.geometry else []
        if not geoms:
            raise _fail(path, "contains no triangle mesh (empty scene or only points/lines)")
        loaded = trimesh.util.concatenate(geoms)
    if not isinstance(loaded, trimesh.Trimesh):
        raise _fail(path, f"contains no triangle mesh (found {type(loaded).__name__})")
    v = np.asarray(loaded.vertices, dtype=np.float64)
    f = np.asarray(loaded.faces)
    if len(f) == 0:
        raise _fail(path, "contains no triangles (empty mesh or point cloud)")
    _check_face_budget(path, len(f), max_faces)
    if f.ndim != 2 or f.shape[1] != 3:
        raise _fail(path, f"faces are not triangles (shape {f.shape})")
    if f.min() < 0 or f.max() >= len(v):
        raise _fail(path, f"face indices out of range (0..{len(v) - 1})")
    if not np.all(np.isfinite(v)):
        raise _fail(path, "vertices have NaN or infinite coordinates")
    return v, f


def load_mesh(source, *, units: str = "m", max_faces: int = DEFAULT_MAX_FACES) -> RawMesh:
    """Read a mesh and convert it to metres.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        A file (format from its suffix; STL read natively), a ``trimesh.Trimesh``, or a pair of arrays
        ``vertices (n, 3)`` and ``faces (m, 3)``.
    units : str
        Length unit of the coordinates (``m``, ``cm``, ``mm``, ``um``, ``in``, ``ft``).
    max_faces : int
        Refuse sources with more triangles than this (protects memory).

    Returns
    -------
    RawMesh

    Raises
    ------
    MeshReadError
        The file does not exist, is a directory, is empty, truncated, not a mesh, or too large.
    UsageError
        Bad ``units`` or malformed arrays.
    """
    scale = length_scale(units)
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        if not os.path.exists(path):
            raise _fail(path, "no such file")
        if os.path.isdir(path):
            raise _fail(path, "is a directory, not a mesh file")
        try:
            suffix = os.path.splitext(path)[1].lower()
            if suffix == ".stl":
                vertices, faces, n = read_stl(path, max_faces=max_faces)
            elif suffix in SUPPORTED_SUFFIXES:
                if os.path.getsize(path) == 0:
                    raise _fail(path, "empty file (0 bytes)")
                vertices, faces = _read_with_trimesh(path, max_faces)
                n = len(faces)
            else:
                raise _fail(path, f"unsupported file type {suffix or '(no suffix)'!r}; expected one of "
                                  f"{', '.join(SUPPORTED_SUFFIXES)}")
        except PermissionError:
            raise _fail(path, "permission denied") from None
        except IsADirectoryError:
            raise _fail(path, "is a directory, not a mesh file") from None
        except MemoryError:
            raise _fail(path, "too large to read into memory (see --max-faces)") from None
        except OSError as exc:
            if isinstance(exc, MeshReadError):
                raise
            raise _fail(path, f"cannot be read ({exc.strerror or exc})") from None
        name = path
    else:
        vertices, faces, name = _from_object(source)
        n = len(faces)
        _check_face_budget(name, n, max_faces)
    if scale != 1.0:
        vertices = vertices * scale
    return RawMesh(vertices=vertices, faces=faces, source=name, units=str(units), file_faces=n)


def _from_object(source):
    try:
        import trimesh
        if isinstance(source, trimesh.Trimesh):
            return np.asarray(source.vertices, dtype=np.float64), np.asarray(source.faces), "<trimesh.Trimesh>"
    except ImportError:  # pragma: no cover
        pass
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
    raise UsageError(f"Expected a file path, a trimesh.Trimesh or a (vertices, faces) pair, got {type(source).__name__}")
