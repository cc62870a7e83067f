"""The one way inertia_tool writes an output file: checked first, then written atomically.

Every file the tool produces (HTML and Markdown reports, SVG plots, CSV trajectories, JSON, URDF/SDF/MJCF
snippets, PNG figures) goes through this module, so there is one overwrite rule and one writer:

* :func:`check_targets` refuses, before any work and before any file is written, a target that exists
  (unless ``force``), is a symbolic link (even with ``force``: the tool neither writes through a link nor
  replaces it), is a directory, is a device, named pipe or socket (even with ``force``), or lies in a
  missing directory.  A command that writes several files checks **all** of them first, so it never stops
  half-way with some files replaced.
* :func:`atomic_target` / :func:`write_text` / :func:`write_bytes` write to a temporary file in the target's
  own directory (same file system) with an unpredictable name created ``O_EXCL | O_NOFOLLOW`` (so a
  planted file or symbolic link is never followed), ``fsync`` it, then rename it onto the target: a reader
  sees the old file or the complete new one, never half a file, and a failure (a full disk, a crash of the
  writer, an exception while producing the content) removes the temporary file and leaves the target as it
  was.  With ``replace=False`` the rename is a hard link that fails if the target appeared meanwhile, so
  "never overwrite" holds at the moment of writing, not only at the check.

Failures are :class:`~inertia_tool.errors.OutputFileError` (a ``UsageError``, exit code 2) with one line
naming the file and the operating system's reason.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
from collections.abc import Iterator, Mapping, Sequence

from .errors import OutputFileError, UsageError

__all__ = ["OutputFileError", "check_targets", "atomic_target", "write_text", "write_bytes", "write_files"]


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
        if os.path.islink(path):
            raise OutputFileError(f"{where}: is a symbolic link; refusing to write through it or replace it "
                                  "(name the file it points to)")
        if os.path.isdir(path):
            raise OutputFileError(f"{where}: is a directory")
        _refuse_special(path, where)
        if os.path.lexists(path) and not force:
            raise OutputFileError(f"{where}: exists; refusing to overwrite it (`force=True` overwrites it)")
        parent = os.path.dirname(full)
        if not os.path.isdir(parent):
            raise OutputFileError(f"{where}: cannot write it (no such directory: {parent})")


_SPECIAL_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                  (stat.S_ISFIFO, "a named pipe"), (stat.S_ISSOCK, "a socket"))


def _refuse_special(path: str, where: str) -> None:
    """Refuse a target that exists and is not a regular file, even with ``force``: the rename would put a
    regular file where ``/dev/null``, a named pipe or a socket was (as root, ``/dev/null`` itself)."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return
    for test, kind in _SPECIAL_KINDS:
        if test(mode):
            raise OutputFileError(f"{where}: is {kind}, not a regular file; refusing to replace it (name a "
                                  "file to write)")


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


#: Errors of ``os.link`` that mean "this file system has no hard links here" (FAT, some network and FUSE
#: file systems): the no-clobber rename falls back to a last existence check and ``os.replace``.
_NO_HARD_LINKS = {getattr(errno, name) for name in ("EPERM", "EACCES", "ENOTSUP", "EOPNOTSUPP", "EXDEV", "EMLINK",
                                                 "ENOSYS")
                  if hasattr(errno, name)}


def _create_temporary(path: str, where: str) -> tuple[int, str, os.stat_result]:
    """``(fd, name, stat)`` of a new, empty temporary file beside ``path``: an unpredictable name, created
    with ``O_CREAT | O_EXCL | O_NOFOLLOW`` (``tempfile.mkstemp``), mode 0600 until it is complete."""
    directory = os.path.dirname(os.path.abspath(path))
    stem, suffix = os.path.splitext(os.path.basename(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{stem[:80]}.", suffix=f".tmp{suffix}", dir=directory)
    except OSError as exc:
        raise OutputFileError(f"{where}: cannot write it ({exc.strerror or exc})") from None
    return fd, tmp, os.fstat(fd)


def _same_file(a: os.stat_result, b: os.stat_result) -> bool:
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _commit(fd: int, tmp: str, created: os.stat_result, path: str, where: str, replace: bool) -> None:
    """Make the temporary file (open as ``fd``) durable and give it the name ``path``.

    The name ``tmp`` must still be the file we created (not swapped for another file or a symbolic link
    while a third-party writer had it).  With ``replace`` false the final step is ``os.link`` (which fails if
    ``path`` exists, so a file created meanwhile is never overwritten) and the temporary name is removed;
    where the file system has no hard links, a last ``lexists`` check and ``os.replace``.
    """
    try:
        now = os.lstat(tmp)
    except FileNotFoundError:
        now = None
    if now is None or not _same_file(now, created):
        raise OutputFileError(f"{where}: its temporary file {tmp} was replaced or removed while it was written; "
                              "nothing was written")
    os.fsync(fd)
    mode = _default_mode()
    if mode is not None:
        os.fchmod(fd, mode)                          # mkstemp makes 0600; give the file the usual rights
    if replace:
        _refuse_special(path, where)                 # a pipe or device made since check_targets
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path, follow_symlinks=False)
    except FileExistsError:
        raise OutputFileError(f"{where}: exists; refusing to overwrite it (`force=True` overwrites it)") from None
    except OSError as exc:
        if exc.errno not in _NO_HARD_LINKS:
            raise
        if os.path.lexists(path):
            raise OutputFileError(f"{where}: exists; refusing to overwrite it (`force=True` overwrites it)") \
                from None
        os.replace(tmp, path)
        return
    os.remove(tmp)


def _remove_quietly(tmp: str, created: os.stat_result) -> None:
    """Remove the temporary name if it is still the file we created."""
    with contextlib.suppress(OSError):
        if _same_file(os.lstat(tmp), created):
            os.remove(tmp)


@contextlib.contextmanager
def _atomic(path: str | os.PathLike[str], label: str | None, replace: bool) -> Iterator[tuple[int, str]]:
    """``(fd, temporary name)``; on a normal exit the file becomes ``path`` (:func:`_commit`), on an
    exception it is removed and ``path`` is left as it was."""
    path = os.fspath(path)
    where = _label(path, label)
    fd, tmp, created = _create_temporary(path, where)
    try:
        yield fd, tmp
        _commit(fd, tmp, created, path, where, replace)
    except BaseException as exc:
        _remove_quietly(tmp, created)
        if isinstance(exc, OSError) and not isinstance(exc, UsageError):
            raise OutputFileError(f"{where}: cannot write it ({exc.strerror or exc})") from None
        raise
    finally:
        os.close(fd)
    _fsync_directory(os.path.dirname(os.path.abspath(path)))


@contextlib.contextmanager
def atomic_target(path: str | os.PathLike[str], *, label: str | None = None, replace: bool = True) -> Iterator[str]:
    """Context manager yielding a temporary path to write; on success it becomes ``path`` atomically.

    The temporary file is in the directory of ``path``, has an unpredictable name (created with
    ``O_EXCL | O_NOFOLLOW``) and keeps the suffix of ``path`` (so ``savefig`` and ``np.savetxt`` pick the
    format from it).  On leaving the block normally it is checked to be still the file created, fsync'd and
    renamed onto ``path`` (``os.replace``); on any exception it is removed and ``path`` is left untouched.
    The overwrite rule is :func:`check_targets`' (call it first).  Writers that hold the bytes should use
    :func:`write_bytes`, which writes through the descriptor and never opens the name again.

    Parameters
    ----------
    path : str or path
        The file to produce.
    label : str, optional
        Prefix of messages (the option that named the file, e.g. ``"--csv"``).
    replace : bool
        Replace ``path`` if it exists by then; when false an existing file (even one created after
        :func:`check_targets`) is refused and left alone.

    Raises
    ------
    OutputFileError
        The operating system refused to create, write or rename the file (one line, the reason).
    """
    with _atomic(path, label, replace) as (_fd, tmp):
        yield tmp


def _default_mode() -> int | None:
    """0666 less the process umask (what ``open(path, "w")`` would give); None on Windows."""
    if os.name != "posix":                                              # pragma: no cover - Windows
        return None
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_bytes(path: str | os.PathLike[str], data: bytes, *, label: str | None = None, replace: bool = True) -> None:
    """Write ``data`` to ``path`` atomically: through the descriptor of a new temporary file beside it, then
    fsync and rename (:func:`atomic_target`).

    Parameters
    ----------
    path : str or path
        The file to produce (check it first with :func:`check_targets`).
    data : bytes
        Its content.
    label : str, optional
        Prefix of messages.
    replace : bool
        Replace ``path`` if it exists by then; when false an existing file is refused and left alone.
    """
    with _atomic(path, label, replace) as (fd, _tmp):
        view = memoryview(data)
        while view:                                  # os.write may write less than asked
            view = view[os.write(fd, view):]


def write_text(path: str | os.PathLike[str], text: str, *, label: str | None = None, replace: bool = True) -> None:
    """Write ``text`` as UTF-8 to ``path`` atomically (``\\n`` line ends on every platform).

    Parameters
    ----------
    path : str or path
        The file to produce (replaced if it exists: check it first with :func:`check_targets`).
    text : str
        Its content.
    label : str, optional
        Prefix of messages.
    replace : bool
        Replace ``path`` if it exists by then (see :func:`write_bytes`).
    """
    write_bytes(path, text.encode("utf-8"), label=label, replace=replace)


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
        write_bytes(path, content.encode("utf-8") if isinstance(content, str) else content, label=label,
                    replace=force)
