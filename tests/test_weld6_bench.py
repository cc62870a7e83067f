"""The stage benchmark refuses to time a checkout whose C kernels are not loaded (issue 25): a rebase that changes
``_accel.c`` without a rebuild makes the package fall back to numpy with one warning, and every row would then
time another program."""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks"))

import bench_stages  # noqa: E402

import inertia_tool._native as native  # noqa: E402


def test_a_stale_or_missing_build_stops_the_benchmark_with_one_line(monkeypatch):
    monkeypatch.delenv(native.NO_ACCEL_ENV, raising=False)
    monkeypatch.setattr(native, "_MODULE", [None])          # what accel() caches for a stale or missing build
    with pytest.raises(SystemExit) as stop:
        bench_stages.main(["--sizes", "1m", "--repeat", "1"])
    message = str(stop.value)
    assert "C kernels" in message and "rebuild" in message and "\n" not in message


def test_numpy_on_purpose_is_allowed(monkeypatch):
    monkeypatch.setenv(native.NO_ACCEL_ENV, "1")
    bench_stages.require_c_kernels()                         # no SystemExit


def test_a_loaded_build_passes(monkeypatch):
    monkeypatch.delenv(native.NO_ACCEL_ENV, raising=False)
    if native.accel() is None:
        pytest.skip("the C extension is not built here")
    bench_stages.require_c_kernels()
