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

INCLUDE=$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
SUFFIX=$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
mkdir -p "$OUT/pkg"
cp -R "$ROOT/inertia_tool" "$OUT/pkg/inertia_tool"
find "$OUT/pkg/inertia_tool" -name '_accel*.so' -delete
find "$OUT/pkg/inertia_tool" -name '__pycache__' -prune -exec rm -rf {} +
"$CC" -shared -fPIC -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined \
    -fno-sanitize-recover=undefined -Wall -Werror -I"$INCLUDE" \
    "$ROOT/inertia_tool/_accel.c" -o "$OUT/pkg/inertia_tool/_accel$SUFFIX"

ASAN_LIB=$("$CC" -print-file-name=libasan.so)
UBSAN_LIB=$("$CC" -print-file-name=libubsan.so)
status=0
env PYTHONPATH="$OUT/pkg" PYTHONDONTWRITEBYTECODE=1 INERTIA_TOOL_NO_ACCEL= \
    INERTIA_SANITIZE_EXTENSION="$OUT/pkg/inertia_tool/_accel$SUFFIX" \
    LD_PRELOAD="$ASAN_LIB $UBSAN_LIB" \
    ASAN_OPTIONS="detect_leaks=0:halt_on_error=1:abort_on_error=1:log_path=$OUT/sanitizer" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$OUT/sanitizer" \
    "$PYTHON" "$ROOT/fuzz/sanitize_replay.py" --mutations "$MUTATIONS" --seed "$SEED" || status=$?

# the replay checks that it ran the sanitizer build; any report in the log is a failure too
if ls "$OUT"/sanitizer.* >/dev/null 2>&1; then
    echo "sanitize: sanitizer reports:" >&2
    cat "$OUT"/sanitizer.* >&2
    status=1
fi
if [ "$status" -ne 0 ]; then
    echo "sanitize: FAILED (exit $status); build and logs kept in $OUT" >&2
    exit "$status"
fi
rm -rf "$OUT"
echo "sanitize: OK (AddressSanitizer + UndefinedBehaviorSanitizer, no reports)"
