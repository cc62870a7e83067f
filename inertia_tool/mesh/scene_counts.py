"""Counting what a scene file places before any parser builds it: glTF/GLB and COLLADA instances.

A scene format can place one small mesh many times (nodes, shared children, GPU instancing, COLLADA
``<instance_geometry>``), so a few megabytes of file can make trimesh build gigabytes of copies (a 10 MB GLB of
200,000 instances took 1.7 GB).  These checks read only the scene description (the glTF JSON, the COLLADA
text), count the triangles every placed instance brings, and refuse past the face limit before loading.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Callable
from typing import Any

from ..errors import MeshReadError

__all__ = ["GLTF_INSTANCE_FACES", "check_gltf", "check_collada_instances"]


def _fail(path: str, problem: str) -> MeshReadError:
    return MeshReadError(f"{os.fsencode(path).decode('utf-8', 'replace')}: {problem}")


#: Each mesh instance a glTF scene places counts as at least this many triangles against ``max_faces``:
#: trimesh spends ~8 kB per placed instance (its own copy of the mesh's arrays and a scene-graph entry), the
#: memory of ~250 triangles, so 200,000 instances of a 12-triangle box no longer pass as "2.4M triangles".
GLTF_INSTANCE_FACES = 256

_GLTF_TRIANGLE_MODES: dict[int, Callable[[int], int]] = {4: lambda n: n // 3, 5: lambda n: max(n - 2, 0),
                                                         6: lambda n: max(n - 2, 0)}


def _document(path: str) -> dict[str, Any]:
    """The JSON of a ``.gltf`` file or of a ``.glb``'s first chunk (checked against the file size)."""
    import json
    from .regular import open_regular
    with open_regular(path) as fh:
        head = fh.read(20)
        if head[:4] == b"glTF":
            if len(head) < 20:
                raise _fail(path, "GLB shorter than its 20-byte header")
            length, kind = struct.unpack_from("<I4s", head, 12)
            if kind != b"JSON" or length > os.path.getsize(path) - 20:
                raise _fail(path, f"GLB JSON chunk of {length:,} bytes does not fit the file (or is not JSON)")
            text = fh.read(length)
        else:
            fh.seek(0)
            text = fh.read()
    try:
        document = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise _fail(path, f"glTF JSON cannot be parsed ({str(exc)[:80] or type(exc).__name__})") from None
    if not isinstance(document, dict):
        raise _fail(path, "glTF JSON is not an object")
    return document


def check_gltf(path: str, size: int, max_faces: int) -> dict[str, int]:
    """Refuse a glTF scene that places more triangles than ``max_faces``, from its JSON, before trimesh builds it;
    return ``{"named_materials": n}``, the named materials its primitives use.

    A primitive's triangles follow from its accessor counts (``indices``, else ``POSITION``; mode 4: count/3,
    strips and fans: count − 2, points and lines: none).  A node places its mesh once per path to it from the
    default scene's roots (shared children repeat) and once per ``EXT_mesh_gpu_instancing`` instance; each
    placement also costs :data:`GLTF_INSTANCE_FACES`.  Node graphs deeper than 64 (a cycle) are refused.
    """
    doc = _document(path)

    def items(key: str) -> list[Any]:
        value = doc.get(key, [])
        return value if isinstance(value, list) else []

    accessors, meshes, nodes = items("accessors"), items("meshes"), items("nodes")

    def accessor_count(index: object) -> int:
        if isinstance(index, int) and 0 <= index < len(accessors) and isinstance(accessors[index], dict):
            count = accessors[index].get("count", 0)
            return count if isinstance(count, int) and count > 0 else 0
        return 0

    def mesh_triangles(index: object) -> int:
        if not (isinstance(index, int) and 0 <= index < len(meshes) and isinstance(meshes[index], dict)):
            return 0
        total = 0
        primitives = meshes[index].get("primitives")
        for primitive in primitives if isinstance(primitives, list) else []:
            if not isinstance(primitive, dict):
                continue
            rule = _GLTF_TRIANGLE_MODES.get(primitive.get("mode", 4))
            attributes = primitive.get("attributes")
            position = attributes.get("POSITION") if isinstance(attributes, dict) else None
            count = accessor_count(primitive["indices"] if "indices" in primitive else position)
            total += rule(count) if rule is not None else 0
        return total

    memo: dict[int, int] = {}

    def placed(index: object, depth: int) -> int:
        if depth > 64:
            raise _fail(path, "glTF node graph deeper than 64 levels (a cycle?)")
        if not (isinstance(index, int) and 0 <= index < len(nodes) and isinstance(nodes[index], dict)):
            return 0
        if index in memo:
            return memo[index]
        node = nodes[index]
        copies = 1
        extensions = node.get("extensions")
        extension = extensions.get("EXT_mesh_gpu_instancing") if isinstance(extensions, dict) else None
        if isinstance(extension, dict) and isinstance(extension.get("attributes"), dict):
            copies = max([accessor_count(a) for a in extension["attributes"].values()] + [1])
        total = copies * (mesh_triangles(node["mesh"]) + GLTF_INSTANCE_FACES) if "mesh" in node else 0
        children = node.get("children", [])
        for child in children if isinstance(children, list) else []:
            total += placed(child, depth + 1)
            if total > max_faces:
                break
        memo[index] = total
        return total

    scenes = items("scenes")
    chosen = doc.get("scene", 0)
    if scenes and isinstance(chosen, int) and 0 <= chosen < len(scenes) and isinstance(scenes[chosen], dict):
        roots = scenes[chosen].get("nodes", [])
    else:
        children = {c for n in nodes if isinstance(n, dict) for c in (n.get("children") or [])
                    if isinstance(c, int)}
        roots = [k for k in range(len(nodes)) if k not in children]
    total = 0
    for root in roots if isinstance(roots, list) else []:
        total += placed(root, 0)
        if total > max_faces:
            raise _fail(path, f"the glTF scene places at least {total:,} triangles (each mesh instance counted, "
                              f"and {GLTF_INSTANCE_FACES} more per instance for its copy), more than `max_faces` "
                              f"({max_faces:,}) allows; refused before loading")
    # named materials that primitives use: then the reader keeps them (per-node parts, mesh/parts.py)
    materials = items("materials")
    used = {p.get("material") for m in meshes if isinstance(m, dict) for p in (m.get("primitives") or [])
            if isinstance(p, dict)}
    named = sum(1 for k in used if isinstance(k, int) and 0 <= k < len(materials)
                and isinstance(materials[k], dict) and materials[k].get("name"))
    return {"named_materials": named}


def check_collada_instances(name: str, data: bytes, max_faces: int) -> None:
    """Refuse a COLLADA document whose ``<instance_geometry>`` and ``<instance_node>`` elements alone, at
    :data:`GLTF_INSTANCE_FACES` triangles each (the scene-graph cost of a placed instance), pass ``max_faces``."""
    instances = data.count(b"<instance_geometry") + data.count(b"<instance_node")
    if instances * GLTF_INSTANCE_FACES > max_faces:
        raise MeshReadError(f"{name}: {instances:,} geometry and node instances, each counted as "
                            f"{GLTF_INSTANCE_FACES} triangles, pass `max_faces` ({max_faces:,}); refused before "
                            "loading")
