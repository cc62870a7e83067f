"""Balancing by removing material: each correction mass becomes a drilled hole (Chapter 4 §4.3.2).

A hole of diameter ``d`` drilled parallel to the shaft at radius ``r`` and angle ``θ``, from the correction
plane ``z_k`` to the depth ``L`` (towards the other correction plane; with one plane, towards the centre of
mass), removes a solid cylinder: mass ``m = ρ π d² L / 4``, centroid on its axis at ``z_k + s L/2``
(``s = ±1`` the drilling direction), own inertia ``m d²/8`` about its axis and ``m (3 d²/4 + L²)/12``
across it (closed form).  An axial cylinder acts on the unbalance as a point mass at its centroid: it takes
``m r e^{iθ}`` from ``U`` and ``z_c m r e^{iθ}`` from ``W`` (notation of :mod:`.rotor`).  Because the centroid
depends on the depth, the depths solve ``m_k r e^{iθ_k} = U_k(z_c)`` with ``U_k`` the body's unbalance resolved
into the planes through the hole centroids (Eq. in :func:`.rotor._resolve`) — a fixed point reached in a few
steps.  Each hole must lie inside the part: sample points of the cylinder are checked with the generalised
winding number of the part's surface (``mesh.checks.winding_number``) when the surface is given.  The drilled
body (part minus the cylinders, exact) is re-analysed like the added-mass corrections.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import PhysicsError, UsageError
from ..mass.properties import MassProperties

__all__ = ["DrilledHole", "drill_holes", "remove_cylinders", "MAX_DEPTH_ITERATIONS"]

#: Most fixed-point steps for the depths (they converge geometrically when the holes are short compared with
#: the distance between the planes).
MAX_DEPTH_ITERATIONS = 100


@dataclass(frozen=True)
class DrilledHole:
    """One balancing hole.

    Attributes
    ----------
    plane : float
        Axial position where drilling starts (the correction plane), m from ``axis_point``.
    angle : float
        rad in [0, 2π), from shaft x towards y: the removal angle (opposite the added mass).
    radius : float
        Distance of the hole axis from the shaft, m.
    diameter : float
        m.
    depth : float
        m, along the shaft from ``plane`` in the sense ``direction``.
    direction : int
        +1 or −1: drilling towards increasing or decreasing shaft z.
    mass : float
        Removed mass, kg.
    entry : (3,) float
        Centre of the hole's entry circle, m, mesh axes.
    axis : (3,) float
        Unit drilling direction, mesh axes.
    centroid : (3,) float
        Centroid of the removed cylinder, m, mesh axes.
    inside_checked : bool
        Whether the cylinder was checked to lie inside the part (winding number of its sample points).
    """

    plane: float
    angle: float
    radius: float
    diameter: float
    depth: float
    direction: int
    mass: float
    entry: np.ndarray
    axis: np.ndarray
    centroid: np.ndarray
    inside_checked: bool


def _cylinder_inertia(mass: float, diameter: float, depth: float, axis: np.ndarray) -> np.ndarray:
    """Central inertia tensor (kg·m², mesh axes) of a solid cylinder: ``m a²/2`` about the axis,
    ``m (3a² + L²)/12`` across (``a = d/2``)."""
    a2 = (0.5 * diameter) ** 2
    axial = 0.5 * mass * a2
    transverse = mass * (3.0 * a2 + depth ** 2) / 12.0
    n = axis / np.linalg.norm(axis)
    return transverse * np.eye(3) + (axial - transverse) * np.outer(n, n)


def remove_cylinders(props: MassProperties, holes) -> MassProperties:
    """The body with the holes' cylinders removed (exact: parallel-axis theorem, Eq. 4.16).

    ``M' = M − Σm``; ``c' = (M c − Σ m_k c_k)/M'``; ``I' = I + M P(c − c') − Σ [I_k + m_k P(c_k − c')]`` with
    ``P(d) = |d|² 𝟙 − d dᵀ``.
    """
    def shift(mass, d):
        return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))

    removed = sum(h.mass for h in holes)
    mass = props.mass - removed
    if not mass > 0:
        raise PhysicsError(f"the holes would remove {removed:.6g} kg of a {props.mass:.6g} kg part")
    com = (props.mass * props.center_of_mass - sum(h.mass * h.centroid for h in holes)) / mass
    inertia = props.inertia + shift(props.mass, props.center_of_mass - com)
    for h in holes:
        inertia = inertia - _cylinder_inertia(h.mass, h.diameter, h.depth, h.axis) - shift(h.mass, h.centroid - com)
    volume = props.volume - removed / props.density
    return MassProperties(mass=mass, volume=volume, center_of_mass=com, inertia=0.5 * (inertia + inertia.T),
                          surface_area=props.surface_area, density=props.density, name=f"{props.name} (drilled)")


def _inside(points, vertices, faces) -> bool:
    from ..mesh.checks import winding_number
    return all(winding_number(p, vertices, faces) > 0.5 for p in points)


def _sample_points(entry, axis, radial, diameter, depth):
    """Points of the cylinder near its surface (12 around, 5 depths) and on its axis, just inside it."""
    tangent = np.cross(axis, radial)
    points = []
    for fraction in (0.02, 0.25, 0.5, 0.75, 1.0):
        centre = entry + fraction * depth * axis
        points.append(centre)
        for k in range(12):
            phi = 2 * math.pi * k / 12
            points.append(centre + 0.49 * diameter * (math.cos(phi) * radial + math.sin(phi) * tangent))
    return points


def drill_holes(props: MassProperties, frame, planes, corrections_radius: float, diameter: float,
                unbalance, moment_unbalance, *, part_mesh=None, rtol: float = 1e-12) -> tuple:
    """Holes that balance the body in place of the correction masses (module docstring).

    Parameters
    ----------
    props : MassProperties
        The rotor (homogeneous: its ``density`` is the drilled material's).
    frame : ShaftFrame
        The shaft.
    planes : tuple of float
        Correction planes (1 or 2), m from ``axis_point``.
    corrections_radius : float
        Radius of the holes' axes, m.
    diameter : float
        Drill diameter, m (> 0).
    unbalance, moment_unbalance : (3,) float
        ``U`` and ``W`` of the body (shaft frame).
    part_mesh : (vertices, faces), optional
        The part's closed surface (m, mesh axes) to check that every hole lies inside it.
    rtol : float
        Relative convergence tolerance of the depths.

    Returns
    -------
    tuple of DrilledHole

    Raises
    ------
    UsageError
        A non-positive diameter.
    PhysicsError
        No density, depths that do not converge, or a hole that leaves the part.
    """
    if not (math.isfinite(diameter) and diameter > 0):
        raise UsageError(f"Expected a positive `drill_diameter` in m, got {diameter!r}")
    rho = props.density
    if not (math.isfinite(rho) and rho > 0):
        raise PhysicsError("drilling needs the part's density (a homogeneous part)")
    area = math.pi * diameter ** 2 / 4.0
    z_com = float(frame.to_shaft(props.center_of_mass)[2])
    if len(planes) == 2:
        sense = [1 if planes[1] > planes[0] else -1, 1 if planes[0] > planes[1] else -1]
    else:
        sense = [1 if z_com >= planes[0] else -1]
    u = np.asarray(unbalance, dtype=float)
    w = np.asarray(moment_unbalance, dtype=float)
    depths = [0.0] * len(planes)
    for _ in range(MAX_DEPTH_ITERATIONS):
        centroids = [z + s * d / 2 for z, s, d in zip(planes, sense, depths)]
        if len(planes) == 2:
            z1, z2 = centroids
            parts = [(z2 * u - w) / (z2 - z1), (w - z1 * u) / (z2 - z1)]
        else:
            parts = [u.copy()]
        new = [float(math.hypot(p[0], p[1])) / corrections_radius / (rho * area) for p in parts]
        change = max(abs(a - b) for a, b in zip(new, depths))
        depths = new
        if change <= rtol * max(max(depths), diameter):
            break
    else:
        raise PhysicsError("the drilling depths do not converge: the holes are too deep for the distance between "
                           "the correction planes (use a larger drill diameter or radius)")
    holes = []
    for z, s, depth, part in zip(planes, sense, depths, parts):
        angle = float(math.atan2(part[1], part[0]) % (2 * math.pi)) if depth > 0 else 0.0
        radial_shaft = np.array([math.cos(angle), math.sin(angle), 0.0])
        entry = frame.to_mesh(corrections_radius * radial_shaft + np.array([0.0, 0.0, z]))
        axis = frame.vector_to_mesh([0.0, 0.0, float(s)])
        checked = False
        if part_mesh is not None and depth > 0:
            vertices = np.asarray(part_mesh[0], dtype=float)
            faces = np.asarray(part_mesh[1])
            if not _inside(_sample_points(entry, axis, frame.vector_to_mesh(radial_shaft), diameter, depth),
                           vertices, faces):
                raise PhysicsError(f"the hole in the plane at {z:.6g} m (Ø {diameter:.6g} m, {depth:.6g} m deep at "
                                   f"radius {corrections_radius:.6g} m, {math.degrees(angle):.1f}°) leaves the part")
            checked = True
        holes.append(DrilledHole(plane=float(z), angle=angle, radius=float(corrections_radius),
                                 diameter=float(diameter), depth=float(depth), direction=int(s),
                                 mass=float(rho * area * depth), entry=entry, axis=axis,
                                 centroid=entry + 0.5 * depth * axis, inside_checked=checked))
    return tuple(holes)
