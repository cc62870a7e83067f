"""Robot descriptions (URDF, xacro, SDFormat, MJCF) read into one model of links, geometry and inertials.

Every format ends up as a :class:`RobotDescription`: per link, the geometry elements of the chosen kind
(collision or visual) with their pose in the **link frame** and their size in metres, and the declared
``<inertial>`` converted to the link frame (centre of mass, tensor about it in link axes).  Meshes are
resolved to files here (``inertia_tool.robot.resolve``), so a missing mesh is reported before any work.

Conventions (``docs/conventions.md``):

* URDF ``<origin xyz rpy>`` and SDFormat ``<pose>x y z roll pitch yaw</pose>``: fixed-axis roll, pitch, yaw,
  ``R = R_z(yaw) R_y(pitch) R_x(roll)`` with active elementary rotations; a point ``p`` of the element frame
  is ``R p + xyz`` in the link frame.
* A ``<cylinder>`` (and ``<capsule>``) has its axis along the element's z, centred on its origin; ``length``
  is the cylindrical part (a capsule adds a hemisphere of ``radius`` at each end).  ``<box size>`` is the
  full edge lengths.  ``<mesh scale>`` multiplies the file coordinates (metres) axis by axis, before the pose.
* The declared inertia is given in the inertial frame (``I_frame``); in link axes it is ``R I_frame Rᵀ``.

xacro files (``*.xacro``) are expanded with the ``xacro`` package (``mappings`` are its ``name:=value``
arguments; ``$(find NAME)`` resolves through ``packages`` and ``ROS_PACKAGE_PATH``) only when the caller says
so (``run_xacro=True``): expansion runs code from the file, so it runs in a child process with limits
(:mod:`inertia_tool.isolate`).  MJCF is read by
``inertia_tool.robot.mjcf``.
"""

from __future__ import annotations

import math
import os
import re
import warnings
from dataclasses import field

import numpy as np

from ..errors import InvalidMeshError, MeshReadError, RobotDescriptionError, SkippedModelWarning, UsageError
from ..mesh.regular import open_regular
from ..units import DECIMAL
from ..values import frozen_value
from .resolve import MAX_FOLDERS_UP, package_directory, resolve_uri
from .xacro_expand import _fail

__all__ = ["GeometryElement", "DeclaredInertial", "LinkGeometry", "RobotDescription", "read_robot",
           "rpy_to_matrix", "GEOMETRY_KINDS", "GEOMETRY_SELECTORS", "parse_geometry", "geometry_words",
           "ROBOT_SUFFIXES", "PRIMITIVES", "parse_decimal", "MAX_ROBOT_LINKS",
           "ROBOT_LENGTH_RANGE", "ROBOT_SCALE_RANGE"]

#: Which geometry of a link to take: ``<collision>`` (default; usually simpler, closed meshes) or ``<visual>``;
#: for MJCF also ``"all"``: every geom in ``<compiler inertiagrouprange>``, as MuJoCo's inertia from geometry.
GEOMETRY_KINDS = ("collision", "visual", "all")

#: MJCF only, beyond :data:`GEOMETRY_KINDS`: ``"group=LIST"`` takes the geoms whose ``group`` is listed (``3``,
#: ``0-2,5``: what ``<compiler inertiagrouprange="3 3">`` makes MuJoCo's inertia from geometry count, for one
#: group), ``"class=LIST"`` the geoms whose default class is named or lies under a named class (``collision``:
#: Menagerie's collision geoms).  Either replaces the contact rule and ``inertiagrouprange``.
GEOMETRY_SELECTORS = ("group", "class")

#: Most groups a ``group=`` list may name (ranges expanded): MuJoCo's groups are small integers (0-5 are drawn).
MAX_GEOMETRY_GROUPS = 1024

_GROUP_ITEM = re.compile(r"(\d{1,9})(?:-(\d{1,9}))?")
_CLASS_NAME = re.compile(r"[^,\s]+")


def parse_geometry(geometry) -> tuple[str, tuple]:
    """``geometry`` (a :data:`GEOMETRY_KINDS` word, ``"group=LIST"`` or ``"class=LIST"``) as ``(kind, values)``:
    ``("collision", ())``, ``("group", (2, 3))`` (sorted, without repeats), ``("class", ("collision",))``.

    Raises
    ------
    UsageError
        Anything else, in one sentence saying what was expected.
    """
    if geometry in GEOMETRY_KINDS:
        return geometry, ()
    kind, sep, listed = str(geometry).partition("=")
    expected = (f"Expected `geometry` to be one of {', '.join(GEOMETRY_KINDS)}, group=LIST (MJCF geom groups, "
                "e.g. group=3 or group=0-2,5) or class=LIST (MJCF default classes, e.g. class=collision)")
    if not sep or kind not in GEOMETRY_SELECTORS or not listed:
        raise UsageError(f"{expected}, got {str(geometry)[:80]!r}")
    items = listed.split(",")
    if kind == "class":
        if not all(_CLASS_NAME.fullmatch(item) for item in items):
            raise UsageError(f"{expected}; class names are separated by commas without spaces, got "
                             f"{str(geometry)[:80]!r}")
        return kind, tuple(dict.fromkeys(items))
    groups: set = set()
    for item in items:
        match = _GROUP_ITEM.fullmatch(item)
        low, high = (int(match.group(1)), int(match.group(2) or match.group(1))) if match else (1, 0)
        if not match or low > high or len(groups) + high - low + 1 > MAX_GEOMETRY_GROUPS:
            raise UsageError(f"{expected}; a group is a whole number >= 0 or a range A-B with A <= B, at most "
                             f"{MAX_GEOMETRY_GROUPS} in all, got {item[:40]!r} in {str(geometry)[:80]!r}")
        groups.update(range(low, high + 1))
    return kind, tuple(sorted(groups))


def geometry_words(geometry: str) -> str:
    """What ``geometry`` takes, for a link without any: ``"collision geometry"``, ``"geom in <compiler
    inertiagrouprange>"``, ``"geom in group 2 or 3"``, ``"geom of class 'collision' (or a class under it)"``."""
    kind, values = parse_geometry(geometry)
    if kind == "all":
        return "geom in <compiler inertiagrouprange>"
    if kind == "group":
        return f"geom in group {' or '.join(map(str, values))}"
    if kind == "class":
        names = " or ".join(repr(v) for v in values)
        return f"geom of class {names} (or a class under {'it' if len(values) == 1 else 'them'})"
    return f"{kind} geometry"


#: The geometry kind a link without geometry of the chosen kind may have instead.
_OTHER_KIND = {"collision": "visual", "visual": "collision"}

#: Primitive shapes with closed-form mass properties.
PRIMITIVES = ("box", "cylinder", "sphere", "capsule", "ellipsoid")

#: Description formats by suffix.
ROBOT_SUFFIXES = {".urdf": "urdf", ".xacro": "xacro", ".sdf": "sdf", ".world": "sdf", ".xml": "mjcf",
                  ".mjcf": "mjcf"}

#: Largest description file read (bytes); descriptions are text of a few hundred KB at most.
MAX_DESCRIPTION_BYTES = 64 << 20

#: Links (MJCF: bodies) a description may hold.  The largest real robots have a few hundred; each link costs a
#: few kB of parsed geometry and audit, so this bounds a hostile file's memory (300,000 links took 4 GB).
MAX_ROBOT_LINKS = 10_000

#: Lengths a robot description may state (primitive sizes, |origin| coordinates), m: a nanometre to a million
#: kilometres.  Inside this range every closed form of ``robot.geometry`` (volumes ~ s³, moments ~ s⁵, times
#: any density of ``OPTION_RANGES``) is a normal float64; outside it they overflow or underflow to 0.
ROBOT_LENGTH_RANGE = (1e-9, 1e9)

#: Mesh scale factors a description may state, by magnitude (a negative factor mirrors): the mesh's own
#: coordinates are bounded by the reader, so a factor in this range keeps the scaled mesh finite.
ROBOT_SCALE_RANGE = (1e-9, 1e9)

#: The one number grammar of robot files (:data:`inertia_tool.units.DECIMAL`: ``xsd:double`` without ``INF``
#: and ``NaN``; no ``1_000``, ``inf``, ``nan`` or non-ASCII digits, which Python's ``float()`` would take).
_DECIMAL = DECIMAL


def rpy_to_matrix(rpy) -> np.ndarray:
    """Active rotation of fixed-axis roll, pitch, yaw (rad): ``R = R_z(yaw) R_y(pitch) R_x(roll)`` (URDF/SDF).

    Parameters
    ----------
    rpy : (3,) array_like
        ``(roll, pitch, yaw)`` in rad.

    Returns
    -------
    (3, 3) float
        Columns are the rotated frame's axes in parent components.
    """
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


def _frozen(a, shape) -> np.ndarray:
    out = np.array(a, dtype=np.float64).reshape(shape)
    out.flags.writeable = False
    return out


@frozen_value
class GeometryElement:
    """One ``<collision>`` or ``<visual>`` geometry of a link (MJCF: one ``<geom>``).

    Attributes
    ----------
    kind : str
        ``"box"``, ``"cylinder"``, ``"sphere"``, ``"capsule"``, ``"ellipsoid"``, ``"polyline"`` or ``"mesh"``.
    rotation : (3, 3) float
        Columns are the element frame's axes in link axes (active).
    translation : (3,) float
        Origin of the element frame in the link frame, m.
    size : tuple of float
        m.  box: full edge lengths ``(x, y, z)``; cylinder, capsule: ``(radius, length)`` with ``length`` the
        cylindrical part along the element z; sphere: ``(radius,)``; ellipsoid: semi-axes ``(a, b, c)``;
        polyline: ``(height,)``; mesh: ``()``.
    mesh : str or None
        Absolute path of the mesh file (``kind == "mesh"``).
    uri : str or None
        The mesh as written in the description (for messages).
    scale : (3,) float
        Mesh scale factors per axis (1 for primitives).
    name : str
        Label: the element's ``name`` or ``"collision 1"``, ``"visual 2"`` ...
    reference_rotation : (3, 3) float
        Applied to the mesh file's coordinates before ``scale`` (MJCF ``refquat``: its conjugate); identity
        elsewhere.  A file point ``v`` is ``rotation (scale ⊙ (reference_rotation v + reference_translation))
        + translation`` in the link frame.
    reference_translation : (3,) float
        m, added after ``reference_rotation`` (MJCF: ``−Qᵀ refpos``); zero elsewhere.
    density : float or None
        kg/m³ the description gives this element (MJCF geom ``density``, MuJoCo's default 1000); None when the
        format has no such notion (URDF, SDFormat).
    mass : float or None
        kg the description gives this element (MJCF geom ``mass``; overrides ``density``); None if not given.
    shell : bool
        The description puts the element's mass on its surface (MJCF ``shellinertia``, ``<mesh inertia="shell">``).
    fit_scale : float or None
        MJCF: a primitive (``kind`` box, sphere, ...) with a ``mesh`` and no size takes its size from the mesh
        (MuJoCo fits it to the mesh's equivalent inertia box, times ``fitscale``); ``size`` is empty until
        :func:`inertia_tool.robot.geometry.fitted_element` fits it.  None for every other element.
    note : str
        What the reader should know about how the element stands for the description's geometry (an MJCF
        height field taken as MuJoCo's inertia box); empty for an element read as written.  It is carried into
        the link result's ``warnings``.
    vertices : (n, 3) float or None
        An inline mesh (MJCF ``<mesh vertex=...>``): its vertices in the file's frame, m, before the reference
        transform and ``scale``; ``mesh`` is then None.  None for a mesh read from a file and for primitives.
    faces : (m, 3) int or None
        The inline mesh's triangles (indices into ``vertices``, wound outwards).
    fit_aabb : bool
        With ``fit_scale``: MuJoCo's ``<compiler fitaabb="true">``, the primitive is fitted to the mesh's
        bounding box in its principal axes instead of its equivalent inertia box.
    mesh_inertia : str
        MJCF ``<mesh inertia>`` when it names ``"convex"`` or ``"legacy"`` (taken with the model's own
        densities: :mod:`inertia_tool.robot.mesh_inertia`); ``"exact"`` otherwise (``shell`` is ``shell``).
    polygons : tuple of tuple of (x, y)
        SDFormat ``<polyline>``: the region's polygons in the element's xy plane, m, checked simple, not meeting
        each other, counter-clockwise (:func:`inertia_tool.mass.extrusion.polygon_region`); extruded from
        ``z = 0`` to ``size[0]``, even-odd nesting.  Empty for every other kind.
    submesh : str
        SDFormat ``<mesh><submesh><name>``: only the COLLADA file's sub-mesh of this name (the geometry of the
        nodes so named, :mod:`inertia_tool.mesh.collada_nodes`) is the element; empty for the whole file.
    submesh_center : bool
        ``<submesh><center>true``: the sub-mesh is moved so that its bounding-box centre is at the origin of the
        file's frame, before ``scale``.
    """

    kind: str
    rotation: np.ndarray
    translation: np.ndarray
    size: tuple = ()
    mesh: str | None = None
    uri: str | None = None
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    name: str = ""
    reference_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    reference_translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    density: float | None = None
    mass: float | None = None
    shell: bool = False
    fit_scale: float | None = None
    note: str = ""
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    fit_aabb: bool = False
    mesh_inertia: str = "exact"
    polygons: tuple = ()
    submesh: str = ""
    submesh_center: bool = False

    def __post_init__(self):
        object.__setattr__(self, "rotation", _frozen(self.rotation, (3, 3)))
        object.__setattr__(self, "translation", _frozen(self.translation, (3,)))
        object.__setattr__(self, "scale", _frozen(self.scale, (3,)))
        object.__setattr__(self, "reference_rotation", _frozen(self.reference_rotation, (3, 3)))
        object.__setattr__(self, "reference_translation", _frozen(self.reference_translation, (3,)))
        object.__setattr__(self, "size", tuple(float(s) for s in self.size))


@frozen_value
class DeclaredInertial:
    """A link's ``<inertial>`` as the description declares it, in the link frame.

    Attributes
    ----------
    mass : float
        kg.
    center_of_mass : (3,) float
        m, link frame (the inertial frame's origin).
    inertia : (3, 3) float
        kg·m² about ``center_of_mass``, **link axes** (``R I_frame Rᵀ``), tensor convention (−∫xy dm).
    rotation : (3, 3) float
        The declared inertial frame's axes (columns) in link axes.
    inertia_in_frame : (3, 3) float
        kg·m², the tensor as written (inertial-frame axes).
    """

    mass: float
    center_of_mass: np.ndarray
    inertia: np.ndarray
    rotation: np.ndarray
    inertia_in_frame: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "mass", float(self.mass))
        for name, shape in (("center_of_mass", (3,)), ("inertia", (3, 3)), ("rotation", (3, 3)),
                            ("inertia_in_frame", (3, 3))):
            object.__setattr__(self, name, _frozen(getattr(self, name), shape))


@frozen_value
class LinkGeometry:
    """A link (MJCF: a body): its geometry elements of the chosen kind and its declared inertial.

    Attributes
    ----------
    name : str
    elements : tuple of GeometryElement
        Empty for a link without geometry of that kind (a frame, a virtual link).
    declared : DeclaredInertial or None
        None when the description has no ``<inertial>`` for the link.
    unselected : int
        Geometry elements of the link the chosen kind leaves out (``<visual>`` when reading collision geometry
        and the other way round; MJCF: the geoms outside the selection), so that a link without geometry can
        say which kind it has.
    unread : str
        Why this entry's geometry could not be read at all, "" otherwise: an SDFormat ``<include>`` whose model
        is not on disk (``read_robot(missing_meshes="per-link")``) is one entry ``NAME::*`` standing for its
        unknown links, with no elements, and an MJCF ``<attach>`` whose model file is not on disk one entry
        ``PREFIX*`` (a body that the attached ``<worldbody>`` would have given geoms says so too); it never gets a
        result.
    """

    name: str
    elements: tuple
    declared: DeclaredInertial | None
    unselected: int = 0
    unread: str = ""


@frozen_value
class RobotDescription:
    """A robot description reduced to what mass properties need.

    Attributes
    ----------
    name : str
        The robot / model name.
    source : str
        The file read.
    format : str
        ``"urdf"``, ``"xacro"`` (expanded to URDF), ``"sdf"`` or ``"mjcf"``.
    geometry : str
        ``"collision"`` or ``"visual"``: which elements ``links`` hold.
    links : tuple of LinkGeometry
        In document order.
    document : bytes
        The XML that was parsed (for xacro: the expanded URDF); ``write_corrected`` edits it.
    """

    name: str
    source: str
    format: str
    geometry: str
    links: tuple
    document: bytes = field(repr=False, default=b"")

    def link(self, name: str) -> LinkGeometry:
        """The link called ``name`` (KeyError naming the known links if absent)."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(f"no link {name!r}; links: {', '.join(link.name for link in self.links)}")


# -- shared parsing helpers ------------------------------------------------------------------------------

def parse_decimal(token: str) -> float:
    """The value of one number of a robot file, by the grammar :data:`_DECIMAL` (ValueError otherwise).

    A token that matches but overflows (``1e999``) comes back as infinity, for the caller's finiteness check.
    """
    if not _DECIMAL.fullmatch(token):
        raise ValueError(f"not a decimal number: {token[:40]!r}")
    return float(token)


def _numbers(text, count: int | None, what: str, source: str, default=None) -> np.ndarray:
    """The whitespace-separated numbers of an attribute or element text (``count`` of them; any count when
    None), each by :func:`parse_decimal` and finite; ``default`` when ``text`` is None."""
    if text is None:
        if default is None:
            raise _fail(source, f"{what}: missing")
        return np.array(default, dtype=np.float64)
    expected = f"{count} " if count is not None else ""
    shown = " ".join(str(text).split())[:80]
    try:
        values = np.array([parse_decimal(t) for t in str(text).split()], dtype=np.float64)
    except ValueError:
        raise _fail(source, f"{what}: expected {expected}decimal numbers (like -1.5e-3), got {shown!r}") from None
    if (count is not None and values.shape != (count,)) or not np.all(np.isfinite(values)):
        raise _fail(source, f"{what}: expected {expected}finite numbers, got {shown!r}")
    return values


def _positive(value: float, what: str, source: str) -> float:
    """``value`` as a size (m): positive and within :data:`ROBOT_LENGTH_RANGE`."""
    low, high = ROBOT_LENGTH_RANGE
    if not (math.isfinite(value) and value > 0):
        raise _fail(source, f"{what}: expected a positive size, got {value:g}")
    if not low <= value <= high:
        raise _fail(source, f"{what}: expected a size between {low:g} and {high:g} m, got {value:g} (its volume "
                            "and moments would not be normal float64 numbers)")
    return float(value)


def _coordinates(values: np.ndarray, what: str, source: str) -> np.ndarray:
    """``values`` (m) as position coordinates: each at most ``ROBOT_LENGTH_RANGE[1]`` in magnitude."""
    high = ROBOT_LENGTH_RANGE[1]
    if np.any(np.abs(values) > high):
        raise _fail(source, f"{what}: expected coordinates at most {high:g} m in magnitude, got "
                            f"{' '.join(f'{v:g}' for v in values)}")
    return values


def _scale(values: np.ndarray, what: str, source: str) -> np.ndarray:
    """Mesh scale factors: each non-zero with a magnitude within :data:`ROBOT_SCALE_RANGE`."""
    low, high = ROBOT_SCALE_RANGE
    if not np.all((np.abs(values) >= low) & (np.abs(values) <= high)):
        raise _fail(source, f"{what}: expected scale factors between {low:g} and {high:g} in magnitude (negative "
                            f"mirrors), got {' '.join(f'{v:g}' for v in values)}")
    return values


#: An XML declaration after leading comments (osrf gazebo_models ``mpl_right_arm/model.sdf`` puts its licence
#: first) or a blank line (``lunar_tranquillitatis_pit``): not well-formed XML, but what Gazebo reads.  Only
#: comments and whitespace may come before it.
_LATE_DECLARATION = re.compile(rb"\A(\xef\xbb\xbf)?((?:\s*<!--.*?-->)*\s*)(<\?xml\s[^?]*\?>)", re.DOTALL)

#: A comment's body: ``--`` inside it (osrf ``src_doorway``: a ``<!--`` opened again inside a comment) is not
#: well-formed XML; Gazebo's parser ends the comment at the first ``-->`` as this does.
_COMMENT = re.compile(rb"<!--(.*?)-->", re.DOTALL)


def _tolerated(data: bytes) -> bytes:
    """``data`` with what Gazebo's parser accepts and XML 1.0 does not made blank, byte for byte the same length
    (offsets stay those of the input): a declaration after leading comments or whitespace; ``--`` inside a
    comment (the second hyphen made a space) and a comment body ending in ``-``."""
    late = _LATE_DECLARATION.match(data)
    declared = re.search(rb"encoding\s*=\s*[\"']([^\"']*)", late.group(3)) if late is not None else None
    if late is not None and late.start(3) > (3 if late.group(1) else 0) \
            and (declared is None or declared.group(1).lower() in (b"utf-8", b"utf8")):
        data = data[:late.start(3)] + b" " * len(late.group(3)) + data[late.end(3):]

    def blank(match: re.Match) -> bytes:
        body = match.group(1).replace(b"--", b"- ")
        if body.endswith(b"-"):
            body = body[:-1] + b" "
        return b"<!--" + body + b"-->"
    return _COMMENT.sub(blank, data)


def parse_xml(data: bytes, source: str):
    """An lxml tree of ``data`` keeping comments and whitespace; no entity expansion, no network.

    What Gazebo reads and XML 1.0 does not (a declaration after leading comments or a blank line, ``--``
    inside a comment) is read as if it were blank (:func:`_tolerated`), so offsets stay those of the input.
    """
    from lxml import etree
    parser = etree.XMLParser(remove_blank_text=False, remove_comments=False, resolve_entities=False,
                             no_network=True, huge_tree=False)
    try:
        return etree.fromstring(data, parser).getroottree()
    except etree.XMLSyntaxError as exc:
        tolerated = _tolerated(data)
        if tolerated != data:
            try:
                return etree.fromstring(tolerated, parser).getroottree()
            except etree.XMLSyntaxError:
                pass
        raise _fail(source, f"not well-formed XML ({exc})") from None


def _read_bytes(path: str, *, head: int | None = None) -> bytes:
    """The bytes of the description file ``path`` (only its first ``head`` bytes when given).

    Opened only as a regular file (:func:`~inertia_tool.mesh.regular.open_regular`: a named pipe or a device
    is refused, never waited on), and never more than :data:`MAX_DESCRIPTION_BYTES` read."""
    try:
        fh = open_regular(path)
    except FileNotFoundError:
        raise _fail(path, "no such file") from None
    except MeshReadError as exc:                 # "PATH: is a FIFO (named pipe), not a regular file"
        raise RobotDescriptionError(str(exc)) from None
    except OSError as exc:
        raise _fail(path, f"cannot be read ({exc.strerror or exc})") from None
    with fh:
        data = fh.read(MAX_DESCRIPTION_BYTES + 1 if head is None else head)
    if head is None and len(data) > MAX_DESCRIPTION_BYTES:
        raise _fail(path, f"more than the {MAX_DESCRIPTION_BYTES:,} bytes a robot description may have")
    return data


# -- xacro -------------------------------------------------------------------------------------------------

def _expand_xacro(path: str, mappings: dict, packages: dict, limits=None) -> bytes:
    """The expanded URDF of a xacro file, expanded in a child process under ``limits`` (xacro runs the
    Python expressions of the file: :mod:`inertia_tool.isolate`, :data:`~inertia_tool.isolate.XACRO_LIMITS`)."""
    from ..errors import IsolatedProcessError
    from ..isolate import XACRO_LIMITS, run_isolated
    from .xacro_expand import expand_here
    try:
        data = run_isolated(expand_here, path, dict(mappings), dict(packages),
                            limits=limits or XACRO_LIMITS, what="xacro expansion")
    except IsolatedProcessError as exc:
        raise _fail(path, str(exc)) from None
    if not isinstance(data, bytes):
        raise _fail(path, "xacro expansion gave no document")
    return data


# -- URDF --------------------------------------------------------------------------------------------------

def _urdf_origin(element, what: str, source: str) -> tuple[np.ndarray, np.ndarray]:
    origin = element.find("origin") if element is not None else None
    if origin is None:
        return np.eye(3), np.zeros(3)
    xyz = _coordinates(_numbers(origin.get("xyz"), 3, f"{what} <origin xyz>", source, default=(0, 0, 0)),
                       f"{what} <origin xyz>", source)
    rpy = _numbers(origin.get("rpy"), 3, f"{what} <origin rpy>", source, default=(0, 0, 0))
    return rpy_to_matrix(rpy), xyz


def _tensor(ixx, ixy, ixz, iyy, iyz, izz) -> np.ndarray:
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=np.float64)


def _declared(mass: float, rotation, position, tensor, what: str, source: str) -> DeclaredInertial:
    if not math.isfinite(mass):
        raise _fail(source, f"{what}: mass is not a finite number")
    if not np.all(np.isfinite(tensor)):
        raise _fail(source, f"{what}: inertia has non-finite entries")
    return DeclaredInertial(mass=mass, center_of_mass=position, inertia=rotation @ tensor @ rotation.T,
                            rotation=rotation, inertia_in_frame=tensor)


def _urdf_inertial(link, source: str) -> DeclaredInertial | None:
    inertial = link.find("inertial")
    if inertial is None:
        return None
    what = f"link {link.get('name')!r} <inertial>"
    rotation, position = _urdf_origin(inertial, what, source)
    mass_el = inertial.find("mass")
    mass = _numbers(mass_el.get("value") if mass_el is not None else None, 1, f"{what} <mass value>", source)[0]
    ie = inertial.find("inertia")
    if ie is None:
        raise _fail(source, f"{what}: no <inertia>")
    values = [_numbers(ie.get(k), 1, f"{what} <inertia {k}>", source, default=(0.0,))[0]
              for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
    return _declared(mass, rotation, position, _tensor(*values), what, source)


def _urdf_geometry(element, link_name: str, label: str, base: str, packages: dict, source: str,
                   missing: str = "refuse"):
    geometry = element.find("geometry")
    what = f"link {link_name!r} {label}"
    shapes = [c for c in geometry if isinstance(c.tag, str)] if geometry is not None else []
    if len(shapes) != 1:
        raise _fail(source, f"{what}: expected one shape inside <geometry>, found {len(shapes)}")
    shape = shapes[0]
    rotation, translation = _urdf_origin(element, what, source)
    kind = shape.tag
    name = element.get("name") or label
    if kind == "box":
        size = tuple(_positive(v, f"{what} <box size>", source)
                     for v in _numbers(shape.get("size"), 3, f"{what} <box size>", source))
        return GeometryElement("box", rotation, translation, size=size, name=name)
    if kind in ("cylinder", "capsule"):
        r = _positive(_numbers(shape.get("radius"), 1, f"{what} <{kind} radius>", source)[0], f"{what} radius", source)
        h = _numbers(shape.get("length"), 1, f"{what} <{kind} length>", source)[0]
        if not (math.isfinite(h) and (h > 0 or (kind == "capsule" and h == 0))):
            raise _fail(source, f"{what}: <{kind} length> must be positive, got {h:g}")
        h = _positive(h, f"{what} <{kind} length>", source) if h else h
        return GeometryElement(kind, rotation, translation, size=(r, h), name=name)
    if kind == "sphere":
        r = _positive(_numbers(shape.get("radius"), 1, f"{what} <sphere radius>", source)[0], f"{what} radius", source)
        return GeometryElement("sphere", rotation, translation, size=(r,), name=name)
    if kind == "mesh":
        uri = shape.get("filename")
        if not uri:
            raise _fail(source, f"{what}: <mesh> without a filename")
        scale = _scale(_numbers(shape.get("scale"), 3, f"{what} <mesh scale>", source, default=(1, 1, 1)),
                       f"{what} <mesh scale>", source)
        path = resolve_uri(uri, base=base, packages=packages, source=source, link=link_name, missing=missing)
        return GeometryElement("mesh", rotation, translation, mesh=path, uri=uri, scale=scale, name=name)
    raise _fail(source, f"{what}: unsupported geometry <{kind}> (expected box, cylinder, sphere, capsule or mesh)")


def _read_urdf(root, source: str, base: str, packages: dict, geometry: str,
               missing: str = "refuse") -> tuple[str, tuple]:
    if root.tag != "robot":
        raise _fail(source, f"not a URDF: the root element is <{root.tag}>, expected <robot>")
    links = []
    for link in root.iter("link"):
        if link.getparent() is not root:
            continue
        name = link.get("name")
        if not name:
            raise _fail(source, "a <link> without a name")
        elements = tuple(_urdf_geometry(el, name, f"{geometry} {k + 1}", base, packages, source, missing)
                         for k, el in enumerate(link.findall(geometry)))
        other = len(link.findall(_OTHER_KIND[geometry])) if geometry in _OTHER_KIND else 0
        links.append(LinkGeometry(name=name, elements=elements, declared=_urdf_inertial(link, source),
                                  unselected=other))
    return root.get("name", ""), tuple(links)


# -- SDFormat ----------------------------------------------------------------------------------------------

def _sdf_pose(element, what: str, source: str) -> tuple[np.ndarray, np.ndarray]:
    pose = element.find("pose") if element is not None else None
    if pose is None:
        return np.eye(3), np.zeros(3)
    relative = pose.get("relative_to")
    if relative not in (None, ""):
        parent = element.getparent()
        own_link = parent.get("name") if parent is not None and parent.tag == "link" else None
        if element.tag != "link" and relative != own_link:
            raise _fail(source, f"{what}: <pose relative_to={relative!r}> (only poses relative to the link are "
                                "supported)")
    text = (pose.text or "").strip()
    values = _numbers(text or "0 0 0 0 0 0", 6, f"{what} <pose>", source)
    rpy = values[3:]
    if pose.get("degrees") == "true":
        rpy = np.radians(rpy)
    if pose.get("rotation_format", "euler_rpy") != "euler_rpy":
        raise _fail(source, f"{what}: <pose rotation_format={pose.get('rotation_format')!r}> is not supported")
    return rpy_to_matrix(rpy), _coordinates(values[:3], f"{what} <pose>", source)


def _sdf_number(element, tag: str, what: str, source: str, default=None) -> float:
    child = element.find(tag) if element is not None else None
    return float(_numbers(child.text if child is not None else None, 1, f"{what} <{tag}>", source,
                          default=None if default is None else (default,))[0])


def _sdf_inertial(link, source: str) -> DeclaredInertial | None:
    inertial = link.find("inertial")
    if inertial is None:
        return None
    what = f"link {link.get('name')!r} <inertial>"
    rotation, position = _sdf_pose(inertial, what, source)
    mass = _sdf_number(inertial, "mass", what, source, default=1.0)
    ie = inertial.find("inertia")
    values = [_sdf_number(ie, k, what, source, default=1.0 if k in ("ixx", "iyy", "izz") else 0.0)
              for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
    return _declared(mass, rotation, position, _tensor(*values), what, source)


def _sdf_geometry(element, link_name: str, label: str, base: str, packages: dict, source: str,
                  missing: str = "refuse"):
    what = f"link {link_name!r} {label}"
    geometry = element.find("geometry")
    shapes = [c for c in geometry if isinstance(c.tag, str)] if geometry is not None else []
    polylines = len(shapes) > 1 and all(c.tag == "polyline" for c in shapes)
    if len(shapes) != 1 and not polylines:
        raise _fail(source, f"{what}: expected one shape inside <geometry> (or only <polyline>s), "
                            f"found {len(shapes)}")
    shape = shapes[0]
    rotation, translation = _sdf_pose(element, what, source)
    name = element.get("name") or label
    kind = shape.tag
    if kind == "polyline":
        return GeometryElement("polyline", rotation, translation, size=(_sdf_polyline_height(shapes, what, source),),
                               polygons=_sdf_polygons(shapes, what, source), name=name)
    if kind == "box":
        size = _numbers(shape.findtext("size"), 3, f"{what} <box><size>", source)
        return GeometryElement("box", rotation, translation, size=tuple(_positive(s, what, source) for s in size),
                               name=name)
    if kind in ("cylinder", "capsule"):
        r = _positive(_sdf_number(shape, "radius", what, source), f"{what} radius", source)
        h = _sdf_number(shape, "length", what, source)
        return GeometryElement(kind, rotation, translation, size=(r, _positive(h, f"{what} length", source)), name=name)
    if kind == "sphere":
        r = _positive(_sdf_number(shape, "radius", what, source), f"{what} radius", source)
        return GeometryElement("sphere", rotation, translation, size=(r,), name=name)
    if kind == "ellipsoid":
        radii = _numbers(shape.findtext("radii"), 3, f"{what} <ellipsoid><radii>", source)
        return GeometryElement("ellipsoid", rotation, translation,
                               size=tuple(_positive(s, what, source) for s in radii), name=name)
    if kind == "mesh":
        uri = (shape.findtext("uri") or "").strip()
        if not uri:
            raise _fail(source, f"{what}: <mesh> without a <uri>")
        scale = _scale(_numbers(shape.findtext("scale"), 3, f"{what} <mesh><scale>", source, default=(1, 1, 1)),
                       f"{what} <mesh><scale>", source)
        path = resolve_uri(uri, base=base, packages=packages, source=source, link=link_name, missing=missing)
        submesh, center = _sdf_submesh(shape.find("submesh"), path, what, source)
        return GeometryElement("mesh", rotation, translation, mesh=path, uri=uri, scale=scale, name=name,
                               submesh=submesh, submesh_center=center)
    raise _fail(source, f"{what}: unsupported geometry <{kind}> (expected box, cylinder, sphere, capsule, "
                        "ellipsoid, polyline or mesh)")


def _sdf_submesh(element, path: str, what: str, source: str) -> tuple[str, bool]:
    """``(name, center)`` of a ``<mesh><submesh>`` (``("", False)`` without one); only COLLADA files name
    their sub-meshes here (:mod:`inertia_tool.mesh.collada_nodes`)."""
    if element is None:
        return "", False
    name = (element.findtext("name") or "").strip()
    if not name:
        raise _fail(source, f"{what}: <mesh><submesh> without a <name>")
    if not path.lower().endswith(".dae"):
        raise _fail(source, f"{what}: <mesh><submesh> {name!r} of {os.path.basename(path)!r}: sub-meshes are "
                            "read from COLLADA (.dae) files only")
    text = (element.findtext("center") or "false").strip().lower()
    if text not in ("true", "false", "1", "0"):
        raise _fail(source, f"{what}: <submesh><center> expected true or false, got {text[:40]!r}")
    return name, text in ("true", "1")


def _sdf_polyline_height(shapes, what: str, source: str) -> float:
    """The extrusion height of the ``<polyline>`` elements of one ``<geometry>`` (SDFormat's default 1 m).

    Gazebo extrudes the whole region by one height; polylines that give different ones are refused rather than
    guessing which one it takes.
    """
    heights = {_sdf_number(shape, "height", f"{what} <polyline>", source, default=1.0) for shape in shapes}
    if len(heights) != 1:
        raise _fail(source, f"{what}: expected one <height> for all <polyline>s of the <geometry>, found "
                            f"{', '.join(f'{h:g}' for h in sorted(heights))}")
    return _positive(heights.pop(), f"{what} <polyline><height>", source)


def _sdf_polygons(shapes, what: str, source: str) -> tuple:
    """The checked, counter-clockwise polygons of ``<polyline>`` elements (even-odd region, see
    :func:`inertia_tool.mass.extrusion.polygon_region`)."""
    from ..mass.extrusion import polygon_region
    polygons = []
    for k, shape in enumerate(shapes):
        points = [_numbers(point.text, 2, f"{what} <polyline> {k + 1} <point>", source)
                  for point in shape.findall("point")]
        polygons.append(np.array(points, dtype=np.float64).reshape(-1, 2))
    try:
        cleaned, _ = polygon_region(polygons)
    except InvalidMeshError as error:
        raise _fail(source, f"{what}: <polyline> {error}") from None
    return tuple(tuple(map(tuple, p.tolist())) for p in cleaned)


#: SDFormat shapes that bound no volume: a ground ``<plane>``, a terrain ``<heightmap>``, ``<empty>``.  Like
#: MuJoCo's planes they give a link no mass: the elements are skipped (a link with nothing else is then a frame).
_SDF_SHAPES_WITHOUT_VOLUME = ("plane", "heightmap", "empty")


def _sdf_without_volume(element) -> bool:
    """Whether a ``<collision>``/``<visual>`` holds one of :data:`_SDF_SHAPES_WITHOUT_VOLUME`."""
    geometry = element.find("geometry")
    shapes = [c for c in geometry if isinstance(c.tag, str)] if geometry is not None else []
    return len(shapes) == 1 and shapes[0].tag in _SDF_SHAPES_WITHOUT_VOLUME


#: Deepest chain of SDFormat ``<include>`` and nested ``<model>`` followed.
MAX_SDF_NESTING = 16

#: Most files the ``<include>``s of one SDFormat description read (repeats counted).
MAX_SDF_INCLUDES = 512


#: Gazebo's stock models that nearly every world file includes and that hold no link with mass: when one is not
#: on disk, the include is skipped with a note (:class:`~inertia_tool.errors.SkippedModelWarning`) instead of
#: refusing the world.  What each one is, for the note.
STOCK_MODELS_WITHOUT_MASS = {"sun": "a directional light", "ground_plane": "a static plane"}


def _searched_folders(scheme: str, packages: dict, base: str) -> str:
    """The folders :func:`~inertia_tool.robot.resolve.package_directory` looked in, for a message."""
    from .resolve import PACKAGE_PATH_VARIABLES
    variables = PACKAGE_PATH_VARIABLES if scheme == "model" else PACKAGE_PATH_VARIABLES[:1]
    parts = [f"{var}={os.environ[var]!r}" if os.environ.get(var) else f"{var} (unset)" for var in variables]
    if packages:
        parts.insert(0, f"the packages given ({', '.join(sorted(packages))})")
    top = os.path.abspath(base)
    for _ in range(MAX_FOLDERS_UP):
        top = os.path.dirname(top)
    parts.append(f"{os.path.abspath(base)} and the folders above it up to {top}")
    return "; ".join(parts)


def _skip_stock_model(uri: str, name: str, source: str) -> None:
    """Warn that the include ``uri`` of the stock model ``name`` (:data:`STOCK_MODELS_WITHOUT_MASS`) is skipped."""
    warnings.warn(SkippedModelWarning(f"{source}: <include> {uri!r} skipped: Gazebo's stock model {name!r} "
                                      f"({STOCK_MODELS_WITHOUT_MASS[name]}, no link with mass) is not on disk"),
                  stacklevel=3)


def _fuel_model(scheme: str, rest: str) -> str | None:
    """The model name of a Gazebo Fuel URL (``https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground
    Plane/2``: ``"Ground Plane"``), None for any other URL."""
    from urllib.parse import unquote
    if scheme not in ("http", "https") or "/models/" not in rest:
        return None
    host = rest.split("/", 1)[0].lower()
    if not host.startswith(("fuel.", "app.")):
        return None
    return unquote(rest.split("/models/", 1)[1].split("/", 1)[0]).strip() or None


def _version_key(text: str | None) -> tuple[int, ...]:
    """``"1.10"`` → ``(1, 10)``; anything unreadable sorts first."""
    parts = re.findall(r"\d+", text or "")
    return tuple(int(p) for p in parts[:4]) if parts else (-1,)


def model_config_files(folder: str) -> tuple[str | None, list[str]]:
    """The SDFormat file Gazebo loads from a model folder, and every file its ``model.config`` lists.

    A Gazebo model folder lists one ``<sdf version="...">FILE</sdf>`` per SDFormat version it ships
    (osrf gazebo_models: ``model-1_2.sdf`` ... ``model.sdf``); Gazebo loads the newest version.  Returns
    ``(None, [])`` when there is no ``model.config`` (or it lists nothing)."""
    config = os.path.join(folder, "model.config")
    if not os.path.isfile(config):
        return None, []
    tree = parse_xml(_read_bytes(config), config)
    listed = [(_version_key(e.get("version")), k, (e.text or "").strip())
              for k, e in enumerate(tree.getroot().iter("sdf")) if (e.text or "").strip()]
    if not listed:
        return None, []
    newest = max(listed, key=lambda item: (item[0], -item[1]))          # the newest; the first of equals
    return (os.path.normpath(os.path.join(folder, newest[2])),
            [os.path.normpath(os.path.join(folder, name)) for _, _, name in listed])


#: The messages of :func:`_sdf_include_file` that say its model is not on disk (not that the include is malformed).
_ABSENT_INCLUDE = re.compile(r"^.*?: <include> .*(?:: cannot find model |, which does not exist$"
                             r"|: a Gazebo Fuel model )")


def _sdf_include_file(include, base: str, packages: dict, source: str) -> str | None:
    """The SDFormat file an ``<include><uri>`` names: a file, or a model folder (the newest version its
    ``model.config`` lists, :func:`model_config_files`, else ``model.sdf``); None for a stock model of
    :data:`STOCK_MODELS_WITHOUT_MASS` that is not on disk (skipped, with a
    :class:`~inertia_tool.errors.SkippedModelWarning` naming it).

    A Gazebo Fuel URL (``https://fuel.gazebosim.org/.../models/Sun``, which Gazebo downloads) is never fetched:
    its model is looked up on disk as ``model://`` would be, under its name in lower case with ``_`` for
    spaces (``Ground Plane``: ``ground_plane``); a stock model is skipped, any other is refused naming it."""
    uri = (include.findtext("uri") or "").strip()
    if not uri:
        raise _fail(source, "<include> without a <uri>")
    scheme, sep, rest = uri.partition("://")
    fuel = _fuel_model(scheme, rest) if sep else None
    if fuel is not None:
        name = fuel.lower().replace(" ", "_")
        directory = package_directory(name, packages, scheme="model", near=base)
        if directory is None and name in STOCK_MODELS_WITHOUT_MASS:
            _skip_stock_model(uri, name, source)
            return None
        if directory is None:
            raise _fail(source, f"<include> {uri!r}: a Gazebo Fuel model ({fuel!r}), which Gazebo downloads and "
                                f"this tool does not; expected a folder {name!r} on disk, searched "
                                f"{_searched_folders('model', packages, base)}")
        path = directory
    elif sep and scheme in ("model", "package"):
        name, _, inner = rest.partition("/")
        directory = package_directory(name, packages, scheme=scheme, near=base)
        if directory is None and scheme == "model" and name in STOCK_MODELS_WITHOUT_MASS:
            _skip_stock_model(uri, name, source)
            return None
        if directory is None:
            raise _fail(source, f"<include> {uri!r}: cannot find model {name!r}; searched "
                                f"{_searched_folders(scheme, packages, base)}")
        path = os.path.join(directory, inner)
    elif sep and scheme == "file":
        path = rest if os.path.isabs(rest) else os.path.join(base, rest)
    elif sep:
        raise _fail(source, f"<include> {uri!r}: unsupported URI scheme {scheme!r}")
    else:
        path = uri if os.path.isabs(uri) else os.path.join(base, uri)
    path = os.path.normpath(path)
    if os.path.isdir(path):
        named, _ = model_config_files(path)
        path = named or os.path.join(path, "model.sdf")
    if not os.path.isfile(path):
        raise _fail(source, f"<include> {uri!r}: resolves to {path}, which does not exist")
    return path


def _sdf_links(model, prefix: str, base: str, packages: dict, geometry: str, source: str, stack: tuple,
               budget: list | None = None, missing: str = "refuse") -> list:
    """The links of ``model`` and of its nested and included models (names prefixed ``model::``).

    ``missing="per-link"``: a mesh file that does not exist is kept (its link says so), and an ``<include>``
    whose model is not on disk becomes one entry ``NAME::*`` without geometry whose ``unread`` says why (its
    links are unknown).

    ``budget``: ``[files, bytes]`` the includes may still read (at most ``MAX_SDF_INCLUDES`` files and
    :data:`MAX_DESCRIPTION_BYTES` bytes in all, so repeated includes cannot multiply without bound)."""
    budget = [MAX_SDF_INCLUDES, MAX_DESCRIPTION_BYTES] if budget is None else budget
    if len(stack) > MAX_SDF_NESTING:
        raise _fail(source, f"models nested or included more than {MAX_SDF_NESTING} deep")
    links = []
    for child in model:
        if not isinstance(child.tag, str):
            continue
        if child.tag == "link":
            name = child.get("name")
            if not name:
                raise _fail(source, "a <link> without a name")
            elements = tuple(_sdf_geometry(el, prefix + name, f"{geometry} {k + 1}", base, packages, source,
                                           missing)
                             for k, el in enumerate(child.findall(geometry)) if not _sdf_without_volume(el))
            other = (sum(1 for el in child.findall(_OTHER_KIND[geometry]) if not _sdf_without_volume(el))
                     if geometry in _OTHER_KIND else 0)
            links.append(LinkGeometry(name=prefix + name, elements=elements, declared=_sdf_inertial(child, source),
                                      unselected=other))
        elif child.tag == "model":
            links += _sdf_links(child, f"{prefix}{child.get('name', '')}::", base, packages, geometry, source,
                                stack + (f"model {child.get('name')}",), budget, missing)
        elif child.tag == "include":
            try:
                path = _sdf_include_file(child, base, packages, source)
            except RobotDescriptionError as exc:
                if missing == "refuse" or not _ABSENT_INCLUDE.search(str(exc)):
                    raise
                links.append(_absent_include(child, prefix, str(exc)[len(source) + 2:]))
                continue
            if path is None:        # a stock light or ground plane that is not on disk: nothing with mass
                continue
            key = os.path.realpath(path)
            if key in stack:
                raise _fail(source, f"<include> of {path} includes itself")
            data = _read_bytes(path)
            budget[0] -= 1
            budget[1] -= len(data)
            if budget[0] < 0 or budget[1] < 0:
                raise _fail(source, f"<include>s read more than {MAX_SDF_INCLUDES} files or "
                                    f"{MAX_DESCRIPTION_BYTES:,} bytes in all")
            root = parse_xml(data, path).getroot()
            inner = root.findall("model")
            if root.tag != "sdf" or len(inner) > 1:
                raise _fail(source, f"<include>: {path} is not an SDFormat file with one <model>")
            if not inner:           # a light, an actor: nothing with mass
                continue
            name = (child.findtext("name") or "").strip() or inner[0].get("name", "")
            links += _sdf_links(inner[0], f"{prefix}{name}::", os.path.dirname(path), packages, geometry, source,
                                stack + (key,), budget, missing)
    return links


def _absent_include(include, prefix: str, reason: str) -> LinkGeometry:
    """The entry standing for the links of an ``<include>`` whose model is not on disk: ``NAME::*`` (the
    include's ``<name>``, else the last part of its URI), no geometry, ``unread`` the reason."""
    uri = (include.findtext("uri") or "").strip()
    name = (include.findtext("name") or "").strip() or uri.rstrip("/").rsplit("/", 1)[-1] or "include"
    return LinkGeometry(name=f"{prefix}{name}::*", elements=(), declared=None,
                        unread=f"included model not read: {reason}")


def _read_sdf(root, source: str, base: str, packages: dict, geometry: str,
              missing: str = "refuse") -> tuple[str, tuple]:
    """Links of the SDFormat ``<model>`` (or of every model of a ``<world>``), nested and included models
    read too; their links are named ``model::link`` as SDFormat scopes them."""
    if root.tag == "gazebo":         # osrf gazebo_models' model-1_2.sdf files
        newest, _ = model_config_files(os.path.dirname(os.path.abspath(source)))
        there = (f"; the model.config beside it names {newest} as the newest version, which Gazebo loads"
                 if newest and os.path.abspath(newest) != os.path.abspath(source) else "")
        raise _fail(source, f"an SDFormat {root.get('version') or '1.2 or older'} file (root element <gazebo>, the "
                            f"format before SDFormat 1.3), which this tool does not read; expected <sdf>{there}")
    if root.tag != "sdf":
        raise _fail(source, f"not an SDFormat file: the root element is <{root.tag}>, expected <sdf>")
    models = root.findall("model")
    worlds = root.findall("world")
    if models and len(models) == 1 and not worlds:
        model = models[0]
        links = _sdf_links(model, "", base, packages, geometry, source, (os.path.realpath(source),), missing=missing)
        return model.get("name", ""), tuple(links)
    if len(worlds) == 1 and not models:
        links = _sdf_links(worlds[0], "", base, packages, geometry, source, (os.path.realpath(source),),
                           missing=missing)
        return worlds[0].get("name", ""), tuple(links)
    others = sorted({c.tag for c in root if isinstance(c.tag, str)} - {"model", "world"})
    if not models and not worlds and others:          # osrf gazebo_models sun/model.sdf: a <light> only
        raise _fail(source, f"no <model> or <world> to audit: the file holds only "
                            f"{', '.join(f'<{t}>' for t in others)} (a light or an actor has no links)")
    raise _fail(source, f"expected one <model> or one <world>, found {len(models)} models and {len(worlds)} worlds")


# -- entry point -------------------------------------------------------------------------------------------

_LINK_TAG = re.compile(rb"<(?:link|body)[\s/>]")


def _check_link_count(data: bytes, source: str) -> None:
    """Refuse more than :data:`MAX_ROBOT_LINKS` ``<link>`` or ``<body>`` start tags, counted in the bytes before
    the XML tree is built (the tree of a 30 MB description costs ~13x its size)."""
    count = len(_LINK_TAG.findall(data))
    if count > MAX_ROBOT_LINKS:
        raise _fail(source, f"holds {count:,} links (or MJCF bodies), more than the {MAX_ROBOT_LINKS:,} allowed; real "
                            "robots have a few hundred: refused before parsing")


def _detect(path: str) -> str:
    fmt = ROBOT_SUFFIXES.get(os.path.splitext(path)[1].lower())
    if fmt is None:
        raise _fail(path, f"unknown robot description type {os.path.splitext(path)[1] or '(no suffix)'!r}; "
                          f"expected one of {', '.join(sorted(ROBOT_SUFFIXES))}")
    return fmt


def _check_unique_names(links, source: str) -> None:
    """Refuse two links of one name, as urdfdom, SDFormat and MuJoCo's compiler do: every result, declared
    inertial and ``--write`` correction is matched to its link by name, so a repeated name would pair one link's
    numbers with the other's element."""
    seen: set[str] = set()
    for link in links:
        if link.name in seen:
            raise _fail(source, f"two links are named {link.name[:80]!r}; expected every link name to be unique")
        seen.add(link.name)


#: What :func:`read_robot` does with a mesh file (or SDFormat included model) that does not exist
#: (``missing_meshes``).
MISSING_MESHES = ("refuse", "per-link")


def read_robot(path, *, packages: dict | None = None, geometry: str = "collision",
               mappings: dict | None = None, run_xacro: bool = False, limits=None,
               missing_meshes: str = "refuse") -> RobotDescription:
    """Read a URDF, xacro, SDFormat or MJCF file into a :class:`RobotDescription`.

    Parameters
    ----------
    path : str or os.PathLike
        ``*.urdf``, ``*.xacro`` (``*.urdf.xacro``), ``*.sdf``, ``*.world`` or ``*.xml``/``*.mjcf`` (MuJoCo).
    packages : dict, optional
        Package name → directory, for ``package://NAME/...`` (and ``model://``, ``$(find NAME)``); looked up
        before ``ROS_PACKAGE_PATH``.
    geometry : {"collision", "visual", "all"} or str
        Which geometry elements to keep (MJCF: geoms that collide, ``contype``/``conaffinity`` not both 0 or in
        a ``<contact><pair>``, or the others).  MJCF only: ``"all"``, every geom in ``<compiler
        inertiagrouprange>`` (what MuJoCo's inertia from geometry counts); ``"group=LIST"`` (``"group=3"``,
        ``"group=0-2,5"``), the geoms of those groups; ``"class=LIST"`` (``"class=collision"``), the geoms whose
        default class (their ``class``, else the ``childclass`` in force) is named or nested in a named
        ``<default>`` (:data:`GEOMETRY_SELECTORS`).
    mappings : dict, optional
        xacro arguments (``name → value``, the ``name:=value`` of the xacro command line).
    run_xacro : bool
        Expanding a xacro file **runs code from the file** (xacro evaluates the Python expressions in
        ``${...}``; its restrictions can be escaped).  A xacro file is refused unless this is True; then it is
        expanded in a child process without the caller's environment and under CPU-time, memory and
        wall-clock limits (:mod:`inertia_tool.isolate`), which stop a file that hangs or explodes but not one
        that does harm within them.  Give a downloaded file only after reading it, or expand it yourself.
    limits : inertia_tool.isolate.Limits, optional
        Limits of the xacro expansion (default :data:`~inertia_tool.isolate.XACRO_LIMITS`; the
        ``INERTIA_TOOL_*_LIMIT`` environment variables override both).
    missing_meshes : {"refuse", "per-link"}
        A mesh file that does not exist refuses the whole description (default, as MuJoCo, urdfdom and
        SDFormat do), or only its link, whose result then says ``mesh file missing: PATH`` (the command line:
        every link that can be computed is).  With ``"per-link"`` an SDFormat ``<include>`` whose model is not
        on disk becomes one entry ``NAME::*`` without geometry, its ``unread`` the reason (its links are
        unknown), and so does an MJCF ``<attach>`` whose model file is not on disk (``PREFIX*``).  An unknown
        package, or a path naming something that is not a regular file, refuses either way.

    Returns
    -------
    RobotDescription

    Raises
    ------
    RobotDescriptionError
        Unreadable or malformed file, unsupported construct, or a mesh that cannot be resolved (the message
        names the link and the URI).
    UsageError
        Bad ``geometry``, ``mappings`` for a file that is not xacro, or a xacro file without ``run_xacro``.
    """
    selection = parse_geometry(geometry)
    if missing_meshes not in MISSING_MESHES:
        raise UsageError(f"Expected `missing_meshes` to be one of {', '.join(MISSING_MESHES)}, got {missing_meshes!r}")
    source = os.fsdecode(os.fspath(path))
    packages = dict(packages or {})
    data = _read_bytes(source)
    fmt = _detect(source)
    if mappings and fmt != "xacro":
        raise UsageError(f"xacro arguments given for {source}, which is not a xacro file")
    if fmt == "xacro":
        if not run_xacro:
            raise UsageError(f"{source}: expanding a xacro file runs code from the file; refused without "
                             "`run_xacro=True` (only for a file you trust, or expand it yourself with xacro and "
                             "give the URDF)")
        data = _expand_xacro(source, mappings or {}, packages, limits)
    _check_link_count(data, source)
    root = parse_xml(data, source).getroot()
    base = os.path.dirname(os.path.abspath(source))
    if fmt == "mjcf":    # *.xml: the root element says which format it is
        fmt = {"robot": "urdf", "sdf": "sdf"}.get(root.tag, "mjcf")
    if fmt == "mjcf":
        from .mjcf import read_mjcf
        name, links = read_mjcf(root, source, base, packages, geometry, missing_meshes=missing_meshes)
    elif selection[0] not in ("collision", "visual"):
        raise UsageError(f"Expected `geometry` collision or visual for {source} (a {fmt.upper()} link's visual "
                         f"and collision elements describe the same part), got {geometry!r} (MJCF only)")
    elif fmt in ("urdf", "xacro"):
        name, links = _read_urdf(root, source, base, packages, geometry, missing_meshes)
    else:
        name, links = _read_sdf(root, source, base, packages, geometry, missing_meshes)
    if not links:
        raise _fail(source, "no links found")
    _check_unique_names(links, source)
    return RobotDescription(name=name, source=source, format=fmt, geometry=geometry, links=links, document=data)
