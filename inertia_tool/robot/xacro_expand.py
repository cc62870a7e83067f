"""xacro expansion, the part that runs in the isolated child process (:mod:`inertia_tool.isolate`).

:func:`expand_here` is the function the child runs: it imports xacro and this module only, not numpy or the
description readers (the child starts a fresh interpreter, and each module it imports is CPU the parent waits
for: ~0.3 s of the 0.4 s a UR5e's expansion cost when the function lived in
:mod:`~inertia_tool.robot.description`, issue 23).  ``$(find NAME)`` resolves through
:func:`~inertia_tool.robot.resolve.package_directory`, as every other package reference does.
"""

from __future__ import annotations

import contextlib
import os
import re

from ..errors import RobotDescriptionError
from .resolve import MAX_FOLDERS_UP, package_directory

__all__ = ["expand_here", "XACRO_MESSAGE_CHARS"]


def _fail(source: str, problem: str) -> RobotDescriptionError:
    """The error of every robot description reader (imported by :mod:`~inertia_tool.robot.description`)."""
    return RobotDescriptionError(f"{source}: {problem}")


@contextlib.contextmanager
def _xacro_find(packages: dict, near: str, problems: list):
    """Make xacro's ``$(find NAME)`` use ``packages``, ROS_PACKAGE_PATH and the folders around ``near`` (the
    xacro file's folder: a ``package.xml`` naming ``NAME`` up the tree, or beside it) instead of an installed
    ROS.  A package not found is appended to ``problems`` (xacro wraps the exception in its own words)."""
    from xacro import substitution_args
    original = substitution_args._eval_find

    def find(name):
        directory = package_directory(name, packages, near=near)
        if directory is None:
            problem = (f"$(find {name}): package {name!r} is not among the packages given, not on "
                       f"ROS_PACKAGE_PATH, and no package.xml naming it in the {MAX_FOLDERS_UP} folders above")
            problems.append(problem)
            raise RobotDescriptionError(problem)
        return directory

    substitution_args._eval_find = find
    try:
        yield
    finally:
        substitution_args._eval_find = original


#: Longest xacro failure text quoted in a message (cut at a word, marked with an ellipsis).
XACRO_MESSAGE_CHARS = 300


def _xacro_message(exc: BaseException) -> str:
    """xacro's failure in one line: without Python class names (``<class '...'>: ``), each sentence once, cut
    at a word boundary."""
    text = " ".join(str(exc).split()) or "unknown failure"
    text = re.sub(r"<class '[\w.]+'>:\s*", "", text)
    text = re.sub(r"\b[\w.]*(Error|Exception): ", "", text)
    pieces: list = []
    for piece in re.split(r"(?<=[.)])\s+|\s+(?=\$\()", text):
        if piece and piece not in pieces:
            pieces.append(piece)
    text = " ".join(pieces)
    if len(text) > XACRO_MESSAGE_CHARS:
        cut = text.rfind(" ", 0, XACRO_MESSAGE_CHARS)
        text = text[:cut if cut > 0 else XACRO_MESSAGE_CHARS].rstrip(" ,;:") + " …"
    return text


def expand_here(path: str, mappings: dict, packages: dict) -> bytes:
    """The expanded URDF of the xacro file ``path``, expanded in this process: only ever called in the isolated
    child (:func:`inertia_tool.robot.description.read_robot` with ``run_xacro=True``)."""
    try:
        import xacro
    except ImportError:
        raise _fail(path, "expanding xacro needs the xacro package (pip install xacro)") from None
    problems: list = []
    try:
        with _xacro_find(packages, os.path.dirname(os.path.abspath(path)), problems):
            doc = xacro.process_file(path, mappings={str(k): str(v) for k, v in mappings.items()})
    except RobotDescriptionError as exc:
        raise _fail(path, problems[0] if problems else str(exc)) from None
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - xacro raises many kinds; all mean "cannot expand"
        if isinstance(exc.__context__, MemoryError) or isinstance(exc.__cause__, MemoryError):
            raise MemoryError from None     # xacro wraps errors of expressions; a memory limit stays one
        if problems:                       # our own $(find) failure, wrapped by xacro: say it once, as we said it
            raise _fail(path, problems[0]) from None
        raise _fail(path, f"xacro expansion failed: {_xacro_message(exc)}") from None
    return doc.toxml(encoding="utf-8")
