"""From a mesh source to ``MassProperties``: read → prepare → integrate → assemble.

This is the public entry point of the engine (``inertia_tool.mass_properties``).  Reading
(:mod:`inertia_tool.mesh.read`) and the decisions about what the triangles mean as a solid
(:mod:`inertia_tool.mesh.prepare`) happen in the mesh layer; this module turns the prepared shells into
bodies with a density, checks the result (finite, physically valid) and names the principal-axis results
that are a choice (equal moments) or at round-off (needles).
"""

from __future__ import annotations

import dataclasses
import math
import os
import warnings
from typing import TYPE_CHECKING, Any, Iterable, Mapping, TypeAlias

import numpy as np

from ..errors import InvalidMeshError, NearlyEqualMomentsWarning, OverlapWarning, PhysicalValidityWarning, UsageError
from ..mesh.classify import classify_shells
from ..mesh.hole_assumptions import UserAssumptions
from ..mesh.options import LoadOptions
from ..mesh.plausibility import warn_implausible_density, warn_implausible_size
from ..mesh.precision import warn_storage_precision
from ..mesh.clean_part import prepare_clean
from ..mesh.prepare import OVERLAP_MODES, PreparedMesh, prepare_mesh
from ..mesh.read import RawMesh, load_mesh
from ..tolerances import NEEDLE_RTOL, PART_OVERLAP_RTOL, TRIANGLE_INEQUALITY_RTOL
from ..units import material_density
from .properties import MassProperties, combine
from ..integrals import VolumeMoments, second_moment_to_inertia

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

    from ..mesh.checks import MeshReport
    from numpy.typing import ArrayLike


__all__ = ["mass_properties", "assembly", "resolve_density", "DEFAULT_DENSITY"]

#: What :func:`~inertia_tool.mesh.read.load_mesh` reads: a file, a ``trimesh.Trimesh``, a pair of arrays
#: ``vertices (n, 3)`` and ``faces (m, 3)``, or a ``RawMesh`` read before.
MeshSource: TypeAlias = "str | os.PathLike[str] | trimesh.Trimesh | tuple[ArrayLike, ArrayLike] | RawMesh"

#: Density used when none of density / material / mass is given (water), kg/m³.  Reports say so.
DEFAULT_DENSITY = 1000.0

_EPS = float(np.finfo(np.float64).eps)
_TINY = float(np.finfo(np.float64).tiny)



def resolve_density(*, density: float | None = None, material: str | None = None,
                    mass: float | None = None) -> tuple[float | None, str]:
    """Decide the density from at most one of ``density``, ``material`` or ``mass``.

    Parameters
    ----------
    density : float, optional
        kg/m³, positive and finite.
    material : str, optional
        A name from :data:`inertia_tool.units.MATERIALS`.
    mass : float, optional
        A target total mass, kg: the density follows from the volume later.

    Returns
    -------
    (float or None, str)
        The density (``None`` when a target mass is used; 1000 kg/m³ when nothing is given) and a description
        for reports.
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


def _check_finite(props: MassProperties, source: str) -> None:
    """Refuse a result with a non-finite number (never print inf or NaN as a mass property)."""
    scalars = (props.mass, props.volume, props.surface_area)
    if not (all(map(math.isfinite, scalars)) and np.isfinite(props.center_of_mass).all()
            and np.isfinite(props.inertia).all()):
        raise InvalidMeshError(f"{source}: the mass properties overflow or are undefined (non-finite values); "
                               "check the coordinates' size and the length unit")


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
    moments = pa.moments.tolist()
    top = max(abs(m) for m in moments)                 # NaN cannot reach here: the tensor was checked finite
    if top > 0 and moments[0] <= NEEDLE_RTOL * top:
        digits = -math.log10(_EPS * top / max(abs(moments[0]), _TINY))
        warnings.warn(PhysicalValidityWarning(
            f"{source}: the smallest principal moment ({pa.moments[0]:.3g} kg·m²) is below {NEEDLE_RTOL:g} of "
            f"the largest (a needle); it carries only about {max(digits, 0):.0f} correct digits"), stacklevel=3)


def _shell_properties(s: VolumeMoments, density: float, name: str, mesh: MeshReport | None = None) -> MassProperties:
    return MassProperties(mass=density * s.volume, volume=s.volume, center_of_mass=s.centroid,
                          inertia=second_moment_to_inertia(s.second_moment, density), surface_area=s.area,
                          density=density, name=name, mesh=mesh)


def _bodies(prepared: PreparedMesh, density: float, name: str) -> list[MassProperties]:
    bodies: list[MassProperties] = []
    owners = sorted(set(prepared.owner.tolist()))     # not np.unique: it imports numpy.ma (~10 ms) on each run
    for b in owners:
        members = [prepared.shells[k] for k in np.flatnonzero(prepared.owner == b)]
        props = [_shell_properties(s, density, name) for s in members]
        if len(props) == 1 and len(owners) == 1:     # one shell: the copy below would equal it field for field
            bodies.append(props[0])
            continue
        volume = sum(s.volume for s in members)
        if not volume > 0:      # a cavity as large as its body (session 14: a void split exactly into two boxes
            raise InvalidMeshError(           # inside it, touching up to rounding; combine() raised a UsageError)
                f"{name}: a body and its cavities as read by nesting depth enclose no material ({volume:.3g} m³): "
                "the shells are wound or nested so that a cavity fills its body; fix the winding of the part meant")
        body = props[0] if len(props) == 1 else combine(props, name=name)
        bodies.append(MassProperties(mass=body.mass, volume=body.volume, center_of_mass=body.center_of_mass,
                                     inertia=body.inertia, surface_area=body.surface_area, density=density,
                                     name=f"{name} body {len(bodies) + 1}" if len(owners) > 1 else name))
    return bodies


def mass_properties(source: MeshSource, *, density: float | None = None, material: str | None = None,
                    mass: float | None = None, name: str | None = None, options: LoadOptions | None = None,
                    material_map: Mapping[str, float | str] | None = None, fast_path: bool = False,
                    **load_options: Any) -> MassProperties:
    """Mass properties of the solid bounded by a triangle mesh, exact for the polyhedron.

    Parameters
    ----------
    source : str or os.PathLike or trimesh.Trimesh or (vertices, faces)
        The mesh (see :func:`inertia_tool.mesh.read.load_mesh`).
    density : float, optional
        kg/m³.
    material : str, optional
        Name from :data:`inertia_tool.units.MATERIALS` (e.g. ``"aluminium"``, ``"steel"``, ``"PLA"``).
    mass : float, optional
        Target total mass in kg; the density is set to ``mass / volume``.
        At most one of ``density``, ``material``, ``mass``; none means 1000 kg/m³ (water).
    name : str, optional
        Label for reports; defaults to the source.
    options : LoadOptions, optional
        How to read and check the mesh (units, repair, merge tolerance, face limit).
    material_map : mapping of str to float or str, optional
        For a file (a path) that names materials per part (a 3MF with base materials or slicer filaments, a STEP
        assembly): part name, ``object ID`` or material name → density (kg/m³) or material name.  Such a file
        is integrated part by part (:mod:`inertia_tool.mass.materials` gives the rule that decides each
        density; ``density``/``material`` are then the default of the parts the file names no material for)
        and the result's ``parts`` are the parts.
    fast_path : bool
        Try the clean-part fast path first (:func:`~inertia_tool.mesh.clean_part.prepare_clean`: one closed,
        consistently wound shell whose faces meet nowhere else, the same checks in fewer steps), falling back to
        the full checks for any other mesh.  The result is the same either way, field for field; ``inertia-tool
        batch`` sets it (its per-part cost is mostly such steps).
    **load_options
        Fields of :class:`~inertia_tool.mesh.options.LoadOptions` (``units="mm"``, ``repair=True``, ...),
        a shortcut that overrides those of ``options``.

    Returns
    -------
    MassProperties
        SI; ``inertia`` about the centre of mass in mesh axes (tensor convention).  ``mesh`` holds the
        :class:`~inertia_tool.mesh.checks.MeshReport`; ``parts`` the bodies when the mesh has several.

    Raises
    ------
    MeshReadError, InvalidMeshError, UsageError
    """
    opts = LoadOptions.build(options, **load_options)
    rho, _ = resolve_density(density=density, material=material, mass=mass)
    if isinstance(source, (str, bytes, os.PathLike)):
        # a file is read here once: when it names materials per part, they decide (a RawMesh passed in is
        # integrated as one solid of the given density, whatever parts it lists: robot geometry at unit density)
        raw = load_mesh(source, units=opts.units, max_faces=opts.max_faces,
                        declared_units_win=opts.declared_units_win)
        if raw.parts or material_map:       # a multi-material file: its parts, each with its own density
            from .materials import material_parts, unused_map_keys
            used: set[str] = set()
            specs = material_parts(raw, material_map=material_map, density=density, material=material, used=used)
            unused_map_keys(material_map, used, [raw])
            for spec in specs:
                spec.pop("decided_by", None)
            return assembly(specs, mass=mass, options=opts, name=name or raw.source)
        source = raw
    elif material_map:
        raise UsageError("`material_map` applies to a file that names parts or materials (give its path), not to "
                         f"{type(source).__name__}")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # non-finite results refused below
        return _part(source, rho, mass, opts, name=name, fast_path=fast_path)[0]


def _part(source: MeshSource, rho: float | None, mass: float | None, options: LoadOptions, *, name: str | None,
          warn_principal: bool = True, self_crossing: str = "refuse",
          fast_path: bool = False) -> tuple[MassProperties, PreparedMesh]:
    """Mass properties of one mesh and its checked mesh (for cross-part checks of an assembly).

    ``self_crossing`` is passed to :func:`~inertia_tool.mesh.prepare.prepare_mesh` (``"unverified"`` only for
    meshes the package made itself by a boolean: spin-it's hollowed parts); ``fast_path`` tries
    :func:`~inertia_tool.mesh.clean_part.prepare_clean` first (the same result on the parts it takes)."""
    raw = load_mesh(source, units=options.units, max_faces=options.max_faces,
                    declared_units_win=options.declared_units_win)
    prepared = prepare_clean(raw) if fast_path and options.overlap in OVERLAP_MODES else None
    if prepared is None:
        prepared = prepare_mesh(raw, repair=options.repair, merge_tolerance=options.merge_tolerance,
                                overlap=options.overlap, self_crossing=self_crossing,
                                assume=UserAssumptions(options.assume))
    label = name or raw.source
    warn_implausible_size(raw, stacklevel=4)
    if len(prepared.shells) == 1:          # one shell, one body: made once, with its report (what the copy below is)
        result = _shell_properties(prepared.shells[0], rho if rho is not None else 1.0, label, prepared.report)
    else:
        bodies = _bodies(prepared, rho if rho is not None else 1.0, label)
        total = bodies[0] if len(bodies) == 1 else combine(bodies, name=label)
        result = MassProperties(mass=total.mass, volume=total.volume, center_of_mass=total.center_of_mass,
                                inertia=total.inertia, surface_area=total.surface_area,
                                density=rho if rho is not None else 1.0, name=label, mesh=prepared.report,
                                parts=tuple(bodies) if len(bodies) > 1 else ())
    if rho is None:
        assert mass is not None, "resolve_density leaves the density open only for a target mass"
        result = result.with_mass(mass)
        warn_implausible_density(label, result.density, mass, result.volume, stacklevel=4)
    _check_finite(result, label)
    _check_physical(result)
    warn_storage_precision(raw, result.volume, stacklevel=4)
    if warn_principal:
        _warn_about_principal(result, label)
    return result, prepared


def _check_physical(props: MassProperties, rtol: float = TRIANGLE_INEQUALITY_RTOL) -> None:
    """Warn when the principal moments fail positivity or the triangle inequality beyond round-off.

    For a real body ``I_k > 0`` and ``I1 + I2 ≥ I3`` (the perpendicular-axis theorem of §4.3.2 turned into an
    inequality); failing them means a mesh problem the checks did not catch (e.g. overlapping shells).
    """
    i1, i2, i3 = props.principal.moments
    if not (i1 > -rtol * i3 and i1 + i2 >= i3 * (1 - rtol)):
        warnings.warn(PhysicalValidityWarning(
            f"{props.name}: principal moments ({i1:.6g}, {i2:.6g}, {i3:.6g}) kg·m² violate positivity or the "
            "triangle inequality I1 + I2 ≥ I3: the mesh does not describe a physical body"), stacklevel=3)


def assembly(parts: Iterable[Mapping[str, Any]], *, mass: float | None = None, options: LoadOptions | None = None,
             name: str = "assembly", **load_options: Any) -> MassProperties:
    """Combine several meshes, each with its own material, into one rigid body.

    Parameters
    ----------
    parts : iterable of dict
        Each ``{"source": path_or_mesh, "density": kg/m³}``, ``{"source": ..., "material": name}`` or
        ``{"source": ..., "mass": kg}``
        (optionally ``"units"``, ``"name"`` and ``"material_label"``, the material's name for reports when the
        density is given as a number; a part's ``"units"`` overrides the options' units; ``"file_part": True``
        for a part of a multi-material file, which keeps even a single part listed in ``parts``).
    mass : float, optional
        Scale the whole assembly to this total mass (kg), keeping the density ratios.
    options : LoadOptions, optional
        How to read and check every part.
    name : str
        Label of the whole for reports.
    **load_options
        Fields of :class:`~inertia_tool.mesh.options.LoadOptions`, overriding those of ``options``.
    """
    opts = LoadOptions.build(options, **load_options)
    bodies: list[MassProperties] = []
    meshes: list[PreparedMesh] = []
    file_parts = False
    for spec in parts:
        spec = dict(spec)
        file_parts |= bool(spec.pop("file_part", False))
        src = spec.pop("source")
        part_mass = spec.pop("mass", None)
        material = spec.pop("material", None)
        label = spec.pop("material_label", None) or material or ""
        rho, _ = resolve_density(density=spec.pop("density", None), material=material, mass=part_mass)
        part_options = opts.replace(units=spec.pop("units")) if "units" in spec else opts
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            # equal moments of one part say nothing about the assembly: checked once on the whole below
            props, prepared = _part(src, rho, part_mass, part_options, name=spec.pop("name", None),
                                    warn_principal=False)
        if label:
            props = dataclasses.replace(props, material=str(label))
        bodies.append(props)
        meshes.append(prepared)
    if not bodies:
        raise UsageError("Expected at least one part in the assembly")
    if len(bodies) == 1 and not file_parts:
        total = bodies[0]
    elif len(bodies) == 1:                 # one part of a multi-material file: the parts table still shows it
        total = combine(bodies, name=name)
    else:
        total = combine(bodies, name=name)
        _warn_about_part_overlaps(meshes, [b.name for b in bodies], [b.material for b in bodies])
    if mass is not None:
        total = total.with_mass(mass)
        warn_implausible_density(total.name, total.mass / total.volume, mass, total.volume)
    _warn_about_principal(total, total.name)
    return total


def _warn_about_part_overlaps(meshes: list[PreparedMesh], names: list[str], materials: list[str] | None = None,
                              rtol: float = PART_OVERLAP_RTOL) -> None:
    """Warn when the parts of an assembly overlap each other (their shared volume counts twice).

    The parts' checked meshes are put side by side and the shell classification of :func:`prepare_mesh` is
    run on the whole: bodies found inside another body beyond those already inside their own part may overlap
    across parts.  Then the volume each pair shares is measured (:func:`~inertia_tool.mesh.overlap.shared_volumes`);
    pairs sharing at most ``rtol`` of the smaller part only touch (coincident faces, written coordinates
    rounded) and are not reported.  When the measure is not available, the classification's word stands.
    """
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    label_offsets = np.cumsum([0] + [len(m.shells) for m in meshes[:-1]])
    vertices = np.vstack([m.vertices for m in meshes])
    faces = np.vstack([m.faces.astype(np.int64) + o for m, o in zip(meshes, offsets)])
    labels = np.concatenate([m.labels + o for m, o in zip(meshes, label_offsets)])
    shells = [s for m in meshes for s in m.shells]
    diag = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    _, _, _, overlaps = classify_shells(vertices, faces, labels, len(shells), shells, diag)
    within = sum(m.report.overlapping_shells for m in meshes)
    if overlaps <= within:
        return
    from ..mesh.overlap import shared_volumes      # imported on use: assemblies whose parts may overlap only
    shared = shared_volumes([(m.vertices, m.faces) for m in meshes]) if all(
        m.report.watertight for m in meshes) else None
    if shared is None:
        warnings.warn(OverlapWarning(f"assembly of {', '.join(names)}: parts overlap each other; the shared "
                                     "volume is counted once per part"), stacklevel=3)
        return
    volumes = [abs(sum(s.volume for s in m.shells)) for m in meshes]
    found = [(i, j, v) for (i, j), v in shared.items() if v > rtol * max(min(volumes[i], volumes[j]), 0.0)]
    if not found:
        return
    materials = materials or [""] * len(names)

    def who(k: int) -> str:
        return f"{names[k]} ({materials[k]})" if materials[k] else names[k]
    pairs = "; ".join(f"{who(i)} and {who(j)} share {v:.4g} m³ ({100 * v / min(volumes[i], volumes[j]):.3g}% of the "
                      "smaller)" for i, j, v in found)
    warnings.warn(OverlapWarning(f"assembly of {', '.join(names)}: parts overlap: {pairs}; the shared volume is "
                                 "counted once per part (its mass with each part's density)"), stacklevel=3)
