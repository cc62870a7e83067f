"""Acceptance run of issue 5: ``inertia-tool analyze --json`` over the whole hostile corpus, as a user runs it.

Each file runs in its own process (``python -m inertia_tool.cli``); the script checks the exit code against
the corpus table, that no output holds a traceback or internal error, that an error is one line naming the
file, and that every accepted file's numbers match the exact engine on the clean copy.  It reports each
process's peak resident memory (``wait4`` rusage) and the largest.

``--big N`` adds an N-triangle ASCII STL with old-Mac (CR-only) line endings, to show that streaming keeps
memory bounded for text files far larger than the read block.

    python tests/corpus/acceptance.py [--big 1000000]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path[:0] = [HERE, ROOT]

from make_corpus import exact_reference, make_corpus, prism  # noqa: E402


_LAUNCH = """
import sys
from inertia_tool.cli import main
code = main(sys.argv[1:])
sys.stdout.flush()
hwm = [line for line in open("/proc/self/status") if line.startswith("VmHWM")]
sys.stderr.write("\\n@peak-rss " + (hwm[0].split()[1] if hwm else "0") + "\\n")
sys.exit(code)
"""


def run(path, args=()):
    """Run one analysis in a child process; returns (exit code, stdout, stderr, seconds, peak RSS in KiB).

    The peak is the child's own ``VmHWM`` (high-water resident set of its address space after exec), so it
    does not include the parent's memory the way ``ru_maxrss`` of a forked child does.
    """
    env = {**os.environ, "PYTHONPATH": ROOT}
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _LAUNCH, "analyze", path, "--json", *args],
                          capture_output=True, env=env)
    err = proc.stderr.decode("utf-8", "replace")
    head, marker, peak = err.rpartition("\n@peak-rss ")
    if marker:
        err = head
    return (proc.returncode, proc.stdout.decode(), err, time.perf_counter() - start,
            int(peak) if marker and peak.strip().isdigit() else 0)


def write_big_ascii(path, n_triangles):
    v, f = prism(n=max(3, n_triangles // 4), radius=0.05, height=0.2)
    with open(path, "wb") as fh:
        fh.write(b"solid big\r")
        for s in range(0, len(f), 100_000):
            tri = v[f[s:s + 100_000]]
            lines = []
            for t in tri:
                lines.append("facet normal 0 0 0\router loop\rvertex %r %r %r\rvertex %r %r %r\rvertex %r %r %r\r"
                             "endloop\rendfacet\r" % tuple(map(float, t.ravel())))
            fh.write("".join(lines).encode())
        fh.write(b"endsolid big\r")
    return [(v, f)]


def main(argv):
    big = int(argv[argv.index("--big") + 1]) if "--big" in argv else 0
    failures = []
    rows = []
    with tempfile.TemporaryDirectory() as d:
        entries = make_corpus(d)
        jobs = [(e.path, e.args, e.exit_code, e.reference) for e in entries]
        if big:
            p = os.path.join(d, "big-old-mac.stl")
            jobs.append((p, (), 0, write_big_ascii(p, big)))
            print(f"wrote {p}: {os.path.getsize(p) / 2**20:.0f} MiB, {len(jobs[-1][3][0][1]):,} triangles")
        peak_kb = 0
        for path, args, want, ref in jobs:
            code, out, err, seconds, rss = run(path, args)
            peak_kb = max(peak_kb, rss)
            name = os.path.basename(path)
            problems = []
            if code != want:
                problems.append(f"exit {code}, expected {want}")
            if "Traceback" in err or "internal error" in err:
                problems.append("traceback/internal error")
            shown = os.fsencode(path).decode("utf-8", "replace")
            if code == 3:
                lines = [x for x in err.splitlines() if x.startswith("inertia-tool: error:")]
                if len(lines) != 1 or shown not in lines[0]:
                    problems.append("error is not one line naming the file")
            if code == 0 and ref is not None:
                r = json.loads(out)
                want = exact_reference(ref)
                mass, com, inertia = want.mass, want.center_of_mass, want.inertia
                scale = np.abs(inertia).max()
                size = np.ptp(np.concatenate([v for v, _ in ref]), axis=0).max()
                if not (abs(r["mass"] - mass) <= 1e-12 * mass
                        and np.allclose(r["center_of_mass"], com, rtol=0, atol=1e-12 * size)
                        and np.allclose(r["inertia"], inertia, rtol=0, atol=1e-12 * scale)):
                    problems.append("numbers differ from the exact engine on the clean copy")
            rows.append((name, code, seconds, rss, "; ".join(problems) or "ok"))
            if problems:
                failures.append(name)
    for name, code, seconds, rss, status in rows:
        print(f"{code}  {seconds:6.2f} s  {rss / 1024:7.1f} MiB  {status:4}  {name}")
    print(f"\n{len(rows)} files, {len(failures)} failures, peak RSS of any run {peak_kb / 1024:.1f} MiB")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
