"""Turn a fuzzer crash file into a regression input: ``python fuzz/save_regression.py CRASH NAME``.

The first byte of a fuzz input selects the format (as in ``fuzz_analyze.py``); the rest is the file.
It is written to ``tests/regressions/NAME<suffix>``, which ``tests/test_hostile.py`` replays.
"""

import os
import sys

SUFFIXES = (".stl", ".obj", ".ply", ".off")   # keep in step with fuzz_analyze.SUFFIXES

if __name__ == "__main__":
    crash, name = sys.argv[1:3]
    data = open(crash, "rb").read()
    out = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "regressions",
                       name + SUFFIXES[data[0] % len(SUFFIXES)])
    with open(out, "wb") as fh:
        fh.write(data[1:])
    print(out)
