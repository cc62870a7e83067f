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
* ``<attach model body prefix>``: :class:`~inertia_tool.robot.mjcf_model._Attachments`; ``<mesh vertex face>``
  and ``builtin``: :func:`~inertia_tool.robot.mjcf_model._inline_mesh`; bodies through ``<frame>`` and
  ``<replicate>``, and copies of geoms in a ``<replicate>``: :mod:`inertia_tool.robot.mjcf_bodies`.

The reader runs in stages, one module each: orientations (:mod:`inertia_tool.robot.mjcf_orientation`), one
model file with its includes, classes and assets, and the models ``<attach>`` brings in
(:mod:`inertia_tool.robot.mjcf_model`), the bodies as MuJoCo names and copies them
(:mod:`inertia_tool.robot.mjcf_bodies`), and here the geoms of each body and the links.
* Geom ``density`` (kg/m³, default 1000), ``mass`` (kg; when given, the geom's density is ``mass / volume``)
  and ``shellinertia`` (mass on the surface; for meshes MuJoCo uses ``<mesh inertia="shell">`` instead) are
  kept on each :class:`GeometryElement` for the "model's own densities" mode; a geom with ``mass="0"`` or
  ``density="0"`` is massless there.
"""

from __future__ import annotations

import dataclasses
import os
import re
import warnings

import numpy as np

from ..errors import UsageError
from .description import (DeclaredInertial, GeometryElement, LinkGeometry, _coordinates, _numbers, _positive,
                          parse_geometry)
from .mjcf_bodies import MAX_REPLICAS, _attached_body, _child_bodies, _replica_poses
from .mjcf_model import (INERTIA_FROM_GEOMETRY, MAX_INCLUDE_DEPTH, MAX_INCLUDED_FILES, MESH_INERTIA_MODES,
                         _Attachments, _InlineMesh, _Model, _model, inertia_from_geometry)
from .mjcf_orientation import _fail, _unit, _z_to, orientation_matrix
from .resolve import resolve_uri

# orientation_matrix, inertia_from_geometry and the limits are read from here too (the modules they moved to
# are stages of this reader)
__all__ = ["read_mjcf", "orientation_matrix", "inertia_from_geometry", "warn_if_nothing_collides", "files_including",
           "MAX_INCLUDE_DEPTH", "MAX_INCLUDED_FILES",
           "MAX_REPLICAS", "MESH_INERTIA_MODES", "INERTIA_FROM_GEOMETRY"]

_GEOM_KINDS = {"box": "box", "sphere": "sphere", "cylinder": "cylinder", "capsule": "capsule",
               "ellipsoid": "ellipsoid", "mesh": "mesh"}


def _mesh_source(file, folders, packages: dict, source: str, link: str, missing_meshes: str = "refuse") -> dict:
    """The ``GeometryElement`` fields that say where a mesh asset's triangles are: ``mesh`` (the file found
    through ``folders``, the first holding it; see :func:`_mesh_path`) and ``uri``; or, for an inline mesh,
    ``vertices`` and ``faces``."""
    if isinstance(file, _InlineMesh):
        return {"mesh": None, "uri": None, "vertices": file.vertices, "faces": file.faces}
    return {"mesh": _mesh_path(file, folders, packages, source, link, missing_meshes), "uri": file}


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


#: Largest OBJ file (bytes) scanned for its objects by :func:`obj_object_triangles`.
OBJ_SCAN_LIMIT = 256 << 20


def obj_object_triangles(path: str, *, limit: int = OBJ_SCAN_LIMIT) -> list[int]:
    """Triangles of each object of an OBJ file, in file order: a new object starts at an ``o`` or ``g`` line
    after at least one face (the grouping of MuJoCo's OBJ loader); a polygon of ``n`` corners counts ``n − 2``.
    An empty list for a file that cannot be read or is larger than ``limit`` bytes."""
    data = _obj_bytes(path, limit)
    return [] if data is None else _object_triangles(data)


def _obj_bytes(path: str, limit: int) -> bytes | None:
    try:
        if os.path.getsize(path) > limit:
            return None
        with open(path, "rb") as fh:
            return fh.read()
    except OSError:
        return None


def _object_triangles(data: bytes) -> list[int]:
    counts = [0]
    for line in data.splitlines():
        word = line.split(None, 1)[:1]
        if not word:
            continue
        if word[0] == b"f":
            counts[-1] += max(len(line.split()) - 3, 0)
        elif word[0] in (b"o", b"g") and counts[-1]:
            counts.append(0)
    return [c for c in counts if c]


#: Whitespace of ``bytes.split()`` within a line, and the line breaks of ``bytes.splitlines()``.
_BLANK = np.zeros(256, dtype=bool)
_BLANK[[32, 9, 11, 12]] = True
_BREAK = np.zeros(256, dtype=bool)
_BREAK[[10, 13]] = True


def _may_hold_objects(data: bytes) -> bool:
    """False only when no ``o`` or ``g`` line follows a line whose first word is ``f`` (then
    :func:`_object_triangles` finds at most one object); True when one may, or when a line starts with
    whitespace (not looked at further).  Without a Python loop over the lines (issue 25: the corpus scanned
    every OBJ file of every scene, ~2 s of CPU)."""
    chars = np.frombuffer(data, dtype=np.uint8)
    if not chars.size:
        return False
    breaks = _BREAK[chars]
    starts = np.flatnonzero(np.concatenate(([True], breaks[:-1])) & ~breaks)   # each non-empty line's first byte
    if np.any(_BLANK[chars[starts]]):
        return True
    after = np.append(chars, 10)[starts + 1]                    # the byte after it (a line break at the end)
    alone = _BLANK[after] | _BREAK[after]                       # the first word is that one byte
    first = chars[starts]
    faces = np.flatnonzero(alone & (first == ord("f")))
    if not faces.size:
        return False
    objects = np.flatnonzero(alone & ((first == ord("o")) | (first == ord("g"))))
    return bool(objects.size and objects[-1] > faces[0])


def _noted_first_object(element: GeometryElement) -> GeometryElement:
    """``element`` with a note when its mesh is an OBJ file of several objects: MuJoCo 4.0 compiles only the
    first (checked: two cubes under ``o a`` / ``o b`` compile to one cube of 12 triangles), the tool the whole
    file, so their inertias of this geom differ."""
    if element.mesh is None or not element.mesh.lower().endswith(".obj"):
        return element
    data = _obj_bytes(element.mesh, OBJ_SCAN_LIMIT)
    objects = _object_triangles(data) if data is not None and _may_hold_objects(data) else []
    if len(objects) < 2:
        return element
    note = (f"mesh {os.path.basename(element.mesh)} holds {len(objects)} objects (OBJ 'o'/'g' groups): the whole "
            f"file ({sum(objects):,} triangles) is integrated; MuJoCo 4.0 reads only the first object "
            f"({objects[0]:,} triangles), so its inertia of this geom differs")
    return dataclasses.replace(element, note=f"{element.note}; {note}" if element.note else note)


def _optional_number(attrs: dict, key: str, what: str, source: str) -> float | None:
    if attrs.get(key) is None:
        return None
    value = float(_numbers(attrs[key], 1, f"{what} {key}", source)[0])
    if value < 0:
        raise _fail(source, f"{what}: {key} must not be negative, got {attrs[key]!r}")
    return value


def _mesh_path(file: str, folders: list, packages: dict, source: str, link: str, missing_meshes: str) -> str:
    """The mesh file of an asset: the first of ``folders`` holding it (else the first folder), resolved; a file
    that does not exist is refused, or with ``missing_meshes="per-link"`` returned as the path it would have."""
    found = [f for f in folders if "://" in file or os.path.isfile(os.path.join(f, file))]
    return resolve_uri(file, base=(found or folders)[0], packages=packages, source=source, link=link,
                       missing=missing_meshes)


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
        file, folders, scale, ref_rotation, ref_translation, mode = meshes[mesh_name]
        fit = float(_numbers(attrs.get("fitscale"), 1, f"{what} fitscale", source, default=(1.0,))[0])
        fitted = GeometryElement(kind, rotation, position, **_mesh_source(file, folders, packages, source, link,
                                                                             missing_meshes),
                                 scale=scale, name=name,
                                 reference_rotation=ref_rotation, reference_translation=ref_translation,
                                 fit_scale=_positive(fit, f"{what} fitscale", source), fit_aabb=fitaabb,
                                 mesh_inertia=mode if mode in ("convex", "legacy") else "exact", **mass_model)
        return _noted_first_object(fitted)
    if kind == "mesh":
        mesh_name = attrs.get("mesh")
        if mesh_name not in meshes:
            raise _fail(source, f"{what}: mesh {mesh_name!r} is not defined in <asset>")
        file, folders, scale, ref_rotation, ref_translation, mode = meshes[mesh_name]
        mass_model["shell"] = mode == "shell"    # MuJoCo: a mesh's shell inertia is a property of the asset
        element = GeometryElement("mesh", rotation, position, **_mesh_source(file, folders, packages, source, link,
                                                                              missing_meshes),
                                  scale=scale, name=name,
                                  reference_rotation=ref_rotation, reference_translation=ref_translation,
                                  mesh_inertia=mode if mode in ("convex", "legacy") else "exact", **mass_model)
        return _noted_first_object(element)
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


def _selected(attrs: dict, selection: tuple, groups: tuple, what: str, source: str,
              paired: frozenset = frozenset(), lineage: tuple = ("main",)) -> bool:
    """Whether a geom belongs to the chosen geometry (``selection``, from
    :func:`~inertia_tool.robot.description.parse_geometry`): collision (``contype``/``conaffinity`` not both 0,
    or named in a ``<contact><pair>``: MuJoCo collides a pair's geoms whatever their bit masks, which is how the
    MJX models of Menagerie give their contacts), visual (the others), ``"all"``: every geom whose ``group``
    lies in ``<compiler inertiagrouprange>`` (MuJoCo's default 0–5), the geoms MuJoCo's inertia from geometry
    counts; ``group``: a geom whose ``group`` is listed; ``class``: a geom whose default class (``lineage``: its
    class and those it is nested in) holds a listed one."""
    kind, values = selection
    if kind in ("all", "group"):
        group = _numbers(attrs.get("group", "0"), 1, f"{what} group", source)[0]
        return groups[0] <= group <= groups[1] if kind == "all" else group in values
    if kind == "class":
        return any(name in values for name in lineage)
    collides = attrs.get("name") in paired or _is_collision(attrs, what, source)
    return collides == (kind == "collision")


def read_mjcf(root, source: str, base: str, packages: dict, geometry: str, *,
              missing_meshes: str = "refuse") -> tuple[str, tuple]:
    """Bodies of an MJCF ``<mujoco>`` tree as links (see the module docstring); returns ``(model, links)``.

    ``missing_meshes="per-link"`` keeps a mesh geom whose file does not exist (its link then has no result and
    says so) instead of refusing the model; an ``<attach>`` whose model file does not exist becomes one entry
    ``PREFIX*`` standing for the bodies it would have brought (all named with its prefix), without geometry, its
    ``unread`` the reason, and a body that a whole attached ``<worldbody>`` would have given geoms has that
    reason too (its geometry is unknown)."""
    from .description import MAX_ROBOT_LINKS
    if root.tag != "mujoco":
        raise _fail(source, f"not an MJCF file: the root element is <{root.tag}>, expected <mujoco>")
    budget = [0, os.path.getsize(source) if os.path.isfile(source) else 0]     # [files, bytes] read in all
    main = _model(root, source, base, packages, budget)
    # compile-time settings are the main model's (MuJoCo applies them to the attached bodies too)
    group_range = next((c.get("inertiagrouprange") for c in reversed(list(root.iter("compiler")))
                        if c.get("inertiagrouprange") is not None), "0 5")
    groups = tuple(_numbers(group_range, 2, "<compiler inertiagrouprange>", source))
    selection = parse_geometry(geometry)
    attachments = _Attachments(packages, main.compiler[2], budget)
    classes = set(main.defaults.classes)     # every default class of the models read, for a class= selection
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
        unselected = [0]
        absent: list[str] = []          # <attach> frames whose model file is not on disk (missing_meshes="per-link")
        collect(body, name, child_class, (np.eye(3), np.zeros(3)), elements, model, stack, unselected, absent)
        unread = (f"attached model not read: {absent[0]} (its geoms would be part of this body)" if absent else "")
        links.append(LinkGeometry(name=name, elements=tuple(elements),
                                  declared=_inertial(body, name, model.compiler, model.source),
                                  unselected=unselected[0], unread=unread))
        walk_children(body, child_class, suffix, model, prefix, stack)

    def walk_children(element, class_name: str, suffix: str, model: _Model, prefix: str, stack: tuple) -> None:
        for child, cls, more in _child_bodies(element, class_name, suffix, model.source, replicas):
            if cls is not None:
                walk_body(child, cls, more, model, prefix, stack)
                continue
            reason = attachments.absent(child, model) if missing_meshes == "per-link" else None
            if reason is not None:
                # one entry standing for the attached bodies, all named with the prefix (as SDFormat's NAME::*)
                counter[0] += 1
                links.append(LinkGeometry(name=f"{prefix}{child.get('prefix')}*{more}", elements=(), declared=None,
                                          unread=f"attached model not read: {reason}"))
                continue
            attached, deeper = attachments.model(child, model, stack)
            classes.update(attached.defaults.classes)
            inner = prefix + child.get("prefix")
            if child.get("body") is None:           # the whole worldbody, as a frame
                for world in attached.root.findall("worldbody"):
                    walk_children(world, "main", more, attached, inner, deeper)
            else:
                body, body_class, copy = _attached_body(child, attached)
                walk_body(body, body_class, copy + more, attached, inner, deeper)

    def collect(element, link: str, class_name: str, pose, elements: list, model: _Model, stack: tuple,
                unselected: list, absent: list) -> None:
        degrees, eulerseq, _ = model.compiler
        for child in element:
            if child.tag == "geom":
                attrs = model.defaults.attributes(child, class_name, model.source)
                if attrs.get("type") == "plane":      # MuJoCo gives a plane no mass and no inertia
                    continue
                lineage = model.defaults.lineage(child.get("class", class_name))
                if _selected(attrs, selection, groups, f"body {link!r} geom {len(elements) + 1}", model.source,
                             model.paired, lineage):
                    label = f"geom {len(elements) + 1}"
                    if attrs.get("type") == "hfield":
                        elements.append(_hfield_geom(attrs, pose, label, link, model.hfields, model.compiler,
                                                     model.source))
                        continue
                    elements.append(_geom(attrs, pose, label, link, model.meshes, packages, model.compiler,
                                          model.source, missing_meshes))
                else:
                    unselected[0] += 1
            elif child.tag == "frame":
                attrs = dict(child.attrib)
                rotation = orientation_matrix(attrs, degrees=degrees, eulerseq=eulerseq, what=f"body {link!r} frame",
                                              source=model.source)
                position = _coordinates(_numbers(attrs.get("pos"), 3, f"body {link!r} frame pos", model.source,
                                                 default=(0, 0, 0)), f"body {link!r} frame pos", model.source)
                composed = (pose[0] @ rotation, pose[0] @ position + pose[1])
                collect(child, link, child.get("childclass", class_name), composed, elements, model, stack, unselected,
                        absent)
            elif child.tag == "replicate":
                for copy in _replica_poses(child, pose, model, replicas):
                    collect(child, link, class_name, copy, elements, model, stack, unselected, absent)
            elif child.tag == "attach" and child.get("body") is None:
                # a whole worldbody attached as a frame: its geoms are this body's, in its own model's terms
                reason = attachments.absent(child, model) if missing_meshes == "per-link" else None
                if reason is not None:
                    absent.append(reason)
                    continue
                attached, deeper = attachments.model(child, model, stack)
                for world in attached.root.findall("worldbody"):
                    collect(world, link, "main", pose, elements, attached, deeper, unselected, absent)

    for world in root.findall("worldbody"):
        walk_children(world, "main", "", main, "", (os.path.realpath(source),))
    unknown = [name for name in selection[1] if selection[0] == "class" and name not in classes]
    if unknown:
        raise UsageError(f"{source} has no <default class={unknown[0]!r}> for `geometry` {geometry!r} (its classes: "
                         f"{', '.join(sorted(classes))})")
    if not links and any(world.find("geom") is not None for world in root.findall("worldbody")):
        raise _fail(source, "no bodies: every geom is in <worldbody> (a scene: terrain, floor, walls), which MuJoCo "
                            "fixes to the world with no mass; expected a model with at least one <body>")
    return root.get("model", ""), tuple(links)


#: :func:`files_including` reads at most this many ``*.xml`` files beside the description, each up to this size.
MAX_SIBLINGS_READ = (200, 4 << 20)


def files_including(source: str) -> tuple[str, ...]:
    """The ``*.xml`` files in the folder of ``source`` whose ``<include file="...">`` names it (by its file name,
    as Menagerie's ``scene.xml`` includes the robot beside it), sorted; at most :data:`MAX_SIBLINGS_READ` files
    of at most its size are looked at."""
    folder = os.path.dirname(os.path.abspath(source))
    name = os.path.basename(source)
    pattern = re.compile(rb"<include\s[^>]*file\s*=\s*[\"'](?:\./)?" + re.escape(name.encode()) + rb"[\"']")
    count, size = MAX_SIBLINGS_READ
    found = []
    try:
        entries = sorted(os.listdir(folder))
    except OSError:
        return ()
    for entry in [e for e in entries if e.endswith(".xml") and e != name][:count]:
        path = os.path.join(folder, entry)
        try:
            if not os.path.isfile(path) or os.path.getsize(path) > size:
                continue
            with open(path, "rb") as fh:
                if pattern.search(fh.read()):
                    found.append(path)
        except OSError:
            continue
    return tuple(found)


def warn_if_nothing_collides(robot) -> None:
    """Warn (:class:`~inertia_tool.errors.NoCollidingGeomWarning`) when an MJCF description read for its
    collision geometry has geoms but none that collides, naming the files beside it that include it: their
    ``<contact><pair>`` elements may collide its geoms (MuJoCo Menagerie's Apptronik Apollo and ``scene.xml``)."""
    from ..errors import NoCollidingGeomWarning
    if robot.format != "mjcf" or robot.geometry != "collision":
        return
    if any(link.elements for link in robot.links) or not any(link.unselected for link in robot.links):
        return
    others = sum(link.unselected for link in robot.links)
    scenes = files_including(robot.source)
    where = (f"; {', '.join(scenes)} include{'s' if len(scenes) == 1 else ''} it and may collide its geoms "
             "through <contact><pair>: audit that file" if scenes else "")
    from .description import parse_xml
    root = parse_xml(robot.document, robot.source).getroot() if robot.document else None
    named = root is not None and any(d.get("class") == "collision" for d in root.iter("default"))
    instead = ("--geometry class=collision reads the geoms of its class 'collision', --geometry visual all the "
               "geoms that do not collide (visual and collision shapes together)" if named else
               "--geometry visual reads the geoms that do not collide (visual and collision shapes together), "
               "--geometry group=LIST or class=LIST the geoms of some groups or default classes")
    warnings.warn(NoCollidingGeomWarning(
        f"{robot.source}: no geom collides (all {others} have contype and conaffinity 0 and none is in a "
        f"<contact><pair> of this file), so no link has collision geometry as MuJoCo counts it{where}; "
        f"{instead}"), stacklevel=2)
