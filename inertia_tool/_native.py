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
on the thread count: only the speed does.  So do the radix-partition weld of large float32 streams and the
census with the shell labels (``census_shells``); the one-table weld runs on one thread.

Both settings are asked for on every call (a test or a pool worker may change them), a dozen times per part of
a batch: each call looks the variable up in the process environment's own table and derives the answer again
only when the raw value changed since the last call (``os.environ.get`` cost ~2 µs a call, mostly the
``KeyError`` of an unset variable; ``os.sched_getaffinity`` ~1.5 µs, read once per process).
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

_UNSET = object()


class _Setting:
    """One environment variable read cheaply on every call: the raw value is looked up in ``os.environ``'s
    table of encoded names (a dict lookup, no exception when unset) and compared with the last one seen; the
    decoded text is returned again unless it changed.  Where ``os.environ`` keeps no such table (not CPython),
    ``os.environ.get`` is asked each time."""

    def __init__(self, name: str) -> None:
        self.name = name
        encode = getattr(os.environ, "encodekey", None)
        self.key = encode(name) if callable(encode) else None
        self.raw: object = _UNSET
        self.text = ""

    def get(self) -> str:
        """The variable's value, ``""`` when unset."""
        data = getattr(os.environ, "_data", None)
        if self.key is None or not isinstance(data, dict):
            return os.environ.get(self.name, "")
        raw = data.get(self.key)
        if raw is not self.raw:
            self.text = os.environ.get(self.name, "")
            self.raw = raw
        return self.text


_NO_ACCEL = _Setting(NO_ACCEL_ENV)
_THREADS = _Setting(THREADS_ENV)
#: ``[INERTIA_TOOL_THREADS as last read, threads()]``: the CPUs are read once per process (a forked child, whose
#: affinity may differ, starts without it)
_THREADS_MEMO: list = []
if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_THREADS_MEMO.clear)


def accel() -> ModuleType | None:
    """The ``inertia_tool._accel`` module, or None when it is not built or ``INERTIA_TOOL_NO_ACCEL`` is set."""
    if _NO_ACCEL.get().strip() not in ("", "0"):
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
    raw = _THREADS.get()
    if _THREADS_MEMO and _THREADS_MEMO[0] is raw:
        return int(_THREADS_MEMO[1])
    text = raw.strip()
    if text.isascii() and text.isdigit() and int(text) >= 1:  # isdigit() alone accepts '²', which int() refuses
        n = min(int(text), MAX_THREADS)
    else:
        try:
            n = len(os.sched_getaffinity(0))
        except (AttributeError, OSError):
            n = os.cpu_count() or 1
        n = max(1, min(n, MAX_THREADS))
    _THREADS_MEMO[:] = [raw, n]
    return n


def faces_for_c(faces) -> np.ndarray:
    """Faces as a C-contiguous, native-order (m, 3) int32 or int64 array (what the C kernels accept)."""
    f = np.asarray(faces)
    if f.dtype not in (np.dtype(np.int32), np.dtype(np.int64)):
        f = f.astype(np.int64)
    return np.ascontiguousarray(f)


def label_dtype(n_faces: int) -> np.dtype:
    """The integer type of per-face shell labels: int32 while the faces fit it (labels are below ``n_faces``),
    else int64 (issue 25: the labels live through the face-pair check; 4 bytes a face instead of 8)."""
    return np.dtype(np.int32) if n_faces < 2**31 else np.dtype(np.int64)


def labels_for_c(labels) -> np.ndarray:
    """Labels as a C-contiguous, native-order (m,) int32 or int64 array, the array itself when it is one already
    (the C kernels read either width; no widening copy)."""
    lab = np.asarray(labels)
    if lab.dtype not in (np.dtype(np.int32), np.dtype(np.int64)):
        lab = lab.astype(np.int64)
    return np.ascontiguousarray(lab)
