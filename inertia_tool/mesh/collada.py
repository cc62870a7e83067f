"""The triangles of a COLLADA (``.dae``) document, placed by its scene's node transforms, without trimesh.

pycollada parses the document (its ``<float_array>`` text as float32, ``<polylist>`` and ``<polygons>`` cut
into fans by :meth:`collada.polylist.Polylist.triangleset`); this module walks the visual scene's nodes as
trimesh's COLLADA loader does (``trimesh.exchange.dae``, trimesh 4-5) and bakes each instance as
``trimesh.Scene.dump`` does, so the vertices and faces are the ones the reader received through trimesh, bit for
bit (``tests/test_robot_collada_reader.py`` compares them on every COLLADA file at hand), for a fraction of the
cost: importing trimesh imports scipy.spatial, networkx and more (about 2.5 s of CPU; issue 23, item 4: UR5e's
visual meshes), and trimesh builds a material, with textures, for every primitive.

What is kept of trimesh's rules, each for the same result:

* every ``<triangles>``, ``<polylist>`` and ``<polygons>`` of every ``<instance_geometry>`` reached from the
  scene's root nodes (through ``<node>`` children and ``<instance_node>``), in document order; lines and
  primitives without a ``VERTEX`` input are skipped;
* per primitive, trimesh's vertex merge (:func:`_merged`: corners whose position rounded at 1e-8, normal at
  1e-2 and, where the material is bound, texture coordinate at 1e-4 agree are one vertex);
* the node matrices multiplied from the root (``parent @ node.matrix``), a rotation part orthogonal only to
  float32 precision replaced by the nearest rotation (:func:`_rigid_repaired`, trimesh's scene graph);
* an instance whose matrix is the identity within 1e-8 keeps its float32 coordinates as stored; otherwise the
  points become ``(M [x y z 1]ᵀ)ᵀ`` in float64, and a mirror (negative determinant) reverses the faces
  (``i j k`` → ``k j i``), so that the surface keeps its outward winding;
* the document's ``<unit meter>``: metres when absent or close to 1 (``numpy.isclose``), else the factor
  through trimesh's table (metres per inch), which the reader then snaps to a named unit.
"""

from __future__ import annotations

from typing import IO, Any, NamedTuple

import numpy as np

__all__ = ["ColladaTriangles", "collada_triangles"]

#: Inches per metre in trimesh's unit table (``resources/units_to_inches.json``): a declared unit goes through
#: it (to inches and back) in trimesh, and the same arithmetic here gives the same float.
_INCHES_PER_METRE = 39.37007874015748


class ColladaTriangles(NamedTuple):
    """The placed triangles of a COLLADA document.

    Attributes
    ----------
    vertices : (3m, 3) float64
        File units; one vertex per triangle corner.
    faces : (m, 3) int64
    instances : int
        Primitive instances read (0: the document holds no triangle of a visual scene).
    declared : (float, str) or None
        Metres per file unit and its name as trimesh spells it (``"meters"`` or ``"0.001 * meters"``); None
        without instances.
    rounding : float
        float32 rounding of the placed coordinates (file units): that of the largest stored coordinate times
        the largest row sum of any instance's matrix (at least 1).
    """

    vertices: np.ndarray
    faces: np.ndarray
    instances: int
    declared: tuple[float, str] | None
    rounding: float


def _is_identity(matrix: np.ndarray) -> bool:
    """trimesh's test for an identity placement: the spread (max − min) of ``M − I`` below 1e-8."""
    return bool(float(np.ptp(matrix - np.eye(4))) < 1e-8)


def _rigid_repaired(matrix: np.ndarray) -> np.ndarray:
    """trimesh's scene graph's ``fix_rigid`` (tolerance 1e-5): a matrix whose rotation part is orthogonal to
    within 1e-5 but not 1e-13 (``max |R Rᵀ − I|``) gets the nearest rotation ``U Vᵀ`` of its SVD, translation
    kept; COLLADA stores node matrices in float32, so a rotation read from a file is nearly always such."""
    rotation = matrix[:3, :3]
    check = float(np.abs(np.dot(rotation, rotation.T) - np.eye(3)).max())
    if not (1e-13 < check < 1e-5):
        return matrix
    u, _, vt = np.linalg.svd(rotation)
    repaired = np.eye(4)
    repaired[:3, :3] = np.dot(u, vt)
    repaired[:3, 3] = matrix[:3, 3]
    if not np.allclose(repaired, matrix, atol=1e-5):
        raise ValueError("a node matrix is nearly but not quite a rotation")     # trimesh's assertion
    return repaired


def _placed(vertices: np.ndarray, faces: np.ndarray, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``vertices`` (float64) and ``faces`` of one instance moved by ``matrix`` (4, 4), as ``Trimesh.
    apply_transform`` moves them."""
    if _is_identity(matrix) or np.abs(matrix - np.eye(4)).max() < 1e-8:
        return vertices, faces
    stack = np.column_stack((vertices, np.ones(len(vertices))))
    moved = np.dot(matrix, stack.T).T[:, :3]
    rotates = not bool(float(np.ptp(matrix[:3, :3] - np.eye(3))) < 1e-6)
    if rotates and np.linalg.det(matrix[:3, :3]) < 0.0:
        faces = np.ascontiguousarray(np.fliplr(faces))
    return moved, faces


def _corners(primitive: Any, bound: bool) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """(3k, 3) float64 corner positions of a triangle set, its corner texture coordinates (when its material is
    bound in the node: trimesh then keys on them) and corner normals, each None when absent."""
    index = primitive.vertex_index
    corners = np.asarray(primitive.vertex[index].reshape(len(index) * 3, 3), dtype=np.float64)
    normals = None
    if primitive.normal is not None:
        normals = np.asarray(primitive.normal[primitive.normal_index].reshape(len(primitive.normal_index) * 3, 3),
                             dtype=np.float64)
    uv = None
    if bound and len(primitive.texcoordset) > 0:
        which = primitive.texcoord_indexset[0]
        uv = np.asarray(primitive.texcoordset[0][which].reshape((len(which) * 3, 2)), dtype=np.float64)
    return corners, uv, normals


#: Odd 64-bit multipliers (SplitMix64's and MurmurHash3's constants) that mix a row of keys into one word.
_ROW_MIX = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0xD6E8FEB86659FD93,
                     0xFF51AFD7ED558CCD, 0xC4CEB9FE1A85EC53, 0x94D049BB133111EB, 0xBF58476D1CE4E5B9], dtype=np.uint64)


def _equal_rows(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The groups of equal rows of ``keys`` ((k, c) int64, ``c ≤ 8``) as ``np.unique(keys, axis=0,
    return_index=True, return_inverse=True)`` gives them, up to the order of the groups: ``(first, inverse)``,
    ``first[g]`` the smallest index of group ``g``'s rows and ``inverse[i]`` the group of row ``i``.

    Each row is mixed into one word (``Σ keyⱼ·Mⱼ`` modulo 2⁶⁴) and the words sorted stably, so that equal rows
    are runs of equal words with their smallest index first; every pair of neighbours with equal words is
    compared whole, and when two different rows share a word (a collision) None is returned and the caller sorts
    the rows themselves.  ``np.unique`` on rows sorts them as raw bytes (3 times slower on the UR5e's COLLADA
    corners: 0.55 → 0.19 s of CPU for 365k corners).
    """
    count, width = keys.shape
    if count == 0 or width > len(_ROW_MIX):
        return None
    words = (np.ascontiguousarray(keys).view(np.uint64) * _ROW_MIX[:width]).sum(axis=1, dtype=np.uint64)
    order = np.argsort(words, kind="stable")
    sorted_words = words[order]
    same = sorted_words[1:] == sorted_words[:-1]
    rows = keys[order]
    if np.any(same & np.any(rows[1:] != rows[:-1], axis=1)):
        return None                                    # a collision: two different rows, one word
    start = np.concatenate(([True], ~same))
    inverse = np.empty(count, dtype=np.int64)
    inverse[order] = np.cumsum(start) - 1
    return order[start], inverse


def _merged(corners: np.ndarray, uv: np.ndarray | None, normals: np.ndarray | None
            ) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)`` of one primitive's corners after trimesh's ``merge_vertices`` (run when trimesh
    builds each geometry): corners whose rounded keys agree — position × 10⁸, and, when present, texture
    coordinates × 10⁴ (only where as many as the corners) and normals × 10² — are one vertex, the first of each
    group in corner order; faces ``0 1 2, 3 4 5, …`` renumbered."""
    stacked = [corners * (10 ** 8)]
    if uv is not None and len(uv) == len(corners):
        stacked.append(uv * (10 ** 4))
    if normals is not None and normals.shape == corners.shape:
        stacked.append(normals * (10 ** 2))
    keys = np.column_stack(stacked).round().astype(np.int64)
    found = _equal_rows(keys)
    if found is None:
        _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    else:
        first, inverse = found
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    faces = rank[inverse.reshape(-1)].reshape(-1, 3)
    return corners[first[order]], faces


def _walk(node: Any, parent: np.ndarray, out: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> None:
    """Every primitive below ``node`` as (vertices (n, 3) float64 as stored, faces, the matrix from the root),
    appended to ``out`` in document order (bounded by the document: pycollada refuses cyclic instance
    references)."""
    import collada
    if isinstance(node, collada.scene.GeometryNode):
        symbols = {m.symbol for m in node.materials}
        for primitive in node.geometry.primitives:
            if isinstance(primitive, collada.polylist.Polylist):
                primitive = primitive.triangleset()
            if not isinstance(primitive, collada.triangleset.TriangleSet) or primitive.vertex is None:
                continue
            vertices, faces = _merged(*_corners(primitive, primitive.material in symbols))
            out.append((vertices, faces, parent))
    elif isinstance(node, collada.scene.Node) and node.children is not None:
        for child in node.children:
            _walk(child, np.dot(parent, node.matrix), out)


def collada_triangles(file_obj: IO[bytes]) -> ColladaTriangles:
    """The placed triangles of the COLLADA document in ``file_obj`` (see the module notes).

    Raises whatever pycollada raises for a document it cannot read at all (the caller names the file); broken
    references and unsupported elements are skipped as trimesh skips them.
    """
    import collada
    errors = collada.common
    ignore = [errors.DaeError, errors.DaeIncompleteError, errors.DaeMalformedError, errors.DaeBrokenRefError,
              errors.DaeUnsupportedError]
    document = collada.Collada(file_obj, ignore=ignore)
    pieces: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    if document.scene is not None:
        for node in document.scene.nodes:
            _walk(node, np.eye(4), pieces)
    if not pieces:
        return ColladaTriangles(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), 0, None, 0.0)
    from .precision import float32_rounding
    vertices, faces, offset = [], [], 0
    delta, norm = 0.0, 1.0
    for stored, own, matrix in pieces:
        matrix = _rigid_repaired(np.asarray(matrix, dtype=np.float64))
        if stored.size:
            delta = max(delta, float32_rounding(float(np.max(np.abs(stored)))))
        norm = max(norm, float(np.abs(np.asarray(matrix)[:3, :3]).sum(axis=1).max()))
        moved, own = _placed(stored, own, matrix)
        vertices.append(moved)
        faces.append(own + offset)
        offset += len(moved)
    unit = document.assetInfo.unitmeter
    if unit is None or np.isclose(unit, 1.0):
        declared = (1.0, "meters")
    else:
        declared = (_INCHES_PER_METRE * float(repr(float(unit))) / _INCHES_PER_METRE, f"{unit} * meters")
    return ColladaTriangles(np.vstack(vertices), np.vstack(faces), len(pieces), declared, delta * norm)
