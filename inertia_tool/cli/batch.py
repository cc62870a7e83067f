"""``inertia-tool batch DIR_OR_GLOB --out results.jsonl|csv``: mass properties of many meshes.

Routing, the progress bar and the summary only; the per-file work and the runner are
:mod:`inertia_tool.batch.runner`, the result files :mod:`inertia_tool.batch.rows`.

Exit codes: 0 when every file is done without error (this run or an earlier one), 3 when some file failed,
in this run or in the earlier row it was skipped for (its row says why), 2 for bad arguments, an ``--out`` that
is not a results file of the same kind or is damaged before its last line (the line is named), or a results file
that cannot be written (a full disk: it keeps its complete rows, and the same command resumes).
"""

from __future__ import annotations

import sys
import time

from ..errors import UsageError
from .help import add_command
from .model_options import add_model_options, load_options_from_args
from .options import check_option, density_and_mass
from ..reports.escape import escape_terminal

# the runner (numpy and the engine) and the results files load in run(): ``batch --help`` needs neither
# (issue 25 item 4)

__all__ = ["register", "run", "Progress", "connect_dask_cli", "summary_line"]

#: Exit code when at least one file failed.
EXIT_SOME_FAILED = 3


class Progress:
    """A progress display on a stream: a redrawn bar on a terminal, plain periodic lines otherwise.

    Parameters
    ----------
    stream : file
        Usually ``sys.stderr``.
    interval : float
        Seconds between plain lines when ``stream`` is not a terminal (the last state is always printed).
    width : int
        Characters of the bar.
    redraw : float
        Seconds between two redraws of the bar on a terminal (the first and the last state are always drawn): a
        redraw per file cost a write and a flush per part, ~2 % of a small part's time.
    """

    def __init__(self, stream=None, *, interval: float = 5.0, width: int = 30, redraw: float = 0.1):
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = interval
        self.redraw = redraw
        self.width = width
        self.start = time.perf_counter()
        self.first = None
        self.last_line = -1e300
        self.state = (0, 0, 0, 0)

    def _text(self, done, total, ok, failed) -> str:
        elapsed = time.perf_counter() - self.start
        computed = ok + failed
        rate = computed / elapsed if elapsed > 0 and computed else 0.0
        eta = f", ETA {((total - done) / rate):.0f} s" if rate > 0 and done < total else ""
        return f"{done}/{total} files ({ok} ok, {failed} failed), {rate:.1f} files/s{eta}"

    def __call__(self, done: int, total: int, ok: int, failed: int) -> None:
        self.state = (done, total, ok, failed)
        now = time.perf_counter()
        if self.tty:
            if now - self.last_line < self.redraw and done != total:
                return
            self.last_line = now
            filled = int(self.width * done / total) if total else self.width
            bar = "#" * filled + "." * (self.width - filled)
            self.stream.write(f"\r[{bar}] {self._text(done, total, ok, failed)}\x1b[K")
            self.stream.flush()
        elif now - self.last_line >= self.interval or done == total:
            self.last_line = now
            self.stream.write(f"batch: {self._text(done, total, ok, failed)}\n")
            self.stream.flush()

    def close(self) -> None:
        """End the bar's line on a terminal."""
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


def connect_dask_cli(address: str, jobs: int):
    """:func:`inertia_tool.batch.cluster.connect_dask`, its messages in terms of the command line's options."""
    from ..batch.cluster import connect_dask

    try:
        return connect_dask(address, jobs)
    except UsageError as exc:
        raise UsageError(f"--dask {address}: {exc}") from None


def check_workers_read_cli(cluster, address: str, files: list[str]) -> None:
    """:func:`inertia_tool.batch.cluster.check_workers_read` on the first and last file, in the command's terms."""
    from ..batch.cluster import check_workers_read

    try:
        check_workers_read(cluster.client, sorted({files[0], files[-1]}) if files else [])
    except UsageError as exc:
        raise UsageError(f"--dask {address}: {exc}") from None


def summary_line(summary, files: int, args) -> str:
    """The closing line of a run: what this run computed, what earlier runs had done, the total mass."""
    where = f"Dask ({args.dask})" if args.dask else f"{args.jobs} process{'es' if args.jobs > 1 else ''}"
    before = ""
    if summary.skipped:
        failed_before = f", {summary.skipped_failed} of them failed" if summary.skipped_failed else ""
        before = f"; {summary.skipped} done before{failed_before}"
    if summary.computed == 0:
        return (f"batch: {files} files: nothing new{before} (same content, same options); total mass of the ok "
                f"files {summary.total_mass:.6g} kg; rows in {args.out}")
    return (f"batch: {files} files: {summary.ok} ok, {summary.failed} failed in this run{before}; total mass of "
            f"the ok files {summary.total_mass:.6g} kg; {summary.seconds:.2f} s, {summary.files_per_second:.1f} "
            f"files/s on {where}; rows in {args.out}")


def register(subparsers) -> None:
    parser = p = add_command(
        subparsers, "batch",
        description="Analyse every mesh in a directory (recursively), matching a glob, or named: one row per "
                    "file (numbers or the error) appended to --out and flushed per file, so a killed run can be "
                    "resumed: files already done (same path, same SHA-256 of the content, same options) are "
                    "skipped.",
        examples=["inertia-tool batch meshes/ --units mm --material steel --out parts.csv",
                  "inertia-tool batch meshes/*.stl --units mm --density 1240 --out parts.jsonl --jobs 2",
                  "inertia-tool batch 'meshes/**/*.stl' --units mm --material pla --out printed.csv"])
    p.add_argument("source", nargs="+", metavar="PATH",
                   help="directories (searched recursively), mesh files (e.g. parts/*.stl expanded by the "
                        "shell) or quoted globs ('parts/**/*.stl', expanded here; ** recurses)")
    add_model_options(p, thin_walls=False)
    p = p.add_argument_group("run")
    p.add_argument("--out", required=True, metavar="FILE", help="results file: *.jsonl or *.csv (appended to)")
    p.add_argument("--jobs", "-j", type=int, default=1, metavar="N",
                   help="worker processes (default 1: in this process); with --dask, the LocalCluster size")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run on a Dask cluster: 'local' for a LocalCluster of --jobs workers on this machine, or "
                        "a scheduler address tcp://host:8786 (needs the 'dask' extra)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress display")
    parser.set_defaults(func=run)


def run(args) -> int:
    from ..batch.rows import open_results, results_format
    from ..batch.runner import BatchOptions, discover_files, run_batch
    from . import speak_options

    results_format(args.out)                      # a bad suffix is a usage error before any work
    density, mass = density_and_mass(args)
    check_option("--jobs", args.jobs)
    # --units is for the files without a unit; a file that declares its own (3MF, glTF, STEP) keeps it
    load = load_options_from_args(args).replace(declared_units_win=True)
    options = BatchOptions(load=load, density=density, material=args.material, mass=mass)
    options.validate()
    if args.jobs < 1:
        raise UsageError(f"Expected --jobs >= 1, got {args.jobs}")
    sources = args.source if isinstance(args.source, (list, tuple)) else [args.source]
    files = sorted({f for source in sources for f in discover_files(source)})
    cluster = None
    with open_results(args.out) as out:
        if out.torn_bytes:
            print(f"batch: warning: {args.out}: ignored a torn last line ({out.torn_bytes} bytes) — the previous "
                  "run was interrupted", file=sys.stderr)
        if args.dask:
            cluster = connect_dask_cli(args.dask, args.jobs)
            try:
                check_workers_read_cli(cluster, args.dask, files)
            except BaseException:
                cluster.close()
                raise
        progress = None if args.quiet else Progress(sys.stderr)
        try:
            implausible = []
            owner = getattr(args, "_subparsers", {}).get("batch")

            def write_row(row):
                if "metres assumed" in str(row.get("warnings") or ""):     # ImplausibleSizeWarning of this file
                    implausible.append(row["path"])
                # the rows of the command speak its options, as `analyze` does ("--repair", not "`repair=True`")
                for column in ("error", "warnings"):
                    if row.get(column) and "`" in row[column]:
                        row[column] = speak_options(row[column], owner)
                out.write_row(row)

            summary = run_batch(files, options, write_row, previous_rows=out.previous_rows,
                                jobs=1 if cluster else args.jobs, client=cluster.client if cluster else None,
                                progress=progress)
        finally:
            if progress is not None:
                progress.close()
            if cluster is not None:
                cluster.close()
    print(escape_terminal(summary_line(summary, len(files), args)), file=sys.stderr)
    if implausible:
        print(f"batch: warning: {len(implausible)} file(s) read without --units are implausibly large or small "
              f"in metres (first: {implausible[0]}); their rows' warnings column names the unit that fits — "
              "give --units", file=sys.stderr)
    for path, message in summary.failures[:10]:
        print(escape_terminal(f"batch: failed: {path}: {message}"), file=sys.stderr)
    if len(summary.failures) > 10:
        print(escape_terminal(f"batch: ... and {len(summary.failures) - 10} more failures (see {args.out})"),
              file=sys.stderr)
    return EXIT_SOME_FAILED if summary.failed or summary.skipped_failed else 0
