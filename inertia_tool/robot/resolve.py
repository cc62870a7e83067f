"""Where a mesh named by a robot description lives: ``package://``, ``model://``, ``file://`` and plain paths.

Rules, in order (the first that names an existing directory wins; the file must then exist):

* ``package://NAME/rest`` and ``model://NAME/rest``: the directory given for ``NAME`` in ``packages``; else
  each entry ``D`` of ``ROS_PACKAGE_PATH`` (and, for ``model://``, of ``GZ_SIM_RESOURCE_PATH`` and
  ``GAZEBO_MODEL_PATH``) holding ``D/NAME``, or ``D`` itself when its last component is ``NAME``.
* ``file:///abs/path`` is the absolute path; ``file://rel/path`` and a plain relative path are relative to
  ``base`` (the description's directory, or MuJoCo's ``meshdir``); an absolute path is itself.

Any other scheme (``http://`` ...) is refused.  Failures raise :class:`RobotDescriptionError` naming the
description file, the link and the URI as written.
"""

from __future__ import annotations

import os
from urllib.parse import unquote

from ..errors import RobotDescriptionError
from ..mesh.regular import not_regular_reason

__all__ = ["resolve_uri", "package_directory", "PACKAGE_PATH_VARIABLES"]

#: Environment variables searched for ``package://`` (first) and ``model://`` (all three) URIs.
PACKAGE_PATH_VARIABLES = ("ROS_PACKAGE_PATH", "GZ_SIM_RESOURCE_PATH", "GAZEBO_MODEL_PATH")


def package_directory(name: str, packages: dict, *, scheme: str = "package") -> str | None:
    """The directory of package ``name``: ``packages[name]`` or a match on the search path; None if none."""
    if name in packages:
        return os.path.abspath(os.fspath(packages[name]))
    variables = PACKAGE_PATH_VARIABLES if scheme == "model" else PACKAGE_PATH_VARIABLES[:1]
    for var in variables:
        for entry in os.environ.get(var, "").split(os.pathsep):
            if not entry:
                continue
            entry = os.path.abspath(entry)
            if os.path.basename(entry.rstrip(os.sep)) == name and os.path.isdir(entry):
                return entry
            if os.path.isdir(os.path.join(entry, name)):
                return os.path.join(entry, name)
    return None


def resolve_uri(uri: str, *, base: str, packages: dict, source: str, link: str) -> str:
    """Absolute path of the file ``uri`` names (see the module docstring for the rules).

    Parameters
    ----------
    uri : str
        As written in the description (``package://ur_description/meshes/base.stl``).
    base : str
        Directory that relative paths are relative to.
    packages : dict
        Package name → directory.
    source, link : str
        The description file and the link, for the message.

    Raises
    ------
    RobotDescriptionError
        Unknown scheme, unknown package, or no such file.
    """
    where = f"{source}: link {link!r}: mesh {uri!r}"
    text = uri.strip()
    scheme, sep, rest = text.partition("://")
    if not sep:
        path = text if os.path.isabs(text) else os.path.join(base, text)
    elif scheme in ("package", "model"):
        name, _, inner = rest.partition("/")
        directory = package_directory(name, packages, scheme=scheme)
        if directory is None:
            searched = ("ROS_PACKAGE_PATH" if scheme == "package"
                        else "ROS_PACKAGE_PATH, GZ_SIM_RESOURCE_PATH, GAZEBO_MODEL_PATH")
            raise RobotDescriptionError(f"{where}: cannot resolve package {name!r} (not among the packages given, "
                                        f"not found on {searched})")
        path = os.path.join(directory, unquote(inner))
    elif scheme == "file":
        inner = unquote(rest)
        path = inner if os.path.isabs(inner) else os.path.join(base, inner)
    else:
        raise RobotDescriptionError(f"{where}: unsupported URI scheme {scheme!r} (expected package://, model://, "
                                    "file:// or a path)")
    path = os.path.normpath(path)
    if not os.path.isfile(path):
        if os.path.exists(path):             # a FIFO, a device or a link to one: never opened (no hang)
            reason = not_regular_reason(os.stat(path).st_mode, path) or "is not a regular file"
            raise RobotDescriptionError(f"{where}: resolves to {path}, which {reason}")
        raise RobotDescriptionError(f"{where}: resolves to {path}, which does not exist")
    return path
