"""``--report FILE.html`` / ``--force`` for commands that show one part (used by ``analyze``).

Routing only: the command hands over the meshes it read and the verdicts it computed, and this module passes
them to :mod:`inertia_tool.reports.html`.
"""

from __future__ import annotations

import os
import sys

from ..errors import UsageError
from ..reports.escape import escape_terminal

__all__ = ["add_report_options", "check_report_path", "write_report_from_args", "REPORT_SUFFIXES",
           "check_output_file", "say_written"]

#: Suffixes of ``--report`` (the only writer here is HTML).
REPORT_SUFFIXES = (".html", ".htm")


def add_report_options(parser) -> None:
    """Add ``--report FILE.html`` and ``--force`` to ``parser``."""
    g = parser.add_argument_group("report")
    g.add_argument("--report", metavar="FILE.html",
                   help="also write a self-contained HTML report (tables, three views with the centre of mass, "
                        "principal axes and inertia ellipsoid; stability where available)")
    g.add_argument("--force", action="store_true", help="let --report replace an existing file")


def check_output_file(path: str | None, option: str, force: bool) -> None:
    """The rule of every file this command line writes (:func:`inertia_tool.output.check_targets`):
    refuse (:class:`UsageError`, exit 2), before any work, to replace an existing file without ``--force``,
    to write over a directory, or into a missing directory."""
    from ..output import check_targets      # imported on use (tempfile, shutil): most runs write no file
    check_targets([(path, option)], force=force)


def check_report_path(args) -> None:
    """Refuse, before any work, a ``--report`` that is not ``*.html``/``*.htm`` or that exists without
    ``--force`` (:class:`UsageError`, exit 2)."""
    path = getattr(args, "report", None)
    if not path:
        return
    if os.path.splitext(path)[1].lower() not in REPORT_SUFFIXES:
        raise UsageError(f"--report writes HTML: expected a file name ending in "
                         f"{' or '.join(REPORT_SUFFIXES)}, got {path!r}")
    check_output_file(path, "--report", getattr(args, "force", False))


def write_report_from_args(args, props, density_source: str | None, warnings=(), *, meshes=(),
                           stability=None, model=None, extra_sections=(), result=None) -> None:
    """Write the HTML report asked for by ``args.report`` (no-op without it): ``meshes`` are the
    ``RawMesh`` objects the command read, ``stability`` its verdict (or the reason it is undefined),
    ``model`` the mass model's summary (:func:`~inertia_tool.reports.models.model_summary`),
    ``extra_sections`` more sections, ``result`` where the numbers come from (default: the mesh's method)."""
    if not getattr(args, "report", None):
        return
    check_report_path(args)
    from ..reports.html import html_report, write_html_report     # imported on use: most runs write no report
    from ..reports.models import model_section
    extra = list(extra_sections) + ([model_section(model)] if model else [])
    document = html_report(props, meshes=[(m.vertices, m.faces) for m in meshes], density_source=density_source,
                           warnings=list(warnings), stability=stability, extra_sections=extra, result=result)
    write_html_report(args.report, document, force=args.force)
    say_written([args.report])


def say_written(paths) -> None:
    """``wrote a.csv, b.png`` on stderr: every file a command writes is named (stdout stays the report)."""
    paths = [str(p) for p in paths if p]
    if paths:
        print(escape_terminal(f"wrote {', '.join(paths)}"), file=sys.stderr)


def save_figure(fig, path: str, *, dpi: int = 120) -> None:
    """Write a matplotlib figure to ``path`` atomically (the format from its suffix) and close it; an OS error
    becomes a one-line :class:`~inertia_tool.output.OutputFileError`."""
    import matplotlib.pyplot as plt

    from ..output import atomic_target
    try:
        with atomic_target(path) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        plt.close(fig)
