"""Compressed single-mesh files (``part.stl.gz``, ``part.obj.bz2``, ``parts.zip`` with one mesh), inflated
with bounds into a temporary file for the readers.

The hostile-input rules of the readers (README, "Bad input") apply: the output is counted while it is
produced, and inflating stops — and the file is refused as a decompression bomb — as soon as it exceeds
``max_bytes`` or, above ``min_ratio_bytes``, ``max_ratio`` times the compressed size.  Nothing larger than
the limit is ever written or held in memory (16 MiB blocks).  A zip must hold exactly one member with a
mesh suffix (other members are refused, not guessed among; macOS ``__MACOSX/`` forks, folder metadata and an
OBJ's material library and textures are passed over, :data:`IGNORED_ZIP_MEMBERS`); its sizes are checked
from the central directory before inflating (for gzip, the size its trailer announces), and again while
inflating (a lying directory or trailer cannot get past the count).
"""

from __future__ import annotations

import bz2
import contextlib
import gzip
import os
import tempfile
import zipfile
import zlib
from collections.abc import Iterator, Sequence
from typing import IO, Protocol

from ..errors import MeshReadError
from .regular import open_regular

__all__ = ["decompressed", "BLOCK_BYTES", "IGNORED_ZIP_MEMBERS"]

#: Bytes inflated per step.
BLOCK_BYTES = 16 << 20

#: Zip members that are no part of the geometry and are passed over (not inflated): macOS resource forks
#: (``__MACOSX/``, ``._name``) and folder metadata that archivers add, and an OBJ's side files (its material
#: library and textures: colours, not mass).
IGNORED_ZIP_MEMBERS = ((".mtl", ".png", ".jpg", ".jpeg", ".tga", ".bmp"), (".ds_store", "thumbs.db", "desktop.ini"))


def _ignored(name: str) -> bool:
    """A zip member that carries no geometry (see :data:`IGNORED_ZIP_MEMBERS`)."""
    parts = name.replace("\\", "/").split("/")
    base = parts[-1].lower()
    if "__MACOSX" in parts[:-1] or base.startswith("._"):
        return True
    side, metadata = IGNORED_ZIP_MEMBERS
    return base in metadata or os.path.splitext(base)[1] in side


class _Readable(Protocol):
    def read(self, size: int, /) -> bytes: ...


def _fail(path: str, problem: str) -> MeshReadError:
    return MeshReadError(f"{os.fsencode(path).decode('utf-8', 'replace')}: {problem}")


def _copy_bounded(src: _Readable, dst: IO[bytes], path: str, compressed: int, max_bytes: int, max_ratio: float,
                  min_ratio_bytes: int) -> None:
    total = 0
    limit = min(max_bytes, max(int(compressed * max_ratio), min_ratio_bytes))
    while True:
        block = src.read(BLOCK_BYTES)
        if not block:
            return
        total += len(block)
        if total > limit:
            raise _fail(path, f"inflates beyond {limit:,} bytes ({compressed:,} compressed; limits: {max_ratio:g}:1 "
                              f"above {min_ratio_bytes:,} bytes and {max_bytes:,} bytes in all): refused as a "
                              "decompression bomb")
        dst.write(block)


@contextlib.contextmanager
def decompressed(path: str, *, max_bytes: int, max_ratio: float, min_ratio_bytes: int,
                 suffixes: Sequence[str]) -> Iterator[tuple[str, str]]:
    """Context manager yielding ``(inflated_path, member_name)`` in a temporary directory removed afterwards.

    Parameters
    ----------
    path : str
        ``*.gz``, ``*.bz2`` (the inner name is the file name without that suffix) or ``*.zip``.
    max_bytes : int
        Largest inflated size accepted.
    max_ratio : float
        Largest inflated/compressed ratio accepted once the output passes ``min_ratio_bytes``.
    suffixes : sequence of str
        Mesh suffixes the inner file may have.

    Raises
    ------
    MeshReadError
        Corrupt archive, no or several meshes in a zip, a nested compressed file, or a decompression bomb.
    """
    outer = os.path.splitext(path)[1].lower()
    compressed = os.path.getsize(path)
    with tempfile.TemporaryDirectory(prefix="inertia-tool-") as tmp:
        try:
            if outer == ".zip":
                with open_regular(path) as raw, zipfile.ZipFile(raw) as zf:
                    members = [i for i in zf.infolist() if not i.is_dir() and not _ignored(i.filename)]
                    meshes = [i for i in members if os.path.splitext(i.filename)[1].lower() in suffixes]
                    if len(meshes) != 1 or len(members) != 1:
                        names = ", ".join(i.filename[:60] for i in members[:5]) or "nothing"
                        raise _fail(path, f"a zip must hold exactly one mesh file; it holds {names}")
                    info = meshes[0]
                    member = os.path.basename(info.filename)
                    if info.flag_bits & 0x1:
                        raise _fail(path, f"member {member[:60]!r} is encrypted (password-protected): it cannot be "
                                          "read")
                    ratio_limit = max(int(info.compress_size * max_ratio), min_ratio_bytes)
                    if info.file_size > min(max_bytes, ratio_limit):
                        raise _fail(path, f"member {member[:60]!r} would inflate to {info.file_size:,} bytes from "
                                          f"{info.compress_size:,}: refused as a decompression bomb before inflating")
                    target = os.path.join(tmp, member)
                    with zf.open(info) as src, open(target, "wb") as dst:
                        _copy_bounded(src, dst, path, info.compress_size, max_bytes, max_ratio, min_ratio_bytes)
            else:
                member = os.path.basename(path)[:-len(outer)]
                if os.path.splitext(member)[1].lower() not in suffixes:
                    raise _fail(path, f"the compressed file {member[:60]!r} is not a mesh with a known suffix "
                                      f"({', '.join(suffixes)})")
                if outer == ".gz" and compressed >= 18:        # ISIZE trailer: size mod 2³², a cheap first look
                    with open_regular(path) as fh:
                        fh.seek(-4, os.SEEK_END)
                        announced = int.from_bytes(fh.read(4), "little")
                    ratio_limit = max(int(compressed * max_ratio), min_ratio_bytes)
                    if announced > min(max_bytes, ratio_limit):
                        raise _fail(path, f"announces {announced:,} bytes inflated from {compressed:,}: refused as a "
                                          "decompression bomb before inflating")
                target = os.path.join(tmp, member)
                with open_regular(path) as raw, \
                        (gzip.GzipFile(fileobj=raw) if outer == ".gz" else bz2.BZ2File(raw)) as src, \
                        open(target, "wb") as dst:
                    _copy_bounded(src, dst, path, compressed, max_bytes, max_ratio, min_ratio_bytes)
        except MeshReadError:
            raise
        except (OSError, EOFError, zipfile.BadZipFile, zlib.error, ValueError, RuntimeError,
                NotImplementedError) as exc:
            raise _fail(path, f"cannot be decompressed ({str(exc)[:120] or type(exc).__name__})") from None
        yield target, member
