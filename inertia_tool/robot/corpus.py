"""Audit every robot description under some folders (a corpus: a Menagerie checkout, a Gazebo model folder, a
ROS workspace) and keep one result per model.

Which files are descriptions: ``*.urdf``, ``*.sdf``, ``*.world`` and ``*.xml`` whose root element is
``<robot>``, ``<sdf>`` or ``<mujoco>`` (read from the first :data:`SNIFF_BYTES` bytes; ``package.xml`` and
other XML are skipped); ``*.xacro`` only when named directly (in a folder they are mostly fragments).  An MJCF
file that another MJCF file of the corpus includes is audited through the including file only (Menagerie's
``scene.xml`` includes the robot); one found in a folder with neither a ``<body>`` nor an ``<include>`` is a
fragment meant to be included (Menagerie's actuator and keyframe files, sites in a ``<worldbody>``) and is
skipped: it has no link to audit.  A Gazebo model folder (a ``model.config`` listing one SDFormat file per
version: ``model-1_2.sdf`` ... ``model.sdf``) is one model: only the newest version, the file Gazebo loads,
is audited.  Folders are
walked in sorted order without following symbolic links, at most :data:`MAX_CORPUS_FILES` descriptions.  A
model that cannot be read is kept with its reason; it never stops the others.
"""

from __future__ import annotations

import os
import re
import warnings

import numpy as np

from ..errors import InertiaToolError, RobotDescriptionError, UsageError
from ..values import frozen_value
from .audit import audit_links
from .description import MAX_DESCRIPTION_BYTES, RobotDescription, _read_bytes, model_config_files, read_robot
from .geometry import MeshCache, link_inertials
from .mjcf import warn_if_nothing_collides

__all__ = ["ModelAudit", "find_descriptions", "audit_corpus", "MAX_CORPUS_FILES", "SNIFF_BYTES"]

#: Most descriptions one corpus run reads.
MAX_CORPUS_FILES = 10_000

#: Bytes read from an ``*.xml`` file to see its root element.
SNIFF_BYTES = 1 << 16

_ROOT = re.compile(rb"<(mujoco|robot|sdf)[\s>/]")
_MODEL_PART = re.compile(rb"<(body|include)[\s>/]")
_INCLUDE = re.compile(rb"<include\s[^>]*file\s*=\s*[\"']([^\"']+)[\"']")


@frozen_value
class ModelAudit:
    """One model of a corpus.

    Attributes
    ----------
    source : str
        The description file.
    robot : RobotDescription or None
        None when it could not be read (``problem`` says why).
    inertials : tuple of LinkInertial
    audits : tuple of LinkAudit
    problem : str or None
    """

    source: str
    robot: RobotDescription | None
    inertials: tuple = ()
    audits: tuple = ()
    problem: str | None = None


def _root_kind(path: str) -> str | None:
    try:
        head = _read_bytes(path, head=SNIFF_BYTES)
    except RobotDescriptionError:          # missing, unreadable, a named pipe or device: read_robot says why
        return None
    head = re.sub(rb"<!--.*?-->", b"", head, flags=re.DOTALL)
    match = _ROOT.search(head)
    return match.group(1).decode() if match else None


def find_descriptions(paths, *, max_files: int = MAX_CORPUS_FILES) -> list:
    """The description files named by ``paths`` (files, or folders walked; see the module docstring)."""
    found: list = []
    explicit: set = set()

    def add(path: str, named: bool) -> None:
        suffix = os.path.splitext(path)[1].lower()
        if named:
            explicit.add(path)
        if suffix in (".urdf", ".sdf", ".world") or (suffix == ".xacro" and named):
            found.append(path)
        elif suffix in (".xml", ".mjcf") and (named or _root_kind(path) is not None):
            found.append(path)
        if len(found) > max_files:
            raise UsageError(f"Expected at most {max_files:,} robot descriptions, found more under "
                             f"{', '.join(map(str, paths))}")

    older: set[str] = set()    # versions of a Gazebo model other than the one its model.config has loaded
    for entry in paths:
        entry = os.fspath(entry)
        if os.path.isdir(entry):
            for folder, subfolders, files in os.walk(entry):
                subfolders.sort()
                if "model.config" in files:
                    try:
                        newest, listed = model_config_files(folder)
                    except RobotDescriptionError:   # an unreadable model.config: every file is audited
                        newest, listed = None, []
                    older.update(p for p in listed if p != newest)
                for name in sorted(files):
                    path = os.path.join(folder, name)
                    if os.path.isfile(path) and not os.path.islink(path):
                        add(path, False)
        else:
            add(entry, True)
    left_out = set()           # included by another file of the corpus, or a fragment
    for path in list(found):
        if os.path.splitext(path)[1].lower() in (".xml", ".mjcf") and _root_kind(path) == "mujoco":
            text = _read_bytes(path, head=MAX_DESCRIPTION_BYTES)
            if path not in explicit and not _MODEL_PART.search(re.sub(rb"<!--.*?-->", b"", text, flags=re.DOTALL)):
                left_out.add(os.path.normpath(path))      # a fragment: actuators, keyframes, sites
                continue
            for name in _INCLUDE.findall(text):
                target = os.path.normpath(os.path.join(os.path.dirname(path), os.fsdecode(name)))
                if target != os.path.normpath(path):
                    left_out.add(target)
    return [p for p in found if os.path.normpath(p) not in left_out
            and (p in explicit or os.path.normpath(p) not in older)]


def _audit_one(path: str, meshes: MeshCache, settings: dict) -> ModelAudit:
    """Read, compute and audit one description (a refusal is kept as the model's ``problem``)."""
    try:
        robot = read_robot(path, packages=settings["packages"], geometry=settings["geometry"],
                           run_xacro=settings["run_xacro"], missing_meshes="per-link")
        warn_if_nothing_collides(robot)      # as the single-file command warns (Apollo's geoms collide only in a scene)
        inertials = link_inertials(robot, density=settings["density"], material=settings["material"],
                                   keep_mass=settings["keep_mass"], repair=settings["repair"], mesh_cache=meshes,
                                   **settings["options"])
        audits = audit_links(robot, inertials, keep_mass=settings["keep_mass"])
    except InertiaToolError as exc:
        return ModelAudit(source=path, robot=None, problem=str(exc))
    return ModelAudit(source=path, robot=robot, inertials=inertials, audits=audits)


#: The mesh bodies a worker process of a parallel corpus run keeps across the folders it is given.
_WORKER_MESHES: MeshCache | None = None


def _audit_folder(paths: list, settings: dict) -> list:
    """In a worker process: ``[(index, ModelAudit, [(warning category, message), ...]), ...]`` for ``paths``
    (``(index, path)`` of the descriptions of one folder), each with the warnings raised while it was audited,
    to be issued again by the parent in the order of a serial run."""
    global _WORKER_MESHES
    if _WORKER_MESHES is None:
        _WORKER_MESHES = MeshCache()
    out = []
    for index, path in paths:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            audit = _audit_one(path, _WORKER_MESHES, settings)
        out.append((index, audit, [(w.category, str(w.message)) for w in caught]))
    return out


def _folder_weight(folder: str, limit: int = 100_000) -> int:
    """Bytes of the files under ``folder`` (at most ``limit`` files looked at): the work a folder's models are
    expected to take, to start the largest first."""
    total = seen = 0
    for root, _, files in os.walk(folder):
        for name in files:
            seen += 1
            if seen > limit:
                return total
            try:
                total += os.path.getsize(os.path.join(root, name))
            except OSError:
                continue
    return total


#: Suffixes of the files :func:`_shared_groups` compares between folders (the mesh formats a description names).
_MESH_SUFFIXES = (".stl", ".obj", ".dae", ".ply", ".off", ".msh", ".3mf", ".glb", ".gltf")


def _shared_groups(folders: list, limit: int = 100_000) -> list:
    """``folders`` in groups that hold mesh files of the same name and size (at most ``limit`` files looked at
    per folder; a sub-folder that is itself one of ``folders`` is left to it): Menagerie's Stretch and Stretch 3
    ship 65 byte-identical meshes, TIAGo and TIAGo dual 12, the two ToddlerBots 35.  A group goes to one worker of a
    parallel run, whose :class:`MeshCache` then integrates (or refuses) each shared file once instead of once per
    worker.  Name and size only choose the grouping; what is shared is still decided by the files' contents.
    Returns lists of folders, each in the order of ``folders``, the groups in the order of their first folder."""
    own = {os.path.abspath(folder) for folder in folders}
    parent = list(range(len(folders)))

    def root(i: int) -> int:
        for _ in range(len(parent)):                # path halving: a chain never outlasts the folders
            if parent[i] == i:
                break
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    seen: dict = {}
    for index, folder in enumerate(folders):
        looked = 0
        for top, subfolders, files in os.walk(folder):
            subfolders[:] = sorted(d for d in subfolders if os.path.abspath(os.path.join(top, d)) not in own)
            for name in files:
                looked += 1
                if looked > limit:
                    break
                if not name.lower().endswith(_MESH_SUFFIXES):
                    continue
                try:
                    key = (name.lower(), os.path.getsize(os.path.join(top, name)))
                except OSError:
                    continue
                other = seen.setdefault(key, index)
                a, b = root(other), root(index)
                if a != b:
                    parent[max(a, b)] = min(a, b)
            if looked > limit:
                break
    groups: dict = {}
    for index, folder in enumerate(folders):
        groups.setdefault(root(index), []).append(folder)
    return list(groups.values())


#: Third-party modules a repair imports (import17: libigl's winding numbers, which import ``scipy.sparse``; the
#: connected components of ``scipy.sparse.csgraph``; ``scipy.spatial``'s trees and hulls; ``scipy.optimize``'s
#: ``linprog``; ``scipy.ndimage``'s labels; pycollada for ``.dae`` meshes), imported by a parallel repair run
#: before its workers fork: ~0.6 s of CPU once instead of once in every worker (issue 25, corpus18).
REPAIR_IMPORTS = ("scipy.sparse.csgraph", "scipy.spatial", "scipy.optimize", "scipy.ndimage", "igl", "collada")


def _import_before_forking(names) -> None:
    """Import the modules ``names`` now, so that forked workers share them; one that is not installed is left
    to the code that needs it (which says so, or does without)."""
    import importlib
    for name in names:
        try:
            importlib.import_module(name)
        except ImportError:
            continue


def audit_corpus(paths, *, density=None, material: str | None = None, keep_mass: bool = False,
                 repair: bool = False, packages: dict | None = None, geometry: str = "collision",
                 run_xacro: bool = False, jobs: int = 1, **options) -> tuple:
    """Read, compute and audit every description under ``paths``; one :class:`ModelAudit` each.

    Parameters are those of :func:`~inertia_tool.robot.read_robot`, :func:`~inertia_tool.robot.link_inertials`
    and :func:`~inertia_tool.robot.audit_links` (``options`` go to ``link_inertials``), and

    jobs : int
        Worker processes (default 1: this process).  With more, the descriptions of each folder go to one
        worker together (a Menagerie folder's scenes share their meshes), and so do folders holding mesh files
        of the same name and size (:func:`_shared_groups`: Stretch and Stretch 3), the groups holding the most
        bytes first; each worker keeps one :class:`MeshCache` for the folders it is given.  The results and every
        model's warnings come back in the order of a serial run, and are the same as its (a mesh shared
        between folders may be integrated once per worker instead of once).  With ``repair`` the parent imports
        :data:`REPAIR_IMPORTS` before the workers fork.
    """
    if not (isinstance(jobs, (int, np.integer)) and not isinstance(jobs, bool) and jobs >= 1):
        raise UsageError(f"Expected `jobs` to be an integer >= 1, got {jobs!r}")
    settings = dict(density=density, material=material, keep_mass=keep_mass, repair=repair, packages=packages,
                    geometry=geometry, run_xacro=run_xacro, options=options)
    found = find_descriptions(paths)
    folders: dict = {}
    for index, path in enumerate(found):
        folders.setdefault(os.path.dirname(os.path.abspath(path)), []).append((index, path))
    if jobs == 1 or len(folders) < 2:
        meshes = MeshCache()             # scene variants and sibling models share mesh files: each integrated once
        return tuple(_audit_one(path, meshes, settings) for path in found)
    from ..batch.runner import _process_pool
    if repair:
        _import_before_forking(REPAIR_IMPORTS)
    done: dict = {}
    weight = {folder: _folder_weight(folder) for folder in folders}
    # the folders sharing mesh files together (each shared file integrated once), the heaviest groups first
    groups = sorted(_shared_groups(list(folders)), key=lambda group: -sum(weight[folder] for folder in group))
    tasks = [[item for folder in group for item in folders[folder]] for group in groups]
    with _process_pool(min(int(jobs), len(tasks))) as pool:
        futures = [pool.submit(_audit_folder, task, settings) for task in tasks]
        for future in futures:
            for index, audit, caught in future.result():
                done[index] = (audit, caught)
    out = []
    for index in range(len(found)):
        audit, caught = done[index]
        for category, message in caught:
            warnings.warn(message, category, stacklevel=2)
        out.append(audit)
    return tuple(out)
