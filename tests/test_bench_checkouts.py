"""The benchmarks of the count of generated cases (``docs/adversarial.md``), and the others that had no way to their
own checkout, import the ``inertia_tool`` of the checkout that holds them
(``benchmarks/_checkouts.this_checkout_first``), not an installed one, unless ``PYTHONPATH`` names another; and
each answers ``--help``.

Each script is run as ``python benchmarks/bench_X.py --help`` would run it (its folder first on ``sys.path``), in
a fresh interpreter started outside the repository, and the child prints the file of the ``inertia_tool`` it
imported.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BENCHES = ("bench_adversarial", "bench_review11", "bench_review9_convex", "bench_near_copies",
           "bench_review12", "bench_kept_cavities", "bench_real_motions",
           # the others that had no way to their own checkout (bench_review9_damage: through damage/coverage.py)
           "bench_arrange", "bench_coplanar", "bench_intersect", "bench_review9_damage", "bench_walls")

# the script run as __main__ with --help (argparse exits 0 after printing), then the package it imported (or,
# where it imports the package only when it runs cases, the one it would import)
_CHILD = """
import runpy, sys
script = sys.argv[1]
sys.path.insert(0, sys.argv[2])
sys.argv = [script, "--help"]
try:
    runpy.run_path(script, run_name="__main__")
except SystemExit as stop:
    if stop.code not in (0, None):
        raise
import inertia_tool  # what the script imports, or would import next
print("IMPORTED", inertia_tool.__file__)
"""


def _imported(bench: str, tmp_path: Path, pythonpath: str | None) -> str:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    done = subprocess.run([sys.executable, "-c", _CHILD, str(ROOT / "benchmarks" / f"{bench}.py"),
                           str(ROOT / "benchmarks")], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    lines = [line for line in done.stdout.splitlines() if line.startswith("IMPORTED ")]
    assert len(lines) == 1, done.stdout[-2000:]
    return lines[0].split(" ", 1)[1]


@pytest.mark.parametrize("bench", BENCHES)
def test_bench_imports_its_own_checkout(bench, tmp_path):
    assert Path(_imported(bench, tmp_path, None)).resolve() == ROOT / "inertia_tool" / "__init__.py"


def test_pythonpath_names_the_checkout(tmp_path):
    """A ``PYTHONPATH`` wins (how ``_checkouts.run_script`` and a user run a baseline): here a stand-in package."""
    other = tmp_path / "other"
    (other / "inertia_tool").mkdir(parents=True)
    (other / "inertia_tool" / "__init__.py").write_text("")
    # bench_adversarial imports the package only when it runs cases, so an empty stand-in serves for --help
    got = _imported("bench_adversarial", tmp_path, str(other))
    assert Path(got).resolve() == (other / "inertia_tool" / "__init__.py").resolve()
