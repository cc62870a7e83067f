"""The first stage of preparing a mesh: from the triangles read to a closed surface (or a bounded estimate).

Refuses a mesh with no triangles, only degenerate ones, no extent, or coordinates beyond float64's safe range;
leaves out degenerate triangles and a shell listed twice with the same vertex indices (R0); and hands a surface
that is not a closed, consistently wound 2-manifold to :func:`~.resolve.resolve_surface` (clean meshes skip it).
"""

from __future__ import annotations

import math
import warnings
from typing import NamedTuple

import numpy as np

from ..errors import DegenerateFacesWarning, InvalidMeshError, MeshRepairedWarning, MeshResolvedWarning
from ..integrals import bounding_box, volume_moments
from .checks import census_and_shells, repeated_corner_faces
from .hole_assumptions import NOTHING_ASSUMED, UserAssumptions
from .read import RawMesh
from .resolve import Resolution, resolve_surface
from .shells import leave_out_coincident

__all__ = ["ClosedSurface", "close_surface", "MAX_COORDINATE", "MIN_EXTENT"]

#: Largest |coordinate| (m) accepted: the second moments grow like L⁵ and must stay far from float64
#: overflow (1.8e308) for any density; 1e30 m is already beyond the observable universe.
MAX_COORDINATE = 1e30


#: Smallest bounding-box diagonal (m) accepted: below it L⁵ approaches float64 underflow.
MIN_EXTENT = 1e-30


class ClosedSurface(NamedTuple):
    """What :func:`close_surface` made of a raw mesh.

    Attributes
    ----------
    vertices : (n, 3) float
        m: the vertices read (the same array) unless the surface had to be resolved.
    faces : (m, 3) int
        The closed surface (a patched one when ``found`` holds a patched estimate).
    found : Resolution
        How the surface was read: ``"exact"`` with no notes when the mesh was clean.  Holds an estimate when only
        one could be given (``repair``).
    lo, hi : (3,) float
        m, the bounding box of the mesh as read.
    diag : float
        m, its diagonal.
    degenerate : int
        Triangles left out for a repeated corner.
    watertight : bool
        The surface (after R0) was a closed, consistently wound 2-manifold as read.
    census : (labels, n_shells) or None
        The shell of each face of ``found.faces`` from the edge census, when the faces are the census's.
    coincident : tuple of str
        R0's note (a shell listed twice with the same vertex indices), warned.
    repeated : (keys, counts) or None
        The faces R0 kept in place of their repeats and how many times each counts
        (:func:`~.shells.leave_out_coincident`).
    """

    vertices: np.ndarray
    faces: np.ndarray
    found: Resolution
    lo: np.ndarray
    hi: np.ndarray
    diag: float
    degenerate: int
    watertight: bool
    census: tuple[np.ndarray, int] | None
    coincident: tuple[str, ...]
    repeated: tuple[np.ndarray, np.ndarray] | None = None


def check_magnitude(lo: np.ndarray, hi: np.ndarray, source: str) -> None:
    """Refuse coordinates (bounding box ``lo``, ``hi``) whose volume integrals (∝ L⁵) would overflow or underflow
    float64."""
    corners = lo.tolist() + hi.tolist()
    top = max(abs(x) for x in corners)                     # = max |coordinate|
    if any(x != x for x in corners):                       # NaN propagates, as numpy's max would
        top = math.nan
    if not top <= MAX_COORDINATE:
        raise InvalidMeshError(f"{source}: coordinates reach {top:.3g} m, beyond the ±{MAX_COORDINATE:g} m the "
                               "volume integrals can hold without overflow (check the length `units`)")
    span = [b - a for a, b in zip(corners[:3], corners[3:])]
    diag = math.hypot(math.hypot(span[0], span[1]), span[2])      # no underflow in the squares
    if 0 < diag < MIN_EXTENT:
        raise InvalidMeshError(f"{source}: the mesh spans only {diag:.3g} m, below the {MIN_EXTENT:g} m the "
                               "volume integrals can hold without underflow (check the length `units`)")


def close_surface(raw: RawMesh, *, repair: bool, merge_tolerance: float,
                  assume: UserAssumptions = NOTHING_ASSUMED) -> ClosedSurface:
    """The surface :func:`~.prepare.prepare_mesh` goes on with (``repair``, ``merge_tolerance`` and ``assume`` as
    there).

    Raises
    ------
    InvalidMeshError
        No triangles, only degenerate ones, no extent, beyond float64's safe range, a closed surface listed with
        its exact inverted copy, or not a solid (and ``repair`` is off).
    """
    source = raw.source
    v, f = raw.vertices, raw.faces
    if len(f) == 0:
        raise InvalidMeshError(f"{source}: the mesh has no triangles")
    lo, hi = bounding_box(v)          # of the mesh as read: reused later while the vertices are these
    check_magnitude(lo, hi, source)
    repeated = repeated_corner_faces(f)
    n_repeated = int(np.count_nonzero(repeated))
    if n_repeated == len(f):
        raise InvalidMeshError(f"{source}: all {len(f):,} triangles are degenerate (no area); nothing to integrate")
    if n_repeated:
        f = f[~repeated]
        warnings.warn(DegenerateFacesWarning(f"{source}: {n_repeated:,} degenerate triangles (a repeated corner) "
                                             "were ignored"), stacklevel=4)
    del repeated                      # (m,) bool: not held through the census, the analysis's high point
    diag = float(np.linalg.norm(hi - lo))
    if not diag > 0:
        raise InvalidMeshError(f"{source}: all vertices coincide; the mesh has no extent")
    topo, census_labels, census_shells = census_and_shells(f, len(v), v)   # R1's shells from the same adjacency
    coincident: tuple[str, ...] = ()
    twice = None
    if topo.nonmanifold_edges:                # R0: a shell listed twice with the same vertex indices
        f, note, twice = leave_out_coincident(v, f, None, source)
        if note is not None:
            coincident = (note,)
            topo, census_labels, census_shells = census_and_shells(f, len(v), v)
    found = Resolution(v, f, "exact", (), 0, None, 0)
    if not topo.oriented:                     # clean meshes skip all of this
        found = resolve_surface(v, f, diag=diag, source=source, repair=repair, merge_tolerance=merge_tolerance,
                                moments=volume_moments, assume=assume)
        v, f = found.vertices, found.faces
        if found.method != "exact" or found.notes:
            warning = MeshRepairedWarning if found.estimate is not None else MeshResolvedWarning
            # the stage's own method: "exact" here says only that the surface was closed as read (the answer's
            # certificate, which later stages may make "united", is stated apart), so it is not printed as "exact"
            what = (f"repaired ({found.method}, an estimate)" if found.estimate is not None
                    else "closed as read" if found.method == "exact" else found.method)
            warnings.warn(warning(f"{source}: {what}: {'; '.join(found.notes)}"), stacklevel=4)
    census = (census_labels, census_shells) if topo.oriented else None     # the faces are the census's: unchanged
    return ClosedSurface(v, f, found, lo, hi, diag, n_repeated, topo.oriented, census, coincident, twice)
