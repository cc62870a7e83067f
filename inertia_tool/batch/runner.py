"""Batch analysis of many meshes: the per-file work, the result-row schema and the runner.

One row per file, flat so that JSONL and CSV carry the same columns (:data:`ROW_FIELDS`, each in a fixed SI
unit; their JSON Schema is the ``batch_row`` of ``inertia_tool/schema/output-v1.json``).  The work for one
file (:func:`analyze_file`) and for a chunk of files (:func:`analyze_chunk`, the task the workers run; how
chunks are sized and fed to a process pool or a Dask cluster is :mod:`inertia_tool.batch.chunks`) is pure and
picklable; it never raises: an :class:`~inertia_tool.errors.InertiaToolError` becomes a row with
``status="error"`` and any other exception a row with ``status="internal_error"`` (the batch goes on).

Resuming: every row carries the SHA-256 of the file's bytes and a key of the options that change the numbers
(:meth:`BatchOptions.key`).  A file counts as done when a previous row has the same path, content hash and
options key and a status of ``"ok"`` or ``"error"`` (an ``InertiaToolError`` is a property of the file, so it
is not retried); ``"internal_error"`` rows are retried.  A changed file or a changed density recomputes.

Writing rows (JSONL/CSV, append-only, one ``write`` per row) is in :mod:`inertia_tool.batch.rows`; the progress
bar is the command line's.  All numbers in a row are SI (m, kg, kg·m²), inertia about the centre of mass in
mesh axes with the tensor sign convention of ``docs/conventions.md``.
"""

from __future__ import annotations

import concurrent.futures as cf
import glob
import hashlib
import json
import math
import os
import platform
import sys
import time
import warnings
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, field
from typing import Any, NamedTuple, cast


from ..values import frozen_value
from ..mesh.checks import MeshReport
from ..errors import InertiaToolError, InertiaToolWarning, MeshReadError, UsageError
from ..mesh.options import LoadOptions
from ..mesh.read import COMPRESSED_SUFFIXES, SUPPORTED_SUFFIXES, load_mesh, os_error_reason
from ..mesh.regular import open_regular, open_regular_fd
from ..mass.pipeline import mass_properties, resolve_density
from .chunks import (DASK_CHUNK_SECONDS, DASK_SHORT_CHUNKS_PER_WORKER, DASK_TAIL_SECONDS, POOL_CHUNK_SECONDS,
                     POOL_SHORT_CHUNKS_PER_WORKER, POOL_TAIL_SECONDS, ChunkSizer, DaskTasks, PoolTasks, file_weights)

__all__ = ["BatchOptions", "BatchSummary", "ROW_FIELDS", "SCHEMA", "SCHEMA_V1", "ROW_FIELDS_V1", "SCHEMA_V2",
           "ROW_FIELDS_V2", "analyze_chunk",
           "analyze_file", "discover_files", "file_sha256", "run_batch", "upgrade_row", "downgrade_row",
           "DONE_STATUSES", "counts_as_done", "row_path", "NO_ASSUMPTIONS"]

#: Schema identifier written in every row (``schema`` column); bump it when columns change meaning.  The JSON
#: Schema of the rows is the ``batch_row`` of ``inertia_tool/schema/output-v1.json`` (docs/json.md).
SCHEMA = "inertia_tool.batch/3"

#: The rows of results files written before the ``assumptions`` column (the user's assumptions a result rests
#: on, issues 21/23) was added; otherwise :data:`SCHEMA`'s.  Read back (:func:`upgrade_row`: ``assumptions``
#: unknown, ``None``) and appended to in their own layout (:func:`downgrade_row`), as :data:`SCHEMA_V1`'s.
SCHEMA_V2 = "inertia_tool.batch/2"

#: The rows of results files written before ``units`` was renamed ``mesh_length_unit`` and ``method`` and the
#: ``uncertainty_*`` columns were added.  They are read back on resume (:func:`upgrade_row`), and a CSV file
#: with their header goes on receiving rows of its own layout (:func:`downgrade_row`), so an old results file
#: resumes without re-running its files.
SCHEMA_V1 = "inertia_tool.batch/1"

#: The bounds of an estimate (``MeshReport.uncertainty``), one column each: ``uncertainty_mass`` (relative),
#: ``uncertainty_center_of_mass`` (m), ``uncertainty_inertia`` (relative, Frobenius),
#: ``uncertainty_volume_in_doubt`` (m³); empty (``None``) when the result is exact.
_UNCERTAINTY = ("mass", "center_of_mass", "inertia", "volume_in_doubt")

#: The ``assumptions`` of an ``ok`` row whose result rests on no assumption of the user's.  An empty cell (``None``)
#: means *not recorded*: a failed row (no result), or a row read back from an ``inertia_tool.batch/2`` file (written
#: before the column).  ``inertia_tool.batch/3`` rows of session 16 left it empty for "none": read back as
#: ``"none"`` (:func:`upgrade_row`; an ``ok`` row of that writer had an empty cell only then).
NO_ASSUMPTIONS = "none"

#: Row statuses that count as done when resuming (``internal_error`` is retried).
DONE_STATUSES = ("ok", "error")

#: The columns of a result row, in order.  Units: m, m², m³, kg, kg/m³, kg·m², s; ``mesh_length_unit`` is the
#: unit the file's coordinates were read in.
ROW_FIELDS = (
    "schema", "path", "status", "error_type", "error", "sha256", "options_key",
    "mesh_length_unit", "density", "density_source",
    # how the solid was obtained (MeshReport.method) and an estimate's bounds (empty when exact)
    "method", *(f"uncertainty_{k}" for k in _UNCERTAINTY),
    "mass", "volume", "surface_area",
    "com_x", "com_y", "com_z",
    # inertia about the centre of mass, mesh axes, tensor convention (off-diagonals are -∫xy dm)
    "ixx", "iyy", "izz", "ixy", "ixz", "iyz",
    # principal moments (ascending) and their unit axes (mesh axes, right-handed)
    "i1", "i2", "i3",
    "axis1_x", "axis1_y", "axis1_z", "axis2_x", "axis2_y", "axis2_z", "axis3_x", "axis3_y", "axis3_z",
    "faces", "bodies", "cavities", "watertight", "repaired", "certificate",
    # the user's assumptions the result rests on (Certificate.assumptions), joined with ","; "none" when none was
    # taken; empty when not recorded (a failed row, a row of a batch/2 file): NO_ASSUMPTIONS
    "assumptions", "warnings", "seconds", "worker",
)

#: The columns of a :data:`SCHEMA_V2` row, frozen: this version's without ``assumptions``.
ROW_FIELDS_V2 = tuple(k for k in ROW_FIELDS if k != "assumptions")

#: The columns of a :data:`SCHEMA_V1` row, frozen (files of that version have exactly these): ``units`` (the
#: mesh's length unit) where ``mesh_length_unit`` is now, no ``method`` and ``uncertainty_*``.
ROW_FIELDS_V1 = (
    "schema", "path", "status", "error_type", "error", "sha256", "options_key", "units", "density", "density_source",
    "mass", "volume", "surface_area", "com_x", "com_y", "com_z", "ixx", "iyy", "izz", "ixy", "ixz", "iyz",
    "i1", "i2", "i3", *(f"axis{k}_{c}" for k in (1, 2, 3) for c in "xyz"),
    "faces", "bodies", "cavities", "watertight", "repaired", "warnings", "seconds", "worker",
)

#: The numeric columns of an ``ok`` row, in the order :func:`_analyze` fills them from one list.
_NUMBER_FIELDS = ("density", "mass", "volume", "surface_area", "com_x", "com_y", "com_z",
                  "ixx", "iyy", "izz", "ixy", "ixz", "iyz", "i1", "i2", "i3",
                  *(f"axis{k}_{c}" for k in (1, 2, 3) for c in "xyz"))

#: Row and column of ``ixx, iyy, izz, ixy, ixz, iyz`` in the inertia tensor.
_TENSOR_ENTRIES = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))

#: Bytes read at a time when hashing a file.
_HASH_CHUNK = 1 << 20

#: Most chunks of :data:`_HASH_CHUNK` bytes hashed from one file by the batch's reader (1 TiB): the bound of its
#: loop; a file still growing beyond it is refused.
_MAX_HASH_CHUNKS = 1 << 20

#: Largest file the batch reads into memory once, to hash it and to parse it from the same bytes (a binary STL of
#: 330,000 triangles); a larger one is hashed and then read by the streaming reader, as it never holds the whole
#: file.
READ_ONCE_BYTES = 1 << 24


def upgrade_row(row: dict) -> dict:
    """A :data:`SCHEMA_V1` row (of an older results file) with this version's columns: ``mesh_length_unit``
    from ``units``, ``method`` and ``uncertainty_*`` unknown (``None``); a :data:`SCHEMA_V2` row with
    ``assumptions`` unknown (``None``: not recorded, never :data:`NO_ASSUMPTIONS`); its ``schema`` stays what the
    file says.  A :data:`SCHEMA` row of an earlier writer (session 16) whose ``ok`` result left ``assumptions``
    empty for "none taken" says :data:`NO_ASSUMPTIONS`.  Other rows are returned unchanged."""
    schema = row.get("schema")
    if schema == SCHEMA:
        if row.get("assumptions") is None and row.get("status") == "ok" and "assumptions" in row:
            return {**row, "assumptions": NO_ASSUMPTIONS}
        return row
    if schema == SCHEMA_V2:
        return {k: row.get(k) for k in ROW_FIELDS}
    if schema != SCHEMA_V1:
        return row
    new = {k: row.get(k) for k in ROW_FIELDS}
    new.update(schema=SCHEMA_V1, mesh_length_unit=row.get("units"))
    return new


def downgrade_row(row: dict, layout: str = SCHEMA_V1) -> dict:
    """A row in an old ``layout``, for appending to an old CSV results file (whose header is never rewritten):
    :data:`SCHEMA_V2` drops ``assumptions``; :data:`SCHEMA_V1` (the default) takes ``units`` from
    ``mesh_length_unit`` and drops ``method``, ``uncertainty_*``, ``certificate`` and ``assumptions``."""
    if layout == SCHEMA_V2:
        older = {k: row.get(k) for k in ROW_FIELDS_V2}
        older["schema"] = SCHEMA_V2
        return older
    old = {k: row.get(k) for k in ROW_FIELDS_V1}
    old.update(schema=SCHEMA_V1, units=row.get("mesh_length_unit"))
    return old


@frozen_value
class BatchOptions:
    """What to do with every file of a batch (the same for all files).

    Attributes
    ----------
    load : LoadOptions
        How every mesh is read and checked (units, repair, merge tolerance, face limit).
    density : float, optional
        kg/m³.  At most one of ``density``, ``material``, ``mass``; none means water (1000 kg/m³).
    material : str, optional
        Material name (``inertia_tool.units.MATERIALS``).
    mass : float, optional
        Target mass of *each* part, kg.
    """

    load: LoadOptions = field(default_factory=LoadOptions)
    density: float | None = None
    material: str | None = None
    mass: float | None = None

    def validate(self) -> None:
        """Raise :class:`UsageError` now (once) rather than once per file."""
        if not isinstance(self.load, LoadOptions):
            raise UsageError(f"Expected `load` to be a LoadOptions, got {type(self.load).__name__}")
        resolve_density(density=self.density, material=self.material, mass=self.mass)

    def key(self) -> str:
        """16 hex digits identifying every option that changes the numbers (all of them, ``max_faces``
        included: it decides whether a file fails).  Computed from the flat field names, so result files
        written before the options were grouped resume unchanged."""
        flat = {**asdict(self.load), "density": self.density, "material": self.material, "mass": self.mass}
        flat["units"] = flat["units"] or "m"       # not given (metres assumed) gives the numbers of "m"
        # it changes only files that were refused before: keys stay those of result files written before it
        # existed (their error rows for such files are kept on resume; a new results file reads them again)
        flat.pop("declared_units_win", None)
        if not flat.get("assume"):         # none stated: the keys of result files written before `assume` existed
            flat.pop("assume", None)
        text = json.dumps(flat, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@frozen_value
class BatchSummary:
    """What a batch run did.

    Attributes
    ----------
    ok, failed, skipped : int
        Files analysed successfully in this run, files that failed (``error`` or ``internal_error``) in this
        run, and files skipped because a previous run had done them.
    skipped_failed : int
        Of the skipped files, those whose earlier row is an ``error`` (a bad file stays bad).
    total_mass : float
        kg: sum of the masses of the ``ok`` files of this batch, including skipped ones done before.
    seconds : float
        Wall time of this run, s.
    failures : tuple of (str, str)
        ``(path, message)`` of the files that failed in this run.
    """

    ok: int
    failed: int
    skipped: int
    skipped_failed: int
    total_mass: float
    seconds: float
    failures: tuple = field(default=(), repr=False)

    @property
    def computed(self) -> int:
        """Files analysed in this run (ok + failed)."""
        return self.ok + self.failed

    @property
    def files_per_second(self) -> float:
        """Analysed files per second of wall time in this run (0 when nothing was analysed)."""
        return self.computed / self.seconds if self.seconds > 0 and self.computed else 0.0


def _mesh_name(name: str, suffixes: tuple[str, ...]) -> bool:
    """A directory entry ``batch`` reads: a mesh suffix, a compressed mesh (``part.stl.gz``, ``part.obj.bz2``)
    or a ``.zip`` (which must hold one mesh; its row says so otherwise)."""
    if name.endswith(suffixes) or name.endswith(".zip"):
        return True
    stem, outer = os.path.splitext(name)
    return outer in COMPRESSED_SUFFIXES and stem.endswith(suffixes)


def discover_files(spec: str | os.PathLike, *, suffixes: Sequence[str] = SUPPORTED_SUFFIXES,
                   max_files: int = 10_000_000) -> list[str]:
    """The mesh files named by a directory (searched recursively) or a glob pattern, sorted, absolute.

    Parameters
    ----------
    spec : str or path
        A directory, a glob (``"parts/**/*.stl"``; ``**`` recurses) or a single file.
    suffixes : sequence of str
        File suffixes taken from a directory (case-insensitive), also compressed (``.gz``, ``.bz2``) and
        ``.zip`` files (issue 24: they were skipped without a word).  A glob or a file is taken as given.
    max_files : int
        Refuse to list more (guards against pointing at ``/``).

    Raises
    ------
    UsageError
        If nothing matches or there are more than ``max_files`` files.
    """
    spec = os.fspath(spec)
    suffixes = tuple(s.lower() for s in suffixes)
    found: list[str] = []
    if os.path.isdir(spec):
        for root, dirs, names in os.walk(spec):
            dirs.sort()
            for n in sorted(names):
                if _mesh_name(n.lower(), suffixes):
                    found.append(os.path.join(root, n))
                    if len(found) > max_files:
                        raise UsageError(f"{spec}: more than {max_files:,} mesh files; narrow the pattern")
    elif os.path.lexists(spec):
        found = [spec]          # a FIFO or a device too: its row says why it is not read (never opened)
    else:
        found = [p for p in glob.iglob(spec, recursive=True) if not os.path.isdir(p)]
        if len(found) > max_files:
            raise UsageError(f"{spec}: more than {max_files:,} files match; narrow the pattern")
    if not found:
        raise UsageError(f"Expected a directory holding mesh files ({', '.join(suffixes)}) or a glob that "
                         f"matches files, got {spec!r} (nothing found)")
    return sorted({os.path.abspath(p) for p in found})


def file_sha256(path: str | os.PathLike) -> str:
    """Hex SHA-256 of a regular file's bytes (read in 1 MiB chunks).

    Raises
    ------
    MeshReadError
        ``path`` is a FIFO, a device, a socket or a link to one (:func:`inertia_tool.mesh.regular.open_regular`:
        never opened, so never a hang).
    OSError
        It cannot be read.
    """
    h = hashlib.sha256()
    with open_regular(path) as fh:
        while chunk := fh.read(_HASH_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def _read_once(path: str, limit: int | None = None, known: str | None = None) -> tuple[bytes | None, str]:
    """The bytes of a regular file of at most ``limit`` bytes and their SHA-256, from one open and one read (the
    reader then parses those bytes: one file read once, its hash that of the bytes analysed); a larger file's
    hash only (``None``, hashed in chunks; the reader streams it), or ``known`` (a hash the caller computed) without
    reading it.  ``limit`` defaults to :data:`READ_ONCE_BYTES`.

    Five system calls for a small file: ``stat``, ``open``, ``fstat``, one ``read`` of the size ``fstat`` gave
    plus one byte (a file that grew since is hashed on to its end, and its bytes not kept: the reader streams
    it; a read that stops short is continued until the size or the end), ``close``.  A file system whose short
    reads end exactly at the size ``fstat`` gave hides a growth since (a local file's read is short only at its
    end): the bytes returned are then the ones hashed, so the row's hash is still that of the bytes analysed.

    Raises
    ------
    MeshReadError
        ``path`` is not a regular file (never opened: :func:`inertia_tool.mesh.regular.open_regular_fd`).
    OSError
        It cannot be read.
    """
    limit = READ_ONCE_BYTES if limit is None else limit
    fd, st = open_regular_fd(path)
    try:
        size = st.st_size
        if size <= limit:
            data = _read_upto(fd, size)
            if len(data) <= size:                  # all of it (a file that grew since the fstat: hashed on)
                return data, hashlib.sha256(data).hexdigest()
            h = hashlib.sha256(data)
        elif known is not None:
            return None, known
        else:
            h = hashlib.sha256()
        for _ in range(_MAX_HASH_CHUNKS):          # to the end of the file (a file growing without end: stopped)
            chunk = _read(fd, _HASH_CHUNK)
            if not chunk:
                return None, h.hexdigest()
            h.update(chunk)
    finally:
        os.close(fd)
    raise MeshReadError(f"{row_path(path)}: still growing after {_MAX_HASH_CHUNKS * _HASH_CHUNK:,} bytes were read "
                        "(is something writing to it?)")


def _read(fd: int, n: int) -> bytes:
    """``os.read(fd, n)`` on a descriptor opened with ``O_NONBLOCK`` (``open_regular_fd``): a regular file's reads
    ignore the flag, but should a file system answer ``EAGAIN`` the flag is cleared and the read made again
    (blocking), rather than the file reported unreadable."""
    try:
        return os.read(fd, n)
    except BlockingIOError:
        os.set_blocking(fd, True)
        return os.read(fd, n)


def _read_upto(fd: int, size: int) -> bytes:
    """Up to ``size + 1`` bytes of the descriptor from its position: reads until ``size`` bytes (a file of the size
    ``fstat`` gave is then whole: one ``read``), one more (it grew) or the end (it shrank)."""
    first = _read(fd, size + 1)         # not a read of `limit`: that would allocate `limit` bytes first
    if len(first) >= size or not first:
        return first
    parts, got = [first], len(first)
    for _ in range(size):                       # each pass reads at least one byte, or stops
        chunk = _read(fd, size + 1 - got)
        if not chunk:
            break
        parts.append(chunk)
        got += len(chunk)
        if got >= size:
            break
    return b"".join(parts)


def _one_line(text: object, limit: int = 500) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _worker_name() -> str:
    return f"{platform.node()}:{os.getpid()}"


def row_path(path: str) -> str:
    """The ``path`` of a file's row: the name itself when it is valid UTF-8; otherwise each byte that is not
    UTF-8 (held by Python as a surrogate escape) written as ``\\xNN``, e.g. ``b"part\\xff.stl"`` becomes
    ``part\\xff.stl`` (backslash, x, f, f), so the row is valid UTF-8 in both formats and a resume matches it.

    Not reversible for a name that also holds a literal ``\\xNN``; a resume still skips only a file whose
    content hash matches its row."""
    try:
        path.encode("utf-8")
        return path
    except UnicodeEncodeError:
        pass
    try:
        return path.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:                          # a lone surrogate that is no escaped byte
        return path.encode("utf-8", "backslashreplace").decode("utf-8")


def _empty_row(path: str, sha256: str | None, options: BatchOptions, key: str | None = None,
               worker: str | None = None) -> dict:
    row = dict.fromkeys(ROW_FIELDS)
    row.update(schema=SCHEMA, path=row_path(path), sha256=sha256, options_key=key or options.key(),
               mesh_length_unit=options.load.units or "m", worker=worker or _worker_name())
    return row


class _Chunk(NamedTuple):
    """What every file of a chunk shares, worked out once per chunk (:func:`_chunk_context`): the options, the
    empty row of this options key and worker (copied per file), the density's description and the warnings
    list that one ``warnings.catch_warnings`` fills for the whole chunk (emptied before each file)."""

    options: BatchOptions
    template: dict
    described: str
    caught: list


def _chunk_context(options: BatchOptions, caught: list, key: str | None = None, worker: str | None = None) -> _Chunk:
    template = dict.fromkeys(ROW_FIELDS)
    template.update(schema=SCHEMA, options_key=key or options.key(), mesh_length_unit=options.load.units or "m",
                    worker=worker or _worker_name())
    _, described = resolve_density(density=options.density, material=options.material, mass=options.mass)
    return _Chunk(options, template, described, caught)


class _CaughtWarnings:
    """``warnings.catch_warnings(record=True)`` with every :class:`InertiaToolWarning` recorded each time it is
    issued (``"always"``): the context of a whole chunk, so that a chunk pays for one, not one per file."""

    def __enter__(self) -> list:
        self._context = warnings.catch_warnings(record=True)
        caught = self._context.__enter__()
        warnings.simplefilter("always", InertiaToolWarning)
        return cast(list, caught)

    def __exit__(self, *exc: Any) -> None:
        self._context.__exit__(*exc)


def analyze_file(path: str, options: BatchOptions, sha256: str | None = None) -> dict:
    """Mass properties of one mesh file as a result row (:data:`ROW_FIELDS`); never raises.

    Parameters
    ----------
    path : str
        Mesh file.
    options : BatchOptions
    sha256 : str, optional
        The file's content hash if the caller already has it.  A file read into memory (up to
        :data:`READ_ONCE_BYTES`) is hashed again from the bytes analysed (they win if the file changed since); a
        larger one keeps this hash, and is hashed here when it is not given.

    Returns
    -------
    dict
        ``status`` is ``"ok"`` (numbers filled in), ``"error"`` (an ``InertiaToolError``: unreadable or
        invalid mesh; ``error_type`` and ``error`` say why) or ``"internal_error"`` (any other exception,
        retried on resume).  ``warnings`` (``None`` when there are none) joins the soft problems with
        ``" | "``; ``seconds`` is the time
        spent on this file.
    """
    with _CaughtWarnings() as caught:
        return _analyze(path, sha256, _chunk_context(options, caught))


def _analyze(path: str, sha256: str | None, chunk: _Chunk) -> dict:
    """:func:`analyze_file` with what the files of a chunk share worked out once (:func:`_chunk_context`); the
    warnings of this file are those ``chunk.caught`` holds when it returns."""
    start = time.perf_counter()
    row = chunk.template.copy()
    row["path"] = name = row_path(path)
    row["sha256"] = sha256
    caught = chunk.caught
    caught.clear()
    options = chunk.options
    try:
        try:
            # read once: hashed here and parsed from the same bytes (the hash is that of the content analysed;
            # a hash given by the caller is replaced by the one of the bytes read now, but for a file too large
            # to hold, which is not read twice for it)
            data, digest = _read_once(path, known=sha256)
        except MeshReadError:       # not a regular file: never opened
            raise
        except OSError as exc:       # unreadable: a property of the file, reported like the reader does
            raise MeshReadError(f"{name}: cannot be read ({os_error_reason(exc, path)})") from None
        row["sha256"] = digest
        described = chunk.described
        load = options.load
        raw = load_mesh(path, units=load.units, max_faces=load.max_faces,
                        declared_units_win=load.declared_units_win, data=data)
        # a file that names materials per part is integrated part by part from its path (it is read again:
        # rare); every other file from the mesh just read, as mass_properties(path) would
        props = mass_properties(path if raw.parts else raw, density=options.density, material=options.material,
                                mass=options.mass, options=load, fast_path=True)
        pa = props.principal
        tensor = props.inertia.tolist()
        axes = pa.axes.tolist()                     # axis k = column k of `axes`
        numbers = [float(props.density), float(props.mass), float(props.volume), float(props.surface_area),
                   *props.center_of_mass.tolist(), *(tensor[i][j] for i, j in _TENSOR_ENTRIES),
                   *pa.moments.tolist(), *(axes[i][k] for k in range(3) for i in range(3))]
        row.update(zip(_NUMBER_FIELDS, [v if math.isfinite(v) else None for v in numbers]))
        if props.mesh is None:           # a multi-material file: its parts, each with its own mesh report
            row.update(_parts_fields(props))
            described = "per part (the file's materials)"
        else:
            mesh = props.mesh
            row.update(method=mesh.method, faces=int(mesh.faces), bodies=int(mesh.bodies),
                       cavities=int(mesh.cavities), watertight=bool(mesh.watertight),
                       repaired=bool(mesh.repaired), certificate=mesh.certificate.kind,
                       assumptions=",".join(mesh.certificate.assumptions) or NO_ASSUMPTIONS)
            if mesh.uncertainty is not None:
                row.update(_bounds(mesh.uncertainty))
        row["status"] = "ok"
        row["density_source"] = described
        row["warnings"] = " | ".join(_one_line(w.message) for w in caught
                                     if issubclass(w.category, InertiaToolWarning)) or None
    except InertiaToolError as exc:
        row.update(status="error", error_type=type(exc).__name__, error=row_path(_one_line(exc)))
    except Exception as exc:  # noqa: BLE001 - one bad file must never stop a batch
        row.update(status="internal_error", error_type=type(exc).__name__, error=row_path(_one_line(exc)))
    row["seconds"] = round(time.perf_counter() - start, 6)
    return row


def _parts_fields(props) -> dict:
    """The mesh columns of a file integrated part by part (:mod:`inertia_tool.mass.materials`): counts added,
    ``method`` the parts' common one (``mixed`` when they differ), the weakest part's certificate, and the
    mass bound the parts' give (the largest relative one; the others are per part only)."""
    from ..mesh.hole_assumptions import user_named
    from ..mesh.policy import CERTIFICATE_KINDS
    reports = [cast(MeshReport, p.mesh) for p in props.parts]
    methods = {r.method for r in reports}
    masses = [getattr(r.uncertainty, "mass", None) for r in reports if r.uncertainty is not None]
    bounds: dict[str, float | None] = {f"uncertainty_{k}": None for k in _UNCERTAINTY}
    finite = [float(m) for m in masses if m is not None and math.isfinite(m)]
    bounds["uncertainty_mass"] = max(finite) if finite else None
    return dict(method=methods.pop() if len(methods) == 1 else "mixed", **bounds,
                faces=sum(int(r.faces) for r in reports), bodies=sum(int(r.bodies) for r in reports),
                cavities=sum(int(r.cavities) for r in reports), watertight=all(r.watertight for r in reports),
                repaired=any(r.repaired for r in reports),
                certificate=max((r.certificate.kind for r in reports), key=CERTIFICATE_KINDS.index),
                assumptions=",".join(user_named(a for r in reports for a in r.certificate.assumptions))
                or NO_ASSUMPTIONS)


def _bounds(uncertainty) -> dict:
    """The ``uncertainty_*`` columns of an estimate's bounds (``None`` each when exact or not finite)."""
    out: dict = {}
    for k in _UNCERTAINTY:
        v = getattr(uncertainty, k, None)
        out[f"uncertainty_{k}"] = float(v) if v is not None and math.isfinite(v) else None
    return out


def analyze_chunk(chunk: Sequence[tuple[str, str | None]], options: BatchOptions) -> list[dict]:
    """The rows of a chunk of files, analysed one after the other in this process; never raises for a file.

    The task a worker runs for :func:`run_batch` (and the one to submit to any other executor): one task per
    chunk instead of one per file, so the executor's per-task cost is paid once per chunk.

    Parameters
    ----------
    chunk : sequence of (str, str or None)
        ``(path, sha256)`` pairs; a ``None`` hash is computed here, from the file as it is read now.
    options : BatchOptions

    Returns
    -------
    list of dict
        One row per file (:func:`analyze_file`), in the order of ``chunk``.
    """
    with _CaughtWarnings() as caught:
        context = _chunk_context(options, caught)
        return [_analyze(path, digest, context) for path, digest in chunk]


def _analyze_chunk_timed(chunk: Sequence[tuple[str, str | None]], options: BatchOptions) -> tuple[list[dict], float]:
    """:func:`analyze_chunk` and the CPU seconds this worker process spent on it (``time.process_time``: what
    sizes the next chunks, which the load of a shared machine does not inflate as it does wall time)."""
    start = time.process_time()
    rows = analyze_chunk(chunk, options)
    return rows, time.process_time() - start


#: Seconds between the checks of the pool workers' watchdog that their parent (the batch run) is alive.
_WATCHDOG_SECONDS = 0.5

_PR_SET_PDEATHSIG = 1            # <linux/prctl.h>


def kernel_threads_per_worker(workers: int) -> int:
    """Threads each of ``workers`` worker processes should give the C kernels: the cores shared out (at least
    1), so that N workers analysing large meshes at once do not run N times the cores in threads.  A
    ``INERTIA_TOOL_THREADS`` set by the user wins (see :func:`inertia_tool._native.threads`)."""
    from .._native import THREADS_ENV, threads

    if os.environ.get(THREADS_ENV, "").strip():
        return threads()
    return max(1, threads() // max(1, workers))


def _init_worker(parent_pid: int, kernel_threads: int) -> None:
    """Pool-worker initializer: the C kernels' share of the cores, and :func:`_exit_with_parent`."""
    from .._native import THREADS_ENV

    os.environ[THREADS_ENV] = str(kernel_threads)
    _exit_with_parent(parent_pid)


def _exit_with_parent(parent_pid: int) -> None:
    """End this worker when the batch process that started it dies, and close the results file it inherited
    (:func:`inertia_tool.batch.rows.close_inherited`).

    A killed parent (``kill -9``, out of memory) cannot shut its pool down, and orphaned workers would go on
    analysing files nobody collects.  On Linux the kernel sends SIGKILL on the parent's death
    (``prctl(PR_SET_PDEATHSIG)``); everywhere, a daemon thread polls ``os.getppid()`` every
    :data:`_WATCHDOG_SECONDS` and exits when the worker has been re-parented.
    """
    import signal
    import threading

    # a forked worker must not hold the results file (and its lock); a parent that never imported the writer
    # has no results file open, and the worker need not import it (7 ms of CPU per worker)
    rows = sys.modules.get(f"{__package__}.rows")
    if rows is not None:
        rows.close_inherited()
    if sys.platform.startswith("linux"):
        try:
            import ctypes
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):
            pass                                                # the watchdog below still works
    # with the fork start method the parent is the batch process; with spawn or forkserver it may be a
    # helper process: watch both the actual parent and the batch process
    watched = os.getppid()

    def orphaned() -> bool:
        if os.getppid() != watched:
            return True
        if os.name != "posix":              # os.kill(pid, 0) would terminate the process on Windows
            return False
        try:
            os.kill(parent_pid, 0)
        except ProcessLookupError:
            return True
        except OSError:                                         # exists, but not ours to signal
            pass
        return False

    if orphaned():                                              # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:
        while True:                                             # ends with the process (daemon thread)
            if orphaned():
                os._exit(1)
            time.sleep(_WATCHDOG_SECONDS)

    threading.Thread(target=watch, name="inertia-tool-parent-watchdog", daemon=True).start()


def _process_pool(jobs: int) -> cf.ProcessPoolExecutor:
    """A pool of ``jobs`` worker processes that exit when this process dies (:func:`_exit_with_parent`), their
    C kernels sharing the cores (:func:`kernel_threads_per_worker`)."""
    return cf.ProcessPoolExecutor(max_workers=jobs, initializer=_init_worker,
                                  initargs=(os.getpid(), kernel_threads_per_worker(jobs)))


def counts_as_done(row: dict) -> bool:
    """Whether a previous row means its file need not be analysed again: its status is one of
    :data:`DONE_STATUSES`, no value in it is NaN or infinite (the writer never writes one: such a row was
    edited or damaged), and an ``ok`` row has every number of :data:`_NUMBER_FIELDS`."""
    status = row.get("status")
    if status not in DONE_STATUSES:
        return False
    if any(isinstance(v, float) and not math.isfinite(v) for v in row.values()):
        return False
    if status == "ok":
        return all(isinstance(row.get(k), (int, float)) and not isinstance(row.get(k), bool)
                   for k in _NUMBER_FIELDS)
    return True


def _done_keys(previous_rows: Iterable[dict]) -> dict:
    """``{(path, sha256, options_key): row}`` of previous rows that count as done (:func:`counts_as_done`)."""
    done = {}
    for r in previous_rows:
        if counts_as_done(r):
            done[(r.get("path"), r.get("sha256"), r.get("options_key"))] = r
    return done


def _as_float(x) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return 0.0
    return v if math.isfinite(v) else 0.0


def run_batch(files: Sequence[str], options: BatchOptions, write_row: Callable[[dict], None], *,
              previous_rows: Iterable[dict] = (), jobs: int = 1, executor: cf.Executor | None = None,
              client: Any = None, progress: Callable[[int, int, int, int], None] | None = None,
              max_in_flight: int | None = None, chunk_seconds: float | None = None) -> BatchSummary:
    """Analyse ``files`` and hand each row to ``write_row`` as soon as it is back (order of completion).

    Parameters
    ----------
    files : sequence of str
        Mesh files (see :func:`discover_files`).
    options : BatchOptions
    write_row : callable(dict)
        Called once per analysed file, in the calling process (so it can append to one file safely).
    previous_rows : iterable of dict
        Rows of an earlier run (read back from the output); files done there are skipped.
    jobs : int
        1 runs in this process, one file after the other; N > 1 uses a pool of N processes
        (``ProcessPoolExecutor``) fed with chunks of files (:mod:`inertia_tool.batch.chunks`).
    executor : concurrent.futures.Executor, optional
        Run the chunks on this executor instead; ``jobs`` is then its number of workers.
    client : dask.distributed.Client, optional
        Run the chunks on this Dask cluster (a LocalCluster's client or one connected to a remote scheduler:
        the same code path); the number of workers is asked of the scheduler.
    progress : callable(done, total, ok, failed), optional
        Called after every file (skipped ones included, at the start).
    max_in_flight : int, optional
        Chunks submitted but not finished at most (default two per worker: one running, one queued), so
        memory stays bounded for huge batches.
    chunk_seconds : float, optional
        CPU time of analysis aimed at per chunk, s (default :data:`~inertia_tool.batch.chunks.POOL_CHUNK_SECONDS`
        for a process pool or executor, :data:`~inertia_tool.batch.chunks.DASK_CHUNK_SECONDS` for Dask).

    Returns
    -------
    BatchSummary

    Notes
    -----
    Rows of a chunk arrive together, in the chunk's order; chunks arrive in order of completion.  A chunk whose
    task fails as a whole (its worker process died, the cluster lost it) is split and its files run again one
    per task; a file that fails alone gets an ``internal_error`` row (retried on resume).  Each file gets
    exactly one row.

    The SHA-256 that decides skipping is computed here only for files that have a done row of the same path
    and options in ``previous_rows``; for the others nothing can be skipped and the worker hashes the file, from
    the bytes it analyses (:func:`analyze_file`).
    """
    if jobs < 1:
        raise UsageError(f"Expected `jobs` >= 1, got {jobs}")
    if executor is not None and client is not None:
        raise UsageError("Give at most one of `executor` and `client`")
    options.validate()
    start = time.perf_counter()
    done = _done_keys(previous_rows)
    key = options.key()
    candidates = {(path, options_key) for path, _, options_key in done}
    todo: list[tuple[str, str | None]] = []
    skipped = skipped_failed = 0
    total_mass = 0.0
    failures: list[tuple[str, str]] = []
    ok = failed = 0
    total = len(files)
    for path in files:
        digest = None
        if (row_path(path), key) in candidates:                 # a done row exists: is the content the same?
            try:
                digest = file_sha256(path)
            except OSError:
                digest = None                                  # the worker writes the error row
        prev = done.get((row_path(path), digest, key)) if digest is not None else None
        if prev is not None:
            skipped += 1
            if prev.get("status") == "ok":
                total_mass += _as_float(prev.get("mass"))
            else:
                skipped_failed += 1
        else:
            todo.append((path, digest))
    if progress:
        progress(skipped, total, ok, failed)

    def record(row: dict) -> None:
        nonlocal ok, failed, total_mass
        write_row(row)
        if row["status"] == "ok":
            ok += 1
            total_mass += _as_float(row["mass"])
        else:
            failed += 1
            failures.append((row["path"], f"{row['error_type']}: {row['error']}"))
        if progress:
            progress(skipped + ok + failed, total, ok, failed)

    if executor is None and client is None and jobs == 1:
        # one warnings context per file here (each row is written as soon as its file is done, outside it: what
        # the writer or the progress bar warns is shown, not recorded); a chunk on a worker shares one
        context = _chunk_context(options, [], key, _worker_name())
        for path, digest in todo:
            with _CaughtWarnings() as caught:
                row = _analyze(path, digest, context._replace(caught=caught))
            record(row)
    else:
        tasks: PoolTasks | DaskTasks
        if client is not None:
            tasks = DaskTasks(client)
        elif executor is not None:
            tasks = PoolTasks(executor=executor, workers=jobs)
        else:
            tasks = PoolTasks(make_pool=lambda: _process_pool(jobs), workers=jobs)
        target = chunk_seconds or (DASK_CHUNK_SECONDS if client is not None else POOL_CHUNK_SECONDS)
        tail = min(target, DASK_TAIL_SECONDS if client is not None else POOL_TAIL_SECONDS)
        try:
            short = DASK_SHORT_CHUNKS_PER_WORKER if client is not None else POOL_SHORT_CHUNKS_PER_WORKER
            sizer = ChunkSizer(file_weights([path for path, _ in todo]), target, tail_seconds=tail,
                               short_chunks_per_worker=short)
            _run_chunks(todo, options, tasks, sizer, record, max_in_flight)
        finally:
            tasks.close()
    return BatchSummary(ok=ok, failed=failed, skipped=skipped, skipped_failed=skipped_failed,
                        total_mass=total_mass,
                        seconds=time.perf_counter() - start, failures=tuple(failures))


def _run_chunks(todo: list[tuple[str, str | None]], options: BatchOptions, tasks: PoolTasks | DaskTasks,
                sizer: ChunkSizer, record: Callable[[dict], None], max_in_flight: int | None) -> None:
    """Feed ``todo`` to ``tasks`` in chunks and ``record`` every row as its chunk comes back.

    A chunk that fails as a whole is split into single files put back at the front of the queue; a single
    file that fails gets an ``internal_error`` row.  Bounded: every pass hands out or takes back at least one
    chunk, there are at most ``2 * len(todo)`` chunks (each file is in at most one chunk and one retry).
    """
    queue: deque[list[tuple[str, str | None]]] = deque()     # single files to retry, first
    weights: dict[int, float] = {}                            # of the chunks in flight, by id (retries: none)
    position = 0
    for _ in range(4 * len(todo) + 2):
        workers = tasks.workers
        limit = max_in_flight or 2 * workers
        while tasks.in_flight() < limit and (queue or position < len(todo)):
            if queue:
                chunk = queue.popleft()
            else:
                size = sizer.next_size(position, workers)
                chunk = todo[position:position + size]
                weights[id(chunk)] = sizer.weight(position, position + size)
                position += size
            tasks.submit(_analyze_chunk_timed, chunk, options)
        if not tasks.in_flight():
            return
        for chunk, result, error in tasks.wait():
            weight = weights.pop(id(chunk), None)
            if result is not None:
                rows, cpu = result
                if weight is not None:
                    sizer.observe(weight, cpu)
                for row in rows:
                    record(row)
            elif len(chunk) > 1:
                queue.extend([item] for item in chunk)
            else:
                path, digest = chunk[0]
                row = _empty_row(path, digest, options)
                row.update(status="internal_error", error_type=type(error).__name__,
                           error=row_path(_one_line(error)) or "worker failed")
                record(row)
    raise RuntimeError("batch: the chunk loop did not finish within its bound")          # pragma: no cover
