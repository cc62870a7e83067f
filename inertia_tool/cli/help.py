"""How every subcommand's ``--help`` reads: the description wrapped, then two or three examples that run."""

from __future__ import annotations

import argparse
import textwrap

__all__ = ["add_command"]


def add_command(subparsers, name: str, *, help: str, description: str, examples: list[str]):
    """Add the subcommand ``name`` with a wrapped ``description`` and an ``examples:`` epilog (one command
    per item, shown as written; each runs from the repository root, ``tests/test_docs_examples.py`` checks)."""
    width = 100
    text = "\n\n".join(textwrap.fill(p, width) for p in description.split("\n\n"))
    epilog = "examples:\n" + "\n".join(f"  {line}" for line in examples)
    return subparsers.add_parser(name, help=help, description=text, epilog=epilog,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
