#!/bin/sh
# Build the C extension with ThreadSanitizer into a temporary folder and run the thread tests
# (tests/test_native_threads.py) against it: any data race in the threaded kernels is a failure.  The tests of
# one-thread code (marked one_thread) are left out, and INERTIA_TOOL_TSAN=1 has the others run each kernel on
# several threads only (the ordinary run of the file adds one thread): no race can be found on one thread.
#
#     scripts/tsan.sh
#
# Needs gcc (or CC) with libtsan and the Python headers; libtsan is preloaded (LD_PRELOAD) ahead of the
# uninstrumented interpreter.  The log goes to $OUT/tsan.* (OUT: the temporary folder, kept on failure).
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PYTHON=${PYTHON:-python3}
CC=${CC:-gcc}
OUT=$(mktemp -d "${TMPDIR:-/tmp}/inertia-tsan.XXXXXX")

. "$ROOT/scripts/instrumented.sh"
build_instrumented "$OUT" -fsanitize=thread -pthread
cp -R "$ROOT/tests" "$OUT/pkg/tests"
find "$OUT/pkg/tests" -name '__pycache__' -prune -exec rm -rf {} +

TSAN_LIB=$("$CC" -print-file-name=libtsan.so)
status=0
(cd "$OUT/pkg" && env PYTHONPATH="$OUT/pkg" PYTHONDONTWRITEBYTECODE=1 INERTIA_TOOL_NO_ACCEL= \
    INERTIA_TOOL_REQUIRE_ACCEL=1 INERTIA_TOOL_TSAN=1 LD_PRELOAD="$TSAN_LIB" \
    TSAN_OPTIONS="report_signal_unsafe=0:halt_on_error=0:log_path=$OUT/tsan" \
    "$PYTHON" -m pytest -q -p no:cacheprovider -m "not one_thread" tests/test_native_threads.py) || status=$?

finish_instrumented tsan "$OUT" tsan "$status" "the threaded kernels ran under ThreadSanitizer without reports"
