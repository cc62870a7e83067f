"""JSON-ready dictionaries of the result objects (all numbers SI, plain lists and floats)."""

from __future__ import annotations

import math
from dataclasses import fields, is_dataclass
from typing import Any

import numpy as np

from ..mesh.checks import MeshReport
from ..mass.properties import MassProperties

__all__ = ["to_jsonable", "mass_properties_dict", "mesh_report_dict", "TENSOR_CONVENTION", "OUTPUT_SCHEMA",
           "SI_UNITS", "command_output", "method_and_uncertainty", "output_schema"]

TENSOR_CONVENTION = "tensor: I_ij = ∫(r²δ_ij − r_i r_j) dm, off-diagonals are −∫xy dm"

#: Version identifier carried as ``"schema"`` by every JSON object a command prints (and by every batch row).
#: The JSON Schema that describes them ships in the package as ``inertia_tool/schema/output-v1.json``
#: (:func:`output_schema`).  Versioning rule (docs/json.md): adding an optional field keeps ``v1``; removing or
#: renaming a field, changing its type, unit or meaning, or making it required makes ``v2`` (a new file beside
#: the old one).
OUTPUT_SCHEMA = "inertia_tool/output/v1"

#: The units of every number of the JSON outputs, unless a command's ``units`` object names another quantity.
SI_UNITS = {"length": "m", "mass": "kg", "inertia": "kg*m^2", "density": "kg/m^3", "time": "s", "angle": "rad",
            "angular_rate": "rad/s"}

_SCHEMA_FILE = "output-v1.json"


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


def output_schema() -> dict:
    """The JSON Schema (draft 2020-12) of every command's JSON output, :data:`OUTPUT_SCHEMA`, as a dict."""
    import json
    from importlib import resources
    return json.loads((resources.files("inertia_tool") / "schema" / _SCHEMA_FILE).read_text("utf-8"))


def command_output(command: str, body: dict, *, warnings=(), units: dict | None = None) -> dict:
    """The JSON object a command prints: ``schema`` and ``command`` first, then ``body``, with ``units``
    (:data:`SI_UNITS` completed by ``body``'s own ``units`` and by ``units``) and ``warnings`` (list of str).

    Non-finite numbers become ``null`` (:func:`to_jsonable`), so the object always dumps with
    ``allow_nan=False``.
    """
    out: dict = {"schema": OUTPUT_SCHEMA, "command": command}
    out.update(body)
    out["units"] = {**SI_UNITS, **(body.get("units") or {}), **(units or {})}
    out["warnings"] = [str(w) for w in warnings]
    return to_jsonable(out)


def method_and_uncertainty(props: MassProperties) -> tuple[str, Any]:
    """``(method, uncertainty)`` of a result: its mesh report's, for one mesh; for an assembly of parts, the
    parts' common method (``"mixed"`` when they differ) and ``None`` when every part is exact.

    An assembly with estimated parts gets the bound that follows from the parts' own: the mass of a sum is
    within ``max_k r_k`` (relative) when each part's is within ``r_k``; ``volume_in_doubt`` adds up.  The
    centre-of-mass and inertia bounds are per part only (``bodies[k].uncertainty``), so they are ``None`` here.
    """
    mesh = props.mesh
    if mesh is not None:
        return getattr(mesh, "method", "exact"), getattr(mesh, "uncertainty", None)
    pairs = [method_and_uncertainty(p) for p in props.parts]
    if not pairs:
        return "exact", None
    methods = {m for m, _ in pairs}
    method = methods.pop() if len(methods) == 1 else "mixed"
    bounds = [u for _, u in pairs if u is not None]
    if not bounds:
        return method, None

    def bound(u, name: str) -> float:
        return float(u[name] if isinstance(u, dict) else getattr(u, name))
    return method, {"mass": max(bound(u, "mass") for u in bounds),
                    "center_of_mass": None, "inertia": None,
                    "volume_in_doubt": sum(bound(u, "volume_in_doubt") for u in bounds),
                    "note": "centre-of-mass and inertia bounds are per part (bodies[k].uncertainty)"}


def mesh_report_dict(report: MeshReport) -> dict:
    """Mesh diagnostics as a dict."""
    return to_jsonable({f.name: getattr(report, f.name) for f in fields(report)})


def mass_properties_dict(props: MassProperties, *, density_source: str | None = None) -> dict:
    """The ``analyze --json`` object for one body or assembly (SI throughout)."""
    pa = props.principal
    origin = np.asarray(props.inertia_about(np.zeros(3), far_point_ratio=None))
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
    whole = method_and_uncertainty(props)                   # uncertainty None (null) when exact
    out["method"], out["uncertainty"] = whole
    if props.mesh is not None:
        out["certificate"] = props.mesh.certificate       # {"kind": ..., "checks": [...]}
        out["mesh"] = mesh_report_dict(props.mesh)
    if props.parts:
        # the shells of one mesh share its report (and its method); the parts of an assembly carry their own
        out["bodies"] = [{"name": b.name, "mass": b.mass, "volume": b.volume, "center_of_mass": b.center_of_mass,
                          "inertia": b.inertia, "material": b.material or None, "density": b.density,
                          **({"certificate": b.mesh.certificate} if b.mesh is not None else {}),
                          **dict(zip(("method", "uncertainty"),
                                     method_and_uncertainty(b) if b.mesh is not None or b.parts else whole))}
                         for b in props.parts]
    return to_jsonable(out)
