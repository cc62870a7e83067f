"""The parts of one file that carries several materials: their names, the materials the file gives them, and the
sub-mesh of each.

A multi-material file (a 3MF with base materials or a slicer's filament assignments, a STEP assembly) is read
into one :class:`~inertia_tool.mesh.read.RawMesh` whose ``parts`` list :class:`PartTag` s: each names a range of
its faces and what the file says about that range's material.  The mass layer
(:mod:`inertia_tool.mass.materials`) turns the names into densities and integrates each part on its own.

Names: a part is called by the name the file gives it (object, slicer volume, STEP label), else
``object ID``; a name that repeats (several instances of one object) gets `` #2``, `` #3``.  ``addresses`` are
every name ``--material-map`` may use for it (see docs/usage.md).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ..errors import MeshReadError

if TYPE_CHECKING:  # pragma: no cover
    from .read import RawMesh
    from .threemf import PlacedObject

__all__ = ["PartTag", "part_mesh", "split_parts", "threemf_parts", "cad_parts", "scene_parts", "primitive_frames",
           "unique_names"]


class PartTag(NamedTuple):
    """One part of a multi-material file.

    Attributes
    ----------
    name : str
        The part's name, unique within the file.
    addresses : tuple of str
        Names ``material_map`` may address it by: its name, then e.g. ``object 3`` (3MF object id).
    material : str or None
        The material the file names for it (a 3MF base material, a slicer's filament type, a STEP material);
        None when it names none.
    density : float or None
        kg/m³ the file itself gives for that material; None when it gives none.
    origin : str
        Where ``material`` comes from, for reports (``"3MF basematerials"``, ``"PrusaSlicer extruder 2"``).
    faces : (int, int)
        Its range ``[start, stop)`` of the mesh's faces.
    role : str
        ``"part"`` (material); ``"negative"`` (a volume a slicer subtracts); ``"modifier"``, ``"support
        blocker"``, ``"support enforcer"``: slicer volumes that are not material.
    """

    name: str
    addresses: tuple[str, ...]
    material: str | None
    density: float | None
    origin: str
    faces: tuple[int, int]
    role: str = "part"


def unique_names(names: Sequence[str]) -> list[str]:
    """``names`` with a repeated one numbered: ``a, a #2, a #3`` (the first keeps its name)."""
    seen: dict[str, int] = {}
    out = []
    for name in names:
        seen[name] = seen.get(name, 0) + 1
        out.append(name if seen[name] == 1 else f"{name} #{seen[name]}")
    return out


def part_mesh(vertices: np.ndarray, faces: np.ndarray, tag: PartTag) -> tuple[np.ndarray, np.ndarray]:
    """The vertices and faces of ``tag``'s face range alone (vertices it does not use dropped, indices renumbered)."""
    start, stop = tag.faces
    own = np.asarray(faces[start:stop])
    used, inverse = np.unique(own.ravel(), return_inverse=True)
    return np.asarray(vertices)[used], inverse.reshape(own.shape).astype(np.int64)


def _slot_material(slot: int, types: list[str], densities: list[float | None]) -> tuple[str, float | None]:
    """The filament type and density (kg/m³) of 1-based ``slot``; ``filament N`` when the project lists none."""
    kind = types[slot - 1] if 0 < slot <= len(types) and types[slot - 1] else f"filament {slot}"
    density = densities[slot - 1] if 0 < slot <= len(densities) else None
    return kind, density


def threemf_parts(placed: Sequence[PlacedObject], slicer: tuple[Any, ...], name: str) -> tuple[PartTag, ...]:
    """The parts of a 3MF build: one per placed object, split by a slicer's volumes where its config has them.

    Parameters
    ----------
    placed : sequence of :class:`~inertia_tool.mesh.threemf.PlacedObject`
    slicer : (objects, types, densities)
        :func:`~inertia_tool.mesh.slicers.read_slicer_config` of the project.
    name : str
        The file, for messages.

    Returns
    -------
    tuple of PartTag
        Empty when nothing in the file names a material or a volume role (the file is then one solid of
        one material, as before).
    """
    objects, types, densities = slicer
    rows: list[tuple[str, tuple[str, ...], str | None, float | None, str, tuple[int, int], str]] = []
    for p in placed:
        start, stop = p.faces
        address = (f"object {p.key}",) if p.key == p.item else (f"object {p.key}", f"object {p.item}")
        config = objects.get(str(p.item)) if p.item is not None else None
        if config is not None and config.slicer == "PrusaSlicer" and config.volumes:
            ranges = sorted(v.faces or (0, 0) for v in config.volumes)
            covered = [0] + [r[1] for r in ranges]
            if any(r[0] != c for r, c in zip(ranges, covered)) or covered[-1] != stop - start:
                raise MeshReadError(f"{name}: the PrusaSlicer volumes of object {p.key} do not cover its "
                                    f"{stop - start} triangles exactly once (ranges "
                                    f"{', '.join(f'{a}..{b - 1}' for a, b in ranges[:6])})")
            for volume in config.volumes:
                first, last = volume.faces or (0, 0)
                material, density = _slot_material(volume.extruder, types, densities)
                label = volume.name or config.name or p.name or f"object {p.key}"
                rows.append((label, address, material, density, f"PrusaSlicer extruder {volume.extruder}",
                             (start + first, start + last), volume.role))
            continue
        if config is not None and config.slicer == "Bambu Studio":
            volume = next((v for v in config.volumes if v.component == str(p.key)), None)
            if volume is not None or not config.volumes:
                extruder = volume.extruder if volume is not None else config.extruder
                material, density = _slot_material(extruder, types, densities)
                label = (volume.name if volume is not None else None) or p.name or config.name or f"object {p.key}"
                rows.append((label, address, material, density, f"Bambu Studio extruder {extruder}", (start, stop),
                             volume.role if volume is not None else "part"))
                continue
        label = p.name or p.item_name or f"object {p.key}"
        if len(p.materials) > 1:
            listed = ", ".join(m[0] for m in p.materials)
            raise MeshReadError(f"{name}: object {p.key} ({label}) names several materials on its triangles "
                                f"({listed}) and none for its volume (pid/pindex on the <object>); which fills it "
                                "is not said")
        own: str | None = p.materials[0][0] if p.materials else None
        density = p.materials[0][1] if p.materials else None
        rows.append((label, address, own, density, "3MF basematerials" if own else "", (start, stop),
                     "part"))
    if not any(r[2] is not None or r[6] != "part" for r in rows):
        return ()
    names = unique_names([r[0] for r in rows])
    return tuple(PartTag(n, tuple(dict.fromkeys((n, r[0], *r[1]))), r[2], r[3], r[4], r[5], r[6])
                 for n, r in zip(names, rows))


def cad_parts(found: Sequence[tuple[str, str | None, float | None, int, int]]) -> tuple[PartTag, ...]:
    """The parts of a STEP assembly (:attr:`~inertia_tool.mesh.cad.CadReading.parts`): names made unique,
    the material and density of its XCAF document."""
    names = unique_names([f[0] for f in found])
    return tuple(PartTag(n, tuple(dict.fromkeys((n, f[0]))), f[1], f[2], "STEP material" if f[1] else "",
                         (f[3], f[4])) for n, f in zip(names, found))


def primitive_frames(nodes: Sequence[str], parents: Mapping[str, str]) -> dict[str, str]:
    """Stable names for the frames trimesh invents for the primitives of a glTF mesh with more than one: it names
    each ``{node}_{6 random hex digits}`` (new on every load), so a part name built on it changed from run to run
    and could not be given back in ``--material-map``.  Such a frame (a child of ``node`` named so) becomes
    ``{node} primitive {k}``, ``k`` counting from 1 in ``nodes`` order (``Scene.dump``'s); other names are kept."""
    out: dict[str, str] = {}
    counts: dict[str, int] = {}
    for name in nodes:
        parent = parents.get(name)
        if parent is not None and re.fullmatch(re.escape(str(parent)) + r"_[0-9a-f]{6}", str(name)):
            counts[parent] = counts.get(parent, 0) + 1
            out[name] = f"{parent} primitive {counts[parent]}"
    return out


def scene_parts(geometries: Sequence[Any], renamed: Mapping[str, str] | None = None) -> tuple[PartTag, ...]:
    """The parts of a glTF scene, one per mesh node (``trimesh.Scene.dump`` order, the order the reader
    concatenates them in): the node's name (``renamed``'s where it has one: :func:`primitive_frames`), the name
    of its primitive's material (trimesh's ``visual.material.name``).  Empty for a single node or when no node's
    mesh has a named material."""
    rows: list[tuple[str, str | None, tuple[int, int]]] = []
    start = 0
    for geometry in geometries:
        material = getattr(getattr(geometry.visual, "material", None), "name", None)
        node = geometry.metadata.get("node") or geometry.metadata.get("name") or f"node {len(rows) + 1}"
        node = (renamed or {}).get(node, node)
        rows.append((str(node), str(material) if material else None, (start, start + len(geometry.faces))))
        start += len(geometry.faces)
    if len(rows) < 2 or not any(r[1] for r in rows):
        return ()
    names = unique_names([r[0] for r in rows])
    return tuple(PartTag(n, tuple(dict.fromkeys((n, r[0]))), r[1], None, "glTF material" if r[1] else "", r[2])
                 for n, r in zip(names, rows))


def split_parts(raw: RawMesh) -> list[tuple[PartTag, RawMesh]]:
    """One :class:`~inertia_tool.mesh.read.RawMesh` per part of ``raw`` (in its order, with its tag), each
    named ``"FILE [part]"`` for messages; every field but the geometry is ``raw``'s."""
    from .read import RawMesh
    out: list[tuple[PartTag, RawMesh]] = []
    for tag in raw.parts:
        vertices, faces = part_mesh(raw.vertices, raw.faces, tag)
        out.append((tag, RawMesh(vertices=vertices, faces=faces, source=f"{raw.source} [{tag.name}]", units=raw.units,
                                 file_faces=len(faces), units_assumed=raw.units_assumed,
                                 storage_rounding=raw.storage_rounding, scale_rounding=raw.scale_rounding)))
    return out
