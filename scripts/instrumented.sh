# Shared by scripts/sanitize.sh and scripts/tsan.sh (sourced, not run): a copy of the package in a temporary
# folder with the C extension built under a sanitizer, and the verdict from the sanitizer's log.
# Expects ROOT, PYTHON and CC to be set.

# build_instrumented OUT FLAGS...: copy inertia_tool to OUT/pkg and build _accel there with FLAGS; sets EXT to
# the built extension.
build_instrumented() {
    out=$1
    shift
    include=$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
    suffix=$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
    mkdir -p "$out/pkg"
    cp -R "$ROOT/inertia_tool" "$out/pkg/inertia_tool"
    find "$out/pkg/inertia_tool" -name '_accel*.so' -delete
    find "$out/pkg/inertia_tool" -name '__pycache__' -prune -exec rm -rf {} +
    EXT="$out/pkg/inertia_tool/_accel$suffix"
    "$CC" -shared -fPIC -g -O1 "$@" -Wall -Werror -I"$include" "$ROOT/inertia_tool/_accel.c" -o "$EXT"
}

# finish_instrumented NAME OUT LOG STATUS MESSAGE: fail (exit) when STATUS is nonzero or the sanitizer wrote a
# report (OUT/LOG.*), keeping OUT; else remove OUT and print MESSAGE.
finish_instrumented() {
    name=$1 out=$2 log=$3 status=$4 message=$5
    if ls "$out/$log".* >/dev/null 2>&1; then
        echo "$name: sanitizer reports:" >&2
        cat "$out/$log".* >&2
        status=1
    fi
    if [ "$status" -ne 0 ]; then
        echo "$name: FAILED (exit $status); build and logs kept in $out" >&2
        exit "$status"
    fi
    rm -rf "$out"
    echo "$name: $message"
}
