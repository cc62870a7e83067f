"""Thin-walled parts: sheet metal and hollow shells (``shell``) and 3D-printed parts (``printed``).

Two models beside the homogeneous solid of ``pipeline.mass_properties``, both from a triangle mesh:

**Shell** (``shell_mass_properties``).  The mesh is the *mid-surface* of a wall of constant thickness ``t``
(sheet metal, a thin-walled casing).  Mass ``ρ t A``; the surface integrals of ``surface`` are exact for
the triangles and the through-thickness term ``t²/12`` makes them exact for each flat triangular plate.
Open sheets are accepted (a bracket is not a closed solid); the winding does not matter.

**Printed part** (``printed_part``).  The mesh is the outer surface of a closed solid printed with a solid
skin of thickness ``s`` and a core filled to the fraction ``f`` (the slicer's infill).  The skin is the part
less its inward offset by ``s`` (every point within ``s`` of the surface, as a slicer's perimeters and top and
bottom layers of that thickness make it); the core is the inward offset, integrated by
:func:`inertia_tool.mass.offset.core_moments` with a bracket that holds for any closed mesh:

* mass ``M = ρ [V − (1 − f) V_core]``
* second moment ``∫ x xᵀ dm = ρ [J − (1 − f) J_core]`` (about the solid's centroid), then the inertia about
  the centre of mass by the parallel-axis theorem

where ``V``, ``J`` are the exact solid moments (``volume``).  On a box, a cylinder and a sphere the core is
known in closed form and the estimate is within about 1e-4 of it; the reported bounds are wider (about
1–3 % of the mass at the default resolution) because they assume nothing about the shape.

See ``docs/conventions.md`` for units and signs.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..values import frozen_value
from ..mesh.checks import MeshReport, edge_topology, repeated_corner_faces, shell_labels
from ..mesh.policy import Certificate
from ..errors import InvalidMeshError, UsageError
from ..mesh.uncertainty import Uncertainty
from ..mesh.hole_assumptions import UserAssumptions
from ..mesh.options import LoadOptions
from ..mesh.plausibility import warn_implausible_density, warn_implausible_size
from ..mesh.prepare import prepare_mesh
from ..mesh.read import load_mesh
from .pipeline import MeshSource, resolve_density
from .properties import MassProperties
from .offset import DEFAULT_BAND_CELLS, CoreMoments, core_moments, vertical_skin_moments
from .surface import shell_inertia, surface_moments
from ..integrals import second_moment_to_inertia, volume_moments

__all__ = ["shell_mass_properties", "printed_part", "PrintedPart"]


def _positive_length(value: float, name: str) -> float:
    x = float(value)
    if not (np.isfinite(x) and x > 0):
        raise UsageError(f"Expected `{name}` to be a positive finite length in m, got {value}")
    return x


def shell_mass_properties(source: MeshSource, *, thickness: float, density: float | None = None,
                          material: str | None = None, mass: float | None = None, name: str | None = None,
                          options: LoadOptions | None = None, **load_options: Any) -> MassProperties:
    """Mass properties of a thin wall of constant ``thickness`` whose mid-surface is the mesh.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        The mid-surface (open or closed; any winding).
    thickness : float
        Wall thickness in m (SI; the command line parses ``2mm``).
    density, material, mass
        As in :func:`inertia_tool.mass_properties` (at most one; none means 1000 kg/m³).
    name : str, optional
        Label for reports.
    options : LoadOptions, optional
        How to read the mesh (``units``, ``max_faces``; the surface need not be closed, so ``repair`` and
        ``merge_tolerance`` do not apply).
    **load_options
        Fields of :class:`~inertia_tool.mesh.options.LoadOptions`, overriding those of ``options``.

    Returns
    -------
    MassProperties
        ``mass = ρ t A``; ``volume = t A`` (material volume); ``inertia`` about the centre of mass in mesh
        axes (tensor convention); ``surface_area = A`` (the mid-surface).  Exact for the union of flat
        triangular plates of thickness ``t``; a wall curved or bent at radius ``R`` errs by a relative
        ``O((t/R)²)`` (see :mod:`inertia_tool.mass.surface`).

    Raises
    ------
    MeshReadError, InvalidMeshError, UsageError
    """
    t = _positive_length(thickness, "thickness")
    opts = LoadOptions.build(options, **load_options)
    rho, _ = resolve_density(density=density, material=material, mass=mass)
    raw = load_mesh(source, units=opts.units, max_faces=opts.max_faces)
    warn_implausible_size(raw)
    v, f = raw.vertices, raw.faces
    if len(f) == 0:
        raise InvalidMeshError(f"{raw.source}: the mesh has no triangles")
    repeated = repeated_corner_faces(f)
    f = f[~repeated]
    if len(f) == 0:
        raise InvalidMeshError(f"{raw.source}: all triangles are degenerate (no area)")
    sm = surface_moments(v, f)
    zero_area = sm.zero_area_faces
    if not sm.area > 0:
        raise InvalidMeshError(f"{raw.source}: the surface has no area")
    topo = edge_topology(f, len(v), v)
    _, n_shells = shell_labels(f, len(v))
    used = v[np.unique(f)]
    report = MeshReport(source=raw.source, units=raw.units, file_faces=raw.file_faces, vertices=len(used),
                        faces=len(f), degenerate_faces=int(np.count_nonzero(repeated)), zero_area_faces=zero_area,
                        bodies=n_shells, cavities=0, flipped_shells=0, overlapping_shells=0,
                        watertight=topo.oriented, welded_tolerance=None, repaired=False, repair_actions=(),
                        repair_volume_change=None, bbox_min=used.min(axis=0), bbox_max=used.max(axis=0),
                        certificate=Certificate("exact", ("thin-wall-model",)))
    rho_used = rho if rho is not None else 1.0
    props = MassProperties(mass=rho_used * t * sm.area, volume=t * sm.area, center_of_mass=sm.centroid,
                           inertia=shell_inertia(sm, t, rho_used), surface_area=sm.area, density=rho_used,
                           name=name or raw.source, mesh=report)
    if rho is None:
        assert mass is not None, "resolve_density leaves the density open only for a target mass"
        props = props.with_mass(mass)
        warn_implausible_density(props.name, props.density, mass, props.volume)
    return props


@frozen_value
class PrintedPart:
    """A printed part (solid skin, partially filled core) with the bounds of its integration.

    Attributes
    ----------
    properties : MassProperties
        kg, m, kg·m²; ``volume`` is the material volume ``V − (1 − f) V_core``, ``density`` the material's,
        ``inertia`` about the centre of mass in mesh axes (tensor convention).
    skin : float
        Skin thickness ``s``, m.
    infill : float
        Core fill fraction ``f`` in [0, 1].
    envelope_volume : float
        ``V``, m³: the volume the outer surface encloses (exact).
    core_volume : float
        ``V_core``, m³: the volume of the inward offset by ``s`` (estimate).
    skin_volume : float
        ``V − V_core``, m³.
    mass_error_bound : float
        The relative error of the mass is at most this (0 when the core is empty or ``f = 1``: then exact).
    center_of_mass_error_bound : float
        The centre of mass is within this distance of the reported one, m.
    inertia_error_bound : float
        The spectral norm of the inertia tensor's error is at most this fraction of the largest principal
        moment.
    cell_size : float
        Edge of the finest cells of the core's integration, m (0 when none was needed).
    top, bottom : float
        Vertical thickness of the solid top and bottom layers, m (0: the skin alone; see ``printed_part``).
    """

    properties: MassProperties
    skin: float
    infill: float
    envelope_volume: float
    core_volume: float
    skin_volume: float
    mass_error_bound: float
    center_of_mass_error_bound: float
    inertia_error_bound: float
    cell_size: float
    top: float = 0.0
    bottom: float = 0.0


def printed_part(source: MeshSource, *, skin: float, infill: float, density: float | None = None,
                 material: str | None = None, mass: float | None = None, name: str | None = None,
                 band_cells: int = DEFAULT_BAND_CELLS, options: LoadOptions | None = None,
                 top: float | None = None, bottom: float | None = None, **load_options: Any) -> PrintedPart:
    """Mass properties of a 3D-printed part: solid skin of thickness ``skin``, core filled to ``infill``.

    The skin is the part less its inward offset by ``skin`` (every point within ``skin`` of the surface); the
    core (the rest) holds the fraction ``infill`` of solid material.  With ``V``, ``J`` the exact moments of the
    solid and ``V_c``, ``J_c`` those of the core (``offset.core_moments``)::

        M = ρ [V − (1 − f) V_c],   ∫ x x^T dm = ρ [J − (1 − f) J_c]

    and the inertia follows by Eqs. (4.11)/(4.13) of Chapter 4 ("Rigid Body Motion") and the parallel-axis
    theorem.  The bounds of the core's integration carry over to ``mass_error_bound``,
    ``center_of_mass_error_bound`` and ``inertia_error_bound``, which hold for any closed mesh.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        A closed mesh (checked as for :func:`inertia_tool.mass_properties`).
    skin : float
        Skin (wall) thickness in m, measured along the surface normal.
    infill : float
        Fill fraction of the core in [0, 1] (0.2 for 20 %).
    density, material, mass
        Material density (of the filament), as in :func:`inertia_tool.mass_properties`; ``mass`` scales the
        density so that the printed part has that mass (a weighed print).
    name : str, optional
        Label for reports.
    band_cells : int
        Resolution of the core's integration (see ``offset.core_moments``): more is slower and tighter.
    options : LoadOptions, optional
        How to read and check the mesh.
    top, bottom : float, optional
        Vertical thickness (m) of the solid top and bottom layers as a slicer makes them (layers × layer
        height): every point of the core within ``top`` below an up-facing surface, or within ``bottom`` above a
        down-facing one, measured vertically, is solid too (``offset.vertical_skin_moments``).  A thickness up
        to ``skin`` adds nothing (the skin already holds it).  The bracket of that integration joins the
        bounds; it assumes only a closed, consistently oriented mesh.
    **load_options
        Fields of :class:`~inertia_tool.mesh.options.LoadOptions`, overriding those of ``options``.

    Returns
    -------
    PrintedPart

    Raises
    ------
    MeshReadError, InvalidMeshError, UsageError
    """
    s = _positive_length(skin, "skin")
    f_in = float(infill)
    if not 0.0 <= f_in <= 1.0:
        raise UsageError(f"Expected `infill` between 0 and 1, got {infill}")
    opts = LoadOptions.build(options, **load_options)
    rho, _ = resolve_density(density=density, material=material, mass=mass)
    raw = load_mesh(source, units=opts.units, max_faces=opts.max_faces)
    prepared = prepare_mesh(raw, repair=opts.repair, merge_tolerance=opts.merge_tolerance, overlap=opts.overlap,
                            assume=UserAssumptions(opts.assume))
    v, f = prepared.vertices, prepared.faces
    warn_implausible_size(raw)
    solid = volume_moments(v, f)
    area = surface_moments(v, f, origin=solid.centroid).area
    o = solid.centroid
    rho_used = rho if rho is not None else 1.0
    core = core_moments(v, f, s, origin=o, band_cells=band_cells) if f_in < 1.0 else None
    top_m = 0.0 if top is None else _non_negative_length(top, "top")
    bottom_m = 0.0 if bottom is None else _non_negative_length(bottom, "bottom")
    if core is not None and max(top_m, bottom_m) > s:
        core = _less_layers(core, vertical_skin_moments(v, f, s, top=top_m, bottom=bottom_m, origin=o,
                                                        band_cells=band_cells))
    void = 1.0 - f_in
    if core is None or core.volume_bounds[1] == 0.0:            # solid throughout: exact
        vc, sc, jc, b_v, b_s, b_j, cell = 0.0, np.zeros(3), np.zeros((3, 3)), 0.0, 0.0, 0.0, 0.0
        if core is not None:
            cell = core.cell_size
    else:
        vc, sc, jc, cell = core.volume, core.first_moment, core.second_moment, core.cell_size
        b_v = max(vc - core.volume_bounds[0], core.volume_bounds[1] - vc)
        b_s, b_j = core.first_moment_bound, core.second_moment_bound
    total = rho_used * (solid.volume - void * vc)
    first = -rho_used * void * sc                               # the solid's own first moment about o is 0
    second = rho_used * (solid.second_moment - void * jc)
    com = o + first / total
    inertia_o = second_moment_to_inertia(second, 1.0)
    q = (first @ first) * np.eye(3) - np.outer(first, first)
    inertia = inertia_o - q / total
    inertia = 0.5 * (inertia + inertia.T)
    bound_m, bound_s, bound_j = rho_used * void * b_v, rho_used * void * b_s, rho_used * void * b_j
    m_low = total - bound_m
    size = float(np.linalg.norm(first))
    if m_low > 0:
        com_bound = (bound_s + size / total * bound_m) / m_low
        shift_bound = 2.0 * bound_s * (2.0 * size + bound_s) / m_low + size * size * bound_m / (total * m_low)
        inertia_bound = (bound_j + shift_bound) / float(np.max(np.linalg.eigvalsh(inertia)))
    else:                                                       # pragma: no cover - a core bound past the solid
        com_bound = inertia_bound = float("inf")
    volume = solid.volume - void * vc
    report = prepared.report
    if bound_m > 0:
        # the printed model's bounds join the mesh's own (an estimate of a damaged file adds its own bounds);
        # the spectral bound becomes a Frobenius one through ‖E‖_F ≤ √3 ‖E‖₂ and ‖I‖_F ≥ λ_max
        own = report.uncertainty
        mine = Uncertainty(mass=bound_m / total, center_of_mass=float(com_bound),
                           inertia=float(np.sqrt(3.0) * inertia_bound), volume_in_doubt=float(void * b_v))
        if own is not None:
            mine = Uncertainty(mass=own.mass + mine.mass, center_of_mass=own.center_of_mass + mine.center_of_mass,
                               inertia=own.inertia + mine.inertia,
                               volume_in_doubt=own.volume_in_doubt + mine.volume_in_doubt)
        report = dataclasses.replace(report, method=f"{report.method}, inward offset", uncertainty=mine,
                                     certificate=Certificate("estimate", tuple(report.certificate.checks)
                                                             + ("inward-offset-bound",),
                                                             report.certificate.assumptions))
    props = MassProperties(mass=total, volume=volume, center_of_mass=com, inertia=inertia,
                           surface_area=area, density=rho_used, name=name or raw.source, mesh=report)
    if rho is None:
        assert mass is not None, "resolve_density leaves the density open only for a target mass"
        props = props.with_mass(mass)
    return PrintedPart(properties=props, skin=s, infill=f_in, envelope_volume=solid.volume, core_volume=vc,
                       skin_volume=solid.volume - vc, mass_error_bound=bound_m / total,
                       center_of_mass_error_bound=float(com_bound), inertia_error_bound=float(inertia_bound),
                       cell_size=cell, top=top_m, bottom=bottom_m)


def _non_negative_length(value: Any, name: str) -> float:
    length = float(value)
    if not (np.isfinite(length) and length >= 0):
        raise UsageError(f"Expected `{name}` to be a finite length ≥ 0 in m, got {value!r}")
    return length


def _less_layers(core: CoreMoments, layers: CoreMoments) -> CoreMoments:
    """The core's moments less those of the part the top/bottom layers make solid; brackets add (the two
    integrations' errors are independent bounds)."""
    low = core.volume_bounds[0] - layers.volume_bounds[1]
    high = core.volume_bounds[1] - layers.volume_bounds[0]
    return dataclasses.replace(core, volume=core.volume - layers.volume,
                               volume_bounds=np.array([max(low, 0.0), max(high, 0.0)]),
                               first_moment=core.first_moment - layers.first_moment,
                               first_moment_bound=core.first_moment_bound + layers.first_moment_bound,
                               second_moment=core.second_moment - layers.second_moment,
                               second_moment_bound=core.second_moment_bound + layers.second_moment_bound)
