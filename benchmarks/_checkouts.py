"""One benchmark, several checkouts: the script run again in a fresh child process for each checkout.

A benchmark that compares this checkout with another (``--baseline DIR``: e.g. a ``git worktree`` of main with
its C extension built) runs itself once per checkout in a new interpreter, so that each imports its own
``inertia_tool`` (never both in one process) and starts from the same state; in rounds, the checkouts take turns
in alternating order, so that a change in the machine's load meets both.  Used by ``bench_intersect_agree.py``
(its child pickles every case's answers) and ``bench_batch.py`` (its child prints JSON lines of timings).
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator, Sequence
from typing import TypeVar

#: What :func:`in_turn` alternates: a checkout, or a checkout with its label.
Item = TypeVar("Item")


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
