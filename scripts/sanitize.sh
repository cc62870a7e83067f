#!/bin/sh
# Build the C extension with AddressSanitizer + UndefinedBehaviorSanitizer into a temporary folder and run a
# bounded replay of the hostile corpus, random mutations of it and edge-case calls of the C API against it
# (fuzz/sanitize_replay.py).  Fails on any sanitizer report or misbehaviour.  One command, from anywhere:
#
#     scripts/sanitize.sh [MUTATIONS] [SEED]        # defaults: 2000 mutations, seed 1
#
# Needs gcc (or CC) with libasan/libubsan and the Python headers; the Python interpreter itself is not
# instrumented, so libasan is preloaded (LD_PRELOAD) ahead of it.  Leak detection is off: CPython keeps
# memory alive until exit by design.  The sanitizer log goes to $OUT/sanitizer.* (OUT: the temporary folder,
# kept on failure).
set -eu
MUTATIONS=${1:-2000}
SEED=${2:-1}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PYTHON=${PYTHON:-python3}
CC=${CC:-gcc}
OUT=$(mktemp -d "${TMPDIR:-/tmp}/inertia-sanitize.XXXXXX")

. "$ROOT/scripts/instrumented.sh"
build_instrumented "$OUT" -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined

ASAN_LIB=$("$CC" -print-file-name=libasan.so)
UBSAN_LIB=$("$CC" -print-file-name=libubsan.so)
status=0
env PYTHONPATH="$OUT/pkg" PYTHONDONTWRITEBYTECODE=1 INERTIA_TOOL_NO_ACCEL= \
    INERTIA_SANITIZE_EXTENSION="$EXT" \
    LD_PRELOAD="$ASAN_LIB $UBSAN_LIB" \
    ASAN_OPTIONS="detect_leaks=0:halt_on_error=1:abort_on_error=1:log_path=$OUT/sanitizer" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$OUT/sanitizer" \
    "$PYTHON" "$ROOT/fuzz/sanitize_replay.py" --mutations "$MUTATIONS" --seed "$SEED" || status=$?

# the replay checks that it ran the sanitizer build; any report in the log is a failure too
finish_instrumented sanitize "$OUT" sanitizer "$status" "OK (AddressSanitizer + UndefinedBehaviorSanitizer, no reports)"
