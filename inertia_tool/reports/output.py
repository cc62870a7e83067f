"""The one way inertia_tool writes an output file: checked first, then written atomically.

Every file the tool produces (HTML and Markdown reports, SVG plots, CSV trajectories, JSON, URDF/SDF/MJCF
snippets, PNG figures) goes through this module, so there is one overwrite rule and one writer:

* :func:`check_targets` refuses, before any work and before any file is written, a target that exists
  (unless ``force``), is a directory, or lies in a missing directory.  A command that writes several files
  checks **all** of them first, so it never stops half-way with some files replaced.
* :func:`atomic_target` / :func:`write_text` / :func:`write_bytes` write to a temporary file in the target's
  own directory (same file system), flush and ``fsync`` it, then ``os.replace`` it onto the target: a reader
  sees the old file or the complete new one, never half a file, and a failure (a full disk, a crash of the
  writer, an exception while producing the content) removes the temporary file and leaves the target as it
  was.

Failures are :class:`~inertia_tool.errors.OutputFileError` (a ``UsageError``, exit code 2) with one line
naming the file and the operating system's reason.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Mapping, Sequence

from ..errors import UsageError

__all__ = ["OutputFileError", "check_targets", "atomic_target", "write_text", "write_bytes", "write_files"]


class OutputFileError(UsageError):
    """An output file cannot be written: it exists (without ``force``), is a directory, its directory is
    missing, or the operating system refused the write."""


def _label(path: str, label: str | None) -> str:
    return f"{label} {path}" if label else path


def check_targets(targets: Sequence[str | None | tuple[str | None, str | None]], *, force: bool = False) -> None:
    """Refuse, before anything is written, any target that cannot be written as asked.

    Parameters
    ----------
    targets : sequence of path or (path, label)
        Every file the command will write; ``label`` (e.g. ``"--report"``) prefixes the message.  ``None``
        or empty paths are skipped.
    force : bool
        Allow replacing existing files.

    Raises
    ------
    OutputFileError
        For the first target that exists (without ``force``), is a directory, or whose directory is missing.
    """
    seen = set()
    for item in targets:
        path, label = (item, None) if not isinstance(item, tuple) else item
        if not path:
            continue
        path = os.fspath(path)
        where = _label(path, label)
        full = os.path.abspath(path)
        if full in seen:
            raise OutputFileError(f"{where}: named twice among the files to write")
        seen.add(full)
        if os.path.isdir(path):
            raise OutputFileError(f"{where}: is a directory")
        if os.path.lexists(path) and not force:
            raise OutputFileError(f"{where}: exists; refusing to overwrite it (`force=True` overwrites it)")
        parent = os.path.dirname(full)
        if not os.path.isdir(parent):
            raise OutputFileError(f"{where}: cannot write it (no such directory: {parent})")


def _fsync_directory(directory: str) -> None:
    """Make the rename durable where the platform allows (POSIX); a no-op elsewhere."""
    if os.name != "posix":                                              # pragma: no cover - Windows
        return
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_target(path: str | os.PathLike, *, label: str | None = None) -> Iterator[str]:
    """Context manager yielding a temporary path to write; on success it becomes ``path`` atomically.

    The temporary file is in the directory of ``path`` and keeps its suffix (so ``savefig`` and
    ``np.savetxt`` pick the format from it).  On leaving the block normally it is fsync'd and renamed onto
    ``path`` (``os.replace``); on any exception it is removed and ``path`` is left untouched.  The overwrite
    rule is :func:`check_targets`' (call it first); this only writes.

    Parameters
    ----------
    path : str or path
        The file to produce.
    label : str, optional
        Prefix of messages (the option that named the file, e.g. ``"--csv"``).

    Raises
    ------
    OutputFileError
        The operating system refused to create, write or rename the file (one line, the reason).
    """
    path = os.fspath(path)
    where = _label(path, label)
    directory = os.path.dirname(os.path.abspath(path))
    base = os.path.basename(path)
    stem, suffix = os.path.splitext(base)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{stem[:80]}.", suffix=f".tmp{suffix}", dir=directory)
        os.close(fd)
    except OSError as exc:
        raise OutputFileError(f"{where}: cannot write it ({exc.strerror or exc})") from None
    try:
        yield tmp
        with open(tmp, "rb+") as fh:                 # whatever wrote the temp file, make its bytes durable
            os.fsync(fh.fileno())
        mode = _default_mode()
        if mode is not None:
            os.chmod(tmp, mode)                      # mkstemp makes 0600; give the file the usual rights
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, UsageError):
            raise OutputFileError(f"{where}: cannot write it ({exc.strerror or exc})") from None
        raise
    _fsync_directory(directory)


def _default_mode() -> int | None:
    """0666 less the process umask (what ``open(path, "w")`` would give); None on Windows."""
    if os.name != "posix":                                              # pragma: no cover - Windows
        return None
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_bytes(path: str | os.PathLike, data: bytes, *, label: str | None = None) -> None:
    """Write ``data`` to ``path`` atomically (:func:`atomic_target`).

    Parameters
    ----------
    path : str or path
        The file to produce (replaced if it exists: check it first with :func:`check_targets`).
    data : bytes
        Its content.
    label : str, optional
        Prefix of messages.
    """
    with atomic_target(path, label=label) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()


def write_text(path: str | os.PathLike, text: str, *, label: str | None = None) -> None:
    """Write ``text`` as UTF-8 to ``path`` atomically (``\\n`` line ends on every platform).

    Parameters
    ----------
    path : str or path
        The file to produce (replaced if it exists: check it first with :func:`check_targets`).
    text : str
        Its content.
    label : str, optional
        Prefix of messages.
    """
    write_bytes(path, text.encode("utf-8"), label=label)


def write_files(files: Mapping[str, str | bytes], *, force: bool = False, label: str | None = None) -> None:
    """Check every target (:func:`check_targets`), then write each one atomically, in order.

    Each file is atomic on its own; a failure part-way leaves the files already written complete and the
    rest untouched.

    Parameters
    ----------
    files : mapping of path to str or bytes
        Every file of the command and its content (text is written as UTF-8), in the order to write them.
    force : bool
        Allow replacing existing files.
    label : str, optional
        Prefix of messages.
    """
    check_targets([(p, label) for p in files], force=force)
    for path, content in files.items():
        write_bytes(path, content.encode("utf-8") if isinstance(content, str) else content, label=label)
