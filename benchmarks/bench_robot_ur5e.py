"""CPU time of ``inertia-tool robot`` on the UR5e with ``--geometry visual --repair`` (issue 23: under 5 s), whole
command (user + system of the process and its children: the xacro expansion included), for one or more source
trees run alternately, so that they share the machine's load.

Universal Robots' ROS 2 description (``ur_description``, BSD) is not in the repository; give its folder::

    python benchmarks/bench_robot_ur5e.py UR_DESCRIPTION [--trees TREE ...] [--runs N] [--out DIR] [--assume NAME]

``--assume flat-islands`` passes the user's assumption on (the wrist links' island holes, issue 23).

Each tree is put first on ``PYTHONPATH`` (a checkout with its compiled ``_accel``); the table and warnings of each
run are kept in ``--out`` (``TREE-NAME_RUN.txt``) so that the outputs of the trees can be compared byte for byte.
Prints one line per run: tree, run, load average at the start, user, system and wall seconds, and the largest
resident set of any child so far (the operating system keeps no per-child peak here).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run_once(tree: str, description: str, out: str, assume: tuple[str, ...] = ()) -> tuple[float, float, float, int]:
    """(user s, system s, wall s, peak RSS KB) of one command with ``tree`` first on PYTHONPATH."""
    env = dict(os.environ, PYTHONPATH=tree)
    command = [sys.executable, "-m", "inertia_tool", "robot", os.path.join(description, "urdf", "ur.urdf.xacro"),
               "--run-xacro", "--arg", "ur_type:=ur5e", "--arg", "name:=ur", "--package",
               f"ur_description={description}", "--geometry", "visual", "--repair", "--density", "1000"]
    for name in assume:
        command += ["--assume", name]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    with open(out, "w") as sink:
        # run in the tree: ``python -m`` puts the working folder first on sys.path, ahead of PYTHONPATH, so a run
        # started from another checkout measured that checkout
        subprocess.run(command, env=env, cwd=tree, stdout=sink, stderr=subprocess.STDOUT, check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime, wall, after.ru_maxrss)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("description", help="the ur_description folder (Universal Robots' ROS 2 description)")
    parser.add_argument("--trees", nargs="+", default=[os.path.dirname(HERE)])
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--out", default=".")
    parser.add_argument("--assume", action="append", default=[], metavar="NAME")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    args.description, args.out = os.path.abspath(args.description), os.path.abspath(args.out)
    args.trees = [os.path.abspath(tree) for tree in args.trees]
    for run in range(1, args.runs + 1):
        for tree in args.trees:
            name = os.path.basename(os.path.normpath(tree))
            load = os.getloadavg()[0]
            user, system, wall, peak = run_once(tree, args.description, os.path.join(args.out, f"{name}_{run}.txt"),
                                                 tuple(args.assume))
            print(f"{name} run {run} load {load:.1f}: user {user:.2f} s, system {system:.2f} s, "
                  f"CPU {user + system:.2f} s, wall {wall:.1f} s, largest child RSS so far {peak // 1024} MB",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
