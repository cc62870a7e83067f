"""One benchmark, several checkouts: the script run again in a fresh child process for each checkout.

A benchmark that compares this checkout with another (``--baseline DIR``: e.g. a ``git worktree`` of main with
its C extension built) runs itself once per checkout in a new interpreter, so that each imports its own
``inertia_tool`` (never both in one process) and starts from the same state; in rounds, the checkouts take turns
in alternating order, so that a change in the machine's load meets both.  Used by ``bench_intersect_agree.py``
(its child pickles every case's answers) and ``bench_batch.py`` (its child prints JSON lines of timings).

:func:`this_checkout_first` is the one rule by which a benchmark run as ``python benchmarks/bench_X.py`` picks the
``inertia_tool`` it measures: the checkout holding the script, unless ``PYTHONPATH`` names one.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator, Sequence
from typing import TypeVar

#: What :func:`in_turn` alternates: a checkout, or a checkout with its label.
Item = TypeVar("Item")


def this_checkout_first() -> str | None:
    """Put the checkout holding ``benchmarks/`` first on ``sys.path``, so that ``import inertia_tool`` finds this
    checkout's package and not an installed one (an editable install points at whichever checkout made it);
    unless ``PYTHONPATH`` is set: then it names the checkout to run (how :func:`run_script` runs another tree,
    and how a user runs these benchmarks on a baseline: ``PYTHONPATH=/path/to/main python benchmarks/...``).

    Call it before the first import of ``inertia_tool`` (or of a ``tests/`` helper that imports it); calling it
    again puts the folder first again without a second entry.

    Returns
    -------
    str or None
        The folder put first, or None when ``PYTHONPATH`` decides.
    """
    if os.environ.get("PYTHONPATH"):
        return None
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    sys.path[:] = [root, *(p for p in sys.path if p != root)]
    return root


def in_turn(checkouts: Sequence[Item], round_: int) -> Iterator[Item]:
    """The checkouts of round ``round_`` (0, 1, ...): in the order given in even rounds, reversed in odd ones."""
    return iter(checkouts if round_ % 2 == 0 else checkouts[::-1])


def child_env(tree: str | None) -> dict[str, str]:
    """The environment of a child timing checkout ``tree``: this one's with ``PYTHONPATH`` the checkout alone and
    ``INERTIA_TOOL_NO_ACCEL`` removed (the child must run the checkout's C kernels); ``tree`` None: this process's
    environment unchanged (a child that puts its checkout on ``sys.path`` itself)."""
    if tree is None:
        return dict(os.environ)
    env = {**os.environ, "PYTHONPATH": tree}
    env.pop("INERTIA_TOOL_NO_ACCEL", None)
    return env


def run_script(script: str, args: Sequence[str], *, tree: str | None = None,
               capture: bool = False) -> subprocess.CompletedProcess:
    """Run the benchmark ``script`` with ``args`` in a fresh interpreter (this one's executable), its environment
    :func:`child_env` of ``tree``; a failure of the child stops the benchmark (``CalledProcessError``).

    Returns
    -------
    subprocess.CompletedProcess
        With the child's output as text when ``capture`` (else it goes to this process's streams).
    """
    return subprocess.run([sys.executable, os.path.abspath(script), *args], env=child_env(tree), check=True,
                          capture_output=capture, text=capture or None)
