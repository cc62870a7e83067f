"""Where a mesh named by a robot description lives: ``package://``, ``model://``, ``file://`` and plain paths.

Rules, in order (the first that names an existing directory wins; the file must then exist):

* ``package://NAME/rest`` and ``model://NAME/rest``: the directory given for ``NAME`` in ``packages``; else
  each entry ``D`` of ``ROS_PACKAGE_PATH`` (and, for ``model://``, of ``GZ_SIM_RESOURCE_PATH`` and
  ``GAZEBO_MODEL_PATH``) holding ``D/NAME``, or ``D`` itself when its last component is ``NAME``; else
  the folders around the description, without any environment variable: walking up from ``base`` (at most
  :data:`MAX_FOLDERS_UP` levels), a folder ``A`` that is the package (its name is ``NAME`` and, for
  ``package://``, it holds a ``package.xml``; or its ``package.xml`` names ``NAME``) or holds it as
  ``A/NAME`` (a sibling model of a Gazebo model folder, a sibling package of a ROS workspace).
* ``package:///NAME/rest`` (three slashes) is read as ``package://NAME/rest``.
* Last, for ``package://`` only: a plain folder ``NAME`` in the description's own directory (``base``) that holds
  ``rest`` and no ``package.xml`` naming another package (MuJoCo Menagerie's Barkour vb URDF writes
  ``package://assets/neck.stl`` for the ``assets/`` folder beside it).  ROS would not resolve such a URI, so
  the file is read with a :class:`~inertia_tool.errors.PackageFolderWarning` saying so; nothing above
  ``base`` is guessed.
* ``file:///abs/path`` is the absolute path; ``file://rel/path`` and a plain relative path are relative to
  ``base`` (the description's directory, or MuJoCo's ``meshdir``); an absolute path is itself.

Any other scheme (``http://`` ...) is refused.  Failures raise :class:`RobotDescriptionError` naming the
description file, the link and the URI as written.  A file that does not exist is never replaced by another
one, but the message names a near match when there is one (:func:`near_match`): the same path in another case
(``Meshes/Base.STL`` for ``meshes/base.stl``: the same file on a case-insensitive file system, not on Linux), the
same name with another mesh extension, or the same file name in a sibling folder of the first folder that does
not exist (Menagerie's Barkour v0 URDF names ``meshes/head.stl``; the file is ``assets/head.stl``).
"""

from __future__ import annotations

import os
import warnings
from urllib.parse import unquote

from ..errors import PackageFolderWarning, RobotDescriptionError
from ..mesh.regular import not_regular_reason

__all__ = ["resolve_uri", "package_directory", "nearby_package", "near_match", "PACKAGE_PATH_VARIABLES",
           "MAX_FOLDERS_UP", "MESH_EXTENSIONS"]

#: How many folders above a description are searched for a package or model it names.
MAX_FOLDERS_UP = 8

#: Mesh file extensions :func:`near_match` tries in place of a missing file's own (lower case).
MESH_EXTENSIONS = (".stl", ".obj", ".dae", ".ply", ".off", ".glb", ".gltf", ".3mf")

#: At most this many entries of one folder are listed by :func:`near_match` (a hint must not cost a scan).
_NEAR_LISTING = 4096

#: Environment variables searched for ``package://`` (first) and ``model://`` (all three) URIs.
PACKAGE_PATH_VARIABLES = ("ROS_PACKAGE_PATH", "GZ_SIM_RESOURCE_PATH", "GAZEBO_MODEL_PATH")


def _package_xml_name(folder: str) -> str | None:
    """The ``<name>`` a ROS ``package.xml`` in ``folder`` declares; None without one (or unreadable)."""
    path = os.path.join(folder, "package.xml")
    if not os.path.isfile(path) or os.path.getsize(path) > 1 << 20:
        return None
    try:
        with open(path, "rb") as fh:
            text = fh.read().decode("utf-8", errors="replace")
    except OSError:
        return None
    start, end = text.find("<name>"), text.find("</name>")
    return text[start + 6:end].strip() if 0 <= start < end else None


def _is_package(folder: str, name: str, scheme: str) -> bool:
    if not os.path.isdir(folder):
        return False
    declared = _package_xml_name(folder)
    if declared is not None:
        return declared == name
    return scheme == "model" and os.path.basename(folder.rstrip(os.sep)) == name


def nearby_package(name: str, near: str, *, scheme: str = "package", max_up: int = MAX_FOLDERS_UP) -> str | None:
    """The folder of package (or Gazebo model) ``name`` around the folder ``near``, walking up (see the module
    docstring); None when none is found."""
    folder = os.path.abspath(near)
    for _ in range(max_up + 1):
        for candidate in (folder, os.path.join(folder, name)):
            if _is_package(candidate, name, scheme):
                return candidate
        parent = os.path.dirname(folder)
        if parent == folder:
            break
        folder = parent
    return None


def package_directory(name: str, packages: dict, *, scheme: str = "package", near: str | None = None) -> str | None:
    """The directory of package ``name``: ``packages[name]``, a match on the search path, or (given ``near``,
    a folder) one found around it by :func:`nearby_package`; None if none."""
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
    return nearby_package(name, near, scheme=scheme) if near is not None else None


def _plain_folder(name: str, inner: str, base: str, where: str) -> str | None:
    """The folder ``base/name`` when it is no package of another name and holds ``inner`` (the last rule of the
    module docstring), with a :class:`PackageFolderWarning`; None otherwise."""
    folder = os.path.join(os.path.abspath(base), name)
    declared = _package_xml_name(folder) if os.path.isdir(folder) else None
    if not os.path.isdir(folder) or declared not in (None, name) or not os.path.isfile(os.path.join(folder, inner)):
        return None
    warnings.warn(PackageFolderWarning(f"{where}: no ROS package {name!r} found; read from the folder {folder} "
                                       "beside the description (ROS tools would not resolve this URI)"),
                  stacklevel=4)
    return folder


def _listing(folder: str) -> list[str]:
    """The names in ``folder``, sorted (at most :data:`_NEAR_LISTING`); empty when it cannot be listed."""
    try:
        with os.scandir(folder) as entries:
            names = []
            for entry in entries:
                names.append(entry.name)
                if len(names) >= _NEAR_LISTING:
                    break
    except OSError:
        return []
    return sorted(names)


def _case_walk(folder: str, parts: list[str]) -> str | None:
    """``folder`` joined with ``parts``, each part matched without regard to case (the first in sorted order
    when several match); None when a part has no match or the result is not a regular file."""
    for k, part in enumerate(parts):
        if part in (".", ".."):
            folder = os.path.normpath(os.path.join(folder, part))
            continue
        names = [n for n in _listing(folder) if n.casefold() == part.casefold()]
        if not names:
            return None
        folder = os.path.join(folder, names[0])
        if k < len(parts) - 1 and not os.path.isdir(folder):
            return None
    return folder if os.path.isfile(folder) else None


def near_match(path: str) -> str | None:
    """A hint for a mesh path that does not exist: ``"near match: P (...)"`` naming an existing file ``P``
    that the author may have meant, or None.  Tried in order, and never used in place of ``path``:

    1. the same path with every component matched without regard to case;
    2. in the folder the file should be in (matched without regard to case), the same stem with another
       extension of :data:`MESH_EXTENSIONS` (``part.STL`` for ``part.obj``);
    3. the same file name (without regard to case) in a sibling of the first folder of ``path`` that does not
       exist (``assets/head.stl`` for ``meshes/head.stl``).

    Each folder is listed at most once per rule, and at most :data:`_NEAR_LISTING` of its entries.
    """
    path = os.path.abspath(path)
    existing = path
    missing: list[str] = []
    for _ in range(256):                     # bounded: a path has fewer components than this
        if os.path.isdir(existing) or os.path.dirname(existing) == existing:
            break
        existing, tail = os.path.split(existing)
        missing.insert(0, tail)
    if not missing:
        return None
    found = _case_walk(existing, missing)
    if found is not None:
        return f"near match: {found} (differs in case only; this file system tells case apart)"
    stem, ext = os.path.splitext(missing[-1])
    folder = _case_walk_folder(existing, missing[:-1])
    if folder is not None:
        for name in _listing(folder):
            other_stem, other_ext = os.path.splitext(name)
            if (other_stem.casefold() == stem.casefold() and other_ext.lower() in MESH_EXTENSIONS
                    and other_ext.lower() != ext.lower() and os.path.isfile(os.path.join(folder, name))):
                return f"near match: {os.path.join(folder, name)} (another extension)"
    if len(missing) > 1:
        for sibling in _listing(existing):
            candidate = os.path.join(existing, sibling)
            if sibling == missing[0] or not os.path.isdir(candidate):
                continue
            found = _case_walk(candidate, missing[1:])
            if found is not None:
                return (f"near match: {found} (the folder {missing[0]}/ does not exist beside "
                        f"{os.path.basename(existing) or existing}/; a file of that name is in {sibling}/)")
    return None


def _case_walk_folder(folder: str, parts: list[str]) -> str | None:
    """The folder ``folder`` joined with ``parts`` matched without regard to case; None when there is none."""
    for part in parts:
        names = [n for n in _listing(folder)
                 if n.casefold() == part.casefold() and os.path.isdir(os.path.join(folder, n))]
        if not names:
            return None
        folder = os.path.join(folder, names[0])
    return folder


def resolve_uri(uri: str, *, base: str, packages: dict, source: str, link: str, missing: str = "refuse") -> str:
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
    missing : {"refuse", "per-link"}
        A path that resolves but names nothing on disk: refused (default), or returned as it is, for the link
        to say which file is absent (``read_robot(missing_meshes="per-link")``).  An unknown package or scheme,
        and a path that names something other than a regular file, are refused either way.

    Raises
    ------
    RobotDescriptionError
        Unknown scheme, unknown package, or no such file (with ``missing="refuse"``).
    """
    where = f"{source}: link {link!r}: mesh {uri!r}"
    text = uri.strip()
    scheme, sep, rest = text.partition("://")
    if not sep:
        path = text if os.path.isabs(text) else os.path.join(base, text)
    elif scheme in ("package", "model"):
        # ``package:///NAME/rest`` (an empty authority: example-robot-data's talos_full_v2.urdf): the package
        # is the first path component all the same
        name, _, inner = rest.lstrip("/").partition("/")
        directory = package_directory(name, packages, scheme=scheme, near=base)
        if directory is None and scheme == "package":
            directory = _plain_folder(name, unquote(inner), base, where)
        if directory is None:
            searched = ("ROS_PACKAGE_PATH" if scheme == "package"
                        else "ROS_PACKAGE_PATH, GZ_SIM_RESOURCE_PATH, GAZEBO_MODEL_PATH")
            raise RobotDescriptionError(f"{where}: cannot resolve package {name!r} (not among the packages given, "
                                        f"not found on {searched} nor in the {MAX_FOLDERS_UP} folders above "
                                        "the description)")
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
        if missing == "per-link":
            return path
        hint = near_match(path)
        raise RobotDescriptionError(f"{where}: resolves to {path}, which does not exist"
                                    + (f"; {hint}" if hint else ""))
    return path
