"""Reference solids: closed triangle meshes together with their closed-form mass properties.

Each function returns a frozen :class:`ReferenceSolid` holding a watertight, consistently wound mesh
(outward normals, no duplicate vertices, no degenerate faces) and two sets of exact values at unit density
(``density = 1``, so mass = volume in m³ and inertia in m⁵):

* ``exact`` — the **ideal** solid (the smooth cone, torus, sphere ...);
* ``mesh_exact`` — the **faceted polyhedron** the mesh actually bounds, also in closed form.  For the
  polyhedra (box, octahedron, pyramid, prism) the two coincide.

Inertia tensors are about the centre of mass in mesh axes, tensor convention (off-diagonals −∫xy dm),
Eq. (4.13) of the chapter; see ``docs/conventions.md``.  Every solid has its symmetry axis along ``z`` and
its centre of mass at ``center`` (default the origin).  Scale a solid to a real material with
``solid.exact.with_mass(...)`` or by multiplying by the density.

Closed forms used below (M the mass, all about the centre of mass)
------------------------------------------------------------------
Axisymmetric solids (about the symmetry axis ``z`` / about any transverse axis through the centre of mass):

============================  ========================================  ============================================
solid                         I_zz                                      I_xx = I_yy
============================  ========================================  ============================================
cone (R, h), ex. 4.6          3MR²/10                                   3M(R² + h²/4)/20
regular n-gonal pyramid       6kMR²/5                                   3kMR²/5 + 3Mh²/80,  k = (2 + cos(2π/n))/12
cylinder (R, h)               MR²/2                                     M(R²/4 + h²/12)
regular n-gonal prism         2kMR²                                     kMR² + Mh²/12
washer (R_o, R_i, h)          M(R_o² + R_i²)/2                          M[(R_o² + R_i²)/4 + h²/12]
torus (R, r)                  M(R² + 3r²/4)                             M(R²/2 + 5r²/8)
thin ring (r → 0), §4.3.2     MR²                                       MR²/2
sphere (r)                    2Mr²/5                                    2Mr²/5
hollow sphere (r_o, r_i)      (8π/15)ρ(r_o⁵ − r_i⁵)                     same
============================  ========================================  ============================================

Box ``a × b × c``: ``I_xx = M(b² + c²)/12`` (cyclic).  Octahedron ``|x|/a + |y|/b + |z|/c ≤ 1`` (exercise 4.9):
``I_xx = M(b² + c²)/10`` (cyclic).  All products of inertia vanish (mirror symmetry in every coordinate plane
through the centre of mass, or n-fold symmetry with n ≥ 3 about ``z``).  The derivations are in each function's
docstring.

Meshes of revolution and their exact polyhedra
----------------------------------------------
Cone, cylinder, washer, torus and sphere meshes are made by one routine, :func:`_revolve`: a closed
*meridian polygon* ``P`` in the (ρ, z) half plane is swept around ``z`` through ``n = segments`` equal
sectors of angle ``θ = 2π/n``.  A profile edge swept over one sector is an isosceles trapezoid (its four
corners are coplanar), so the mesh bounds the solid ``{ρ((1 − t) e_j + t e_{j+1}) + z ẑ : (ρ, z) ∈ P,
t ∈ [0, 1]}`` whose volume element is ``ρ sin θ dρ dz dt``.  Hence, with ``Q_pq = ∫_P ρ^p z^q dA``:

* ``V = n sin θ · Q_10`` (the ideal solid of revolution has ``2π Q_10``, Pappus),
* ``∫ z dV = n sin θ · Q_11``,  ``∫ z² dV = n sin θ · Q_12``,
* ``∫ (x² + y²) dV = n sin θ · (2 + cos θ)/3 · Q_30``  (``∫_0^1 |(1 − t) e_j + t e_{j+1}|² dt = (2 + cos θ)/3``),
* in-plane products and ``∫ xz dV`` vanish for ``n ≥ 3`` by the n-fold symmetry.

The ``Q_pq`` of the polygon follow exactly from Green's theorem, ``Q_pq = ∮ ρ^(p+1) z^q/(p+1) dz``, with
3-point Gauss–Legendre on each edge (exact for the degree ≤ 4 polynomials that occur).  Each swept edge
contributes the trapezoid area ``n (ρ_1 + ρ_2) sin(θ/2) √(Δz² + Δρ² cos²(θ/2))``.  This gives
``mesh_exact`` for every revolved mesh, independently of the signed-tetrahedron engine, and shows where the
O(1/n²) discretisation error comes from: ``n sin θ / 2π = 1 − θ²/6 + …`` and ``(2 + cos θ)/3 = 1 − θ²/6 + …``
for the sweep, plus the inscribed-polygon error of ``P`` (O(1/rings²)) for curved meridians.

Sphere meshes are UV spheres (``segments`` meridians × ``rings`` latitude bands, poles as single vertices)
rather than icospheres: the UV sphere is a revolved mesh, so it has an exact ``mesh_exact`` and the same
O(1/n²) convergence story as the other solids of revolution (doubling ``segments`` and ``rings`` divides the
error by 4); an icosphere only refines by factors of 4 in face count and has no closed form.
"""

from __future__ import annotations

import math
import os
import struct

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..values import frozen_value
from ..errors import UsageError
from .properties import MassProperties
from ..output import write_bytes
from ..units import length_scale

__all__ = [
    "ReferenceSolid",
    "box",
    "octahedron",
    "cone",
    "pyramid",
    "cylinder",
    "prism",
    "washer",
    "hollow_cylinder",
    "torus",
    "thin_ring",
    "sphere",
    "hollow_sphere",
    "write_stl",
]

#: Default sectors around the axis for curved solids of revolution.
DEFAULT_SEGMENTS = 128
#: Default latitude bands of a sphere (pole to pole).
DEFAULT_SPHERE_RINGS = 64
#: Default sides of the tube cross-section of a torus.
DEFAULT_TORUS_RINGS = 32


@frozen_value
class ReferenceSolid:
    """A closed triangle mesh with the analytic mass properties of the solid it approximates.

    Attributes
    ----------
    name : str
        Human-readable label with the parameters, e.g. ``"cone(R=0.02, h=0.05, n=128)"``.
    vertices : (n, 3) float64
        Vertex coordinates in m, mesh axes; read-only.  No duplicates.
    faces : (m, 3) int64
        Triangles indexing ``vertices``, counter-clockwise seen from outside (outward normals; walls that
        bound a hole or cavity face into it).  Closed, consistently wound, no zero-area faces; read-only.
    exact : MassProperties
        The ideal solid at unit density (kg/m³ = 1): ``mass == volume`` (m³), ``center_of_mass`` (m),
        ``inertia`` (m⁵ = kg·m² at unit density) about the centre of mass, mesh axes, tensor convention;
        ``surface_area`` analytic (m²) or ``nan`` where no closed form is used.
    mesh_exact : MassProperties
        The same quantities for the faceted polyhedron bounded by ``faces``, in closed form.  Equal to
        ``exact`` for polyhedra.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    exact: MassProperties
    mesh_exact: MassProperties

    def __post_init__(self) -> None:
        v = np.array(self.vertices, dtype=np.float64).reshape(-1, 3)
        f = np.array(self.faces, dtype=np.int64).reshape(-1, 3)
        v.flags.writeable = False
        f.flags.writeable = False
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    def transformed(self, rotation: ArrayLike | None = None,
                    translation: ArrayLike | None = None) -> ReferenceSolid:
        """The same solid moved rigidly, ``x ↦ R x + t``: its mesh and both closed forms.

        Parameters
        ----------
        rotation : (3, 3) array_like, optional
            Proper rotation (active), e.g. ``inertia_tool.rotations.rotation_z(angle)``.  Default identity.
        translation : (3,) array_like, optional
            m.  Default zero.

        Returns
        -------
        ReferenceSolid
            Vertices ``R v + t`` (winding unchanged: a proper rotation keeps the outward normals outward);
            ``exact`` and ``mesh_exact`` with ``center_of_mass = R c + t`` and ``inertia = R I Rᵀ``
            (:meth:`MassProperties.transformed`).
        """
        exact = self.exact.transformed(rotation, translation)        # checks the rotation and translation
        mesh_exact = self.mesh_exact.transformed(rotation, translation)
        r = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        t = np.zeros(3) if translation is None else np.asarray(translation, dtype=np.float64).reshape(3)
        return ReferenceSolid(name=self.name, vertices=self.vertices @ r.T + t, faces=self.faces, exact=exact,
                              mesh_exact=mesh_exact)


# -- input checks -------------------------------------------------------------------------------------

def _positive(value: float, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"Expected `{name}` to be a positive number, got {value!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise UsageError(f"Expected `{name}` to be a positive finite number, got {value!r}")
    return x


def _count(value: int, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise UsageError(f"Expected `{name}` to be an integer >= {minimum}, got {value!r}")
    if value < minimum:
        raise UsageError(f"Expected `{name}` to be an integer >= {minimum}, got {value}")
    return int(value)


def _center(center: ArrayLike | None) -> np.ndarray:
    if center is None:
        return np.zeros(3)
    c = np.asarray(center, dtype=np.float64)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise UsageError(f"Expected `center` to be 3 finite numbers, got {center!r}")
    return c


def _props(volume: float, center: np.ndarray, moments: ArrayLike, area: float, name: str) -> MassProperties:
    """Unit-density ``MassProperties`` with a diagonal central tensor ``moments = (I_xx, I_yy, I_zz)``."""
    return MassProperties(mass=volume, volume=volume, center_of_mass=center, inertia=np.diag(moments),
                          surface_area=area, density=1.0, name=name)


def _polygon_circumradius_factor(sides: int) -> tuple[float, float]:
    """Area and in-plane second-moment factor of a regular polygon of unit circumradius.

    Returns ``(A, k)`` with ``A = (n/2) sin(2π/n)`` and ``∫ x² dA = ∫ y² dA = k A R²`` for circumradius ``R``,
    ``k = (2 + cos(2π/n))/12``.  Derivation: the polygon is ``n`` isosceles triangles with apex angle
    ``θ = 2π/n`` and legs ``R`` at the centre; a triangle ``(0, p, q)`` has polar moment
    ``A_t (|p|² + |q|² + p·q)/6 = A_t R² (2 + cos θ)/6`` about its apex, and n-fold symmetry (n ≥ 3) makes
    the in-plane tensor isotropic, so ``∫ x² dA`` is half the polar moment.  ``n → ∞`` gives the disc,
    ``k = 1/4``; ``n = 4`` gives the square of side ``s = R√2``: ``k A R² = R⁴/3 = s⁴/12``.
    """
    theta = 2.0 * math.pi / sides
    return 0.5 * sides * math.sin(theta), (2.0 + math.cos(theta)) / 12.0


# -- solids of revolution -----------------------------------------------------------------------------

def _revolve(profile: np.ndarray, segments: int, center: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sweep a closed meridian polygon around ``z``.

    Parameters
    ----------
    profile : (k, 2) float
        Vertices ``(ρ, z)`` of a simple polygon, counter-clockwise in the (ρ, z) plane (material on the
        left), with ``ρ ≥ 0``; points with ``ρ == 0`` lie on the axis and become single vertices; edges
        along the axis produce no faces.
    segments : int
        Sectors around the axis, ≥ 3.

    Returns
    -------
    vertices (N, 3) float, faces (F, 3) int64
        For the surface ``X(s, φ)`` with tangents ``∂_s`` along the profile and ``∂_φ`` around the axis,
        ``∂_s × ∂_φ`` points to the right of a counter-clockwise profile's travel, i.e. inward; the faces
        ``(A, B, C)`` with ``A → B`` along ``φ`` and ``B → C`` along the profile are therefore wound by
        ``∂_φ × ∂_s``: outward.
    """
    phi = 2.0 * math.pi * np.arange(segments) / segments
    ring = np.column_stack([np.cos(phi), np.sin(phi)])
    blocks, index = [], []
    start = 0
    for rho, z in profile:
        if rho == 0.0:
            blocks.append(np.array([[0.0, 0.0, z]]))
            index.append(np.full(segments, start, dtype=np.int64))
            start += 1
        else:
            blocks.append(np.column_stack([rho * ring, np.full(segments, z)]))
            index.append(start + np.arange(segments, dtype=np.int64))
            start += segments
    vertices = np.vstack(blocks) + center
    faces = []
    count = len(profile)
    nxt = np.roll(np.arange(segments), -1)
    for k in range(count):
        k2 = (k + 1) % count
        on_axis_1, on_axis_2 = profile[k][0] == 0.0, profile[k2][0] == 0.0
        if on_axis_1 and on_axis_2:
            continue
        a, b = index[k], index[k][nxt]          # this profile point at φ_j, φ_{j+1}
        d, c = index[k2], index[k2][nxt]        # next profile point at φ_j, φ_{j+1}
        if on_axis_1:
            faces.append(np.column_stack([a, c, d]))
        elif on_axis_2:
            faces.append(np.column_stack([a, b, c]))
        else:
            faces.append(np.column_stack([a, b, c]))
            faces.append(np.column_stack([a, c, d]))
    return vertices, np.vstack(faces).astype(np.int64)


# 3-point Gauss–Legendre on [0, 1]: exact for polynomials of degree ≤ 5.
_GL_NODES = 0.5 + 0.5 * np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_GL_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


def _profile_moment(profile: np.ndarray, p: int, q: int) -> float:
    """``Q_pq = ∫_P ρ^p z^q dA`` of the counter-clockwise polygon ``profile`` by Green's theorem.

    ``∬ ρ^p z^q dA = ∮ ρ^(p+1) z^q / (p+1) dz``; on an edge ρ and z are linear in the parameter, so the
    integrand is a polynomial of degree ``p + q + 1`` integrated exactly by Gauss–Legendre when ≤ 5.
    """
    start = profile
    delta = np.roll(profile, -1, axis=0) - profile
    rho = start[:, :1] + _GL_NODES * delta[:, :1]          # (k, 3)
    z = start[:, 1:] + _GL_NODES * delta[:, 1:]
    integrand = rho ** (p + 1) * z ** q / (p + 1)
    return float(np.sum((integrand @ _GL_WEIGHTS) * delta[:, 1]))


def _revolved_polyhedron(profile: np.ndarray, segments: int, center: np.ndarray, name: str) -> MassProperties:
    """Closed-form unit-density mass properties of the polyhedron made by :func:`_revolve` (see module notes)."""
    theta = 2.0 * math.pi / segments
    sweep = segments * math.sin(theta)
    volume = sweep * _profile_moment(profile, 1, 0)
    z_c = sweep * _profile_moment(profile, 1, 1) / volume
    zz = sweep * _profile_moment(profile, 1, 2) - volume * z_c ** 2      # ∫ (z − z_c)² dV
    radial = sweep * (2.0 + math.cos(theta)) / 3.0 * _profile_moment(profile, 3, 0)   # ∫ (x² + y²) dV
    nxt = np.roll(profile, -1, axis=0)
    half = 0.5 * theta
    area = segments * math.sin(half) * float(np.sum(
        (profile[:, 0] + nxt[:, 0])
        * np.hypot(nxt[:, 1] - profile[:, 1], (nxt[:, 0] - profile[:, 0]) * math.cos(half))))
    i_xx = 0.5 * radial + zz
    return _props(volume, center + np.array([0.0, 0.0, z_c]), (i_xx, i_xx, radial), area, name)


def _revolved_solid(name: str, profile: ArrayLike, segments: int, center: np.ndarray,
                    exact: MassProperties) -> ReferenceSolid:
    profile = np.asarray(profile, dtype=np.float64)
    vertices, faces = _revolve(profile, segments, center)
    mesh_exact = _revolved_polyhedron(profile, segments, center, name + " [mesh]")
    return ReferenceSolid(name=name, vertices=vertices, faces=faces, exact=exact, mesh_exact=mesh_exact)


def _circle_arc(radius: float, count: int, start: float, stop: float,
                center: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """``count + 1`` points ``(ρ, z) = center + radius (sin α, −cos α)`` for α from ``start`` to ``stop``;
    ρ forced to exactly 0 where ``sin α`` is 0 (poles)."""
    alpha = np.linspace(start, stop, count + 1)
    rho = radius * np.sin(alpha)
    rho[np.isclose(np.sin(alpha), 0.0, atol=1e-15)] = 0.0
    return np.column_stack([center[0] + rho, center[1] - radius * np.cos(alpha)])


# -- public constructors ------------------------------------------------------------------------------

def cone(radius: float, height: float, *, segments: int = DEFAULT_SEGMENTS,
         center: ArrayLike | None = None) -> ReferenceSolid:
    """Right circular cone (exercise 4.6), axis ``+z`` from the base to the apex.

    Parameters
    ----------
    radius : float
        Base radius ``R``, m.
    height : float
        Height ``h``, m.
    segments : int, optional
        Sides of the inscribed base polygon (default 128, ≥ 3); the mesh is the regular n-gonal pyramid
        of :func:`pyramid`, which is its ``mesh_exact``.
    center : (3,) float, optional
        Centre of mass in m (default origin).  The base lies at ``z = center_z − h/4``, the apex at
        ``center_z + 3h/4``.

    Notes
    -----
    With the apex at the origin and ``z`` pointing into the cone, the radius at depth ``z`` is
    ``Rz/h``, so ``V = ∫_0^h π R² z²/h² dz = πR²h/3``.  Centre of mass: ``∫ z dV / V = 3h/4`` from the apex,
    i.e. ``h/4`` above the base (exercise 4.6a).  A disc of radius ρ has ``∫(x² + y²) dA = πρ⁴/2`` and
    ``∫x² dA = πρ⁴/4``; integrating the slices, ``∫(x² + y²) dV = ∫_0^h π(Rz/h)⁴/2 dz = πR⁴h/10``, i.e.
    ``I_zz = 3MR²/10``, and ``∫x² dV = 3MR²/20``.  Along the axis ``∫z² dV = 3Mh²/5`` about the apex, so about
    the centre of mass ``∫(z − 3h/4)² dV = M(3/5 − 9/16)h² = 3Mh²/80``.  By Eq. (4.13),
    ``I_xx = ∫(y² + (z − z_c)²) dV = 3MR²/20 + 3Mh²/80 = 3M(R² + h²/4)/20`` (exercise 4.6b).
    Surface area: base ``πR²`` plus lateral ``πR√(R² + h²)``.
    """
    radius, height = _positive(radius, "radius"), _positive(height, "height")
    segments = _count(segments, "segments", 3)
    c = _center(center)
    mass = math.pi * radius ** 2 * height / 3.0
    i_zz = 0.3 * mass * radius ** 2
    i_xx = 0.15 * mass * (radius ** 2 + height ** 2 / 4.0)
    area = math.pi * radius ** 2 + math.pi * radius * math.hypot(radius, height)
    name = f"cone(R={radius:g}, h={height:g}, n={segments})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    z0 = -height / 4.0
    profile = [(0.0, z0), (radius, z0), (0.0, z0 + height)]
    return _revolved_solid(name, profile, segments, c, exact)


def pyramid(circumradius: float, height: float, sides: int, *, center: ArrayLike | None = None) -> ReferenceSolid:
    """Right pyramid over a regular ``sides``-gon (exercise 4.6 with a polygonal base), apex on ``+z``.

    Parameters
    ----------
    circumradius : float
        Distance ``R`` from the base centre to a base corner, m.  The first corner is on ``+x``.
    height : float
        ``h``, m.
    sides : int
        Number of base corners ``n`` ≥ 3.
    center : (3,) float, optional
        Centre of mass in m (default origin); the base lies at ``center_z − h/4``.

    Notes
    -----
    The slice at height ``z`` above the base is the base polygon scaled by ``s = 1 − z/h``, with area
    ``A s²`` and in-plane ``∫x² dA = k A R² s⁴`` where ``A = (n/2) R² sin(2π/n)`` and
    ``k = (2 + cos(2π/n))/12`` (see ``_polygon_circumradius_factor``).  Hence ``V = Ah/3``, the centre of mass
    is ``h/4`` above the base (the area profile is the cone's), ``∫x² dV = k A R² h/5 = 3kMR²/5`` and
    ``∫(z − z_c)² dV = 3Mh²/80`` as for the cone, so by Eq. (4.13)
    ``I_zz = 6kMR²/5`` and ``I_xx = I_yy = 3kMR²/5 + 3Mh²/80`` (``k → 1/4`` recovers the cone).
    Area: ``A + n · R sin(π/n) · √(h² + R² cos²(π/n))`` (base plus ``n`` triangles of base ``2R sin(π/n)``
    and slant height ``√(h² + apothem²)``).
    """
    circumradius, height = _positive(circumradius, "circumradius"), _positive(height, "height")
    sides = _count(sides, "sides", 3)
    c = _center(center)
    unit_area, k = _polygon_circumradius_factor(sides)
    base = unit_area * circumradius ** 2
    mass = base * height / 3.0
    i_zz = 1.2 * k * mass * circumradius ** 2
    i_xx = 0.6 * k * mass * circumradius ** 2 + 3.0 * mass * height ** 2 / 80.0
    half = math.pi / sides
    area = base + sides * circumradius * math.sin(half) * math.hypot(height, circumradius * math.cos(half))
    name = f"pyramid(R={circumradius:g}, h={height:g}, n={sides})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    z0 = -height / 4.0
    profile = [(0.0, z0), (circumradius, z0), (0.0, z0 + height)]
    solid = _revolved_solid(name, profile, sides, c, exact)
    return ReferenceSolid(name, solid.vertices, solid.faces, exact, exact)


def cylinder(radius: float, height: float, *, segments: int = DEFAULT_SEGMENTS,
             center: ArrayLike | None = None) -> ReferenceSolid:
    """Solid circular cylinder, axis ``z``.

    Parameters
    ----------
    radius, height : float
        ``R`` and ``h`` in m.
    segments : int, optional
        Sides of the inscribed polygon (default 128, ≥ 3); the mesh is the prism of :func:`prism`.
    center : (3,) float, optional
        Centre of mass in m (default origin).

    Notes
    -----
    ``V = πR²h``.  Discs: ``∫(x² + y²) dV = h πR⁴/2`` so ``I_zz = MR²/2``; ``∫x² dV = MR²/4`` and
    ``∫z² dV = Mh²/12`` give ``I_xx = M(R²/4 + h²/12)`` by Eq. (4.13).  Area ``2πR² + 2πRh``.
    The end caps are fans around a centre vertex.
    """
    radius, height = _positive(radius, "radius"), _positive(height, "height")
    segments = _count(segments, "segments", 3)
    c = _center(center)
    mass = math.pi * radius ** 2 * height
    i_zz = 0.5 * mass * radius ** 2
    i_xx = mass * (radius ** 2 / 4.0 + height ** 2 / 12.0)
    area = 2.0 * math.pi * radius * (radius + height)
    name = f"cylinder(R={radius:g}, h={height:g}, n={segments})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    z = height / 2.0
    profile = [(0.0, -z), (radius, -z), (radius, z), (0.0, z)]
    return _revolved_solid(name, profile, segments, c, exact)


def prism(circumradius: float, height: float, sides: int, *, center: ArrayLike | None = None) -> ReferenceSolid:
    """Right prism over a regular ``sides``-gon, axis ``z``; the first corner on ``+x``.

    Parameters
    ----------
    circumradius : float
        Centre-to-corner distance ``R`` of the cross-section, m.
    height : float
        ``h``, m.
    sides : int
        ``n`` ≥ 3.
    center : (3,) float, optional
        Centre of mass in m (default origin).

    Notes
    -----
    With ``A = (n/2) R² sin(2π/n)`` and ``k = (2 + cos(2π/n))/12`` (``∫x² dA = kAR²``): ``V = Ah``,
    ``I_zz = 2kMR²``, ``I_xx = I_yy = kMR² + Mh²/12``; area ``2A + n · 2R sin(π/n) · h``.
    """
    circumradius, height = _positive(circumradius, "circumradius"), _positive(height, "height")
    sides = _count(sides, "sides", 3)
    c = _center(center)
    unit_area, k = _polygon_circumradius_factor(sides)
    base = unit_area * circumradius ** 2
    mass = base * height
    i_zz = 2.0 * k * mass * circumradius ** 2
    i_xx = k * mass * circumradius ** 2 + mass * height ** 2 / 12.0
    area = 2.0 * base + 2.0 * sides * circumradius * math.sin(math.pi / sides) * height
    name = f"prism(R={circumradius:g}, h={height:g}, n={sides})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    z = height / 2.0
    profile = [(0.0, -z), (circumradius, -z), (circumradius, z), (0.0, z)]
    solid = _revolved_solid(name, profile, sides, c, exact)
    return ReferenceSolid(name, solid.vertices, solid.faces, exact, exact)


def washer(outer_radius: float, inner_radius: float, height: float, *, segments: int = DEFAULT_SEGMENTS,
           center: ArrayLike | None = None) -> ReferenceSolid:
    """Washer / hollow cylinder: the annulus ``R_i ≤ ρ ≤ R_o`` extruded over ``|z| ≤ h/2``.

    One closed surface of genus 1: the outer wall faces away from the axis, the inner wall (the hole)
    faces the axis, both away from the material.

    Parameters
    ----------
    outer_radius, inner_radius : float
        ``R_o > R_i > 0`` in m.
    height : float
        ``h`` in m.
    segments : int, optional
        Sides of the inscribed polygons (default 128, ≥ 3).
    center : (3,) float, optional
        Centre of mass in m (default origin).

    Notes
    -----
    A cylinder of radius R_o minus one of radius R_i (moments are additive, Eq. 4.13):
    ``V = π(R_o² − R_i²)h``, ``I_zz = π h (R_o⁴ − R_i⁴)/2 = M(R_o² + R_i²)/2``,
    ``I_xx = M[(R_o² + R_i²)/4 + h²/12]``.  Area ``2π(R_o² − R_i²) + 2π(R_o + R_i)h``.
    """
    outer_radius, inner_radius = _positive(outer_radius, "outer_radius"), _positive(inner_radius, "inner_radius")
    height = _positive(height, "height")
    if not inner_radius < outer_radius:
        raise UsageError(f"Expected `inner_radius` < `outer_radius`, got {inner_radius:g} >= {outer_radius:g}")
    segments = _count(segments, "segments", 3)
    c = _center(center)
    r2 = outer_radius ** 2 + inner_radius ** 2
    mass = math.pi * (outer_radius ** 2 - inner_radius ** 2) * height
    i_zz = 0.5 * mass * r2
    i_xx = mass * (r2 / 4.0 + height ** 2 / 12.0)
    area = (2.0 * math.pi * (outer_radius ** 2 - inner_radius ** 2)
            + 2.0 * math.pi * (outer_radius + inner_radius) * height)
    name = f"washer(R_o={outer_radius:g}, R_i={inner_radius:g}, h={height:g}, n={segments})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    z = height / 2.0
    profile = [(inner_radius, -z), (outer_radius, -z), (outer_radius, z), (inner_radius, z)]
    return _revolved_solid(name, profile, segments, c, exact)


#: Alias of :func:`washer`.
hollow_cylinder = washer


def torus(major_radius: float, minor_radius: float, *, segments: int = DEFAULT_SEGMENTS,
          rings: int = DEFAULT_TORUS_RINGS, center: ArrayLike | None = None) -> ReferenceSolid:
    """Solid torus (ring) around ``z``: the disc ``(ρ − R)² + z² ≤ r²`` swept around the axis.

    Parameters
    ----------
    major_radius : float
        ``R``, distance from the axis to the tube centre, m.
    minor_radius : float
        ``r < R``, tube radius, m.
    segments : int, optional
        Sectors around ``z`` (default 128, ≥ 3).
    rings : int, optional
        Sides of the tube cross-section polygon (default 32, ≥ 3).
    center : (3,) float, optional
        Centre of mass in m (default origin).

    Notes
    -----
    Write ``ρ = R + u`` over the tube disc D (``∫_D dA = πr²``, ``∫_D u dA = 0``, ``∫_D u² dA = ∫_D z² dA = πr⁴/4``).
    Pappus: ``V = 2π ∫_D ρ dA = 2π²Rr²``; ``I_zz = ∫ρ² dV = 2π ∫_D ρ³ dA = 2π · πr² R (R² + 3r²/4) = M(R² + 3r²/4)``;
    ``∫z² dV = 2π R πr⁴/4 = Mr²/4``; so ``I_xx = I_zz/2 + ∫z² dV = M(R²/2 + 5r²/8)`` (Eq. 4.13).
    As ``r → 0`` these tend to the thin ring of §4.3.2, ``MR²`` and ``MR²/2``.  Area ``4π²Rr``.
    """
    major_radius, minor_radius = _positive(major_radius, "major_radius"), _positive(minor_radius, "minor_radius")
    if not minor_radius < major_radius:
        raise UsageError(f"Expected `minor_radius` < `major_radius`, got {minor_radius:g} >= {major_radius:g}")
    segments = _count(segments, "segments", 3)
    rings = _count(rings, "rings", 3)
    c = _center(center)
    big, small = major_radius, minor_radius
    mass = 2.0 * math.pi ** 2 * big * small ** 2
    i_zz = mass * (big ** 2 + 0.75 * small ** 2)
    i_xx = mass * (0.5 * big ** 2 + 0.625 * small ** 2)
    area = 4.0 * math.pi ** 2 * big * small
    name = f"torus(R={big:g}, r={small:g}, n={segments}, m={rings})"
    exact = _props(mass, c, (i_xx, i_xx, i_zz), area, name)
    alpha = 2.0 * math.pi * np.arange(rings) / rings
    profile = np.column_stack([big + small * np.cos(alpha), small * np.sin(alpha)])   # counter-clockwise
    return _revolved_solid(name, profile, segments, c, exact)


def thin_ring(radius: float, wire_radius: float, *, segments: int = 256, rings: int = 8,
              center: ArrayLike | None = None) -> ReferenceSolid:
    """A thin ring (§4.3.2): a torus of major radius ``radius`` and tiny tube radius ``wire_radius``.

    ``exact`` is the torus of :func:`torus`; as ``wire_radius/radius → 0`` its moments tend to the chapter's
    thin ring, ``I_zz = MR²`` and ``I_xx = I_yy = MR²/2`` (perpendicular-axis theorem), with relative
    deviations ``3r²/(4R²)`` and ``5r²/(4R²)``.

    Parameters
    ----------
    radius : float
        Ring radius ``R``, m.
    wire_radius : float
        Wire (tube) radius ``r < R``, m.
    segments : int, optional
        Sectors around ``z`` (default 256).  The mesh's centre line is a regular n-gon inscribed in the
        circle; a thin wire along it has ``I_zz = MR² (2 + cos θ)/3`` (θ = 2π/n), a relative offset
        ``(cos θ − 1)/3 ≈ −1.0e-4`` at n = 256 (``mesh_exact`` includes it).
    rings : int, optional
        Sides of the wire cross-section (default 8).
    center : (3,) float, optional
        Centre of mass in m (default origin).
    """
    solid = torus(radius, wire_radius, segments=segments, rings=rings, center=center)
    name = f"thin_ring(R={float(radius):g}, r={float(wire_radius):g}, n={segments}, m={rings})"
    return ReferenceSolid(name, solid.vertices, solid.faces, solid.exact, solid.mesh_exact)


def sphere(radius: float, *, segments: int = DEFAULT_SEGMENTS, rings: int = DEFAULT_SPHERE_RINGS,
           center: ArrayLike | None = None) -> ReferenceSolid:
    """Solid sphere as a UV mesh (see the module notes for why UV rather than an icosphere).

    Parameters
    ----------
    radius : float
        ``r`` in m.
    segments : int, optional
        Meridians (default 128, ≥ 3).
    rings : int, optional
        Latitude bands from pole to pole (default 64, ≥ 2); the poles are single vertices.
    center : (3,) float, optional
        Centre in m (default origin).

    Notes
    -----
    ``V = 4πr³/3``; ``∫x² dV = (1/3)∫ρ² dV = (1/3) 4π r⁵/5``, so ``I = ∫(y² + z²) dV = (8π/15) r⁵ = 2Mr²/5``.
    Area ``4πr²``.
    """
    radius = _positive(radius, "radius")
    segments = _count(segments, "segments", 3)
    rings = _count(rings, "rings", 2)
    c = _center(center)
    mass = 4.0 * math.pi * radius ** 3 / 3.0
    moment = 0.4 * mass * radius ** 2
    name = f"sphere(r={radius:g}, n={segments}, m={rings})"
    exact = _props(mass, c, (moment, moment, moment), 4.0 * math.pi * radius ** 2, name)
    profile = _circle_arc(radius, rings, 0.0, math.pi)           # south pole → north pole
    return _revolved_solid(name, profile, segments, c, exact)


def hollow_sphere(outer_radius: float, inner_radius: float, *, segments: int = DEFAULT_SEGMENTS,
                  rings: int = DEFAULT_SPHERE_RINGS, center: ArrayLike | None = None) -> ReferenceSolid:
    """Spherical shell ``r_i ≤ |x| ≤ r_o``: two closed UV shells, the outer facing out, the inner facing into
    the cavity (away from the material).

    Parameters
    ----------
    outer_radius, inner_radius : float
        ``r_o > r_i > 0`` in m.
    segments, rings : int, optional
        As for :func:`sphere` (defaults 128 and 64), used for both shells.
    center : (3,) float, optional
        Centre in m (default origin).

    Notes
    -----
    Sphere minus sphere (moments are additive, Eq. 4.13): ``V = 4π(r_o³ − r_i³)/3``,
    ``I = (8π/15)(r_o⁵ − r_i⁵) = (2/5) M (r_o⁵ − r_i⁵)/(r_o³ − r_i³)``, area ``4π(r_o² + r_i²)``.
    """
    outer_radius, inner_radius = _positive(outer_radius, "outer_radius"), _positive(inner_radius, "inner_radius")
    if not inner_radius < outer_radius:
        raise UsageError(f"Expected `inner_radius` < `outer_radius`, got {inner_radius:g} >= {outer_radius:g}")
    segments = _count(segments, "segments", 3)
    rings = _count(rings, "rings", 2)
    c = _center(center)
    mass = 4.0 * math.pi * (outer_radius ** 3 - inner_radius ** 3) / 3.0
    moment = 8.0 * math.pi * (outer_radius ** 5 - inner_radius ** 5) / 15.0
    area = 4.0 * math.pi * (outer_radius ** 2 + inner_radius ** 2)
    name = f"hollow_sphere(r_o={outer_radius:g}, r_i={inner_radius:g}, n={segments}, m={rings})"
    exact = _props(mass, c, (moment, moment, moment), area, name)
    outer = _circle_arc(outer_radius, rings, 0.0, math.pi)      # south → north
    inner = _circle_arc(inner_radius, rings, math.pi, 0.0)      # north → south: the cavity wall
    return _revolved_solid(name, np.vstack([outer, inner]), segments, c, exact)


def box(length_x: float, length_y: float, length_z: float, *, center: ArrayLike | None = None) -> ReferenceSolid:
    """Rectangular box with edges along the axes (12 triangles).

    Parameters
    ----------
    length_x, length_y, length_z : float
        Full edge lengths ``a, b, c`` in m.
    center : (3,) float, optional
        Centre in m (default origin).

    Notes
    -----
    ``V = abc``; ``∫x² dV = bc ∫_{−a/2}^{a/2} x² dx = Ma²/12``, so ``I_xx = M(b² + c²)/12`` (cyclic, Eq. 4.13).
    Area ``2(ab + bc + ca)``.
    """
    a, b, cz = (_positive(length_x, "length_x"), _positive(length_y, "length_y"), _positive(length_z, "length_z"))
    c = _center(center)
    mass = a * b * cz
    moments = (mass * (b * b + cz * cz) / 12.0, mass * (a * a + cz * cz) / 12.0, mass * (a * a + b * b) / 12.0)
    name = f"box({a:g} x {b:g} x {cz:g})"
    exact = _props(mass, c, moments, 2.0 * (a * b + b * cz + cz * a), name)
    corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.float64)
    vertices = (corners - 0.5) * np.array([a, b, cz]) + c          # index = 4i + 2j + k
    faces = np.array([
        [0, 1, 3], [0, 3, 2],      # x = −a/2, normal −x
        [4, 6, 7], [4, 7, 5],      # x = +a/2, normal +x
        [0, 4, 5], [0, 5, 1],      # y = −b/2, normal −y
        [2, 3, 7], [2, 7, 6],      # y = +b/2, normal +y
        [0, 2, 6], [0, 6, 4],      # z = −c/2, normal −z
        [1, 5, 7], [1, 7, 3],      # z = +c/2, normal +z
    ], dtype=np.int64)
    return ReferenceSolid(name, vertices, faces, exact, exact)


def octahedron(half_x: float, half_y: float, half_z: float, *, center: ArrayLike | None = None) -> ReferenceSolid:
    """The octahedron ``|x|/a + |y|/b + |z|/c ≤ 1`` of exercise 4.9 (8 triangles).

    Parameters
    ----------
    half_x, half_y, half_z : float
        Half-diagonals ``a, b, c`` in m: the corners are ``(±a, 0, 0)``, ``(0, ±b, 0)``, ``(0, 0, ±c)``.
        Exercise 4.9's figure has ``h > b > a``; we read ``a, b, h`` as the half-diagonals along
        ``x, y, z`` (so ``half_z = h``).
    center : (3,) float, optional
        Centre in m (default origin).

    Notes
    -----
    Each octant holds the tetrahedron ``x/a + y/b + z/c ≤ 1`` (``x, y, z ≥ 0``), the image of the unit simplex
    under ``diag(a, b, c)``.  The unit simplex has ``∫ dV = 1/6`` and ``∫u² dV = 2!/5! = 1/60``, so
    ``V = 8abc/6 = 4abc/3`` and ``∫x² dV = 8a³bc/60 = Va²/10``.  All products vanish by the mirror
    symmetries, so the tensor about the centre is diagonal (the coordinate axes are principal) with
    ``I_xx = M(b² + c²)/10``, ``I_yy = M(a² + c²)/10``, ``I_zz = M(a² + b²)/10`` (Eq. 4.13).  With
    ``a < b < h`` the largest moment is ``I_xx`` (about the shortest diagonal), the smallest ``I_zz`` (about the
    longest) and ``I_yy`` is intermediate: steady spins about the ``x`` or ``z`` diagonal are stable, about ``y``
    unstable (exercise 4.9b, §4.4.1); only ``x`` survives dissipation.
    Area: 8 congruent faces with corners ``(a,0,0), (0,b,0), (0,0,c)``, each ``½√(a²b² + b²c² + c²a²)``.
    """
    a, b, cz = _positive(half_x, "half_x"), _positive(half_y, "half_y"), _positive(half_z, "half_z")
    c = _center(center)
    mass = 4.0 * a * b * cz / 3.0
    moments = (mass * (b * b + cz * cz) / 10.0, mass * (a * a + cz * cz) / 10.0, mass * (a * a + b * b) / 10.0)
    area = 4.0 * math.sqrt((a * b) ** 2 + (b * cz) ** 2 + (cz * a) ** 2)
    name = f"octahedron(a={a:g}, b={b:g}, c={cz:g})"
    exact = _props(mass, c, moments, area, name)
    vertices = np.array([[a, 0, 0], [-a, 0, 0], [0, b, 0], [0, -b, 0], [0, 0, cz], [0, 0, -cz]],
                        dtype=np.float64) + c
    faces = []
    for sx in (0, 1):
        for sy in (2, 3):
            for sz in (4, 5):
                # (x-corner, y-corner, z-corner) is counter-clockwise seen from outside when the octant has
                # an even number of negative signs.
                negatives = (sx == 1) + (sy == 3) + (sz == 5)
                faces.append([sx, sy, sz] if negatives % 2 == 0 else [sx, sz, sy])
    return ReferenceSolid(name, vertices, np.array(faces, dtype=np.int64), exact, exact)


# -- output -------------------------------------------------------------------------------------------

def write_stl(solid: ReferenceSolid, path: str | os.PathLike[str], *, binary: bool = True, units: str = "m") -> Path:
    """Write ``solid``'s mesh as an STL file (atomically, replacing an existing file:
    :func:`inertia_tool.output.write_bytes`).

    Parameters
    ----------
    solid : ReferenceSolid
        The mesh (coordinates in m).
    path : str or path-like
        Output file.
    binary : bool, optional
        Binary STL (default; 50 bytes per triangle, float32 coordinates) or ASCII (``%.9g``, which
        round-trips float32 exactly but not float64).
    units : str, optional
        Length unit of the coordinates in the file (``"m"``, ``"mm"`` ... of ``inertia_tool.units``);
        STL carries no units, so readers must be told the same unit.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    scale = 1.0 / length_scale(units)
    path = Path(path)
    tri = solid.vertices[solid.faces] * scale                          # (m, 3, 3)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norms = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, norms, out=np.zeros_like(normals), where=norms > 0)
    if binary:
        record = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
        data = np.zeros(len(tri), dtype=record)
        data["normal"] = normals
        data["vertices"] = tri
        header = f"inertia_tool {solid.name} units={units}".encode("ascii", "replace")[:80].ljust(80, b" ")
        write_bytes(path, header + struct.pack("<I", len(tri)) + data.tobytes())
    else:
        label = "".join(ch if ch.isalnum() else "_" for ch in solid.name)
        lines = [f"solid {label}"]
        for n, t in zip(normals, tri):
            lines.append(f"  facet normal {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}")
            lines.append("    outer loop")
            lines.extend(f"      vertex {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}" for p in t)
            lines.append("    endloop")
            lines.append("  endfacet")
        lines.append(f"endsolid {label}")
        write_bytes(path, ("\n".join(lines) + "\n").encode("ascii"))
    return path
