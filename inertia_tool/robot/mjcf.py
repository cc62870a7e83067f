"""MuJoCo MJCF bodies and geoms as :class:`~inertia_tool.robot.description.LinkGeometry` (one link per body).

What is read (MuJoCo XML reference, "MJCF"): ``<compiler angle eulerseq meshdir assetdir>`` (angles in
**degrees** unless ``angle="radian"``, MuJoCo's default), ``<default>`` classes (nested, ``class`` and
``childclass``) for ``<geom>`` and ``<mesh>`` attributes, ``<asset><mesh name file scale>`` (or inline
``vertex``/``face``, or ``builtin``), ``<asset><hfield size>``, and under ``<worldbody>`` every ``<body>``
(``<frame>`` elements compose their pose into the geoms they hold, ``<replicate>`` copies its bodies and
geoms, ``<attach>`` brings in the bodies of an ``<asset><model>``).  A geom's
frame is ``pos`` and one of ``quat`` (w x y z), ``axisangle``, ``euler`` (sequence ``eulerseq``: lower case
letters rotate with the frame, upper case stay fixed), ``xyaxes``, ``zaxis``; or ``fromto`` for capsules,
cylinders, boxes and ellipsoids (the axis runs from the first point to the second).  Sizes are MuJoCo's
half-sizes: box half-edges, cylinder and capsule ``radius half-length``, ellipsoid semi-axes.

Collision geoms are those with ``contype`` or ``conaffinity`` non-zero (MuJoCo's default is 1) and those
named in a ``<contact><pair>`` (MuJoCo collides them whatever their bit masks); the others are visual.  Geoms
directly in ``<worldbody>`` belong to no body and are skipped, and so are planes in a body (MuJoCo gives them
no mass or inertia).  A height field in a body is MuJoCo's inertia box (:func:`_hfield_geom`), noted on the
element.

MuJoCo's rules, as its compiler applies them (checked against ``mujoco`` 4.0):

* ``<include file>`` is replaced by the children of the included ``<mujoco>``, recursively; the file is looked
  up relative to the main model's folder first, then relative to the including file's folder; its root is
  ``<mujoco>`` or ``<mujocoinclude>``.  At most :data:`MAX_INCLUDE_DEPTH` levels, :data:`MAX_INCLUDED_FILES`
  files and ``MAX_DESCRIPTION_BYTES`` bytes in all; a file that includes itself (directly or not) is refused.
  A mesh is found through the merged ``<compiler meshdir>`` relative to the main model's folder; a mesh
  declared in an included file that is not found there is looked up, as MuJoCo 4.0 does, beside that file
  (its folder joined with the mesh's ``file``, without any ``meshdir``: Menagerie's MJX scenes in MuJoCo
  Playground give ``file="assets/link0.stl"`` for this lookup); then, beyond what MuJoCo does, through that
  file's own ``meshdir``, relative to its folder.
* Defaults: an element's own attribute overrides its class, the class its parent class.  The orientation is
  one attribute: an element (or class) that gives any of ``quat``, ``axisangle``, ``euler``, ``xyaxes``,
  ``zaxis`` replaces whatever orientation its class gave.  ``size`` is read number by number: an element's
  ``size="0.02"`` replaces the first number of its class's ``size`` and keeps the others.  Several top-level
  ``<default>`` blocks (from included files) all add to the class ``main``.
* ``fromto`` takes precedence over ``pos`` and the orientation; the radius (and the box or ellipsoid cross
  section) still come from ``size``.
* Mesh ``refpos``/``refquat``: file vertices ``v`` become ``scale ⊙ (q̄ (v − refpos) q)`` — the reference
  position is subtracted, the conjugate of ``refquat`` rotates, the scale applies last.
* ``<attach model body prefix>``: :class:`_Attachments`; ``<mesh vertex face>`` and ``builtin``:
  :func:`_inline_mesh`; copies of geoms in a ``<replicate>``: :func:`_replica_poses`.
* Geom ``density`` (kg/m³, default 1000), ``mass`` (kg; when given, the geom's density is ``mass / volume``)
  and ``shellinertia`` (mass on the surface; for meshes MuJoCo uses ``<mesh inertia="shell">`` instead) are
  kept on each :class:`GeometryElement` for the "model's own densities" mode; a geom with ``mass="0"`` or
  ``density="0"`` is massless there.
"""

from __future__ import annotations

import dataclasses
import math
import os
from typing import Any
import re

import numpy as np

from ..errors import RobotDescriptionError
from .description import DeclaredInertial, GeometryElement, LinkGeometry, _coordinates, _numbers, _positive, _scale
from .resolve import resolve_uri

#: The values of MJCF ``<mesh inertia>`` (MuJoCo 3.x): how the compiler takes a mesh's mass and inertia.
MESH_INERTIA_MODES = ("convex", "exact", "legacy", "shell")

__all__ = ["read_mjcf", "orientation_matrix", "inertia_from_geometry", "MAX_INCLUDE_DEPTH", "MAX_INCLUDED_FILES"]

#: Deepest chain of ``<include>`` followed (MuJoCo's own models nest two or three).
MAX_INCLUDE_DEPTH = 16

#: Most files one model may pull in through ``<include>`` (counting repeats).
MAX_INCLUDED_FILES = 512

#: Root elements of an included file: MuJoCo takes the children of whatever root it has; ``<mujocoinclude>`` is
#: the name older models use (MyoSuite, Meta-World, Gymnasium-Robotics); other roots (a URDF's ``<robot>``) are
#: refused rather than read as nothing.
_INCLUDED_ROOTS = ("mujoco", "mujocoinclude")

#: The orientation attributes of MJCF: one orientation, whichever of them is given.
_ORIENTATION = ("quat", "axisangle", "euler", "xyaxes", "zaxis")

#: Shortest x axis, and part of the y axis across it, that ``xyaxes`` may give: MuJoCo's compiler refuses
#: shorter ones ("xaxis too small", "yaxis too small"; checked against ``mujoco`` 4.0).
_AXIS_TOO_SHORT = 1e-6

_GEOM_KINDS = {"box": "box", "sphere": "sphere", "cylinder": "cylinder", "capsule": "capsule",
               "ellipsoid": "ellipsoid", "mesh": "mesh"}


def _fail(source: str, problem: str) -> RobotDescriptionError:
    return RobotDescriptionError(f"{source}: {problem}")


def _unit(vector) -> np.ndarray | None:
    """``vector`` scaled to length 1, or None when it is zero.

    Divided by its largest component first, so that components near the float64 limits (``1e308``, ``1e-320``)
    neither overflow nor underflow the norm: a direction is refused only when it is zero, never turned into a
    wrong one (an overflowed norm would make every component 0 and the rotation the identity)."""
    v = np.asarray(vector, dtype=np.float64)
    largest = float(np.max(np.abs(v)))
    if not largest > 0:
        return None
    v = v / largest
    return v / np.linalg.norm(v)


def _quaternion_matrix(q) -> np.ndarray:
    """Rotation of the quaternion ``q`` (w x y z, any non-zero length)."""
    unit = _unit(q)
    if unit is None:
        raise ValueError("a quaternion of zero length has no rotation")
    w, x, y, z = unit
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _axis_angle(axis, angle: float) -> np.ndarray:
    n = _unit(axis)
    if n is None:
        raise ValueError("a zero axis has no rotation")
    k = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def _z_to(direction) -> np.ndarray:
    """The minimal rotation taking +z onto ``direction`` (MuJoCo's ``zaxis`` and ``fromto`` frames)."""
    d = _unit(direction)
    if d is None:
        raise ValueError("a zero direction has no rotation")
    axis = np.cross([0.0, 0.0, 1.0], d)
    s, c = np.linalg.norm(axis), float(d[2])
    if s < 1e-14:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    return _axis_angle(axis, math.atan2(s, c))


_ELEMENTARY_AXES = {"x": 0, "y": 1, "z": 2}


def _euler_matrix(sequence: str, angles) -> np.ndarray:
    """Active rotation of the Euler angles ``angles`` (rad) about the axes of ``sequence`` (three of ``xyzXYZ``,
    checked by :func:`_compiler`), composed as MuJoCo does: a lower-case axis rotates with the frame
    (``R ← R R_k``, intrinsic), an upper-case one stays fixed (``R ← R_k R``, extrinsic); cases may mix."""
    rotation = np.eye(3)
    for letter, angle in zip(sequence, angles):
        axis = np.zeros(3)
        axis[_ELEMENTARY_AXES[letter.lower()]] = 1.0
        step = _axis_angle(axis, float(angle))
        rotation = rotation @ step if letter.islower() else step @ rotation
    return rotation


def orientation_matrix(attrs: dict, *, degrees: bool, eulerseq: str, what: str, source: str) -> np.ndarray:
    """Active rotation (frame axes as columns, in parent axes) from MJCF orientation attributes.

    Parameters
    ----------
    attrs : dict
        Attribute values (strings) after defaults: ``quat`` (w x y z), ``axisangle``, ``euler``, ``xyaxes``,
        ``zaxis``; at most one of them.
    degrees : bool
        ``<compiler angle="degree">`` (MuJoCo's default) or radians.
    eulerseq : str
        ``<compiler eulerseq>``, three of ``xyzXYZ``: lower case rotate with the frame (intrinsic).
    """
    given = [k for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis") if attrs.get(k) is not None]
    if len(given) > 1:
        raise _fail(source, f"{what}: more than one orientation ({', '.join(given)})")
    if not given:
        return np.eye(3)
    key = given[0]
    unit = math.pi / 180.0 if degrees else 1.0
    if key == "quat":
        q = _numbers(attrs[key], 4, f"{what} quat", source)
        if _unit(q) is None:
            raise _fail(source, f"{what}: quat of zero length")
        return _quaternion_matrix(q)
    if key == "axisangle":
        a = _numbers(attrs[key], 4, f"{what} axisangle", source)
        if _unit(a[:3]) is None:
            raise _fail(source, f"{what}: axisangle with a zero axis")
        return _axis_angle(a[:3], a[3] * unit)
    if key == "euler":
        angles = _numbers(attrs[key], 3, f"{what} euler", source) * unit
        return _euler_matrix(eulerseq, angles)
    if key == "xyaxes":
        a = _numbers(attrs[key], 6, f"{what} xyaxes", source)
        # MuJoCo refuses an x axis, or the part of y across x, shorter than 1e-6 ("xaxis/yaxis too small");
        # both lengths are computed on the numbers scaled by their largest, so no length overflows to inf
        x, y = _unit(a[:3]), a[3:]
        y_scale = float(np.max(np.abs(y)))
        across = None
        if x is not None and y_scale > 0:
            across = y / y_scale - ((y / y_scale) @ x) * x
        x_scale = float(np.max(np.abs(a[:3])))
        if (x is None or across is None or x_scale * float(np.linalg.norm(a[:3] / x_scale)) < _AXIS_TOO_SHORT
                or y_scale * float(np.linalg.norm(across)) < _AXIS_TOO_SHORT):
            raise _fail(source, f"{what}: xyaxes are zero or parallel (expected an x axis and a y axis across it "
                                f"at least {_AXIS_TOO_SHORT:g} long, got {attrs[key]!r})")
        y_axis = across / np.linalg.norm(across)
        return np.column_stack([x, y_axis, np.cross(x, y_axis)])
    z = _numbers(attrs[key], 3, f"{what} zaxis", source)
    if _unit(z) is None:
        raise _fail(source, f"{what}: zaxis of zero length")
    return _z_to(z)


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
        for top in root.findall("default"):
            self._collect(top, self.classes["main"] if top.get("class", "main") == "main" else {}, source)

    def _collect(self, element, inherited: dict, source: str) -> None:
        name = element.get("class", "main")
        merged = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in element:
            if isinstance(child.tag, str) and child.tag != "default":
                merged[child.tag] = _merge_attributes(merged.get(child.tag, {}), child.attrib)
        self.classes[name] = merged
        for child in element.findall("default"):
            if not child.get("class"):
                raise _fail(source, "a nested <default> without a class")
            self._collect(child, merged, source)

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


def _mesh_source(file, folders, packages: dict, source: str, link: str, missing_meshes: str = "refuse") -> dict:
    """The ``GeometryElement`` fields that say where a mesh asset's triangles are: ``mesh`` (the file found
    through ``folders``, the first holding it; see :func:`_mesh_path`) and ``uri``; or, for an inline mesh,
    ``vertices`` and ``faces``."""
    if isinstance(file, _InlineMesh):
        return {"mesh": None, "uri": None, "vertices": file.vertices, "faces": file.faces}
    return {"mesh": _mesh_path(file, folders, packages, source, link, missing_meshes), "uri": file}


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


def _hfield_geom(attrs: dict, pose, label: str, link: str, hfields: dict, compiler, source: str) -> GeometryElement:
    """A ``type="hfield"`` geom in a body as MuJoCo's compiler takes it for the body's inertia: the box centred
    on the geom's frame with half-sizes ``(radius_x, radius_y, elevation_z/4 + base_z/2)`` of its
    ``<hfield size>`` (checked against ``mujoco`` 4.0: ``geom_size`` and the body's mass, centre and inertia
    are those of this box, whatever the elevation data), noted on the element as a stand-in."""
    name = attrs.get("hfield")
    if name is None:
        raise _fail(source, f"body {link!r} {label}: a height field geom without hfield (expected the name of an "
                            "<asset><hfield>)")
    if name not in hfields:
        raise _fail(source, f"body {link!r} {label}: height field {name!r} is not defined in <asset>")
    rx, ry, elevation, base = hfields[name]
    boxed = {k: v for k, v in attrs.items() if k not in ("fromto", "mesh", "hfield", "size")}
    boxed.update(type="box", size=f"{rx!r} {ry!r} {0.25 * elevation + 0.5 * base!r}")
    element = _geom(boxed, pose, label, link, {}, {}, compiler, source)
    note = (f"height field {name!r} ({element.name}) taken as MuJoCo's inertia box "
            f"{2 * rx:g} x {2 * ry:g} x {0.5 * elevation + base:g} m, as MuJoCo's compiler does (not the shape "
            "of its surface)")
    return dataclasses.replace(element, note=note)


def _optional_number(attrs: dict, key: str, what: str, source: str) -> float | None:
    if attrs.get(key) is None:
        return None
    value = float(_numbers(attrs[key], 1, f"{what} {key}", source)[0])
    if value < 0:
        raise _fail(source, f"{what}: {key} must not be negative, got {attrs[key]!r}")
    return value


_MISSING = re.compile(r": resolves to (.+), which does not exist$")


def _mesh_path(file: str, folders: list, packages: dict, source: str, link: str, missing_meshes: str) -> str:
    """The mesh file of an asset: the first of ``folders`` holding it (else the first folder), resolved; a file
    that does not exist is refused, or with ``missing_meshes="per-link"`` returned as the path it would have."""
    found = [f for f in folders if "://" in file or os.path.isfile(os.path.join(f, file))]
    try:
        return resolve_uri(file, base=(found or folders)[0], packages=packages, source=source, link=link)
    except RobotDescriptionError as exc:
        match = _MISSING.search(str(exc))
        if missing_meshes == "refuse" or match is None:
            raise
        return match.group(1)


def _geom(attrs: dict, pose, label: str, link: str, meshes: dict, packages: dict, compiler,
          source: str, missing_meshes: str = "refuse") -> GeometryElement:
    degrees, eulerseq, fitaabb = compiler
    what = f"body {link!r} {label}"
    kind = _GEOM_KINDS.get(attrs.get("type", "sphere"))
    if kind is None:
        raise _fail(source, f"{what}: geom type {attrs.get('type')!r} is not supported")
    rotation = orientation_matrix(attrs, degrees=degrees, eulerseq=eulerseq, what=what, source=source)
    position = _coordinates(_numbers(attrs.get("pos"), 3, f"{what} pos", source, default=(0, 0, 0)),
                            f"{what} pos", source)
    size = list(_numbers(attrs.get("size") or "", None, f"{what} size", source))
    half_length = None
    if attrs.get("fromto") is not None and kind in ("capsule", "cylinder", "box", "ellipsoid"):
        ends = _coordinates(_numbers(attrs["fromto"], 6, f"{what} fromto", source), f"{what} fromto", source)
        axis = ends[3:] - ends[:3]
        if _unit(axis) is None:
            raise _fail(source, f"{what}: fromto with coincident ends")
        rotation, position = _z_to(axis), 0.5 * (ends[:3] + ends[3:])
        half_length = 0.5 * _positive(float(np.linalg.norm(axis)), f"{what} fromto length", source)
    frame_rotation, frame_translation = pose
    rotation, position = frame_rotation @ rotation, frame_rotation @ position + frame_translation
    name = attrs.get("name") or label
    mass_model = {"density": _optional_number(attrs, "density", what, source),
                  "mass": _optional_number(attrs, "mass", what, source),
                  "shell": attrs.get("shellinertia", "false") == "true"}
    if mass_model["density"] is None:
        mass_model["density"] = 1000.0       # MuJoCo's default geom density, kg/m³

    def need(count):
        if len(size) < count:
            raise _fail(source, f"{what}: {kind} needs {count} size values, got {attrs.get('size')!r}")
        return [_positive(s, f"{what} size", source) for s in size[:count]]

    if kind != "mesh" and attrs.get("mesh") is not None and attrs.get("fromto") is None:
        # a primitive fitted to a mesh (arx_l5: type="capsule" from a class, mesh="link1", no size)
        mesh_name = attrs.get("mesh")
        if mesh_name not in meshes:
            raise _fail(source, f"{what}: mesh {mesh_name!r} is not defined in <asset>")
        file, folders, scale, ref_rotation, ref_translation, _mode = meshes[mesh_name]
        fit = float(_numbers(attrs.get("fitscale"), 1, f"{what} fitscale", source, default=(1.0,))[0])
        return GeometryElement(kind, rotation, position, **_mesh_source(file, folders, packages, source, link,
                                                                           missing_meshes),
                               scale=scale, name=name,
                               reference_rotation=ref_rotation, reference_translation=ref_translation,
                               fit_scale=_positive(fit, f"{what} fitscale", source), fit_aabb=fitaabb,
                               **mass_model)
    if kind == "mesh":
        mesh_name = attrs.get("mesh")
        if mesh_name not in meshes:
            raise _fail(source, f"{what}: mesh {mesh_name!r} is not defined in <asset>")
        file, folders, scale, ref_rotation, ref_translation, mode = meshes[mesh_name]
        mass_model["shell"] = mode == "shell"    # MuJoCo: a mesh's shell inertia is a property of the asset
        return GeometryElement("mesh", rotation, position, **_mesh_source(file, folders, packages, source, link,
                                                                           missing_meshes),
                               scale=scale, name=name,
                               reference_rotation=ref_rotation, reference_translation=ref_translation,
                               mesh_inertia=mode if mode in ("convex", "legacy") else "exact", **mass_model)
    if kind == "sphere":
        return GeometryElement("sphere", rotation, position, size=need(1), name=name, **mass_model)
    if kind in ("capsule", "cylinder"):
        radius = need(1)[0]
        half = half_length if half_length is not None else need(2)[1]
        return GeometryElement(kind, rotation, position, size=(radius, 2.0 * half), name=name, **mass_model)
    if kind == "box":
        if half_length is not None:
            half = need(2)
            return GeometryElement("box", rotation, position, size=(2 * half[0], 2 * half[1], 2 * half_length),
                                   name=name, **mass_model)
        return GeometryElement("box", rotation, position, size=tuple(2 * s for s in need(3)), name=name,
                               **mass_model)
    if half_length is not None:
        half = need(2)
        return GeometryElement("ellipsoid", rotation, position, size=(half[0], half[1], half_length), name=name,
                               **mass_model)
    return GeometryElement("ellipsoid", rotation, position, size=need(3), name=name, **mass_model)


def _inertial(body, name: str, compiler, source: str) -> DeclaredInertial | None:
    inertial = body.find("inertial")
    if inertial is None:
        return None
    degrees, eulerseq, _ = compiler
    what = f"body {name!r} <inertial>"
    attrs = dict(inertial.attrib)
    position = _coordinates(_numbers(attrs.get("pos"), 3, f"{what} pos", source), f"{what} pos", source)
    mass = _numbers(attrs.get("mass"), 1, f"{what} mass", source)[0]
    if attrs.get("fullinertia") is not None:
        if any(attrs.get(k) is not None for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis")):
            raise _fail(source, f"{what}: fullinertia together with an orientation (MuJoCo refuses it)")
        m11, m22, m33, m12, m13, m23 = _numbers(attrs["fullinertia"], 6, f"{what} fullinertia", source)
        rotation = np.eye(3)
        tensor = np.array([[m11, m12, m13], [m12, m22, m23], [m13, m23, m33]])
    else:
        rotation = orientation_matrix(attrs, degrees=degrees, eulerseq=eulerseq, what=what, source=source)
        tensor = np.diag(_numbers(attrs.get("diaginertia"), 3, f"{what} diaginertia", source))
    return DeclaredInertial(mass=mass, center_of_mass=position, inertia=rotation @ tensor @ rotation.T,
                            rotation=rotation, inertia_in_frame=tensor)


def _is_collision(attrs: dict, what: str, source: str) -> bool:
    bits = [_numbers(attrs.get(k, "1"), 1, f"{what} {k}", source)[0] for k in ("contype", "conaffinity")]
    if any(b != int(b) for b in bits):
        raise _fail(source, f"{what}: contype and conaffinity are integer bit masks, got "
                            f"{attrs.get('contype', '1')!r} and {attrs.get('conaffinity', '1')!r}")
    return any(b != 0 for b in bits)


def _selected(attrs: dict, geometry: str, groups: tuple, what: str, source: str,
              paired: frozenset = frozenset()) -> bool:
    """Whether a geom belongs to the chosen geometry: collision (``contype``/``conaffinity`` not both 0, or
    named in a ``<contact><pair>``: MuJoCo collides a pair's geoms whatever their bit masks, which is how the MJX
    models of Menagerie give their contacts), visual (the others), or ``"all"``: every geom whose ``group``
    lies in ``<compiler inertiagrouprange>`` (MuJoCo's default 0–5), the geoms MuJoCo's inertia from geometry
    counts."""
    if geometry == "all":
        group = _numbers(attrs.get("group", "0"), 1, f"{what} group", source)[0]
        return groups[0] <= group <= groups[1]
    collides = attrs.get("name") in paired or _is_collision(attrs, what, source)
    return collides == (geometry == "collision")


def _paired_geoms(root) -> frozenset:
    """Names of the geoms in ``<contact><pair geom1 geom2>`` elements (explicit contact pairs)."""
    names: set = set()
    for contact in root.findall("contact"):
        for pair in contact.findall("pair"):
            names.update(n for n in (pair.get("geom1"), pair.get("geom2")) if n)
    return frozenset(names)


#: Most copies one ``<replicate>`` may make (and all of them together).
MAX_REPLICAS = 10_000


def _child_bodies(element, class_name: str, suffix: str = "", source: str = "", budget: list | None = None):
    """The ``<body>`` children of ``element``, looking through ``<frame>`` and ``<replicate>`` elements, with
    their default class and name suffix.

    ``<replicate count sep>`` repeats its bodies ``count`` times; MuJoCo names copy ``i`` of ``NAME``
    ``NAME + sep + i`` (``i`` zero-padded to the digits of ``count − 1``), inner replicates' suffixes first.
    The copies' placement (``offset``, orientation) does not change a body's own mass properties.
    An ``<attach>`` element is yielded as it is, with ``None`` for its class: its bodies are another model's.
    """
    budget = [MAX_REPLICAS] if budget is None else budget
    for child in element:
        if child.tag == "body":
            yield child, class_name, suffix
        elif child.tag == "frame":
            yield from _child_bodies(child, child.get("childclass", class_name), suffix, source, budget)
        elif child.tag == "replicate":
            count = _numbers(child.get("count"), 1, "<replicate count>", source)[0]
            if not (count == int(count) and 1 <= count <= budget[0]):
                raise _fail(source, f"<replicate count={child.get('count')!r}>: expected a whole number from 1 to "
                                    f"{budget[0]:,} (copies left of {MAX_REPLICAS:,})")
            budget[0] -= int(count)
            width = len(str(int(count) - 1))
            for k in range(int(count)):
                yield from _child_bodies(child, class_name, f"{child.get('sep', '')}{k:0{width}d}{suffix}", source,
                                         budget)
        elif child.tag == "attach":
            yield child, None, suffix          # the caller reads the attached model (:func:`read_mjcf`)


def _replica_poses(replicate, pose, model, budget: list) -> list:
    """The poses of the copies a ``<replicate count offset euler>`` makes of the geoms (and frames) it holds
    in a body, composed onto ``pose``: copy ``k`` is turned by the Euler angles ``k · euler`` (the model's angle
    unit and ``eulerseq``) and moved by ``Σ_{j<k} R(j · euler) offset`` — each step's offset taken in the
    previous copy's axes (checked against ``mujoco`` 4.0's ``geom_pos`` and ``geom_quat``; for angles about
    one axis this is the step ``x ↦ R x + offset`` applied ``k`` times).  ``budget`` is the copies left of
    :data:`MAX_REPLICAS`."""
    degrees, eulerseq, _ = model.compiler
    count = _numbers(replicate.get("count"), 1, "<replicate count>", model.source)[0]
    if not (count == int(count) and 1 <= count <= budget[0]):
        raise _fail(model.source, f"<replicate count={replicate.get('count')!r}>: expected a whole number from 1 to "
                                  f"{budget[0]:,} (copies left of {MAX_REPLICAS:,})")
    budget[0] -= int(count)
    angles = _numbers(replicate.get("euler"), 3, "<replicate euler>", model.source, default=(0, 0, 0))
    angles = angles * (math.pi / 180.0 if degrees else 1.0)
    step = _coordinates(_numbers(replicate.get("offset"), 3, "<replicate offset>", model.source, default=(0, 0, 0)),
                        "<replicate offset>", model.source)
    poses = []
    rotation, translation = pose
    moved = np.zeros(3)
    for k in range(int(count)):
        turn = _euler_matrix(eulerseq, k * angles)
        poses.append((rotation @ turn, rotation @ moved + translation))
        moved = moved + turn @ step
    return poses


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


def _named_bodies(element, class_name: str, suffix: str, source: str, budget: list):
    """Every body under ``element`` as MuJoCo names it: ``(body element, default class in force, name suffix of
    its ``<replicate>`` copies)``, depth first (the bodies of ``<attach>`` elements are another model's)."""
    for child, cls, more in _child_bodies(element, class_name, suffix, source, budget):
        if cls is None:
            continue
        yield child, cls, more
        yield from _named_bodies(child, child.get("childclass", cls), more, source, budget)


def _attached_body(attach, model: _Model):
    """``(body element, its default class, name suffix)`` of the body an ``<attach body>`` names in ``model``:
    a body of that name, or a ``<replicate>`` copy of one by MuJoCo's name for it (``leg-1``: checked against
    ``mujoco`` 4.0, which attaches that copy alone, its subtree named with the copy's suffix).  The class is
    the ``childclass`` in force where the body stands in its own model."""
    wanted = attach.get("body")
    for world in model.root.findall("worldbody"):
        for body, class_name, suffix in _named_bodies(world, "main", "", model.source, [MAX_REPLICAS]):
            if body.get("name") is not None and body.get("name") + suffix == wanted:
                return body, class_name, suffix
    raise _fail(model.source, f"<attach model=... body={wanted!r}>: the model has no body {wanted!r}")


def read_mjcf(root, source: str, base: str, packages: dict, geometry: str, *,
              missing_meshes: str = "refuse") -> tuple[str, tuple]:
    """Bodies of an MJCF ``<mujoco>`` tree as links (see the module docstring); returns ``(model, links)``.

    ``missing_meshes="per-link"`` keeps a mesh geom whose file does not exist (its link then has no result and
    says so) instead of refusing the model."""
    from .description import MAX_ROBOT_LINKS
    if root.tag != "mujoco":
        raise _fail(source, f"not an MJCF file: the root element is <{root.tag}>, expected <mujoco>")
    budget = [0, os.path.getsize(source) if os.path.isfile(source) else 0]     # [files, bytes] read in all
    main = _model(root, source, base, packages, budget)
    # compile-time settings are the main model's (MuJoCo applies them to the attached bodies too)
    group_range = next((c.get("inertiagrouprange") for c in reversed(list(root.iter("compiler")))
                        if c.get("inertiagrouprange") is not None), "0 5")
    groups = tuple(_numbers(group_range, 2, "<compiler inertiagrouprange>", source))
    attachments = _Attachments(packages, main.compiler[2], budget)
    links = []
    counter = [0]
    replicas = [MAX_REPLICAS]

    def walk_body(body, class_name: str, suffix: str, model: _Model, prefix: str, stack: tuple) -> None:
        counter[0] += 1
        if counter[0] > MAX_ROBOT_LINKS:
            raise _fail(source, f"holds more than the {MAX_ROBOT_LINKS:,} bodies allowed (attached models "
                                "included)")
        name = prefix + body.get("name") + suffix if body.get("name") else f"body {counter[0]}"
        child_class = body.get("childclass", class_name)
        elements: list[GeometryElement] = []
        collect(body, name, child_class, (np.eye(3), np.zeros(3)), elements, model, stack)
        links.append(LinkGeometry(name=name, elements=tuple(elements),
                                  declared=_inertial(body, name, model.compiler, model.source)))
        walk_children(body, child_class, suffix, model, prefix, stack)

    def walk_children(element, class_name: str, suffix: str, model: _Model, prefix: str, stack: tuple) -> None:
        for child, cls, more in _child_bodies(element, class_name, suffix, model.source, replicas):
            if cls is not None:
                walk_body(child, cls, more, model, prefix, stack)
                continue
            attached, deeper = attachments.model(child, model, stack)
            inner = prefix + child.get("prefix")
            if child.get("body") is None:           # the whole worldbody, as a frame
                for world in attached.root.findall("worldbody"):
                    walk_children(world, "main", more, attached, inner, deeper)
            else:
                body, body_class, copy = _attached_body(child, attached)
                walk_body(body, body_class, copy + more, attached, inner, deeper)

    def collect(element, link: str, class_name: str, pose, elements: list, model: _Model, stack: tuple) -> None:
        degrees, eulerseq, _ = model.compiler
        for child in element:
            if child.tag == "geom":
                attrs = model.defaults.attributes(child, class_name, model.source)
                if attrs.get("type") == "plane":      # MuJoCo gives a plane no mass and no inertia
                    continue
                if _selected(attrs, geometry, groups, f"body {link!r} geom {len(elements) + 1}", model.source,
                             model.paired):
                    label = f"geom {len(elements) + 1}"
                    if attrs.get("type") == "hfield":
                        elements.append(_hfield_geom(attrs, pose, label, link, model.hfields, model.compiler,
                                                     model.source))
                        continue
                    elements.append(_geom(attrs, pose, label, link, model.meshes, packages, model.compiler,
                                          model.source, missing_meshes))
            elif child.tag == "frame":
                attrs = dict(child.attrib)
                rotation = orientation_matrix(attrs, degrees=degrees, eulerseq=eulerseq, what=f"body {link!r} frame",
                                              source=model.source)
                position = _coordinates(_numbers(attrs.get("pos"), 3, f"body {link!r} frame pos", model.source,
                                                 default=(0, 0, 0)), f"body {link!r} frame pos", model.source)
                composed = (pose[0] @ rotation, pose[0] @ position + pose[1])
                collect(child, link, child.get("childclass", class_name), composed, elements, model, stack)
            elif child.tag == "replicate":
                for copy in _replica_poses(child, pose, model, replicas):
                    collect(child, link, class_name, copy, elements, model, stack)
            elif child.tag == "attach" and child.get("body") is None:
                # a whole worldbody attached as a frame: its geoms are this body's, in its own model's terms
                attached, deeper = attachments.model(child, model, stack)
                for world in attached.root.findall("worldbody"):
                    collect(world, link, "main", pose, elements, attached, deeper)

    for world in root.findall("worldbody"):
        walk_children(world, "main", "", main, "", (os.path.realpath(source),))
    if not links and any(world.find("geom") is not None for world in root.findall("worldbody")):
        raise _fail(source, "no bodies: every geom is in <worldbody> (a scene: terrain, floor, walls), which MuJoCo "
                            "fixes to the world with no mass; expected a model with at least one <body>")
    return root.get("model", ""), tuple(links)
