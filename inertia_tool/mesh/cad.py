"""STEP and IGES parts read through OpenCASCADE and tessellated at a stated chord tolerance.

The exact B-rep mass properties and the comparison with the tessellation are in
:mod:`inertia_tool.mass.brep`.

OpenCASCADE runs in a child process with CPU-time, memory and wall-clock limits (:func:`read_cad`,
:mod:`inertia_tool.isolate`): a file that crashes it (a segmentation fault) or makes it run for minutes becomes
a :class:`~inertia_tool.errors.MeshReadError` naming the reason.  :func:`read_brep`, :func:`tessellate` and
:func:`solids_fused` run in the calling process, for shapes the caller trusts.

Two back ends, both OpenCASCADE:

* **OCP** (``pip install cadquery-ocp-novtk``, the ``[cad]`` extra): reads STEP/IGES into a B-rep in metres
  (the file's own length unit is converted by the reader, ``xstep.cascade.unit = M``), tessellates it with
  ``BRepMesh_IncrementalMesh`` and integrates the exact solid with ``BRepGProp.VolumeProperties_s``
  (Gauss integration on the B-rep faces; its ``MatrixOfInertia`` is about the centre of mass in the tensor
  convention, ``Ixy = −∫xy dm``, checked in the tests).
* **cascadio** (``pip install cascadio``): STEP → GLB at the same tolerances, read by the glTF reader (no
  exact properties).  Used only when OCP is missing.

Tessellation error.  Every triangle of the mesh lies within the chord tolerance ``δ`` (``linear_deflection``,
m) of the true surface, so the solid between the two surfaces is a layer no thicker than ``δ``: the volume
differs by at most ``A·δ`` (``A`` the surface area) and the centre of mass by at most ``A·δ·(|c| + L)/V``
for a part of size ``L``.  :class:`BrepComparison` states ``A·δ/V`` as the bound of the relative volume error
next to the differences actually found.  ``angular_deflection`` (rad) also limits each curved face's
triangles; the smaller of the two governs.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidMeshError, MeshReadError, UsageError
from ..values import frozen_value
from .edges import unique_rows
from .read import BREP_SUFFIXES      # CAD exchange suffixes read as B-reps, defined with the reader's suffixes
from .weld import weld_exact

if TYPE_CHECKING:
    from ..isolate import Limits

__all__ = ["BREP_SUFFIXES", "DEFAULT_CHORD_RTOL", "DEFAULT_ANGULAR_DEFLECTION", "read_brep", "tessellate",
           "chord_tolerance", "tessellate_closed", "tessellated_arrays", "has_ocp", "read_cad", "CadReading",
           "solids_fused", "brep_integrals", "FUSIONS", "step_parts", "MAX_ASSEMBLY_DEPTH", "MAX_ASSEMBLY_PARTS"]

#: How :func:`solids_fused` made one solid of a file's solids.
FUSIONS = ("one solid", "apart", "fused", "failed")

#: Default chord tolerance as a fraction of the bounding-box diagonal.
DEFAULT_CHORD_RTOL = 1e-4

#: Default angular deflection of the tessellation, rad.
DEFAULT_ANGULAR_DEFLECTION = 0.1


def has_ocp() -> bool:
    """Whether OCP (OpenCASCADE's Python bindings) is installed (looked up, not imported: the import takes
    most of a second and the reading runs in a child process anyway)."""
    import importlib.util
    try:
        return importlib.util.find_spec("OCP") is not None
    except (ImportError, ValueError):
        return False


def _fail(path: str, problem: str) -> MeshReadError:
    return MeshReadError(f"{os.fsencode(path).decode('utf-8', 'replace')}: {problem}")


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """OpenCASCADE prints progress banners on stdout (fd 1); keep them off our output."""
    import sys
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def read_brep(path: str | os.PathLike[str]) -> object:
    """The B-rep (``TopoDS_Shape``, metres) of a STEP or IGES file; needs OCP."""
    path = os.fsdecode(os.fspath(path))
    try:
        from OCP.IFSelect import IFSelect_ReturnStatus
        from OCP.IGESControl import IGESControl_Reader
        from OCP.Interface import Interface_Static
        from OCP.STEPControl import STEPControl_Reader
    except ImportError as exc:
        if has_ocp():       # installed but not loadable: under a memory limit, mapping its libraries fails
            if "map segment" in str(exc) or "allocate memory" in str(exc):
                raise MemoryError(str(exc)) from None
            raise _fail(path, f"OCP is installed but cannot be loaded ({exc})") from None
        raise _fail(path, "reading STEP/IGES exactly needs OCP (pip install cadquery-ocp-novtk, or the [cad] "
                          "extra)") from None
    if not os.path.isfile(path):
        raise _fail(path, "no such file")
    suffix = os.path.splitext(path)[1].lower()
    # the reader's constructor initialises the exchange parameters (xstep.cascade.unit back to MM the first
    # time), so the target unit is set after it and restored afterwards
    reader = STEPControl_Reader() if suffix in (".step", ".stp") else IGESControl_Reader()
    previous = Interface_Static.CVal_s("xstep.cascade.unit")
    Interface_Static.SetCVal_s("xstep.cascade.unit", "M")
    try:
        with _quiet():
            status = reader.ReadFile(path)
            if status != IFSelect_ReturnStatus.IFSelect_RetDone:
                raise _fail(path, f"not a readable {'STEP' if suffix in ('.step', '.stp') else 'IGES'} file "
                                  f"({status.name})")
            reader.TransferRoots()
            shape = reader.OneShape()
    finally:
        Interface_Static.SetCVal_s("xstep.cascade.unit", previous or "MM")
    if shape is None or shape.IsNull():
        raise _fail(path, "holds no shape")
    return shape


#: Deepest assembly nesting followed in a STEP file's XCAF document (a cycle or a pathological file stops there).
MAX_ASSEMBLY_DEPTH = 32
#: Most parts (leaf shape instances) read from one STEP assembly.
MAX_ASSEMBLY_PARTS = 10_000


def _label_name(label: Any) -> str | None:
    from OCP.TDataStd import TDataStd_Name
    attribute = TDataStd_Name()
    if label.FindAttribute(TDataStd_Name.GetID_s(), attribute):
        text = attribute.Get().ToExtString()
        return str(text) if text else None
    return None


def _label_entry(label: Any) -> str:
    from OCP.TCollection import TCollection_AsciiString
    from OCP.TDF import TDF_Tool
    entry = TCollection_AsciiString()
    TDF_Tool.Entry_s(label, entry)
    return str(entry.ToCString())


def _materials_by_shape(doc: Any) -> dict[str, tuple[str, float | None]]:
    """Shape label entry → (material name, density kg/m³ or None) of the XCAF document's materials.

    OpenCASCADE keeps a material's density as written in the STEP ``material property`` (its own writer puts
    g/cm³ there, and ``XCAFDoc_MaterialTool::GetDensityForShape`` reads it so); taken as g/cm³, a value that
    gives no plausible solid density (:data:`inertia_tool.units.PLAUSIBLE_DENSITY`) is dropped and the part is
    then mapped by its material's name.  Each material's tree node lists the shapes that use it."""
    from OCP.OCP.collections import Sequence_TDF_Label
    from OCP.TDataStd import TDataStd_TreeNode
    from OCP.XCAFDoc import XCAFDoc, XCAFDoc_DocumentTool, XCAFDoc_Material
    from ..units import PLAUSIBLE_DENSITY
    out: dict[str, tuple[str, float | None]] = {}
    materials = Sequence_TDF_Label()
    XCAFDoc_DocumentTool.MaterialTool_s(doc.Main()).GetMaterialLabels(materials)
    for i in range(1, min(materials.Length(), MAX_ASSEMBLY_PARTS) + 1):
        label = materials.Value(i)
        material = XCAFDoc_Material()
        node = TDataStd_TreeNode()
        if not (label.FindAttribute(XCAFDoc_Material.GetID_s(), material)
                and label.FindAttribute(XCAFDoc.MaterialRefGUID_s(), node)):
            continue
        name = material.GetName().ToCString() if material.GetName() is not None else ""
        density: float | None = float(material.GetDensity()) * 1000.0
        if not (density is not None and PLAUSIBLE_DENSITY[0] <= density <= PLAUSIBLE_DENSITY[1]):
            density = None
        child = node.First() if node.HasFirst() else None
        for _ in range(MAX_ASSEMBLY_PARTS):
            if child is None:
                break
            out[_label_entry(child.Label())] = (str(name) or f"material {i}", density)
            child = child.Next() if child.HasNext() else None
    return out


def step_parts(path: str) -> list[tuple[str, str | None, float | None, Any]]:
    """The parts of a STEP assembly through OpenCASCADE's XCAF document: ``(name, material, density kg/m³ or
    None, located shape in metres)`` for every leaf shape instance, assemblies followed down with their
    placements composed.  One entry (or none) for a file that is not an assembly.  Needs OCP; run in the
    isolated child only.  :func:`_read_here` integrates the parts apart only when some part has a material:
    otherwise the solids are fused as before (the exact B-rep of their union)."""
    try:
        from OCP.IFSelect import IFSelect_ReturnStatus
        from OCP.Interface import Interface_Static
        from OCP.OCP.collections import Sequence_TDF_Label
        from OCP.STEPCAFControl import STEPCAFControl_Reader
        from OCP.TCollection import TCollection_ExtendedString
        from OCP.TDF import TDF_Label
        from OCP.TDocStd import TDocStd_Document
        from OCP.TopLoc import TopLoc_Location
        from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ShapeTool
    except ImportError as exc:      # as read_brep: under a memory limit, mapping the libraries fails
        if "map segment" in str(exc) or "allocate memory" in str(exc):
            raise MemoryError(str(exc)) from None
        raise _fail(path, f"OCP is installed but cannot be loaded ({exc})") from None
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    reader.SetMatMode(True)
    previous = Interface_Static.CVal_s("xstep.cascade.unit")
    Interface_Static.SetCVal_s("xstep.cascade.unit", "M")
    doc = TDocStd_Document(TCollection_ExtendedString("inertia-tool"))
    try:
        with _quiet():
            if reader.ReadFile(path) != IFSelect_ReturnStatus.IFSelect_RetDone or not reader.Transfer(doc):
                return []
    finally:
        Interface_Static.SetCVal_s("xstep.cascade.unit", previous or "MM")
    materials = _materials_by_shape(doc)
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    free = Sequence_TDF_Label()
    shapes.GetFreeShapes(free)
    parts: list[tuple[str, str | None, float | None, Any]] = []

    def walk(label: Any, location: Any, name: str | None, material: tuple[str, float | None] | None,
             depth: int) -> None:
        if depth > MAX_ASSEMBLY_DEPTH or len(parts) >= MAX_ASSEMBLY_PARTS:
            raise _fail(path, f"the assembly nests deeper than {MAX_ASSEMBLY_DEPTH} or holds more than "
                              f"{MAX_ASSEMBLY_PARTS:,} parts")
        name = _label_name(label) or name
        material = materials.get(_label_entry(label), material)
        if XCAFDoc_ShapeTool.IsAssembly_s(label):
            components = Sequence_TDF_Label()
            XCAFDoc_ShapeTool.GetComponents_s(label, components, False)
            for i in range(1, components.Length() + 1):
                component = components.Value(i)
                referred = TDF_Label()
                if not XCAFDoc_ShapeTool.GetReferredShape_s(component, referred):
                    continue
                placed = location.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(component))
                walk(referred, placed, _label_name(component) if not _label_name(referred) else None,
                     materials.get(_label_entry(component), material), depth + 1)
            return
        shape = XCAFDoc_ShapeTool.GetShape_s(label)
        if shape is not None and not shape.IsNull():
            parts.append((name or f"part {len(parts) + 1}", material[0] if material else None,
                          material[1] if material else None, shape.Moved(location)))

    for i in range(1, free.Length() + 1):
        walk(free.Value(i), TopLoc_Location(), None, None, 0)
    return parts


def _bounding_diagonal(shape: Any) -> float:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    if box.IsVoid():        # CornerMin() of a void box raises Standard_ConstructionError
        raise InvalidMeshError("the shape has no bounding box (it holds no points, curves or faces)")
    return float(box.CornerMin().Distance(box.CornerMax()))


def chord_tolerance(shape: Any, chord: float | None = None) -> float:
    """The chord tolerance in m: ``chord`` if given, else :data:`DEFAULT_CHORD_RTOL` × bounding-box diagonal."""
    if chord is not None:
        if not (np.isfinite(chord) and chord > 0):
            raise UsageError(f"Expected a positive finite chord tolerance in m, got {chord}")
        return float(chord)
    return DEFAULT_CHORD_RTOL * _bounding_diagonal(shape)


def tessellate(shape: Any, *, chord: float, angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION,
               max_faces: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the B-rep (``BRepMesh_IncrementalMesh``): ``(vertices (n, 3) m, faces (m, 3))``, outward.

    ``max_faces``: refuse (:class:`UsageError`) a tessellation of more triangles before copying them out.

    Each B-rep face is meshed on its own; reversed faces have their triangles flipped so the normals point
    out of the solid, and each face's location is applied.  The faces' nodes on one B-rep edge are the same
    points of one edge discretisation (the mesher shares it), but each face carries its own copy, moved by its
    own location, so copies can differ in the last bits: they are joined here by topology
    (:func:`_seam_nodes`: the same B-rep vertex, or the same node of the same B-rep edge), not by a distance,
    so the surface arrives closed and no tolerance weld is reported for a clean B-rep.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS
    BRepMesh_IncrementalMesh(shape, chord, False, angular_deflection, True)
    if max_faces is not None:
        total, explorer = 0, TopExp_Explorer(shape, TopAbs_FACE)
        while explorer.More():
            triangulation = BRep_Tool.Triangulation_s(TopoDS.Face(explorer.Current()), TopLoc_Location())
            total += triangulation.NbTriangles() if triangulation is not None else 0
            explorer.Next()
        if total > max_faces:
            raise UsageError(f"the tessellation at a chord tolerance of {chord:.3g} m has {total:,} triangles, "
                             f"more than `max_faces` ({max_faces:,}) allows")
    vertices: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    seams: list[tuple[int, tuple[Any, ...]]] = []
    offset = 0
    seam_keys = _SeamKeys(shape)
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        location = TopLoc_Location()
        triangulation = BRep_Tool.Triangulation_s(face, location)
        explorer.Next()
        if triangulation is None:
            continue
        transform = location.Transformation()
        nodes = np.array([triangulation.Node(i).Transformed(transform).Coord()
                          for i in range(1, triangulation.NbNodes() + 1)], dtype=np.float64)
        tris = np.array([triangulation.Triangle(i).Get() for i in range(1, triangulation.NbTriangles() + 1)],
                        dtype=np.int64) - 1
        if face.Orientation() == TopAbs_REVERSED:
            tris = tris[:, ::-1]
        seams.extend((offset + node, key) for node, key in seam_keys.of_face(face, triangulation, location, nodes))
        vertices.append(nodes)
        faces.append(tris + offset)
        offset += len(nodes)
    if not faces:
        raise UsageError("the shape has no faces to tessellate")
    points, triangles = np.vstack(vertices), np.vstack(faces)
    joined = _seam_nodes(points, seams, _bounding_diagonal(shape))
    if joined is not None:
        points, triangles, new_index = _renumber(points, triangles, joined)
        named = {key: int(new_index[joined[node]]) for node, key in seams}
        chains = [[named[key] for key in chain] for chain in seam_keys.chains.values()
                  if all(key in named for key in chain)]
        triangles = _split_skipped(triangles, chains)
    # the exact weld still joins what topology did not name (bit-identical copies), as before
    welded_vertices, welded_faces = weld_exact(points[triangles])
    # the nodes of a degenerate B-rep edge (a sphere's or cone's pole) are one point: triangles on them collapse
    collapsed = (welded_faces[:, 0] == welded_faces[:, 1]) | (welded_faces[:, 1] == welded_faces[:, 2]) \
        | (welded_faces[:, 2] == welded_faces[:, 0])
    return welded_vertices, welded_faces[~collapsed].astype(np.int64, copy=False)


#: Largest distance between two copies of one seam node (a B-rep vertex, or the k-th node of a B-rep edge's
#: discretisation) that :func:`_seam_nodes` joins, as a fraction of the bounding-box diagonal: copies differ
#: only by each face's location applied in floating point (~1e-16 of the coordinates); anything farther means
#: the copies are not what the topology says, and nothing is joined.
SEAM_JOIN_RTOL = 1e-9


class _SeamKeys:
    """Names of the nodes of a face's triangulation that lie on its B-rep edges: ``("v", i)`` for the B-rep
    vertex ``i`` at an edge's end, ``("e", j, k)`` for the ``k``-th inner node of B-rep edge ``j`` counted from
    its first vertex.  Edges and vertices are numbered by ``TopExp.MapShapes`` (the same shape at the same
    location is one entry, whatever its orientation)."""

    def __init__(self, shape: Any) -> None:
        from OCP.TopAbs import TopAbs_EDGE, TopAbs_VERTEX
        from OCP.TopExp import TopExp
        from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
        self.edges, self.vertices = ShapeMap(), ShapeMap()
        TopExp.MapShapes_s(shape, TopAbs_EDGE, self.edges)
        TopExp.MapShapes_s(shape, TopAbs_VERTEX, self.vertices)
        #: each B-rep edge's nodes in order from its first vertex, by name (as the first face met gives them)
        self.chains: dict[int, list[tuple[Any, ...]]] = {}

    def of_face(self, face: Any, triangulation: Any, location: Any,
                nodes: np.ndarray) -> list[tuple[int, tuple[Any, ...]]]:
        """``(node index in this face's triangulation, seam name)`` for every node on the face's edges."""
        from OCP.BRep import BRep_Tool
        from OCP.TopAbs import TopAbs_EDGE
        from OCP.TopExp import TopExp, TopExp_Explorer
        from OCP.TopoDS import TopoDS
        out: list[tuple[int, tuple[Any, ...]]] = []
        explorer = TopExp_Explorer(face, TopAbs_EDGE)
        while explorer.More():
            edge = TopoDS.Edge(explorer.Current())
            explorer.Next()
            polygon = BRep_Tool.PolygonOnTriangulation_s(edge, triangulation, location)
            if polygon is None or polygon.NbNodes() < 2:
                continue
            index = np.array([polygon.Node(i) for i in range(1, polygon.NbNodes() + 1)], dtype=np.int64) - 1
            if index.min() < 0 or index.max() >= len(nodes):
                continue
            first, last = TopExp.FirstVertex_s(edge), TopExp.LastVertex_s(edge)
            a = np.array(BRep_Tool.Pnt_s(first).Coord())
            b = np.array(BRep_Tool.Pnt_s(last).Coord())
            ends = nodes[index[[0, -1]]]
            forward = np.linalg.norm(ends[0] - a) + np.linalg.norm(ends[1] - b)
            backward = np.linalg.norm(ends[0] - b) + np.linalg.norm(ends[1] - a)
            if backward < forward:              # the polygon runs from the edge's last vertex to its first
                index = index[::-1]
            j = self.edges.FindIndex(edge)
            names = [("v", self.vertices.FindIndex(first))] + [("e", j, k) for k in range(1, len(index) - 1)] \
                + [("v", self.vertices.FindIndex(last))]
            self.chains.setdefault(j, names)
            out.extend(zip(index.tolist(), names))
        return out


def _seam_nodes(points: np.ndarray, seams: list[tuple[int, tuple[Any, ...]]],
                diagonal: float) -> np.ndarray | None:
    """The node each node is joined to (``(n,)`` int, itself when not on a seam), or ``None`` when some copies
    of one seam node lie farther apart than ``SEAM_JOIN_RTOL`` × ``diagonal`` (then nothing is joined)."""
    target = np.arange(len(points))
    if not seams:
        return None
    first: dict[tuple[Any, ...], int] = {}
    for node, key in seams:
        target[node] = first.setdefault(key, node)
    gap = np.linalg.norm(points - points[target], axis=1).max(initial=0.0)
    if not gap <= SEAM_JOIN_RTOL * diagonal:
        return None
    return target


def _renumber(points: np.ndarray, triangles: np.ndarray,
              target: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points and triangles with every node replaced by the node it is joined to, unused nodes dropped, and
    the new number of each kept node (-1 for the others)."""
    keep = np.unique(target)
    new_index = np.full(len(points), -1, dtype=np.int64)
    new_index[keep] = np.arange(len(keep))
    return points[keep], new_index[target][triangles], new_index


def _split_skipped(triangles: np.ndarray, chains: list[list[int]]) -> np.ndarray:
    """Triangles with every triangle edge that skips nodes of a B-rep edge's chain split at them.

    OpenCASCADE's mesher can leave a node of a face's edge polygon out of that face's triangles: a triangle
    edge runs from the node before it to the node after it, a T-junction against the neighbouring face, which
    uses the node.  Such a triangle edge, used once, whose ends are two nodes of one chain ``k`` apart
    (``k > 1``), is replaced by the chain between them: the triangle becomes a fan from its third corner over
    the skipped nodes.  The skipped nodes lie on the B-rep edge, on the face's boundary, as the mesher's own
    polygon puts them; the fan covers the triangle and the sliver between the triangle edge and the polygon,
    which is what the face's triangles should have covered.
    """
    if not chains:
        return triangles
    directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, inverse, uses = unique_rows(undirected, return_inverse=True, return_counts=True)
    once = np.flatnonzero(uses[inverse.reshape(-1)] == 1)
    if not len(once):
        return triangles
    where: dict[int, list[tuple[int, int]]] = {}
    for c, chain in enumerate(chains):
        for position, node in enumerate(chain):
            where.setdefault(node, []).append((c, position))
    replaced: dict[int, list[list[int]]] = {}
    n = len(triangles)
    for slot in once.tolist():
        a, b = (int(x) for x in directed[slot])
        best: list[int] | None = None
        for c, pa in where.get(a, ()):
            for c2, pb in where.get(b, ()):
                if c2 != c or abs(pa - pb) < 2:
                    continue
                inner = chains[c][pa + 1:pb] if pa < pb else chains[c][pb + 1:pa][::-1]
                if best is None or len(inner) < len(best):
                    best = inner
        if best is None:
            continue
        t, corner = slot % n, slot // n                # the edge runs from corner `corner` to the next
        tri = triangles[t].tolist()
        third = tri[(corner + 2) % 3]
        if t in replaced:                              # a triangle with two such edges: leave it to the checks
            continue
        path = [a, *best, b]
        replaced[t] = [[path[i], path[i + 1], third] for i in range(len(path) - 1)]
    if not replaced:
        return triangles
    keep = np.ones(n, dtype=bool)
    keep[list(replaced)] = False
    fans = np.array([tri for fan in replaced.values() for tri in fan], dtype=triangles.dtype)
    return np.concatenate([triangles[keep], fans])


#: Further tessellations tried when the mesher leaves a closed B-rep's triangles open (each at
#: :data:`RETRY_DEFLECTION_FACTOR` times the previous angular deflection).
TESSELLATION_RETRIES = 2
RETRY_DEFLECTION_FACTOR = 0.7


def _open_edges(faces: np.ndarray) -> int:
    """Undirected edges of ``faces`` not used by exactly two triangles."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return int(np.count_nonzero(unique_rows(edges, return_counts=True)[1] != 2))


def _has_solid(shape: Any) -> bool:
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    return bool(TopExp_Explorer(shape, TopAbs_SOLID).More())


def tessellate_closed(shape: Any, *, chord: float, angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION,
                      max_faces: int | None = None) -> tuple[np.ndarray, np.ndarray, float, int]:
    """:func:`tessellate`, again at a finer angular deflection when the mesher left a solid's surface open.

    ``BRepMesh`` sometimes leaves a T-junction where two faces meet (a triangle of one face spans two segments
    of the shared edge: trimesh's ``featuretype``-like parts and fused solids show it), so a closed B-rep
    arrives as an open mesh and the mesh analysis refuses it.  When the shape has a solid and the triangles
    have open edges, the triangulation is cleared and the shape tessellated again at
    :data:`RETRY_DEFLECTION_FACTOR` × the angular deflection, at most :data:`TESSELLATION_RETRIES` times; the
    chord tolerance (which bounds the volume error) is unchanged.  Returns ``(vertices, faces, angular
    deflection used, open edges of the first tessellation)``; the last attempt is returned as it is if none
    is closed (the mesh analysis then says what is open).
    """
    vertices, faces = tessellate(shape, chord=chord, angular_deflection=angular_deflection, max_faces=max_faces)
    first = _open_edges(faces)
    if not first or not _has_solid(shape):
        return vertices, faces, angular_deflection, first
    from OCP.BRepTools import BRepTools
    used = angular_deflection
    for _ in range(TESSELLATION_RETRIES):
        used *= RETRY_DEFLECTION_FACTOR
        BRepTools.Clean_s(shape)
        vertices, faces = tessellate(shape, chord=chord, angular_deflection=used, max_faces=max_faces)
        if not _open_edges(faces):
            break
    return vertices, faces, used, first


def _cascadio_arrays(path: str, chord: float, angular_deflection: float) -> tuple[np.ndarray, np.ndarray]:
    import tempfile
    try:
        import cascadio
    except ImportError:
        raise _fail(path, "reading STEP needs OCP or cascadio (pip install cadquery-ocp-novtk, or cascadio)") from None
    if os.path.splitext(path)[1].lower() not in (".step", ".stp"):
        raise _fail(path, "reading IGES needs OCP (pip install cadquery-ocp-novtk); cascadio reads STEP only")
    from .read_trimesh import _read_with_trimesh
    with tempfile.TemporaryDirectory(prefix="inertia-tool-") as tmp:
        glb = os.path.join(tmp, "part.glb")
        with _quiet():   # cascadio's tolerance is in OpenCASCADE's working unit, mm; its GLB is in metres
            cascadio.step_to_glb(path, glb, tol_linear=chord * 1e3, tol_angular=angular_deflection,
                                 tol_relative=False)
        if not os.path.isfile(glb):
            raise _fail(path, "cascadio could not convert the file")
        vertices, faces, _ = _read_with_trimesh(glb, 1 << 62)
    return vertices, faces


def solids_fused(shape: Any) -> tuple[object, int, float, str]:
    """The union of the solids of ``shape`` (OpenCASCADE's boolean ``BRepAlgoAPI_Fuse``) when some may overlap.

    A STEP file of an assembly, or of a part exported as several bodies, holds solids that may overlap; the
    B-rep integrals of such a compound are the *sum* over the solids, counting shared volume twice.  The fused
    shape is the solid the user means.  Only solids whose bounding boxes meet are fused (each such group on
    its own): solids apart from every other one are exact as they are, and a file of thousands of separate
    bodies is not run through thousands of booleans.

    Returns
    -------
    shape : TopoDS_Shape
        The solids with each group of possibly overlapping ones fused, or ``shape`` itself (no two solids'
        boxes meet, or a fuse failed).
    solids : int
        Solids in the file.
    summed_volume : float
        Sum of the solids' volumes, m³ (their overlap is ``summed_volume`` minus the fused volume).
    fusion : str
        :data:`FUSIONS`: ``"one solid"`` (or none), ``"apart"`` (no two bounding boxes meet: nothing to fuse,
        the sum is the union), ``"fused"`` (the booleans ran and succeeded) or ``"failed"`` (a boolean failed:
        ``shape`` is returned as it was, and its integrals are the sum).
    """
    from OCP.Bnd import Bnd_Box
    from OCP.BRep import BRep_Builder
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Compound
    solids, boxes, summed = [], [], 0.0
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        solid = explorer.Current()
        solids.append(solid)
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(solid, props)
        summed += abs(props.Mass())
        box = Bnd_Box()
        BRepBndLib.Add_s(solid, box)
        # a void box (CornerMin() would raise) meets nothing
        void = (np.inf,) * 3 + (-np.inf,) * 3
        boxes.append(void if box.IsVoid() else box.CornerMin().Coord() + box.CornerMax().Coord())
        explorer.Next()
    groups = _meeting_groups(np.array(boxes, dtype=np.float64).reshape(-1, 6))
    if len(solids) < 2:
        return shape, len(solids), summed, "one solid"
    if all(len(group) < 2 for group in groups):
        return shape, len(solids), summed, "apart"
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for group in groups:
        union = solids[group[0]]
        for k in group[1:]:           # one at a time: the list types of the bindings differ between versions
            fuse = BRepAlgoAPI_Fuse(union, solids[k])
            if not fuse.IsDone() or fuse.Shape().IsNull():
                return shape, len(solids), summed, "failed"
            union = fuse.Shape()
        builder.Add(compound, union)
    return compound, len(solids), summed, "fused"


def _meeting_groups(boxes: np.ndarray) -> list[list[int]]:
    """Indices of solids grouped by chains of meeting bounding boxes ``(n, 6)`` (min xyz, max xyz)."""
    n = len(boxes)
    parent = list(range(n))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    order = np.argsort(boxes[:, 0], kind="stable")     # sweep along x: only boxes whose x-ranges meet are paired
    sorted_min_x = boxes[order, 0]
    for a_pos, a in enumerate(order):
        stop = int(np.searchsorted(sorted_min_x, boxes[a, 3], side="right"))
        others = order[a_pos + 1:stop]
        meet = np.all(boxes[others, :3] <= boxes[a, 3:], axis=1) & np.all(boxes[a, :3] <= boxes[others, 3:], axis=1)
        for b in others[meet]:
            parent[root(int(a))] = root(int(b))
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(root(i), []).append(i)
    return [sorted(g) for g in groups.values()]


def brep_integrals(shape: Any) -> tuple[float, np.ndarray, np.ndarray, float]:
    """Unit-density ``(volume m³, centre of mass (3,) m, inertia (3, 3) m⁵ about it, surface area m²)`` of
    the B-rep (``BRepGProp``: Gauss integration on its faces; tensor convention, ``Ixy = −∫xy dV``)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    matrix = props.MatrixOfInertia()
    tensor = np.array([[matrix.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)])
    area = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, area)
    return (float(props.Mass()), np.array(props.CentreOfMass().Coord(), dtype=np.float64), 0.5 * (tensor + tensor.T),
            float(area.Mass()))


@frozen_value
class CadReading:
    """What the isolated OpenCASCADE run gives back for one STEP/IGES file.

    Attributes
    ----------
    vertices : (n, 3) float
        Tessellation, m.
    faces : (m, 3) int
        Outward triangles.
    chord : float
        Chord tolerance used, m.
    backend : str
        ``"OCP"`` or ``"cascadio"``.
    integrals : tuple or None
        OCP only: :func:`brep_integrals` of the (fused) solid.
    solids : int
        Solids in the file (OCP only; 0 with cascadio).
    summed_volume : float
        Sum of the solids' volumes, m³ (:func:`solids_fused`).
    fusion : str
        How several solids became one (:func:`solids_fused`; the tessellation and ``integrals`` are of the
        result).
    parts : tuple of (name, material or None, density kg/m³ or None, first face, stop face)
        A STEP assembly of several parts, some with a material (:func:`step_parts`): each part tessellated on its
        own, its face range of ``faces``; the solids are then not fused and ``integrals`` is None (each part has
        its own material).
    angular_deflection : float
        Angular deflection of the tessellation returned, rad (finer than asked when the first was open:
        :func:`tessellate_closed`; the finest of an assembly's parts).
    first_open_edges : int
        Open edges the mesher left in the first tessellation (0: closed at the angular deflection asked).
    """

    vertices: np.ndarray
    faces: np.ndarray
    chord: float
    backend: str
    integrals: tuple[float, np.ndarray, np.ndarray, float] | None = None
    solids: int = 0
    summed_volume: float = 0.0
    fusion: str = "one solid"
    parts: tuple[tuple[str, str | None, float | None, int, int], ...] = ()
    angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION
    first_open_edges: int = 0


def _read_here(path: str, chord: float | None, angular_deflection: float, use_ocp: bool,
               max_faces: int | None = None) -> dict[str, Any]:
    """Read, fuse, tessellate and integrate in this process: run only in the isolated child
    (:func:`read_cad`); returns plain values (:func:`inertia_tool.isolate.run_isolated`)."""
    if use_ocp and os.path.splitext(path)[1].lower() in (".step", ".stp"):
        # parts of different materials are integrated apart; without materials the solids are fused and the
        # exact B-rep of their union is the answer, as for any STEP file
        found = step_parts(path)
        if len(found) > 1 and any(material is not None for _, material, _, _ in found):
            return _assembly_here(path, found, chord, angular_deflection, max_faces)
    if use_ocp:
        shape, solids, summed, fusion = solids_fused(read_brep(path))
        try:
            tol = chord_tolerance(shape, chord)
        except InvalidMeshError as exc:     # a shape without a bounding box: name the file
            raise _fail(path, str(exc)) from None
        vertices, faces, used, first_open = tessellate_closed(shape, chord=tol, angular_deflection=angular_deflection,
                                                              max_faces=max_faces)
        return {"vertices": vertices, "faces": faces, "chord": tol, "backend": "OCP", "angular_deflection": used,
                "first_open_edges": first_open,
                "integrals": brep_integrals(shape), "solids": solids, "summed_volume": summed, "fusion": fusion}
    if chord is None:
        v, _ = _cascadio_arrays(path, 1e-3, 0.5)
        chord = DEFAULT_CHORD_RTOL * float(np.linalg.norm(np.ptp(v, axis=0)))
    vertices, faces = _cascadio_arrays(path, chord, angular_deflection)
    return {"vertices": vertices, "faces": faces, "chord": float(chord), "backend": "cascadio"}


def _assembly_here(path: str, found: list[tuple[str, str | None, float | None, Any]], chord: float | None,
                   angular_deflection: float, max_faces: int | None) -> dict[str, Any]:
    """Tessellate each part of a STEP assembly on its own (one chord tolerance for all, from the whole)."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for *_, shape in found:
        builder.Add(compound, shape)
    try:
        tol = chord_tolerance(compound, chord)
    except InvalidMeshError as exc:
        raise _fail(path, str(exc)) from None
    vertices, faces, parts, offset, start, finest, first_open = [], [], [], 0, 0, angular_deflection, 0
    for name, material, density, shape in found:
        try:
            v, f, used, opened = tessellate_closed(shape, chord=tol, angular_deflection=angular_deflection,
                                                   max_faces=None if max_faces is None else max_faces - start)
            finest, first_open = min(finest, used), first_open + opened
        except UsageError as exc:
            raise _fail(path, f"part {name!r}: {exc}") from None
        vertices.append(v)
        faces.append(f + offset)
        parts.append((name, material, density, start, start + len(f)))
        offset += len(v)
        start += len(f)
    return {"vertices": np.vstack(vertices), "faces": np.vstack(faces), "chord": tol, "backend": "OCP",
            "angular_deflection": finest, "first_open_edges": first_open, "integrals": None, "solids": len(found),
            "summed_volume": 0.0, "fusion": "apart", "parts": parts}


#: The last reading, keyed by the file's identity and the tolerances: ``analyze`` reads a STEP file as a mesh
#: and then compares it with its B-rep, one child process for both.
_LAST: list[tuple[tuple[object, ...], CadReading]] = []


def read_cad(path: str | os.PathLike[str], *, chord: float | None = None,
             angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION, limits: Limits | None = None,
             max_faces: int | None = None) -> CadReading:
    """Read, fuse (:func:`solids_fused`), tessellate and integrate a STEP/IGES file in a child process.

    OpenCASCADE can crash on a malformed file (a segmentation fault) or spend minutes and gigabytes on a big
    one, so it runs under :func:`inertia_tool.isolate.run_isolated` with ``limits`` (default
    :data:`~inertia_tool.isolate.CAD_LIMITS`; the ``INERTIA_TOOL_*_LIMIT`` environment variables override).

    ``max_faces`` refuses a tessellation of more triangles in the child, before they are copied out.

    Raises
    ------
    MeshReadError
        Unreadable file, more than ``max_faces`` triangles, or the child crashed or hit a limit (the message
        says which).
    """
    from ..errors import IsolatedProcessError
    from ..isolate import CAD_LIMITS, run_isolated
    path = os.fsdecode(os.fspath(path))
    if not os.path.isfile(path):
        raise _fail(path, "no such file" if not os.path.exists(path) else "is not a regular file")
    stat = os.stat(path)
    use_ocp = has_ocp()
    key = (os.path.realpath(path), stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns, chord,
           float(angular_deflection), use_ocp)
    if _LAST and _LAST[0][0] == key and (max_faces is None or len(_LAST[0][1].faces) <= max_faces):
        return _LAST[0][1]
    try:
        out = run_isolated(_read_here, path, chord, float(angular_deflection), use_ocp, max_faces,
                           limits=limits or CAD_LIMITS, what="OpenCASCADE")
    except IsolatedProcessError as exc:
        raise _fail(path, str(exc)) from None
    except UsageError as exc:              # "the shape has no faces": a property of the file
        raise _fail(path, str(exc)) from None
    reading = CadReading(vertices=np.asarray(out["vertices"], dtype=np.float64),
                         faces=np.asarray(out["faces"], dtype=np.int64), chord=float(out["chord"]),
                         backend=str(out["backend"]), integrals=out.get("integrals"),
                         solids=int(out.get("solids", 0)), summed_volume=float(out.get("summed_volume", 0.0)),
                         fusion=str(out.get("fusion", "one solid")),
                         angular_deflection=float(out.get("angular_deflection", angular_deflection)),
                         first_open_edges=int(out.get("first_open_edges", 0)),
                         parts=tuple((str(n), None if m is None else str(m), None if d is None else float(d), int(a),
                                      int(b)) for n, m, d, a, b in out.get("parts", ())))
    _LAST[:] = [(key, reading)]
    return reading


def tessellated_arrays(path: str | os.PathLike[str], *, chord: float | None = None,
                       angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION,
                       max_faces: int | None = None) -> tuple[np.ndarray, np.ndarray, float, str]:
    """``(vertices m, faces, chord m, backend)`` of a STEP/IGES file: OCP if installed, else cascadio.

    Read in a child process with limits (:func:`read_cad`); several solids are fused into one.  Without
    ``chord`` and with cascadio, the default tolerance is relative to the file's size as cascadio reports it
    after a first coarse conversion.
    """
    reading = read_cad(path, chord=chord, angular_deflection=angular_deflection, max_faces=max_faces)
    return reading.vertices, reading.faces, reading.chord, reading.backend
