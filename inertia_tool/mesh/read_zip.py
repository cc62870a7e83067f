"""Zip archives (3MF, ``.zae``, a zipped mesh): the limits checked from the central directory before anything is
inflated, and 3MF read through the streaming reader :mod:`.threemf`."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .read_base import _Counts, _display, _fail
from .regular import open_regular

if TYPE_CHECKING:
    import zipfile

    from .parts import PartTag

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
