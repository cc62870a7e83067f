"""What every mesh reader shares: the one-line read error naming the file, the face budget, header counts,
declared units, and streaming a text file in bounded blocks of whole lines.

The format readers (``read_stl``, ``read_obj``, ``read_ply``, ``read_off``, ``read_zip``, ``read_collada``,
``read_trimesh``) import from here; :mod:`.read` dispatches to them.
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import IO, TypeAlias

import numpy as np

from ..errors import MeshReadError
from ..units import LENGTH_UNITS
from .options import MAX_SUPPORTED_FACES
from .regular import open_regular

#: What a header check found: element counts by name (``"vertex"``, ``"face"``) and, for PLY, ``"float32"``
#: (1 when the vertex coordinates are stored as float32).
_Counts: TypeAlias = "dict[str, int]"
#: ``(vertices (n, 3), faces (m, 3), declared (metres per file unit, unit name) or None)`` of a reader.
_Arrays: TypeAlias = "tuple[np.ndarray, np.ndarray, tuple[float, str] | None]"


#: Formats whose files declare their length unit (3MF ``<model unit>``, default millimetre by the 3MF
#: specification; COLLADA ``<asset><unit meter>``; glTF is metres by its specification).  The declared unit
#: wins over the default ``units="m"``; an explicit other ``units`` that contradicts it is refused.
DECLARES_UNITS = (".3mf", ".dae", ".zae", ".glb", ".gltf")


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


def _header_count(path: str, word: bytes) -> int:
    try:
        n = int(word)
    except ValueError:
        raise _fail(path, f"header count {word[:20].decode('utf-8', 'replace')!r} is not an integer") from None
    if n < 0:
        raise _fail(path, f"header count {n} is negative")
    return n


def _named_scale(path: str, scale: float, spelled: str) -> tuple[float, str]:
    """``(metres per file unit, name)`` of a declared unit: a named unit when within 1e-12 of one, else
    ``"<factor> m"``; refused unless finite and positive (``spelled``: the file's spelling, for the message)."""
    if not (np.isfinite(scale) and scale > 0):
        raise _fail(path, f"declares an invalid length unit {spelled[:40]!r}")
    for name, value in LENGTH_UNITS.items():      # snap "centimeter" → 0.01 exactly (trimesh gives 0.00999…)
        if abs(scale - value) <= 1e-12 * value:
            return value, name
    return scale, f"{scale:g} m"


def _float32_rounding(vertices: np.ndarray) -> float:
    """Per-coordinate rounding of float32 storage for ``vertices`` (file units): :func:`.precision.float32_rounding`
    of the largest magnitude."""
    from .precision import float32_rounding
    return float32_rounding(float(np.max(np.abs(vertices)))) if vertices.size else 0.0


# -- text files, streamed in blocks of whole lines ------------------------------------------------------

#: Bytes read per step when streaming a text file.
_BLOCK_BYTES = 1 << 24
#: Longest text line accepted (a longer one means the file is not the text format it claims to be).
MAX_LINE_BYTES = 1 << 20


def _text_blocks(fh: IO[bytes], path: str, *, block_bytes: int | None = None,
                 max_line: int = MAX_LINE_BYTES) -> Iterator[bytes]:
    """Yield the bytes of a text file in blocks of whole lines, every line ending normalised to ``\n``.

    Reads fixed-size byte blocks and splits on any of ``\r\n``, ``\r`` (old Mac) and ``\n`` itself, carrying
    the partial last line into the next block, so memory stays bounded by ``block_bytes + max_line`` however
    the lines end.  A line longer than ``max_line`` is refused (the file is not line-structured text).
    ``block_bytes`` defaults to :data:`_BLOCK_BYTES` as it is when called (a test may set it smaller).
    """
    block_bytes = _BLOCK_BYTES if block_bytes is None else block_bytes
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
