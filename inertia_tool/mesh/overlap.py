"""The volume two closed parts share, by a robust boolean intersection (manifold3d, float64).

Used for the parts of an assembly: parts that only touch (an insert in its pocket, coincident faces) share a
sliver at round-off; parts that overlap share real volume, which a sum of the parts counts twice.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["shared_volumes"]


def _boxes_meet(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.all(a.min(axis=0) <= b.max(axis=0)) and np.all(b.min(axis=0) <= a.max(axis=0)))


def shared_volumes(parts: Sequence[tuple[np.ndarray, np.ndarray]]) -> dict[tuple[int, int], float] | None:
    """The volume (m³, in the vertices' unit cubed) each pair of parts shares, for the pairs whose bounding boxes
    meet; None when a part is not a closed, consistently wound 2-manifold the boolean accepts (the caller falls
    back to a test that does not measure).

    Parameters
    ----------
    parts : sequence of (vertices (n, 3) float, faces (m, 3) int)
        Each part outward-wound, as integrated.
    """
    try:
        import manifold3d as m3
    except ImportError:                       # pragma: no cover - a runtime dependency
        return None
    from .union import UnionError, _manifold
    if not parts:
        return {}
    everything = np.vstack([np.asarray(v, dtype=np.float64) for v, _ in parts])
    centre = 0.5 * (everything.min(axis=0) + everything.max(axis=0))     # the boolean works near the origin
    solids: dict[int, object] = {}
    out: dict[tuple[int, int], float] = {}
    for i in range(len(parts)):
        for j in range(i + 1, len(parts)):
            if not _boxes_meet(np.asarray(parts[i][0]), np.asarray(parts[j][0])):
                continue
            try:
                for k in (i, j):
                    if k not in solids:
                        solids[k] = _manifold(m3, np.asarray(parts[k][0], dtype=np.float64) - centre,
                                              np.asarray(parts[k][1], dtype=np.int64))
            except UnionError:
                return None
            out[(i, j)] = float((solids[i] ^ solids[j]).volume())       # type: ignore[operator]
    return out
