"""Write ``inertia_tool/schema/output-v1.json``, the JSON Schema of every command's JSON output (docs/json.md).

The schema file is what ships and what users validate against; this script is where it is edited (Python is
easier to keep consistent than 3,000 lines of JSON).  ``tests/test_json_schema.py`` checks that the committed
file is what this script writes, and that every command's output validates and declares every field.

    python scripts/make_output_schema.py            # rewrite the file
    python scripts/make_output_schema.py --check    # exit 1 when the committed file is out of date
"""

import json
import os
import sys

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "inertia_tool", "schema",
                   "output-v1.json")
N = {"type": "number"}
NN = {"type": ["number", "null"]}
S = {"type": "string"}
SN = {"type": ["string", "null"]}
B = {"type": "boolean"}
COUNT = {"type": "integer", "minimum": 0}
V3 = {"$ref": "#/$defs/vector3"}
V3N = {"$ref": "#/$defs/vector3_or_null"}
M3 = {"$ref": "#/$defs/matrix3"}


def ref(name):
    return {"$ref": f"#/$defs/{name}"}


def arr(items, **kw):
    return {"type": "array", "items": items, **kw}


def obj(props, required=None, desc=None, extra=True):
    """An object schema; ``required`` defaults to every property, ``extra=False`` forbids other fields."""
    o = {"type": "object"}
    if desc:
        o["description"] = desc
    o["properties"] = props
    o["required"] = list(props) if required is None else required
    if not extra:
        o["additionalProperties"] = False
    return o


def d(desc, s):
    return {**s, "description": desc}


ENVELOPE = {
    "schema": {"const": "inertia_tool/output/v1"},
    "units": ref("units"),
    "warnings": ref("warnings"),
}
def command(name, props, required, desc):
    p = {"schema": ENVELOPE["schema"], "command": {"const": name}, **props,
         "units": ENVELOPE["units"], "warnings": ENVELOPE["warnings"]}
    return obj(p, ["schema", "command", *required, "units", "warnings"], desc)

defs = {}
defs["vector3"] = arr(N, minItems=3, maxItems=3)
defs["vector3_or_null"] = arr(NN, minItems=3, maxItems=3)
defs["matrix3"] = arr(V3, minItems=3, maxItems=3)
defs["units"] = d("The unit of each kind of quantity in the object: SI throughout (length m, mass kg, inertia "
                  "kg*m^2, density kg/m^3, time s, angle rad, angular_rate rad/s); a command adds the quantities "
                  "it reports (balance: unbalance kg*m, force N, ...). mesh_length_unit is the unit of the mesh "
                  "file's coordinates (they are converted to m).",
                  {"type": "object", "required": ["length", "mass", "inertia", "density"],
                   "properties": {"length": {"const": "m"}, "mass": {"const": "kg"}, "inertia": {"const": "kg*m^2"},
                                  "density": {"const": "kg/m^3"}, "time": {"const": "s"}, "angle": {"const": "rad"},
                                  "angular_rate": {"const": "rad/s"}, "mesh_length_unit": SN},
                   "additionalProperties": {"type": ["string", "null"]}})
defs["warnings"] = d("The soft problems (InertiaToolWarning) met while computing the result, one sentence each, "
                     "in command-line words; also printed on stderr.", arr(S))
defs["method"] = d("How the solid was obtained from the surface: exact, oriented, welded, deduplicated, union, sum "
                   "(shared volume counted twice, on request), patched or winding (estimates of --repair, see "
                   "uncertainty), mixed (an assembly whose parts differ).", S)
defs["uncertainty"] = d("null when the result is exact for the polyhedron; for an estimate, its bounds: mass "
                        "(relative, also volume), center_of_mass (m), inertia (relative, Frobenius), volume_in_doubt "
                        "(m^3). A null bound inside the object means no combined bound (see the parts).",
                        {"type": ["object", "null"], "required": ["mass", "center_of_mass", "inertia"],
                         "properties": {"mass": NN, "center_of_mass": NN, "inertia": NN, "volume_in_doubt": NN,
                                        "note": S}})
CERT_KINDS = ["exact", "united", "summed", "unverified", "estimate"]
#: The assumptions a user may state (inertia_tool.mesh.hole_assumptions.USER_ASSUMPTIONS; a test checks the two agree).
USER_ASSUMPTION_NAMES = ["flat-islands", "smooth-holes", "faceted-holes"]
ASSUMPTIONS_SAID = ("optional: the user's assumptions (--assume, assume=) the result rests on: those a repair took "
                    "(a hole filled under one); empty when none was taken or none stated")
defs["certificate"] = d("Optional: how far the numbers can be trusted. kind exact (the checks that make the integral "
                        "exact ran and passed), united (overlapping bodies united by a boolean, then exact), summed "
                        "(overlaps counted twice, on request), unverified (a check could not finish) or estimate "
                        "(bounds in uncertainty); checks lists the checks that ran and passed; assumptions the "
                        "user's assumptions (--assume, assume=) the result rests on. null where there is "
                        "no result (a robot link without geometry).",
                        {"type": ["object", "null"], "required": ["kind", "checks"],
                         "properties": {"kind": {"enum": CERT_KINDS}, "checks": arr(S),
                                        "assumptions": d(ASSUMPTIONS_SAID, arr({"enum": USER_ASSUMPTION_NAMES},
                                                                               uniqueItems=True))}})
defs["mesh_report"] = obj({
    "source": S, "units": S, "file_faces": COUNT, "vertices": COUNT, "faces": COUNT, "degenerate_faces": COUNT,
    "zero_area_faces": COUNT, "bodies": COUNT, "cavities": COUNT, "flipped_shells": COUNT, "overlapping_shells": COUNT,
    "watertight": B, "welded_tolerance": NN, "repaired": B, "repair_actions": arr(S),
    "repair_volume_change": NN, "bbox_min": V3, "bbox_max": V3, "method": ref("method"),
    "uncertainty": ref("uncertainty"), "certificate": ref("certificate"), "notes": arr(S), "flipped_faces": COUNT,
    "nonmanifold_edges": COUNT},
    ["source", "units", "faces", "bodies", "cavities", "watertight", "repaired", "bbox_min", "bbox_max", "method",
     "uncertainty"], "Mesh diagnostics: what the checks found and what was done (lengths m).")
defs["body"] = obj({"name": SN, "mass": N, "volume": NN, "center_of_mass": V3, "inertia": M3,
                    "material": d("the part's material name (a 3MF base material, a slicer's filament type, "
                                  "FILE:material); null when its density was given as a number", SN),
                    "density": d("kg/m^3 of this body", NN),
                    "method": ref("method"), "uncertainty": ref("uncertainty"), "certificate": ref("certificate")},
                   ["name", "mass", "center_of_mass", "inertia"],
                   "One body of a mesh or one part of an assembly (a multi-material file's parts, FILE:material "
                   "files): kg, m^3, m; inertia kg*m^2 about its own centre of mass, mesh axes. The whole's values "
                   "are the parts' sum about the common centre of mass (parallel-axis theorem).")
MP = {
    "name": SN,
    "units": ref("units"),
    "mass": d("kg", N), "volume": d("m^3", N), "surface_area": d("m^2", NN), "density": d("kg/m^3", NN),
    "density_source": SN,
    "center_of_mass": d("m, mesh axes", V3N),
    "inertia": d("kg*m^2 about the centre of mass, mesh axes; off-diagonals are tensor elements (-∫xy dm)", M3),
    "inertia_reference": S, "inertia_convention": S,
    "inertia_about_origin": d("kg*m^2 about the mesh origin, mesh axes", M3),
    "principal_moments": d("kg*m^2, ascending", V3),
    "principal_axes": d("principal_axes[k] is the unit axis of principal_moments[k] (mesh axes)", M3),
    "principal_axes_note": S,
    "radii_of_gyration": d("m", V3),
    "equal_moments": arr(arr({"type": "integer"})), "equal_moments_rtol": N,
    "checks": obj({"positive_moments": B, "triangle_inequality": B, "triangle_inequality_margin": NN}),
    "method": ref("method"), "uncertainty": ref("uncertainty"), "certificate": ref("certificate"),
    "mesh": ref("mesh_report"),
    "bodies": arr(ref("body")),
}
MP_REQUIRED = ["mass", "volume", "center_of_mass", "inertia", "principal_moments", "principal_axes", "method",
               "uncertainty"]
defs["mass_properties"] = obj(MP, MP_REQUIRED, "Mass properties of one part or assembly (analyze's core), SI.")
defs["stability_axis"] = obj({
    "axis_name": {"enum": ["minor", "intermediate", "major"]}, "moment": N, "axis": V3,
    "kind": S, "coefficient": NN, "growth_rate_per_unit_spin": NN, "e_folding_turns": NN,
    "wobble_frequency_per_unit_spin": NN, "wobble_period_turns": NN, "wobble_amplification": NN,
    "perturbation": NN, "turns_to_grow": NN, "dissipation_stable": B},
    ["axis_name", "moment", "axis", "kind"],
    "Torque-free spin about one principal axis (Chapter 4, §4.4.1): stable or unstable, growth or wobble per "
    "unit spin.")
defs["model"] = d("The mass model: solid, shell (with its thickness) or printed (shell and infill).",
                  {"type": "object", "required": ["model"], "properties": {
                      "model": {"enum": ["solid", "shell", "printed"]}, "thickness": d("m", NN), "skin": d("m", NN),
                      "infill": d("fraction of the core, 0 to 1", NN), "envelope_volume": d("m^3", NN),
                      "core_volume": d("m^3: the inward offset by the skin (printed; estimate)", NN),
                      "skin_volume": d("m^3: the part less its inward offset (printed)", NN),
                      "mass_error_bound": d("relative; a bound that holds (printed)", NN),
                      "center_of_mass_error_bound": d("m; a bound that holds (printed)", NN),
                      "inertia_error_bound": d("spectral norm of the error over the largest principal moment; a "
                                               "bound that holds (printed)", NN),
                      "cell_size": d("m: finest cells of the core's integration (printed)", NN),
                      "approximation": S}})

defs["analyze"] = command("analyze", {**{k: v for k, v in MP.items() if k != "units"},
                                      "stability": {"anyOf": [arr(ref("stability_axis")), {"type": "null"}]},
                                      "model": ref("model"), "brep": {"type": "object"}, "units_assumed": B,
                                      "coordinate_system": obj(
                                          {"origin": V3, "axes": ref("matrix3"), "center_of_mass": V3,
                                           "inertia_about_origin": ref("matrix3"),
                                           "inertia_about_center_of_mass": ref("matrix3"), "convention": S},
                                          ["origin", "axes", "center_of_mass", "inertia_about_origin",
                                           "inertia_about_center_of_mass"],
                                          "analyze --about/--axes: the chosen coordinate system (SI, tensor "
                                          "convention, the system's axes; axes are its x, y, z in mesh "
                                          "coordinates)")},
                          MP_REQUIRED + ["stability", "units_assumed"],
                          "inertia-tool analyze --json (also --format json).")
defs["spin"] = command("spin", {
    "name": SN, "density_source": SN, "mass": d("kg", N), "method": ref("method"),
    "uncertainty": ref("uncertainty"), "model": ref("model"), "units_assumed": B,
    "stability": arr(ref("stability_axis")),
    "spin": obj({"axis_name": S, "moment": N, "axis": V3, "kind": S, "coefficient": NN,
                 "rate": d("rad/s", N), "perturbation": N, "initial_angular_velocity": d("rad/s, body axes", V3),
                 "predicted": obj({"linear_period": NN, "time_to_grow": NN, "turns_to_grow": NN,
                                   "polhode_period": NN, "period": NN}, []),
                 "simulated": obj({"duration": d("s", N), "samples": COUNT, "method": S, "period": NN, "events": COUNT,
                                   "first_flip_time": NN, "max_tilt": NN, "relative_energy_drift": NN},
                                  ["duration", "samples", "method"]),
                 "period_kind": S},
                ["axis_name", "moment", "axis", "kind", "rate", "predicted", "simulated"])},
    ["name", "mass", "method", "uncertainty", "stability", "spin", "units_assumed"],
    "inertia-tool spin --json: stability of each principal axis and the simulated spin.")
defs["top"] = command("top", {
    "name": SN, "density_source": SN, "mass": d("kg", N), "method": ref("method"),
    "uncertainty": ref("uncertainty"), "model": ref("model"), "units_assumed": B,
    "top": obj({"transverse_moment": d("kg*m^2 about the pivot", N), "axial_moment": d("kg*m^2", N),
                "mass": N, "length": d("m, pivot to centre of mass", N), "gravity": d("m/s^2", N),
                "theta0": d("rad", N), "omega3": d("rad/s", N), "theta_dot0": N, "phi_dot0": N,
                "a": NN, "b": NN, "alpha": NN, "beta": NN, "roots": arr(NN),
                "theta_min": NN, "theta_max": NN, "nutation_period": NN, "precession_kind": SN,
                "precession_zero_u": NN, "sleeping_stable": {"type": ["boolean", "null"]}, "sleeping_margin": NN,
                "precession_rate_slow": NN, "precession_rate_fast": NN, "pivot": V3, "symmetry_axis": V3,
                "transverse_asymmetry": NN, "critical_sleeping_spin": NN,
                "simulation": {"type": ["object", "null"], "properties": {
                    "duration": N, "samples": COUNT, "theta_min": NN, "theta_max": NN, "nutation_period": NN,
                    "mean_precession_rate": NN, "relative_energy_drift": NN}}},
               ["transverse_moment", "axial_moment", "mass", "length", "theta_min", "theta_max", "nutation_period",
                "pivot", "symmetry_axis"]),
    "top_bounds": {"type": ["object", "null"], "description": (
        "null for an exact part; for an estimate (a repaired part), its bounds carried to the top "
        "(dynamics/top_bounds.py): bounded (false: the bounds give none, every result in doubt), moment (kg*m^2, "
        "each of I1, I3 and the transverse moments about the pivot), length (m), gravity_torque ([lo, hi] N*m), "
        "asymmetry ([lo, hi] of I1), symmetric (true, false or null: in doubt), sleeping_margin ([lo, hi]), "
        "steady_possible (true, false or null), precession_rate_slow/_fast ([lo, hi] rad/s or null), in_doubt "
        "(keys of the results left in doubt)"),
        "properties": {"bounded": B, "moment": N, "length": N, "gravity_torque": arr(N), "asymmetry": arr(N),
                       "symmetric": {"type": ["boolean", "null"]}, "sleeping_margin": arr(NN),
                       "steady_possible": {"type": ["boolean", "null"]},
                       "precession_rate_slow": {"type": ["array", "null"], "items": N},
                       "precession_rate_fast": {"type": ["array", "null"], "items": N}, "in_doubt": arr(S)},
        "required": ["bounded", "in_doubt"]}},
    ["name", "mass", "method", "uncertainty", "top", "units_assumed"],
    "inertia-tool top --json: the heavy symmetric top (Chapter 4, §4.4.3).")
STATE = {"kind": S, "center_of_mass_shaft": V3, "offset": N, "static_unbalance": V3,
         "static_unbalance_magnitude": N, "moment_unbalance_about_axis_point": V3, "couple_unbalance": V3,
         "couple_unbalance_magnitude": N, "products_of_inertia_xz_yz": arr(N, minItems=2, maxItems=2),
         "principal_axis_mesh": V3, "tilt": NN, "tilt_angle": NN, "principal_axis_distance_to_shaft": NN}
defs["balance_state"] = obj(STATE, ["kind", "center_of_mass_shaft", "static_unbalance", "couple_unbalance"],
                            "Unbalance of the part (ISO 21940-2), shaft frame: kg*m, kg*m^2, m, rad.")
PLANE = obj({"position": N, "unbalance": V3, "magnitude": N, "angle": NN, "permissible": NN, "share": NN,
             "within_tolerance": {"type": ["boolean", "null"]}, "bearing_load": V3},
            ["position", "unbalance", "magnitude"])
defs["balance"] = command("balance", {
    "name": SN, "conventions": S, "mass": N, "speed": d("rad/s", N), "rpm": N, "axis_point": V3,
    "shaft_axes_mesh": M3, "initial": ref("balance_state"), "support_force": d("N", V3),
    "support_torque_about_axis_point": d("N*m", V3),
    "grade": {"type": ["object", "null"], "properties": {"name": S, "value": N, "typical_parts": S}},
    "permissible_unbalance": NN, "tolerance_planes": arr(PLANE), "achieved_value": NN, "achieved_grade": SN,
    "single_plane": B, "correction_planes": arr(PLANE),
    "corrections": arr(obj({"plane": N, "mass": N, "radius": N, "angle": N, "position": V3, "removal_angle": N,
                            "removal_position": V3})),
    "verification": obj({**STATE, "achieved_value": NN, "achieved_grade": SN, "couple_corrected": B,
                         "summary": S}, ["kind", "center_of_mass_shaft", "static_unbalance", "couple_unbalance",
                                         "couple_corrected"]),
    "drillings": arr(obj({"plane": N, "angle": N, "radius": N, "diameter": N, "depth": N, "direction": S,
                          "mass": N, "entry": V3, "axis": V3, "centroid": V3, "inside_checked": B},
                         ["plane", "angle", "diameter", "depth", "mass"])),
    "drilled_verification": {"anyOf": [{"type": "null"}, obj({**STATE, "achieved_value": NN, "achieved_grade": SN},
                                                              ["kind", "center_of_mass_shaft", "static_unbalance"])]},
    "notes": arr(S), "density_source": SN, "model": ref("model"), "units_assumed": B,
    "method": ref("method"), "uncertainty": ref("uncertainty")},
    ["mass", "speed", "initial", "corrections", "verification", "method", "uncertainty", "units_assumed"],
    "inertia-tool balance --json: static/couple unbalance, ISO 21940-11 tolerance, corrections and their "
    "verification by re-analysis.")
defs["robot_link"] = obj({
    "name": S, "mass": NN, "volume": NN, "density": NN, "density_basis": SN,
    "center_of_mass": {"anyOf": [V3, {"type": "null"}]},
    "inertia": {"anyOf": [M3, {"type": "null"}]},
    "method": d("exact, united, summed or estimate (a link's elements combined: the least certain wins); null "
                "without a result (see problem).", {"enum": ["exact", "united", "summed", "estimate", None]}),
    "uncertainty": ref("uncertainty"), "certificate": ref("certificate"),
    "assumptions": d(ASSUMPTIONS_SAID + " (of the link's meshes together)",
                     arr({"enum": USER_ASSUMPTION_NAMES}, uniqueItems=True)),
    "geometry": arr(obj({"kind": S, "name": SN, "mesh": SN,
                         "submesh": d("SDFormat <submesh><name>: the sub-mesh of the COLLADA file that is the "
                                      "geometry (null: the whole file)", SN)}, ["kind"])),
    "problem": SN,
    "declared": {"type": ["object", "null"], "properties": {
        "mass": NN, "center_of_mass": {"anyOf": [V3, {"type": "null"}]}, "inertia": {"anyOf": [M3, {"type": "null"}]}}},
    "audit": {"type": ["object", "null"], "properties": {
        "mass_ratio": d("declared / geometry", NN), "com_distance": d("m", NN), "com_distance_relative": NN,
        "inertia_difference": d("relative Frobenius difference at equal mass", NN),
        "declared_positive_definite": {"type": ["boolean", "null"]},
        "declared_triangle_inequality": {"type": ["boolean", "null"]}, "implied_density": d("kg/m^3", NN),
        "density_plausible": {"type": ["boolean", "null"]}, "com_in_bounding_box": {"type": ["boolean", "null"]},
        "com_inside_geometry": {"type": ["boolean", "null"]}, "link_size": d("m", NN), "issues": arr(S),
        "causes": d("Likely causes of a declared inertial that disagrees with the geometry, most likely first: "
                    "each with its evidence and the declared values with the cause undone.", arr(obj({
                        "cause": S, "explanation": S, "difference_before": NN, "difference_after": NN,
                        "corrected_inertia": {"anyOf": [M3, {"type": "null"}]}, "corrected_mass": NN},
                        ["cause", "explanation"]))),
        "nearest_valid_inertia": d("The nearest tensor that simulators accept (positive definite, triangle "
                                   "inequality), when the declared one is not; else null.",
                                   {"anyOf": [M3, {"type": "null"}]})}},
    "warnings": d("The link's own soft problems (mesh warnings, massless geoms), one sentence each.", arr(S))},
    ["name", "mass", "center_of_mass", "inertia", "method", "uncertainty", "geometry", "problem", "declared", "audit"],
    "One link: mass properties from its geometry (null when it has none: see problem), centre of mass in the link "
    "frame, inertia about the centre of mass in link axes, and the audit of its declared <inertial>.")
defs["robot"] = command("robot", {
    "robot": SN, "source": S, "format": {"enum": ["urdf", "xacro", "sdf", "mjcf"]}, "geometry": S,
    "frames": S, "inertia_convention": S, "density_range": arr(N, minItems=2, maxItems=2),
    "links": arr(ref("robot_link")),
    "summary": d("One line: links, computed, exact, and the links without a result.", S),
    "links_without_result": d("Links that have geometry or should have it but got no result (the command "
                              "then exits 5).", arr(S))},
    ["source", "format", "geometry", "links", "summary", "links_without_result"],
    "inertia-tool robot --json: every link's mass properties from its geometry and the audit of its <inertial>.")
_ROBOT_BODY = {k: v for k, v in defs["robot"]["properties"].items() if k not in ("schema", "command", "warnings")}
defs["robot-corpus"] = command("robot-corpus", {
    "models": arr({"anyOf": [obj(_ROBOT_BODY, ["source", "format", "links"]),
                             obj({"source": S, "problem": S})]}),
    "summary": S, "likely_causes": d("How many links each likely cause was named for.",
                                     {"type": "object", "additionalProperties": COUNT})},
    ["models", "summary", "likely_causes"],
    "inertia-tool robot DIR... --json: every description found audited, one summary.")
METRICS = {"type": "object", "required": ["mass"], "properties": {
    "mass": N, "axis_moment": NN, "next_moment": NN, "moment_ratio": NN, "axis_tilt": NN, "axis_offset": NN,
    "nearest_principal": SN, "epsilon_coefficient": NN, "sleeping_threshold": NN, "transverse_asymmetry": NN,
    "height": NN}}
defs["spin-it"] = command("spin-it", {
    "mode": {"enum": ["yoyo", "top"]}, "axis": V3, "origin_m": V3, "wall_m": N, "measured_wall_m": NN,
    "cavity_volume_m3": N, "cell_size_m": N, "allowed_cells": COUNT, "removed_cells": COUNT,
    "objective": obj({"before": NN, "after": NN}),
    "quadric": obj({"coefficients": arr(N), "centre_m": V3, "half_extent_m": N, "monomials": S}),
    "optimisation_seconds": N, "objective_evaluations": COUNT, "seconds": N,
    "before": obj({"metrics": METRICS, "mass_properties": ref("mass_properties")}),
    "after": obj({"metrics": METRICS, "mass_properties": ref("mass_properties")}),
    "insert": {"type": ["object", "null"], "properties": {"density_kg_m3": N, "volume_m3": N, "mass_kg": N,
                                                          "shape": SN, "mass_properties": ref("mass_properties")}},
    "output": SN, "verified": S, "method": ref("method"), "uncertainty": ref("uncertainty"),
    "verification": obj({"passed": B, "attempts": arr(obj({
        "resolution": COUNT, "ok": B, "reasons": arr(S), "notes": arr(S),
        "axis_tilt_before": d("rad", N), "axis_tilt_after": d("rad", N), "objective_before": N,
        "objective_after": N, "wobble_before": NN, "wobble_after": NN,
        "product_weight": d("the product-of-inertia penalty weight the attempt was optimised with", N)}, []))},
        ["passed", "attempts"],
        "the design compared with its input (design/verify.py): every attempt, the last one accepted")},
    ["mode", "axis", "origin_m", "wall_m", "before", "after", "method", "uncertainty"],
    "inertia-tool spin-it --json: the hollowed design, before and after (after = exact re-analysis of the "
    "hollowed mesh; method/uncertainty are the hollowed part's: a repaired part's estimate and bounds, carried "
    "over, where the input was repaired).")

ROW_NUMBERS = {"density": "kg/m^3", "mass": "kg", "volume": "m^3", "surface_area": "m^2",
               **{f"com_{c}": "m, mesh axes" for c in "xyz"},
               **{k: "kg*m^2 about the centre of mass, mesh axes, tensor convention (ixy = -∫xy dm)"
                  for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")},
               **{f"i{k}": "kg*m^2, principal moment, ascending" for k in (1, 2, 3)},
               **{f"axis{k}_{c}": f"unit principal axis of i{k}, mesh axes" for k in (1, 2, 3) for c in "xyz"}}
UNCERTAINTY_COLUMNS = {"uncertainty_mass": "relative bound on mass and volume",
                       "uncertainty_center_of_mass": "m, bound on the centre of mass",
                       "uncertainty_inertia": "relative bound on the inertia (Frobenius)",
                       "uncertainty_volume_in_doubt": "m^3 that may or may not be material"}
def row(version):
    v1 = version == 1
    p = {"schema": {"const": f"inertia_tool.batch/{version}"},
         "path": S, "status": {"enum": ["ok", "error", "internal_error"]}, "error_type": SN, "error": SN,
         "sha256": {"type": ["string", "null"], "pattern": "^[0-9a-f]{64}$"},
         "options_key": {"type": "string", "pattern": "^[0-9a-f]{16}$"}}
    if v1:
        p["units"] = d("the unit the mesh file was read in (m, mm, cm, in, ...)", SN)
    else:
        p["mesh_length_unit"] = d("the unit the mesh file's coordinates were read in (they are converted to m)", SN)
    p["density"] = d("kg/m^3", NN)
    p["density_source"] = SN
    if not v1:
        p["method"] = {"anyOf": [ref("method"), {"type": "null"}]}
        p.update({k: d(v + "; null when the result is exact", NN) for k, v in UNCERTAINTY_COLUMNS.items()})
    p.update({k: d(u, NN) for k, u in ROW_NUMBERS.items() if k != "density"})
    p.update({"faces": {"type": ["integer", "null"]}, "bodies": {"type": ["integer", "null"]},
              "cavities": {"type": ["integer", "null"]}, "watertight": {"type": ["boolean", "null"]},
              "repaired": {"type": ["boolean", "null"]}})
    if not v1:
        p["certificate"] = d("optional: the certificate's kind (see certificate)", {"enum": CERT_KINDS + [None]})
    if version >= 3:
        one = "(" + "|".join(USER_ASSUMPTION_NAMES) + ")"
        p["assumptions"] = d("the user's assumptions (--assume) the result rests on, joined with ','; 'none' when "
                             "none was taken; null when not recorded (a failed row, and rows read back from "
                             "inertia_tool.batch/2 files: unknown, never 'none')",
                             {"anyOf": [{"type": "string", "pattern": f"^(none|{one}(,{one})*)$"},
                                        {"type": "null"}]})
    p.update({"warnings": d("the soft problems, joined with ' | '", SN), "seconds": d("s", NN), "worker": SN})
    required = [k for k in p if k != "certificate"]
    o = obj(p, required, extra=False)
    # an ok row has every number (and, from batch/2 on, its method); a failed row says why
    then = {"properties": {k: N for k in ROW_NUMBERS}}
    if not v1:
        then["properties"]["method"] = ref("method")
    o["if"] = {"properties": {"status": {"const": "ok"}}}
    o["then"] = then
    o["else"] = {"properties": {"error_type": S, "error": S}}
    return o
defs["batch_row"] = d("One row of inertia-tool batch: a flat object (JSON Lines), or a CSV record with the same "
                      "columns in the same order (empty cell = null, booleans true/false). Every number in its "
                      "column's SI unit (see each column); inertia about the centre of mass, mesh axes, tensor "
                      "convention; i1 <= i2 <= i3 with unit axes axisK_x..z. A row carries what the checks "
                      "concluded (method, certificate, watertight, faces, bodies, cavities), never the face-pair "
                      "check's diagnostic counters (candidate_pairs, tested_pairs: they describe the search, and the "
                      "batch's clean-part fast path does not compute them); a row is the same on either path.",
                      row(3))
defs["batch_row_v2"] = d("A row of a results file written before inertia_tool.batch/3 (read back on resume): no "
                         "assumptions column.", row(2))
defs["batch_row_v1"] = d("A row of a results file written before inertia_tool.batch/2 (read back on resume): units "
                         "is the mesh length unit, no method and uncertainty columns.", row(1))

schema = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "$id": "urn:inertia_tool:schema:output-v1",
    "title": "inertia-tool JSON output, version inertia_tool/output/v1",
    "description": "Every JSON object printed by inertia-tool (analyze --json, spin --json, top --json, balance "
                   "--json, robot --json, spin-it --json) carries schema = inertia_tool/output/v1 and command; "
                   "every batch row carries schema = inertia_tool.batch/3 (inertia_tool.batch/2 or /1 in older "
                   "results files). Adding an optional field keeps the version; removing or renaming a field, "
                   "changing its type, unit or meaning, or making a field required makes a new version (a new "
                   "file beside this one). Consumers should ignore fields they do not know. Batch rows are a "
                   "fixed table: any change of their columns makes a new row version.",
    "type": "object",
    "required": ["schema"],
    "properties": {"schema": {"enum": ["inertia_tool/output/v1", "inertia_tool.batch/3", "inertia_tool.batch/2",
                                       "inertia_tool.batch/1"]}},
    "allOf": [
        {"if": {"properties": {"schema": {"const": "inertia_tool/output/v1"}}},
         "then": {"required": ["command"], "properties": {"command": {"enum": ["analyze", "spin", "top", "balance",
                                                                                "robot", "robot-corpus", "spin-it"]}}}},
        *({"if": {"properties": {"command": {"const": c}}, "required": ["command"]}, "then": ref(c)}
          for c in ["analyze", "spin", "top", "balance", "robot", "robot-corpus", "spin-it"]),
        {"if": {"properties": {"schema": {"const": "inertia_tool.batch/3"}}}, "then": ref("batch_row")},
        {"if": {"properties": {"schema": {"const": "inertia_tool.batch/2"}}}, "then": ref("batch_row_v2")},
        {"if": {"properties": {"schema": {"const": "inertia_tool.batch/1"}}}, "then": ref("batch_row_v1")},
    ],
    "$defs": defs,
}


def render() -> str:
    """The schema file's text."""
    return json.dumps(schema, indent=1, ensure_ascii=False) + "\n"


if __name__ == "__main__":
    text = render()
    if sys.argv[1:] == ["--check"]:
        with open(OUT, encoding="utf-8") as fh:
            sys.exit(0 if fh.read() == text else 1)
    with open(OUT, "w", encoding="utf-8") as fh:
        fh.write(text)
