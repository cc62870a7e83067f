"""One MJCF model file as its elements are read, before any body: ``<include>`` expanded, ``<default>``
classes, ``<compiler>``, mesh and height-field assets, contact pairs (:class:`_Model`), and the model assets
``<attach>`` takes bodies from (:class:`_Attachments`).  The rules are MuJoCo's (see
:mod:`inertia_tool.robot.mjcf`, which turns the bodies of these models into links)."""

from __future__ import annotations

import dataclasses
import os
from typing import Any

import numpy as np

from .description import _coordinates, _numbers, _positive, _scale
from .mjcf_orientation import _ORIENTATION, _fail, _quaternion_matrix, _unit

__all__ = ["inertia_from_geometry", "MAX_INCLUDE_DEPTH", "MAX_INCLUDED_FILES", "MESH_INERTIA_MODES",
           "INERTIA_FROM_GEOMETRY"]

#: The values of MJCF ``<mesh inertia>`` (MuJoCo 3.x): how the compiler takes a mesh's mass and inertia.
MESH_INERTIA_MODES = ("convex", "exact", "legacy", "shell")

#: Deepest chain of ``<include>`` followed (MuJoCo's own models nest two or three).
MAX_INCLUDE_DEPTH = 16

#: Most files one model may pull in through ``<include>`` (counting repeats).
MAX_INCLUDED_FILES = 512

#: Root elements of an included file: MuJoCo takes the children of whatever root it has; ``<mujocoinclude>`` is
#: the name older models use (MyoSuite, Meta-World, Gymnasium-Robotics); other roots (a URDF's ``<robot>``) are
#: refused rather than read as nothing.
_INCLUDED_ROOTS = ("mujoco", "mujocoinclude")

def _merge_attributes(base: dict, own) -> dict:
    """``own`` attributes over ``base`` with MuJoCo's rules: one orientation, ``size`` number by number."""
    out = dict(base)
    own = dict(own)
    if any(k in own for k in _ORIENTATION):
        for key in _ORIENTATION:
            out.pop(key, None)
    if "size" in own and "size" in out:
        mine, theirs = str(own["size"]).split(), str(out["size"]).split()
        own["size"] = " ".join(mine + theirs[len(mine):])
    out.update(own)
    return out


class _Defaults:
    """MJCF default classes: class name → {element tag → attributes}, each merged with its parents."""

    def __init__(self, root, source: str):
        self.classes: dict = {"main": {}}
        self.parents: dict = {}          # class name → the class it is nested in ("main" has none)
        for top in root.findall("default"):
            self._collect(top, self.classes["main"] if top.get("class", "main") == "main" else {}, source, None)

    def _collect(self, element, inherited: dict, source: str, parent: str | None) -> None:
        name = element.get("class", "main")
        merged = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in element:
            if isinstance(child.tag, str) and child.tag != "default":
                merged[child.tag] = _merge_attributes(merged.get(child.tag, {}), child.attrib)
        self.classes[name] = merged
        if parent is not None:
            self.parents[name] = parent
        for child in element.findall("default"):
            if not child.get("class"):
                raise _fail(source, "a nested <default> without a class")
            self._collect(child, merged, source, name)

    def lineage(self, name: str) -> tuple[str, ...]:
        """``name`` and the classes it is nested in, innermost first, ending with ``"main"`` (at most one step
        per class: a name is defined once)."""
        out = [name]
        for _ in range(len(self.parents)):
            if out[-1] not in self.parents:
                break
            out.append(self.parents[out[-1]])
        if out[-1] != "main":
            out.append("main")
        return tuple(out)

    def attributes(self, element, class_name: str, source: str) -> dict:
        name = element.get("class", class_name)
        if name not in self.classes:
            raise _fail(source, f"<{element.tag}> uses the undefined default class {name!r}")
        attrs = _merge_attributes(self.classes[name].get(element.tag, {}), element.attrib)
        attrs.pop("class", None)
        return attrs


def _compiler(root, source: str) -> tuple[bool, str, str | None]:
    """``(degrees, eulerseq, mesh folder)`` from every ``<compiler>`` in document order (later ones win)."""
    merged: dict = {}
    for compiler in root.iter("compiler"):
        merged.update(compiler.attrib)
    angle = merged.get("angle", "degree")
    if angle not in ("degree", "radian"):
        raise _fail(source, f"<compiler angle={angle[:40]!r}>: expected 'degree' or 'radian'")
    eulerseq = merged.get("eulerseq", "xyz")
    if len(eulerseq) != 3 or any(c not in "xyzXYZ" for c in eulerseq):
        raise _fail(source, f"<compiler eulerseq={eulerseq[:40]!r}>: expected three of the letters xyzXYZ "
                            "(lower case rotates with the frame, upper case about the fixed axes)")
    return angle == "degree", eulerseq, merged.get("meshdir", merged.get("assetdir"))


#: The values of ``<compiler inertiafromgeom>`` (MuJoCo's default: ``auto``).
INERTIA_FROM_GEOMETRY = ("false", "true", "auto")


def inertia_from_geometry(source: str, document: bytes | None = None) -> str:
    """MuJoCo's ``<compiler inertiafromgeom>`` for the model ``source``: ``"true"`` (every body's inertia is
    computed from its geoms and every ``<inertial>`` is ignored), ``"false"`` or ``"auto"`` (the default: only
    bodies without an ``<inertial>``).  Read as MuJoCo reads it: from every ``<compiler>`` of the file and of
    the files it includes, in document order, the last one that sets it winning; comments and other elements
    do not count.

    Parameters
    ----------
    source : str
        The main MJCF file (included files are found relative to it).
    document : bytes, optional
        Its content, when already read.

    Raises
    ------
    RobotDescriptionError
        Unreadable file or include, or a value MuJoCo refuses.
    """
    from .description import _read_bytes, parse_xml
    data = _read_bytes(source) if document is None else document
    root = parse_xml(data, source).getroot()
    _expand_includes(root, source)
    value = "auto"
    for compiler in root.iter("compiler"):
        value = compiler.get("inertiafromgeom", value)
    if value not in INERTIA_FROM_GEOMETRY:
        raise _fail(source, f"<compiler inertiafromgeom={value[:40]!r}>: expected one of "
                            f"{', '.join(INERTIA_FROM_GEOMETRY)}")
    return value


def _own_mesh_folder(root, folder: str) -> str:
    """The folder a file's own ``<compiler meshdir/assetdir>`` names, relative to ``folder`` (the file's)."""
    merged: dict = {}
    for compiler in root.iter("compiler"):
        merged.update(compiler.attrib)
    return os.path.join(folder, merged.get("meshdir", merged.get("assetdir", "")) or "")


def _expand_includes(root, source: str, *, max_depth: int = MAX_INCLUDE_DEPTH,
                     max_files: int = MAX_INCLUDED_FILES, budget: list | None = None) -> dict:
    """Replace every ``<include file>`` under ``root`` by the included ``<mujoco>``'s children, in place.

    ``budget``: ``[files, bytes]`` already read by other files of the same model (the models ``<attach>``
    brings in share one budget with the main model's includes); updated in place.

    Returns ``{<mesh> element: fallback folders}`` for meshes declared in included files: the declaring
    file's own mesh folder, then those of the files that included it, outwards (used when MuJoCo's
    main-folder lookup finds nothing).
    """
    from .description import MAX_DESCRIPTION_BYTES, _read_bytes, parse_xml
    main_folder = os.path.dirname(os.path.abspath(source))
    fallbacks: dict = {}
    if budget is None:
        budget = [0, os.path.getsize(source) if os.path.isfile(source) else 0]

    def expand(element, including: str, stack: tuple, chain: tuple) -> None:
        for include in list(element.iter("include")):
            name = include.get("file")
            if not name:
                raise _fail(source, f"<include> without a file (in {including})")
            candidates = [os.path.normpath(os.path.join(main_folder, name)),
                          os.path.normpath(os.path.join(os.path.dirname(including), name))]
            path = next((c for c in candidates if os.path.isfile(c)), None)
            if path is None:
                raise _fail(source, f"<include file={name!r}> (in {including}): no such file (looked in "
                                    f"{' and '.join(dict.fromkeys(os.path.dirname(c) for c in candidates))})")
            key = os.path.realpath(path)
            if key in stack:
                raise _fail(source, f"<include file={name!r}> (in {including}) includes itself: "
                                    f"{' -> '.join(stack + (key,))}")
            if len(stack) >= max_depth:
                raise _fail(source, f"<include file={name!r}> (in {including}): includes nested more than "
                                    f"{max_depth} deep")
            budget[0] += 1
            if budget[0] > max_files:
                raise _fail(source, f"more than {max_files} included files")
            data = _read_bytes(path)
            budget[1] += len(data)
            if budget[1] > MAX_DESCRIPTION_BYTES:
                raise _fail(source, f"the included files hold more than the {MAX_DESCRIPTION_BYTES:,} bytes a robot "
                                    "description may have, all files together")
            included = parse_xml(data, path).getroot()
            if included.tag not in _INCLUDED_ROOTS:
                raise _fail(source, f"<include file={name!r}>: {path} has the root element <{included.tag}>, "
                                    "expected <mujoco> or <mujocoinclude>")
            folders = (_own_mesh_folder(included, os.path.dirname(path)),) + chain
            expand(included, path, stack + (key,), folders)
            for mesh in included.iter("mesh"):        # MuJoCo's own fallback first: beside the declaring file
                fallbacks.setdefault(mesh, (os.path.dirname(path),) + folders)
            parent = include.getparent()
            index = parent.index(include)
            tail = include.tail
            parent.remove(include)
            children = [c for c in included]
            for offset, child in enumerate(children):
                parent.insert(index + offset, child)
            if children:
                children[-1].tail = (children[-1].tail or "") + (tail or "")

    expand(root, os.path.abspath(source), (os.path.realpath(source),), ())
    return fallbacks


#: Most vertices and triangles an inline ``<mesh vertex face>`` may hold (MuJoCo models write a few hundred;
#: larger meshes are files).  The text is bounded by ``MAX_DESCRIPTION_BYTES`` already; this bounds the hull.
MAX_INLINE_VERTICES = 1_000_000


@dataclasses.dataclass(frozen=True)
class _InlineMesh:
    """The vertices (n, 3), m, and outward triangles (m, 3) of an inline ``<mesh>``."""

    vertices: np.ndarray
    faces: np.ndarray


def _convex_hull(vertices: np.ndarray, what: str, source: str) -> np.ndarray:
    """Outward-wound triangles of the convex hull of ``vertices`` (MuJoCo's mesh from ``vertex`` alone).

    Qhull's facets (``scipy.spatial.ConvexHull``, triangulated) come in no consistent order; each is turned so
    that its normal ``(b − a) × (c − a)`` points along the facet's outward plane normal."""
    from scipy.spatial import ConvexHull, QhullError
    try:
        hull = ConvexHull(vertices)
    except (QhullError, ValueError):
        raise _fail(source, f"{what}: its vertices span no volume (expected at least 4 points not in one plane, "
                            "whose convex hull MuJoCo takes)") from None
    faces = np.array(hull.simplices, dtype=np.int64)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.equations[:, :3]) < 0
    faces[inward] = faces[inward][:, ::-1]
    return np.ascontiguousarray(faces)


def _inline_mesh(attrs: dict, source: str) -> _InlineMesh | None:
    """The mesh an MJCF ``<mesh vertex="x y z ..." face="i j k ...">`` spells out, or MuJoCo generates
    (``<mesh builtin params>``: :func:`~inertia_tool.robot.mjspec.builtin_mesh`); None for a mesh file.

    ``vertex`` without ``face`` is MuJoCo's convex hull of the points.  Checked as MuJoCo checks it: at least
    4 vertices, whole face indices within range; together with a ``file`` it is refused (two meshes in one)."""
    if attrs.get("builtin") is not None and attrs.get("builtin") != "none":
        what = f"<mesh name={attrs.get('name')!r} builtin={attrs.get('builtin')!r}>"
        if attrs.get("file") or attrs.get("vertex") is not None:
            raise _fail(source, f"{what}: also a file or vertices (expected one source of triangles)")
        if not attrs.get("name"):
            raise _fail(source, f"{what}: without a name (expected one, as it has no file to name it)")
        from .mjspec import builtin_mesh
        vertices, faces = builtin_mesh(attrs["builtin"], attrs.get("params"), what=what, source=source)
        vertices = _coordinates(vertices, f"{what} vertices", source)
        if faces is None:
            return _InlineMesh(vertices, _convex_hull(vertices, what, source))
        return _InlineMesh(vertices, faces)
    if attrs.get("vertex") is None:
        if attrs.get("face") is not None:
            raise _fail(source, f"<mesh name={attrs.get('name')!r}>: face without vertex")
        return None
    what = f"<mesh name={attrs.get('name')!r}>"
    if attrs.get("file"):
        raise _fail(source, f"{what}: both a file and inline vertices (expected one of them)")
    if not attrs.get("name"):
        raise _fail(source, "an inline <mesh vertex> without a name (expected a name, as it has no file to name it)")
    flat = _numbers(attrs["vertex"], None, f"{what} vertex", source)
    if flat.size % 3 or not 12 <= flat.size <= 3 * MAX_INLINE_VERTICES:
        raise _fail(source, f"{what}: expected vertex to hold x y z of 4 to {MAX_INLINE_VERTICES:,} points, got "
                            f"{flat.size} numbers")
    vertices = _coordinates(flat.reshape(-1, 3), f"{what} vertex", source)
    if attrs.get("face") is None:
        return _InlineMesh(vertices, _convex_hull(vertices, what, source))
    indices = _numbers(attrs["face"], None, f"{what} face", source)
    if (indices.size % 3 or indices.size == 0 or indices.size > 6 * MAX_INLINE_VERTICES
            or np.any(indices != np.round(indices)) or np.any(indices < 0) or np.any(indices >= len(vertices))):
        raise _fail(source, f"{what}: expected face to hold triples of whole vertex indices from 0 to "
                            f"{len(vertices) - 1}, got {' '.join(str(attrs['face']).split())[:80]!r}")
    return _InlineMesh(vertices, indices.astype(np.int64).reshape(-1, 3))


def _meshes(root, defaults: _Defaults, mesh_base: str, fallbacks: dict, compiler, source: str) -> dict:
    """``{name: (file, folders, scale, reference rotation, reference translation, inertia mode)}`` of every mesh
    asset (the mode of ``<mesh inertia>``; ``"exact"`` when not given: this tool integrates the solid)."""
    meshes = {}
    for asset in root.findall("asset"):
        for mesh in asset.findall("mesh"):
            attrs = defaults.attributes(mesh, "main", source)
            inline = _inline_mesh(attrs, source)
            file = attrs.get("file")
            if not file and inline is None:
                raise _fail(source, f"<mesh name={attrs.get('name')!r}> without a file or vertex")
            name = attrs.get("name") or os.path.splitext(os.path.basename(file or ""))[0]
            what = f"<mesh name={name!r}>"
            scale = _scale(_numbers(attrs.get("scale"), 3, f"{what} scale", source, default=(1, 1, 1)),
                           f"{what} scale", source)
            refpos = _numbers(attrs.get("refpos"), 3, f"{what} refpos", source, default=(0, 0, 0))
            refquat = _numbers(attrs.get("refquat"), 4, f"{what} refquat", source, default=(1, 0, 0, 0))
            if _unit(refquat) is None:
                raise _fail(source, f"{what}: refquat of zero length")
            # v ↦ q̄ (v − refpos) q: rotation Qᵀ, translation −Qᵀ refpos
            back = _quaternion_matrix(refquat).T
            folders = [mesh_base, *fallbacks.get(mesh, ())]
            mode = attrs.get("inertia", "exact")
            if mode not in MESH_INERTIA_MODES:
                raise _fail(source, f"{what}: inertia must be one of {', '.join(MESH_INERTIA_MODES)}, "
                                    f"got {mode!r}")
            meshes[name] = (inline if inline is not None else file, folders, scale, back, -back @ refpos, mode)
    return meshes


def _hfields(root, source: str) -> dict:
    """``{name: (radius_x, radius_y, elevation_z, base_z)}`` (m) of every ``<asset><hfield>``.

    Only ``size`` is read (MuJoCo requires it: four positive numbers); the elevation data (``file`` or
    ``elevation``) is not, because MuJoCo's inertia of a height field depends on its size alone."""
    found = {}
    for asset in root.findall("asset"):
        for hfield in asset.findall("hfield"):
            name = hfield.get("name") or os.path.splitext(os.path.basename(hfield.get("file") or ""))[0]
            what = f"<hfield name={name!r}>"
            size = _numbers(hfield.get("size"), 4, f"{what} size", source)
            found[name] = tuple(_positive(float(s), f"{what} size", source) for s in size)
    return found


def _paired_geoms(root) -> frozenset:
    """Names of the geoms in ``<contact><pair geom1 geom2>`` elements (explicit contact pairs)."""
    names: set = set()
    for contact in root.findall("contact"):
        for pair in contact.findall("pair"):
            names.update(n for n in (pair.get("geom1"), pair.get("geom2")) if n)
    return frozenset(names)


@dataclasses.dataclass(frozen=True)
class _Model:
    """One MJCF file as its own elements are read: the main model, or a model asset an ``<attach>`` takes bodies
    from (each keeps its own compiler angles, mesh folder, default classes, assets and contact pairs)."""

    source: str
    root: Any               # the lxml <mujoco> element, includes expanded
    defaults: _Defaults
    compiler: tuple
    meshes: dict
    hfields: dict
    paired: frozenset
    models: dict


def _model(root, source: str, folder: str, packages: dict, budget: list, fitaabb: bool | None = None) -> _Model:
    """The :class:`_Model` of the ``<mujoco>`` ``root`` read from ``source`` in ``folder`` (its includes
    expanded here, in place, counted in ``budget``: ``[files, bytes]`` of the whole model); ``fitaabb`` is the
    main model's (a compile-time setting), its own when None."""
    fallbacks = _expand_includes(root, source, budget=budget)
    if fitaabb is None:
        fitaabb = any(c.get("fitaabb") == "true" for c in root.iter("compiler"))
    degrees, eulerseq, meshdir = _compiler(root, source)
    defaults = _Defaults(root, source)
    compiler = (degrees, eulerseq, fitaabb)
    meshes = _meshes(root, defaults, os.path.join(folder, meshdir or ""), fallbacks, compiler, source)
    models = {}
    for asset in root.findall("asset"):
        for model in asset.findall("model"):
            if not model.get("name") or not model.get("file"):
                raise _fail(source, f"<asset><model name={model.get('name')!r} file={model.get('file')!r}>: "
                                    "expected both a name and a file")
            models[model.get("name")] = os.path.normpath(os.path.join(folder, model.get("file")))
    return _Model(source, root, defaults, compiler, meshes, _hfields(root, source), _paired_geoms(root), models)


class _Attachments:
    """The model assets ``<attach>`` elements take bodies from, each read once, with MuJoCo's rules:
    ``<asset><model name file>`` names a file relative to the declaring model's folder; ``<attach model body
    prefix>`` puts the body ``body`` of that model, with its subtree, where the ``<attach>`` stands, every
    name prefixed with ``prefix`` (required); without ``body`` the model's whole ``<worldbody>`` is attached
    as a ``<frame>`` (its geoms join the enclosing body).  At most :data:`MAX_INCLUDE_DEPTH` models deep and
    :data:`MAX_INCLUDED_FILES` files; a model that attaches itself is refused."""

    def __init__(self, packages: dict, fitaabb: bool, budget: list):
        self.packages, self.fitaabb, self.budget = packages, fitaabb, budget
        self.read: dict = {}

    def absent(self, attach, host: _Model) -> str | None:
        """Why the model file ``attach`` names cannot be read because it is not on disk (with a near match,
        :func:`~inertia_tool.robot.resolve.near_match`; nothing is read in its place), or None: a file that
        exists, or a problem of the ``<attach>`` itself (no prefix, an undeclared model), which :meth:`model`
        refuses."""
        from .resolve import near_match
        name = attach.get("model")
        if attach.get("prefix") is None or name not in host.models or os.path.exists(host.models[name]):
            return None
        hint = near_match(host.models[name])
        return (f"<attach model={name!r}> in {host.source}: the model file {host.models[name]} does not exist"
                + (f" ({hint})" if hint else ""))

    def model(self, attach, host: _Model, stack: tuple) -> tuple[_Model, tuple]:
        """The model asset ``attach`` names (declared in ``host``) and the attach chain extended by it."""
        from .description import MAX_DESCRIPTION_BYTES, _read_bytes, parse_xml
        name = attach.get("model")
        what = f"<attach model={name!r}>"
        if attach.get("prefix") is None:
            raise _fail(host.source, f"{what}: expected a prefix (MuJoCo requires one)")
        if name not in host.models:
            raise _fail(host.source, f"{what}: no <asset><model name={name!r}> declares it")
        path = host.models[name]
        key = os.path.realpath(path)
        if key in stack:
            raise _fail(host.source, f"{what}: {path} attaches itself: {' -> '.join(stack + (key,))}")
        if len(stack) > MAX_INCLUDE_DEPTH:
            raise _fail(host.source, f"{what}: models attached more than {MAX_INCLUDE_DEPTH} deep")
        if key not in self.read:
            if not os.path.isfile(path):
                raise _fail(host.source, f"{what}: the model file {path} does not exist")
            self.budget[0] += 1
            if self.budget[0] > MAX_INCLUDED_FILES:
                raise _fail(host.source, f"more than {MAX_INCLUDED_FILES} included and attached files")
            data = _read_bytes(path)
            self.budget[1] += len(data)
            if self.budget[1] > MAX_DESCRIPTION_BYTES:
                raise _fail(host.source, f"the included and attached files hold more than the "
                                         f"{MAX_DESCRIPTION_BYTES:,} bytes a robot description may have, all "
                                         "files together")
            root = parse_xml(data, path).getroot()
            if root.tag != "mujoco":
                raise _fail(host.source, f"{what}: {path} has the root element <{root.tag}>, expected <mujoco>")
            self.read[key] = _model(root, path, os.path.dirname(os.path.abspath(path)), self.packages, self.budget,
                                    self.fitaabb)
        return self.read[key], stack + (key,)
