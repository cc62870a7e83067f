"""COLLADA (``.dae``, zipped ``.zae``): the float arrays checked before pycollada parses them, and ``.dae`` read
through pycollada (:mod:`.collada`) without trimesh."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from typing import IO

import numpy as np

from ..errors import MeshReadError
from .read_base import _Counts, _display, _fail, _named_scale, _parsing
from .read_zip import _check_zip, zip_inflate_limit
from .regular import open_regular
from .scene_counts import check_collada_instances

#: A ``<float_array>`` element's opening tag (any namespace prefix; not self-closing) and its closing tag.  An
#: array's text runs from the end of its opening tag to the first closing tag after it: what the lazy
#: ``<float_array ...>(.*?)</float_array>`` matched, found with two searches (the lazy match tried the closing tag
#: at every byte: 0.12 of the 0.2 s of CPU this check cost on the UR5e's 9 MB of visual meshes, issue 23).
_ARRAY_OPENS = re.compile(rb"<(?:\w+:)?float_array\b[^>]*(?<!/)>")
_ARRAY_CLOSES = re.compile(rb"</(?:\w+:)?float_array\s*>")
_NOT_DECIMAL = re.compile(rb"[^0-9eE+\-.\s]")
#: The bytes :data:`_NOT_DECIMAL` lets through (``\s`` of a bytes pattern: space, \t, \n, \v, \f, \r).
_DECIMAL_BYTES = b"0123456789eE+-. \t\n\x0b\x0c\r"
_BIG_EXPONENT = re.compile(rb"[eE]\+?0*([1-9][0-9]+)")


def _float_arrays(data: bytes) -> Iterator[bytes]:
    """The text of each ``<float_array>`` of the COLLADA document ``data``, in order (an opening tag without a
    closing tag after it ends the search: no later one has one either)."""
    start = 0
    for _ in range(len(data) + 1):                   # bounded: each turn moves past a closing tag
        opened = _ARRAY_OPENS.search(data, start)
        if opened is None:
            return
        closed = _ARRAY_CLOSES.search(data, opened.end())
        if closed is None:
            return
        yield data[opened.end():closed.start()]
        start = closed.end()


def _check_collada_floats(name: str, data: bytes) -> None:
    """Refuse a COLLADA document whose ``<float_array>`` text holds anything but decimal numbers.

    pycollada parses each array with ``numpy.fromstring(..., float32)`` and then sets every NaN to 0, so a
    ``nan`` coordinate would silently become the origin (and ``inf``, ``1e999``, become infinity); the text is
    checked here, before it is parsed: only digits, signs, ``.``, exponents and white space may appear (an
    array whose bytes are all of those needs no search for the first that is not).
    """
    for text in _float_arrays(data):
        big = _BIG_EXPONENT.search(text)
        if big is not None and int(big.group(1)) >= 38:     # float32 overflows past 3.4e38 (trimesh then drops
            raise MeshReadError(f"{name}: a <float_array> holds a number with exponent {int(big.group(1))}, "
                                "beyond float32 (the COLLADA reader would make it infinite)")   # the faces)
        bad = _NOT_DECIMAL.search(text) if text.translate(None, _DECIMAL_BYTES) else None
        if bad is not None:
            start = text.rfind(b" ", 0, bad.start()) + 1
            token = text[start:start + 24].split()[0].decode("utf-8", "replace")
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
