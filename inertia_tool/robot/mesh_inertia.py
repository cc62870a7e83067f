"""MuJoCo's mesh inertia modes other than the solid: ``<mesh inertia="convex">`` and ``inertia="legacy"``.

An MJCF mesh asset says how MuJoCo's compiler takes its mass and inertia when they come from geometry
(MuJoCo 3.x; the default is ``legacy``): ``exact`` integrates the solid the triangles bound (what this tool
always computes for a closed mesh), ``shell`` puts the mass on the surface (``inertia_tool.robot.geometry``),
``convex`` integrates the convex hull of the vertices, and ``legacy`` sums the *absolute* volumes of the
tetrahedra from a centre to each triangle (for a non-convex mesh this counts parts of the volume twice: an
L-shaped block of 4 m³ gets 4.16 m³).  With the model's own densities (``--density model``) a mesh that
names ``convex`` or ``legacy`` is taken the way the model asks, so that the tool gives the body MuJoCo gives
it; a mesh without the attribute is integrated as the solid.

Both functions take the mesh as placed in its element frame (reference transform and scale applied) and
return unit-density properties about their centre of mass, element axes.
"""

from __future__ import annotations

import numpy as np

from ..errors import InvalidMeshError
from ..integrals import second_moment_to_inertia, volume_moments
from ..mass.properties import MassProperties

__all__ = ["convex_hull_properties", "legacy_properties"]


def convex_hull_properties(vertices: np.ndarray, *, source: str) -> MassProperties:
    """Unit-density mass properties of the convex hull of ``vertices`` (MuJoCo's ``inertia="convex"``).

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    source : str
        The mesh, for messages.

    Returns
    -------
    MassProperties
        ``mass == volume`` (m³); centre in m; inertia about it per kg/m³, the exact integral over the hull
        (Qhull's facets, each turned to face away from the hull's interior).

    Raises
    ------
    InvalidMeshError
        The points span no volume (fewer than four, or all in one plane).
    """
    from scipy.spatial import ConvexHull, QhullError
    points = np.asarray(vertices, dtype=np.float64)
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError) as exc:
        raise InvalidMeshError(f"{source}: inertia=\"convex\": expected points spanning a volume, got "
                               f"{len(points)} points that do not ({str(exc).splitlines()[0][:80]})") from None
    faces = hull.simplices.copy()
    p = points[faces]
    outward = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), hull.equations[:, :3])
    faces[outward < 0] = faces[outward < 0][:, ::-1]
    moments = volume_moments(points, faces)
    return MassProperties(mass=moments.volume, volume=moments.volume, center_of_mass=moments.centroid,
                          inertia=second_moment_to_inertia(moments.second_moment), surface_area=moments.area,
                          density=1.0, name=source)


def legacy_properties(vertices: np.ndarray, faces: np.ndarray, *, source: str) -> MassProperties:
    """Unit-density mass properties by MuJoCo's legacy mesh inertia (``inertia="legacy"``).

    MuJoCo's compiler (``mjCMesh`` in MuJoCo 3.x/4.0, read from its source): with ``a_i``, ``c_i`` the area
    and centroid of triangle ``i`` and ``f = Σ a_i c_i / Σ a_i`` the centroid of the surface,

    1. the centre is ``c = Σ v_i (3 c_i + f)/4 / Σ v_i`` with ``v_i = |det(D − f, E − f, F − f)|/6`` the
       absolute volume of the tetrahedron from ``f`` to the triangle ``DEF``;
    2. the volume is ``V = Σ w_i``, ``w_i`` the absolute volume of the tetrahedron from ``c``, and the second
       moment about ``c`` is ``C = Σ w_i/20 (S Sᵀ + D Dᵀ + E Eᵀ + F Fᵀ)`` with corners relative to ``c`` and
       ``S = D + E + F`` (the second moment of a tetrahedron with one corner at the origin); the inertia is
       ``tr(C) 𝟙 − C`` (Eq. 4.13 of Chapter 4, "Rigid Body Motion", per unit density).

    For a convex mesh every tetrahedron is positive from an interior point and this is the exact solid; for
    a non-convex one it is not the solid of the mesh.

    Parameters
    ----------
    vertices : (n, 3) float
        m.
    faces : (m, 3) int
    source : str
        The mesh, for messages.

    Returns
    -------
    MassProperties
        ``mass == volume == V`` (m³), centre ``c`` (m), inertia about ``c`` per kg/m³, element axes.

    Raises
    ------
    InvalidMeshError
        A surface of no area or no volume (MuJoCo refuses it too).
    """
    points = np.asarray(vertices, dtype=np.float64)
    corners = points[np.asarray(faces)]
    doubled = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    area = 0.5 * float(doubled.sum())
    if not area > 0:
        raise InvalidMeshError(f"{source}: inertia=\"legacy\": expected a surface of positive area, got none")
    centroids = corners.mean(axis=1)
    surface_centre = (0.5 * doubled) @ centroids / area
    relative = corners - surface_centre
    first = np.abs(np.linalg.det(relative)) / 6
    if not first.sum() > 0:
        raise InvalidMeshError(f"{source}: inertia=\"legacy\": expected a surface enclosing a volume, got none")
    centre = (first @ (0.75 * centroids + 0.25 * surface_centre)) / first.sum()
    relative = corners - centre
    weights = np.abs(np.linalg.det(relative)) / 6
    volume = float(weights.sum())
    total = relative.sum(axis=1)
    second = (np.einsum("i,ij,ik->jk", weights, total, total)
              + np.einsum("i,ivj,ivk->jk", weights, relative, relative)) / 20
    return MassProperties(mass=volume, volume=volume, center_of_mass=centre,
                          inertia=second_moment_to_inertia(second), surface_area=area, density=1.0, name=source)
