"""MJCF as MuJoCo itself reads it: a cross-check of :func:`~inertia_tool.robot.mjcf.read_mjcf` against
``mujoco.MjSpec`` where the ``mujoco`` package is installed (one source of truth for MJCF's semantics; the
built-in reader stays the one that computes, and the one used where MuJoCo is not installed).

:func:`compare_with_mujoco` compiles the description's file with MuJoCo (``MjSpec.from_file(...).compile()``,
the model's own settings) and compares, body by body in MuJoCo's order:

* the bodies: how many, and their names (the reader names an unnamed body ``body N``; MuJoCo leaves it
  empty) — what ``<include>``, ``<frame>``, ``<replicate>`` and ``childclass`` decide;
* the geoms the chosen geometry selects, by the reader's rule applied to MuJoCo's compiled values
  (collision: ``contype`` or ``conaffinity`` non-zero, or in a ``<contact><pair>``; visual: the others; all:
  ``group`` within ``inertiagrouprange``) — what default classes decide;
* for each primitive geom (not fitted to a mesh): its kind, its centre in the body frame (``geom_pos``) and
  ``R diag(h²) Rᵀ`` built from its half-sizes ``h`` (capsule and cylinder: ``(r, r, half-length)``) and its
  orientation ``R`` — a tensor that does not depend on which of a shape's symmetric orientations each reader
  picked (MuJoCo turns a ``fromto`` capsule along +z by 180° about x; the reader does not turn it) — what
  ``size`` merging, ``fromto``, ``euler``/``eulerseq``, ``axisangle``, ``xyaxes``, ``zaxis`` and frames decide;
* for each mesh geom: the file's name (MuJoCo moves a mesh's frame to its centre and principal axes, so its
  compiled pose is not the element's).

Each disagreement is one sentence; none means MuJoCo and the reader read the file alike in all of these.
"""

from __future__ import annotations

import os

import numpy as np

from .description import RobotDescription, parse_geometry

__all__ = ["mujoco_available", "compare_with_mujoco", "builtin_mesh"]

#: Largest difference, relative to the body's largest geom size, of a geom's centre or shape tensor that
#: counts as agreement (MuJoCo stores positions and sizes in float64; its quaternions are normalised).
AGREEMENT_RTOL = 1e-9


def mujoco_available() -> bool:
    """Whether the ``mujoco`` package can be imported."""
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def _quat_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _half_sizes(kind: str, size) -> np.ndarray:
    """Half-extents along the element's axes from the reader's ``size`` (box edges, capsule and cylinder
    ``(radius, length)``, sphere ``(radius,)``, ellipsoid semi-axes)."""
    if kind == "box":
        return 0.5 * np.asarray(size, dtype=np.float64)
    if kind in ("capsule", "cylinder"):
        return np.array([size[0], size[0], 0.5 * size[1]])
    if kind == "sphere":
        return np.full(3, size[0])
    return np.asarray(size, dtype=np.float64)


def _mujoco_half_sizes(kind: str, size) -> np.ndarray:
    if kind in ("capsule", "cylinder"):
        return np.array([size[0], size[0], size[1]])
    if kind == "sphere":
        return np.full(3, size[0])
    return np.asarray(size[:3], dtype=np.float64)


def _shape(rotation, half) -> np.ndarray:
    return rotation @ np.diag(np.square(half)) @ rotation.T


def _selected(model, g: int, geometry: str, paired: set, groups, lineage: tuple = ("main",)) -> bool:
    """The reader's rule (:func:`inertia_tool.robot.mjcf._selected`) on MuJoCo's compiled values; ``lineage``:
    the geom's default class (MuJoCo's) and the classes it is nested in."""
    kind, values = parse_geometry(geometry)
    if kind == "all":
        return bool(groups[0] <= model.geom_group[g] <= groups[1])
    if kind == "group":
        return int(model.geom_group[g]) in values
    if kind == "class":
        return any(name in values for name in lineage)
    collides = g in paired or model.geom_contype[g] != 0 or model.geom_conaffinity[g] != 0
    return bool(collides) == (kind == "collision")


def _class_lineages(spec, document: bytes | None) -> dict:
    """Compiled geom index → its default class as MuJoCo gives it (``MjsGeom.classname``) and the classes it is
    nested in, read from the ``<default>`` elements of the main file (``MjSpec`` keeps no nesting; a class of an
    included or attached file counts as nested in ``main`` only)."""
    from .description import parse_xml
    parents: dict = {}
    if document:
        for default in parse_xml(document, "the description").getroot().iter("default"):
            above = default.getparent()
            if default.get("class") and above is not None and above.tag == "default":
                parents[default.get("class")] = above.get("class", "main")
    out = {}
    for geom in spec.geoms:
        chain = [geom.classname.name or "main"]
        for _ in range(len(parents)):
            if chain[-1] not in parents:
                break
            chain.append(parents[chain[-1]])
        out[geom.id] = tuple(chain) + (("main",) if chain[-1] != "main" else ())
    return out


def compare_with_mujoco(robot: RobotDescription, *, rtol: float = AGREEMENT_RTOL) -> tuple[str, ...] | None:
    """Where MuJoCo reads ``robot``'s MJCF file differently from the built-in reader (see the module
    docstring); ``()`` when they agree, None when ``mujoco`` is not installed or ``robot`` is not MJCF.

    Parameters
    ----------
    robot : RobotDescription
        From :func:`~inertia_tool.robot.read_robot` on an MJCF file.
    rtol : float
        Agreement of centres and shape tensors, relative to the body's largest half-size squared (tensors)
        or largest half-size (centres).

    Returns
    -------
    tuple of str or None
        One sentence per disagreement; a model MuJoCo refuses to compile is one sentence saying so.
    """
    if robot.format != "mjcf" or not mujoco_available():
        return None
    import mujoco
    try:
        spec = mujoco.MjSpec.from_file(robot.source)
        model = spec.compile()
    except Exception as exc:  # noqa: BLE001 -- MuJoCo's refusal is the finding (its errors are ValueError)
        return (f"MuJoCo refuses the model: {str(exc).strip().splitlines()[0][:200]}",)
    out: list = []
    if model.nbody - 1 != len(robot.links):
        return (f"MuJoCo has {model.nbody - 1} bodies, the reader {len(robot.links)} links",)
    paired = set(model.pair_geom1.tolist()) | set(model.pair_geom2.tolist())
    groups = tuple(spec.compiler.inertiagrouprange)
    lineages = _class_lineages(spec, robot.document)
    mesh_kind = mujoco.mjtGeom.mjGEOM_MESH
    kinds = {mujoco.mjtGeom.mjGEOM_BOX: "box", mujoco.mjtGeom.mjGEOM_SPHERE: "sphere",
             mujoco.mjtGeom.mjGEOM_CAPSULE: "capsule", mujoco.mjtGeom.mjGEOM_CYLINDER: "cylinder",
             mujoco.mjtGeom.mjGEOM_ELLIPSOID: "ellipsoid", mesh_kind: "mesh",
             mujoco.mjtGeom.mjGEOM_HFIELD: "box"}       # MuJoCo's size of a height field is its inertia box
    for index, link in enumerate(robot.links, start=1):
        name = model.body(index).name
        if (name or f"body {index}") != link.name:
            out.append(f"body {index}: MuJoCo names it {name!r}, the reader {link.name!r}")
            continue
        theirs = [g for g in range(model.ngeom) if model.geom_bodyid[g] == index
                  and _selected(model, g, robot.geometry, paired, groups, lineages.get(g, ("main",)))]
        if len(theirs) != len(link.elements):
            out.append(f"body {link.name!r}: MuJoCo selects {len(theirs)} {robot.geometry} geoms, the reader "
                       f"{len(link.elements)}")
            continue
        scale = max([float(np.max(model.geom_size[g][:3])) for g in theirs] + [1e-300])
        for g, element in zip(theirs, link.elements):
            kind = kinds.get(int(model.geom_type[g]), f"type {int(model.geom_type[g])}")
            what = f"body {link.name!r} geom {model.geom(g).name or element.name!r}"
            if kind != element.kind:
                out.append(f"{what}: MuJoCo reads a {kind}, the reader a {element.kind}")
                continue
            if kind == "mesh":
                file = model.paths[model.mesh_pathadr[model.geom_dataid[g]]:].split(b"\0", 1)[0].decode()
                if os.path.basename(file) != os.path.basename(element.mesh or ""):
                    out.append(f"{what}: MuJoCo reads the mesh file {os.path.basename(file)!r}, the reader "
                               f"{os.path.basename(element.mesh or '')!r}")
                continue
            if element.fit_scale is not None:           # sized by a fit to its mesh: compared by the integrals
                continue
            centre = np.abs(model.geom_pos[g] - element.translation).max()
            if not centre <= rtol * scale:
                out.append(f"{what}: MuJoCo puts its centre at {np.round(model.geom_pos[g], 9).tolist()}, the "
                           f"reader at {np.round(element.translation, 9).tolist()}")
            mine = _shape(element.rotation, _half_sizes(kind, element.size))
            their = _shape(_quat_matrix(model.geom_quat[g]), _mujoco_half_sizes(kind, model.geom_size[g]))
            if not np.abs(mine - their).max() <= rtol * scale * scale:
                out.append(f"{what}: MuJoCo's size and orientation differ from the reader's (half-sizes "
                           f"{np.round(_mujoco_half_sizes(kind, model.geom_size[g]), 9).tolist()} against "
                           f"{np.round(_half_sizes(kind, element.size), 9).tolist()})")
    return tuple(out)


def builtin_mesh(builtin: str, params: str | None, *, what: str, source: str) -> tuple:
    """The vertices (n, 3) and triangles (m, 3) of MuJoCo's ``<mesh builtin params>`` (MuJoCo 3.3+: ``sphere``,
    ``hemisphere``, ``cone``, ``supersphere``, ``supertorus``, ``wedge``, ...), as MuJoCo's own parser
    generates them (``MjSpec``'s ``uservert`` and ``userface``), before the asset's ``scale``, ``refpos`` and
    ``refquat``.  The triangles are None when MuJoCo gives only points (``cone``, ``wedge``): it then takes their
    convex hull, as for ``vertex`` without ``face``.

    The generator is MuJoCo's (its tessellation is not a closed form of the named shape: its ``sphere`` of
    radius 1 holds 0.87 of the ball's volume), so reading one needs the ``mujoco`` package.

    Raises
    ------
    RobotDescriptionError
        ``mujoco`` is not installed, or MuJoCo refuses the parameters (its message, first line).
    """
    from lxml import etree

    from ..errors import RobotDescriptionError
    if not mujoco_available():
        raise RobotDescriptionError(f"{source}: {what}: builtin={builtin!r} meshes are generated by MuJoCo; "
                                    "expected the mujoco package to be installed to read them")
    import mujoco
    mesh = etree.Element("mesh", name="m", builtin=builtin)
    if params is not None:
        mesh.set("params", params)
    text = ("<mujoco><asset>" + etree.tostring(mesh, encoding="unicode") + "</asset></mujoco>")
    try:
        spec = mujoco.MjSpec.from_string(text)
    except Exception as exc:  # noqa: BLE001 -- MuJoCo's refusal is the finding (its errors are ValueError)
        problem = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else type(exc).__name__
        raise RobotDescriptionError(f"{source}: {what}: MuJoCo refuses builtin={builtin!r} "
                                    f"params={params!r}: {problem}") from None
    generated = spec.meshes[0]
    vertices = np.array(generated.uservert, dtype=np.float64).reshape(-1, 3)
    faces = np.array(generated.userface, dtype=np.int64).reshape(-1, 3)
    return vertices, (faces if len(faces) else None)
