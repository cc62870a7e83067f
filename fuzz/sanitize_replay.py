"""Bounded replay for the sanitizer run (``scripts/sanitize.sh``): the hostile corpus, seeded random mutations
of it, and direct calls of the C kernels with edge-case arguments.

It needs no fuzzing engine: every input goes through the checks of ``fuzz_analyze.run_one`` (exit 0 with
finite numbers, or exit 3 with one line naming the file), and ``inertia_tool._accel`` is whatever the
caller put first on ``PYTHONPATH`` (the sanitizer build, under ``scripts/sanitize.sh``).  A sanitizer report
aborts the process (``halt_on_error``), so the exit code says it all; a misbehaviour the checks catch is
printed and counted.

Usage::

    python fuzz/sanitize_replay.py --mutations 2000 --seed 1 [--max-bytes 65536]

Prints one summary line: ``inputs N (corpus C, mutations M, C API calls K), findings F``; exit 1 when F > 0.
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.append(ROOT)                  # after PYTHONPATH, which names the package under test
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402

import inertia_tool  # noqa: E402,F401  (imported first: fuzz_analyze puts ROOT ahead on sys.path)

from corpus.make_corpus import make_corpus  # noqa: E402
import fuzz_analyze  # noqa: E402
from fuzz_analyze import SUFFIXES, Finding, run_one  # noqa: E402

#: Integers that sit on the edges of header counts and index types.
_BOUNDARY_WORDS = (0, 1, 2, 3, 0x7F, 0xFF, 0x7FFF, 0xFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0x2AAAAAAB)


def mutate(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    """One random change of ``data``: bit flips, a boundary integer, a cut, a duplicated or inserted run of
    bytes, or a splice with another input."""
    if not data:
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 64)))
    b = bytearray(data)
    kind = rng.randrange(6)
    if kind == 0:
        for _ in range(rng.randrange(1, 9)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
    elif kind == 1 and len(b) >= 4:
        i = rng.randrange(len(b) - 3)
        b[i:i + 4] = rng.choice(_BOUNDARY_WORDS).to_bytes(4, "little")
    elif kind == 2:
        del b[rng.randrange(len(b)):]
    elif kind == 3:
        i, j = sorted(rng.randrange(len(b) + 1) for _ in range(2))
        b[j:j] = b[i:j][:4096]
    elif kind == 4:
        i = rng.randrange(len(b) + 1)
        b[i:i] = bytes(rng.choice(b" \n\t0123456789.-e+/facetvrxdn") for _ in range(rng.randrange(1, 32)))
    else:
        other = rng.choice(others)
        i, j = rng.randrange(len(b) + 1), rng.randrange(len(other) + 1)
        b = b[:i] + other[j:]
    return bytes(b)


def c_api_calls() -> int:
    """Call every kernel of ``inertia_tool._accel`` with empty, minimal and invalid arguments; return the
    number of calls.  Invalid arguments must raise ValueError/TypeError, never touch memory."""
    from inertia_tool._native import accel
    lib = accel()
    if lib is None:
        raise SystemExit("inertia_tool._accel is not importable: nothing to sanitize")
    expected = os.environ.get("INERTIA_SANITIZE_EXTENSION")
    if expected and os.path.realpath(lib.__file__) != os.path.realpath(expected):
        raise SystemExit(f"expected the sanitizer build {expected}, imported {lib.__file__}")
    print(f"sanitize replay: C extension {lib.__file__}", file=sys.stderr)
    calls = 0

    def expect_error(fn, *args):
        nonlocal calls
        calls += 1
        try:
            fn(*args)
        except (ValueError, TypeError, OverflowError, MemoryError):
            return
        raise Finding(f"{getattr(fn, '__name__', fn)} accepted invalid arguments")

    for dtype in ("float32", "float64"):
        w = lib.Welder(dtype, 0)
        w.vertices_into(np.empty((0, 3)))                          # zero vertices: no copy of 0 bytes
        w.feed(np.empty((0, 3), dtype=dtype), np.empty(0, dtype=np.int32))
        w.vertices_into(np.empty((0, 3)))
        pts = np.array([[0.0, -0.0, 1.0], [0.0, 0.0, 1.0], [np.nan, 1, 2]], dtype=dtype)
        ids = np.empty(3, dtype=np.int32)
        w.feed(pts, ids)
        out = np.empty((w.count, 3))
        w.vertices_into(out)
        calls += 5
        expect_error(w.vertices_into, np.empty((w.count + 1, 3)))
        expect_error(w.feed, pts, np.empty(2, dtype=np.int32))
        expect_error(w.feed, pts[:, :2], np.empty(3, dtype=np.int32))
        expect_error(w.feed, pts.astype(np.float16), ids)
    expect_error(lib.Welder, "int8", 0)
    for hint in (-5, 1 << 62):                                    # a size hint is clamped, never trusted
        lib.Welder("float32", hint).vertices_into(np.empty((0, 3)))
        calls += 1
    for itype in (np.int32, np.int64):
        none = np.empty((0, 3), dtype=itype)
        lib.edge_census(none, 0)
        lib.shell_labels(none, 0, np.empty(0, dtype=itype))
        sums, zero = np.zeros((1, 11)), np.zeros(1, dtype=np.int64)
        lib.tetra_sums(np.empty((0, 3)), none, (0.0, 0.0, 0.0), 0.0, None, sums, zero)
        lib.edge_shell_labels(none, 0, np.empty(0, dtype=itype))
        lib.face_measures(np.empty((0, 3)), none)
        calls += 5
        tri = np.array([[0, 1, 2]], dtype=itype)
        bad = np.array([[0, 1, 3]], dtype=itype)
        neg = np.array([[0, -1, 2]], dtype=itype)
        v = np.eye(3)
        lib.edge_census(tri, 3)
        lib.shell_labels(tri, 3, np.empty(1, dtype=itype))
        lib.tetra_sums(v, tri, (0.0, 0.0, 0.0), 0.0, None, sums, zero)
        lib.edge_shell_labels(tri, 3, np.empty(1, dtype=itype))
        lib.face_measures(v, tri, 2)
        lib.contact_scan(v, np.tile(tri, (3, 1)), -1, 2)
        calls += 6
        # boxes past float32's range (-inf .. +inf) must not meet a leaf's empty padding positions
        huge = np.array([[-1e300] * 3, [1e300] * 3, [1e300, -1e300, 1e300], [-1e300, 1e300, -1e300]])
        lib.contact_scan(huge, np.array([[0, 1, 2], [0, 1, 3], [1, 2, 3]], dtype=itype), -1, 1, 3)
        out = np.zeros((1, 3))
        lib.roundoff_sums(np.empty((0, 3)), none, (0.0, 0.0, 0.0), None, out, 1)
        lib.roundoff_sums(v, tri, (0.0, 0.0, 0.0), None, out, 1 << 62)
        calls += 3
        expect_error(lib.roundoff_sums, v, tri, (0.0, 0.0, 0.0), np.array([5], dtype=itype), np.zeros((2, 3)), 8)
        expect_error(lib.roundoff_sums, v, tri, (0.0, 0.0, 0.0), None, np.zeros((0, 3)), 8)
        for faces in (bad, neg):
            expect_error(lib.edge_shell_labels, faces, 3, np.empty(1, dtype=itype))
            expect_error(lib.face_measures, v, faces)
            expect_error(lib.contact_scan, v, faces, -1)
            expect_error(lib.roundoff_sums, v, faces, (0.0, 0.0, 0.0), None, np.zeros((1, 3)), 8)
            expect_error(lib.edge_census, faces, 3)
            expect_error(lib.shell_labels, faces, 3, np.empty(1, dtype=itype))
            expect_error(lib.tetra_sums, v, faces, (0.0, 0.0, 0.0), 0.0, None, sums, zero)
        expect_error(lib.edge_census, tri, -1)
        expect_error(lib.edge_census, np.asfortranarray(np.tile(tri, (2, 1))), 3)
        expect_error(lib.shell_labels, tri, 3, np.empty(2, dtype=itype))
        expect_error(lib.edge_shell_labels, tri, 3, np.empty(2, dtype=itype))
        expect_error(lib.tetra_sums, v, tri, (0.0, 0.0, 0.0), 0.0, np.array([5], dtype=itype), sums, zero)
    return calls


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mutations", type=int, default=2000, help="random mutations to run (default 2000)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    ap.add_argument("--max-bytes", type=int, default=1 << 16,
                    help="corpus files larger than this are replayed but not mutated (default 65536)")
    args = ap.parse_args(argv)
    rng = random.Random(args.seed)
    findings = 0
    try:
        calls = c_api_calls()             # first: proves the extension under test is the one imported
    except Finding as exc:
        findings, calls = 1, 0
        print(f"finding: C API: {exc}", file=sys.stderr)
    with tempfile.TemporaryDirectory(prefix="inertia-sanitize-") as tmp:
        entries = make_corpus(os.path.join(tmp, "corpus"))
        seeds: list[tuple[bytes, str]] = []
        corpus_runs = 0
        for e in entries:
            suffix = os.path.splitext(e.name)[1].lower()
            if e.args or not os.path.isfile(e.path):
                continue                 # entries that need command-line options are the hostile test's
            data = open(e.path, "rb").read() if os.path.getsize(e.path) <= 64 << 20 else None
            if data is None:
                continue
            corpus_runs += 1
            try:
                run_one(data, suffix)
            except Finding as exc:
                findings += 1
                print(f"finding: corpus {e.name}: {exc}", file=sys.stderr)
            if suffix in SUFFIXES and len(data) <= args.max_bytes:
                seeds.append((data, suffix))
        others = [d for d, _ in seeds]
        for k in range(args.mutations):
            data, suffix = rng.choice(seeds)
            if rng.random() < 0.1:
                suffix = rng.choice(SUFFIXES)                   # the right bytes under the wrong name
            sample = mutate(data, rng, others)
            try:
                run_one(sample, suffix)
            except Finding as exc:
                findings += 1
                keep = os.path.join(HERE, "crashes", f"sanitize-{args.seed}-{k}{suffix}")
                os.makedirs(os.path.dirname(keep), exist_ok=True)
                with open(keep, "wb") as fh:
                    fh.write(sample)
                print(f"finding: mutation {k} ({suffix}, kept as {keep}): {exc}", file=sys.stderr)
    total = corpus_runs + args.mutations + calls
    print(f"sanitize replay: inputs {total} (corpus {corpus_runs}, mutations {args.mutations}, C API calls "
          f"{calls}), findings {findings}")
    return 1 if findings else 0


if __name__ == "__main__":
    try:
        code = main()
    finally:
        import shutil
        shutil.rmtree(fuzz_analyze._TMP, ignore_errors=True)
    sys.exit(code)
