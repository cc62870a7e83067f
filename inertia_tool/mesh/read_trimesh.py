"""The formats read through trimesh (ASCII PLY, glTF/GLB, ``.zae``), with their headers checked first; the dispatch
of every format that is not STL, OBJ, OFF or a B-rep (3MF, ``.dae`` and binary PLY go to their own readers from
here)."""

from __future__ import annotations

import os
import warnings
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import MeshReadError
from .read_base import (DECLARES_UNITS, _Arrays, _check_face_budget, _Counts, _fail, _float32_rounding, _named_scale,
                        _parse_failure)
from .read_collada import _check_collada, _check_zipped_collada, _read_collada
from .read_off import _check_off_header
from .read_ply import _check_ply_header, _ply_polygons_clipped, _read_binary_ply
from .read_zip import _read_3mf
from .regular import open_regular, regular_file_resolver
from .scene_counts import check_gltf

if TYPE_CHECKING:
    from .parts import PartTag

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


def _read_with_trimesh(path: str, max_faces: int) -> _Arrays:
    """``(vertices, faces, declared unit)`` of a file trimesh reads (see :func:`_read_with_trimesh_rounding`)."""
    vertices, faces, declared, _ = _read_with_trimesh_rounding(path, max_faces)
    return vertices, faces, declared


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
    if suffix == ".ply" and counts.get("binary"):
        native = _read_binary_ply(path)          # trimesh refuses face lists of mixed lengths (review 12, R2)
        if native is not None:
            v, f = _checked_arrays(path, *native, counts, max_faces)
            return v, f, None, _float32_rounding(v) if counts.get("float32") else 0.0
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
    import logging  # imported on use, like trimesh: only the formats trimesh reads need it
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
                    from .parts import primitive_frames, scene_parts
                    graph = loaded.graph
                    parts = scene_parts(geoms, primitive_frames(list(graph.nodes_geometry),
                                                                dict(graph.transforms.parents)))
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
