"""From a mesh source to ``MassProperties``: read → weld → check → integrate → assemble.

This is the public entry point of the engine (``inertia_tool.mass_properties``).  Each stage lives in its
own module (``io``, ``weld``, ``checks``, ``volume``, ``properties``); this module only routes between them
and decides what to do with what the checks found: refuse (open, non-manifold, inconsistently wound,
flat), repair on request, flip an inside-out shell with a warning, count a nested negative shell as a cavity,
warn about overlapping bodies.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .checks import MeshReport, edge_topology, repeated_corner_faces, shell_labels, winding_number
from .errors import (DegenerateFacesWarning, InsideOutWarning, InvalidMeshError, MeshRepairedWarning,
                     NearlyEqualMomentsWarning, OverlapWarning, PhysicalValidityWarning, UsageError)
from .io import DEFAULT_MAX_FACES, RawMesh, load_mesh
from .properties import MassProperties, combine
from .units import material_density
from .volume import VolumeMoments, body_volume_moments, bounding_box, reference_point, second_moment_to_inertia
from .weld import weld_tolerance

__all__ = ["mass_properties", "assembly", "resolve_density", "DEFAULT_DENSITY", "DEFAULT_MERGE_TOLERANCE",
           "prepare_mesh", "PreparedMesh"]

#: Density used when none of density / material / mass is given (water), kg/m³.  Reports say so.
DEFAULT_DENSITY = 1000.0

#: Relative (to the bounding-box diagonal) grid spacing for welding nearly coincident vertices when exact
#: welding leaves the surface open.
DEFAULT_MERGE_TOLERANCE = 1e-6

#: Shells with |volume| below this fraction of the bounding-box diagonal cubed are flat.
_FLAT_RTOL = 1e-12

#: Largest |coordinate| (m) accepted: the second moments grow like L⁵ and must stay far from float64
#: overflow (1.8e308) for any density; 1e30 m is already beyond the observable universe.
MAX_COORDINATE = 1e30

#: Smallest bounding-box diagonal (m) accepted: below it L⁵ approaches float64 underflow.
MIN_EXTENT = 1e-30

#: Relative precision (of the largest principal moment) under which the smallest one is only round-off.
_NEEDLE_RTOL = 1e-10

#: Upper bound on triangle-point solid-angle evaluations spent on cavity / overlap classification.
_WINDING_BUDGET = 200_000_000


@dataclass(frozen=True)
class PreparedMesh:
    """A checked mesh ready for integration, with its shells classified.

    Attributes
    ----------
    vertices : (n, 3) float64
        m, mesh axes.
    faces : (m, 3) int
        Outward-wound after any flips.
    labels : (m,) int
        Shell of each face.
    shells : tuple of VolumeMoments
        Per-shell unit-density moments (after flips; cavities have negative volume).
    owner : (k,) int
        For each shell, the body it belongs to (a cavity belongs to the body around it).
    report : MeshReport
    """

    vertices: np.ndarray
    faces: np.ndarray
    labels: np.ndarray
    shells: tuple
    owner: np.ndarray
    report: MeshReport


def resolve_density(*, density=None, material=None, mass=None) -> tuple[float | None, str]:
    """Decide the density from at most one of ``density`` (kg/m³), ``material`` (name) or ``mass`` (kg).

    Returns ``(density or None when a target mass is used, description)``.
    """
    given = [x is not None for x in (density, material, mass)]
    if sum(given) > 1:
        raise UsageError("Give at most one of density, material and mass")
    if density is not None:
        if not (np.isfinite(density) and density > 0):
            raise UsageError(f"Expected a positive finite density in kg/m³, got {density}")
        return float(density), f"{float(density):g} kg/m³"
    if material is not None:
        rho = material_density(material)
        return rho, f"{material} ({rho:g} kg/m³)"
    if mass is not None:
        if not (np.isfinite(mass) and mass > 0):
            raise UsageError(f"Expected a positive finite mass in kg, got {mass}")
        return None, f"scaled to a total mass of {float(mass):g} kg"
    return DEFAULT_DENSITY, f"{DEFAULT_DENSITY:g} kg/m³ (default: water; give a density, material or mass)"


def _describe_edges(topo, source: str) -> str:
    parts = []
    if topo.boundary_edges:
        parts.append(f"{topo.boundary_edges:,} boundary edges (holes)")
    if topo.nonmanifold_edges:
        parts.append(f"{topo.nonmanifold_edges:,} non-manifold edges (shared by 3+ faces)")
    if topo.misoriented_edges:
        parts.append(f"{topo.misoriented_edges:,} edges with inconsistent winding (flipped faces)")
    where = ""
    if len(topo.sample):
        a, b = topo.sample[0]
        where = f", e.g. the edge ({a[0]:.6g}, {a[1]:.6g}, {a[2]:.6g})–({b[0]:.6g}, {b[1]:.6g}, {b[2]:.6g}) m"
    return f"{source}: not a closed, consistently wound solid: {'; '.join(parts)}{where}; use --repair to fix"


def _repair(vertices, faces, source):
    """Close holes and fix winding with trimesh; returns new arrays and the list of actions."""
    import trimesh

    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    actions = []
    before_faces = len(mesh.faces)
    if not mesh.is_winding_consistent:
        trimesh.repair.fix_winding(mesh)
        actions.append("made the winding consistent")
    if not mesh.is_watertight:
        trimesh.repair.fill_holes(mesh)
        if len(mesh.faces) != before_faces:
            actions.append(f"filled holes with {len(mesh.faces) - before_faces} new triangles")
    if not (mesh.is_watertight and mesh.is_winding_consistent):
        raise InvalidMeshError(f"{source}: could not be repaired into a closed solid "
                               "(holes too complex or non-manifold edges remain)")
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces), actions


def _signed_volume(vertices, faces) -> float:
    o = reference_point(vertices)
    a = vertices[faces[:, 0]] - o
    return float(np.einsum("ij,ij->i", a, np.cross(vertices[faces[:, 1]] - o, vertices[faces[:, 2]] - o)).sum() / 6)


def _classify_shells(vertices, faces, labels, n_shells, shells, diag):
    """Flip inside-out shells, attach cavities to their bodies, detect overlaps.

    Returns (shells, owner, flipped, cavities, overlaps, face_flip_mask_per_shell).
    """
    vols = np.array([s.volume for s in shells])
    flip = np.zeros(n_shells, dtype=bool)
    owner = np.arange(n_shells)
    if n_shells == 1:
        flip[0] = vols[0] < 0
        return flip, owner, 0, 0
    # bounding boxes per shell and one probe point per shell (centroid of its first face)
    order = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[order], np.arange(n_shells))
    corner = vertices[faces[order]]
    lo = np.minimum.reduceat(corner.min(axis=1), starts, axis=0)
    hi = np.maximum.reduceat(corner.max(axis=1), starts, axis=0)
    probe = corner[starts].mean(axis=1)
    face_count = np.diff(np.r_[starts, len(faces)])
    sign = np.sign(vols)
    if vols.sum() < 0:
        # the whole mesh is inside out: flip every shell first
        sign = -sign
        flip[:] = True
    winding = np.zeros(n_shells)
    budget = _WINDING_BUDGET
    for s in range(n_shells):
        inside_box = np.all((probe[s] >= lo) & (probe[s] <= hi), axis=1)
        inside_box[s] = False
        for t in np.flatnonzero(inside_box):
            budget -= face_count[t]
            if budget < 0:
                break
            orient = -1.0 if flip[t] else 1.0
            w = orient * winding_number(probe[s], vertices, faces[order[starts[t]:starts[t] + face_count[t]]])
            winding[s] += w
            if sign[s] < 0 and w > 0.5 and sign[t] > 0:
                owner[s] = t
    cavities = 0
    overlapped = np.zeros(n_shells, dtype=bool)
    cavity = np.zeros(n_shells, dtype=bool)
    for s in range(n_shells):
        inside_material = winding[s] > 0.5
        if sign[s] < 0:
            if inside_material:
                cavities += 1           # a void inside a body: keep its negative volume
                cavity[s] = True
            else:
                flip[s] = not flip[s]   # an inside-out body on its own: flip it
                owner[s] = s
        elif inside_material:
            overlapped[s] = True
    if budget > 0:
        overlapped |= _overlap_probes(vertices, faces, order, starts, face_count, lo, hi, flip, ~cavity,
                                      diag, budget)
    return flip, owner, cavities, int(np.count_nonzero(overlapped))


def _overlap_probes(vertices, faces, order, starts, face_count, lo, hi, flip, body, diag, budget,
                    probes_per_shell: int = 16, nudge: float = 1e-6):
    """Bodies with material of another body just inside their surface (partial overlaps).

    The centroids of each body's ``probes_per_shell`` largest faces, moved ``nudge · diag`` inward, are
    tested against every other body whose bounding box holds them (winding number > 1/2 means inside).
    Catches overlaps whose vertices all lie outside the other body (two crossing bars); an overlap that
    no probe reaches stays undetected.  Spends at most ``budget`` triangle-point evaluations.
    """
    n_shells = len(starts)
    found = np.zeros(n_shells, dtype=bool)
    for s in np.flatnonzero(body):
        others = np.flatnonzero(np.all(lo <= hi[s], axis=1) & np.all(hi >= lo[s], axis=1))
        others = others[others != s]
        if not np.any(body[others]):
            continue
        f = faces[order[starts[s]:starts[s] + face_count[s]]]
        a, b, c = vertices[f[:, 0]], vertices[f[:, 1]], vertices[f[:, 2]]
        normal = np.cross(b - a, c - a)
        length = np.linalg.norm(normal, axis=1)
        pick = np.argsort(-length, kind="stable")[:probes_per_shell]
        pick = pick[length[pick] > 0]
        outward = normal[pick] / length[pick, None] * (-1.0 if flip[s] else 1.0)
        points = (a[pick] + b[pick] + c[pick]) / 3.0 - nudge * diag * outward
        material = np.zeros(len(points))   # signed count of the other shells' material at each probe
        for t in others:
            faces_t = faces[order[starts[t]:starts[t] + face_count[t]]]
            orient = -1.0 if flip[t] else 1.0   # cavities stay inward-wound and count negative
            for k in np.flatnonzero(np.all((points >= lo[t]) & (points <= hi[t]), axis=1)):
                budget -= face_count[t]
                if budget < 0:
                    return found
                material[k] += orient * winding_number(points[k], vertices, faces_t)
        found[s] = bool(np.any(material > 0.5))
    return found


def _check_magnitude(vertices, source: str) -> None:
    """Refuse coordinates whose volume integrals (∝ L⁵) would overflow or underflow float64."""
    if not len(vertices):
        return
    lo, hi = bounding_box(vertices)
    top = float(np.max(np.abs(np.r_[lo, hi])))    # = max |coordinate| (NaN propagates)
    if not top <= MAX_COORDINATE:
        raise InvalidMeshError(f"{source}: coordinates reach {top:.3g} m, beyond the ±{MAX_COORDINATE:g} m the "
                               "volume integrals can hold without overflow (check --units)")
    span = hi - lo
    diag = float(np.hypot(np.hypot(span[0], span[1]), span[2]))   # no underflow in the squares
    if 0 < diag < MIN_EXTENT:
        raise InvalidMeshError(f"{source}: the mesh spans only {diag:.3g} m, below the {MIN_EXTENT:g} m the "
                               "volume integrals can hold without underflow (check --units)")


def _check_finite(props: MassProperties, source: str) -> None:
    """Refuse a result with a non-finite number (never print inf or NaN as a mass property)."""
    values = np.r_[props.mass, props.volume, props.center_of_mass, props.inertia.ravel(), props.surface_area]
    if not np.all(np.isfinite(values)):
        raise InvalidMeshError(f"{source}: the mass properties overflow or are undefined (non-finite values); "
                               "check the coordinates' size and --units")


def _warn_about_principal(props: MassProperties, source: str) -> None:
    """Name the principal-axis results that are a choice (equal moments) or at round-off level (needle)."""
    pa = props.principal
    if len(pa.equal_pairs) >= 2:
        warnings.warn(NearlyEqualMomentsWarning(
            f"{source}: all three principal moments are equal within {pa.rtol:g} (relative); any axes are "
            "principal, the ones reported are an arbitrary choice"), stacklevel=3)
    elif pa.equal_pairs:
        a, b = pa.equal_pairs[0]
        warnings.warn(NearlyEqualMomentsWarning(
            f"{source}: principal moments I{a + 1} and I{b + 1} are equal within {pa.rtol:g} (relative); the "
            "axes in their plane are an arbitrary choice"), stacklevel=3)
    top = float(np.max(np.abs(pa.moments)))
    if top > 0 and pa.moments[0] <= _NEEDLE_RTOL * top:
        digits = -np.log10(np.finfo(float).eps * top / max(abs(pa.moments[0]), np.finfo(float).tiny))
        warnings.warn(PhysicalValidityWarning(
            f"{source}: the smallest principal moment ({pa.moments[0]:.3g} kg·m²) is below {_NEEDLE_RTOL:g} of "
            f"the largest (a needle); it carries only about {max(digits, 0):.0f} correct digits"), stacklevel=3)


def prepare_mesh(raw: RawMesh, *, repair: bool = False,
                 merge_tolerance: float = DEFAULT_MERGE_TOLERANCE) -> PreparedMesh:
    """Check a raw mesh and classify its shells (see the module docstring for the policy)."""
    source = raw.source
    v, f = raw.vertices, raw.faces
    if len(f) == 0:
        raise InvalidMeshError(f"{source}: the mesh has no triangles")
    _check_magnitude(v, source)
    repeated = repeated_corner_faces(f)
    n_repeated = int(np.count_nonzero(repeated))
    if n_repeated == len(f):
        raise InvalidMeshError(f"{source}: all {len(f):,} triangles are degenerate (no area); nothing to integrate")
    if n_repeated:
        f = f[~repeated]
        warnings.warn(DegenerateFacesWarning(f"{source}: {n_repeated:,} degenerate triangles (a repeated corner) "
                                             "were ignored"), stacklevel=3)
    lo, hi = bounding_box(v)
    diag = float(np.linalg.norm(hi - lo))
    if not diag > 0:
        raise InvalidMeshError(f"{source}: all vertices coincide; the mesh has no extent")
    topo = edge_topology(f, len(v), v)
    watertight = topo.oriented
    welded = None
    if not topo.closed and merge_tolerance and merge_tolerance > 0:
        tol = merge_tolerance * diag
        f2 = weld_tolerance(v, f, tol)
        keep = ~((f2[:, 0] == f2[:, 1]) | (f2[:, 1] == f2[:, 2]) | (f2[:, 2] == f2[:, 0]))
        f2 = f2[keep]
        topo2 = edge_topology(f2, len(v), v)
        if topo2.closed and len(f2):  # welding must not collapse the whole surface
            f, topo, welded = f2, topo2, tol
            watertight = topo.oriented
    repaired = False
    actions: list[str] = []
    volume_change = None
    if not topo.oriented:
        if not repair:
            raise InvalidMeshError(_describe_edges(topo, source),
                                   details={"boundary_edges": topo.boundary_edges,
                                            "nonmanifold_edges": topo.nonmanifold_edges,
                                            "misoriented_edges": topo.misoriented_edges})
        before = _signed_volume(v, f)
        v, f, actions = _repair(v, f, source)
        after = _signed_volume(v, f)
        volume_change = (abs(after) - abs(before)) / abs(after) if after else None
        repaired = bool(actions)
        if repaired:
            change = f"; volume changed by {100 * volume_change:+.3g}%" if volume_change is not None else ""
            warnings.warn(MeshRepairedWarning(f"{source}: repaired: {', '.join(actions)}{change}"), stacklevel=3)
    labels, n_shells = shell_labels(f, len(v))
    if n_shells == 0:
        raise InvalidMeshError(f"{source}: no triangles are left after removing degenerate ones")
    shells = body_volume_moments(v, f, labels, n_shells)
    flat = [k for k, s in enumerate(shells) if abs(s.volume) <= _FLAT_RTOL * diag ** 3]
    if flat:
        what = "the mesh encloses" if n_shells == 1 else f"{len(flat)} of {n_shells} shells enclose"
        raise InvalidMeshError(f"{source}: {what} no volume (flat or collapsed surface)")
    flip, owner, cavities, overlaps = _classify_shells(v, f, labels, n_shells, shells, diag)
    if flip.any():
        face_flip = flip[labels]
        f = f.copy()
        f[face_flip] = f[face_flip][:, ::-1]
        shells = [VolumeMoments(-s.volume, s.centroid, -s.second_moment, s.area, s.zero_area_faces) if flip[k] else s
                  for k, s in enumerate(shells)]
        n_flipped = int(np.count_nonzero(flip))
        what = "the mesh is" if n_shells == 1 or n_flipped == n_shells else f"{n_flipped} of {n_shells} shells are"
        warnings.warn(InsideOutWarning(f"{source}: {what} inside out (normals point inward); flipped"),
                      stacklevel=3)
    if overlaps:
        warnings.warn(OverlapWarning(f"{source}: {overlaps} bod{'y overlaps' if overlaps == 1 else 'ies overlap'} "
                                     "another body; the overlapping volume is counted twice"), stacklevel=3)
    bodies = int(np.count_nonzero(owner == np.arange(n_shells)))
    bbox_min, bbox_max = bounding_box(v)
    report = MeshReport(source=source, units=raw.units, file_faces=raw.file_faces, vertices=len(v), faces=len(f),
                        degenerate_faces=n_repeated, zero_area_faces=sum(s.zero_area_faces for s in shells), bodies=bodies, cavities=cavities,
                        flipped_shells=int(np.count_nonzero(flip)), overlapping_shells=overlaps,
                        watertight=watertight, welded_tolerance=welded, repaired=repaired,
                        repair_actions=tuple(actions), repair_volume_change=volume_change,
                        bbox_min=bbox_min, bbox_max=bbox_max)
    return PreparedMesh(vertices=v, faces=f, labels=labels, shells=tuple(shells), owner=owner, report=report)


def _shell_properties(s: VolumeMoments, density: float, name: str) -> MassProperties:
    return MassProperties(mass=density * s.volume, volume=s.volume, center_of_mass=s.centroid,
                          inertia=second_moment_to_inertia(s.second_moment, density), surface_area=s.area,
                          density=density, name=name)


def _bodies(prepared: PreparedMesh, density: float, name: str) -> list[MassProperties]:
    bodies = []
    owners = np.unique(prepared.owner)
    for b in owners:
        members = [prepared.shells[k] for k in np.flatnonzero(prepared.owner == b)]
        props = [_shell_properties(s, density, name) for s in members]
        body = props[0] if len(props) == 1 else combine(props, name=name)
        bodies.append(MassProperties(mass=body.mass, volume=body.volume, center_of_mass=body.center_of_mass,
                                     inertia=body.inertia, surface_area=body.surface_area, density=density,
                                     name=f"{name} body {len(bodies) + 1}" if len(owners) > 1 else name))
    return bodies


def mass_properties(source, *, units: str = "m", density: float | None = None, material: str | None = None,
                    mass: float | None = None, repair: bool = False,
                    merge_tolerance: float = DEFAULT_MERGE_TOLERANCE, max_faces: int = DEFAULT_MAX_FACES,
                    name: str | None = None) -> MassProperties:
    """Mass properties of the solid bounded by a triangle mesh, exact for the polyhedron.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        The mesh (see :func:`inertia_tool.io.load_mesh`).
    units : str
        Length unit of the mesh coordinates: ``m``, ``cm``, ``mm``, ``um``, ``in``, ``ft``.
    density : float, optional
        kg/m³.
    material : str, optional
        Name from :data:`inertia_tool.units.MATERIALS` (e.g. ``"aluminium"``, ``"steel"``, ``"PLA"``).
    mass : float, optional
        Target total mass in kg; the density is set to ``mass / volume``.
        At most one of ``density``, ``material``, ``mass``; none means 1000 kg/m³ (water).
    repair : bool
        Close holes and fix inconsistent winding (through trimesh) instead of refusing the mesh; the
        mesh report says what changed and by how much the volume moved.
    merge_tolerance : float
        Relative (to the bounding-box diagonal) spacing for welding nearly coincident vertices when
        bit-exact welding leaves the surface open; 0 disables it.
    max_faces : int
        Refuse meshes with more triangles (memory guard).
    name : str, optional
        Label for reports; defaults to the source.

    Returns
    -------
    MassProperties
        SI; ``inertia`` about the centre of mass in mesh axes (tensor convention).  ``mesh`` holds the
        :class:`~inertia_tool.checks.MeshReport`; ``parts`` the bodies when the mesh has several.

    Raises
    ------
    MeshReadError, InvalidMeshError, UsageError
    """
    rho, _ = resolve_density(density=density, material=material, mass=mass)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # non-finite results refused below
        return _mass_properties(source, rho, mass, units=units, repair=repair, merge_tolerance=merge_tolerance,
                                max_faces=max_faces, name=name)


def _mass_properties(source, rho, mass, *, units, repair, merge_tolerance, max_faces, name) -> MassProperties:
    return _part(source, rho, mass, units=units, repair=repair, merge_tolerance=merge_tolerance,
                 max_faces=max_faces, name=name)[0]


def _part(source, rho, mass, *, units, repair, merge_tolerance, max_faces, name, warn_principal=True):
    """Mass properties of one mesh and its checked mesh (for cross-part checks of an assembly)."""
    raw = load_mesh(source, units=units, max_faces=max_faces)
    prepared = prepare_mesh(raw, repair=repair, merge_tolerance=merge_tolerance)
    label = name or raw.source
    bodies = _bodies(prepared, rho if rho is not None else 1.0, label)
    total = bodies[0] if len(bodies) == 1 else combine(bodies, name=label)
    result = MassProperties(mass=total.mass, volume=total.volume, center_of_mass=total.center_of_mass,
                            inertia=total.inertia, surface_area=total.surface_area,
                            density=rho if rho is not None else 1.0, name=label, mesh=prepared.report,
                            parts=tuple(bodies) if len(bodies) > 1 else ())
    if rho is None:
        result = result.with_mass(mass)
    _check_finite(result, label)
    _check_physical(result)
    if warn_principal:
        _warn_about_principal(result, label)
    return result, prepared


def _check_physical(props: MassProperties, rtol: float = 1e-9) -> None:
    """Warn when the principal moments fail positivity or the triangle inequality beyond round-off.

    For a real body ``I_k > 0`` and ``I1 + I2 ≥ I3`` (the perpendicular-axis theorem of §4.3.2 turned into an
    inequality); failing them means a mesh problem the checks did not catch (e.g. overlapping shells).
    """
    i1, i2, i3 = props.principal.moments
    if not (i1 > -rtol * i3 and i1 + i2 >= i3 * (1 - rtol)):
        warnings.warn(PhysicalValidityWarning(
            f"{props.name}: principal moments ({i1:.6g}, {i2:.6g}, {i3:.6g}) kg·m² violate positivity or the "
            "triangle inequality I1 + I2 ≥ I3: the mesh does not describe a physical body"), stacklevel=3)


def assembly(parts, *, units: str = "m", mass: float | None = None, **options) -> MassProperties:
    """Combine several meshes, each with its own material, into one rigid body.

    Parameters
    ----------
    parts : iterable of dict
        Each ``{"source": path_or_mesh, "density": kg/m³}`` or ``{"source": ..., "material": name}``
        (optionally ``"units"`` and ``"name"``).
    units : str
        Default length unit of the parts.
    mass : float, optional
        Scale the whole assembly to this total mass (kg), keeping the density ratios.
    **options
        Passed to :func:`mass_properties` (``repair``, ``merge_tolerance``, ``max_faces``).
    """
    bodies, meshes = [], []
    for spec in parts:
        spec = dict(spec)
        src = spec.pop("source")
        rho, _ = resolve_density(density=spec.pop("density", None), material=spec.pop("material", None),
                                 mass=spec.pop("mass", None))
        opts = {"repair": False, "merge_tolerance": DEFAULT_MERGE_TOLERANCE, "max_faces": DEFAULT_MAX_FACES,
                **options}
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            # equal moments of one part say nothing about the assembly: checked once on the whole below
            props, prepared = _part(src, rho, None, units=spec.pop("units", units), name=spec.pop("name", None),
                                    warn_principal=False, **opts)
        bodies.append(props)
        meshes.append(prepared)
    if not bodies:
        raise UsageError("Expected at least one part in the assembly")
    if len(bodies) == 1:
        total = bodies[0]
    else:
        total = combine(bodies, name="assembly")
        _warn_about_part_overlaps(meshes, [b.name for b in bodies])
    total = total.with_mass(mass) if mass is not None else total
    _warn_about_principal(total, total.name)
    return total


def _warn_about_part_overlaps(meshes, names) -> None:
    """Warn when the parts of an assembly overlap each other (their shared volume counts twice).

    The parts' checked meshes are put side by side and the shell classification of :func:`prepare_mesh` is
    run on the whole: bodies found inside another body beyond those already inside their own part overlap
    across parts.
    """
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    label_offsets = np.cumsum([0] + [len(m.shells) for m in meshes[:-1]])
    vertices = np.vstack([m.vertices for m in meshes])
    faces = np.vstack([m.faces.astype(np.int64) + o for m, o in zip(meshes, offsets)])
    labels = np.concatenate([m.labels + o for m, o in zip(meshes, label_offsets)])
    shells = [s for m in meshes for s in m.shells]
    diag = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    _, _, _, overlaps = _classify_shells(vertices, faces, labels, len(shells), shells, diag)
    within = sum(m.report.overlapping_shells for m in meshes)
    if overlaps > within:
        warnings.warn(OverlapWarning(f"assembly of {', '.join(names)}: parts overlap each other; the shared "
                                     "volume is counted once per part"), stacklevel=3)
