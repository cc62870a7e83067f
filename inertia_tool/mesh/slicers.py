"""The per-object and per-volume filament assignments two slicers write into a 3MF project, read as materials.

Neither is part of the 3MF Core Specification; both are the slicers' own ``Metadata/`` members, documented
here as the projects write them (formats as PrusaSlicer 2.x and Bambu Studio 1.x/2.x save a project; the
test fixtures in ``tests/test_assembly_3mf.py`` are modelled on them):

**PrusaSlicer** — ``Metadata/Slic3r_PE_model.config`` (XML)::

    <config>
     <object id="1" instances_count="1">                  # id: the 3MF <object> placed by the build
      <metadata type="object" key="name" value="..."/>
      <metadata type="object" key="extruder" value="1"/>
      <volume firstid="0" lastid="11">                   # triangle range of the object's mesh, inclusive
       <metadata type="volume" key="name" value="Body"/>
       <metadata type="volume" key="volume_type" value="ModelPart"/>   # or ParameterModifier, NegativeVolume,
       <metadata type="volume" key="extruder" value="2"/>              #    SupportBlocker, SupportEnforcer
      </volume>
     </object>
    </config>

and ``Metadata/Slic3r_PE.config``, the print settings as ``; key = value`` lines, per-extruder values separated
by ``;``: ``; filament_type = PLA;PETG`` and ``; filament_density = 1.24;1.27`` (g/cm³).  Extruder ``0`` means
"the object's" (and the object's ``0``, the first).

**Bambu Studio** (and OrcaSlicer) — ``Metadata/model_settings.config`` (XML)::

    <config>
     <object id="2">                                      # id: the 3MF <object> of the build item
      <metadata key="name" value="..."/>
      <metadata key="extruder" value="1"/>
      <part id="1" subtype="normal_part">               # id: the component's object id; subtype also
       <metadata key="name" value="..."/>                #   modifier_part, negative_part, support_blocker,
       <metadata key="extruder" value="2"/>              #   support_enforcer
      </part>
     </object>
    </config>

and ``Metadata/project_settings.config``, JSON, with per-filament lists ``"filament_type": ["PLA", "PETG"]``
and ``"filament_density": ["1.24", "1.27"]`` (g/cm³).  A part without an extruder takes its object's.

Everything read here is small; the members are refused above :data:`MAX_CONFIG_BYTES` by the caller.
"""

from __future__ import annotations

import json
from typing import Any, NamedTuple

from ..errors import MeshReadError
from ..units import DECIMAL

__all__ = ["SlicerVolume", "SlicerObject", "read_slicer_config", "CONFIG_MEMBERS", "MAX_CONFIG_BYTES"]

#: The ``Metadata/`` members read, lower case: PrusaSlicer's model and print configs, Bambu Studio's.
CONFIG_MEMBERS = ("metadata/slic3r_pe_model.config", "metadata/slic3r_pe.config",
                  "metadata/model_settings.config", "metadata/project_settings.config")
#: Largest slicer config member read (bytes); a project's settings are a few hundred kB.
MAX_CONFIG_BYTES = 16 << 20

#: Volume kinds that are not material: PrusaSlicer's ``volume_type`` and Bambu Studio's ``subtype``.
_NOT_MATERIAL = {"ParameterModifier": "modifier", "SupportBlocker": "support blocker",
                 "SupportEnforcer": "support enforcer", "modifier_part": "modifier",
                 "support_blocker": "support blocker", "support_enforcer": "support enforcer"}
_NEGATIVE = ("NegativeVolume", "negative_part")


class SlicerVolume(NamedTuple):
    """One volume (PrusaSlicer) or part (Bambu Studio) of a slicer object.

    Attributes
    ----------
    name : str or None
    role : str
        ``"part"`` (material), ``"negative"`` (a volume the slicer subtracts) or the kind of a volume that is
        not material (``"modifier"``, ``"support blocker"``, ``"support enforcer"``).
    extruder : int
        1-based filament slot (the object's when the volume names none).
    faces : (int, int) or None
        PrusaSlicer: the triangle range ``[first, last + 1)`` in the object's mesh; None for Bambu.
    component : str or None
        Bambu Studio: the component's object id; None for PrusaSlicer.
    """

    name: str | None
    role: str
    extruder: int
    faces: tuple[int, int] | None
    component: str | None


class SlicerObject(NamedTuple):
    """A slicer object: its name, volumes, ``slicer`` (``"PrusaSlicer"`` or ``"Bambu Studio"``) and its own
    extruder (1-based; its volumes' default)."""

    name: str | None
    volumes: tuple[SlicerVolume, ...]
    slicer: str
    extruder: int = 1


def _metadata(element: Any, kind: str | None = None) -> dict[str, str]:
    """``key -> value`` of the ``<metadata>`` children of ``element`` (PrusaSlicer's ``type`` must be ``kind``)."""
    out: dict[str, str] = {}
    for child in element:
        if child.tag == "metadata" and child.get("key") is not None:
            if kind is None or child.get("type") in (None, kind):
                out[str(child.get("key"))] = str(child.get("value", ""))
    return out


def _slot(text: str | None, inherited: int, where: str) -> int:
    """A 1-based extruder from ``text``; ``0`` or absent: ``inherited``."""
    if text is None or not text.strip():
        return inherited
    if not text.strip().isdigit():
        raise MeshReadError(f"{where}: extruder {text[:20]!r} is not a whole number")
    value = int(text.strip())
    return inherited if value == 0 else value


def _xml(data: bytes, where: str) -> Any:
    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False, remove_comments=True)
    try:
        return etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise MeshReadError(f"{where}: not well-formed XML ({str(exc)[:120]})") from None


def _prusa_objects(data: bytes, where: str) -> dict[str, SlicerObject]:
    objects: dict[str, SlicerObject] = {}
    for obj in _xml(data, where).iter("object"):
        meta = _metadata(obj, "object")
        own = _slot(meta.get("extruder"), 1, where)
        volumes = []
        for volume in obj.iter("volume"):
            vmeta = _metadata(volume, "volume")
            try:
                first, last = int(volume.get("firstid", "")), int(volume.get("lastid", ""))
            except ValueError:
                raise MeshReadError(f"{where}: a <volume> without whole numbers firstid and lastid") from None
            if not 0 <= first <= last:
                raise MeshReadError(f"{where}: a <volume> with the triangle range {first}..{last}")
            kind = vmeta.get("volume_type", "ModelPart")
            role = "negative" if kind in _NEGATIVE else _NOT_MATERIAL.get(kind, "part")
            volumes.append(SlicerVolume(vmeta.get("name"), role, _slot(vmeta.get("extruder"), own, where),
                                        (first, last + 1), None))
        objects[str(obj.get("id"))] = SlicerObject(meta.get("name"), tuple(volumes), "PrusaSlicer", own)
    return objects


def _bambu_objects(data: bytes, where: str) -> dict[str, SlicerObject]:
    objects: dict[str, SlicerObject] = {}
    for obj in _xml(data, where).iter("object"):
        meta = _metadata(obj)
        own = _slot(meta.get("extruder"), 1, where)
        volumes = []
        for part in obj.iter("part"):
            pmeta = _metadata(part)
            kind = str(part.get("subtype", "normal_part"))
            role = "negative" if kind in _NEGATIVE else _NOT_MATERIAL.get(kind, "part")
            volumes.append(SlicerVolume(pmeta.get("name"), role, _slot(pmeta.get("extruder"), own, where), None,
                                        str(part.get("id"))))
        objects[str(obj.get("id"))] = SlicerObject(meta.get("name"), tuple(volumes), "Bambu Studio", own)
    return objects


def _densities(values: list[Any], where: str) -> list[float | None]:
    """Filament densities, g/cm³ in the file, as kg/m³ (None where not a positive number)."""
    out: list[float | None] = []
    for value in values:
        text = str(value).strip()
        out.append(float(text) * 1000.0 if DECIMAL.fullmatch(text) and float(text) > 0 else None)
    return out


def _prusa_filaments(data: bytes, where: str) -> tuple[list[str], list[float | None]]:
    values: dict[str, str] = {}
    for line in data.decode("utf-8", errors="replace").splitlines():
        key, sep, value = line.lstrip("; ").partition(" = ")
        if sep and key in ("filament_type", "filament_density"):
            values[key] = value.strip()
    types = [t.strip().strip('"') for t in values["filament_type"].split(";")] if "filament_type" in values else []
    densities = _densities(values["filament_density"].split(";"), where) if "filament_density" in values else []
    return types, densities


def _bambu_filaments(data: bytes, where: str) -> tuple[list[str], list[float | None]]:
    try:
        settings = json.loads(data.decode("utf-8", errors="replace"))
    except ValueError:
        raise MeshReadError(f"{where}: not valid JSON") from None
    if not isinstance(settings, dict):
        return [], []

    def listed(key: str) -> list[Any]:
        value = settings.get(key, [])
        return value if isinstance(value, list) else [value]
    return [str(t) for t in listed("filament_type")], _densities(listed("filament_density"), where)


def read_slicer_config(members: dict[str, bytes], name: str) -> tuple[dict[str, SlicerObject], list[str],
                                                                        list[float | None]]:
    """The slicer objects by 3MF object id and the filament slots' types and densities (kg/m³) of a project.

    ``members``: the :data:`CONFIG_MEMBERS` the archive holds, by lower-case name.  PrusaSlicer's config wins
    when a file holds both (none does in practice).  Empty results when neither slicer's model config is there.
    """
    objects: dict[str, SlicerObject] = {}
    types: list[str] = []
    densities: list[float | None] = []
    if "metadata/model_settings.config" in members:
        where = f"{name}:Metadata/model_settings.config"
        objects = _bambu_objects(members["metadata/model_settings.config"], where)
        if "metadata/project_settings.config" in members:
            types, densities = _bambu_filaments(members["metadata/project_settings.config"],
                                                f"{name}:Metadata/project_settings.config")
    if "metadata/slic3r_pe_model.config" in members:
        objects = _prusa_objects(members["metadata/slic3r_pe_model.config"], f"{name}:Metadata/Slic3r_PE_model.config")
        if "metadata/slic3r_pe.config" in members:
            types, densities = _prusa_filaments(members["metadata/slic3r_pe.config"],
                                                f"{name}:Metadata/Slic3r_PE.config")
    return objects, types, densities
