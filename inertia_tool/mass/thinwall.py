"""Thin-walled parts: sheet metal and hollow shells (``shell``) and 3D-printed parts (``printed``).

Two models beside the homogeneous solid of ``pipeline.mass_properties``, both from a triangle mesh:

**Shell** (``shell_mass_properties``).  The mesh is the *mid-surface* of a wall of constant thickness ``t``
(sheet metal, a thin-walled casing).  Mass ``ρ t A``; the surface integrals of ``surface`` are exact for
the triangles and the through-thickness term ``t²/12`` makes them exact for each flat triangular plate.
Open sheets are accepted (a bracket is not a closed solid); the winding does not matter.

**Printed part** (``printed_part``).  The mesh is the outer surface of a closed solid printed with a solid
skin of thickness ``s`` and a core filled to the fraction ``f`` (the slicer's infill).  To first order in
``s`` the skin is the shell of thickness ``s`` on the surface and the core is the rest of the solid:

* mass ``M ≈ ρ [f V + (1 − f) A s]``
* inertia ``I ≈ ρ [f I_solid + (1 − f) I_shell(s)]`` (both about the common centre of mass)

where ``V``, ``I_solid`` are the exact solid moments (``volume``) and ``A``, ``I_shell`` the exact shell
moments at thickness ``s``.  The approximation: the exact skin is the region between the surface and its
inward offset, whose volume is ``A s − K s² + O(s³)`` with ``K`` from
``surface.inward_offset_coefficient`` (edges where faces meet); the first-order model therefore
over-counts the skin mass by about ``ρ (1 − f) K s²`` (returned as ``mass_error_estimate``), and it
places the skin on the surface instead of ``s/2`` inside it, which over-estimates the skin's moments by
a relative ``O(s / L)``.  With infill ``f > 0`` both are second order in ``s / L`` relative to the whole
part (``L`` a typical size or radius of curvature); with ``f = 0`` (an empty skin) the inertia error is
first order, about ``s / L``.  Slicers also add top/bottom layers and perimeters of differing thickness;
model them with the mean skin thickness.

See ``docs/conventions.md`` for units and signs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..values import frozen_value
from ..mesh.checks import MeshReport, edge_topology, repeated_corner_faces, shell_labels
from ..mesh.policy import Certificate
from ..errors import InvalidMeshError, PhysicsError, UsageError
from ..mesh.options import LoadOptions
from ..mesh.plausibility import warn_implausible_density, warn_implausible_size
from ..mesh.prepare import prepare_mesh
from ..mesh.read import load_mesh
from .pipeline import MeshSource, resolve_density
from .properties import MassProperties
from .surface import inward_offset_coefficient, shell_inertia, surface_moments
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
    """A printed part (solid skin, partially filled core) and the size of its approximation.

    Attributes
    ----------
    properties : MassProperties
        kg, m, kg·m²; ``volume`` is the material volume ``f V + (1 − f) A s``, ``density`` the material's,
        ``inertia`` about the centre of mass in mesh axes (tensor convention).
    skin : float
        Skin thickness ``s``, m.
    infill : float
        Core fill fraction ``f`` in [0, 1].
    envelope_volume : float
        ``V``, m³: the volume the outer surface encloses.
    skin_volume : float
        ``A s``, m³: the first-order skin volume used.
    offset_coefficient : float
        ``K``, m (``surface.inward_offset_coefficient``): the exact skin volume is ``A s − K s² + O(s³)``.
    mass_error_estimate : float
        ``ρ (1 − f) K s² / M``: the estimated relative over-count of the mass by the first-order model
        (negative when concave edges dominate).
    inertia_error_order : str
        ``"(s/L)^2"`` when ``f > 0`` else ``"s/L"``: the order of the inertia error (see the module text).
    """

    properties: MassProperties
    skin: float
    infill: float
    envelope_volume: float
    skin_volume: float
    offset_coefficient: float
    mass_error_estimate: float
    inertia_error_order: str


def printed_part(source: MeshSource, *, skin: float, infill: float, density: float | None = None,
                 material: str | None = None, mass: float | None = None, name: str | None = None,
                 options: LoadOptions | None = None, **load_options: Any) -> PrintedPart:
    """Mass properties of a 3D-printed part: solid skin of thickness ``skin``, core filled to ``infill``.

    First order in the skin thickness; see the module docstring for the formulas and the error.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        A closed mesh (checked as for :func:`inertia_tool.mass_properties`).
    skin : float
        Skin (shell, perimeter) thickness in m.
    infill : float
        Fill fraction of the core in [0, 1] (0.2 for 20 %).
    density, material, mass
        Material density (of the filament), as in :func:`inertia_tool.mass_properties`; ``mass`` scales the
        density so that the printed part has that mass (a weighed print).
    name : str, optional
        Label for reports.
    options : LoadOptions, optional
        How to read and check the mesh.
    **load_options
        Fields of :class:`~inertia_tool.mesh.options.LoadOptions`, overriding those of ``options``.

    Returns
    -------
    PrintedPart

    Raises
    ------
    PhysicsError
        When the first-order skin volume ``A s`` reaches the enclosed volume (the part is all skin: print
        it solid, i.e. ``infill=1``, or model it as a solid).
    MeshReadError, InvalidMeshError, UsageError
    """
    s = _positive_length(skin, "skin")
    f_in = float(infill)
    if not 0.0 <= f_in <= 1.0:
        raise UsageError(f"Expected `infill` between 0 and 1, got {infill}")
    opts = LoadOptions.build(options, **load_options)
    rho, _ = resolve_density(density=density, material=material, mass=mass)
    raw = load_mesh(source, units=opts.units, max_faces=opts.max_faces)
    prepared = prepare_mesh(raw, repair=opts.repair, merge_tolerance=opts.merge_tolerance, overlap=opts.overlap)
    v, f = prepared.vertices, prepared.faces
    warn_implausible_size(raw)
    solid = volume_moments(v, f)
    sm = surface_moments(v, f, origin=solid.centroid)
    skin_volume = sm.area * s
    if skin_volume >= solid.volume:
        raise PhysicsError(f"{raw.source}: a skin of {s:g} m on {sm.area:.6g} m² is {skin_volume:.6g} m³, not less "
                           f"than the enclosed volume {solid.volume:.6g} m³: the part is all skin; "
                           "model it as a solid (infill 100%) instead")
    k = inward_offset_coefficient(v, f)
    rho_used = rho if rho is not None else 1.0
    m_core = rho_used * f_in * solid.volume
    m_skin = rho_used * (1.0 - f_in) * skin_volume
    total = m_core + m_skin
    com = (m_core * solid.centroid + m_skin * sm.centroid) / total
    i_core = second_moment_to_inertia(solid.second_moment, rho_used * f_in)
    i_skin = shell_inertia(sm, s, rho_used * (1.0 - f_in))
    shift = [(m_core, solid.centroid), (m_skin, sm.centroid)]
    inertia = i_core + i_skin
    for m_part, c in shift:
        d = c - com
        inertia = inertia + m_part * ((d @ d) * np.eye(3) - np.outer(d, d))
    volume = f_in * solid.volume + (1.0 - f_in) * skin_volume
    props = MassProperties(mass=total, volume=volume, center_of_mass=com, inertia=0.5 * (inertia + inertia.T),
                           surface_area=sm.area, density=rho_used, name=name or raw.source, mesh=prepared.report)
    if rho is None:
        assert mass is not None, "resolve_density leaves the density open only for a target mass"
        props = props.with_mass(mass)
    error = (1.0 - f_in) * k * s * s / (f_in * solid.volume + (1.0 - f_in) * skin_volume)
    return PrintedPart(properties=props, skin=s, infill=f_in, envelope_volume=solid.volume, skin_volume=skin_volume,
                       offset_coefficient=k, mass_error_estimate=float(error),
                       inertia_error_order="(s/L)^2" if f_in > 0 else "s/L")
