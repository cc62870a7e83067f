"""Start-up benchmark: a small STL end to end, against a bare interpreter, ``import numpy`` and trimesh, in one run.

Issue #15 ("small files: instant small runs"): ``inertia-tool analyze meshes/box.stl --json`` should take at
most twice as long as ``python -c "import numpy"`` on the same machine in the same run.  Each command below
runs in a fresh process (start-up and imports included, as a user sees it), round-robin so that other load on
the machine hits every command alike, and the best of ``--repeat`` runs is kept:

* ``python -c pass`` and ``python -c "import numpy"`` (the yardstick);
* ``python -m inertia_tool analyze meshes/box.stl --json``, the same through the ``inertia-tool`` console
  script, and as text and with ``--units mm``;
* ``inertia-tool --help`` and ``inertia-tool analyze --help``;
* trimesh on the same file: ``import trimesh; trimesh.load(path).mass_properties`` (the peer).

Every child imports the package of this checkout (``PYTHONPATH``; the script says which file it timed).  Children
may write bytecode caches, and one untimed warm-up run of each command comes first, so the timings are those of
an installed package (``pip install`` compiles it); with ``PYTHONDONTWRITEBYTECODE`` set and no cache, every run
would compile the package from source.  ``--importtime`` also lists the largest imports of the analyze run
(``python -X importtime``, self time, best of the repeats).

    python benchmarks/bench_startup.py [--repeat 15] [--importtime]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BOX = "meshes/box.stl"

#: Ratio of the analyze run to ``import numpy`` that issue #15 asks for at most.
GOAL = 2.0

TRIMESH = "import sys, trimesh; m = trimesh.load(sys.argv[1]); p = m.mass_properties; p['inertia'], p['center_mass']"


def child_env() -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "INERTIA_TOOL_NO_ACCEL")}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, os.environ.get("PYTHONPATH", "")) if p)
    return env


def console_script() -> str | None:
    """The ``inertia-tool`` script of this interpreter's environment (None when it is not installed)."""
    beside = os.path.join(os.path.dirname(sys.executable), "inertia-tool")
    return beside if os.path.exists(beside) else shutil.which("inertia-tool")


def commands() -> list[tuple[str, list[str]]]:
    py = sys.executable
    rows = [
        ("python -c pass", [py, "-c", "pass"]),
        ('python -c "import numpy"', [py, "-c", "import numpy"]),
        (f"python -m inertia_tool analyze {BOX} --json", [py, "-m", "inertia_tool", "analyze", BOX, "--json"]),
    ]
    script = console_script()
    if script:
        rows += [(f"inertia-tool analyze {BOX} --json", [script, "analyze", BOX, "--json"]),
                 (f"inertia-tool analyze {BOX}", [script, "analyze", BOX]),
                 (f"inertia-tool analyze {BOX} --units mm", [script, "analyze", BOX, "--units", "mm"]),
                 ("inertia-tool --help", [script, "--help"]),
                 ("inertia-tool analyze --help", [script, "analyze", "--help"])]
    else:
        rows += [("python -m inertia_tool --help", [py, "-m", "inertia_tool", "--help"])]
    rows.append((f"trimesh.load({BOX}).mass_properties", [py, "-c", TRIMESH, BOX]))
    return rows


def run(argv: list[str], env: dict) -> float:
    start = time.perf_counter()
    subprocess.run(argv, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - start


def importtime(env: dict, repeat: int, top: int = 15) -> list[tuple[int, str]]:
    """The ``top`` largest self times (µs, best of ``repeat``) of ``python -X importtime`` on the analyze run."""
    best: dict[str, int] = {}
    for _ in range(repeat):
        done = subprocess.run([sys.executable, "-X", "importtime", "-m", "inertia_tool", "analyze", BOX, "--json"],
                              cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                              check=True)
        for line in done.stderr.splitlines():
            if not line.startswith("import time:") or "self [us]" in line:
                continue
            self_us, _, name = line[len("import time:"):].split("|")
            name = name.strip()
            best[name] = min(best.get(name, 1 << 62), int(self_us))
    return sorted(((us, name) for name, us in best.items()), reverse=True)[:top]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=15, help="runs of each command; the best is kept")
    parser.add_argument("--importtime", action="store_true", help="also list the largest imports of analyze")
    args = parser.parse_args()
    env = child_env()
    where = subprocess.run([sys.executable, "-c", "import inertia_tool; print(inertia_tool.__file__)"], cwd=ROOT,
                           env=env, capture_output=True, text=True, check=True).stdout.strip()
    rows = commands()
    for _, argv in rows:                              # warm-up: bytecode caches written, files in the page cache
        run(argv, env)
    times = {label: float("inf") for label, _ in rows}
    for _ in range(args.repeat):
        for label, argv in rows:
            times[label] = min(times[label], run(argv, env))
    numpy_time = times['python -c "import numpy"']
    print(f"inertia_tool from {where}; Python {sys.version.split()[0]}; best of {args.repeat}, one run")
    width = max(len(label) for label, _ in rows)
    print(f"{'command':<{width}}  {'best':>8}  {'/ import numpy':>14}")
    for label, _ in rows:
        print(f"{label:<{width}}  {times[label]:7.3f}s  {times[label] / numpy_time:13.2f}x")
    analyze = times[f"python -m inertia_tool analyze {BOX} --json"]
    ratio = analyze / numpy_time
    verdict = "met" if ratio <= GOAL else "NOT met"
    print(f"goal (issue #15): analyze {BOX} --json within {GOAL:g}x import numpy: {ratio:.2f}x, {verdict}")
    peer = times[f"trimesh.load({BOX}).mass_properties"]
    print(f"trimesh load + mass_properties of the same file / analyze --json: {peer / analyze:.2f}")
    if args.importtime:
        print(f"\nlargest imports of analyze {BOX} --json (python -X importtime, self time, best of {args.repeat}):")
        for us, name in importtime(env, args.repeat):
            print(f"  {us / 1000:7.2f} ms  {name}")


if __name__ == "__main__":
    main()
