"""Opening the files a user names: regular files only.

A FIFO, a device (``/dev/zero``, ``/dev/tty``), a socket, or a symbolic link to any of them can carry a mesh
suffix; opening one blocks forever (a FIFO no one writes to) or reads without end (``/dev/zero``), so a
``batch`` would hang with its results file locked.  Every file the tool opens because a user or a file named it
— a mesh, a side file a mesh refers to (a glTF buffer or image, an OBJ material library, read through
:func:`regular_file_resolver`), a file hashed for a batch row — goes through :func:`open_regular`:

1. ``os.stat`` (following symbolic links) must say ``S_ISREG``, else :class:`~inertia_tool.errors.MeshReadError`
   naming what the path is;
2. the file is opened with ``O_NONBLOCK``, so that a FIFO put in its place after the check cannot block the
   open, and ``fstat`` of the open descriptor must again say ``S_ISREG`` (what is read is what was checked);
3. ``O_NONBLOCK`` is cleared (it means nothing for a regular file) and the descriptor wrapped as a binary file.

:func:`open_regular_fd` stops after step 2 and returns the descriptor with the ``fstat`` it made: ``inertia-tool
batch`` reads a small file whole with ``os.read`` (stat, open, fstat, read, close: five system calls, where the
buffered file object adds an ``ioctl`` to clear ``O_NONBLOCK``, one to ask whether it is a terminal, a ``seek``,
another ``fstat`` and two more ``read`` calls to find the end).
"""

from __future__ import annotations

import os
import stat
from typing import Any, BinaryIO, TypeAlias

from ..errors import MeshReadError

__all__ = ["open_regular", "open_regular_fd", "check_regular", "not_regular_reason", "regular_file_resolver"]

#: A file name as :func:`os.open` takes it (a ``bytes`` name keeps undecodable bytes).
PathName: TypeAlias = "str | bytes | os.PathLike[str] | os.PathLike[bytes]"

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _display(path: PathName) -> str:
    """A printable form of a file name (undecodable bytes of a non-UTF-8 name become U+FFFD)."""
    return os.fsencode(path).decode("utf-8", "replace")


def not_regular_reason(mode: int, path: PathName | None = None) -> str | None:
    """Why a file of ``mode`` (``st_mode`` of ``os.stat``) is not opened: ``"is a FIFO (named pipe), not a regular
    file"`` (``"is a symbolic link to ..."`` when ``path`` is one), or None for a regular file."""
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
    link = path is not None and os.path.islink(path)
    return f"is {'a symbolic link to ' if link else ''}{kind}, not a regular file"


def check_regular(path: PathName) -> os.stat_result:
    """``os.stat(path)`` of a regular file; :class:`MeshReadError` naming the file and what it is otherwise.

    Raises
    ------
    MeshReadError
        ``path`` is a FIFO, a device, a socket, a directory or a link to one.
    OSError
        ``os.stat`` failed (no such file, permission denied, ...): the caller words it.
    """
    st = os.stat(path)
    reason = not_regular_reason(st.st_mode, path)
    if reason is not None:
        raise MeshReadError(f"{_display(path)}: {reason}")
    return st


def open_regular_fd(path: PathName) -> tuple[int, os.stat_result]:
    """Open a regular file for reading as a raw descriptor, never blocking on what is not one (steps 1 and 2
    of the module docstring).

    Parameters
    ----------
    path : str, bytes or path

    Returns
    -------
    (int, os.stat_result)
        The descriptor (``O_NONBLOCK`` left set: a regular file's reads ignore it; the caller closes it) and
        its ``fstat``, which says it is a regular file (its ``st_size`` is the size when opened).

    Raises
    ------
    MeshReadError
        ``path`` is (or, by the time it is opened, has become) a FIFO, a device, a socket or a directory.
    OSError
        It cannot be opened (no such file, permission denied, ...).
    """
    check_regular(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(path, flags)
    try:
        st = os.fstat(fd)
        reason = not_regular_reason(st.st_mode)
        if reason is not None:
            raise MeshReadError(f"{_display(path)}: {reason} (it changed while being opened)")
        return fd, st
    except BaseException:
        os.close(fd)
        raise


def open_regular(path: PathName) -> BinaryIO:
    """Open a regular file for reading in binary mode, never blocking on what is not one.

    Parameters
    ----------
    path : str, bytes or path

    Returns
    -------
    file
        Binary, buffered, positioned at the start; the caller closes it.

    Raises
    ------
    MeshReadError
        ``path`` is (or, by the time it is opened, has become) a FIFO, a device, a socket or a directory.
    OSError
        It cannot be opened (no such file, permission denied, ...).
    """
    fd, _ = open_regular_fd(path)
    try:
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def regular_file_resolver(path: str) -> Any:
    """A trimesh ``FilePathResolver`` for the side files of ``path`` (glTF buffers and images, OBJ material
    libraries, COLLADA images) that reads each through :func:`open_regular`, restricted to ``path``'s
    directory as trimesh's own: a side file that is a FIFO or a device is a :class:`MeshReadError` naming
    ``path`` and the reference, not a hang."""
    from trimesh.resolvers import FilePathResolver

    class _RegularFileResolver(FilePathResolver):
        def get(self, name: str) -> bytes:
            stripped = name.strip()
            for candidate in (stripped, stripped.lstrip("/"), os.path.split(name)[-1]):
                named = os.path.join(self.parent, candidate)          # before links are followed
                if os.path.lexists(named) and os.path.exists(named):
                    reason = not_regular_reason(os.stat(named).st_mode, named)
                    if reason is not None:
                        raise MeshReadError(f"{_display(path)}: refers to {stripped[:200]!r}, which {reason}")
                try:
                    target = self.absolute(candidate)
                except ValueError:
                    continue
                if os.path.lexists(target):
                    with open_regular(target) as fh:
                        return fh.read()
            try:
                self.absolute(name)
            except ValueError:
                raise MeshReadError(f"{_display(path)}: refers to {stripped[:200]!r}, which lies outside the "
                                    "file's directory (refused)") from None
            raise FileNotFoundError(name)

        def namespaced(self, namespace: str) -> FilePathResolver:
            return _RegularFileResolver(os.path.join(self.parent, namespace), allow_anywhere=self.allow_anywhere)

    return _RegularFileResolver(path)
