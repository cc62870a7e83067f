"""How every subcommand's ``--help`` reads: the description wrapped, then two or three examples that run."""

from __future__ import annotations

import argparse
import textwrap

__all__ = ["add_command", "SUMMARIES"]

#: Every subcommand and its one-line summary, in the order ``inertia-tool --help`` lists them.  The command
#: line shows these without importing the subcommands' modules (each imports the engine layers it uses).
SUMMARIES = {
    "analyze": "mass, centre of mass, inertia tensor and principal axes of a mesh",
    "balance": "static/couple unbalance, ISO 21940-11 tolerance and correction masses about a shaft",
    "spin": "stability of spin about a principal axis: classification, flip or wobble period",
    "top": "the body spinning on a fixed pivot as a heavy symmetric top: nutation, precession",
    "spin-it": "hollow a part so that it spins stably as a yo-yo or a top",
    "batch": "mass properties of many meshes into one JSONL/CSV file (parallel, resumable)",
    "robot": "link mass properties from a URDF/xacro/SDF/MJCF's geometry; audit and correct <inertial>",
}


def add_command(subparsers, name: str, *, description: str, examples: list[str]):
    """Add the subcommand ``name`` with its summary (:data:`SUMMARIES`), a wrapped ``description`` and an
    ``examples:`` epilog (one command per item, shown as written; each runs from the repository root,
    ``tests/test_docs_examples.py`` checks)."""
    width = 100
    text = "\n\n".join(textwrap.fill(p, width) for p in description.split("\n\n"))
    epilog = "examples:\n" + "\n".join(f"  {line}" for line in examples)
    return subparsers.add_parser(name, help=SUMMARIES[name], description=text, epilog=epilog,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
