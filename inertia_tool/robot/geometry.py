"""Mass properties of a link from its geometry: primitives in closed form, meshes through the engine.

Every element is first taken at unit density in its own frame, then scaled (meshes), then moved into the
link frame (``x ↦ R x + t``: centre ``R c + t``, tensor ``R I Rᵀ``), and the elements of a link are summed
with the parallel-axis theorem (Eq. 4.16, :func:`inertia_tool.mass.properties.combine`).  Overlapping elements
are counted twice (as a simulator's inertia-from-geometry does).

Closed forms (unit density, about the element's centre, element axes; M = V):

* box ``a × b × c``: ``I_xx = M(b² + c²)/12`` (cyclic) — :func:`inertia_tool.mass.shapes.box`;
* cylinder (R, h) along z: ``I_zz = MR²/2``, ``I_xx = M(R²/4 + h²/12)`` — :func:`inertia_tool.mass.shapes.cylinder`;
* sphere (r): ``2Mr²/5`` — :func:`inertia_tool.mass.shapes.sphere`;
* ellipsoid (a, b, c): ``V = 4πabc/3``, ``I_xx = M(b² + c²)/5`` (cyclic): the unit sphere's ``∫x² dV = V/5``
  stretched by ``a²``;
* capsule (R, cylinder length L) along z: the cylinder plus two hemispheres of mass ``m_h = 2πR³/3`` whose
  centres sit ``3R/8`` beyond the cylinder ends; a hemisphere has ``I_zz = 2 m_h R²/5`` and, about its own
  centre, ``I_xx = 2 m_h R²/5 − m_h (3R/8)² = 83 m_h R²/320``; the parallel-axis theorem moves it to the
  capsule centre, ``I_xx += m_h (L/2 + 3R/8)²``.

Mesh scale ``S = diag(s)``: ``∫_{S(V)} f(y) dy = |det S| ∫_V f(S x) dx``, so the volume becomes
``|det S| V``, the centre ``S c``, and the central second moments ``Σ = ∫ x xᵀ dV`` become ``|det S| S Σ S``;
the tensor is ``I = tr(Σ) 1 − Σ`` (Eq. 4.13).  A negative factor (a mirrored mesh) is handled by ``|det S|``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InvalidMeshError, MeshReadError, UsageError
from ..mass import shapes
from ..mass.pipeline import mass_properties, resolve_density
from ..mass.properties import MassProperties, combine
from ..mesh.options import DEFAULT_MAX_FACES, MAX_SUPPORTED_FACES
from ..values import frozen_value
from .description import GeometryElement, LinkGeometry, RobotDescription

__all__ = ["element_mass_properties", "link_mass_properties", "link_inertials", "LinkInertial", "mesh_properties",
           "points_inside_element", "element_bounds"]


def mesh_properties(path: str, *, repair: bool = False, max_faces: int | None = None) -> MassProperties:
    """Unit-density mass properties of the mesh file ``path`` (metres, file axes).

    The one place where the robot tools call the mesh engine.

    Parameters
    ----------
    path : str
        The mesh file.
    repair : bool
        Let the engine repair an open or inconsistently wound mesh (``LoadOptions.repair``) instead of raising
        :class:`InvalidMeshError` (the caller then reports the link).
    max_faces : int, optional
        Refuse a file of more triangles (the reader's limit, ``LoadOptions.max_faces``); its default when None.

    Returns
    -------
    MassProperties
        Unit density: ``mass == volume``.
    """
    # robot descriptions give mesh coordinates in metres (the element's `scale` is applied afterwards), so the
    # unit is stated, not assumed: no size warning for a millimetre mesh scaled by 0.001 in the description
    if max_faces is None:
        return mass_properties(path, density=1.0, repair=repair, units="m")
    return mass_properties(path, density=1.0, repair=repair, units="m", max_faces=max_faces)


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


def _scaled(props: MassProperties, scale) -> MassProperties:
    s = np.asarray(scale, dtype=np.float64)
    if np.all(s == 1.0):
        return props
    det = abs(float(np.prod(s)))
    if det == 0:
        raise UsageError(f"Expected non-zero mesh scale factors, got {s.tolist()}")
    sigma = 0.5 * np.trace(props.inertia) * np.eye(3) - props.inertia
    sigma = det * (s[:, None] * sigma * s[None, :])
    volume = det * props.volume
    return MassProperties(mass=volume, volume=volume, center_of_mass=s * props.center_of_mass,
                          inertia=np.trace(sigma) * np.eye(3) - sigma, density=1.0, name=props.name)


def element_mass_properties(element: GeometryElement, *, cache: dict | None = None,
                            repair: bool = False, budget: list | None = None) -> MassProperties:
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

    Returns
    -------
    MassProperties
        ``mass == volume`` (m³), centre of mass in m and tensor about it in kg·m² per kg/m³, link axes.

    Raises
    ------
    InvalidMeshError, MeshReadError
        From the mesh engine, for a mesh element.
    """
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
    elif kind == "mesh":
        if cache is not None and element.mesh in cache:
            local = cache[element.mesh]
        else:
            assert element.mesh is not None, "a mesh element carries the path of its file"
            if budget is not None and budget[0] < 1:
                raise MeshReadError(f"{element.mesh}: not read: the meshes read before it hold all the triangles "
                                    "`max_faces` allows (the limit is on all the meshes of the robot together)")
            try:
                local = mesh_properties(element.mesh, repair=repair,
                                        max_faces=None if budget is None else budget[0])
            except MeshReadError as exc:
                if budget is None or budget[0] == budget[1] or "`max_faces`" not in str(exc):
                    raise
                raise MeshReadError(f"{exc}: the limit counts all the robot's meshes together ({budget[1]:,}), "
                                    f"and the meshes read before this one left {budget[0]:,}") from None
            if budget is not None and local.mesh is not None:
                budget[0] -= local.mesh.file_faces
            if cache is not None:
                cache[element.mesh] = local
        local = _scaled(local, element.scale)
    else:
        raise UsageError("Expected a geometry kind among box, cylinder, sphere, capsule, ellipsoid, mesh, "
                         f"got {kind!r}")
    return local.transformed(rotation=element.rotation, translation=element.translation)


def link_mass_properties(link: LinkGeometry, *, cache: dict | None = None, repair: bool = False,
                         budget: list | None = None) -> MassProperties:
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

    Returns
    -------
    MassProperties
        Unit density, link frame.  Raises :class:`UsageError` for a link without geometry.
    """
    if not link.elements:
        raise UsageError(f"Expected link {link.name!r} to have geometry, got none")
    parts = [element_mass_properties(e, cache=cache, repair=repair, budget=budget) for e in link.elements]
    total = parts[0] if len(parts) == 1 else combine(parts, name=link.name)
    return MassProperties(mass=total.mass, volume=total.volume, center_of_mass=total.center_of_mass,
                          inertia=total.inertia, surface_area=total.surface_area, density=1.0, name=link.name)


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
        kg/m³ used (with ``keep_mass``: the implied density ``declared mass / volume``); nan without result.
    basis : str
        How the density was chosen (``"7850 kg/m³"``, ``"steel (7850 kg/m³)"``, ``"declared masses kept"``).
    problem : str or None
        Why there is no result: no geometry, no declared mass to keep, a mesh that needs repair.
    """

    name: str
    properties: MassProperties | None
    density: float
    basis: str
    problem: str | None = None


def link_inertials(robot: RobotDescription, *, density: float | None = None, material: str | None = None,
                   keep_mass: bool = False, repair: bool = False, max_faces: int = DEFAULT_MAX_FACES) -> tuple:
    """Mass properties of every link from its geometry, in the link frame.

    Parameters
    ----------
    robot : RobotDescription
    density : float, optional
        kg/m³ for every link.
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

    Returns
    -------
    tuple of LinkInertial
        One per link, in the description's order.  A link whose mesh is not a closed solid has
        ``properties=None`` and ``problem`` naming the mesh and what the engine found.
    """
    chosen = sum([density is not None, material is not None, bool(keep_mass)])
    if chosen != 1:
        raise UsageError("Give exactly one of `density`, `material` and `keep_mass`")
    rho, basis = (None, "") if keep_mass else resolve_density(density=density, material=material)
    if not (isinstance(max_faces, (int, np.integer)) and 0 < max_faces <= MAX_SUPPORTED_FACES):
        raise UsageError(f"Expected `max_faces` to be an integer from 1 to {MAX_SUPPORTED_FACES:,}, got {max_faces!r}")
    cache: dict = {}
    budget = [int(max_faces), int(max_faces)]
    out = []
    for link in robot.links:
        if not link.elements:
            out.append(LinkInertial(link.name, None, float("nan"), basis, f"no {robot.geometry} geometry"))
            continue
        try:
            unit = link_mass_properties(link, cache=cache, repair=repair, budget=budget)
        except (InvalidMeshError, MeshReadError) as exc:
            out.append(LinkInertial(link.name, None, float("nan"), basis,
                                    f"mesh needs repair or cannot be read: {exc}"))
            continue
        if keep_mass:
            if link.declared is None or not link.declared.mass > 0:
                mass = float("nan") if link.declared is None else link.declared.mass
                out.append(LinkInertial(link.name, None, float("nan"), "declared masses kept",
                                        "no declared mass to keep" if link.declared is None
                                        else f"declared mass {mass:g} kg is not positive"))
                continue
            props = unit.with_mass(link.declared.mass)
            out.append(LinkInertial(link.name, props, props.mass / props.volume, "declared masses kept"))
        else:
            assert rho is not None, "resolve_density gives a density when no target mass is asked"
            props = MassProperties(mass=unit.mass * rho, volume=unit.volume, center_of_mass=unit.center_of_mass,
                                   inertia=unit.inertia * rho, surface_area=unit.surface_area, density=rho,
                                   name=link.name)
            out.append(LinkInertial(link.name, props, rho, basis))
    return tuple(out)


# -- where the geometry is (for the audit) -----------------------------------------------------------------

def _mesh_vertices_faces(element: GeometryElement):
    from ..mesh.read import load_mesh
    raw = load_mesh(element.mesh, units="m")
    return raw.vertices * element.scale, raw.faces


def element_bounds(element: GeometryElement) -> np.ndarray:
    """(2, 3) m: the link-frame axis-aligned bounding box of the element (lower, upper corners)."""
    kind, size = element.kind, element.size
    if kind == "mesh":
        v, _ = _mesh_vertices_faces(element)
        pts = v @ element.rotation.T + element.translation
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
    if kind == "capsule":
        z = float(np.clip(local[2], -0.5 * size[1], 0.5 * size[1]))
        d = local - np.array([0.0, 0.0, z])
        return bool(d @ d <= size[0] ** 2)
    from ..mesh.checks import winding_number
    v, f = _mesh_vertices_faces(element)
    return abs(winding_number(local, v, f)) >= 0.5
