"""Command line: ``inertia-tool SUBCOMMAND ...``.

Routing and formatting only; every number comes from the engine.  Each subcommand lives in its own module
in this package exposing ``register(subparsers)``, which adds a parser whose ``func(args) -> int`` runs it.

Exit codes (README): 0 success, 2 usage error, 3 unreadable or invalid mesh, 4 a physically impossible
request, 5 ``robot``: a link without a result (the others reported), 1 an unexpected internal error
(reported in one line, never a traceback; ``INERTIA_TOOL_DEBUG=1`` shows the traceback).
:data:`EXIT_CODES` maps the engine's exception types to them, and :func:`speak_options` turns the API
parameter names in engine messages into this command's options: the engine knows nothing of either.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings
from collections.abc import Collection

from ..errors import (DesignRejectedError, InertiaToolError, InertiaToolWarning, InvalidMeshError,
                      IsolatedProcessError, MeshReadError, PhysicsError, RobotDescriptionError, UsageError)
from ..reports.escape import escape_terminal
from .help import SUMMARIES

__all__ = ["main", "build_parser", "exit_code", "speak_options", "EXIT_CODES", "EXIT_OK", "EXIT_INTERNAL",
           "EXIT_USAGE", "EXIT_MESH", "EXIT_PHYSICS", "EXIT_INCOMPLETE", "EXIT_DESIGN"]

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2
EXIT_MESH = 3
EXIT_PHYSICS = 4
#: ``robot``: the report is complete except for links that have no result (each named with its reason).
EXIT_INCOMPLETE = 5
#: ``spin-it``: every design it tried was worse than the part (DesignRejectedError); nothing is written.
EXIT_DESIGN = 6

#: Exit code of each exception type; the most specific class of an exception's MRO that is listed wins.
EXIT_CODES = {
    UsageError: EXIT_USAGE,
    MeshReadError: EXIT_MESH,
    RobotDescriptionError: EXIT_MESH,
    InvalidMeshError: EXIT_MESH,
    IsolatedProcessError: EXIT_MESH,
    PhysicsError: EXIT_PHYSICS,
    DesignRejectedError: EXIT_DESIGN,
    InertiaToolError: EXIT_INTERNAL,
}

#: API parameter names whose option is not simply ``--name-with-dashes`` of a parser's ``dest``.
PARAMETER_OPTIONS = {
    "units": "--units",
    "axis_point": "--axis-point",
    "axis_direction": "--axis-direction",
    "force": "--force",
}

_PARAMETER = re.compile(r"`(\w+)(=True)?`")


def exit_code(exc: BaseException) -> int:
    """The exit code of an engine exception (:data:`EXIT_CODES`)."""
    for cls in type(exc).__mro__:
        if cls in EXIT_CODES:
            return EXIT_CODES[cls]
    return EXIT_INTERNAL


def _options_of(parser) -> dict:
    """``dest → option string`` of a parser's optional arguments (the long form)."""
    names = {}
    for action in getattr(parser, "_actions", ()):
        longs = [o for o in action.option_strings if o.startswith("--")]
        if longs:
            names[action.dest] = longs[0]
    return names


def speak_options(message: str, parser=None) -> str:
    """Engine message → command-line message: `` `name` `` and `` `name=True` `` become the option of
    ``parser`` (or of :data:`PARAMETER_OPTIONS`) that sets that parameter; other names lose their backticks."""
    options = {**PARAMETER_OPTIONS, **(_options_of(parser) if parser is not None else {})}

    def option(match):
        name = match.group(1)
        return options.get(name, name)
    return _PARAMETER.sub(option, message)

#: Subcommands, in the order ``--help`` lists them; ``spin-it`` lives in the module ``spin_it``.
SUBCOMMANDS = list(SUMMARIES)


# Values such as "-40,40", "-5,0,0", "-20deg", "-2mm,0,0" or "-40mm,40mm" start with "-" but are numbers
# (each comma-separated item a number, possibly signed, with any unit glued on), not options.  No option of
# this tool starts with "-" and a digit, so nothing real is shadowed.
_NEGATIVE_VALUE = re.compile(r"^-\.?\d[^\s,]*(,[-+]?\.?\d[^\s,]*)*$")


def _terminal_columns(fallback: int = 80) -> int:
    """The width help is wrapped to, as :func:`shutil.get_terminal_size` gives it: ``COLUMNS`` if a positive
    integer, else the terminal of standard output, else ``fallback``."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns    # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns if columns > 0 else fallback


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse treats "-40,40" as an option unless it matches this private pattern
        self._negative_number_matcher = _NEGATIVE_VALUE

    def _get_formatter(self):
        # argparse's formatter takes its default width from shutil.get_terminal_size(); importing shutil (with
        # bz2 and lzma) costs a few ms of every run, since add_argument builds a formatter for each option
        return self.formatter_class(prog=self.prog, width=_terminal_columns() - 2)

    def error(self, message):  # one line, exit code 2, as documented (no usage block)
        message = " ".join(str(message).split())
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(commands: Collection[str] | None = None, *, others: bool = True) -> argparse.ArgumentParser:
    """The ``inertia-tool`` parser.

    ``commands``: the subcommands whose parsers are built in full (their modules imported, and with them the
    engine layers they use); all when None.  The others get a placeholder with their one-line summary
    (:data:`~.help.SUMMARIES`), which is all ``inertia-tool --help`` and the choice of a command read; with
    ``others=False`` they are left out (``argv`` starts with the command, so neither is read: each placeholder
    is a whole ArgumentParser, about a tenth of a millisecond).
    """
    parser = _Parser(prog="inertia-tool",
                     description="Exact mass properties, principal axes, spin stability, dynamics and balancing "
                                 "of triangle meshes (STL, OBJ, PLY, OFF, 3MF).")
    from .. import __version__
    parser.add_argument("--version", action="version", version=f"inertia-tool {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in SUBCOMMANDS:
        if commands is None or name in commands:
            importlib.import_module(f"{__name__}.{name.replace('-', '_')}").register(sub)
        elif others:
            sub.add_parser(name, help=SUMMARIES[name])
    parser.set_defaults(_subparsers=sub.choices)
    return parser


def _command_in(argv) -> tuple[str, ...]:
    """The subcommand ``argv`` names, as a 1-tuple (``()`` when it names none): its first word that is not an
    option, since the options before the command (``--help``, ``--version``) take no value."""
    for word in sys.argv[1:] if argv is None else argv:
        if not word.startswith("-"):
            return (word,) if word in SUMMARIES else ()
    return ()


def _format_warning(w: warnings.WarningMessage) -> str:
    return f"warning: {w.message}"


class _TerminalSafe:
    """A text stream that writes through :func:`~inertia_tool.reports.escape.escape_terminal` (lines kept):
    a file or part name holding terminal escape sequences reaches the terminal as visible ``\\u001b`` text,
    and JSON on it stays valid (the escape is JSON's own).  Installed as ``sys.stdout`` while a command runs;
    nothing this tool prints to standard output is a control sequence of its own."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        self._stream.write(escape_terminal(text, lines=True))
        return len(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    """Entry point of the ``inertia-tool`` console script; returns the exit code.

    Called without ``argv`` (as the console script and ``python -m inertia_tool`` call it) it is the program:
    once the command is done it ends the process itself when nothing is left to run at exit
    (:func:`_end_program`).
    """
    code = _main(argv)
    if argv is None:
        _end_program(code)
    return code


def _end_program(code: int) -> None:
    """End the process with ``code`` now, skipping the interpreter's teardown, when that loses nothing.

    Tearing down an interpreter that has loaded numpy and this package (clearing every module, collecting
    every object) costs about a tenth of a start-up on a small part, and ~0.3 s of CPU once a repair has loaded
    scipy, libigl and pycollada (issue 23: a UR5e run); it does nothing a finished command needs.  So the
    process ends with :func:`os._exit` once what the normal exit would do first is done: if no other thread is
    running, the ``atexit`` callbacks are run here, in the order the normal exit runs them (the hooks of
    ``logging``, ``multiprocessing``, ``weakref.finalize``, temporary directories, Pillow and libigl register
    one; :func:`atexit._run_exitfuncs` runs each once and clears them), then standard output and error are
    flushed.  A running thread (before or after the callbacks) means the normal exit, which joins it.  Files
    this tool writes are closed by their writer (:mod:`inertia_tool.output`) before the command returns.  When
    a flush fails (a closed pipe) the normal exit takes over and reports it as usual.
    """
    import atexit
    run_callbacks = getattr(atexit, "_run_exitfuncs", None)    # CPython's; elsewhere: the normal exit
    if run_callbacks is None or _other_threads():
        return
    run_callbacks()
    if _other_threads():                                       # a callback started one: let the normal exit join it
        return
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        return
    os._exit(code)


def _other_threads() -> bool:
    """Whether a thread besides the main one is running (``threading`` never imported: none was started)."""
    threading = sys.modules.get("threading")
    return threading is not None and threading.active_count() > 1


def _main(argv) -> int:
    command = _command_in(argv)
    words = sys.argv[1:] if argv is None else list(argv)
    # only the running command's module is imported; the other commands are left out when nothing before the
    # command could print the top-level help (``inertia-tool --help analyze`` lists them all)
    parser = build_parser(command, others=not command or words[0] != command[0])
    try:
        args, extra = parser.parse_known_args(argv)
        if extra:   # reported by the subcommand's parser, so that the line names the command and its --help
            owner = args._subparsers.get(getattr(args, "command", None), parser)
            owner.error(f"unrecognized arguments: {' '.join(extra)}")
    except SystemExit as exc:      # --help, --version, or a usage error already printed in one line
        return int(exc.code or 0) if not isinstance(exc.code, str) else EXIT_USAGE
    debug = os.environ.get("INERTIA_TOOL_DEBUG") == "1"
    error_line = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        stdout = sys.stdout
        try:
            sys.stdout = _TerminalSafe(stdout)      # type: ignore[assignment]
            try:
                code = args.func(args)
            finally:
                sys.stdout = stdout
        except InertiaToolError as exc:
            if debug:
                raise
            owner = args._subparsers.get(getattr(args, "command", None))
            error_line = f"inertia-tool: error: {speak_options(str(exc), owner)}"
            code = exit_code(exc)
        except KeyboardInterrupt:
            print("inertia-tool: interrupted", file=sys.stderr)
            code = 130
        except MemoryError:
            error_line = "inertia-tool: error: out of memory (try --max-faces or a smaller mesh)"
            code = EXIT_INTERNAL
        except BrokenPipeError:
            code = EXIT_OK
        except Exception as exc:  # noqa: BLE001 - last line of defence: one line, never a traceback
            if debug:
                raise
            error_line = (f"inertia-tool: internal error: {type(exc).__name__}: {exc} "
                          "(please report it; INERTIA_TOOL_DEBUG=1 shows the traceback)")
            code = EXIT_INTERNAL
    if error_line is not None:
        # a failed command prints one line: warnings about a result that was never produced are dropped
        print(escape_terminal(error_line.replace("\n", " ")), file=sys.stderr)
        return int(code)
    # a warning the command already printed with its report is not printed again when standard output and
    # standard error are the same terminal (the user would read it twice); redirected, stderr keeps them all
    shown: frozenset[str] = getattr(args, "warnings_shown", frozenset()) if _same_terminal() else frozenset()
    owner = args._subparsers.get(getattr(args, "command", None))
    for w in caught:
        if issubclass(w.category, InertiaToolWarning) and speak_options(str(w.message), owner) not in shown:
            print(escape_terminal(f"inertia-tool: {speak_options(_format_warning(w), owner)}"), file=sys.stderr)
    return int(code or 0)


def _same_terminal() -> bool:
    """True when standard output and standard error are one terminal (both a tty, the same device)."""
    try:
        out, err = sys.stdout, sys.stderr
        return bool(out.isatty() and err.isatty()
                    and os.path.samestat(os.fstat(out.fileno()), os.fstat(err.fileno())))
    except (AttributeError, OSError, ValueError):      # a captured or closed stream
        return False


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
