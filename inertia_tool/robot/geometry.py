"""Mass properties of a link from its geometry: primitives in closed form, meshes through the engine.

Every element is first taken at unit density in its own frame (a mesh with its reference transform and
``scale`` applied to its vertices before the engine integrates it: :func:`mesh_properties`), then moved into the
link frame (``x ↦ R x + t``: centre ``R c + t``, tensor ``R I Rᵀ``), and the elements of a link are summed
with the parallel-axis theorem (Eq. 4.16, :func:`inertia_tool.mass.properties.combine`).  Overlapping elements
are counted twice (as a simulator's inertia-from-geometry does).

Closed forms (unit density, about the element's centre, element axes; M = V):

* box ``a × b × c``: ``I_xx = M(b² + c²)/12`` (cyclic) — :func:`inertia_tool.mass.shapes.box`;
* cylinder (R, h) along z: ``I_zz = MR²/2``, ``I_xx = M(R²/4 + h²/12)`` — :func:`inertia_tool.mass.shapes.cylinder`;
* sphere (r): ``2Mr²/5`` — :func:`inertia_tool.mass.shapes.sphere`;
* ellipsoid (a, b, c): ``V = 4πabc/3``, ``I_xx = M(b² + c²)/5`` (cyclic): the unit sphere's ``∫x² dV = V/5``
  stretched by ``a²``;
* polyline (SDFormat extruded polygons, even-odd holes): Green's theorem on each polygon's edges —
  :func:`inertia_tool.mass.extrusion.extruded_region`;
* capsule (R, cylinder length L) along z: the cylinder plus two hemispheres of mass ``m_h = 2πR³/3`` whose
  centres sit ``3R/8`` beyond the cylinder ends; a hemisphere has ``I_zz = 2 m_h R²/5`` and, about its own
  centre, ``I_xx = 2 m_h R²/5 − m_h (3R/8)² = 83 m_h R²/320``; the parallel-axis theorem moves it to the
  capsule centre, ``I_xx += m_h (L/2 + 3R/8)²``.

Mesh scale ``S = diag(s)`` is applied to the coordinates, not to the integrals, so that the engine's checks,
warnings and bounds speak of the body as placed, in metres; a negative factor (a mirrored mesh) reverses the
faces with it, so the surface keeps its outward winding.
"""

from __future__ import annotations

import copy
import hashlib
import math
import os
import re
import warnings
from typing import NamedTuple
from dataclasses import replace

import numpy as np

from ..errors import InertiaToolError, InvalidMeshError, MeshReadError, UsageError
from ..mass import shapes, shell_shapes
from ..mass.extrusion import extruded_region
from ..mass.extrusion import point_in_polygon as _inside_polygon
from ..mass.pipeline import mass_properties, resolve_density
from ..mass.properties import MassProperties, combine
from ..mesh.hole_assumptions import NOTHING_ASSUMED, UserAssumptions, user_named
from ..mesh.options import DEFAULT_MAX_FACES, MAX_SUPPORTED_FACES, LoadOptions
from ..values import frozen_value
from ..mesh.read import RawMesh
from .description import GeometryElement, LinkGeometry, RobotDescription, geometry_words
from ..rounding import round_up
from ..mesh.uncertainty import Uncertainty
from ..tolerances import EIGEN_ROUNDOFF_RTOL, ESTIMATE_MAX_MASS_RTOL

__all__ = ["element_mass_properties", "link_mass_properties", "link_inertials", "LinkInertial", "mesh_properties",
           "points_inside_element", "element_bounds", "LinkUncertainty", "METHODS", "MODEL_DENSITY", "fitted_element",
           "MeshCache", "fitted_mass_bound"]

#: What ``LinkInertial.method`` can say: ``"exact"`` (closed forms, and meshes integrated exactly, after
#: orienting, welding, sealing cracks without moving a point or dropping repeated faces), ``"united"``
#: (overlapping bodies of a mesh united by a boolean, then exact), ``"summed"`` (overlapping bodies added, the
#: shared volume counted twice, as asked), ``"unverified"`` (a mesh whose face-intersection check did not prove
#: it, see ``MeshReport.certificate``; or an MJCF mesh taken by MuJoCo's ``inertia="legacy"`` formula with the
#: model's densities), ``"estimate"`` (a repaired open mesh, or a primitive fitted to one: see ``uncertainty``).
#: For a mesh it is the kind of the engine's certificate, from the strongest to the weakest.
METHODS = ("exact", "united", "summed", "unverified", "estimate")

#: The value of ``density`` (and of ``robot --density``) that asks for the description's own densities.
MODEL_DENSITY = "model"


def mesh_properties(path: str | None, *, repair: bool = False, max_faces: int | None = None,
                    element: GeometryElement | None = None,
                    assume: UserAssumptions = NOTHING_ASSUMED) -> MassProperties:
    """Unit-density mass properties of the mesh file ``path`` (metres), placed as ``element`` places it.

    The one place where the robot tools call the mesh engine.  The element's reference transform (MJCF
    ``refpos``/``refquat``) and ``scale`` are applied to the vertices *before* the engine checks and integrates
    them, so that everything the engine says — volumes in its warnings, the bounds of an estimate (a centre of
    mass bound in m) — is about the body as the description places it, in SI.  A mirroring scale (negative
    determinant) reverses the faces with the coordinates, so the surface keeps its winding.

    Parameters
    ----------
    path : str or None
        The mesh file; None for an inline mesh (``element.vertices`` and ``element.faces``).
    repair : bool
        Let the engine repair an open or inconsistently wound mesh (``LoadOptions.repair``) instead of raising
        :class:`InvalidMeshError` (the caller then reports the link).
    max_faces : int, optional
        Refuse a file of more triangles (the reader's limit, ``LoadOptions.max_faces``); its default when None.
    element : GeometryElement, optional
        The mesh element: its reference transform and scale (none when not given).
    assume : UserAssumptions
        The user's assumptions about the holes a repair fills (``LoadOptions.assume``); only with ``repair``.

    Returns
    -------
    MassProperties
        Unit density: ``mass == volume``; in the element's mesh frame after its scale (before its pose).
    """
    raw = _raw_mesh(path, element, max_faces)
    if element is not None:
        raw = _placed(raw, element)
    return mass_properties(raw, density=1.0, repair=repair, assume=assume.names)


def _mesh_label(element: GeometryElement) -> str:
    """The mesh of ``element`` for messages: its file, or ``inline mesh of geom NAME``."""
    return element.mesh if element.mesh is not None else f"inline mesh of {element.name!r}"


def _raw_mesh(path: str | None, element: GeometryElement | None, max_faces: int | None = None) -> RawMesh:
    """The mesh file ``path`` read in metres, or the element's inline vertices and faces (MJCF
    ``<mesh vertex face>``: float64 text, so no storage rounding), before its placement."""
    if path is None:
        if element is None or element.vertices is None or element.faces is None:
            raise UsageError("Expected a mesh file or an element with inline vertices and faces, got neither")
        faces = np.asarray(element.faces)
        if max_faces is not None and len(faces) > max_faces:
            raise MeshReadError(f"{_mesh_label(element)}: {len(faces):,} triangles, more than `max_faces` "
                                f"({max_faces:,})")
        return RawMesh(vertices=np.array(element.vertices, dtype=np.float64), faces=faces.copy(),
                       source=_mesh_label(element), units="m", file_faces=len(faces))
    limit = DEFAULT_MAX_FACES if max_faces is None else max_faces
    submesh = (element.submesh, bool(element.submesh_center)) if element is not None and element.submesh else None
    key = _content_key(path, submesh)
    hit = _READ_CACHE.get(key) if key is not None else None
    if hit is not None and hit[0].file_faces <= limit:
        _READ_CACHE[key] = _READ_CACHE.pop(key)  # most recently used last
        _reissue(hit[1])
        return hit[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        raw = _read_mesh_file(path, element, limit)
    _reissue(caught)
    if key is not None:
        _remember(key, raw, tuple(caught))
    return raw


#: Meshes read in this process (``_raw_mesh``): the link integrals, the audit's bounds and its inside tests read
#: each mesh file of a robot, three reads of every COLLADA file of UR5e's visual geometry before.  Keyed by the
#: file's real path, size, a hash of its bytes and the sub-mesh (:func:`_content_key`); the arrays are made
#: read-only; the reader's warnings are kept and issued again on every use.  At most :data:`READ_CACHE_FACES`
#: faces are kept (least recently used dropped first).
_READ_CACHE: dict = {}
READ_CACHE_FACES = 4_000_000


#: Files larger than this are read every time, not hashed and kept.
READ_CACHE_BYTES = 64 << 20


def _content_key(path: str, submesh) -> tuple | None:
    """The cache key of a mesh file: its real path, size and a hash of its bytes (a file rewritten within the
    file system's timestamp resolution is still told apart), with the sub-mesh; None when it is not kept."""
    from ..mesh.regular import open_regular
    try:
        if os.path.getsize(path) > READ_CACHE_BYTES:
            return None
        with open_regular(path) as fh:
            data = fh.read(READ_CACHE_BYTES + 1)
    except (OSError, InertiaToolError):          # the reader says what is wrong with the path
        return None
    if len(data) > READ_CACHE_BYTES:
        return None
    return os.path.realpath(path), len(data), hashlib.blake2b(data, digest_size=16).digest(), submesh


def _remember(key, raw: RawMesh, caught: tuple) -> None:
    faces = len(raw.faces)
    if faces > READ_CACHE_FACES:
        return
    raw.vertices.flags.writeable = False
    raw.faces.flags.writeable = False
    _READ_CACHE[key] = (raw, caught)
    while sum(len(item[0].faces) for item in _READ_CACHE.values()) > READ_CACHE_FACES:
        _READ_CACHE.pop(next(iter(_READ_CACHE)))


def _read_mesh_file(path: str, element: GeometryElement | None, limit: int) -> RawMesh:
    from ..mesh.read import load_mesh
    # robot descriptions give mesh coordinates in metres (the element's `scale` is applied here), so the unit is
    # stated, not assumed: no size warning for a millimetre mesh scaled by 0.001 in the description
    if element is None or not element.submesh:
        return load_mesh(path, units="m", max_faces=limit)
    return _submesh(path, element, limit)


def _submesh(path: str, element: GeometryElement, max_faces: int) -> RawMesh:
    """The sub-mesh ``element.submesh`` of the COLLADA file ``path`` (SDFormat ``<submesh>``), re-centred on
    its bounding-box centre when ``element.submesh_center`` (gz-common ``SubMesh::Center``)."""
    import tempfile

    from ..mesh.collada_nodes import select_collada_node
    from ..mesh.read import load_mesh
    selected = select_collada_node(path, element.submesh)
    with tempfile.TemporaryDirectory(prefix="inertia_tool_submesh_") as folder:
        copy = os.path.join(folder, os.path.basename(path))
        with open(copy, "wb") as fh:
            fh.write(selected)
        label = f"{path} [submesh {element.submesh!r}]"
        try:
            raw = load_mesh(copy, units="m", max_faces=max_faces)
        except MeshReadError as error:       # name the file the user gave, not the temporary copy
            raise MeshReadError(str(error).replace(copy, label)) from None
    raw = replace(raw, source=label)
    if element.submesh_center:
        centre = 0.5 * (raw.vertices.min(axis=0) + raw.vertices.max(axis=0))
        raw = replace(raw, vertices=raw.vertices - centre)
    return raw


def _placed(raw: RawMesh, element: GeometryElement) -> RawMesh:
    """``raw`` with the element's reference transform, then its ``scale``, applied to the vertices (a mirroring
    scale reverses the faces, so the surface keeps its winding); the one placement of a mesh file in its
    element, for the integrals and for the audit's bounds and inside tests."""
    scale = np.asarray(element.scale, dtype=np.float64)
    if not np.all(np.isfinite(scale)) or np.any(scale == 0):
        raise UsageError(f"Expected finite non-zero mesh scale factors, got {scale.tolist()}")
    moved = not (np.array_equal(element.reference_rotation, np.eye(3)) and not np.any(element.reference_translation))
    if not moved and np.all(scale == 1.0):
        return raw
    v = raw.vertices
    reach = math.sqrt(3.0) * max(float(np.max(v)), -float(np.min(v))) if len(v) else 0.0
    if moved:
        v = v @ element.reference_rotation.T + element.reference_translation
        reach += float(np.max(np.abs(element.reference_translation)))
    f = raw.faces if float(np.prod(np.sign(scale))) > 0 else raw.faces[:, ::-1]
    largest = float(np.max(np.abs(scale)))
    exact = not moved and all(math.frexp(float(s))[0] in (0.5, -0.5) for s in scale)
    # R7 counts how far these products moved a coordinate (review 12's R6): a rotated coordinate is a sum of three
    # products (γ₃·Σ|vⱼ||Rᵢⱼ| ≤ 3.01·u·√3·max|v|), then the translation and the scale add one rounding each:
    # below 8·u·(√3·max|v| + max|t|)·max|s| in all, as the reader's own conversion is carried (scaled) too
    moved_by = raw.scale_rounding * largest + (0.0 if exact else 8.0 * 2.0 ** -53 * reach * largest)
    return replace(raw, vertices=v * scale, faces=np.ascontiguousarray(f),
                   storage_rounding=raw.storage_rounding * largest, scale_rounding=moved_by)


def _capsule(radius: float, length: float) -> MassProperties:
    r, half = radius, 0.5 * length
    cyl_mass = math.pi * r * r * length
    hemi = 2.0 * math.pi * r ** 3 / 3.0
    offset = half + 3.0 * r / 8.0
    axial = 0.5 * cyl_mass * r * r + 2.0 * (0.4 * hemi * r * r)
    transverse = (cyl_mass * (r * r / 4.0 + length * length / 12.0)
                  + 2.0 * (83.0 / 320.0 * hemi * r * r + hemi * offset * offset))
    volume = cyl_mass + 2.0 * hemi
    return MassProperties(mass=volume, volume=volume, center_of_mass=np.zeros(3),
                          inertia=np.diag([transverse, transverse, axial]), density=1.0,
                          surface_area=2.0 * math.pi * r * length + 4.0 * math.pi * r * r)


def _ellipsoid(a: float, b: float, c: float) -> MassProperties:
    volume = 4.0 * math.pi * a * b * c / 3.0
    moments = (volume * (b * b + c * c) / 5.0, volume * (a * a + c * c) / 5.0, volume * (a * a + b * b) / 5.0)
    return MassProperties(mass=volume, volume=volume, center_of_mass=np.zeros(3), inertia=np.diag(moments),
                          density=1.0)


def _mesh_key(element: GeometryElement) -> tuple:
    """Cache key of a mesh element's unit-density body: the file and how the element scales and moves it."""
    where = element.mesh
    if where is None and element.vertices is not None and element.faces is not None:
        digest = hashlib.sha256(np.ascontiguousarray(element.vertices, dtype=np.float64).tobytes())
        digest.update(np.ascontiguousarray(element.faces, dtype=np.int64).tobytes())
        where = f"inline:{digest.hexdigest()}"
    return (where, tuple(np.asarray(element.scale, dtype=np.float64).tolist()),
            element.reference_rotation.tobytes(), np.asarray(element.reference_translation).tobytes(),
            element.submesh, element.submesh_center)


def element_shell_properties(element: GeometryElement) -> MassProperties:
    """Unit-areal-density properties of the element's surface (mass = area in m²), in the **link frame**.

    Closed forms for spheres, boxes, cylinders and capsules (:mod:`inertia_tool.mass.shell_shapes`); the
    triangles of a mesh (any winding, open or closed) through :func:`inertia_tool.mass.surface.surface_moments`.
    An ellipsoid's surface has no closed form (MuJoCo approximates it): :class:`UsageError`.
    """
    element = fitted_element(element)
    kind, size = element.kind, element.size
    if kind == "sphere":
        local = shell_shapes.sphere_shell(size[0])
    elif kind == "box":
        local = shell_shapes.box_shell(size)
    elif kind == "cylinder":
        local = shell_shapes.cylinder_shell(*size)
    elif kind == "capsule":
        local = shell_shapes.capsule_shell(*size)
    elif kind == "mesh":
        from ..mass.surface import surface_moments
        v, f = _mesh_vertices_faces(element)
        moments = surface_moments(v, f)
        c = moments.second_moment
        local = MassProperties(mass=moments.area, volume=0.0, center_of_mass=moments.centroid,
                               inertia=np.trace(c) * np.eye(3) - c, surface_area=moments.area,
                               density=float("nan"), name=element.name)
    else:
        raise UsageError(f"Expected a shell of a sphere, box, cylinder, capsule or mesh, got {kind!r} "
                         f"({element.name}): an ellipsoid's surface has no closed form")
    return local.transformed(rotation=element.rotation, translation=element.translation)


def _inertia_box_sums(moments: np.ndarray) -> np.ndarray:
    """(3,) kg·m² per unit density: ``s_k = I_i + I_j − I_k`` of principal moments sorted from the largest."""
    m = np.asarray(moments, dtype=np.float64)
    return np.array([m[1] + m[2] - m[0], m[0] + m[2] - m[1], m[0] + m[1] - m[2]])


def _inertia_box_half_sizes(sums: np.ndarray, volume: float) -> np.ndarray:
    """(3,) m: the half-sizes ``h_k = √(3 s_k / (2 V))`` of the box with the same volume and principal moments
    (unit density; ``sums`` from :func:`_inertia_box_sums`): MuJoCo's inertia-box fit."""
    return np.sqrt(np.maximum(0.0, 3.0 * np.asarray(sums, dtype=np.float64) / (2.0 * volume)))


def _inertia_box_size(kind: str, half: np.ndarray) -> tuple:
    """The ``size`` of the primitive of ``kind`` MuJoCo fits to inertia-box half-sizes ``half`` (already times
    ``fitscale``): a box ``2h``, an ellipsoid ``h``, a sphere the mean of the three, a cylinder radius
    ``(h_x + h_y)/2`` and length ``2 h_z``, a capsule the same radius and length ``2 max(0, h_z − r/2)``."""
    if kind == "sphere":
        return (float(np.mean(half)),)
    if kind in ("cylinder", "capsule"):
        radius = 0.5 * float(half[0] + half[1])
        length = float(half[2]) if kind == "cylinder" else max(0.0, float(half[2]) - 0.5 * radius)
        return (radius, 2.0 * length)
    return tuple(2.0 * half) if kind == "box" else tuple(half)


def fitted_element(element: GeometryElement, *, cache: dict | None = None, repair: bool = False,
                   budget: list | None = None, assume: UserAssumptions = NOTHING_ASSUMED,
                   mesh_properties: MassProperties | None = None) -> GeometryElement:
    """The primitive MuJoCo fits to a mesh (``<geom type="capsule" mesh="...">`` without a size).

    MuJoCo's default fit (``<compiler fitaabb="false">``): the mesh's equivalent inertia box — the box of the
    same volume and principal moments, half-sizes ``h_k = √(3 (I_i + I_j − I_k) / (2 V))`` at unit density
    (from ``I_k = V (h_i² + h_j²) / 3``) — placed at the mesh's centre of volume along its principal axes,
    ordered so that the x axis has the largest moment (the smallest ``h``) and z the smallest (the largest
    ``h``).  Then, times ``fitscale``: a box or an ellipsoid takes ``(h_x, h_y, h_z)``, a sphere the mean of
    the three, a cylinder radius ``(h_x + h_y)/2`` and half-length ``h_z``, a capsule the same radius ``r`` and
    half-length ``max(0, h_z − r/2)`` (checked against MuJoCo 4.0).

    With ``<compiler fitaabb="true">`` (``element.fit_aabb``): the bounding box of the mesh's vertices in the
    same principal axes, half-sizes ``h`` and centre the box's (not the centre of volume); then, times
    ``fitscale``, a box or an ellipsoid takes ``h``, a sphere ``max h``, a cylinder radius ``max(h_x, h_y)``
    and half-length ``h_z``, a capsule the same radius ``r`` and half-length ``max(0, h_z − r)`` (checked
    against MuJoCo 4.0: Menagerie's RealSense D435i).

    MuJoCo fits to the moments and axes of the mesh's own inertia mode, and so does this fit (issue 23, checked
    against MuJoCo 4.0's body inertias): ``inertia="convex"`` the convex hull, ``"legacy"`` MuJoCo's legacy
    formula (:mod:`inertia_tool.robot.mesh_inertia`), otherwise (``exact``, no attribute) the solid.  The
    fitted size is the model's geom whatever density the tool is run with.  Elements that are not fitted are
    returned as they are.  ``mesh_properties``: the mesh's unit-density body to fit instead of the one computed
    here (the corpus benchmark fits to the triangles as MuJoCo integrates them, to tell its values apart).
    """
    if element.fit_scale is None:
        return element
    mesh = GeometryElement("mesh", np.eye(3), np.zeros(3), mesh=element.mesh, uri=element.uri, scale=element.scale,
                           name=element.name, vertices=element.vertices, faces=element.faces,
                           reference_rotation=element.reference_rotation,
                           reference_translation=element.reference_translation,
                           mesh_inertia=element.mesh_inertia)
    memo = (_fit_memo_key(mesh, repair, assume) if cache is None and budget is None and mesh_properties is None
            else None)
    props = _FIT_BODIES.get(memo) if memo is not None else mesh_properties
    if props is not None and memo is not None:
        _FIT_BODIES[memo] = _FIT_BODIES.pop(memo)          # most recently used last
        if isinstance(props, _FitRefusal):
            _reissue(props.caught)
            raise props.error.with_traceback(None)
    elif props is not None:                               # the caller's body (mesh_properties)
        pass
    elif element.mesh_inertia in ("convex", "legacy"):
        props = _mesh_inertia_part(mesh, cache={} if cache is None else cache, budget=budget)[1]
    elif memo is None:
        props = element_mass_properties(mesh, cache=cache, repair=repair, budget=budget, assume=assume)
    else:
        with warnings.catch_warnings(record=True) as recorded:
            warnings.simplefilter("always")
            try:
                props = element_mass_properties(mesh, cache=cache, repair=repair, budget=budget, assume=assume)
            except InertiaToolError as exc:
                props = _FitRefusal(exc, tuple(recorded))
        _reissue(recorded)
    if memo is not None and memo not in _FIT_BODIES:
        _FIT_BODIES[memo] = props
        while len(_FIT_BODIES) > FIT_BODIES_KEPT:
            _FIT_BODIES.pop(next(iter(_FIT_BODIES)))
    if isinstance(props, _FitRefusal):
        raise props.error.with_traceback(None)
    moments, axes = np.linalg.eigh(0.5 * (props.inertia + props.inertia.T))
    axes = axes[:, ::-1]                                 # x: the largest moment, z: the smallest
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    half = _inertia_box_half_sizes(_inertia_box_sums(moments[::-1]), props.volume)
    kind = element.kind
    centre = props.center_of_mass
    if element.fit_aabb:
        vertices, faces = _mesh_vertices_faces(element)
        used = vertices[np.unique(faces)] @ axes       # the corners in the principal axes
        low, high = used.min(axis=0), used.max(axis=0)
        half = 0.5 * (high - low) * element.fit_scale
        centre = axes @ (0.5 * (high + low))
        if kind == "sphere":
            size_aabb: tuple = (float(np.max(half)),)
        elif kind in ("cylinder", "capsule"):
            radius = float(max(half[0], half[1]))
            size_aabb = (radius, 2.0 * (half[2] if kind == "cylinder" else max(0.0, half[2] - radius)))
        else:
            size_aabb = tuple(2.0 * half) if kind == "box" else tuple(half)
        return GeometryElement(kind, element.rotation @ axes, element.rotation @ centre + element.translation,
                               size=size_aabb, name=element.name, density=element.density, mass=element.mass,
                               shell=element.shell)
    size = _inertia_box_size(kind, half * element.fit_scale)
    return GeometryElement(kind, element.rotation @ axes, element.rotation @ props.center_of_mass + element.translation,
                           size=size, name=element.name, density=element.density, mass=element.mass,
                           shell=element.shell)


#: Unit-density bodies of the meshes that primitives are fitted to, for the calls of :func:`fitted_element`
#: without a robot cache (the audit's bounding boxes and inside tests fit every fitted geom again: before this
#: memo, each such call integrated the mesh anew, 22 of the 57 s of CPU of a Menagerie corpus audit).  Keyed by
#: :func:`_fit_memo_key` (the file's content, how the element places it, its inertia mode and ``repair``), at
#: most :data:`FIT_BODIES_KEPT` entries (least recently used dropped first).  A refusal is kept too, as a
#: :class:`_FitRefusal` (issues 23/25, corpus15: the audit fits without repair, so a mesh that only a repair
#: integrates was refused again on every call, Piper's ``link3.stl`` 2.7 s of CPU each time); it is raised
#: again with the engine's warnings of the first attempt.
_FIT_BODIES: dict = {}
FIT_BODIES_KEPT = 256


class _FitRefusal(NamedTuple):
    """A :data:`_FIT_BODIES` entry for a mesh the engine refused: the error and the warnings raised before it."""

    error: InertiaToolError
    caught: tuple


def _repair_key(repair: bool, assume: UserAssumptions) -> tuple[bool, tuple[str, ...]]:
    """What a cached body depends on besides the file and its placement: ``repair`` and the user's assumptions
    ``assume`` (the call's parameter), so that a body prepared under ``--assume flat-islands`` is never handed to
    a call without it, or the other way round."""
    return bool(repair), assume.names


def _fit_memo_key(mesh: GeometryElement, repair: bool, assume: UserAssumptions) -> tuple | None:
    """The :data:`_FIT_BODIES` key of a fitted geom's mesh element, or None when its file is not kept (too
    large or unreadable: :func:`_content_key`)."""
    content = None
    if mesh.mesh is not None:
        submesh = (mesh.submesh, bool(mesh.submesh_center)) if mesh.submesh else None
        content = _content_key(mesh.mesh, submesh)
        if content is None:
            return None
    return (content, _mesh_key(mesh), mesh.mesh_inertia, _repair_key(repair, assume))


class MeshCache:
    """Unit-density mesh bodies kept across the robots of one run (a corpus: Menagerie's scene variants, the
    left and right links of a robot, share mesh files), failures included.

    Each entry is keyed by the file, how the element scales and moves it, and ``repair``; it holds the result
    (or the exception that refused the mesh), the engine's warnings about it (issued again on every robot that
    uses it, so that each link still names what was done to its meshes) and the file's triangle count (taken
    off each robot's ``max_faces`` budget as if it had been read).  Entries are never changed once stored.

    Open mesh pieces joined into one surface and refused together (:func:`_joined_pieces`) are kept by their
    content too (issue 25: Stretch and Stretch 3 ship byte-identical ``link_arm_l0_{0,1,2}.obj``, ~17 s of CPU
    each to refuse).

    A result or a refusal is also kept by the file's *content* (:func:`_content_key` without the path: its
    size and a hash of its bytes, with the file's suffix, the placement and ``repair``), so that a byte-identical
    copy in another folder (TIAGo and TIAGo dual ship the same ``gripper_link.stl``) is integrated, or refused,
    once; the copy gets the result or the refusal with every warning and message addressed to its own file
    (:meth:`get_copy`; issue 25, corpus19: Stretch and Stretch 3 refused ``link_lift_3.obj`` and 30 other
    copies twice: 8.4 s of CPU at load 18).  Open pieces joined into one solid are kept by their content the same way
    (:meth:`joined_copy`).
    """

    def __init__(self) -> None:
        self._entries: dict = {}
        self._by_content: dict = {}
        self._refused_joins: set = set()
        self._joins: dict = {}

    def join_refused(self, content) -> bool:
        """Whether open pieces with this content (:func:`_join_content`) were joined before and refused."""
        return content is not None and content in self._refused_joins

    def refuse_join(self, content) -> None:
        """Keep that the pieces with this content do not close together, even repaired (never a refusal by a
        robot's ``max_faces`` budget: that one is the robot's, not the files')."""
        if content is not None:
            self._refused_joins.add(content)

    def __len__(self) -> int:
        return len(self._entries)

    def get(self, key):
        """``(result or exception, warnings, faces)`` for ``key``, or None."""
        return self._entries.get(key)

    def put(self, key, outcome, caught: tuple, faces: int, content=None) -> None:
        self._entries.setdefault(key, (outcome, caught, faces))
        if content is not None:
            self._by_content.setdefault(content, (key[0][0], outcome, caught, faces))

    def get_copy(self, content, path: str):
        """``(result or exception, warnings, faces)`` of a file with the same content integrated (or refused)
        under another path, the warnings' and the refusal's text and the result's mesh report re-addressed to
        ``path`` (:func:`_readdressed`); None when there is none, or when a text cannot be re-addressed."""
        found = self._by_content.get(content) if content is not None else None
        if found is None:
            return None
        other, outcome, caught, faces = found
        if other == path:
            return outcome, caught, faces
        moved = _moved_warnings(caught, [(other, path)])
        if moved is None:
            return None
        if isinstance(outcome, BaseException):
            outcome = _moved_error(outcome, [(other, path)])
            return None if outcome is None else (outcome, moved, faces)
        report = outcome.mesh
        if report is not None and getattr(report, "source", None) == other:
            outcome = replace(outcome, mesh=replace(report, source=path))
        return outcome, moved, faces

    def keep_join(self, content, labels: list, found: tuple, caught: tuple) -> None:
        """Keep a join of open pieces that closed (``found``: :func:`_joined_pieces`'s body before its placement,
        method and uncertainty; ``caught``: the engine's warnings), by the pieces' content (:func:`_join_content`)
        with the pieces' ``labels`` (their files, in order)."""
        if content is not None:
            self._joins.setdefault(content, (list(labels), found, caught))

    def joined_copy(self, content, labels: list):
        """``(found, warnings)`` of pieces with this content joined before under other files, the warnings' text
        and the body's mesh report re-addressed to ``labels``; None when there is none, or when a text cannot be
        re-addressed."""
        kept = self._joins.get(content) if content is not None else None
        if kept is None:
            return None
        others, (local, method, uncertainty), caught = kept
        pairs = [(a, b) for a, b in zip(others, labels) if a != b]
        if not pairs:
            return (local, method, uncertainty), caught
        moved = _moved_warnings(caught, pairs)
        if moved is None:
            return None
        report = local.mesh
        if report is not None and getattr(report, "source", None) is not None:
            source = _readdressed(report.source, pairs)
            if source is None:
                return None
            local = replace(local, mesh=replace(report, source=source))
        return (local, method, uncertainty), moved


def _readdressed(text: str, pairs: list) -> str | None:
    """``text`` with every file ``a`` of ``pairs`` ``[(a, b), ...]`` replaced by ``b``; None when the text may
    name a file otherwise than by its whole path (its base name appears beyond the whole path's occurrences, and
    the two base names differ), so that a replacement could leave the old file named."""
    for a, b in pairs:
        name = os.path.basename(a)
        if name != os.path.basename(b) and text.count(name) != text.count(a):
            return None
    new = dict(pairs)
    # one pass, the longest file first: a new name is never taken for an old one
    pattern = "|".join(re.escape(a) for a in sorted(new, key=len, reverse=True))
    return re.sub(pattern, lambda match: new[match.group(0)], text)


def _moved_warnings(caught, pairs: list) -> tuple | None:
    """The warnings ``caught`` with their text re-addressed (:func:`_readdressed`); None when one cannot be."""
    moved = []
    for item in caught:
        text = _readdressed(str(item.message), pairs)
        if text is None:
            return None
        try:
            message = item.category(text)
        except TypeError:                      # a warning class that takes more than its text
            return None
        moved.append(warnings.WarningMessage(message, item.category, item.filename, item.lineno))
    return tuple(moved)


def _moved_error(error: BaseException, pairs: list) -> BaseException | None:
    """A copy of the refusal ``error`` (its class and attributes, e.g. ``InvalidMeshError.details``) whose
    message is re-addressed (:func:`_readdressed`); None when it has more than a message or cannot be."""
    if len(error.args) != 1 or not isinstance(error.args[0], str):
        return None
    text = _readdressed(error.args[0], pairs)
    if text is None:
        return None
    try:
        moved = copy.copy(error)
    except Exception:                          # an exception class that cannot be rebuilt from its arguments
        return None
    moved.args = (text,)
    return moved


def _reissue(caught) -> None:
    for item in caught:
        warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)


def _cached_mesh(element: GeometryElement, *, cache: dict | None, repair: bool, budget: list | None,
                 assume: UserAssumptions = NOTHING_ASSUMED):
    """The unit-density body of a mesh element, through the robot's ``cache`` (mesh key → result or the
    exception that refused it, so that a mesh shared by links is read, and refused, once) and the run's shared
    :class:`MeshCache` (``cache["shared"]``, when given)."""
    key = _mesh_key(element)
    if cache is not None and key in cache:
        found = cache[key]
        if isinstance(found, BaseException):
            raise found.with_traceback(None)
        return found
    shared = cache.get(_SHARED) if cache is not None else None
    entry = shared.get((key, _repair_key(repair, assume))) if shared is not None else None
    content = None
    if shared is not None and entry is None and element.mesh is not None:
        found = _content_key(element.mesh, (element.submesh, bool(element.submesh_center)) if element.submesh
                             else None)
        if found is not None:
            content = (found[1:], os.path.splitext(element.mesh)[1].lower(), key[1:], _repair_key(repair, assume))
            entry = shared.get_copy(content, element.mesh)
    if entry is not None:
        outcome, caught, faces = entry
        if budget is not None and faces > budget[0] and not isinstance(outcome, BaseException):
            outcome = MeshReadError(f"{_mesh_label(element)}: {faces:,} triangles, more than the {budget[0]:,} that "
                                    f"`max_faces` leaves (the limit counts all the robot's meshes together, "
                                    f"{budget[1]:,})")
        elif budget is not None:
            budget[0] -= faces
        _reissue(caught)
    else:
        if budget is not None and budget[0] < 1:
            raise MeshReadError(f"{_mesh_label(element)}: not read: the meshes read before it hold all the triangles "
                                "`max_faces` allows (the limit is on all the meshes of the robot together)")
        faces = 0
        with warnings.catch_warnings(record=True) as recorded:
            warnings.simplefilter("always")
            try:
                outcome = mesh_properties(element.mesh, repair=repair, element=element,
                                          max_faces=None if budget is None else budget[0], assume=assume)
            except MeshReadError as exc:
                if budget is None or budget[0] == budget[1] or "`max_faces`" not in str(exc):
                    outcome = exc
                else:
                    outcome = MeshReadError(f"{exc}: the limit counts all the robot's meshes together "
                                            f"({budget[1]:,}), and the meshes read before this one left "
                                            f"{budget[0]:,}")
            except InertiaToolError as exc:
                outcome = exc
        caught = tuple(recorded)
        _reissue(caught)
        if not isinstance(outcome, BaseException) and outcome.mesh is not None:
            faces = int(outcome.mesh.file_faces)
            if budget is not None:
                budget[0] -= faces
        if shared is not None and not (isinstance(outcome, MeshReadError) and "`max_faces`" in str(outcome)):
            # a budget refusal is this robot's, not the file's
            shared.put((key, _repair_key(repair, assume)), outcome, caught, faces,
                       content=content)
    if cache is not None:
        cache[key] = outcome
    if isinstance(outcome, BaseException):
        raise outcome.with_traceback(None)
    return outcome


#: Key of the run's shared :class:`MeshCache` inside a robot's cache dict.
_SHARED = "shared"


def element_mass_properties(element: GeometryElement, *, cache: dict | None = None,
                            repair: bool = False, budget: list | None = None,
                            assume: UserAssumptions = NOTHING_ASSUMED) -> MassProperties:
    """Unit-density mass properties of one geometry element, in the **link frame**.

    Parameters
    ----------
    element : GeometryElement
    cache : dict, optional
        Mesh path → unit-density properties, shared between the elements of one robot.
    repair : bool
        Passed to :func:`mesh_properties`.
    budget : list of two int, optional
        ``[left, total]``: triangles the meshes still to be read may hold together, of ``total``
        (``robot --max-faces``); each new mesh file is read with ``left`` as its limit and its triangles are
        taken off.
    assume : UserAssumptions
        The user's assumptions about the holes a repair fills, passed to :func:`mesh_properties`.

    Returns
    -------
    MassProperties
        ``mass == volume`` (m³), centre of mass in m and tensor about it in kg·m² per kg/m³, link axes.

    Raises
    ------
    InvalidMeshError, MeshReadError
        From the mesh engine, for a mesh element.
    """
    if element.fit_scale is not None:
        element = fitted_element(element, cache=cache, repair=repair, budget=budget, assume=assume)
    kind, size = element.kind, element.size
    if kind == "box":
        local = shapes.box(*size).exact
    elif kind == "cylinder":
        local = shapes.cylinder(size[0], size[1], segments=3).exact
    elif kind == "sphere":
        local = shapes.sphere(size[0], segments=3, rings=2).exact
    elif kind == "capsule":
        local = _capsule(*size)
    elif kind == "ellipsoid":
        local = _ellipsoid(*size)
    elif kind == "polyline":
        local = extruded_region(element.polygons, size[0])
    elif kind == "mesh":
        local = _cached_mesh(element, cache=cache, repair=repair, budget=budget, assume=assume)
    else:
        raise UsageError("Expected a geometry kind among box, cylinder, sphere, capsule, ellipsoid, polyline, mesh, "
                         f"got {kind!r}")
    return local.transformed(rotation=element.rotation, translation=element.translation)


#: What a link's warnings say of a mesh taken by its MJCF ``<mesh inertia>`` mode (``--density model``).
_MESH_INERTIA_NOTES = {
    "convex": "mesh {} has inertia=\"convex\" in the model: its convex hull is integrated, as MuJoCo does",
    "legacy": ("mesh {} has inertia=\"legacy\" in the model: MuJoCo's legacy formula (absolute volumes of the "
               "tetrahedra from the surface's centre) is used, as MuJoCo does; for a non-convex mesh it is not "
               "the solid's integral, hence 'unverified'"),
}


def fitted_mass_bound(element: GeometryElement, mesh: MassProperties, bounds) -> float | None:
    """Relative bound on the mass of the primitive MuJoCo fits to a mesh (:func:`fitted_element`, its default
    inertia-box fit) whose integrals are an estimate, from the estimate's bounds; None where none follows (an
    unbounded tensor or volume).

    ``mesh``: the mesh's unit-density properties (volume ``V̂``, tensor ``Î`` about the centre of mass);
    ``bounds``: its :class:`~inertia_tool.mesh.uncertainty.Uncertainty` — the true volume within ``ε_m V̂``, the
    true tensor within ``ε_I ‖Î‖_F`` (Frobenius).  By the Hoffman–Wielandt inequality the sorted principal moments
    move by ``d`` with ``‖d‖₂ ≤ δ = ε_I ‖Î‖_F``, so each ``s_k = I_i + I_j − I_k`` of the fit's half-sizes
    ``h_k = √(3 s_k / (2 V))`` by ``|d_i + d_j − d_k| ≤ √3 δ`` (Cauchy–Schwarz; reached by an error along the
    principal axes); the moments as float64 computes them are a further ``EIGEN_ROUNDOFF_RTOL ‖Î‖_F`` off the exact
    ones of ``Î``, added to ``δ`` (a flat part's smallest ``s_k`` is below that round-off).  Every fitted
    primitive's volume (box
    and ellipsoid ``∝ h_x h_y h_z``, sphere ``∝ mean(h)³``, cylinder ``π r² 2h_z``, capsule
    ``2π r² max(0, h_z − r/2) + 4/3 π r³`` with ``r = (h_x + h_y)/2``, whose derivative in ``r`` is
    ``4π r h_z + π r² > 0`` while the cylinder part is there) grows with each ``h_k``, so the true fit's volume
    lies between the volumes at ``h_k`` from ``(s_k − √3 δ, V̂(1 + ε_m))`` and from ``(s_k + √3 δ, V̂(1 − ε_m))``.  The
    centre of the fit is the mesh's centre of mass (its bound carries over); no bound on the fit's tensor is
    derived (its axes are the mesh's principal axes, which a tensor bound does not hold when moments are close).
    """
    tensor = 0.5 * (np.asarray(mesh.inertia, dtype=np.float64) + np.asarray(mesh.inertia, dtype=np.float64).T)
    volume = float(mesh.volume)
    if not (np.isfinite(bounds.inertia) and np.isfinite(bounds.mass) and volume > 0 and bounds.mass < 1):
        return None
    moments = np.linalg.eigvalsh(tensor)[::-1]
    # the moments as computed are within EIGEN_ROUNDOFF_RTOL ‖Î‖_F of the exact ones of Î (review 11, D3)
    delta = (float(bounds.inertia) + EIGEN_ROUNDOFF_RTOL) * float(np.linalg.norm(tensor))
    s = _inertia_box_sums(moments)

    def fitted_volume(sums: np.ndarray, vol: float) -> float:
        # s_k, V -> h -> the fitted primitive (as fitted_element sizes it) -> its closed-form volume
        size = _inertia_box_size(element.kind, _inertia_box_half_sizes(sums, vol) * element.fit_scale)
        if min(size[:1] if element.kind == "capsule" else size) <= 0:       # (a capsule of length 0: a ball)
            return 0.0
        return float(element_mass_properties(GeometryElement(element.kind, np.eye(3), np.zeros(3),
                                                             size=size)).volume)

    middle = fitted_volume(s, volume)
    if not middle > 0:
        return None
    low = fitted_volume(s - np.sqrt(3.0) * delta, volume * (1.0 + bounds.mass))
    high = fitted_volume(s + np.sqrt(3.0) * delta, volume * (1.0 - bounds.mass))
    return round_up(max(middle - low, high - middle) / middle * (1.0 + 1e-9) + 1e-12)


def _fitted_estimate_note(element: GeometryElement, bounds, fitted: float | None) -> str:
    """What a link's warnings say of a primitive fitted to a mesh that only a repair could integrate: the mesh's
    warning calls the mesh an estimate, and the link's method says what follows for the fit, the same in the text
    table and in ``--json`` (robots10: arx_l5 ``link2``): an estimate with the bound of
    :func:`fitted_mass_bound`, or ``unverified`` with no uncertainty where that bound is past the ±50 % at which an
    estimate is given, or none follows."""
    head = (f"{element.kind} {element.name!r} is fitted to {os.path.basename(_mesh_label(element))}, whose integrals "
            f"are an estimate after repair (volume ±{round_up(100 * bounds.mass, 3):.3g} %, inertia "
            f"±{round_up(100 * bounds.inertia, 3):.3g} %): ")
    if fitted is not None and fitted <= ESTIMATE_MAX_MASS_RTOL:
        return head + (f"the fitted {element.kind}'s mass follows within ±{round_up(100 * fitted, 3):.3g} % and its "
                       "centre within the mesh's bound (no bound on its tensor is derived)")
    why = ("no bound on it follows from theirs" if fitted is None else
           f"the bound that follows for it, ±{round_up(100 * fitted, 3):.3g} % mass, is past the ±"
           f"{100 * ESTIMATE_MAX_MASS_RTOL:g} % at which an estimate is given")
    return head + (f"the fitted {element.kind} is exact for those integrals, but {why}, hence 'unverified' and no "
                   "uncertainty")


def _mesh_inertia_part(element: GeometryElement, *, cache: dict, budget: list | None) -> tuple:
    """``(element, unit properties in the link frame, method, None)`` of a mesh taken by its MJCF inertia
    mode (:mod:`inertia_tool.robot.mesh_inertia`): ``convex`` is the exact integral of the hull, ``legacy``
    MuJoCo's formula, labelled ``unverified`` (no check makes it the solid's)."""
    from .mesh_inertia import convex_hull_properties, legacy_properties
    key = ("mesh inertia", element.mesh_inertia) + _mesh_key(element)
    found = cache.get(key)
    if found is None:
        raw = _placed(_raw_mesh(element.mesh, element, None if budget is None else budget[0]), element)
        if budget is not None:
            budget[0] -= int(raw.file_faces)
        label = _mesh_label(element)
        found = (convex_hull_properties(raw.vertices, source=label) if element.mesh_inertia == "convex"
                 else legacy_properties(raw.vertices, raw.faces, source=label))
        cache[key] = found
    method = "exact" if element.mesh_inertia == "convex" else "unverified"
    return element, found.transformed(rotation=element.rotation, translation=element.translation), method, None


def _piece_group(element: GeometryElement, model: bool) -> tuple:
    """Elements whose open meshes may be joined: the same placement and scale, and the same density with no
    mass of their own (``model``; otherwise the robot's one density weighs them all)."""
    weight = (element.mass is None, element.density) if model else ()
    return (element.rotation.tobytes(), np.asarray(element.translation, dtype=np.float64).tobytes(),
            _mesh_key(element)[1:], weight)


def _boundary_edges(vertices: np.ndarray, faces: np.ndarray) -> set:
    """The edges of ``faces`` used once (a piece's open rim), each as the bytes of its two end points in a fixed
    order, so that pieces with their own vertex numbering can be compared."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges.sort(axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rims = unique[counts == 1]
    ends = np.ascontiguousarray(vertices[rims], dtype=np.float64)             # (k, 2, 3)
    swap = [tuple(a) > tuple(b) for a, b in zip(ends[:, 0].tolist(), ends[:, 1].tolist())]
    ends[swap] = ends[swap][:, ::-1]
    return {row.tobytes() for row in ends}


def _join_content(pieces: list, repair: bool, assume: UserAssumptions) -> tuple | None:
    """What a join of ``pieces`` depends on: each file's size and hash (not its path), suffix, sub-mesh and
    placement (:func:`_mesh_key` without the path), in order, ``repair`` and ``assume``; None when a file is not
    hashed."""
    out = []
    for element in pieces:
        if element.mesh is None:
            return None
        found = _content_key(element.mesh, (element.submesh, bool(element.submesh_center)) if element.submesh
                             else None)
        if found is None:
            return None
        out.append((found[1:], os.path.splitext(element.mesh)[1].lower(), _mesh_key(element)[1:]))
    return tuple(out), _repair_key(repair, assume)


def _joined_pieces(pieces: list, *, budget: list | None, repair: bool, shared: MeshCache | None = None,
                   assume: UserAssumptions = NOTHING_ASSUMED):
    """``(unit-density body, method, uncertainty)`` of the open meshes ``pieces`` (elements of one link, one
    placement) integrated as one surface, or None when together they are not a closed solid either (with
    ``repair``: not even a bounded estimate) or cannot be read.

    Menagerie's Stretch splits a part into one OBJ file per material (``link_arm_l1_0.obj`` carbon fibre,
    ``link_arm_l1_1.obj`` printed plastic): each file is open where it meets the other, and together they bound
    the part.  The union of the pieces' triangles is checked and integrated by the engine like any mesh: first
    without repair; if it still has holes and ``repair`` is asked, repaired as one surface (the seams the
    pieces share are then not taken for holes, which is what refused most of them one by one).  ``shared``: the
    run's :class:`MeshCache`, which keeps the joins refused (by content), so that a copy is not joined again."""
    first = pieces[0]
    vertices, faces, offset, count = [], [], 0, 0
    seams: list[set] = []
    try:
        for element in pieces:
            raw = _placed(_raw_mesh(element.mesh, element), element)
            seams.append(_boundary_edges(raw.vertices, raw.faces))
            vertices.append(raw.vertices)
            faces.append(raw.faces.astype(np.int64) + offset)
            offset += len(raw.vertices)
            count += int(raw.file_faces)
        if budget is not None and count > budget[0]:
            return None
    except InertiaToolError:
        return None
    # pieces of one part meet along seams: a boundary edge of one is a boundary edge of another (the same two
    # points); pieces with no seam in common are separate holes, no better repaired together than apart
    if not any(seams[i] & seams[j] for i in range(len(seams)) for j in range(i + 1, len(seams))):
        return None
    content = _join_content(pieces, repair, assume) if shared is not None else None
    if shared is not None and shared.join_refused(content):
        return None                 # the same files, placed alike, refused before (the budget checked above)
    labels = [_mesh_label(e) for e in pieces]
    kept = shared.joined_copy(content, labels) if shared is not None else None
    if kept is not None:            # the same files, placed alike, joined before (the budget checked above)
        (local, method, uncertainty), caught = kept
        _reissue(caught)
        return _placed_join(local, first), method, uncertainty
    try:
        joined = RawMesh(vertices=np.concatenate(vertices), faces=np.concatenate(faces),
                         source=" + ".join(labels), units="m", file_faces=count)
    except InertiaToolError:
        return None
    for fix in (False, True) if repair else (False,):
        with warnings.catch_warnings(record=True) as recorded:
            warnings.simplefilter("always")
            try:
                local = mass_properties(joined, density=1.0, repair=fix, assume=assume.names if fix else ())
            except InertiaToolError:
                continue
        _reissue(recorded)
        report = local.mesh
        method = ("exact" if report is None else "estimate" if report.uncertainty is not None
                  else report.certificate.kind)
        uncertainty = None if report is None else report.uncertainty
        if shared is not None:
            shared.keep_join(content, labels, (local, method, uncertainty), tuple(recorded))
        return _placed_join(local, first), method, uncertainty
    if shared is not None:
        shared.refuse_join(content)
    return None


def _placed_join(local: MassProperties, first: GeometryElement) -> MassProperties:
    """The body of joined pieces placed as their first element places it, the engine's mesh report kept (its
    certificate, for :func:`_users_taken`)."""
    return replace(local.transformed(rotation=first.rotation, translation=first.translation), mesh=local.mesh)


def _join_open_pieces(parts: list, refused: list, *, model: bool, repair: bool,
                      budget: list | None, shared: MeshCache | None = None,
                      assume: UserAssumptions = NOTHING_ASSUMED) -> tuple[list, list, list]:
    """``parts`` and ``refused`` with each group of at least two open mesh pieces that close together
    (:func:`_joined_pieces`) replaced by one part; the third value names what was joined, for the link's
    warnings.  Open pieces are the meshes refused as needing repair and those repaired into estimates."""
    candidates = [e for e, _ in refused] + [e for e, _, m, _ in parts if m == "estimate" and e.fit_scale is None]
    groups: dict = {}
    for element in candidates:
        if element.kind == "mesh" and not element.shell and (element.mass is None or not model):
            groups.setdefault(_piece_group(element, model), []).append(element)
    notes = []
    for pieces in groups.values():
        keys = [_mesh_key(e) for e in pieces]
        if len(pieces) < 2 or len(set(keys)) < len(keys):     # one piece, or a mesh twice: nothing to join
            continue
        found = _joined_pieces(pieces, budget=budget, repair=repair, shared=shared, assume=assume)
        if found is None:
            continue
        local, method, uncertainty = found
        joined = {id(e) for e in pieces}
        parts = [p for p in parts if id(p[0]) not in joined] + [(pieces[0], local, method, uncertainty)]
        refused = [r for r in refused if id(r[0]) not in joined]
        notes.append(f"meshes {', '.join(os.path.basename(_mesh_label(e)) for e in pieces)} are open one by one: "
                     + ("they close together (pieces of one part) and were integrated as one solid"
                        if method != "estimate" else "integrated as one surface, repaired together"))
    return parts, refused, notes


def _element_parts(link: LinkGeometry, *, cache: dict, repair: bool, model: bool,
                   budget: list | None = None, assume: UserAssumptions = NOTHING_ASSUMED):
    """Per element of ``link``: ``(element, unit properties, mesh method, mesh uncertainty)``; massless
    elements (``model`` mode) are left out and named in the second return value; the third says what the
    link's warnings should: meshes taken by their MJCF ``inertia`` mode, open mesh pieces integrated together
    (:func:`_join_open_pieces`)."""
    parts: list[tuple] = []
    massless, refused, notes = [], [], []
    for element in link.elements:
        if model and (element.mass == 0 or (element.mass is None and element.density == 0)):
            massless.append(element)
            continue
        if model and element.shell:
            parts.append((element, element_shell_properties(element), "exact", None))
            continue
        if model and element.kind == "mesh" and element.mesh_inertia != "exact" and element.fit_scale is None:
            parts.append(_mesh_inertia_part(element, cache=cache, budget=budget))
            notes.append(_MESH_INERTIA_NOTES[element.mesh_inertia].format(os.path.basename(_mesh_label(element))))
            continue
        try:
            props = element_mass_properties(element, cache=cache, repair=repair, budget=budget, assume=assume)
        except InvalidMeshError as exc:      # an open piece may close with the link's other pieces: tried below
            if element.kind != "mesh" or element.fit_scale is not None:
                raise
            refused.append((element, exc))
            continue
        fitted = element.fit_scale is not None
        key = _mesh_key(element) if element.kind == "mesh" or fitted else None
        report = cache[key].mesh if key is not None and key in cache else None
        method: str = "exact"
        uncertainty: Uncertainty | None = None
        if report is not None and fitted:
            # a primitive fitted to a mesh is a closed form sized by the mesh's integrals: exactly as sure as
            # they are (a united mesh gives a united fit); no bound follows for a fit to a repaired mesh
            method = "unverified" if report.uncertainty is not None else report.certificate.kind
            if report.uncertainty is not None:
                bound = None if element.fit_aabb else fitted_mass_bound(element, cache[key], report.uncertainty)
                if bound is not None and bound <= ESTIMATE_MAX_MASS_RTOL:
                    method = "estimate"
                    uncertainty = Uncertainty(mass=bound, center_of_mass=report.uncertainty.center_of_mass,
                                              inertia=float("inf"), volume_in_doubt=bound * props.volume)
                notes.append(_fitted_estimate_note(element, report.uncertainty, bound))
        elif report is not None:        # the engine's certificate (a result with bounds is an estimate)
            method = "estimate" if report.uncertainty is not None else report.certificate.kind
            uncertainty = report.uncertainty
        parts.append((element, props, method, uncertainty))
    joined: list = []
    if len(refused) + sum(1 for p in parts if p[2] == "estimate") >= 2:
        parts, refused, joined = _join_open_pieces(parts, refused, model=model, repair=repair, budget=budget,
                                                   shared=cache.get(_SHARED), assume=assume)
    if refused:
        raise refused[0][1]
    return parts, massless, notes + joined


def link_mass_properties(link: LinkGeometry, *, cache: dict | None = None, repair: bool = False,
                         budget: list | None = None, assume: UserAssumptions = NOTHING_ASSUMED) -> MassProperties:

    """Unit-density mass properties of all the link's elements together, link frame (parallel-axis sum).

    Parameters
    ----------
    link : LinkGeometry
    cache : dict, optional
        Mesh path → unit-density properties, shared between links.
    repair : bool
        Passed to :func:`mesh_properties`.
    budget : list of one int, optional
        Shared triangle budget (:func:`element_mass_properties`).
    assume : UserAssumptions
        The user's assumptions about the holes a repair fills, passed to :func:`mesh_properties`.

    Returns
    -------
    MassProperties
        Unit density, link frame.  Raises :class:`UsageError` for a link without geometry.
    """
    if not link.elements:
        raise UsageError(f"Expected link {link.name!r} to have geometry, got none")
    parts = [element_mass_properties(e, cache=cache, repair=repair, budget=budget, assume=assume)
             for e in link.elements]
    total = parts[0] if len(parts) == 1 else combine(parts, name=link.name)
    return MassProperties(mass=total.mass, volume=total.volume, center_of_mass=total.center_of_mass,
                          inertia=total.inertia, surface_area=total.surface_area, density=1.0, name=link.name)


@frozen_value
class LinkUncertainty:
    """Bounds on a link result that contains estimated meshes (``method == "estimate"``).

    Attributes
    ----------
    mass : float
        Relative: the true mass lies within ``mass · m`` of the reported ``m`` (the elements' absolute bounds
        added).
    center_of_mass : float
        m: ``(Σ m_i e_i + Σ δm_i |c_i − c|) / (M − Σ δm_i)`` with ``e_i`` the elements' centre bounds and
        ``δm_i`` their absolute mass bounds (the centre ``Σ m_i c_i / M`` perturbed, to first order exact,
        bounded with the smallest possible total mass).
    inertia : float or None
        Relative Frobenius bound on the tensor when the link is a single element; None otherwise (no bound
        is claimed for a sum of estimated and exact parts, nor for a primitive fitted to an estimated mesh).
    """

    mass: float
    center_of_mass: float
    inertia: float | None


@frozen_value
class LinkInertial:
    """The mass properties a link's geometry implies.

    Attributes
    ----------
    name : str
        The link.
    properties : MassProperties or None
        Link frame: ``center_of_mass`` in m, ``inertia`` in kg·m² about it in link axes; ``volume`` the
        geometry's m³.  None when the link has no geometry or its geometry could not be integrated
        (``problem`` says why).
    density : float
        kg/m³ used (with ``keep_mass``: the implied density ``declared mass / volume``; with the model's own
        densities: total mass / total volume); nan without result.
    basis : str
        How the density was chosen (``"7850 kg/m³"``, ``"steel (7850 kg/m³)"``, ``"declared masses kept"``,
        ``"the model's own densities"``).
    problem : str or None
        Why there is no result: no geometry, no declared mass to keep, a mesh that needs repair.
    method : str or None
        One of :data:`METHODS` (the least certain of the link's elements); None without result.
    uncertainty : LinkUncertainty or None
        Bounds when ``method == "estimate"``; None when the result is exact for the geometry as described.
    warnings : tuple of str
        What the reader should know about a result (massless geoms left out, a repaired mesh).
    assumptions : tuple of str
        The user's assumptions (``assume``) the result rests on: those the certificates of the link's repaired
        meshes name (:attr:`~inertia_tool.mesh.policy.Certificate.assumptions`); empty when none was taken.
    """

    name: str
    properties: MassProperties | None
    density: float
    basis: str
    problem: str | None = None
    method: str | None = None
    uncertainty: LinkUncertainty | None = None
    warnings: tuple = ()
    assumptions: tuple[str, ...] = ()


def _users_taken(parts: list, cache: dict) -> tuple[str, ...]:
    """The user's assumptions the link's mesh bodies rest on: those their certificates name (a joined body's
    report is kept on it, a single mesh's is in the robot's ``cache``)."""
    names: set[str] = set()
    for element, props, _, _ in parts:
        report = props.mesh
        if report is None and (element.kind == "mesh" or element.fit_scale is not None):
            report = getattr(cache.get(_mesh_key(element)), "mesh", None)
        if report is not None:
            names.update(report.certificate.assumptions)
    return user_named(names)


def _link_uncertainty(parts: list, total: MassProperties, scale) -> LinkUncertainty | None:
    """Bounds for a link from its elements'.  ``scale``: the link result's mass per unit of each part's
    (unit-density) mass, one number for all parts or one per part (``--density model``: each geom's density, or
    its ``mass`` over its unit mass); a part's absolute mass bound is ``u.mass * p.mass * scale``."""
    scales = list(scale) if isinstance(scale, (list, tuple)) else [scale] * len(parts)
    estimated = [(p, u, k) for (_, p, m, u), k in zip(parts, scales, strict=True) if m == "estimate" and u is not None]
    if not estimated:
        return None
    dm = [u.mass * p.mass * k for p, u, k in estimated]
    spread = sum(d * float(np.linalg.norm(p.center_of_mass - total.center_of_mass))
                 for d, (p, _, _) in zip(dm, estimated))
    shift = sum(p.mass * k * u.center_of_mass for p, u, k in estimated)
    floor = total.mass - sum(dm)
    com = (shift + spread) / floor if floor > 0 else float("inf")
    inertia = estimated[0][1].inertia if len(parts) == 1 and np.isfinite(estimated[0][1].inertia) else None
    return LinkUncertainty(mass=sum(dm) / total.mass, center_of_mass=com, inertia=inertia)


_RANK = {m: k for k, m in enumerate(METHODS)}


def _with_engine_warnings(result: LinkInertial, caught: list) -> LinkInertial:
    """``result`` with the engine's warnings about its meshes (the mesh engine's ``InertiaToolWarning``s:
    faces turned, bodies united, a repair) added to ``warnings``; they are issued again for the caller."""
    from ..errors import InertiaToolWarning
    texts = []
    for item in caught:
        if issubclass(item.category, InertiaToolWarning):
            texts.append(str(item.message))
        warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
    if not texts:
        return result
    return replace(result, warnings=tuple(result.warnings) + tuple(texts))


def _one_link(link: LinkGeometry, **options) -> LinkInertial:
    """:func:`_one_link_result` with the engine's warnings about the link's meshes in its ``warnings``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = _one_link_result(link, **options)
    return _with_engine_warnings(result, caught)


def _missing_files(paths: list) -> str:
    """``"mesh file missing: P"`` for a link's absent mesh files, each with its near match if there is one
    (:func:`~inertia_tool.robot.resolve.near_match`: nothing is read in its place)."""
    from .resolve import near_match
    named = []
    for path in dict.fromkeys(paths):
        hint = near_match(path)
        named.append(f"{path} ({hint})" if hint else path)
    return f"mesh file missing: {', '.join(named)}"


#: The problem of a link whose geoms are all massless under ``density="model"``, with the way on.
MASSLESS = "every geom is massless in the description (--density RHO or --material M gives each geom a density)"

#: The start of a link's problem when its mesh was refused: without ``repair``, and with it.
REFUSED = "mesh needs repair or cannot be read"
REFUSED_REPAIRED = "mesh cannot be read or bounded, even with repair"


def _one_link_result(link: LinkGeometry, *, rho, basis: str, keep_mass: bool, model: bool, repair: bool,
                     cache: dict, geometry: str, budget: list | None = None,
                     assume: UserAssumptions = NOTHING_ASSUMED) -> LinkInertial:
    """The result for one link, or the reason there is none (never raises for the link's own problems)."""
    nan = float("nan")
    if link.unread:      # an SDFormat include not on disk (read_robot(missing_meshes="per-link"))
        return LinkInertial(link.name, None, nan, basis, link.unread)
    if not link.elements:
        other = {"collision": "visual", "visual": "collision"}.get(geometry)
        has = (f"; {link.unselected} {other} element{'s' if link.unselected > 1 else ''}, which --geometry "
               f"{other} reads" if link.unselected and other else "")
        return LinkInertial(link.name, None, nan, basis, f"no {geometry_words(geometry)}{has}")
    missing = [e.mesh for e in link.elements if e.mesh is not None and not os.path.exists(e.mesh)
               and not (model and (e.mass == 0 or (e.mass is None and e.density == 0)))]
    if missing:          # read_robot(missing_meshes="per-link"): the link says which file, the others compute
        return LinkInertial(link.name, None, nan, basis, _missing_files(missing))
    try:
        parts, massless, joined = _element_parts(link, cache=cache, repair=repair, model=model, budget=budget,
                                                 assume=assume)
    except InertiaToolError as exc:
        # with repair on, "needs repair" would contradict the warning that it was tried (review 8)
        return LinkInertial(link.name, None, nan, basis, f"{REFUSED_REPAIRED if repair else REFUSED}: {exc}")
    except (ValueError, ArithmeticError) as exc:     # numerical trouble in one link's geometry: its reason
        return LinkInertial(link.name, None, nan, basis, f"cannot be computed: {exc}")
    warned = [e.note for e in link.elements if e.note] + joined
    warned += [f"{e.kind} {e.name!r} is massless in the description "
               f"({'mass=0' if e.mass == 0 else 'density=0'}): left out" for e in massless]
    if not parts:
        # the file gives its geoms no mass (Fourier N1's collision geoms: mass="0", its <inertial>s hold the masses)
        return LinkInertial(link.name, None, nan, basis, MASSLESS,
                            warnings=tuple(warned))
    method = max((m for _, _, m, _ in parts), key=_RANK.__getitem__)
    taken = _users_taken(parts, cache)
    warned += [f"{e.name or e.kind}: {round_up(u.mass, 2):.2g} relative mass bound from the repaired mesh"
               for e, _, m, u in parts if m == "estimate" and u is not None]
    try:
        if model:
            weighted = []
            for element, unit, _, _ in parts:
                if element.mass is not None:
                    weighted.append(unit.with_mass(element.mass))
                else:
                    weighted.append(MassProperties(mass=unit.mass * element.density, volume=unit.volume,
                                                   center_of_mass=unit.center_of_mass,
                                                   inertia=unit.inertia * element.density,
                                                   surface_area=unit.surface_area, density=element.density))
            total = weighted[0] if len(weighted) == 1 else combine(weighted, name=link.name)
            volume = sum(u.volume for _, u, _, _ in parts)
            props = MassProperties(mass=total.mass, volume=volume, center_of_mass=total.center_of_mass,
                                   inertia=total.inertia, surface_area=total.surface_area,
                                   density=total.mass / volume if volume > 0 else nan, name=link.name)
            scales = [w.mass / unit.mass if unit.mass else 0.0 for w, (_, unit, _, _) in zip(weighted, parts)]
            uncertainty = _link_uncertainty(parts, props, scales) if method == "estimate" else None
            return LinkInertial(link.name, props, props.density, basis, method=method, uncertainty=uncertainty,
                                warnings=tuple(warned), assumptions=taken)
        units = [u for _, u, _, _ in parts]
        total = units[0] if len(units) == 1 else combine(units, name=link.name)
        unit = MassProperties(mass=total.mass, volume=total.volume, center_of_mass=total.center_of_mass,
                              inertia=total.inertia, surface_area=total.surface_area, density=1.0, name=link.name)
        if keep_mass:
            if link.declared is None or not link.declared.mass > 0:
                mass = nan if link.declared is None else link.declared.mass
                return LinkInertial(link.name, None, nan, "declared masses kept",
                                    "no declared mass to keep" if link.declared is None
                                    else f"declared mass {mass:g} kg is not positive", warnings=tuple(warned))
            props = unit.with_mass(link.declared.mass)
            scale = props.mass / unit.mass
            return LinkInertial(link.name, props, props.mass / props.volume, "declared masses kept", method=method,
                                uncertainty=_link_uncertainty(parts, props, scale), warnings=tuple(warned),
                                assumptions=taken)
        props = MassProperties(mass=unit.mass * rho, volume=unit.volume, center_of_mass=unit.center_of_mass,
                               inertia=unit.inertia * rho, surface_area=unit.surface_area, density=rho,
                               name=link.name)
        return LinkInertial(link.name, props, rho, basis, method=method,
                            uncertainty=_link_uncertainty(parts, props, rho), warnings=tuple(warned),
                            assumptions=taken)
    except (InertiaToolError, ValueError, ArithmeticError) as exc:
        return LinkInertial(link.name, None, nan, basis, f"cannot be computed: {exc}", warnings=tuple(warned))


def link_inertials(robot: RobotDescription, *, density: float | str | None = None, material: str | None = None,
                   keep_mass: bool = False, repair: bool = False, max_faces: int = DEFAULT_MAX_FACES,
                   mesh_cache: MeshCache | None = None, assume: tuple[str, ...] = ()) -> tuple:
    """Mass properties of every link from its geometry, in the link frame.

    Parameters
    ----------
    robot : RobotDescription
    density : float or "model", optional
        kg/m³ for every link; or :data:`MODEL_DENSITY` (``"model"``) for the description's own densities
        (MJCF geom ``density``, ``mass``, ``shellinertia``: each geom at its density, a geom with a ``mass``
        scaled to it, massless geoms left out and named in ``warnings``).
    material : str, optional
        Material name (``inertia_tool.units.MATERIALS``).
    keep_mass : bool
        Keep each link's declared mass and take the shape from the geometry (the implied density is
        reported).  Exactly one of ``density``, ``material``, ``keep_mass``.
    repair : bool
        Repair open or inconsistently wound meshes (the engine's ``repair``; it warns what it changed) instead
        of reporting the link as needing repair.
    max_faces : int
        Triangles all the robot's mesh files together may hold (each file is read once); a mesh past the
        remaining budget is refused before it is read into memory (its link reports why).
    mesh_cache : MeshCache, optional
        Mesh bodies shared with other robots of the same run (a corpus); each mesh file placed the same way is
        then integrated (or refused) once for all of them.  Without it, once per robot.  Its entries are keyed
        by ``repair`` and ``assume`` (a body prepared under an assumption is never reused without it).
    assume : tuple of str
        The user's assumptions about the holes a repair fills (``LoadOptions.assume``: ``("flat-islands",)``),
        in force for every mesh of the robot; only with ``repair``.

    Returns
    -------
    tuple of LinkInertial
        One per link, in the description's order.  A link that cannot be computed (a mesh that is not a
        closed solid, a degenerate repair, no geometry) has ``properties=None`` and ``problem`` saying why;
        it never stops the other links.
    """
    chosen = sum([density is not None, material is not None, bool(keep_mass)])
    if chosen != 1:
        raise UsageError("Give exactly one of `density`, `material` and `keep_mass`")
    model = isinstance(density, str)
    if model and density != MODEL_DENSITY:
        raise UsageError(f"Expected `density` to be a number or {MODEL_DENSITY!r}, got {density!r}")
    if model and robot.format != "mjcf":
        raise UsageError(f"Expected a MuJoCo MJCF description for density={MODEL_DENSITY!r} (only MJCF gives "
                         f"densities), got {robot.format}")
    if model or keep_mass:
        rho, basis = None, ("the model's own densities" if model else "")
    else:
        assert not isinstance(density, str), "checked above"
        rho, basis = resolve_density(density=density, material=material)
    if not (isinstance(max_faces, (int, np.integer)) and 0 < max_faces <= MAX_SUPPORTED_FACES):
        raise UsageError(f"Expected `max_faces` to be an integer from 1 to {MAX_SUPPORTED_FACES:,}, got {max_faces!r}")
    checked = LoadOptions(repair=bool(repair), assume=tuple(assume))    # the one check of `assume` (UsageError)
    cache: dict = {} if mesh_cache is None else {_SHARED: mesh_cache}
    budget = [int(max_faces), int(max_faces)]
    assumed = UserAssumptions(checked.assume)        # every mesh of the robot, read however deep, takes them
    return tuple(_one_link(link, rho=rho, basis=basis, keep_mass=keep_mass, model=model, repair=repair,
                           cache=cache, geometry=robot.geometry, budget=budget, assume=assumed) for link in robot.links)


# -- where the geometry is (for the audit) -----------------------------------------------------------------

def _mesh_vertices_faces(element: GeometryElement):
    """The mesh's vertices in the element frame (reference transform, then scale: :func:`_placed`) and its
    faces."""
    raw = _placed(_raw_mesh(element.mesh, element), element)
    return raw.vertices, raw.faces


def element_bounds(element: GeometryElement) -> np.ndarray:
    """(2, 3) m: the link-frame axis-aligned bounding box of the element (lower, upper corners)."""
    element = fitted_element(element)
    kind, size = element.kind, element.size
    if kind == "mesh":
        v, _ = _mesh_vertices_faces(element)
        pts = v @ element.rotation.T + element.translation
        return np.array([pts.min(axis=0), pts.max(axis=0)])
    if kind == "polyline":
        xy = np.concatenate([np.asarray(p) for p in element.polygons])
        corners = np.array([[x, y, z] for x in (xy[:, 0].min(), xy[:, 0].max())
                            for y in (xy[:, 1].min(), xy[:, 1].max()) for z in (0.0, size[0])])
        pts = corners @ element.rotation.T + element.translation
        return np.array([pts.min(axis=0), pts.max(axis=0)])
    if kind == "box":
        half = 0.5 * np.asarray(size)
    elif kind == "sphere":
        half = np.full(3, size[0])
    elif kind == "ellipsoid":
        half = np.asarray(size)
    elif kind == "cylinder":
        half = np.array([size[0], size[0], 0.5 * size[1]])
    else:
        half = np.array([size[0], size[0], 0.5 * size[1] + size[0]])
    extent = np.abs(element.rotation) @ half          # half-extent of the rotated box along link axes
    return np.array([element.translation - extent, element.translation + extent])


def points_inside_element(element: GeometryElement, point) -> bool:
    """Whether ``point`` (m, link frame) lies inside the element (meshes: winding number ≥ ½)."""
    element = fitted_element(element)
    local = element.rotation.T @ (np.asarray(point, dtype=np.float64) - element.translation)
    kind, size = element.kind, element.size
    if kind == "box":
        return bool(np.all(np.abs(local) <= 0.5 * np.asarray(size)))
    if kind == "sphere":
        return bool(local @ local <= size[0] ** 2)
    if kind == "ellipsoid":
        return bool(np.sum((local / np.asarray(size)) ** 2) <= 1.0)
    if kind == "cylinder":
        return bool(local[:2] @ local[:2] <= size[0] ** 2 and abs(local[2]) <= 0.5 * size[1])
    if kind == "polyline":       # even-odd: inside an odd number of the region's polygons
        inside = sum(_inside_polygon(local[:2], np.asarray(p)) for p in element.polygons)
        return bool(0.0 <= local[2] <= size[0] and inside % 2)
    if kind == "capsule":
        z = float(np.clip(local[2], -0.5 * size[1], 0.5 * size[1]))
        d = local - np.array([0.0, 0.0, z])
        return bool(d @ d <= size[0] ** 2)
    from ..mesh.checks import winding_number
    v, f = _mesh_vertices_faces(element)
    return abs(winding_number(local, v, f)) >= 0.5
