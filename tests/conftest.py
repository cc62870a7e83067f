import os
import signal
import subprocess
import time
import warnings

import numpy as np
import pytest
import trimesh
from hypothesis import settings

# CI runs the property tests on a fixed sequence of examples so a landing never depends on a random draw;
# developers' runs (no CI variable) keep exploring new examples.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

#: A developer's scaled run of the property tests (the adversarial review at scale): every hypothesis test's
#: max_examples multiplied by this factor, and its examples drawn from ``--hypothesis-seed`` instead of a fixed
#: sequence (``derandomize`` off), e.g. ``INERTIA_TOOL_HYPOTHESIS_SCALE=20 pytest tests/test_review_proofs.py
#: --hypothesis-seed 7``.  Unset (CI, ordinary runs): nothing changes.
HYPOTHESIS_SCALE = float(os.environ.get("INERTIA_TOOL_HYPOTHESIS_SCALE", "0") or 0)


def pytest_configure(config):
    """Markers of the tests' own (here, not in pyproject.toml: scripts/tsan.sh runs a copy of tests/ without it)."""
    config.addinivalue_line("markers", "one_thread: a test of one-thread code only (scripts/tsan.sh leaves it out: "
                            "no data race to find there)")


def pytest_collection_modifyitems(items):
    """Apply :data:`HYPOTHESIS_SCALE` to the collected hypothesis tests (their settings are read when they run,
    so the explicit ``@settings(max_examples=...)`` of each is scaled, not replaced)."""
    if HYPOTHESIS_SCALE <= 0:
        return
    for item in items:
        test = getattr(item, "obj", None)
        current = getattr(test, "_hypothesis_internal_use_settings", None)
        if current is None or getattr(test, "_inertia_tool_scaled", False):
            continue
        test._hypothesis_internal_use_settings = settings(
            current, max_examples=max(1, int(round(current.max_examples * HYPOTHESIS_SCALE))), derandomize=False,
            database=None)
        test._inertia_tool_scaled = True


class MujocoWarning(UserWarning):
    """A warning MuJoCo issued (it would otherwise append it to MUJOCO_LOG.TXT in the working directory)."""


def pytest_collection_finish(session):
    """MuJoCo writes its warnings to ``MUJOCO_LOG.TXT`` in the current directory (the repository root under
    pytest): when a selected test module uses MuJoCo, route them to Python warnings instead (imported only then:
    the import takes most of a second)."""
    paths = {str(item.fspath) for item in session.items}
    if not any("mujoco" in open(path, encoding="utf-8", errors="replace").read() for path in paths
               if path.endswith(".py")):
        return
    try:
        import mujoco
    except ImportError:
        return
    mujoco.set_mju_user_warning(lambda message: warnings.warn(f"MuJoCo: {message}", MujocoWarning, stacklevel=1))


@pytest.fixture
def box_mesh():
    """Axis-aligned box 1 x 2 x 3 m centred at the origin (trimesh, outward winding)."""
    return trimesh.creation.box([1.0, 2.0, 3.0])


def box_arrays(extents=(1.0, 2.0, 3.0), center=(0.0, 0.0, 0.0)):
    m = trimesh.creation.box(extents)
    return np.asarray(m.vertices) + np.asarray(center), np.asarray(m.faces)


def write_binary_stl(path, vertices, faces, header=b"", extra=b""):
    tri = np.asarray(vertices, dtype=np.float32)[np.asarray(faces)]
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    with open(path, "wb") as fh:
        fh.write(header.ljust(80, b" ")[:80])
        fh.write(np.uint32(len(tri)).tobytes())
        fh.write(rec.tobytes())
        fh.write(extra)


def write_ascii_stl(path, vertices, faces, newline="\n"):
    tri = np.asarray(vertices, dtype=float)[np.asarray(faces)]
    lines = ["solid test"]
    for t in tri:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in t]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid test")
    with open(path, "w", newline="") as fh:
        fh.write(newline.join(lines) + newline)


try:
    from inertia_tool import _accel  # noqa: F401  (the optional C extension)
    HAVE_ACCEL = True
except ImportError:
    HAVE_ACCEL = False

#: CI sets this so that a silently failed build of the C extension fails the suite instead of skipping.
REQUIRE_ACCEL = os.environ.get("INERTIA_TOOL_REQUIRE_ACCEL", "") not in ("", "0")


def _engine_state():
    """What selects the engine's path: the two environment variables ``_native`` reads, its ``accel`` function
    and its cached import (the list and what it holds)."""
    from inertia_tool import _native

    return (os.environ.get(_native.NO_ACCEL_ENV), os.environ.get(_native.THREADS_ENV), _native.accel,
            id(_native._MODULE), [id(m) for m in _native._MODULE])


@pytest.fixture(autouse=True)
def _engine_path_restored():
    """Issue 21 (leak16): a test that leaves the numpy path (or a thread count, or a stand-in for ``accel``)
    selected changes what every later test in the process runs; this fails the test that did it, after its own
    fixtures (``monkeypatch``) are undone.  The first import of the extension (an empty cache filled) is not a
    change."""
    before = _engine_state()
    yield
    after = _engine_state()
    if before[4] == [] and after[3] == before[3]:
        after = after[:4] + ([],)
    if after != before:
        pytest.fail(f"the test left the engine's path changed: (NO_ACCEL, THREADS, accel, cache, cached) "
                    f"{before!r} -> {after!r}; restore it (monkeypatch.setenv/delenv, monkeypatch.setattr)")


@pytest.fixture(params=["c", "numpy"])
def engine_path(request, monkeypatch):
    """Run a test on the C extension's kernels and on the pure-numpy path (the reference).

    Engine test modules apply it to every test with ``pytestmark = pytest.mark.usefixtures("engine_path")``.
    """
    if request.param == "c":
        if not HAVE_ACCEL:
            if REQUIRE_ACCEL:
                pytest.fail("inertia_tool._accel is not built but INERTIA_TOOL_REQUIRE_ACCEL is set")
            pytest.skip("inertia_tool._accel is not built (no C compiler at install time)")
        monkeypatch.delenv("INERTIA_TOOL_NO_ACCEL", raising=False)
    else:
        monkeypatch.setenv("INERTIA_TOOL_NO_ACCEL", "1")
    return request.param


def assert_tensor_close(actual, desired, rtol, err_msg=""):
    """Compare two computed tensors with a tolerance scaled to the tensor, not entry by entry.

    A relative tolerance alone fails on entries that are round-off zeros (an off-diagonal of -7.5e-38 against
    0.0 is a perfect match for a tensor of norm 1e-5, but infinitely far in relative terms); an absolute one
    alone means nothing across units.  Every entry must agree to ``rtol`` times the larger Frobenius norm of
    the two tensors, plus ``rtol`` relative to itself.
    """
    actual = np.asarray(actual, dtype=float)
    desired = np.asarray(desired, dtype=float)
    scale = max(np.linalg.norm(actual), np.linalg.norm(desired))
    np.testing.assert_allclose(actual, desired, rtol=rtol, atol=rtol * scale, err_msg=err_msg)


def kill_after_lines(cmd, out, lines, *, env=None, seconds=60.0, poll=0.05):
    """Start ``cmd``, wait until the file ``out`` holds at least ``lines`` line breaks (or the process ended, or
    ``seconds`` passed), then SIGKILL it (a crash in the middle of a run) and reap it."""
    proc = subprocess.Popen(cmd, env=env, stderr=subprocess.DEVNULL)
    try:
        for _ in range(int(seconds / poll)):
            if out.exists() and out.read_bytes().count(b"\n") >= lines or proc.poll() is not None:
                break
            time.sleep(poll)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()


#: ``offset.core_moments`` results by their arguments' bytes, shared by the tests that ask for
#: :func:`core_moments_memo` (several CLI commands on the same printed part: about 7 s of CPU each).
_CORE_MOMENTS = {}


@pytest.fixture
def core_moments_memo(monkeypatch):
    """``thinwall.core_moments`` answered from a cache for arguments seen before (bit for bit the same arrays,
    depth, origin and band): a pure function, so a repeated call gets what it would compute.  Any difference in
    what a command passes (another skin, top or bottom, a rounding of a unit) misses the cache and is
    computed."""
    from inertia_tool.mass import offset, thinwall

    def memo(vertices, faces, depth, *, origin, band_cells=offset.DEFAULT_BAND_CELLS):
        v, f, o = (np.ascontiguousarray(a) for a in (vertices, faces, origin))
        key = (v.dtype.str, v.shape, v.tobytes(), f.dtype.str, f.shape, f.tobytes(), float(depth).hex(),
               o.tobytes(), int(band_cells))
        if key not in _CORE_MOMENTS:
            _CORE_MOMENTS[key] = offset.core_moments(vertices, faces, depth, origin=origin, band_cells=band_cells)
        return _CORE_MOMENTS[key]

    monkeypatch.setattr(thinwall, "core_moments", memo)
