"""Coverage-guided fuzzing of every mesh reader and robot-description parser, with atheris (libFuzzer).

Every module of ``inertia_tool`` (the readers, the mesh checks and the robot parsers among them) and the
third-party readers it calls for 3MF, glTF/GLB, PLY/OFF and COLLADA (``trimesh.exchange``, ``collada``) are
imported inside ``atheris.instrument_imports()``, so the coverage feedback reaches the parsing code (the older
``fuzz_analyze.py`` saw 58 edges: its block imported only the command line, whose readers load lazily).

The first byte of an input chooses the format (:data:`FORMATS`: STL, OBJ, PLY, OFF, 3MF, glTF, GLB, COLLADA,
URDF, SDF, MJCF; no xacro, whose expansion runs code from the file); the rest is written to a file with that
suffix and read through the API: :func:`inertia_tool.mass_properties` for a mesh, ``read_robot`` →
``link_inertials`` → ``audit_links`` for a robot.  The invariant (:func:`check_one`): every input either gives
a result with finite numbers or raises one of the project's named errors (a subclass of ``InertiaToolError``
other than the bare base, i.e. an exit code 2, 3 or 4 on the command line); anything else — another exception,
a non-finite number in an accepted result, an input running past the time bound — is a finding.

Run (the committed seeds in ``fuzz/corpus/``, 2,000 inputs, 10 s per input at most)::

    python fuzz/fuzz_readers.py -atheris_runs=2000 -timeout=10 -rss_limit_mb=3072 fuzz/work

``fuzz/work`` is created and seeded from ``fuzz/corpus/`` (each seed prefixed with its format byte).  CI runs
a short budget of it (``tests/test_fuzz_readers.py``) when atheris is installed, and without atheris a replay
of the corpus plus hypothesis-generated mutations through the same :func:`check_one`.  Every finding becomes a
file in ``tests/regressions/`` replayed by ``tests/test_fuzz_readers.py``.
"""

from __future__ import annotations

import atexit
import math
import os
import shutil
import signal
import sys
import tempfile
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "corpus")
if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
from instrumented import INCLUDE, import_readers  # noqa: E402

if __name__ == "__main__":
    import atheris

    with atheris.instrument_imports(include=list(INCLUDE)):
        import_readers()
else:
    import_readers()

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.errors import InertiaToolError  # noqa: E402
from inertia_tool.robot.audit import audit_links  # noqa: E402
from inertia_tool.robot.description import read_robot  # noqa: E402
from inertia_tool.robot.geometry import link_inertials  # noqa: E402

#: The formats, by the first byte of an input (modulo their count); ``.xml`` is MJCF.
FORMATS = (".stl", ".obj", ".ply", ".off", ".3mf", ".gltf", ".glb", ".dae", ".urdf", ".sdf", ".xml")
ROBOT_FORMATS = (".urdf", ".sdf", ".xml")

#: The face limit of the meshes read here: enough for every seed and its mutations, small enough that a lying
#: count is refused rather than allocated.
MAX_FACES = 200_000

#: Longest time one input may take in the replay (s); under atheris, libFuzzer's ``-timeout`` does this.
TIME_LIMIT = 10.0

_TMP = tempfile.mkdtemp(prefix="inertia-fuzz-readers-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
atexit.register(shutil.rmtree, _TMP, ignore_errors=True)


class Finding(Exception):
    """The tool misbehaved on this input."""


class _TimeUp(BaseException):
    """Raised by the replay's alarm: the input ran past :data:`TIME_LIMIT` (a BaseException, so that no
    ``except Exception`` of the code under test swallows it)."""


def format_of(suffix: str) -> str:
    """The file suffix a seed's name stands for (``seed-mjcf.xml`` → ``.xml``)."""
    return os.path.splitext(suffix)[1].lower()


def _numbers(x):
    if isinstance(x, (list, tuple)):
        for v in x:
            yield from _numbers(v)
    elif x is not None:
        import numpy as np
        for v in np.asarray(x, dtype=float).ravel().tolist():
            yield v


def _check_mesh(path: str) -> str:
    props = mass_properties(path, max_faces=MAX_FACES)
    if not (math.isfinite(props.mass) and props.mass > 0 and math.isfinite(props.volume) and props.volume > 0):
        raise Finding(f"accepted with mass {props.mass!r}, volume {props.volume!r}")
    if not all(math.isfinite(v) for v in _numbers([props.center_of_mass, props.inertia])):
        raise Finding("accepted with a non-finite centre of mass or inertia")
    return "result"


def _check_robot(path: str) -> str:
    robot = read_robot(path, geometry="collision")
    inertials = link_inertials(robot, density=1000.0)
    audit_links(robot, inertials)
    for r in inertials:
        p = r.properties
        if p is not None and not all(math.isfinite(v) for v in _numbers([p.mass, p.center_of_mass, p.inertia])):
            raise Finding(f"link {r.name!r} accepted with a non-finite number")
    return "result"


def check_one(data: bytes, suffix: str, *, time_limit: float | None = TIME_LIMIT) -> str:
    """Read ``data`` saved with ``suffix``: ``"result"``, or ``"refused: ErrorClass"`` for a named error.

    Raises :class:`Finding` on anything else: an exception that is not a named error of the project (or is
    the bare ``InertiaToolError``, an internal error on the command line), a non-finite number in an accepted
    result, or (with ``time_limit``, SIGALRM on POSIX) an input that runs longer than ``time_limit`` seconds.
    """
    path = os.path.join(_TMP, "input" + suffix)
    with open(path, "wb") as fh:
        fh.write(data)
    use_alarm = time_limit is not None and hasattr(signal, "setitimer")
    if use_alarm:
        def _alarm(signum, frame):
            raise _TimeUp()
        previous = signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, time_limit)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return _check_robot(path) if suffix in ROBOT_FORMATS else _check_mesh(path)
    except _TimeUp:
        raise Finding(f"no answer within {time_limit:g} s") from None
    except Finding:
        raise
    except InertiaToolError as exc:
        if type(exc) is InertiaToolError:
            raise Finding(f"bare InertiaToolError (an internal error): {exc}") from exc
        return f"refused: {type(exc).__name__}"
    except Exception as exc:  # noqa: BLE001 - the finding is exactly this
        raise Finding(f"{type(exc).__name__}: {str(exc)[:300]}") from exc
    finally:
        if use_alarm:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)


def seeds(corpus: str = CORPUS) -> list[tuple[str, bytes]]:
    """``(suffix, bytes)`` of every seed in ``corpus``, sorted by name."""
    out = []
    for name in sorted(os.listdir(corpus)):
        suffix = format_of(name)
        if suffix in FORMATS:
            with open(os.path.join(corpus, name), "rb") as fh:
                out.append((suffix, fh.read()))
    return out


def TestOneInput(data: bytes) -> None:
    if not data:
        return
    check_one(data[1:], FORMATS[data[0] % len(FORMATS)], time_limit=None)    # libFuzzer's -timeout bounds it


def seed_directory(work: str, corpus: str = CORPUS) -> None:
    """Copy the seeds into libFuzzer's corpus directory ``work``, each prefixed with its format byte."""
    os.makedirs(work, exist_ok=True)
    for k, (suffix, data) in enumerate(seeds(corpus)):
        with open(os.path.join(work, f"seed-{k:02d}{suffix}"), "wb") as fh:
            fh.write(bytes([FORMATS.index(suffix)]) + data)


if __name__ == "__main__":
    argv = sys.argv[1:]
    work = [a for a in argv if not a.startswith("-")]
    if not work:
        work = [os.path.join(HERE, "work")]
        argv.append(work[0])
    seed_directory(work[0])
    try:
        atheris.Setup([sys.argv[0]] + argv, TestOneInput)
        atheris.Fuzz()
    finally:
        shutil.rmtree(_TMP, ignore_errors=True)
