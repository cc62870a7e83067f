"""spin-it over every bundled mesh (``meshes/``): outcome, objective, CPU time and peak memory per run.

Run from the repository root::

    python benchmarks/bench_spin_it_meshes.py [--resolution 48] [--markdown]

Each run is ``inertia-tool spin-it FILE ... --json`` in a fresh process (what a user runs), with the CPU time
(user + system) and peak resident memory of that process from ``os.wait4``.  The goal of each row: the
documented default (``--mode yoyo`` about ``--axis 0,0,1``, resolution 48) on every mesh, and the top and
insert goals where they make sense.  Walls are those of ``bench_spin_it.py``.

Besides the table the script checks the promises of ``design/verify.py``: no run ends with a traceback, every
exit code is a documented one (0, 4 no room, 6 rejected), and a run that exits 0 passed its verification with an
objective no worse than the part's.  It exits 1 when one does not hold.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

#: (label, file, arguments after the common ones)
RUNS = [
    ("box", "box.stl", ["--wall", "2mm"]),
    ("cone", "cone.stl", ["--wall", "2mm"]),
    ("cone, steel insert", "cone.stl", ["--wall", "2mm", "--insert", "steel"]),
    ("hollow_sphere", "hollow_sphere.stl", ["--wall", "1mm"]),
    ("octahedron", "octahedron.stl", ["--wall", "2mm"]),
    ("spinning_top", "spinning_top.stl", ["--wall", "2mm"]),
    ("spinning_top, top", "spinning_top.stl", ["--wall", "2mm", "--mode", "top", "--pivot", "0,0,0"]),
    ("spinning_top, top, steel insert", "spinning_top.stl",
     ["--wall", "2mm", "--mode", "top", "--pivot", "0,0,0", "--insert", "steel"]),
    ("t_handle", "t_handle.stl", ["--wall", "2mm"]),
    ("t_handle, steel insert", "t_handle.stl", ["--wall", "2mm", "--insert", "steel"]),
    ("t_handle, top", "t_handle.stl", ["--wall", "2mm", "--mode", "top", "--pivot", "0,0,0"]),
    ("t_handle, axis y (major)", "t_handle.stl", ["--wall", "2mm", "--axis", "0,1,0"]),
    ("torus", "torus.stl", ["--wall", "2mm"]),
    ("unbalanced_wheel", "unbalanced_wheel.stl", ["--wall", "3mm"]),
    ("unbalanced_wheel, through 0,0,0", "unbalanced_wheel.stl", ["--wall", "3mm", "--through", "0,0,0"]),
    ("washer", "washer.stl", ["--wall", "1.5mm"]),
]

DOCUMENTED_EXITS = {0: "designed", 4: "no room", 6: "rejected"}


#: Runs the command in a process of its own and prints that one child's CPU time and peak memory on stderr's
#: last line (``RUSAGE_CHILDREN`` of a fresh parent is exactly that child's).
_WRAP = ("import resource, subprocess, sys; code = subprocess.call(sys.argv[1:]); "
         "u = resource.getrusage(resource.RUSAGE_CHILDREN); "
         "sys.stderr.write(f'\\n@usage {u.ru_utime + u.ru_stime} {u.ru_maxrss}\\n'); sys.exit(code)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, default=48)
    parser.add_argument("--meshes", default="meshes")
    args = parser.parse_args()
    broken = []
    print("| run | outcome | objective before → after | tilt after | attempts | CPU s | peak MB |")
    print("|---|---|---|---|---|---|---|")
    for label, name, extra in RUNS:
        command = [sys.executable, "-c", _WRAP, sys.executable, "-m", "inertia_tool", "spin-it",
                   os.path.join(args.meshes, name), "--units", "mm", "--material", "pla", "--axis", "0,0,1",
                   "--resolution", str(args.resolution), "--json", *extra]
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        out, err = process.communicate()
        err, _, usage = err.rpartition("@usage ")
        cpu, peak = float(usage.split()[0]), float(usage.split()[1]) / 1024      # s, MB (ru_maxrss is in KB)
        code = process.returncode
        outcome = DOCUMENTED_EXITS.get(code, f"exit {code}")
        objective = tilt = attempts = "—"
        if "Traceback" in err or code not in DOCUMENTED_EXITS:
            broken.append(f"{label}: exit {code}: {err[-300:]}")
        if code == 0:
            body = json.loads(out)
            ob, oa = body["objective"]["before"], body["objective"]["after"]
            objective = f"{ob:.4g} → {oa:.4g}"
            verdicts = body["verification"]["attempts"]
            tilt = f"{verdicts[-1]['axis_tilt_after'] * 57.29577951308232:.3g}°"
            attempts = ", ".join(f"{v['resolution']}" + ("" if v["product_weight"] <= 1e4 else
                                                           f" (w_p {v['product_weight']:.0e})")
                                 for v in verdicts)
            if not body["verification"]["passed"] or oa > ob * (1 + 1e-9):
                broken.append(f"{label}: exit 0 with a worse part ({ob} → {oa})")
        else:
            lines = [line for line in err.splitlines() if "error:" in line]
            outcome += ": " + (lines[-1].split("error:", 1)[1].strip() if lines else err[-200:]).replace("|", "\\|")
        print(f"| {label} | {outcome} | {objective} | {tilt} | {attempts} | {cpu:.2f} | {peak:.0f} |", flush=True)
    for line in broken:
        print("BROKEN:", line, file=sys.stderr)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
