"""A robot corpus (MuJoCo Menagerie and other MJCF/URDF/SDF trees) through ``inertia-tool robot``, link by link,
and every MJCF body against MuJoCo's own compiler.

For each description that :func:`inertia_tool.robot.corpus.find_descriptions` finds under the folders given:

* read it and compute every link (the settings of ``--geometry``, ``--density``, ``--repair``), with the CPU
  time of each model;
* count links answered by method and links without a result by cause (the first words of their ``problem``);
* for MJCF models, compile the file with MuJoCo (``mujoco.MjSpec``; ``inertiafromgeom="true"``, every mesh's
  ``inertia="exact"``, so that MuJoCo integrates the geometry as this tool does) and compare each body's
  mass, centre of mass and inertia tensor (``body_mass``, ``body_ipos``, ``body_inertia`` in ``body_iquat``)
  with the tool's, computed with ``geometry="all"`` and ``density="model"`` (every geom in
  ``inertiagrouprange`` at its own density, as MuJoCo's inertia from geometry).  The figure is the relative
  difference ``max(|Δm|/m, |Δc|/size, ‖ΔI‖/‖I‖)`` per body, ``size`` the body's radius of gyration.
  Bodies where MuJoCo and the tool disagree by more than ``--rtol`` are listed with both values.

MuJoCo is not the truth for an open or self-overlapping mesh (its exact mode integrates the signed volume of
whatever it is given, or refuses the mesh); the tool's certificate says which bodies were exact.  The table
therefore splits the agreement by the tool's method.

    python benchmarks/bench_robot_corpus.py DIR [DIR ...] [--repair] [--geometry collision] [--no-mujoco]
        [--package NAME=DIR]
    python benchmarks/bench_robot_corpus.py --menagerie ROOT [--repair] [--compare-only] [--models-only] [--reverse]
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from inertia_tool.errors import InertiaToolError  # noqa: E402
from inertia_tool.robot import audit_links, link_inertials, read_robot  # noqa: E402
from inertia_tool.robot.corpus import find_descriptions  # noqa: E402


def _cause(problem: str) -> str:
    """A short name for a link's problem (the part before the file name or the first colon)."""
    for key in ("mesh needs repair", "mesh file missing", "every geom is massless", "no collision geometry",
                "no visual geometry", "no all geometry", "cannot be computed", "no declared mass",
                "attached model not read", "included model not read"):
        if problem.startswith(key):
            if key == "mesh needs repair":
                for detail in ("not a closed solid", "passes through itself", "not closed", "open",
                               "inconsistently", "self-intersect", "crossing", "zero volume", "negative volume",
                               "inside out", "no outward", "refused", "no such file"):
                    if detail in problem:
                        return f"{key} ({detail})"
            return key
    return problem.split(":")[0][:60]


_MESH_NAMED = re.compile(r"mesh '([^']+)'|: (\S+)$")


def mujoco_bodies(path: str, *, max_refusals: int = 200):
    """name → (mass, centre, tensor in body axes) from MuJoCo, inertia from geometry with exact meshes; and
    the bodies left out because MuJoCo refuses the exact inertia of one of their meshes (that mesh is then
    compiled with the model's own mesh inertia, so that the rest of the model can be compared)."""
    import mujoco
    spec = mujoco.MjSpec.from_file(path)
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    refused: dict = {}
    for _ in range(max_refusals):
        try:
            model = spec.compile()
            break
        except ValueError as exc:
            text = str(exc).splitlines()[0]
            match = _MESH_NAMED.search(text)
            name = match and (match.group(1) or match.group(2))
            mesh = spec.mesh(name) if name else None
            if mesh is None or name in refused:
                raise
            refused[name] = text
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
    else:
        raise ValueError(f"MuJoCo refused more than {max_refusals} meshes")
    skipped = {}
    for g in range(model.ngeom):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            mesh_name = model.mesh(model.geom_dataid[g]).name
            if mesh_name in refused:
                skipped[int(model.geom_bodyid[g]) - 1] = f"MuJoCo: {refused[mesh_name]}"
    out = []
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out.append((model.body(i).name, float(model.body_mass[i]), model.body_ipos[i].copy(),
                    rot @ np.diag(model.body_inertia[i]) @ rot.T))
    return out, skipped


def compare(path: str, rtol: float, repair: bool) -> tuple[list, list, str | None]:
    """[(body, method, difference)], [disagreement lines], problem of the MuJoCo compile (or None)."""
    try:
        reference, skipped = mujoco_bodies(path)
    except Exception as exc:   # noqa: BLE001 -- MuJoCo's own refusal is a finding, reported as such
        return [], [], f"MuJoCo refuses it: {str(exc).splitlines()[0][:160]}"
    robot = read_robot(path, geometry="all")
    ours = link_inertials(robot, density="model", repair=repair)
    rows, lines = [], []
    if len(ours) != len(reference):
        return [], [f"  {len(ours)} links against MuJoCo's {len(reference)} bodies"], None
    for index, (mine, (name, mass, com, tensor)) in enumerate(zip(ours, reference)):
        if name and mine.name != name:
            lines.append(f"  body {name!r} of MuJoCo is the tool's {mine.name!r}")
            continue
        if index in skipped:
            rows.append((name, "mujoco refused", float("nan")))
            continue
        if mine.properties is None:
            rows.append((name, "none", float("nan")))
            continue
        props = mine.properties
        if mass == 0:
            diff = 0.0 if props.mass == 0 else float("inf")
        else:
            size = max(np.sqrt(np.trace(tensor) / (2 * mass)), 1e-12)
            diff = max(abs(props.mass - mass) / mass, float(np.linalg.norm(props.center_of_mass - com)) / size,
                       float(np.linalg.norm(props.inertia - tensor) / max(np.linalg.norm(tensor), 1e-300)))
        rows.append((name, mine.method or "?", diff))
        if not diff <= rtol:
            lines.append(f"  {name} [{mine.method}]: {diff:.2e}  mass {props.mass:.6g} vs MuJoCo {mass:.6g}, "
                         f"com {np.array2string(props.center_of_mass, precision=5)} vs "
                         f"{np.array2string(com, precision=5)}")
    return rows, lines, None


# -- the whole MuJoCo Menagerie (--menagerie ROOT) ----------------------------------------------------------------

_ROOT_TAG = re.compile(rb"<(mujoco|robot|sdf)[\s>/]")
_BODY_OR_INCLUDE = re.compile(rb"<(body|include)[\s>/]")
_OPENING = re.compile(r"Error opening file '([^']+)'")
_ELEMENT = re.compile(r"Element name '([^']*)'")
_TOO_SMALL = re.compile(r"too small: (\S+) \.")
_SENTINEL_RGBA = (0.123, 0.456, 0.789, 0.321)          # marks a geom whose mesh file is missing


def menagerie_files(root: str) -> tuple[list, list]:
    """(model files, scene files): every ``*.xml`` under ``root`` whose root element is ``<mujoco>`` and that
    holds a ``<body>`` or an ``<include>`` (actuator, keyframe and asset fragments are not models); a scene is
    a file named ``scene*.xml``.  Included files are kept: each model file is read on its own too."""
    models, scenes = [], []
    for folder, subfolders, files in os.walk(root):
        subfolders.sort()
        for name in sorted(files):
            if not name.endswith(".xml"):
                continue
            path = os.path.join(folder, name)
            with open(path, "rb") as fh:
                text = re.sub(rb"<!--.*?-->", b"", fh.read(), flags=re.DOTALL)
            match = _ROOT_TAG.search(text)
            if not match or match.group(1) != b"mujoco" or not _BODY_OR_INCLUDE.search(text):
                continue
            (scenes if name.startswith("scene") else models).append(path)
    return models, scenes


def _refusal(text: str) -> str:
    """The bucket of a description the tool refuses (the work of another helper is named as pending)."""
    if "which does not exist" in text:
        return "mesh file missing"
    for key, label in (("<attach", "pending <attach>"), ("inline vertices", "pending inline mesh vertices"),
                       ("hfield", "pending height field"), ("height field", "pending height field")):
        if key in text:
            return label
    return text.split(": ", 2)[-1][:80]


def _massless(element) -> bool:
    return element.mass == 0 or (element.mass is None and element.density == 0)


def mujoco_reference(path: str, *, geometry: str = "collision", max_rounds: int = 400):
    """MuJoCo's inertia from geometry for every body of ``path``, each mesh with exact inertia where MuJoCo
    accepts it (``inertia="shell"`` kept; a mesh whose exact inertia MuJoCo refuses keeps the file's own mode).

    Returns ``(bodies, refused, missing)``: ``bodies`` [(name, mass, centre, tensor in body axes, faces by mesh
    file basename)], ``refused`` {mesh file basename: MuJoCo's reason}, ``missing`` {body name: [files]} (a
    missing file's geoms are compiled as small spheres, so that the rest of the model compiles; their bodies
    are not compared unless every such geom is massless: a visual mesh under ``geometry="collision"``).
    ``geometry="collision"``: the geoms that do not collide (``contype`` and
    ``conaffinity`` 0, in no ``<contact><pair>``) are made massless first, so that MuJoCo's inertia from
    geometry is that of the collision geoms (a body left without mass is bounded by ``boundmass`` and
    ``boundinertia`` 1e-15, which nothing else reaches)."""
    import mujoco
    spec = mujoco.MjSpec.from_file(path)
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    if geometry == "collision":
        paired = {name for pair in spec.pairs for name in (pair.geomname1, pair.geomname2)}
        for geom in spec.geoms:
            if geom.contype == 0 and geom.conaffinity == 0 and geom.name not in paired:
                geom.mass, geom.density = 0.0, 0.0
        spec.compiler.boundmass, spec.compiler.boundinertia = 1e-15, 1e-15
    declared = {}
    for mesh in spec.meshes:
        declared[mesh.name] = mesh.inertia
        if mesh.inertia != mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL:
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    refused: dict = {}
    retried: set = set()
    missing: dict = collections.defaultdict(list)
    for _ in range(max_rounds):
        try:
            model = spec.compile()
            break
        except ValueError as exc:
            text = str(exc)
            first = text.splitlines()[0]
            opening = _OPENING.search(first)
            if opening:
                base = os.path.basename(opening.group(1))
                gone = [m for m in spec.meshes if os.path.basename(m.file) == base]
                if not gone:
                    raise
                for mesh in gone:
                    key = mesh.name or os.path.splitext(os.path.basename(mesh.file))[0]
                    for geom in spec.geoms:
                        if geom.meshname == key:
                            if not (geom.mass == 0 or (np.isnan(geom.mass) and geom.density == 0)):
                                # a massless geom's stand-in adds nothing: its body is still compared
                                missing[geom.parent.name].append(base)
                            geom.type, geom.meshname = mujoco.mjtGeom.mjGEOM_SPHERE, ""
                            geom.size, geom.rgba = [1e-3, 0, 0], list(_SENTINEL_RGBA)
                    spec.delete(mesh)
                continue
            names = [m.group(1) for m in (_ELEMENT.search(text), _TOO_SMALL.search(first), _MESH_NAMED.search(first))
                     if m and m.group(1)]
            mesh = next((spec.mesh(n) for n in names if spec.mesh(n) is not None), None)
            if mesh is None or mesh.name in retried:
                raise
            # keyed by file for the report, retried by mesh: several meshes may name one file (Talos, TIAGo,
            # Lite 6 and Cassie use one file for a left and a right mesh, each refused in turn)
            retried.add(mesh.name)
            refused[os.path.basename(mesh.file)] = first.removeprefix("Error: ")
            keep = declared.get(mesh.name, mujoco.mjtMeshInertia.mjMESH_INERTIA_LEGACY)
            mesh.inertia = (keep if keep != mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
                            else mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX)
    else:
        raise ValueError(f"MuJoCo refused more than {max_rounds} meshes")
    faces = {}
    for m in range(model.nmesh):
        file = model.paths[model.mesh_pathadr[m]:].split(b"\0", 1)[0].decode()
        faces[os.path.basename(file)] = int(model.mesh_facenum[m])
    bodies = []
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        bodies.append((model.body(i).name, float(model.body_mass[i]), model.body_ipos[i].copy(),
                       rot @ np.diag(model.body_inertia[i]) @ rot.T))
    return bodies, refused, dict(missing), faces


def _difference(props, mass: float, com, tensor) -> float:
    """``max(|Δm|/m, |Δc|/size, ‖ΔI‖/‖I‖)``, ``size`` the body's radius of gyration."""
    if mass == 0:
        return 0.0 if props.mass == 0 else float("inf")
    size = max(np.sqrt(np.trace(tensor) / (2 * mass)), 1e-12)
    return max(abs(props.mass - mass) / mass, float(np.linalg.norm(props.center_of_mass - com)) / size,
               float(np.linalg.norm(props.inertia - tensor) / max(np.linalg.norm(tensor), 1e-300)))


#: Unit-density mesh bodies of :func:`twin`, by file, overlap rule, rounding and placement (one run).
_TWIN_MESHES: dict = {}


def _as_given(raw):
    """Unit-density mass properties of the triangles of ``raw`` exactly as read: their signed volume integrals
    summed (no weld, no orientation, no repair), what MuJoCo's ``inertia="exact"`` integrates.  An overlap of
    two bodies is counted twice, a crack left open, an inside-out part subtracted."""
    from inertia_tool.integrals import second_moment_to_inertia, volume_moments
    from inertia_tool.mass.properties import MassProperties
    moments = volume_moments(raw.vertices, raw.faces)
    return MassProperties(mass=moments.volume, volume=moments.volume, center_of_mass=moments.centroid,
                          inertia=second_moment_to_inertia(moments.second_moment), density=1.0)


def twin(link, *, overlap: str = "union", float32: bool = False):
    """The body recomputed from its elements at the model's densities the way MuJoCo's compiler integrates it:
    ``overlap="sum"`` counts a mesh's overlapping bodies twice (meshes that need repair raise),
    ``overlap="given"`` sums the signed integrals of each mesh's triangles exactly as read (:func:`_as_given`:
    MuJoCo's exact mode; never refuses), ``float32`` rounds the file's coordinates to float32 first (MuJoCo
    stores vertices in float32)."""
    from dataclasses import replace

    from inertia_tool import mass_properties
    from inertia_tool.mass.properties import MassProperties, combine
    from inertia_tool.mesh.read import load_mesh
    from inertia_tool.robot.geometry import _placed, element_mass_properties, element_shell_properties, fitted_element
    weighted = []
    for e in link.elements:
        if _massless(e):
            continue
        if e.shell:
            unit = element_shell_properties(e)
        elif e.kind == "mesh":
            key = (e.mesh, overlap, float32, e.scale.tobytes(), e.reference_rotation.tobytes(),
                   e.reference_translation.tobytes())
            if key not in _TWIN_MESHES:
                raw = load_mesh(e.mesh, units="m")
                if float32:
                    raw = replace(raw, vertices=raw.vertices.astype(np.float32).astype(np.float64))
                _TWIN_MESHES[key] = (_as_given(_placed(raw, e)) if overlap == "given"
                                     else mass_properties(_placed(raw, e), density=1.0, overlap=overlap))
            unit = _TWIN_MESHES[key].transformed(rotation=e.rotation, translation=e.translation)
        elif overlap == "given" and e.fit_scale is not None and e.mesh is not None:
            # a primitive MuJoCo fits to the mesh's moments: fitted to the triangles as it integrates them
            raw = load_mesh(e.mesh, units="m")
            if float32:
                raw = replace(raw, vertices=raw.vertices.astype(np.float32).astype(np.float64))
            unit = element_mass_properties(fitted_element(e, mesh_properties=_as_given(_placed(raw, e))))
        else:
            unit = element_mass_properties(e)
        if e.mass is not None:
            weighted.append(unit.with_mass(e.mass))
        else:
            weighted.append(MassProperties(mass=unit.mass * e.density, volume=unit.volume,
                                           center_of_mass=unit.center_of_mass, inertia=unit.inertia * e.density,
                                           density=e.density))
    return weighted[0] if len(weighted) == 1 else combine(weighted)


def _bounds_hold(result, mass: float, com, tensor) -> bool:
    """Whether MuJoCo's values lie within the estimate's stated bounds (mass relative, centre in m, tensor
    relative Frobenius where a bound is given)."""
    u, p = result.uncertainty, result.properties
    if u is None:
        return False
    ok = abs(p.mass - mass) <= u.mass * p.mass and float(np.linalg.norm(p.center_of_mass - com)) <= u.center_of_mass
    if u.inertia is not None:
        ok = ok and float(np.linalg.norm(p.inertia - tensor)) <= u.inertia * float(np.linalg.norm(p.inertia))
    return bool(ok)


def compare_menagerie_file(path: str, *, rtol: float, repair: bool, cache, geometry: str = "collision") -> list:
    """[(body, bucket, difference, detail)] for every body of ``path`` (see :func:`run_menagerie`)."""
    reference, refused, missing, faces = mujoco_reference(path, geometry=geometry)
    robot = read_robot(path, geometry=geometry, missing_meshes="per-link")
    ours = link_inertials(robot, density="model", repair=repair, mesh_cache=cache)
    if len(ours) != len(reference):
        return [("*", "bodies differ in number", float("nan"), f"{len(ours)} links, MuJoCo {len(reference)}")]
    rows = []
    for result, link, (name, mass, com, tensor) in zip(ours, robot.links, reference):
        files = {os.path.basename(e.mesh) for e in link.elements if e.mesh and not _massless(e)}
        if name in missing or (result.problem or "").startswith("mesh file missing"):
            rows.append((name, "mesh file missing", float("nan"), ", ".join(sorted(set(missing.get(name, ())))
                                                                                 or [result.problem[19:]])))
            continue
        if name and result.name != name:
            rows.append((name, "named differently", float("nan"), result.name))
            continue
        if result.properties is None:
            rows.append((name, f"no result: {_cause(result.problem or '')}", float("nan"), result.problem))
            continue
        diff = _difference(result.properties, mass, com, tensor)
        said = sorted(files & set(refused))
        declared = link.declared
        if (diff > rtol and declared is not None and abs(declared.mass - mass) <= 1e-9 * mass
                and float(np.linalg.norm(declared.center_of_mass - com)) <= 1e-9):
            # MuJoCo compiles the bodies of an <attach>ed model with that model's own compiler (checked on 4.0:
            # neither the main spec's inertiafromgeom nor body.explicitinertial reaches them), whose default
            # inertiafromgeom="auto" keeps a declared <inertial>: its body is not from geometry
            rows.append((name, f"MuJoCo keeps the declared <inertial> ({result.method})", diff,
                         "an attached model's own compiler"))
            continue
        if said:
            rows.append((name, f"MuJoCo's exact mode refuses a mesh ({result.method})", diff,
                         f"{said[0]}: {refused[said[0]]}"))
            continue
        method = result.method
        if method == "estimate" and _bounds_hold(result, mass, com, tensor):
            rows.append((name, "estimate, bounds hold", diff, ""))
            continue
        if method != "estimate" and diff <= rtol:
            rows.append((name, f"{method}, agrees", diff, ""))
            continue
        cause, detail = _mujoco_side(link, result, mass, com, tensor, rtol=rtol, faces=faces)
        if method == "estimate":
            bucket = f"estimate, bounds fail: {cause}" if cause else "estimate, bounds fail"
        else:
            bucket = f"{method}: {cause}" if cause else f"{method}, disagrees"
        rows.append((name, bucket, diff, detail))
    return rows


#: How much more mass the summed triangles must carry than the tool's solid before a body whose MuJoCo value is
#: their sum is said to count an overlap twice (below it the sum differs by round-off, float32 or cracks).
DOUBLE_COUNT_RTOL = 1e-4


def _mujoco_side(link, result, mass: float, com, tensor, *, rtol: float, faces: dict) -> tuple[str, str]:
    """``(cause, detail)`` of a body where MuJoCo and the tool differ by more than ``rtol``, when MuJoCo's value
    is shown to be something else than the solid the tool computes ("" for a real disagreement):

    * **double count**: MuJoCo's value equals the summed signed integrals of the meshes' triangles as read
      (:func:`twin` ``overlap="given"``, float64 or float32 coordinates; a fitted primitive fitted to them) to
      ``rtol`` and to a tenth of the tool's difference from MuJoCo, and that sum carries more
      than :data:`DOUBLE_COUNT_RTOL` more mass than the tool's solid (overlapping bodies, counted once by the
      tool's union, twice by MuJoCo);
    * **triangles as read**: the same agreement, the masses within that: MuJoCo integrates the file's unwelded
      float32 triangles (cracks, rounding) where the tool integrates the welded solid;
    * float32 vertices (the overlap-summed solid of float32 coordinates agrees), MuJoCo's OBJ loader keeping
      the first object only, or fewer triangles."""
    try:
        given = min((_difference(twin(link, overlap="given", float32=f32), mass, com, tensor), f32)
                    for f32 in (False, True))
        excess = twin(link, overlap="given", float32=given[1]).mass / result.properties.mass - 1.0
    except Exception as exc:   # noqa: BLE001 -- the diagnosis failing is reported, not fatal
        given, excess, note = (float("nan"), False), float("nan"), f"as-read sum failed: {exc}"
    else:
        note = (f"triangles as read{' (float32)' if given[1] else ''}: {given[0]:.1e} from MuJoCo, "
                f"{excess:+.1e} mass vs the tool")
    diff = _difference(result.properties, mass, com, tensor)
    if given[0] <= min(rtol, 0.1 * diff):       # MuJoCo's value is the sum, ten times closer than the tool's
        if excess > DOUBLE_COUNT_RTOL:
            return "MuJoCo counts overlaps twice (its value is the triangles' summed integral)", note
        return "MuJoCo integrates the triangles as read (unwelded, float32; their summed integral agrees)", note
    try:
        summed = _difference(twin(link, overlap="sum"), mass, com, tensor)
        rounded = _difference(twin(link, overlap="sum", float32=True), mass, com, tensor)
    except Exception as exc:   # noqa: BLE001 -- a mesh that needs repair has no overlap-summed solid
        summed = rounded = float("nan")
        note += f"; twin failed: {str(exc)[:80]}"
    else:
        note += f"; summed {summed:.1e}, float32 {rounded:.1e}"
    files = {os.path.basename(e.mesh) for e in link.elements if e.mesh and not _massless(e)}
    dropped = [f for f in files if f in faces and f.lower().endswith(".obj") and faces[f] < _file_triangles(link, f)]
    close = min(rtol, 0.1 * diff)
    if result.method != "exact" and summed <= close:
        return "MuJoCo counts overlaps twice (summed integral agrees)", note
    if rounded <= close:
        return "MuJoCo approximate (float32 vertices)", note
    if result.method == "estimate" and np.isfinite(given[0]):
        sums = twin(link, overlap="given", float32=given[1])
        if _bounds_hold(result, sums.mass, sums.center_of_mass, sums.inertia):
            return ("the bounds hold against the triangles' own summed integral; MuJoCo differs from that sum too "
                    "(its own mesh processing)", note)
    if dropped and all(_first_object_only(link, f, faces[f]) for f in dropped):
        return ("MuJoCo reads only the first object of an OBJ file (the tool the whole file; said in the link's "
                "warnings)", note)
    if dropped:
        return ("MuJoCo approximate (its OBJ loader keeps fewer triangles: polygons it cannot clip)",
                note + f"; {dropped[0]}: MuJoCo {faces[dropped[0]]} triangles, the file "
                       f"{_file_triangles(link, dropped[0])}")
    return "", note



def _first_object_only(link, basename: str, kept: int) -> bool:
    """Whether MuJoCo's ``kept`` triangles of an OBJ file are exactly its first object's (the file has more)."""
    from inertia_tool.robot.mjcf import obj_object_triangles
    element = next(e for e in link.elements if e.mesh and os.path.basename(e.mesh) == basename)
    objects = obj_object_triangles(element.mesh)
    return len(objects) > 1 and objects[0] == kept


def _file_triangles(link, basename: str) -> int:
    from inertia_tool.mesh.read import load_mesh
    element = next(e for e in link.elements if e.mesh and os.path.basename(e.mesh) == basename)
    return int(len(load_mesh(element.mesh, units="m").faces))


def _cli_corpus(root: str, repair: bool) -> tuple[float, float, int]:
    """CPU (children) and wall seconds and exit code of ``inertia-tool robot ROOT --density 1000`` (folder mode)."""
    import resource
    import subprocess
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "inertia_tool", "robot", root, "--density", "1000"]
                          + (["--repair"] if repair else []), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                          env=dict(os.environ, PYTHONPATH=os.path.dirname(HERE)), check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime), wall, done.returncode


def run_menagerie(root: str, *, repair: bool, rtol: float, mujoco: bool, folder_mode: bool, verbose: bool,
                  geometry: str = "collision", compare_only: bool = False, models_only: bool = False,
                  reverse: bool = False, scenes_only: bool = False, shard: tuple[int, int] = (0, 1)) -> int:
    """Every model file and scene of a Menagerie checkout through the tool, then every body against MuJoCo
    (``compare_only``: the comparison alone; ``models_only``: the model files, not the scenes, which repeat
    their bodies).  The comparison prints each file's line as it ends (a long run cut off keeps what it did)."""
    from inertia_tool.robot.geometry import MeshCache
    models, scenes = menagerie_files(root)
    if models_only:
        scenes = []
    if scenes_only:        # the files people open: each <include>s a model file and adds a floor, lights, objects
        models = []
    if reverse:            # a second process from the other end: two runs meet in the middle
        models, scenes = models[::-1], scenes[::-1]
    part, parts = shard    # --shard K/N: every N-th file from the K-th, so that N processes share the list
    models, scenes = models[part::parts], scenes[part::parts]
    folders = sorted({os.path.relpath(p, root).split(os.sep)[0] for p in models + scenes})
    print(f"Menagerie at {root}: {len(folders)} model folders, {len(models)} model files, {len(scenes)} scenes; "
          f"load average {os.getloadavg()[0]:.1f} at start", flush=True)
    refusals: collections.Counter = collections.Counter()
    refused_files: dict = collections.defaultdict(list)
    read = {"model": 0, "scene": 0}
    methods: collections.Counter = collections.Counter()
    causes: collections.Counter = collections.Counter()
    cache = MeshCache()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    for path in [] if compare_only else models + scenes:
        kind = "scene" if path in scenes else "model"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                # as the CLI reads it: a mesh file or an attached model absent from the folder leaves its
                # links without a result, each with the reason, rather than refusing the whole file
                robot = read_robot(path, missing_meshes="per-link")
                results = link_inertials(robot, density=1000.0, repair=repair, mesh_cache=cache)
                audit_links(robot, results)
            except InertiaToolError as exc:
                bucket = _refusal(str(exc))
                refusals[bucket] += 1
                refused_files[bucket].append(f"{os.path.relpath(path, root)}: {str(exc).split(': ', 1)[-1][:160]}")
                continue
        read[kind] += 1
        for r in results:
            if r.properties is not None:
                methods[r.method] += 1
            elif r.problem:
                causes[_cause(r.problem)] += 1
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    print(f"\ninertia-tool robot FILE --density 1000{' --repair' if repair else ''} (collision geometry), every "
          f"file in one process, meshes shared:\n  read {read['model']}/{len(models)} model files, "
          f"{read['scene']}/{len(scenes)} scenes; CPU {cpu:.1f} s, wall {wall:.1f} s")
    print(f"  links computed: {sum(methods.values())} ({', '.join(f'{k} {v}' for k, v in methods.most_common())}); "
          f"without a result: {sum(causes.values())}")
    for cause, n in causes.most_common():
        print(f"    {n:5d}  {cause}")
    print("  files refused, by reason:")
    for bucket, n in refusals.most_common():
        print(f"    {n:5d}  {bucket}")
        if verbose or bucket.startswith(("mesh file missing", "pending")):
            for line in refused_files[bucket]:
                print(f"             {line}")
    if folder_mode:
        ccpu, cwall, code = _cli_corpus(root, repair)
        print(f"\ninertia-tool robot {root} --density 1000{' --repair' if repair else ''} (folder mode, one "
              f"command): CPU {ccpu:.1f} s, wall {cwall:.1f} s, exit code {code}", flush=True)
    if not mujoco:
        return 0
    buckets: collections.Counter = collections.Counter()
    diffs: dict = collections.defaultdict(list)
    listed: list = []
    unreadable: list = []
    cpu0 = time.process_time()
    for path in models + scenes:
        start = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                rows = compare_menagerie_file(path, rtol=rtol, repair=repair, cache=cache, geometry=geometry)
            except Exception as exc:   # noqa: BLE001 -- a refusal (MuJoCo's or the tool's) is a finding
                unreadable.append(f"{os.path.relpath(path, root)}: {type(exc).__name__}: "
                                  f"{str(exc).splitlines()[0][:200]}")
                continue
        worst = max((d for _, b, d, _ in rows if np.isfinite(d) and b.endswith(", agrees")), default=0.0)
        print(f"  {time.process_time() - start:7.1f} s  {os.path.relpath(path, root)}: {len(rows)} bodies, "
              f"{sum(b.endswith(', agrees') for _, b, _, _ in rows)} agree (max {worst:.1e}); "
              + "; ".join(f"{body} [{b}] {d:.1e}" for body, b, d, _ in rows
                          if "disagree" in b or "fail" in b or "approximate" in b or "twice" in b or "as read" in b),
              flush=True)
        for body, bucket, diff, detail in rows:
            buckets[bucket] += 1
            if np.isfinite(diff):
                diffs[bucket].append(diff)
            if "disagree" in bucket or "fail" in bucket or "approximate" in bucket or verbose:
                listed.append(f"  {os.path.relpath(path, root)}: {body} [{bucket}] {diff:.1e} {detail[:200]}")
    print(f"\nagainst MuJoCo {_mujoco_version()} (--geometry {geometry} --density model"
          f"{' --repair' if repair else ''}, "
          f"every body of every file; MuJoCo with inertiafromgeom, exact mesh inertia where it accepts it"
          f"{', non-colliding geoms massless' if geometry == 'collision' else ''}), "
          f"CPU {time.process_time() - cpu0:.1f} s:")
    for bucket, n in sorted(buckets.items(), key=lambda kv: (-kv[1], kv[0])):
        d = np.array(diffs.get(bucket, []))
        print(f"  {n:5d}  {bucket}" + (f"  (median {np.median(d):.1e}, max {d.max():.1e})" if d.size else ""))
    for line in unreadable:
        print(f"  not compared: {line}")
    for line in listed:
        print(line)
    return 0


def _mujoco_version() -> str:
    import mujoco
    return mujoco.__version__


def _shard(text: str) -> tuple[int, int]:
    """``"K/N"`` as ``(K, N)``, 0 <= K < N."""
    try:
        part, parts = (int(x) for x in text.split("/"))
    except ValueError:
        raise SystemExit(f"--shard: expected K/N (two integers), got {text!r}") from None
    if not 0 <= part < parts:
        raise SystemExit(f"--shard: expected 0 <= K < N, got {text!r}")
    return part, parts


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="*")
    parser.add_argument("--menagerie", metavar="ROOT", help="every model file and scene*.xml of a MuJoCo Menagerie "
                        "checkout, then every body against MuJoCo")
    parser.add_argument("--no-folder-mode", action="store_true", help="with --menagerie: skip timing the "
                        "folder-mode command")
    parser.add_argument("--compare-only", action="store_true", help="with --menagerie: only the comparison with "
                        "MuJoCo (not the first pass at --density 1000)")
    parser.add_argument("--models-only", action="store_true", help="with --menagerie: the model files, not the "
                        "scenes (which repeat their bodies)")
    parser.add_argument("--scenes-only", action="store_true", help="with --menagerie: the scene files alone")
    parser.add_argument("--shard", default="0/1", metavar="K/N", help="with --menagerie: every N-th file from "
                        "the K-th (0-based), for N processes")
    parser.add_argument("--reverse", action="store_true", help="with --menagerie: the files in reverse order (a "
                        "second process from the other end)")
    parser.add_argument("--geometry", default="collision")
    parser.add_argument("--density", default="1000")
    parser.add_argument("--repair", action="store_true")
    parser.add_argument("--no-mujoco", action="store_true")
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--package", action="append", default=[], metavar="NAME=DIR")
    parser.add_argument("--verbose", action="store_true", help="print every link without a result")
    args = parser.parse_args(argv)
    if args.menagerie:
        return run_menagerie(args.menagerie, repair=args.repair, rtol=args.rtol, mujoco=not args.no_mujoco,
                             folder_mode=not args.no_folder_mode and not args.compare_only, verbose=args.verbose,
                             geometry="all" if args.geometry == "all" else "collision",
                             compare_only=args.compare_only, models_only=args.models_only, reverse=args.reverse,
                             scenes_only=args.scenes_only, shard=_shard(args.shard))
    if not args.folders:
        parser.error("give folders, or --menagerie ROOT")
    density = args.density if args.density == "model" else float(args.density)
    packages = dict(item.split("=", 1) for item in args.package)
    models = find_descriptions(args.folders)
    answered: collections.Counter = collections.Counter()
    causes: collections.Counter = collections.Counter()
    unreadable: list = []
    agreement: dict = collections.defaultdict(list)
    disagreements: list = []
    mujoco_refusals: list = []
    cpu_total = 0.0
    links_total = 0
    for path in models:
        start = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                robot = read_robot(path, geometry=args.geometry, packages=packages)
                results = link_inertials(robot, density=density, repair=args.repair)
            except InertiaToolError as exc:
                unreadable.append(f"{path}: {exc}")
                cpu_total += time.process_time() - start
                continue
            except Exception as exc:   # noqa: BLE001 -- a crash is the finding
                unreadable.append(f"{path}: CRASH {type(exc).__name__}: {exc}")
                cpu_total += time.process_time() - start
                continue
            cpu = time.process_time() - start
            cpu_total += cpu
            links_total += len(results)
            for r in results:
                if r.properties is not None:
                    answered[r.method] += 1
                else:
                    causes[_cause(r.problem)] += 1
                    if args.verbose:
                        print(f"  {os.path.relpath(path)}: {r.name}: {r.problem[:300]}")
            if robot.format == "mjcf" and not args.no_mujoco:
                try:
                    rows, lines, refused = compare(path, args.rtol, args.repair)
                except Exception as exc:   # noqa: BLE001
                    rows, lines, refused = [], [], f"comparison crashed: {type(exc).__name__}: {exc}"
                if refused:
                    mujoco_refusals.append(f"{path}: {refused}")
                for _, method, diff in rows:
                    agreement[method].append(diff)
                if lines:
                    disagreements.append(f"{path}:")
                    disagreements.extend(lines)
        print(f"{cpu:7.2f} s  {len(results):3d} links  {path}", flush=True)
    print(f"\n{len(models)} descriptions, {len(unreadable)} unreadable, {links_total} links: "
          f"{sum(answered.values())} answered ({dict(answered)}), {sum(causes.values())} without a result; "
          f"CPU {cpu_total:.1f} s")
    for cause, n in causes.most_common():
        print(f"  {n:4d}  {cause}")
    for line in unreadable:
        print(f"unreadable: {line[:400]}")
    if agreement:
        print("\nagainst MuJoCo (geometry all, the model's densities, exact mesh inertia), per body:")
        for method, diffs in sorted(agreement.items()):
            d = np.array(diffs)
            finite = d[np.isfinite(d)]
            within = int(np.sum(finite <= args.rtol))
            print(f"  {method:10s} {len(d):4d} bodies, {within} within {args.rtol:g}"
                  + (f", median {np.median(finite):.1e}, max {finite.max():.1e}" if finite.size else ""))
        for line in mujoco_refusals:
            print(f"  {line}")
        for line in disagreements:
            print(line[:400])
    return 0


if __name__ == "__main__":
    sys.exit(main())
