"""The boundary to the optional C extension ``inertia_tool._accel``.

The engine's hot loops (exact welding, the edge census, shell labels, the tetrahedron sums, the face-pair
check, the float32 storage bound, the splitting integrator's steps) have two implementations: C kernels in
``_accel.c`` (built by ``pip install`` when a C compiler is present) and the pure-numpy (or pure-Python) code
of ``weld``, ``checks``, ``volume``, ``intersect``, ``precision`` and ``dynamics.splitting``, which is the
reference and the fallback.  Each of those
modules asks :func:`accel` at call time which one to run.  Set the environment variable
``INERTIA_TOOL_NO_ACCEL=1`` to force the numpy path (results are identical, or equal to round-off for the
integrals, which the C kernel sums with compensation).

The edge census, the integrals and the bounding box use :func:`threads` threads on large meshes (the cores
this process may run on, at most 16, or ``INERTIA_TOOL_THREADS``), split so that their results do not depend
on the thread count: only the speed does.  The weld and the shell labels run on one thread.
"""

from __future__ import annotations

import os
import warnings
import zlib
from types import ModuleType

import numpy as np

__all__ = ["accel", "faces_for_c", "threads"]

#: Environment variable that, set to anything but "" or "0", forces the pure-numpy path.
NO_ACCEL_ENV = "INERTIA_TOOL_NO_ACCEL"

#: Environment variable: the number of threads the C kernels may use (an integer >= 1).
THREADS_ENV = "INERTIA_TOOL_THREADS"

#: The most threads a kernel uses (MAX_THREADS in _accel.c).
MAX_THREADS = 16

_MODULE: list[ModuleType | None] = []   # the import result, cached: [module or None]


def accel() -> ModuleType | None:
    """The ``inertia_tool._accel`` module, or None when it is not built or ``INERTIA_TOOL_NO_ACCEL`` is set."""
    if os.environ.get(NO_ACCEL_ENV, "").strip() not in ("", "0"):
        return None
    if not _MODULE:
        try:
            from . import _accel
        except ImportError:
            _accel = None
        if _accel is not None and not _matches_source(_accel):
            warnings.warn("inertia_tool._accel was built from another _accel.c than the one beside it (a source "
                          "checkout updated without a rebuild; rebuild with `pip install -e .`): the C kernels are "
                          "set aside and the pure-numpy path is used (the same results, slower)", RuntimeWarning,
                          stacklevel=2)
            _accel = None
        _MODULE.append(_accel)
    return _MODULE[0]


def _source_crc() -> int | None:
    """CRC-32 of the ``_accel.c`` beside this package (a source checkout), None where it is not installed."""
    try:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "_accel.c"), "rb") as f:
            return zlib.crc32(f.read())
    except OSError:
        return None


def _matches_source(module: ModuleType) -> bool:
    """False only when both the build's ``SOURCE_CRC`` and the source beside it are known and differ."""
    built = getattr(module, "SOURCE_CRC", None)
    if built is None:
        return True
    source = _source_crc()
    return source is None or int(built) == source


def threads() -> int:
    """Threads for the C kernels: ``INERTIA_TOOL_THREADS`` if set to an integer >= 1, else the CPUs this process
    may run on; at most 16.  A malformed value counts as unset."""
    raw = os.environ.get(THREADS_ENV, "").strip()
    if raw.isascii() and raw.isdigit() and int(raw) >= 1:     # isdigit() alone accepts '²', which int() refuses
        return min(int(raw), MAX_THREADS)
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    return max(1, min(n, MAX_THREADS))


def faces_for_c(faces) -> np.ndarray:
    """Faces as a C-contiguous, native-order (m, 3) int32 or int64 array (what the C kernels accept)."""
    f = np.asarray(faces)
    if f.dtype not in (np.dtype(np.int32), np.dtype(np.int64)):
        f = f.astype(np.int64)
    return np.ascontiguousarray(f)
