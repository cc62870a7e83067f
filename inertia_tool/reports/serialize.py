"""JSON-ready dictionaries of the result objects (all numbers SI, plain lists and floats)."""

from __future__ import annotations

import math
from dataclasses import fields, is_dataclass

import numpy as np

from ..mesh.checks import MeshReport
from ..mass.properties import MassProperties

__all__ = ["to_jsonable", "mass_properties_dict", "mesh_report_dict", "TENSOR_CONVENTION"]

TENSOR_CONVENTION = "tensor: I_ij = ∫(r²δ_ij − r_i r_j) dm, off-diagonals are −∫xy dm"


def to_jsonable(x):
    """Recursively convert numpy arrays/scalars and dataclasses to JSON-compatible Python objects.

    Non-finite floats become ``None`` (JSON has no NaN).
    """
    if isinstance(x, np.ndarray):
        return to_jsonable(x.tolist())
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    if isinstance(x, dict):
        return {str(k): to_jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [to_jsonable(v) for v in x]
    if is_dataclass(x) and not isinstance(x, type):
        return {f.name: to_jsonable(getattr(x, f.name)) for f in fields(x) if f.repr}
    return x


def mesh_report_dict(report: MeshReport) -> dict:
    """Mesh diagnostics as a dict."""
    return to_jsonable({f.name: getattr(report, f.name) for f in fields(report)})


def mass_properties_dict(props: MassProperties, *, density_source: str | None = None) -> dict:
    """The ``analyze --json`` object for one body or assembly (SI throughout)."""
    pa = props.principal
    origin = np.asarray(props.inertia_about(np.zeros(3)))
    out = {
        "name": props.name,
        "units": {"length": "m", "mass": "kg", "inertia": "kg*m^2", "density": "kg/m^3",
                  "mesh_length_unit": getattr(props.mesh, "units", None)},
        "mass": props.mass,
        "volume": props.volume,
        "surface_area": props.surface_area,
        "density": props.density,
        "density_source": density_source,
        "center_of_mass": props.center_of_mass,
        "inertia": props.inertia,
        "inertia_reference": "center_of_mass, mesh axes",
        "inertia_convention": TENSOR_CONVENTION,
        "inertia_about_origin": origin,
        "principal_moments": pa.moments,
        "principal_axes": pa.axes.T,
        "principal_axes_note": "principal_axes[k] is the unit axis of principal_moments[k]; "
                               "as columns they form a right-handed rotation (det +1)",
        "radii_of_gyration": pa.radii_of_gyration,
        "equal_moments": [list(p) for p in pa.equal_pairs],
        "equal_moments_rtol": pa.rtol,
        "checks": {
            "positive_moments": bool(np.all(pa.moments > 0)),
            "triangle_inequality": bool(pa.triangle_inequality_margin >= -1e-9),
            "triangle_inequality_margin": pa.triangle_inequality_margin,
        },
    }
    if props.mesh is not None:
        out["method"] = props.mesh.method
        out["uncertainty"] = props.mesh.uncertainty        # None (null) when exact
        out["mesh"] = mesh_report_dict(props.mesh)
    if props.parts:
        out["bodies"] = [{"name": b.name, "mass": b.mass, "volume": b.volume, "center_of_mass": b.center_of_mass,
                          "inertia": b.inertia} for b in props.parts]
    return to_jsonable(out)
