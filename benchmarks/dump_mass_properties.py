"""Every field of ``mass_properties`` (plain and ``repair=True``) of a corpus of real files, one line per file and
mode, byte for byte, so that two checkouts can be compared with ``cmp`` (issue 25: a faster kernel must give the
same answer and the same certificate).

    PYTHONPATH=<main checkout> python benchmarks/dump_mass_properties.py /tmp/main.tsv
    PYTHONPATH=. python benchmarks/dump_mass_properties.py /tmp/branch.tsv
    cmp /tmp/main.tsv /tmp/branch.tsv

Default corpus: trimesh's test models (``--models``: its STL, OBJ, PLY and OFF files) and every STL file under
the gazebo models folder (``--gazebo``), files above ``--max-mb`` left out.  A line is the path, the mode and
either the result (every dataclass field, recursively; floats as ``float.hex``, arrays as dtype, shape and raw
bytes) or the exception's type and message (a refusal must be the same refusal).  Warnings are ignored.  The
package measured is the one ``import inertia_tool`` finds (printed to stderr with the CPU time).
"""

from __future__ import annotations

import argparse
import dataclasses
import glob
import os
import sys
import time
import warnings

import numpy as np


def encode(value: object, depth: int = 0) -> str:
    """A text form of ``value`` that differs whenever a bit of it does (dataclasses to depth 6)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type) and depth < 6:
        fields = (f"{f.name}={encode(getattr(value, f.name), depth + 1)}" for f in dataclasses.fields(value))
        return "{" + ", ".join(fields) + "}"
    if isinstance(value, np.ndarray):
        return f"{value.dtype}{value.shape}:{value.tobytes().hex()}"
    if isinstance(value, float):
        return value.hex()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(encode(item, depth + 1) for item in value) + "]"
    return repr(value)


def corpus(models: str, gazebo: str, max_mb: float) -> list[str]:
    """The files compared: trimesh's models of the formats read natively, then gazebo's STL files, sorted."""
    files = sorted(f for f in glob.glob(os.path.join(models, "*"))
                   if f.lower().rsplit(".", 1)[-1] in ("stl", "obj", "ply", "off"))
    files += sorted(glob.glob(os.path.join(gazebo, "**", "*.stl"), recursive=True)
                    + glob.glob(os.path.join(gazebo, "**", "*.STL"), recursive=True))
    return [f for f in files if os.path.getsize(f) <= max_mb * 1e6]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the file written (one line per file and mode)")
    parser.add_argument("--models", default="/work/data/tm/models", help="trimesh's test models folder")
    parser.add_argument("--gazebo", default="/work/data/gazebo", help="gazebo models folder (STL files, recursive)")
    parser.add_argument("--max-mb", type=float, default=60.0, help="files larger than this are left out")
    args = parser.parse_args(argv)
    import inertia_tool
    from inertia_tool import mass_properties

    files = corpus(args.models, args.gazebo, args.max_mb)
    start = time.process_time()
    with open(args.out, "w") as out:
        for path in files:
            for repair in (False, True):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        line = encode(mass_properties(path, repair=repair))
                    except Exception as error:  # every refusal is compared too
                        line = f"{type(error).__name__}: {error}"
                out.write(f"{path}\t{repair}\t{line}\n")
    print(f"{inertia_tool.__file__}: {len(files)} files, {2 * len(files)} lines, "
          f"CPU {time.process_time() - start:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
