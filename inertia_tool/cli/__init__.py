"""Command line: ``inertia-tool SUBCOMMAND ...``.

Routing and formatting only; every number comes from the engine.  Each subcommand lives in its own module
in this package exposing ``register(subparsers)``, which adds a parser whose ``func(args) -> int`` runs it.

Exit codes (README, ``inertia_tool.errors``): 0 success, 2 usage error, 3 unreadable or invalid mesh,
4 a physically impossible request, 1 an unexpected internal error (reported in one line, never a traceback;
``INERTIA_TOOL_DEBUG=1`` shows the traceback).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings

from ..errors import InertiaToolError, InertiaToolWarning

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_INTERNAL", "EXIT_USAGE", "EXIT_MESH", "EXIT_PHYSICS"]

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2
EXIT_MESH = 3
EXIT_PHYSICS = 4

#: Subcommand modules, in the order ``--help`` lists them.
SUBCOMMANDS = ["analyze", "balance", "spin", "top", "batch"]


# Values such as "-40,40", "-5,0,0", "-20deg", "-2mm,0,0" or "-40mm,40mm" start with "-" but are numbers
# (each comma-separated item a number, possibly signed, with any unit glued on), not options.  No option of
# this tool starts with "-" and a digit, so nothing real is shadowed.
_NEGATIVE_VALUE = re.compile(r"^-\.?\d[^\s,]*(,[-+]?\.?\d[^\s,]*)*$")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse treats "-40,40" as an option unless it matches this private pattern
        self._negative_number_matcher = _NEGATIVE_VALUE

    def error(self, message):  # one line, exit code 2, as documented (no usage block)
        message = " ".join(str(message).split())
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="inertia-tool",
                     description="Exact mass properties, principal axes, spin stability, dynamics and balancing "
                                 "of triangle meshes (STL, OBJ, PLY, OFF, 3MF).")
    from .. import __version__
    parser.add_argument("--version", action="version", version=f"inertia-tool {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in SUBCOMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    parser.set_defaults(_subparsers=sub.choices)
    return parser


def _format_warning(w: warnings.WarningMessage) -> str:
    return f"warning: {w.message}"


def main(argv=None) -> int:
    """Entry point of the ``inertia-tool`` console script; returns the exit code."""
    parser = build_parser()
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
        try:
            code = args.func(args)
        except InertiaToolError as exc:
            if debug:
                raise
            error_line = f"inertia-tool: error: {exc}"
            code = exc.exit_code
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
        print(error_line.replace("\n", " "), file=sys.stderr)
        return int(code)
    for w in caught:
        if issubclass(w.category, InertiaToolWarning):
            print(f"inertia-tool: {_format_warning(w)}", file=sys.stderr)
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
