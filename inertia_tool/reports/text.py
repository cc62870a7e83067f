"""Human-readable text report of ``analyze``.  Formatting only: every number comes from the engine."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..mass.properties import MassProperties
from .serialize import TENSOR_CONVENTION
from .numbers import number, round_off_zero
from ..rounding import round_up

if TYPE_CHECKING:
    from ..mesh.checks import MeshReport

__all__ = ["format_mass_properties"]


def _num(x: float) -> str:
    return number(x)


def _clean(a, rel: float = 1e-12, scale: float = 0.0) -> np.ndarray:
    """Display only: entries below ``rel`` times the largest magnitude (or ``scale``, if larger) print as 0
    (round-off, not data)."""
    return round_off_zero(a, rel, scale)


def _vec(v, scale: float = 0.0, rel: float = 1e-12) -> str:
    return "(" + ", ".join(f"{x: .6g}" for x in _clean(v, rel=rel, scale=scale)) + ")"


def _position(v, size: float) -> str:
    """A point, with coordinates below 1e-10 of the part size shown as 0 (float32 STL coordinates carry
    ~6e-8 relative precision, so such offsets are round-off of the integration, not geometry)."""
    return _vec(v, size, rel=1e-10)


def _parts_table(props: MassProperties, size: float) -> list[str]:
    """The parts of an assembly, one row each (like a CAD assembly's mass properties report): name, material,
    density, mass, volume, centre of mass and the certificate of its own integral; the totals above are their
    sum about the common centre of mass (parallel-axis theorem, Chapter 4 "Rigid Body Motion", Eq. (4.16))."""
    header = ["part", "material", "density (kg/m³)", "mass (kg)", "volume (m³)", "centre of mass (m)", "certificate"]
    rows = [[b.name, b.material or "-", f"{b.density:.6g}", _num(b.mass), _num(b.volume),
             _position(b.center_of_mass, size),
             b.mesh.certificate.brief() if b.mesh is not None else "-"] for b in props.parts]
    widths = [max(len(r[k]) for r in [header, *rows]) for k in range(len(header))]
    lines = [f"  parts ({len(props.parts)}), each integrated alone; the totals above are their sum about the common "
             "centre of mass (parallel-axis theorem, Eq. 4.16):"]
    for r in [header, *rows]:
        lines.append("    " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return lines


def _matrix(m, indent: str) -> list[str]:
    m = _clean(m)
    return [indent + "[" + "  ".join(f"{x: .6e}" for x in row) + " ]" for row in m]


def method_line(mesh) -> str:
    """One line: whether the numbers are exact, how the solid was read, and the bounds of an estimate."""
    if mesh is None:
        return "exact"
    u = mesh.uncertainty
    if u is None and mesh.certificate.kind == "unverified":
        return (f"NOT VERIFIED (method: {mesh.method}): the integral of the surface as it stands; the check for "
                "faces crossing each other did not finish, so the surface may pass through itself")
    if u is None and mesh.certificate.kind == "united":     # review19: said "exact for the polyhedron" above it
        return (f"exact for the united solid, the region of winding number ≥ 1 (method: {mesh.method}; the "
                "certificate lists the checks that establish it)")
    if u is None:
        extra = " (shared volume of overlapping bodies counted twice, on request)" if mesh.method == "sum" else ""
        return f"exact for the polyhedron (method: {mesh.method}){extra}"
    why = ("the printed part's core is integrated numerically" if mesh.method.endswith("inward offset")
           else "the file's winding does not decide whether a shell inside another is a cavity or a body"
           if mesh.method == "nesting" else "the tolerance weld moved corners; bounded by how far (the weld's sweep)"
           if mesh.method in ("welded", "deduplicated", "sealed") else "the file does not define a closed solid")
    return (f"ESTIMATE (method: {mesh.method}; {why}): mass within "
            f"±{round_up(100 * u.mass):.3g}%, centre of mass within {round_up(u.center_of_mass):.3g} m, inertia within "
            f"±{round_up(100 * u.inertia):.3g}% (Frobenius)")


def format_mass_properties(props: MassProperties, *, density_source: str | None = None,
                           result: str | None = None) -> str:
    """Multi-line report: units, volume, mass, COM, inertia (about COM and mesh origin), principal axes,
    radii of gyration, physical checks and mesh diagnostics.  ``result`` replaces the line saying where the
    numbers come from (:func:`method_line` of the mesh; a STEP file's exact B-rep says so)."""
    pa = props.principal
    lines = [f"Mass properties of {props.name}"]
    mesh = props.mesh
    size = float(np.linalg.norm(mesh.bbox_max - mesh.bbox_min)) if mesh is not None else 0.0
    unit_note = f" (mesh coordinates in {mesh.units}, converted)" if mesh is not None else ""
    lines.append(f"  result: {result or method_line(mesh)}")
    if mesh is not None:
        lines.append(f"  certificate: {mesh.certificate.describe()}")
    lines.append(f"  units: SI — m, kg, kg·m²{unit_note}")
    if density_source:
        lines.append(f"  density:          {density_source}")
    lines.append(f"  volume:           {_num(props.volume)} m³")
    lines.append(f"  mass:             {_num(props.mass)} kg")
    lines.append(f"  surface area:     {_num(props.surface_area)} m²")
    lines.append(f"  centre of mass:   {_position(props.center_of_mass, size)} m")
    lines.append(f"  inertia about the centre of mass, mesh axes (kg·m²; {TENSOR_CONVENTION}):")
    lines += _matrix(props.inertia, "    ")
    lines.append("  inertia about the mesh origin (0, 0, 0), mesh axes (kg·m²):")
    lines += _matrix(np.asarray(props.inertia_about(np.zeros(3), far_point_ratio=None)), "    ")
    lines.append("  (shown as 0: matrix and axis entries below 1e-12 of the largest, coordinates below 1e-10 of "
                 "the part size)")
    lines.append("  principal moments (ascending) and axes (unit vectors, mesh axes, right-handed):")
    for k in range(3):
        lines.append(f"    I{k + 1} = {pa.moments[k]:.6e} kg·m²   axis {_vec(pa.axes[:, k])}   "
                     f"radius of gyration {_num(pa.radii_of_gyration[k])} m")
    if pa.is_spherical:
        lines.append(f"    all three moments are equal within {pa.rtol:g}: every axis through the centre of mass "
                     "is principal (axes shown are the mesh axes)")
    elif pa.is_axisymmetric:
        i, j = pa.equal_pairs[0]
        lines.append(f"    I{i + 1} and I{j + 1} are equal within {pa.rtol:g} (axisymmetric): any axis in their plane "
                     "is principal; the two shown are one choice")
    margin = pa.triangle_inequality_margin
    ok = np.all(pa.moments > 0) and margin >= -1e-9
    lines.append(f"  checks: moments positive: {'yes' if np.all(pa.moments > 0) else 'NO'}; "
                 f"triangle inequality I1 + I2 ≥ I3: {'yes' if margin >= -1e-9 else 'NO'} "
                 f"(margin {margin:.3g}){'' if ok else '  <- not a physical body'}")
    if props.parts and any(b.mesh is not None for b in props.parts):
        lines += _parts_table(props, size)
    elif props.parts:
        lines.append(f"  bodies ({len(props.parts)}):")
        for b in props.parts:
            lines.append(f"    {b.name}: mass {_num(b.mass)} kg, volume {_num(b.volume)} m³, "
                         f"centre of mass {_position(b.center_of_mass, size)} m")
    if mesh is not None:
        lines.append("  mesh:")
        lines.append(f"    faces {face_count_text(mesh)}, vertices {mesh.vertices:,}, "
                     f"bodies {mesh.bodies}, cavities {mesh.cavities}")
        lines.append(f"    watertight and consistently wound as read: {'yes' if mesh.watertight else 'no'}"
                     f"; degenerate faces ignored: {mesh.degenerate_faces}; zero-area faces: {mesh.zero_area_faces}")
        if mesh.welded_tolerance is not None:
            lines.append(f"    nearly coincident vertices welded within {round_up(mesh.welded_tolerance):.3g} m")
        if mesh.flipped_shells:
            lines.append(f"    inside-out shells flipped: {mesh.flipped_shells}")
        if mesh.overlapping_shells:
            how = "united, shared volume counted once" if mesh.method == "union" else "volume counted twice"
            lines.append(f"    overlapping bodies ({how}): {mesh.overlapping_shells}")
        for note in mesh.notes:
            lines.append(f"    {note}")
        if mesh.repaired:
            change = (f", volume changed by {100 * mesh.repair_volume_change:+.3g}%"
                      if mesh.repair_volume_change is not None else "")
            if not mesh.notes:
                lines.append(f"    repaired: {', '.join(mesh.repair_actions)}{change}")
        lines.append(f"    bounding box: {_vec(mesh.bbox_min)} – {_vec(mesh.bbox_max)} m")
    return "\n".join(lines)


def face_count_text(mesh: MeshReport) -> str:
    """The faces integrated and how they relate to the file's, so that the counts add up: the file's less the
    degenerate ones and those left out (flat pieces, copies: see the notes), or a surface the tool formed (the
    boolean union, repair patches)."""
    kept = mesh.file_faces - mesh.degenerate_faces
    if mesh.faces == mesh.file_faces:
        return f"{mesh.faces:,} (as in the file)"
    base_method = mesh.method.split(",", 1)[0]  # "union, inward offset" (a printed part) is still a union
    if base_method in ("union", "patched") or (mesh.faces > kept and mesh.repaired):
        made = "the boolean union's surface" if base_method == "union" else "after repair"
        return f"{mesh.faces:,} ({made}; the file has {mesh.file_faces:,})"
    if mesh.faces > kept:
        # nothing was repaired, so the extra triangles come from the file's polygons (OBJ/PLY/OFF quads, n-gons)
        return f"{mesh.faces:,} triangles (the file's {mesh.file_faces:,} polygons split into triangles)"
    parts = [f"{mesh.degenerate_faces:,} degenerate"] if mesh.degenerate_faces else []
    if mesh.faces < kept:
        parts.append(f"{kept - mesh.faces:,} left out: see the notes")
    return f"{mesh.faces:,} (the file's {mesh.file_faces:,} less {' and '.join(parts)})"
