"""Coverage-guided fuzzing of the mesh readers and ``inertia-tool analyze`` with atheris (libFuzzer).

The first byte of each input chooses the format (STL, OBJ, PLY, OFF); the rest is written to a file in a
RAM disk and run through ``inertia_tool.cli.main(["analyze", FILE, "--json"])`` in-process.  A finding is
any exit code other than 0 (a result) or 3 (one-line mesh error), an internal error, a message without the
file's name, or an accepted file whose JSON carries a non-finite or missing number.

Run (seeds from the hostile corpus, ~100 000 inputs)::

    python tests/corpus/make_corpus.py /tmp/corpus
    python fuzz/fuzz_analyze.py --seeds /tmp/corpus -- -atheris_runs=100000 -max_len=4096 \
        -artifact_prefix=fuzz/crashes/ fuzz/work

Every input that ever crashed is kept in ``tests/regressions/`` and replayed by ``tests/test_hostile.py``.
``run_one`` (the checks of one input) is also used without atheris by ``fuzz/sanitize_replay.py``, the
bounded replay that ``scripts/sanitize.sh`` runs under AddressSanitizer and UndefinedBehaviorSanitizer.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

if __name__ == "__main__":
    import atheris  # noqa: E402

    sys.path.insert(0, HERE)
    from instrumented import INCLUDE, import_readers  # noqa: E402

    # the readers load lazily: imported here, inside the block, or they are not instrumented (58 edges before)
    with atheris.instrument_imports(include=list(INCLUDE)):
        import_readers()
        from inertia_tool.cli import main  # noqa: E402
else:   # imported for its checks (run_one) by fuzz/sanitize_replay.py, without atheris
    from inertia_tool.cli import main  # noqa: E402

SUFFIXES = (".stl", ".obj", ".ply", ".off")
_TMP = tempfile.mkdtemp(prefix="inertia-fuzz-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None)


class Finding(Exception):
    """The tool misbehaved on this input."""


def _numbers(x):
    if isinstance(x, dict):
        for v in x.values():
            yield from _numbers(v)
    elif isinstance(x, list):
        for v in x:
            yield from _numbers(v)
    elif isinstance(x, float):
        yield x


def run_one(data: bytes, suffix: str) -> tuple[int, str, str]:
    """Run analyze on ``data`` saved with ``suffix``; raise Finding on misbehaviour."""
    path = os.path.join(_TMP, "input" + suffix)
    with open(path, "wb") as fh:
        fh.write(data)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["analyze", path, "--json"])
    stderr = err.getvalue()
    if code not in (0, 3) or "internal error" in stderr or "Traceback" in stderr:
        raise Finding(f"exit {code}: {stderr.strip()[:500]}")
    if code == 3:
        errors = [line for line in stderr.splitlines() if line.startswith("inertia-tool: error:")]
        if len(errors) != 1 or path not in errors[0]:
            raise Finding(f"exit 3 without a one-line error naming the file: {stderr[:500]!r}")
    else:
        result = json.loads(out.getvalue())
        for key in ("mass", "volume"):
            if not (isinstance(result.get(key), float) and math.isfinite(result[key]) and result[key] > 0):
                raise Finding(f"accepted with {key} = {result.get(key)!r}")
        if result.get("center_of_mass") is None or None in result["center_of_mass"] or \
                any(v is None for row in result["inertia"] for v in row):
            raise Finding("accepted with a missing (non-finite) number")
        if not all(math.isfinite(v) for v in _numbers(result)):
            raise Finding("accepted with a non-finite number")
    return code, out.getvalue(), stderr


def TestOneInput(data: bytes) -> None:
    if not data:
        return
    run_one(data[1:], SUFFIXES[data[0] % len(SUFFIXES)])


def seed_directory(corpus: str, work: str) -> None:
    """Copy small files of the hostile corpus as seeds, prefixed with their format byte."""
    os.makedirs(work, exist_ok=True)
    for name in sorted(os.listdir(corpus)):
        path = os.path.join(corpus, name)
        suffix = os.path.splitext(name)[1].lower()
        if not os.path.isfile(path) or suffix not in SUFFIXES or os.path.getsize(path) > 8192:
            continue
        data = bytes([SUFFIXES.index(suffix)]) + open(path, "rb").read()
        with open(os.path.join(work, "seed-" + os.fsencode(name).hex()), "wb") as fh:
            fh.write(data)


if __name__ == "__main__":
    argv = sys.argv[1:]
    if argv[:1] == ["--seeds"]:
        seeds, argv = argv[1], argv[2:]
        if argv[:1] == ["--"]:
            argv = argv[1:]
        work = [a for a in argv if not a.startswith("-")]
        seed_directory(seeds, work[0] if work else os.path.join(HERE, "work"))
    try:
        atheris.Setup([sys.argv[0]] + argv, TestOneInput)
        atheris.Fuzz()
    finally:
        shutil.rmtree(_TMP, ignore_errors=True)
