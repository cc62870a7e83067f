"""``_native``'s two settings (``INERTIA_TOOL_NO_ACCEL``, ``INERTIA_TOOL_THREADS``) read cheaply on every call.

``accel()`` and ``threads()`` are asked a dozen times per part of a batch; they used to call ``os.environ.get``
(an exception inside for an unset variable) and ``os.sched_getaffinity`` each time.  Now the raw values are looked
up in the environment's own table and decoded again only when they change: every change made through
``os.environ`` (``monkeypatch.setenv``, a pool worker's initializer) must still be seen at the next call, including
a change to a value of the same length, and a forked child must read its CPUs again.
"""

import os

import pytest

from conftest import HAVE_ACCEL
from inertia_tool import _native


def test_every_change_of_the_switch_is_seen_at_the_next_call(monkeypatch):
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "1")
    assert _native.accel() is None
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "0")              # same length as before
    assert (_native.accel() is not None) == HAVE_ACCEL
    monkeypatch.setenv(_native.NO_ACCEL_ENV, "yes")
    assert _native.accel() is None
    monkeypatch.delenv(_native.NO_ACCEL_ENV)
    assert (_native.accel() is not None) == HAVE_ACCEL
    os.environ[_native.NO_ACCEL_ENV] = " 1 "                   # set directly, as a pool initializer does
    try:
        assert _native.accel() is None
    finally:
        del os.environ[_native.NO_ACCEL_ENV]
    assert (_native.accel() is not None) == HAVE_ACCEL


def test_an_unchanged_environment_is_not_read_again(monkeypatch):
    """After the first call, neither ``os.environ.get`` nor ``os.sched_getaffinity`` runs while nothing changes."""
    monkeypatch.delenv(_native.NO_ACCEL_ENV, raising=False)
    monkeypatch.delenv(_native.THREADS_ENV, raising=False)
    _native.accel(), _native.threads()
    if not isinstance(getattr(os.environ, "_data", None), dict):
        pytest.skip("this Python's os.environ keeps no table of encoded names: os.environ.get is asked each time")
    calls = []
    real_get = os.environ.get
    monkeypatch.setattr(os.environ, "get", lambda *a: calls.append(a) or real_get(*a))
    if hasattr(os, "sched_getaffinity"):
        real_affinity = os.sched_getaffinity
        monkeypatch.setattr(os, "sched_getaffinity", lambda pid: calls.append(pid) or real_affinity(pid))
    first = _native.threads()
    for _ in range(20):
        _native.accel()
        assert _native.threads() == first
    assert calls == []
    monkeypatch.setenv(_native.THREADS_ENV, "3")
    assert _native.threads() == 3 and calls                    # the change is read
    calls.clear()
    monkeypatch.setenv(_native.THREADS_ENV, "4")               # same length
    assert _native.threads() == 4
    monkeypatch.delenv(_native.THREADS_ENV)
    assert _native.threads() == first


def test_without_a_table_of_names_the_environment_is_asked_each_time(monkeypatch):
    """A process whose ``os.environ`` is a plain mapping (no ``_data``): every call asks it."""
    fake = {_native.NO_ACCEL_ENV: "1"}
    monkeypatch.setattr(os, "environ", fake)
    assert _native.accel() is None
    fake[_native.NO_ACCEL_ENV] = "0"
    assert (_native.accel() is not None) == HAVE_ACCEL
    fake[_native.THREADS_ENV] = "2"
    assert _native.threads() == 2
    fake[_native.THREADS_ENV] = "5"
    assert _native.threads() == 5


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_a_forked_child_reads_its_cpus_again(monkeypatch):
    monkeypatch.delenv(_native.THREADS_ENV, raising=False)
    _native.threads()
    assert _native._THREADS_MEMO
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:                                                # the child: its memo was cleared at the fork
        try:
            os.write(write, b"cleared" if not _native._THREADS_MEMO else b"kept")
        finally:
            os._exit(0)
    os.close(write)
    os.waitpid(pid, 0)
    assert os.read(read, 16) == b"cleared"
    os.close(read)
