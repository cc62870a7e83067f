"""Densities for the parts of a multi-material file, and the file as an assembly of them.

A file that names materials per part (:mod:`inertia_tool.mesh.parts`) is integrated part by part, each with
its own density, and the parts are joined by :func:`~inertia_tool.mass.properties.combine` (masses add; each
central tensor is moved to the common centre of mass by the parallel-axis theorem, Chapter 4 "Rigid Body
Motion", Eq. (4.16)).  A file whose parts are all of one material (or none), given ``density`` or ``material``
and no ``material_map``, takes that for all of them, as any file of one material does.  Otherwise the density
of a part is decided by one rule, first match wins:

1. ``material_map`` names the part (by any of its ``addresses``: its name, ``object ID``);
2. ``material_map`` names the part's material (case and spacing ignored);
3. the file gives a density for that material (a slicer's ``filament_density``, the ``it:density`` spin-it
   writes on a 3MF base material);
4. the material's name is in :data:`inertia_tool.units.MATERIALS` (or one of its aliases);
5. a glTF part whose material (an appearance) is unknown, and a part the file names no material for, take
   ``density``/``material``, the default for the file; when no part of the file names a material (a slicer
   project whose volumes name no filament), without a default they all take
   :data:`~inertia_tool.mass.pipeline.DEFAULT_DENSITY` (water), as a file of one part does, and say so.

Anything else is refused (:class:`~inertia_tool.errors.MaterialError`) with the name to map: a density is
never guessed.  A ``material_map`` entry that matches nothing is refused too (a typo would otherwise be
silently ignored).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidMeshError, MaterialError, NonMaterialVolumeWarning, UsageError
from ..mesh.parts import PartTag, split_parts
from ..tolerances import PART_OVERLAP_RTOL
from ..units import MATERIALS, material_density
from .pipeline import DEFAULT_DENSITY

if TYPE_CHECKING:  # pragma: no cover
    from ..mesh.read import RawMesh

__all__ = ["material_parts", "unused_map_keys", "normalise_name", "APPEARANCE_ORIGINS"]

#: Origins of material names that name an appearance rather than a physical material (glTF materials are
#: render settings: "Material.001", "Brushed metal"): a name the rule cannot map takes the file's default when
#: one is given, instead of being refused.
APPEARANCE_ORIGINS = ("glTF material",)


def normalise_name(name: str) -> str:
    """A name as compared: lower case, runs of spaces and ``_`` as one space."""
    return " ".join(str(name).strip().lower().replace("_", " ").split())


def _in_table(name: str) -> float | None:
    try:
        return material_density(name)
    except MaterialError:
        return None


def _mapped(value: float | str, key: str, where: str) -> tuple[float, str]:
    """A ``material_map`` value: a density (kg/m³) or a material name of the table → (density, label)."""
    if isinstance(value, str):
        try:
            return material_density(value), value
        except MaterialError:
            raise MaterialError(f"{where}: `material_map` gives {key!r} the material {value!r}, which is not in "
                                f"the material table ({', '.join(sorted(MATERIALS))}); give a density instead "
                                f"(e.g. {key}=1.24g/cm3)") from None
    number = float(value)
    if not (np.isfinite(number) and number > 0):
        raise UsageError(f"{where}: `material_map` gives {key!r} the density {value!r}; expected a positive "
                         "finite number of kg/m³")
    return number, ""


def _decide(tag: PartTag, where: str, mapping: dict[str, tuple[str, float | str]], used: set[str],
            density: float | None, material: str | None, any_material: bool) -> tuple[float, str, str]:
    """``(density kg/m³, material label, how it was decided)`` of one part, by the rule of the module."""
    for address in tag.addresses:
        hit = mapping.get(normalise_name(address))
        if hit is not None:
            used.add(hit[0])
            rho, label = _mapped(hit[1], hit[0], where)
            return rho, label or tag.material or "", f"material_map {hit[0]}"
    if tag.material is not None:
        hit = mapping.get(normalise_name(tag.material))
        if hit is not None:
            used.add(hit[0])
            rho, label = _mapped(hit[1], hit[0], where)
            return rho, label or tag.material, f"material_map {hit[0]}"
        if tag.density is not None:
            return tag.density, tag.material, f"the file ({tag.origin})"
        known = _in_table(tag.material)
        if known is not None:
            return known, tag.material, f"material table ({tag.origin})"
        if tag.origin in APPEARANCE_ORIGINS and (density is not None or material is not None):
            # an appearance's name ("Material.001") says nothing of the density: the given default does
            return (density if density is not None else material_density(str(material)), material or "",
                    "the file's default")
        either = (", or one for every part with `density` or `material` (an appearance's name says nothing of "
                  "the density)") if tag.origin in APPEARANCE_ORIGINS else ""
        raise MaterialError(f"{where}: part {tag.name!r} is of material {tag.material!r} ({tag.origin}), which is "
                            "not in the material table, and the file gives no density for it; give one with "
                            f"`material_map` ({tag.material}=1.24g/cm3 or {tag.material}=pla){either}")
    if density is not None:
        return density, "", "the file's default"
    if material is not None:
        return material_density(material), material, "the file's default"
    if not any_material:
        return DEFAULT_DENSITY, "", "default (water)"
    raise MaterialError(f"{where}: part {tag.name!r} has no material in the file while other parts have; give it "
                        f"one with `material_map` ({tag.name}=MATERIAL or {tag.name}=DENSITY) or a default for the "
                        "file (FILE:material, `density`, `material`)")


def material_parts(raw: RawMesh, *, material_map: Mapping[str, float | str] | None = None, density: float | None = None,
                   material: str | None = None, used: set[str] | None = None) -> list[dict[str, Any]]:
    """The parts of a multi-material ``RawMesh`` as :func:`~inertia_tool.mass.pipeline.assembly` specs.

    Parameters
    ----------
    raw : RawMesh
        With ``parts`` (:mod:`inertia_tool.mesh.parts`).
    material_map : mapping of str to float or str, optional
        Part name, ``object ID`` or material name → density (kg/m³) or material name of the table.
    density, material : optional
        The default for the parts the file names no material for (at most one).
    used : set of str, optional
        Filled with the ``material_map`` keys that matched (for :func:`unused_map_keys`).

    Returns
    -------
    list of dict
        ``{"source": RawMesh of the part, "density": kg/m³, "name": part name, "material_label": material,
        "decided_by": how, "file_part": True}`` (pop ``decided_by`` before passing them on).  Slicer volumes
        that are not material are left out (:class:`~inertia_tool.errors.NonMaterialVolumeWarning`); parts of
        one material that overlap are joined into one, ``"a + b"``, whose union is integrated.

    Raises
    ------
    MaterialError
        A part whose density the rule cannot decide.
    InvalidMeshError
        A slicer's negative volume (subtracted material): not supported.
    UsageError
        A default that would apply to no part (every part has a material of its own, of several materials).

    A file whose parts are all of one material (or none) takes a given ``density``/``material`` for all of
    them, as a file of one material does (without ``material_map``).
    """
    where = raw.source
    mapping = {normalise_name(k): (k, v) for k, v in (material_map or {}).items()}
    used = used if used is not None else set()
    specs: list[dict[str, Any]] = []
    skipped = []
    any_material = any(t.material is not None for t in raw.parts)
    # a file of one material (a slicer project printed in one filament): a given density or material is the
    # user's word for all of it, as for any file of one material; several materials need `material_map`
    kinds = {None if t.material is None else normalise_name(t.material) for t in raw.parts if t.role == "part"}
    override = (density is not None or material is not None) and not mapping and len(kinds) == 1
    for tag, part in split_parts(raw):
        if tag.role == "negative":
            raise InvalidMeshError(f"{where}: part {tag.name!r} is a negative volume (material the slicer "
                                   "subtracts); subtracting it is not supported: remove it or apply it in the "
                                   "slicer (Boolean) and export again")
        if tag.role != "part":
            skipped.append(f"{tag.name!r} ({tag.role})")
            continue
        if override:
            rho = density if density is not None else material_density(str(material))
            label, how = material or "", "the file's default"
        else:
            rho, label, how = _decide(tag, where, mapping, used, density, material, any_material)
        specs.append({"source": part, "density": rho, "name": tag.name, "material_label": label,
                      "decided_by": how, "file_part": True})
    if skipped:
        warnings.warn(NonMaterialVolumeWarning(f"{where}: slicer volumes that are not material left out: "
                                               f"{', '.join(skipped)}"), stacklevel=2)
    if not specs:
        raise InvalidMeshError(f"{where}: no part of the file is material (only slicer modifiers)")
    specs = _unite_same_material(specs)
    if (density is not None or material is not None) and all(s["decided_by"] != "the file's default"
                                                            for s in specs):
        option = "`density`" if density is not None else "`material`"
        raise UsageError(f"{where}: {option} would apply to no part: every part has a material of its own in "
                         "the file (override one with `material_map`)")
    return specs


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Σ v0 · (v1 × v2) / 6 of a closed outward-wound mesh (the divergence theorem), m³."""
    v = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


def _unite_same_material(specs: list[dict[str, Any]], rtol: float = PART_OVERLAP_RTOL) -> list[dict[str, Any]]:
    """Parts of one material and density that overlap (share more than ``rtol`` of the smaller one's volume,
    :func:`~inertia_tool.mesh.overlap.shared_volumes`) become one part, ``"a + b"``, whose mesh holds both:
    the mesh layer then integrates their union, as it did when the file was read as one solid.  Parts of
    different materials are left apart (which material fills the shared volume is not said; the assembly
    warns)."""
    from ..mesh.overlap import shared_volumes
    from ..mesh.read import RawMesh
    groups: dict[tuple[float, str], list[int]] = {}
    for k, spec in enumerate(specs):
        groups.setdefault((float(spec["density"]), str(spec["material_label"])), []).append(k)
    parent = list(range(len(specs)))

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for members in groups.values():
        if len(members) < 2:
            continue
        meshes = [(specs[k]["source"].vertices, specs[k]["source"].faces) for k in members]
        shared = shared_volumes(meshes)
        if not shared:
            continue
        volumes = [abs(_signed_volume(v, f)) for v, f in meshes]
        for (i, j), volume in shared.items():
            if volume > rtol * min(volumes[i], volumes[j]):
                parent[root(members[i])] = root(members[j])
    joined: dict[int, list[int]] = {}
    for k in range(len(specs)):
        joined.setdefault(root(k), []).append(k)
    if all(len(ks) == 1 for ks in joined.values()):
        return specs
    out = []
    for ks in sorted(joined.values()):
        if len(ks) == 1:
            out.append(specs[ks[0]])
            continue
        first = specs[ks[0]]["source"]
        offsets = np.cumsum([0] + [len(specs[k]["source"].vertices) for k in ks[:-1]])
        name = " + ".join(specs[k]["name"] for k in ks)
        mesh = RawMesh(vertices=np.vstack([specs[k]["source"].vertices for k in ks]),
                       faces=np.vstack([np.asarray(specs[k]["source"].faces) + o for k, o in zip(ks, offsets)]),
                       source=f"{first.source.rsplit(' [', 1)[0]} [{name}]", units=first.units,
                       file_faces=sum(len(specs[k]["source"].faces) for k in ks), units_assumed=first.units_assumed,
                       storage_rounding=first.storage_rounding,
                       scale_rounding=max(specs[k]["source"].scale_rounding for k in ks))
        out.append({**specs[ks[0]], "source": mesh, "name": name})
    return out


def unused_map_keys(material_map: Mapping[str, Any] | None, used: Iterable[str], sources: Iterable[Any]) -> None:
    """Refuse (:class:`UsageError`) the ``material_map`` keys that matched no part or material of ``sources``."""
    left = [k for k in (material_map or {}) if k not in set(used)]
    if not left:
        return
    names: list[str] = []
    materials: list[str] = []
    for raw in sources:
        for tag in getattr(raw, "parts", ()):
            names.append(tag.name)
            if tag.material is not None and tag.material not in materials:
                materials.append(tag.material)
    found = (f"parts: {', '.join(names)}; materials: {', '.join(materials) or 'none'}" if names
             else "no file names parts or materials")
    raise UsageError(f"`material_map` names {', '.join(repr(k) for k in left)}, which match no part or material "
                     f"({found})")
