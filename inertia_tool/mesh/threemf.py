"""A streaming 3MF reader: the model parts' XML read element by element, into flat arrays, within the face limit.

A 3MF is a zip whose model parts (``3D/3dmodel.model`` and any other ``*.model``) hold, per 3MF Core
Specification (§3–§4): ``<model unit>`` (``micron``, ``millimeter`` (default), ``centimeter``, ``inch``,
``foot``, ``meter``), ``<resources>`` of ``<object id>`` each holding a ``<mesh>`` (``<vertices>`` of
``<vertex x y z>`` and ``<triangles>`` of ``<triangle v1 v2 v3>``, 0-based) or ``<components>`` of
``<component objectid transform>``, and ``<build>`` of ``<item objectid transform>`` (on both, the Production
extension's ``path`` attribute names another model part that defines the object).  A transform is twelve
numbers ``m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32``: a point ``p`` (row) becomes
``p · M + (m30, m31, m32)``.

Memory: a tree parser (trimesh's, through lxml) holds every element, about 1.6 kB per triangle.  Here each
element is cleared once read, so the XML costs a constant; vertices (3 doubles) and triangles (3 int64) are
appended to flat arrays, 24 bytes each, and counted as they come: a part is refused as soon as its triangles
pass ``max_faces`` or its vertices ``3 · max_faces + 3``, and the build is refused from the triangle, vertex
and instance counts of what it places (components multiply; an instance of an empty object counts too: more
than ``max_faces`` instances are refused) before any instance is placed.  Only instances with a triangle
below them are placed, so a deep tree of empty objects costs nothing.

Materials (3MF Core Specification §4.1 and §5.1): a ``<basematerials id>`` resource lists ``<base name
displaycolor>``; an ``<object pid pindex>`` points at one of them for its volume, a ``<triangle pid p1>`` for
that triangle's surface.  The reader records, per placed object, the base materials it names (the object's
own, else those of its triangles; colour groups and textures are not materials and are left out) and any
density written on a ``<base>`` in a namespace of its own (``density`` attribute, kg/m³; inertia_tool's
spin-it writes one).  Every placed object is returned with its face range, so the mesh layer can split the
build into parts (:mod:`inertia_tool.mesh.parts`).
"""

from __future__ import annotations

import array
import zipfile
from collections.abc import Sequence
from typing import IO, Any, NamedTuple, TypeAlias

import numpy as np

from ..errors import MeshReadError
from ..units import DECIMAL

__all__ = ["read_3mf", "PlacedObject", "THREEMF_UNITS", "MAX_COMPONENT_DEPTH", "DENSITY_NAMESPACE"]

#: Metres per unit of ``<model unit>`` (3MF Core Specification §3.4.1; millimetre when absent).
THREEMF_UNITS = {"micron": 1e-6, "millimeter": 1e-3, "centimeter": 1e-2, "inch": 0.0254, "foot": 0.3048,
                 "meter": 1.0}
_UNIT_NAMES = {"micron": "um", "millimeter": "mm", "centimeter": "cm", "inch": "in", "foot": "ft", "meter": "m"}

#: Namespace of the ``density`` attribute (kg/m³) inertia_tool writes on a ``<base>`` material (any namespace is
#: read: the attribute is matched by its local name).
DENSITY_NAMESPACE = "http://schemas.inertia-tool.org/3mf/density/2026"

#: Distinct triangle material references kept per object (beyond one, the object's volume material is in doubt).
_MAX_TRIANGLE_MATERIALS = 4

#: Deepest nesting of components followed (a cycle or a pathological file is refused beyond it).
MAX_COMPONENT_DEPTH = 32

#: A build item or component: (model part name or None for the same part, object id, 4 × 3 transform).
_Reference: TypeAlias = "tuple[str | None, str | None, np.ndarray]"


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _attribute(element: Any, name: str) -> str | None:
    """An attribute by local name, whatever its namespace (``path`` of the Production extension)."""
    value = element.get(name)
    if value is not None:
        return str(value)
    for key, value in element.attrib.items():
        if _local(key) == name:
            return str(value)
    return None


def _plain(text: str) -> str:
    """``text`` unchanged, or ValueError when it holds ``_`` or a non-ASCII character: Python's ``float`` and
    ``int`` read ``1_0`` as 10 and ``١٢`` as 12, which no 3MF number (``xsd:double``/``xsd:int``) means."""
    if "_" in text or not text.isascii():
        raise ValueError(text)
    return text


def _three(get: Any, names: tuple[str, str, str], convert: Any, where: str, tag: str) -> tuple[Any, Any, Any]:
    """The three numbers ``names`` of a ``<vertex>`` (``float``) or ``<triangle>`` (``int``) element."""
    texts = (get(names[0]), get(names[1]), get(names[2]))
    try:
        return convert(_plain(texts[0])), convert(_plain(texts[1])), convert(_plain(texts[2]))
    except (TypeError, ValueError):
        found = " ".join(repr(t)[:24] for t in texts)
        raise MeshReadError(f"{where}: a <{tag}> without three numbers {' '.join(names)} (found {found})") from None


def _transform(text: str | None, where: str) -> np.ndarray:
    """A 3MF transform as a 4 × 3 matrix (``p · M[:3] + M[3]``); identity when absent.  Each number by the
    one grammar :data:`inertia_tool.units.DECIMAL`."""
    if text is None:
        return np.vstack([np.eye(3), np.zeros(3)])
    tokens = text.split()
    if all(DECIMAL.fullmatch(t) for t in tokens):
        values = np.array([float(t) for t in tokens], dtype=np.float64)
    else:
        values = np.zeros(0)
    if values.shape != (12,) or not np.all(np.isfinite(values)):
        raise MeshReadError(f"{where}: transform {text[:80]!r} is not twelve finite numbers")
    return values.reshape(4, 3)


#: One base material: its name and the density (kg/m³) the file writes for it, or None.
Material: TypeAlias = "tuple[str, float | None]"


class PlacedObject(NamedTuple):
    """One object instance of the build with triangles, as placed in the returned arrays.

    Attributes
    ----------
    item : str or None
        Object id of the build item that placed it (the top of its component tree).
    key : str or None
        Object id of the mesh object itself (``item`` when the item names a mesh directly).
    name : str or None
        The mesh object's ``name`` attribute.
    item_name : str or None
        The build item's object's ``name`` attribute.
    materials : tuple of (str, float or None)
        The base materials the object names for its volume (its own ``pid``/``pindex``; without one, the
        distinct ones of its triangles): name and the density written on it (kg/m³) or None.  Empty: none.
    faces : (int, int)
        Its range ``[start, stop)`` in the returned faces.
    """

    item: str | None
    key: str | None
    name: str | None
    item_name: str | None
    materials: tuple[Material, ...]
    faces: tuple[int, int]


class _Part:
    """What one model part defines: meshes and component lists by object id, build items, its unit."""

    def __init__(self) -> None:
        self.meshes: dict[str | None, tuple[np.ndarray, np.ndarray]] = {}   # id -> (vertices (n, 3), triangles (m, 3))
        self.components: dict[str | None, list[_Reference]] = {}             # id -> its components
        self.items: list[_Reference] = []                                    # the build items
        self.unit = "millimeter"
        self.names: dict[str | None, str | None] = {}                        # id -> name attribute
        self.references: dict[str | None, list[tuple[str | None, str | None]]] = {}   # id -> [(pid, index)]
        self.basematerials: dict[str | None, list[Material]] = {}           # basematerials id -> its bases

    def materials(self, key: str | None) -> tuple[Material, ...]:
        """The base materials object ``key`` names (see :class:`PlacedObject`); references that are not
        base materials (colour groups, textures) or out of range are left out."""
        found: list[Material] = []
        for pid, index in self.references.get(key, ()):
            bases = self.basematerials.get(pid)
            try:
                position = int(_plain(index or "0"))
            except ValueError:
                continue
            if bases is not None and 0 <= position < len(bases) and bases[position] not in found:
                found.append(bases[position])
        return tuple(found)


def _density(element: Any) -> float | None:
    """The ``density`` attribute (kg/m³) of a ``<base>`` in another namespace, or None when absent or not a
    positive finite number."""
    for key, value in element.attrib.items():
        if _local(key) == "density" and key != "density":
            text = str(value).strip()
            if DECIMAL.fullmatch(text):
                number = float(text)
                if np.isfinite(number) and number > 0:
                    return number
    return None


#: Elements the reader handles (any namespace); lxml yields only these, and only at their end.
_TAGS = ("vertex", "triangle", "component", "item", "object", "model", "base", "basematerials")
#: Elements read between two sweeps of the already-read siblings out of the tree.
_SWEEP = 4096


def _read_part(source: IO[bytes], where: str, budget: list[int]) -> _Part:
    """Stream one model part; ``budget = [triangles left, vertices left]`` is shared by all parts.

    Each element is handled at its end event and cleared; every :data:`_SWEEP` elements the siblings already
    read are removed from their parent, so the tree never holds more than a few thousand empty elements.
    """
    from lxml import etree
    part = _Part()
    coords = array.array("d")
    corners = array.array("q")
    components: list[_Reference] = []
    bases: list[Material] = []
    triangle_refs: list[tuple[str | None, str | None]] = []
    kinds: dict[str, str] = {}          # element tag (with its namespace) -> local name
    seen = 0
    try:
        for _, element in etree.iterparse(source, events=("end",), tag=[f"{{*}}{t}" for t in _TAGS],
                                          resolve_entities=False, no_network=True, huge_tree=False,
                                          remove_comments=True):
            tag = kinds.get(element.tag)
            if tag is None:
                tag = kinds.setdefault(element.tag, _local(element.tag))
            get = element.get
            if tag == "vertex" or tag == "triangle":
                vertex = tag == "vertex"
                (coords if vertex else corners).extend(
                    _three(get, ("x", "y", "z") if vertex else ("v1", "v2", "v3"), float if vertex else int,
                           where, tag))
                slot = 1 if vertex else 0
                if not vertex and (get("p1") is not None or get("pid") is not None):
                    ref = (get("pid"), get("p1"))
                    if ref not in triangle_refs and len(triangle_refs) < _MAX_TRIANGLE_MATERIALS:
                        triangle_refs.append(ref)
                budget[slot] -= 1
                if budget[slot] < 0:
                    what = "vertices than 3 × `max_faces` + 3" if vertex else "triangles than `max_faces`"
                    raise MeshReadError(f"{where}: holds more {what} allows; refused while reading")
            elif tag == "component":
                components.append((_attribute(element, "path"), get("objectid"),
                                   _transform(get("transform"), where)))
            elif tag == "item":                    # build items (the core specification has no other <item>)
                part.items.append((_attribute(element, "path"), get("objectid"), _transform(get("transform"), where)))
            elif tag == "base":
                bases.append((str(get("name") or f"material {len(bases) + 1}")[:200], _density(element)))
                budget[1] -= 1                 # counted as a vertex: a file of millions of them is refused
                if budget[1] < 0:
                    raise MeshReadError(f"{where}: holds more vertices and base materials than 3 × `max_faces` + "
                                        "3 allows; refused while reading")
            elif tag == "basematerials":
                part.basematerials[get("id")] = bases
                bases = []
            elif tag == "object":
                key = get("id")
                part.names[key] = get("name")
                if get("pid") is not None:      # the object's own material: its volume's (triangles: surface)
                    part.references[key] = [(get("pid"), get("pindex"))]
                elif triangle_refs:             # a triangle without pid takes the object's: none here
                    part.references[key] = [(pid, index) for pid, index in triangle_refs if pid is not None]
                if coords or corners:
                    v = np.frombuffer(coords, dtype=np.float64).reshape(-1, 3).copy()
                    f = np.frombuffer(corners, dtype=np.int64).reshape(-1, 3).copy()
                    if len(f) and (f.min() < 0 or f.max() >= len(v)):
                        raise MeshReadError(f"{where}: object {str(key)[:20]!r} has a triangle index outside "
                                            f"0..{len(v) - 1}")
                    part.meshes[key] = (v, f)
                if components:
                    part.components[key] = components
                coords, corners, components = array.array("d"), array.array("q"), []
                triangle_refs = []
            else:                                  # the <model> root, at the very end
                part.unit = get("unit", "millimeter")
                break
            element.clear()
            seen += 1
            if seen % _SWEEP == 0 or tag == "object":
                parent = element.getparent()
                if parent is not None:
                    del parent[:parent.index(element)]     # the siblings before this one, all read
    except etree.XMLSyntaxError as exc:
        raise MeshReadError(f"{where}: not well-formed XML ({str(exc)[:120]})") from None
    return part


def read_3mf(path: str, members: Sequence[zipfile.ZipInfo], zf: zipfile.ZipFile, *, max_faces: int,
             name: str) -> tuple[np.ndarray, np.ndarray, tuple[float, str], list[PlacedObject]]:
    """Read the model parts ``members`` (``ZipInfo``, the root model first) of the open archive ``zf``.

    Returns
    -------
    vertices : (n, 3) float64
        In the file's unit, every build item placed.
    faces : (m, 3) int64
    declared : (float, str)
        Metres per file unit and the unit's short name.
    placed : list of PlacedObject
        Every object instance placed, in the order of the faces.

    Raises
    ------
    MeshReadError
        Malformed XML or attributes, an unknown unit, a reference to an object or part that does not exist, a
        component cycle, or a build placing more triangles or object instances than ``max_faces`` or more
        vertices than ``3 · max_faces + 3`` (components and items repeated).
    """
    budget = [int(max_faces), 3 * int(max_faces) + 3]
    by_name = {"/" + info.filename.lstrip("/"): info for info in members}
    parts: dict[str, _Part] = {}

    def load(part_name: str) -> _Part | None:
        """A model part, streamed the first time a build item or component needs it (others are never read)."""
        if part_name not in parts and part_name in by_name:
            info = by_name[part_name]
            with zf.open(info) as source:
                parts[part_name] = _read_part(source, f"{name}:{info.filename[:60]}", budget)
        return parts.get(part_name)

    root_name = "/" + members[0].filename.lstrip("/")
    root = load(root_name)
    if root is None:
        raise MeshReadError(f"{name}: the root model part {root_name[:60]!r} cannot be read")
    if root.unit not in THREEMF_UNITS:
        raise MeshReadError(f"{name}: unknown 3MF unit {root.unit[:40]!r}; expected one of "
                            f"{', '.join(THREEMF_UNITS)}")

    def lookup(part_name: str, key: str | None) -> _Part:
        part = load(part_name)
        if part is None:
            raise MeshReadError(f"{name}: a component names the model part {part_name[:60]!r}, which the archive "
                                "does not hold")
        if key not in part.meshes and key not in part.components:
            raise MeshReadError(f"{name}: a build item or component names object {str(key)[:20]!r}, which "
                                f"{part_name[:60]} does not define")
        return part

    # what one instance of an object brings, components included: (triangles, vertices, placements), each
    # capped just above its limit so that a deep, wide tree stays cheap to count (memoised; cycles refused)
    limits = (int(max_faces), 3 * int(max_faces) + 3, max(int(max_faces), 1))
    counts: dict[tuple[str, str | None], tuple[int, int, int]] = {}

    def tally(part_name: str, key: str | None, depth: int) -> tuple[int, int, int]:
        if depth > MAX_COMPONENT_DEPTH:
            raise MeshReadError(f"{name}: components nested deeper than {MAX_COMPONENT_DEPTH} (a cycle?)")
        if (part_name, key) in counts:
            return counts[(part_name, key)]
        part = lookup(part_name, key)
        v, f = part.meshes.get(key, (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)))
        total = [len(f), len(v), 1]
        for sub_part, sub_key, _ in part.components.get(key, ()):
            sub = tally(sub_part or part_name, sub_key, depth + 1)
            total = [min(t + s, limit + 1) for t, s, limit in zip(total, sub, limits)]
        counts[(part_name, key)] = (total[0], total[1], total[2])
        return counts[(part_name, key)]

    placing = [0, 0, 0]
    for item_part, key, _ in root.items:
        sub = tally(item_part or root_name, key, 0)
        placing = [min(t + s, limit + 1) for t, s, limit in zip(placing, sub, limits)]
    for count, limit, what in zip(placing, limits, ("triangles", "vertices", "object instances")):
        if count > limit:
            raise MeshReadError(f"{name}: the build places at least {count:,} {what} (components and items "
                                f"repeated), more than `max_faces` ({max_faces:,}) allows; refused before placing "
                                "them")
    out_v: list[np.ndarray] = []
    out_f: list[np.ndarray] = []
    offset = [0, 0]                                   # vertices, faces placed so far
    placed: list[PlacedObject] = []

    def place(part_name: str, key: str | None, matrix: np.ndarray, item: tuple[str | None, str | None]) -> None:
        part = parts[part_name]
        if key in part.meshes:
            v, f = part.meshes[key]
            linear = matrix[:3]
            out_v.append(v @ linear + matrix[3])
            out_f.append((f[:, ::-1] if np.linalg.det(linear) < 0 else f) + offset[0])   # a mirror turns winding
            placed.append(PlacedObject(item[0], key, part.names.get(key), item[1], part.materials(key),
                                       (offset[1], offset[1] + len(f))))
            offset[0] += len(v)
            offset[1] += len(f)
        for sub_part, sub_key, sub in part.components.get(key, ()):
            if not counts[(sub_part or part_name, sub_key)][0]:
                continue                                  # no triangle below: nothing to place
            # the component's transform first, then the parent's: p · S · M + (t_S · M + t_M)
            combined = np.vstack([sub[:3] @ matrix[:3], sub[3] @ matrix[:3] + matrix[3]])
            place(sub_part or part_name, sub_key, combined, item)

    with np.errstate(invalid="ignore", over="ignore"):       # non-finite coordinates are refused by the caller
        for item_part, key, matrix in root.items:
            if counts[(item_part or root_name, key)][0]:
                owner = parts[item_part or root_name]
                place(item_part or root_name, key, matrix, (key, owner.names.get(key)))
    if not out_f or not sum(len(f) for f in out_f):
        raise MeshReadError(f"{name}: contains no triangle mesh (no build item places an object with triangles)")
    vertices = np.concatenate(out_v)
    faces = np.concatenate(out_f)
    return vertices, faces, (THREEMF_UNITS[root.unit], _UNIT_NAMES[root.unit]), placed
