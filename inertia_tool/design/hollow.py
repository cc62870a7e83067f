"""``spin_it``: hollow a part so that it spins the way the user wants (yo-yo or top), verified by re-analysis.

Pipeline (one function per stage):

1. the checked mesh and its exact mass properties (the engine, ``inertia_tool.mass_properties``);
2. a voxel grid of its inside (``design.grid``): the cells whose centres lie deeper than the wall (plus half a
   cell diagonal, for the approximate distance transform) may be removed;
3. the quadric cavity that minimises the mode's objective of the mass moments (``design.optimize``,
   ``design.moments``);
4. the cavity as a closed mesh — the zero level set of ``min(depth − wall, −q)`` by marching tetrahedra
   (``design.tetra``), kept ``wall`` from the part's surface and added to it turned inward (no boolean);
5. the wall measured exactly (distance from every cavity vertex to the outer surface, ``design.grid``), and
   the hollowed mesh re-analysed by the exact engine: every number reported comes from that re-analysis.

Frames: the **design frame** has its origin at the ``through`` point (yo-yo; the part's centre of mass if none
is given) or the ``pivot`` (top), and axes ``(e1, e2, axis)`` with ``(e1, e2)`` from
``rotations.perpendicular_basis`` (right-handed).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import AsymmetricTopWarning, NoRoomError, PhysicsError, PivotOffPartWarning, UsageError
from ..tolerances import EQUAL_MOMENTS_RTOL, PIVOT_GAP_RTOL
from .carried import carry_repair_bounds
from .cavity_mesh import DEPTH_MARGIN, cut_pocket  # noqa: F401  (DEPTH_MARGIN: used by the benchmark too)
from .grid import SurfaceTree, interior_grid, surface_distance
from .limits import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from .moments import OBJECTIVES, frame_quantities, moment_vector, top_threshold_measure
from .optimize import QuadricCavity, optimize_quadric_cavity

if TYPE_CHECKING:  # pragma: no cover
    from .insert import QuadricInsert

__all__ = ["SpinDesignMetrics", "SpinItResult", "spin_it", "design_metrics", "principal_tilt", "MODES",
           "DEFAULT_RESOLUTION"]

#: ``"yoyo"`` (free spin, §4.4.1) and ``"top"`` (heavy symmetric top on a pivot, §4.4.3).
MODES = ("yoyo", "top")




@dataclass(frozen=True)
class SpinDesignMetrics:
    """How well a body spins about the requested axis (from its exact mass properties).

    Attributes
    ----------
    mass : float
        kg.
    axis_moment : float
        Moment about the axis through the centre of mass parallel to the requested axis, kg·m² (yo-yo), or
        ``I3`` about the symmetry axis through the pivot (top).
    next_moment : float
        Yo-yo: the larger principal moment of the central tensor in the plane ⟂ the axis, kg·m².
        Top: the transverse moment ``I1`` about the pivot (mean of the two), kg·m².
    moment_ratio : float
        ``axis_moment / next_moment`` (> 1: the axis carries the largest moment).
    axis_tilt : float
        rad: yo-yo, angle between the requested axis and the nearest principal eigenspace of the central
        tensor (``principal_tilt``: equal moments form one, in which every direction is principal); top,
        angle between the requested axis and the pivot → centre-of-mass line.
    axis_offset : float or None
        Distance of the centre of mass from the requested axis line, m; ``None`` for a yo-yo without a
        ``through`` point.
    nearest_principal : str
        ``"minor"``, ``"intermediate"`` or ``"major"``: the principal axis nearest the requested one.
    epsilon_coefficient : float
        ``c`` of ``ε̈ = c ω² ε`` (§4.4.1) for that principal axis: negative is a stable spin, and
        ``√(−c)`` is the wobble frequency per unit spin.
    sleeping_threshold : float or None
        Top: the spin ``√(4 I1 M g l)/I3`` (rad/s) above which the upright top sleeps (§4.4.3, from
        ``inertia_tool.dynamics.top``); ``None`` for a yo-yo.
    transverse_asymmetry : float or None
        Top: ``inertia_tool.dynamics.top``'s measure of how far the body is from a symmetric top about the pivot
        (0 for a symmetric top); ``None`` for a yo-yo.
    height : float or None
        Top: distance ``l`` from the pivot to the centre of mass, m.
    """

    mass: float
    axis_moment: float
    next_moment: float
    moment_ratio: float
    axis_tilt: float
    axis_offset: float | None
    nearest_principal: str
    epsilon_coefficient: float
    sleeping_threshold: float | None = None
    transverse_asymmetry: float | None = None
    height: float | None = None


@dataclass(frozen=True)
class SpinItResult:
    """A hollowed part and the evidence that it spins better.

    Attributes
    ----------
    mode : str
        ``"yoyo"`` or ``"top"``.
    axis : (3,) float
        Unit spin axis, mesh axes.
    origin : (3,) float
        Design-frame origin (through point, part centre of mass or pivot), m, mesh axes.
    wall : float
        Requested minimum wall thickness, m.
    vertices : (n, 3) float
        The hollowed part (outer surface and cavity surface, outward-wound), m, mesh axes.
    faces : (m, 3) int
    before, after : MassProperties
        Exact mass properties of the solid part and of the hollowed mesh (re-analysed).
    metrics_before, metrics_after : SpinDesignMetrics
        From ``before`` and ``after``.
    measured_wall : float
        Smallest distance from a vertex of the cavity surface to the outer surface, m, exact up to
        ``wall + cell_size`` (a larger wall reads as that cap); ``inf`` without cavity.
    cavity_volume : float
        Removed volume, m³ (``before.volume − after.volume``).
    cavity : QuadricCavity
        The optimised quadric (design-frame coordinates) and its objective on the cells.
    cell_size : float
        Voxel edge, m.
    allowed_cells, removed_cells : int
        Cells deep enough to be removed, and removed by the optimum.
    objective_before, objective_after : float
        The mode's objective (``design.moments``) of the solid part and of the re-analysed hollowed part.
    optimisation_seconds : float
        Time spent optimising the quadric.
    objective_evaluations : int
        Evaluations of the objective in all optimisations.
    seconds : float
        Wall-clock time of the whole design.
    insert_vertices, insert_faces : (k, 3) float, (l, 3) int, or None
        The dense insert (m, mesh axes), when one was asked for and helps; it fills a pocket of the part.
    insert : MassProperties or None
        The insert alone, re-analysed at ``insert_density`` (``after`` includes it).
    insert_density : float or None
        kg/m³ of the insert material.
    insert_shape : str or None
        ``"quadric"`` or ``"ring"`` (a rim about the spin axis; ``design.insert``), None without an insert.
    loaded : tuple or None
        The checked input ``(vertices, faces, before, name)``, for another attempt (``spin_it(loaded=…)``).
    """

    mode: str
    axis: np.ndarray
    origin: np.ndarray
    wall: float
    vertices: np.ndarray
    faces: np.ndarray
    before: object
    after: object
    metrics_before: SpinDesignMetrics
    metrics_after: SpinDesignMetrics
    measured_wall: float
    cavity_volume: float
    cavity: QuadricCavity
    cell_size: float
    allowed_cells: int
    removed_cells: int
    objective_before: float
    objective_after: float
    optimisation_seconds: float
    objective_evaluations: int
    seconds: float
    insert_vertices: np.ndarray | None = None
    insert_faces: np.ndarray | None = None
    insert: object = None
    insert_density: float | None = None
    insert_shape: str | None = None
    loaded: tuple | None = field(default=None, repr=False, compare=False)


def _unit(vector, name: str) -> np.ndarray:
    v = np.asarray(vector, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or not np.linalg.norm(v) > 0:
        raise UsageError(f"Expected `{name}` to be a finite non-zero 3-vector, got {vector!r}")
    return v / np.linalg.norm(v)


def _point(value, name: str) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise UsageError(f"Expected `{name}` to be a finite 3-vector (m), got {value!r}")
    return v


def design_frame(axis) -> np.ndarray:
    """(3, 3) with columns ``e1, e2, axis`` (``rotations.perpendicular_basis``), right-handed."""
    from ..rotations import perpendicular_basis
    e1, e2 = perpendicular_basis(axis)
    return np.column_stack([e1, e2, axis])


def principal_tilt(inertia, axis, *, equal_rtol: float = EQUAL_MOMENTS_RTOL) -> tuple[float, int]:
    """Angle between a direction and the nearest principal **eigenspace** of a tensor, and that eigenspace.

    Moments equal within ``equal_rtol`` of the largest (the tolerance under which ``principal_axes`` calls two
    moments equal and the axes in their plane an arbitrary choice) form one eigenspace, and the angle is
    measured to that space, not to the arbitrary basis vectors chosen in it: for a body of revolution the
    symmetry axis is an eigenspace of its own and every transverse direction lies in the other, at angle 0.
    Moments farther apart than that are distinct, and their axes are judged one by one (the rule is never
    looser for a tensor without equal moments).

    Parameters
    ----------
    inertia : (3, 3) array_like
        Symmetric inertia tensor (kg·m², any reference point; spin-it passes the central one).
    axis : (3,) array_like
        Unit direction, same axes.
    equal_rtol : float
        Relative tolerance of equal moments (default ``tolerances.EQUAL_MOMENTS_RTOL``).

    Returns
    -------
    (float, int)
        The angle (rad, in [0, π/2]) and the index, in ascending moment order, of the principal axis of that
        eigenspace nearest the direction.
    """
    moments, vectors = np.linalg.eigh(np.asarray(inertia, dtype=np.float64))
    direction = np.asarray(axis, dtype=np.float64)
    cosines = np.abs(vectors.T @ direction)
    tol = equal_rtol * float(np.max(np.abs(moments)))
    groups, start = [], 0
    for k in range(1, 4):
        if k == 3 or moments[k] - moments[k - 1] > tol:
            groups.append(list(range(start, k)))
            start = k
    best_angle, best_index = math.pi / 2, int(np.argmax(cosines))
    for group in groups:
        basis = vectors[:, group]
        inside = basis @ (basis.T @ direction)          # the direction's projection on the eigenspace
        angle = float(math.atan2(np.linalg.norm(direction - inside), np.linalg.norm(inside)))   # no acos rounding
        if angle < best_angle or (angle == best_angle and best_index not in group):
            best_angle, best_index = angle, max(group, key=lambda k: cosines[k])
    return best_angle, int(best_index)


def design_metrics(props, mode: str, axis, origin=None, *, gravity: float = 9.80665) -> SpinDesignMetrics:
    """:class:`SpinDesignMetrics` of a body spinning about an axis.

    Parameters
    ----------
    props : MassProperties
        The body.
    mode : {"yoyo", "top"}
        Free spin (§4.4.1) or heavy top on a pivot (§4.4.3).
    axis : (3,) array_like
        Spin axis direction, mesh axes.
    origin : (3,) array_like, optional
        Yo-yo: a point of the axis (``None``: only the direction counts); top: the pivot (required). m.
    gravity : float
        m/s², for the sleeping-top threshold.

    Returns
    -------
    SpinDesignMetrics
    """
    from ..dynamics.spin_stability import stability

    axis = _unit(axis, "axis")
    report = stability(props)
    tilt, nearest = principal_tilt(props.inertia, axis)
    entry = report.axes[nearest]
    offset = None
    if origin is not None:
        rel = props.center_of_mass - _point(origin, "origin")
        offset = float(np.linalg.norm(rel - (rel @ axis) * axis))
    if mode == "yoyo":
        frame = design_frame(axis)
        central = frame.T @ props.inertia @ frame
        transverse = np.linalg.eigvalsh(central[:2, :2])
        return SpinDesignMetrics(mass=props.mass, axis_moment=float(central[2, 2]),
                                 next_moment=float(transverse[1]),
                                 moment_ratio=float(central[2, 2] / transverse[1]),
                                 axis_tilt=tilt, axis_offset=offset,
                                 nearest_principal=entry.name, epsilon_coefficient=float(entry.coefficient))
    from ..dynamics.top import heavy_top_on_pivot
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AsymmetricTopWarning)      # reported as transverse_asymmetry
        top = heavy_top_on_pivot(props, origin, theta0=0.0, omega3=1.0, g=gravity)
    return SpinDesignMetrics(mass=props.mass, axis_moment=top.axial_moment, next_moment=top.transverse_moment,
                             moment_ratio=top.axial_moment / top.transverse_moment,
                             axis_tilt=float(math.acos(min(1.0, abs(top.symmetry_axis @ axis)))),
                             axis_offset=offset, nearest_principal=entry.name,
                             epsilon_coefficient=float(entry.coefficient),
                             sleeping_threshold=top.critical_sleeping_spin,
                             transverse_asymmetry=top.transverse_asymmetry, height=top.length)


def _load(source, units: str | None, density, material, mass, repair: bool = False, assume: tuple[str, ...] = ()):
    """Checked vertices and faces (m, outward-wound) and the exact mass properties of the solid part."""
    from ..mass.pipeline import mass_properties, resolve_density
    from ..mesh.hole_assumptions import UserAssumptions
    from ..mesh.options import LoadOptions
    from ..mesh.prepare import prepare_mesh
    from ..mesh.read import load_mesh

    rho, _ = resolve_density(density=density, material=material, mass=mass)
    assumed = UserAssumptions(LoadOptions(repair=bool(repair), assume=tuple(assume)).assume)   # UsageError
    from ..mesh.plausibility import warn_implausible_size

    raw = load_mesh(source, units=units)
    kinds = {(t.material, t.density) for t in raw.parts if t.role == "part"}
    if len(kinds) > 1:          # a multi-material file (mesh/parts.py) would be hollowed as one density
        from ..errors import UsageError
        listed = ", ".join(sorted(f"{t.name} ({t.material})" for t in raw.parts if t.role == "part"))[:300]
        raise UsageError(f"{raw.source}: spin-it designs a part of one material, and the file holds parts of "
                         f"several ({listed}); export the part alone")
    warn_implausible_size(raw, stacklevel=4)
    prepared = prepare_mesh(raw, repair=repair, assume=assumed)
    props = mass_properties((prepared.vertices, prepared.faces), density=rho, mass=mass, name=raw.source,
                            units="m")           # already converted: metres stated, not assumed
    if prepared.report.uncertainty is not None:   # a repaired estimate: its report (bounds, certificate), not the
        props = replace(props, mesh=prepared.report)     # re-analysis's of the patched surface
    return prepared.vertices, prepared.faces, props, raw.source


def _exact_near_wall(grid, vertices, faces, wall: float, tree=None):
    """The grid with exact depths (``design.grid.surface_distance``, capped at ``wall + 2h``) at the inside cells
    whose approximate depth lies in ``[wall − h, wall + 2h]``, where the allowed region is decided."""
    from dataclasses import replace

    h = grid.spacing
    band = grid.inside & (grid.signed_distance >= wall - h) & (grid.signed_distance <= wall + 2 * h)
    index = np.nonzero(band)
    if len(index[0]) == 0:
        return grid
    depth = grid.signed_distance.copy()
    depth[index] = surface_distance(grid.centers(index), vertices, faces, cutoff=wall + 2 * h, tree=tree)
    return replace(grid, signed_distance=depth)


#: Cells beyond the wall up to which the grid's depths are computed (``interior_grid(depth_cap=…)``): the cavity
#: field asks for ``wall`` + up to 2 cells of margin (``cavity_mesh``), and its smooth minimum reaches 2 more.
DEPTH_CAP_CELLS = 6

#: A cavity is meshed when the region deeper than the wall spans about this many cells across.
_CELLS_ACROSS = 3.0


def _too_thin(name: str, grid, wall: float, extent: float, resolution: int, *, chosen: int = 0) -> NoRoomError:
    """Why no cavity could be made, and the resolution that would leave room: the region deeper than the wall
    is ``2 (D − wall)`` thick at the deepest point ``D``; it must span ``_CELLS_ACROSS`` cells."""
    h = grid.spacing
    deepest = float(np.max(grid.signed_distance[grid.inside])) if np.any(grid.inside) else 0.0
    why = ("no cell lies deeper than the {w} mm wall plus half a cell" if not chosen else
           f"the {chosen} cells the optimiser chose are too thin a layer to make a cavity of")
    head = (f"{name}: no room for a cavity at resolution {resolution} (cells of {h * 1e3:.3g} mm): "
            + why.replace("{w}", f"{wall * 1e3:.3g}") + "; the part is "
            + ("at least" if deepest >= grid.depth_cap else "about") + f" {deepest * 1e3:.3g} mm deep at its thickest")
    if deepest + h <= wall:      # the grid's depth is within a cell of the true one (design.grid)
        return NoRoomError(head + " — nowhere deeper than the wall: a thinner `wall` is the only way")
    if deepest <= wall:
        return NoRoomError(head + f" — a resolution of about {MAX_RESOLUTION} (the largest) may find room; else "
                           "use a thinner `wall`", suggested=MAX_RESOLUTION)
    needed = int(math.ceil(extent * _CELLS_ACROSS / (2.0 * (deepest - wall))))
    if needed > MAX_RESOLUTION:
        return NoRoomError(head + f" — a resolution of about {needed} would be needed, above the largest "
                           f"({MAX_RESOLUTION}): use a thinner `wall`", suggested=MAX_RESOLUTION)
    return NoRoomError(head + f" — try `resolution` {max(needed, resolution + 1)}",
                       suggested=max(needed, resolution + 1))


def _warn_pivot_off_part(name: str, pivot: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                         tree: SurfaceTree, extent: float, units: str | None = None) -> None:
    """``PivotOffPartWarning`` when a top's pivot lies outside the part, farther than ``PIVOT_GAP_RTOL`` of its
    largest extent from the surface (inside: the generalized winding number above one half).  Lengths in the
    message are in ``units`` (the user's, as the pivot was given), metres without."""
    from ..mesh.winding import winding_numbers
    from ..units import length_scale

    gap = float(np.sqrt(tree.squared_distance(np.asarray(pivot, dtype=np.float64)[None, :])[0]))
    if gap <= PIVOT_GAP_RTOL * extent:
        return
    # one point: the exact solid-angle sum (the project's winding numbers), not libigl's approximation
    if float(winding_numbers(np.asarray(pivot, dtype=np.float64)[None, :], tree.vertices, tree.faces,
                             fast=False)[0]) > 0.5:
        return
    unit, scale = "m", 1.0
    if units:
        try:
            unit, scale = str(units), length_scale(units)
        except ValueError:          # an unknown unit was refused where it was given; metres here
            pass
    p = ", ".join(f"{c / scale:.6g}" for c in pivot)
    warnings.warn(PivotOffPartWarning(
        f"{name}: the pivot ({p}) {unit} lies in empty space, {gap / scale:.3g} {unit} from the part's surface "
        f"({gap / extent:.1%} of its {extent / scale:.3g} {unit} extent): a top stands on a point of its own "
        "surface; check --pivot and --units (designed as asked)"), stacklevel=3)


def spin_it(source, *, axis, mode: str = "yoyo", wall: float, through=None, pivot=None, units: str | None = None,
            density: float | None = None, material: str | None = None, mass: float | None = None,
            resolution: int = DEFAULT_RESOLUTION, center_weight: float = 1e4, product_weight: float = 1e4,
            gravity: float = 9.80665, insert_density: float | None = None, repair: bool = False,
            storage_scale: float | None = None, loaded: tuple | None = None,
            assume: tuple[str, ...] = ()) -> SpinItResult:
    """Hollow a part so that it spins stably about ``axis`` (Bächer et al. 2014; Hafner et al. 2024).

    Parameters
    ----------
    source : path, trimesh.Trimesh or (vertices, faces)
        A closed mesh.
    axis : (3,) array_like
        Spin axis direction, mesh axes (normalised here).
    mode : {"yoyo", "top"}
        ``"yoyo"``: free spin (§4.4.1): the axis a principal axis through the centre of mass with the
        largest moment, the transverse moments as small as possible relative to it.  ``"top"``: heavy
        symmetric top on ``pivot`` (§4.4.3): centre of mass on the axis above the pivot, equal transverse
        moments, and the sleeping-top spin ``√(4 I1 M g l)/I3`` as low as possible.
    wall : float
        Minimum wall thickness, m (> 0), measured from the outer surface.
    through : (3,) array_like, optional
        Yo-yo: a point of the axis (m, mesh axes); the centre of mass is pulled onto that line.  Without it
        only the direction counts (the axis then passes through the centre of mass).
    pivot : (3,) array_like
        Top: the pivot (m, mesh axes); required for ``"top"``.
    units, density, material, mass
        As in ``inertia_tool.mass_properties``.
    resolution : int
        Cells across the part's largest extent (12 to 128; default 48).
    center_weight, product_weight : float
        Penalty weights of the centre-of-mass offset and of the products of inertia / transverse asymmetry
        (see ``design.moments``).
    gravity : float
        m/s², for the sleeping-top threshold.
    insert_density : float, optional
        kg/m³ of a denser material that may fill part of the interior (a second quadric region,
        ``design.insert``); it must exceed the part's density.
    repair : bool
        Read a damaged mesh (holes, cracks) as ``mass_properties(repair=True)`` does, and design on the
        repaired surface; every 'after' number is the exact re-analysis of the hollowed mesh, and its
        certificate the repaired part's: an estimate, with the bounds carried over (``design.carried``).
    assume : tuple of str
        The user's assumptions about the holes the repair fills, as ``mass_properties(assume=...)``
        (``("flat-islands",)``); only with ``repair``.  Default ``()``: none.
    storage_scale : float, optional
        m per unit of the file the result will be written to as float32 (an STL in ``units``): the hollowed
        mesh is rounded as that file holds it before it is re-analysed, so that the file analyses to the
        numbers reported.  ``None``: kept in float64.
    loaded : tuple, optional
        ``(vertices, faces, MassProperties, name)`` of this ``source`` already read and checked (``_load``):
        ``spin_it_verified`` reads the part once for all its attempts.

    Returns
    -------
    SpinItResult

    Raises
    ------
    UsageError, PhysicsError
    """
    started = time.perf_counter()
    if mode not in MODES:
        raise UsageError(f"Expected `mode` to be one of {MODES}, got {mode!r}")
    axis = _unit(axis, "axis")
    if not (isinstance(wall, (int, float)) and math.isfinite(wall) and wall > 0):
        raise UsageError(f"Expected a positive finite `wall` (m), got {wall!r}")
    if not (isinstance(resolution, (int, np.integer)) and MIN_RESOLUTION <= resolution <= MAX_RESOLUTION):
        raise UsageError(f"Expected {MIN_RESOLUTION} <= `resolution` <= {MAX_RESOLUTION}, got {resolution!r}")
    if mode == "top":
        if pivot is None:
            raise UsageError("mode 'top' needs a `pivot`")
        if through is not None:
            raise UsageError("`through` is for mode 'yoyo'; a top's axis passes through its `pivot`")
        pivot = _point(pivot, "pivot")
    elif pivot is not None:
        raise UsageError("`pivot` is for mode 'top'")
    vertices, faces, before, name = loaded or _load(source, units, density, material, mass, repair, assume)
    if insert_density is not None and not (isinstance(insert_density, (int, float)) and math.isfinite(insert_density)
                                           and insert_density > before.density):
        raise UsageError(f"Expected `insert_density` above the part's {before.density:g} kg/m³, got {insert_density!r}")
    size = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    extent = float(np.max(vertices.max(axis=0) - vertices.min(axis=0)))
    if mode == "yoyo":
        origin = _point(through, "through") if through is not None else before.center_of_mass.copy()
    else:
        origin = pivot
    frame = design_frame(axis)
    rho = before.density

    h = extent / resolution
    tree = SurfaceTree(vertices, faces)
    if mode == "top":
        _warn_pivot_off_part(name, pivot, vertices, faces, tree, extent, units)
    # depths matter up to the deepest cavity threshold (wall + margins) plus the smooth minimum's reach
    grid = interior_grid(vertices, faces, spacing=h, depth_cap=wall + DEPTH_CAP_CELLS * h)
    grid = _exact_near_wall(grid, vertices, faces, wall, tree)
    deep = grid.inside & (grid.signed_distance >= wall + DEPTH_MARGIN * h)
    index = np.nonzero(deep)
    if len(index[0]) == 0:
        raise (_too_thin(name, grid, wall, extent, resolution))
    centres = grid.centers(index)
    points = (centres - origin) @ frame
    mu_part = moment_vector(before, origin, frame) / rho
    if mode == "yoyo":
        def objective(mu):
            return OBJECTIVES["yoyo"](mu, size=size, center_weight=center_weight, product_weight=product_weight,
                                      axis_through_origin=through is not None)
    else:
        _, c0, _, _ = frame_quantities(mu_part)
        if not c0[2] > 0:
            raise PhysicsError(f"{name}: the centre of mass is not above the pivot along the axis "
                               f"(height {c0[2]:.6g} m): a top stands on its pivot below the centre of mass")
        reference = top_threshold_measure(mu_part)

        def objective(mu):
            return OBJECTIVES["top"](mu, size=size, center_weight=center_weight, product_weight=product_weight,
                                     reference_threshold=reference)
    cavity = optimize_quadric_cavity(objective, mu_part, points, h, size=size)
    design: QuadricCavity | QuadricInsert = cavity
    if insert_density is not None and len(points):
        from .insert import optimize_cavity_and_insert
        design = optimize_cavity_and_insert(objective, mu_part, points, h, cavity, size=size,
                                            density_ratio=insert_density / rho)
        cavity = design.cavity
    # an insert may come with alternatives (another shape, worse on the cells): each is meshed and re-analysed,
    # and the best exact objective kept
    made = None
    for candidate in (design, *getattr(design, "alternatives", ())):
        attempt = _made(candidate, vertices, faces, grid, centres, origin, frame, wall, tree, storage_scale, rho,
                        insert_density, name, before)
        if attempt is None:
            continue
        value = float(objective(moment_vector(attempt[0], origin, frame) / rho))
        if made is None or value < made[-1]:
            made = (*attempt, candidate, value)
    if made is None:
        if int(cavity.removed.sum()) > 0:
            raise (_too_thin(name, grid, wall, extent, resolution, chosen=int(cavity.removed.sum())))
        after, pocket, insert_props, chosen = before, None, None, design
    else:
        after, pocket, insert_props, chosen, _ = made
    cavity = chosen.cavity if hasattr(chosen, "cavity") else chosen
    out_v, out_f, ins_v, ins_f, measured = ((vertices, faces, None, None, math.inf) if pocket is None else
                                            (pocket.vertices, pocket.faces, pocket.insert_vertices,
                                             pocket.insert_faces, pocket.measured_wall))
    insert_shape = getattr(chosen, "shape", None) if ins_v is not None else None
    metric_origin = origin if (mode == "top" or through is not None) else None
    return SpinItResult(mode=mode, axis=axis, origin=origin, wall=float(wall), vertices=out_v, faces=out_f,
                        before=before, after=after,
                        metrics_before=design_metrics(before, mode, axis, metric_origin, gravity=gravity),
                        metrics_after=design_metrics(after, mode, axis, metric_origin, gravity=gravity),
                        measured_wall=measured,
                        cavity_volume=float(before.volume - after.volume), cavity=cavity,
                        cell_size=h, allowed_cells=int(len(points)), removed_cells=int(cavity.removed.sum()),
                        objective_before=float(objective(mu_part)),
                        objective_after=float(objective(moment_vector(after, origin, frame) / rho)),
                        optimisation_seconds=cavity.seconds, objective_evaluations=cavity.evaluations,
                        seconds=time.perf_counter() - started, insert_vertices=ins_v, insert_faces=ins_f,
                        insert=insert_props, insert_density=None if insert_density is None else float(insert_density),
                        insert_shape=insert_shape, loaded=(vertices, faces, before, name))


def _made(design, vertices, faces, grid, centres, origin, frame, wall: float, tree, storage_scale, rho: float,
          insert_density, name: str, before):
    """One design meshed and re-analysed: (after, pocket, insert properties), or None when no cavity came out
    of the meshing (the chosen cells too thin a layer)."""
    pockets = cut_pocket(vertices, faces, grid, design, centres, origin, frame, wall, tree=tree,
                         storage_scale=storage_scale)
    if not pockets:
        return None
    pocket, after = _first_certified(pockets, rho, f"{name} (hollowed)")
    # exact for the mesh written; for the user's part, as much an estimate as the repaired part it was cut from
    after = carry_repair_bounds(before, after)
    insert_props = None
    if pocket.insert_vertices is not None:
        assert insert_density is not None, "an insert is made only when its density is given"
        from ..mass.properties import combine
        insert_props = _reanalysed((pocket.insert_vertices, pocket.insert_faces), float(insert_density),
                                   f"{name} (insert)")
        after = combine([after, insert_props], name=f"{name} (hollowed, with insert)")
    return after, pocket, insert_props


def _reanalysed(mesh, density: float, name: str):
    """Mass properties of a mesh made here, by the engine with every check of ``analyze`` (a surface that
    passes through itself is refused, as ``analyze`` would refuse the file)."""
    from ..mass.pipeline import _part
    from ..mesh.options import LoadOptions

    return _part(mesh, density, None, LoadOptions(), name=name)[0]


def replay_warnings(caught, name: str, *, seen: set | None = None) -> None:
    """Warn again the recorded ``caught`` (``warnings.WarningMessage``), a mesh made here named ``name`` instead
    of ``"<arrays>"`` (the name of an in-memory mesh); one whose category and text are in ``seen`` is skipped
    (and each warned one added), so that a retry does not repeat what the first attempt said."""
    for w in caught:
        text = str(w.message).replace("<arrays>", name)
        if seen is not None:
            if (w.category, text) in seen:
                continue
            seen.add((w.category, text))
        message = w.category(text)
        message.about_made_mesh = True     # type: ignore[attr-defined]  # verify drops these of a rejected design
        warnings.warn_explicit(message, w.category, w.filename, w.lineno)


def _first_certified(pockets, density: float, name: str):
    """The first candidate pocket whose hollowed part the engine certifies ``exact`` (as ``analyze`` will the
    file), and its mass properties.  A cavity added to the part's surface keeps the wall from it and is an
    embedded surface (``design.tetra``), so the first normally passes; the manifold3d simplification is the
    one that may fold, and the marching tetrahedra's own mesh is tried next."""
    from ..errors import InvalidMeshError

    failures = []
    for pocket in pockets:
        # a candidate that is not kept says nothing: its warnings (a fold it had, "<arrays>" for its name) are
        # about a mesh the user never gets
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                props = _reanalysed((pocket.vertices, pocket.faces), density, name)
            except InvalidMeshError as exc:
                failures.append(str(exc))
                continue
        if props.mesh is None or props.mesh.certificate.kind == "exact":
            replay_warnings(caught, name)
            return pocket, props
        failures.append(f"certificate {props.mesh.certificate.kind}")
    raise PhysicsError(f"{name}: no mesh of the cavity could be certified exact ({'; '.join(failures)})")
