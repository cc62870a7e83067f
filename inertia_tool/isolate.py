"""Run work on untrusted input in a child process with CPU-time, memory and wall-clock limits.

Some third-party parsers are not safe to run inside the tool's own process: xacro evaluates Python
expressions from the file (it *runs code*, and ``${9**9**9}`` never ends), and OpenCASCADE can crash with a
segmentation fault on a malformed STEP file or spend minutes and gigabytes on a large one.  :func:`run_isolated`
runs one top-level function in a fresh Python interpreter (``python -I``) and returns its value, so that

* a crash (a signal), a CPU-time limit (``RLIMIT_CPU``), a memory limit (``RLIMIT_AS``, the address space) or a
  wall-clock limit becomes an :class:`~inertia_tool.errors.IsolatedProcessError` whose ``reason`` says which,
  instead of taking the tool (or a whole batch) down;
* the child inherits no secrets: its environment is a small allow-list (:data:`ENVIRONMENT_ALLOW_LIST`), its
  stdin is closed (``/dev/null``), its stdout discarded (OpenCASCADE prints banners there), its stderr goes to
  a file of which the last few KB are kept for a message (any file it writes is capped at the memory limit,
  ``RLIMIT_FSIZE``), and it runs in its own session, so the wall-clock limit kills everything it started.

This is resource isolation, not a sandbox: the child runs as the same user.  Code that the user has asked to run
(``--run-xacro``) can still do what that user can do; the limits only stop it from hanging or exhausting the
machine.  Where the ``resource`` module is missing (Windows) the CPU and memory limits are not applied; the wall
clock and the crash isolation still are.

Protocol.  The parent pickles ``(function, args, kwargs)`` into a private temporary directory; the child
unpickles it, runs it and pickles ``("ok", value)`` or ``("error", class name, message)`` back.  The parent
unpickles the child's answer with a restricted unpickler (plain Python values and numpy arrays only), so a
child that ran hostile code cannot make the parent run any by what it writes back.

Limits (:class:`Limits`) have per-use defaults (:data:`XACRO_LIMITS`, :data:`CAD_LIMITS`); the environment
variables ``INERTIA_TOOL_CPU_LIMIT`` (seconds), ``INERTIA_TOOL_MEMORY_LIMIT`` (bytes, or with a ``K``/``M``/``G``
suffix) and ``INERTIA_TOOL_WALL_LIMIT`` (seconds) override them for every isolated job.
"""

from __future__ import annotations

import errno
import io
import json
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass, replace
from collections.abc import Mapping
from typing import Any, Callable

from .errors import IsolatedProcessError, UsageError
from .units import DECIMAL

__all__ = ["Limits", "run_isolated", "limits_from_environment", "XACRO_LIMITS", "CAD_LIMITS",
           "ENVIRONMENT_ALLOW_LIST"]


# a plain frozen dataclass, not :func:`~inertia_tool.values.frozen_value`: the child imports this module, and
# ``values`` imports numpy (~0.15 s of the xacro child's CPU; the fields are numbers, nothing to make read-only)
@dataclass(frozen=True)
class Limits:
    """Resource limits of one isolated job.

    Attributes
    ----------
    cpu_seconds : float
        CPU time (user + system) of the child, s (``RLIMIT_CPU``; the child gets ``SIGXCPU``).
    memory_bytes : int
        Address space of the child, bytes (``RLIMIT_AS``): everything it maps, the interpreter and its
        libraries included, so it must leave a few hundred MB above the data the job needs.
    wall_seconds : float
        Elapsed time, s, after which the child and everything it started are killed.
    """

    cpu_seconds: float
    memory_bytes: int
    wall_seconds: float


#: xacro expansion: a description of a few hundred links expands in well under a second.
XACRO_LIMITS = Limits(cpu_seconds=30.0, memory_bytes=1 << 30, wall_seconds=60.0)

#: OpenCASCADE reading, tessellating and integrating a STEP/IGES part: large assemblies take minutes.
CAD_LIMITS = Limits(cpu_seconds=300.0, memory_bytes=6 << 30, wall_seconds=600.0)

#: Environment variables the child keeps; every other one (tokens, credentials, ``LD_PRELOAD`` ...) is dropped.
ENVIRONMENT_ALLOW_LIST = ("PATH", "HOME", "LANG", "LC_ALL", "LC_CTYPE", "TMPDIR", "TEMP", "TMP", "SYSTEMROOT",
                          "ROS_PACKAGE_PATH")

#: Threads of numerical libraries in the child: one (each thread reserves address space under ``RLIMIT_AS``).
_CHILD_THREADS = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

#: Largest part of the child's stderr kept for a message.
_STDERR_KEEP = 4000

_ENV_CPU, _ENV_MEMORY, _ENV_WALL = "INERTIA_TOOL_CPU_LIMIT", "INERTIA_TOOL_MEMORY_LIMIT", "INERTIA_TOOL_WALL_LIMIT"

_MEMORY_SUFFIXES = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30}


#: Largest limits accepted: seconds (about 30 years) and bytes (``setrlimit`` takes a C long; a larger value
#: made the child fail before running the job).
_MOST_SECONDS = 1e9
_MOST_BYTES = 1 << 62



def _positive(name: str, text: str) -> float:
    text = text.strip()
    value = float(text) if DECIMAL.fullmatch(text) else float("nan")     # no 1_0, inf, nan
    if not 0 < value <= _MOST_SECONDS:
        raise UsageError(f"Expected {name} to be a number of seconds above 0 and at most {_MOST_SECONDS:g}, "
                         f"got {text!r}")
    return value


def limits_from_environment(default: Limits, environ: Mapping[str, str] | None = None) -> Limits:
    """``default`` with the ``INERTIA_TOOL_{CPU,MEMORY,WALL}_LIMIT`` variables of ``environ`` applied.

    Raises
    ------
    UsageError
        A variable that is set but is not a positive number (memory: an integer with an optional ``K``, ``M``
        or ``G`` suffix).
    """
    if environ is None:
        environ = os.environ
    limits = default
    if environ.get(_ENV_CPU):
        limits = replace(limits, cpu_seconds=_positive(_ENV_CPU, environ[_ENV_CPU]))
    if environ.get(_ENV_WALL):
        limits = replace(limits, wall_seconds=_positive(_ENV_WALL, environ[_ENV_WALL]))
    if environ.get(_ENV_MEMORY):
        text = environ[_ENV_MEMORY].strip().upper().removesuffix("B")
        suffix = text[-1:] if text[-1:] in _MEMORY_SUFFIXES else ""
        number = text[:-1] if suffix else text
        memory = int(number) * _MEMORY_SUFFIXES[suffix] if number.isascii() and number.isdigit() else 0
        if not 0 < memory <= _MOST_BYTES:
            raise UsageError(f"Expected {_ENV_MEMORY} to be a number of bytes above 0 and at most 2^62 (e.g. 2G, "
                             f"512M), got {environ[_ENV_MEMORY]!r}")
        limits = replace(limits, memory_bytes=memory)
    return limits


def _child_environment() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k in ENVIRONMENT_ALLOW_LIST}
    env.update(_CHILD_THREADS)
    return env


def _size(n: float) -> str:
    return f"{n / (1 << 30):g} GiB" if n >= 1 << 30 else f"{n / (1 << 20):g} MiB"


# -- the parent's side -------------------------------------------------------------------------------------

_CHILD_CODE = ("import sys, json; sys.path[:] = json.loads(sys.argv[1]); "
               "from inertia_tool.isolate import _child_main; _child_main(sys.argv[2])")


def run_isolated(function: Callable[..., Any], *args: Any, limits: Limits = CAD_LIMITS, what: str = "the job",
                 **kwargs: Any) -> Any:
    """``function(*args, **kwargs)`` run in a child process under ``limits``; its return value.

    Parameters
    ----------
    function : callable
        A module-level function (pickled by reference; the child imports its module).
    *args, **kwargs
        Its arguments: picklable.  Its return value must be made of ``None``, ``bool``, ``int``, ``float``,
        ``str``, ``bytes``, tuples, lists, dicts and numpy arrays (the parent accepts nothing else).
    limits : Limits
        CPU time, memory and wall clock of the child; the environment overrides them
        (:func:`limits_from_environment`).
    what : str
        What the child does, for the messages ("xacro expansion", "OpenCASCADE").

    Raises
    ------
    IsolatedProcessError
        The child crashed (a signal), hit a limit, or exited without an answer; ``reason`` says which.
    InertiaToolError
        The function raised one of the package's errors: the same class with the same message.
    """
    limits = limits_from_environment(limits)
    workdir = tempfile.mkdtemp(prefix="inertia-tool-isolate-")
    try:
        job, answer = os.path.join(workdir, "job.pickle"), os.path.join(workdir, "answer.pickle")
        with open(job, "wb") as fh:
            pickle.dump({"function": function, "args": args, "kwargs": kwargs, "answer": answer,
                         "cpu": limits.cpu_seconds, "memory": limits.memory_bytes}, fh)
        command = [sys.executable, "-I", "-c", _CHILD_CODE, json.dumps(sys.path), job]
        # stderr goes to a file (its size capped by RLIMIT_FSIZE in the child), never into this process's memory
        with open(os.path.join(workdir, "stderr"), "w+b") as stderr_file:
            process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                       stderr=stderr_file, env=_child_environment(), start_new_session=True)
            try:
                process.wait(timeout=limits.wall_seconds)
            except subprocess.TimeoutExpired:
                _kill_group(process)
                process.wait()
                raise IsolatedProcessError(f"{what} took longer than {limits.wall_seconds:g} s (wall clock; set "
                                           f"{_ENV_WALL} to allow more)", kind="wall") from None
            except BaseException:            # KeyboardInterrupt: leave no child behind
                _kill_group(process)
                process.wait()
                raise
            _kill_group(process)             # anything the job started and left running
            stderr_file.seek(max(0, os.fstat(stderr_file.fileno()).st_size - _STDERR_KEEP))
            stderr = stderr_file.read(_STDERR_KEEP)
        return _outcome(process.returncode, answer, stderr, limits, what)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def _kill_group(process: subprocess.Popen[bytes]) -> None:
    if hasattr(os, "killpg"):
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    elif process.poll() is None:
        process.kill()


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def _outcome(returncode: int, answer: str, stderr: bytes, limits: Limits, what: str) -> Any:
    last = " ".join(stderr[-_STDERR_KEEP:].decode("utf-8", "replace").split())[-300:]
    if returncode < 0:
        name = _signal_name(-returncode)
        if name == "SIGXCPU":
            raise IsolatedProcessError(f"{what} exceeded {limits.cpu_seconds:g} s of CPU (set {_ENV_CPU} to "
                                       "allow more)", kind="cpu")
        hint = {"SIGSEGV": "segmentation fault", "SIGBUS": "bus error", "SIGILL": "illegal instruction",
                "SIGABRT": f"aborted; possibly out of memory under the {_size(limits.memory_bytes)} limit",
                "SIGKILL": "killed; possibly by the system's out-of-memory killer"}
        detail = hint.get(name, "killed by a signal")
        raise IsolatedProcessError(f"{what} crashed ({name}, {detail})", kind="crash")
    try:
        with open(answer, "rb") as fh:
            outcome = _RestrictedUnpickler(fh).load()
    except FileNotFoundError:
        raise IsolatedProcessError(f"{what} ended without an answer (exit code {returncode}"
                                   + (f": {last}" if last else "") + ")", kind="crash") from None
    except (pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError, ValueError) as exc:
        raise IsolatedProcessError(f"{what} gave an answer that cannot be read ({exc})", kind="crash") from None
    if not isinstance(outcome, tuple) or not outcome:
        raise IsolatedProcessError(f"{what} gave an answer that cannot be read", kind="crash")
    if outcome[0] == "ok" and len(outcome) == 2:
        return outcome[1]
    if outcome[0] == "file":
        raise IsolatedProcessError(f"{what} wrote more than {_size(limits.memory_bytes)} (the memory limit) to a "
                                   "file or to its error output", kind="memory")
    if outcome[0] == "memory":
        raise IsolatedProcessError(f"{what} exceeded the memory limit of {_size(limits.memory_bytes)} (set "
                                   f"{_ENV_MEMORY} to allow more)", kind="memory")
    if outcome[0] == "error" and len(outcome) == 3:
        raise _rebuild_error(str(outcome[1]), str(outcome[2]), what)
    raise IsolatedProcessError(f"{what} gave an answer that cannot be read", kind="crash")


def _rebuild_error(name: str, message: str, what: str) -> Exception:
    from . import errors
    cls = getattr(errors, name, None)
    if isinstance(cls, type) and issubclass(cls, errors.InertiaToolError) and name in errors.__all__:
        try:
            return cls(message)
        except TypeError:        # a class with another constructor: keep the message
            pass
    return IsolatedProcessError(f"{what} failed ({name}: {message})", kind="error")


#: What the parent accepts from the child's pickle: numpy arrays and scalars; builtins need no lookup.
_ALLOWED_GLOBALS = {
    ("numpy.core.multiarray", "_reconstruct"), ("numpy._core.multiarray", "_reconstruct"),
    ("numpy.core.multiarray", "scalar"), ("numpy._core.multiarray", "scalar"),
    ("numpy.core.numeric", "_frombuffer"), ("numpy._core.numeric", "_frombuffer"),
    ("numpy", "ndarray"), ("numpy", "dtype"),
}


class _RestrictedUnpickler(pickle.Unpickler):
    def find_class(self, module: str, name: str) -> Any:
        if (module, name) in _ALLOWED_GLOBALS:
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"the answer holds a {module}.{name}, which is not accepted")


# -- the child's side --------------------------------------------------------------------------------------

def _apply_limits(cpu: float, memory: int) -> None:
    try:
        import resource
    except ImportError:        # Windows: wall clock only
        return
    whole = max(1, int(cpu + 0.999))
    # files the job writes (its stderr included) are capped at the memory limit
    for which, soft, hard in ((resource.RLIMIT_CPU, whole, whole + 2), (resource.RLIMIT_AS, memory, memory),
                              (resource.RLIMIT_FSIZE, memory, memory)):
        current_hard = resource.getrlimit(which)[1]
        if current_hard != resource.RLIM_INFINITY:
            soft, hard = min(soft, current_hard), min(hard, current_hard)
        resource.setrlimit(which, (soft, hard))


def _child_main(job_path: str) -> None:
    """Entry point of the child (``python -I -c``): run the job in ``job_path`` and write its answer."""
    with open(job_path, "rb") as fh:
        job = pickle.load(fh)
    answer_path = job["answer"]
    _apply_limits(job["cpu"], job["memory"])
    try:
        outcome: tuple[Any, ...] = ("ok", job["function"](*job["args"], **job["kwargs"]))
    except MemoryError:
        outcome = ("memory",)
    except OSError as exc:             # Python ignores SIGXFSZ: a write past RLIMIT_FSIZE fails with EFBIG
        outcome = (("file",) if exc.errno == errno.EFBIG else
                   ("error", type(exc).__name__, " ".join(str(exc).split()) or type(exc).__name__))
    except Exception as exc:  # noqa: BLE001 - every failure of the job goes back to the parent as its answer
        outcome = ("error", type(exc).__name__, " ".join(str(exc).split()) or type(exc).__name__)
    try:
        buffer = io.BytesIO()
        pickle.dump(outcome, buffer, protocol=pickle.HIGHEST_PROTOCOL)
    except MemoryError:
        buffer = io.BytesIO(pickle.dumps(("memory",)))
    except Exception as exc:  # noqa: BLE001 - an answer that cannot be pickled is an error, not a crash
        buffer = io.BytesIO(pickle.dumps(("error", "TypeError", f"the answer cannot be sent back ({exc})")))
    temporary = answer_path + ".part"
    with open(temporary, "wb") as fh:
        fh.write(buffer.getbuffer())
    os.replace(temporary, answer_path)
