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


# Values such as "-40,40", "-5,0,0" or "-20deg" start with "-" but are numbers, not options.
_NEGATIVE_VALUE = re.compile(r"^-(\d|\.\d)[\d.eE+\-,]*[a-zA-Zµ/%]*$")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse treats "-40,40" as an option unless it matches this private pattern
        self._negative_number_matcher = _NEGATIVE_VALUE

    def error(self, message):  # one line, exit code 2, as documented
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


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
    return parser


def _format_warning(w: warnings.WarningMessage) -> str:
    return f"warning: {w.message}"


def main(argv=None) -> int:
    """Entry point of the ``inertia-tool`` console script; returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:      # --help, --version, or a usage error already printed in one line
        return int(exc.code or 0) if not isinstance(exc.code, str) else EXIT_USAGE
    debug = os.environ.get("INERTIA_TOOL_DEBUG") == "1"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaToolWarning)
        try:
            code = args.func(args)
        except InertiaToolError as exc:
            if debug:
                raise
            print(f"inertia-tool: error: {exc}", file=sys.stderr)
            code = exc.exit_code
        except KeyboardInterrupt:
            print("inertia-tool: interrupted", file=sys.stderr)
            code = 130
        except MemoryError:
            print("inertia-tool: error: out of memory (try --max-faces or a smaller mesh)", file=sys.stderr)
            code = EXIT_INTERNAL
        except BrokenPipeError:
            code = EXIT_OK
        except Exception as exc:  # noqa: BLE001 - last line of defence: one line, never a traceback
            if debug:
                raise
            print(f"inertia-tool: internal error: {type(exc).__name__}: {exc} "
                  "(please report it; INERTIA_TOOL_DEBUG=1 shows the traceback)", file=sys.stderr)
            code = EXIT_INTERNAL
    for w in caught:
        if issubclass(w.category, InertiaToolWarning):
            print(f"inertia-tool: {_format_warning(w)}", file=sys.stderr)
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
