"""``spin_it``: hollow a part so that it spins the way the user wants (yo-yo or top), verified by re-analysis.

Pipeline (one function per stage):

1. the checked mesh and its exact mass properties (the engine, ``inertia_tool.mass_properties``);
2. a voxel grid of its inside (``design.grid``): the cells whose centres lie deeper than the wall (plus half a
   cell diagonal, for the approximate distance transform) may be removed;
3. the quadric cavity that minimises the mode's objective of the mass moments (``design.optimize``,
   ``design.moments``);
4. the cavity as a closed mesh — the zero level set of ``min(depth − wall, −q)`` by marching tetrahedra
   (``manifold3d.Manifold.level_set``) — subtracted from the part with manifold3d's robust boolean;
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
from dataclasses import dataclass

import numpy as np

from ..errors import AsymmetricTopWarning, PhysicsError, UsageError
from .grid import interior_grid, surface_distance
from .limits import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from .moments import OBJECTIVES, frame_quantities, moment_vector, top_threshold_measure
from .optimize import QuadricCavity, optimize_quadric_cavity

__all__ = ["SpinDesignMetrics", "SpinItResult", "spin_it", "design_metrics", "MODES", "DEFAULT_RESOLUTION"]

#: ``"yoyo"`` (free spin, §4.4.1) and ``"top"`` (heavy symmetric top on a pivot, §4.4.3).
MODES = ("yoyo", "top")


#: Cells of extra depth asked of the cavity beyond the wall (the depths near the wall are exact at the cell
#: centres; the margin covers the linear interpolation of the level set between them).
DEPTH_MARGIN = 0.5

#: Edges of the cavity mesh shorter than this fraction of a cell are collapsed (``Manifold.simplify``), so
#: that a float32 STL of the result keeps every vertex distinct.
SNAP = 1e-3

#: Smallest separate void kept, in cell volumes.
MIN_VOID_CELLS = 8

#: Attempts at meshing the cavity, each with half a cell more margin if the measured wall came out thin.
MAX_MESH_ATTEMPTS = 4


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
        rad: yo-yo, angle between the requested axis and the nearest principal axis; top, angle between the
        requested axis and the pivot → centre-of-mass line.
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
    axes = np.column_stack([e.axis for e in report.axes])
    cosines = np.abs(axes.T @ axis)
    nearest = int(np.argmax(cosines))
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
                                 axis_tilt=float(math.acos(min(1.0, cosines[nearest]))), axis_offset=offset,
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


def _load(source, units: str, density, material, mass):
    """Checked vertices and faces (m, outward-wound) and the exact mass properties of the solid part."""
    from ..mass.pipeline import mass_properties, resolve_density
    from ..mesh.prepare import prepare_mesh
    from ..mesh.read import load_mesh

    rho, _ = resolve_density(density=density, material=material, mass=mass)
    raw = load_mesh(source, units=units)
    prepared = prepare_mesh(raw)
    props = mass_properties((prepared.vertices, prepared.faces), density=rho, mass=mass, name=raw.source)
    return prepared.vertices, prepared.faces, props, raw.source


def _exact_near_wall(grid, vertices, faces, wall: float):
    """The grid with exact depths (``design.grid.surface_distance``, capped at ``wall + 2h``) at the inside cells
    whose approximate depth lies in ``[wall − h, wall + 2h]``, where the allowed region is decided."""
    from dataclasses import replace

    h = grid.spacing
    band = grid.inside & (grid.signed_distance >= wall - h) & (grid.signed_distance <= wall + 2 * h)
    index = np.nonzero(band)
    if len(index[0]) == 0:
        return grid
    depth = grid.signed_distance.copy()
    depth[index] = surface_distance(grid.centers(index), vertices, faces, cutoff=wall + 2 * h)
    return replace(grid, signed_distance=depth)


def _cavity_field(grid, terms, centre, half: float, origin, frame, threshold: float):
    """The scalar field ``min(depth − threshold, −s_k q_k · half_extent …)`` (m, positive inside the region), for
    the quadric ``terms`` ``[(coefficients, s_k)]`` (``s = +1``: inside where ``q < 0``; ``−1``: outside it),
    creases rounded over a quarter cell, as a Python callable of mesh coordinates for ``Manifold.level_set``;
    the depth is trilinear between the grid's cell centres."""
    sd = grid.signed_distance
    nx, ny, nz = sd.shape
    flat = sd.ravel().tolist()
    ox, oy, oz = (float(c) for c in grid.origin)
    inv = 1.0 / grid.spacing
    r = frame
    c = centre
    quadrics = [((np.asarray(t) / np.linalg.norm(t)).tolist(), float(sign)) for t, sign in terms]
    # frame coordinates, normalised: x̂ = (Rᵀ (x − o) − centre)/half = A x + b
    a = (r.T / half).tolist()
    b = ((-(r.T @ np.asarray(origin)) - c) / half).tolist()
    stride_x, stride_y = ny * nz, nz
    smooth = 0.25 * grid.spacing

    def field(x, y, z):
        gx, gy, gz = (x - ox) * inv, (y - oy) * inv, (z - oz) * inv
        i = min(max(int(math.floor(gx)), 0), nx - 2)
        j = min(max(int(math.floor(gy)), 0), ny - 2)
        k = min(max(int(math.floor(gz)), 0), nz - 2)
        fx = min(max(gx - i, 0.0), 1.0)
        fy = min(max(gy - j, 0.0), 1.0)
        fz = min(max(gz - k, 0.0), 1.0)
        base = i * stride_x + j * stride_y + k
        c00 = flat[base] * (1 - fz) + flat[base + 1] * fz
        c01 = flat[base + stride_y] * (1 - fz) + flat[base + stride_y + 1] * fz
        c10 = flat[base + stride_x] * (1 - fz) + flat[base + stride_x + 1] * fz
        c11 = flat[base + stride_x + stride_y] * (1 - fz) + flat[base + stride_x + stride_y + 1] * fz
        depth = (c00 * (1 - fy) + c01 * fy) * (1 - fx) + (c10 * (1 - fy) + c11 * fy) * fx
        u = a[0][0] * x + a[0][1] * y + a[0][2] * z + b[0]
        v = a[1][0] * x + a[1][1] * y + a[1][2] * z + b[1]
        w = a[2][0] * x + a[2][1] * y + a[2][2] * z + b[2]
        value = depth - threshold
        for t, sign in quadrics:
            q = (t[0] + t[1] * u + t[2] * v + t[3] * w + t[4] * u * u + t[5] * v * v + t[6] * w * w
                 + t[7] * u * v + t[8] * u * w + t[9] * v * w)
            inner = -sign * q * half
            # smooth minimum (rounds the crease where the wall meets the quadric, so the two sheets of the
            # marching tetrahedra do not pinch at a shared point): min(d, e) − k log(1 + exp(−|d − e|/k))
            value = min(value, inner) - smooth * math.log1p(math.exp(-abs(value - inner) / smooth))
        return value

    return field


def _manifold_of(vertices, faces):
    import manifold3d

    mesh = manifold3d.Mesh64(vert_properties=np.array(vertices, dtype=np.float64, order="C"),   # writable copies
                             tri_verts=np.array(faces, dtype=np.uint64, order="C"))
    return manifold3d.Manifold(mesh)


def _arrays_of(manifold):
    mesh = manifold.to_mesh64()
    return np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)


def _separate_pinches(vertices, faces, distance: float):
    """Move apart vertices that share a position (float32), each by ``distance`` along its outward normal.

    Marching tetrahedra can leave two sheets of the cavity touching at one point, as two distinct vertices at
    the same position: a valid manifold, but a mesh file welds them into a non-manifold vertex.  Moving each
    copy outward (into the cavity it bounds) separates the sheets by ``2 distance``.
    """
    v = np.array(vertices, dtype=np.float64)
    _, inverse, counts = np.unique(v.astype(np.float32), axis=0, return_inverse=True, return_counts=True)
    shared = counts[inverse.ravel()] > 1
    if not np.any(shared):
        return v, faces
    tri = v[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    vertex_normal = np.zeros_like(v)
    for k in range(3):
        np.add.at(vertex_normal, faces[:, k], normal)
    length = np.linalg.norm(vertex_normal[shared], axis=1)
    v[shared] += distance * vertex_normal[shared] / np.where(length > 0, length, 1.0)[:, None]
    return v, faces


def _region(grid, terms, centre, half, cells, vertices, faces, origin, frame, wall: float):
    """A closed mesh (manifold) of the region of ``terms`` deeper than the wall, from ``Manifold.level_set``,
    with its wall measured exactly; remeshed deeper (up to ``MAX_MESH_ATTEMPTS``) if thinner than ``wall``.
    Returns (manifold or None when empty, measured wall)."""
    import manifold3d

    h = grid.spacing
    lo = cells.min(axis=0) - 2 * h
    hi = cells.max(axis=0) + 2 * h
    margin = DEPTH_MARGIN * h
    for _ in range(MAX_MESH_ATTEMPTS):
        field = _cavity_field(grid, terms, centre, half, origin, frame, wall + margin)
        # marching tetrahedra can leave vertices closer than a float32 STL can tell apart: merge them
        region = manifold3d.Manifold.level_set(field, [*lo, *hi], h).simplify(SNAP * h)
        # slivers the marching tetrahedra leave where the field grazes zero: voids smaller than (2h)³ change
        # the moments by nothing measurable and no print could be emptied of them
        pieces = [piece for piece in region.decompose() if piece.volume() >= MIN_VOID_CELLS * h ** 3]
        if not pieces:
            return None, math.inf
        region = manifold3d.Manifold.batch_boolean(pieces, manifold3d.OpType.Add)
        region_v, _ = _arrays_of(region)
        measured = float(surface_distance(region_v, vertices, faces, cutoff=wall + h).min())
        if measured >= wall + SNAP * h:          # pinches are separated by SNAP·h below
            return region, measured - SNAP * h
        margin += 0.5 * h
    raise PhysicsError(f"could not mesh a cavity keeping a wall of {wall:g} m: the thinnest came out "
                       f"{measured:g} m after {MAX_MESH_ATTEMPTS} attempts")


def _hollow(vertices, faces, grid, design, centres, origin, frame, wall: float):
    """Mesh the cavity (and the insert), check the wall exactly, subtract, separate pinches.

    ``design`` is a :class:`QuadricCavity` or a :class:`~.insert.QuadricInsert`.  Returns (vertices, faces,
    insert vertices or None, insert faces or None, measured wall)."""
    try:
        import manifold3d
    except ImportError as exc:                # pragma: no cover - a dependency of the package
        raise UsageError("spin_it needs manifold3d (pip install manifold3d)") from exc
    cavity = design if isinstance(design, QuadricCavity) else design.cavity
    inserted = getattr(design, "inserted", None)
    h = grid.spacing
    walls = [math.inf]
    insert = hole = None
    if inserted is not None and np.any(inserted):
        insert, measured = _region(grid, [(design.insert_coefficients, 1.0)], cavity.centre, cavity.half_extent,
                                   centres[inserted], vertices, faces, origin, frame, wall)
        walls.append(measured)
    in_q1 = cavity.removed if inserted is None else cavity.removed | (inserted & (cavity.values(
        (centres - origin) @ frame) < 0))
    if np.any(in_q1):
        hole, measured = _region(grid, [(cavity.coefficients, 1.0)], cavity.centre, cavity.half_extent,
                                 centres[in_q1], vertices, faces, origin, frame, wall)
        walls.append(measured)
    if hole is None and insert is None:
        return vertices, faces, None, None, math.inf
    # the pocket is the union of both regions: the part keeps none of it, the insert fills its own share
    pocket = hole if insert is None else (insert if hole is None else hole + insert)
    part = _manifold_of(vertices, faces)
    if part.status() != manifold3d.Error.NoError:
        raise PhysicsError(f"the part is not a manifold solid for the boolean ({part.status()})")
    result = part - pocket
    if result.status() != manifold3d.Error.NoError:
        raise PhysicsError(f"the boolean subtraction failed ({result.status()})")
    out_v, out_f = _separate_pinches(*_arrays_of(result), SNAP * h)
    ins_v = ins_f = None
    if insert is not None:
        ins_v, ins_f = _separate_pinches(*_arrays_of(insert), SNAP * h)
    return out_v, out_f, ins_v, ins_f, min(walls)


def spin_it(source, *, axis, mode: str = "yoyo", wall: float, through=None, pivot=None, units: str = "m",
            density: float | None = None, material: str | None = None, mass: float | None = None,
            resolution: int = DEFAULT_RESOLUTION, center_weight: float = 1e4, product_weight: float = 1e4,
            gravity: float = 9.80665, insert_density: float | None = None) -> SpinItResult:
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
    from ..mass.pipeline import mass_properties
    vertices, faces, before, name = _load(source, units, density, material, mass)
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
    grid = _exact_near_wall(interior_grid(vertices, faces, spacing=h), vertices, faces, wall)
    deep = grid.inside & (grid.signed_distance >= wall + DEPTH_MARGIN * h)
    index = np.nonzero(deep)
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
    design = cavity
    if insert_density is not None and len(points):
        from .insert import optimize_cavity_and_insert
        design = optimize_cavity_and_insert(objective, mu_part, points, h, cavity, size=size,
                                            density_ratio=insert_density / rho)
        cavity = design.cavity
    out_v, out_f, ins_v, ins_f, measured = _hollow(vertices, faces, grid, design, centres, origin, frame, wall)
    after = before
    insert_props = None
    if out_v is not vertices:
        after = mass_properties((out_v, out_f), density=rho, name=f"{name} (hollowed)")
    if ins_v is not None:
        from ..mass.properties import combine
        insert_props = mass_properties((ins_v, ins_f), density=float(insert_density), name=f"{name} (insert)")
        after = combine([after, insert_props], name=f"{name} (hollowed, with insert)")
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
                        insert=insert_props, insert_density=None if insert_density is None else float(insert_density))
