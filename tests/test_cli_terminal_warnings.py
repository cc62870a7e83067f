"""A warning is read once: when standard output and standard error are the same terminal, a warning the report
already shows is not printed again on stderr; redirected, stderr keeps every warning (docs/usage.md, exit codes
and streams).  Run through a real pseudo-terminal, the way a user sees it."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import trimesh

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal")

WARNING = "inside out"


def _inside_out_cube(tmp_path):
    """A closed cube with every face wound inward: read, it is flipped with a warning."""
    box = trimesh.creation.box(extents=(0.02, 0.03, 0.04))
    path = tmp_path / "inward.stl"
    trimesh.Trimesh(box.vertices, np.ascontiguousarray(box.faces[:, ::-1]), process=False).export(path)
    return path


def _run(args, *, stderr_on_terminal: bool) -> tuple[str, str]:
    """(what the terminal shows, what went to a separate stderr pipe) of ``python -m inertia_tool ARGS``."""
    main, child = os.openpty()
    env = {**os.environ, "COLUMNS": "200"}
    proc = subprocess.Popen([sys.executable, "-m", "inertia_tool", *args], stdin=subprocess.DEVNULL,
                            stdout=child, stderr=child if stderr_on_terminal else subprocess.PIPE, env=env)
    os.close(child)
    chunks = []
    while True:
        try:
            data = os.read(main, 65536)
        except OSError:               # EIO: the child's side is closed
            break
        if not data:
            break
        chunks.append(data)
    err = proc.stderr.read().decode() if proc.stderr is not None else ""
    proc.wait(timeout=120)
    os.close(main)
    return b"".join(chunks).decode(errors="replace"), err


@pytest.mark.parametrize("extra", [[], ["--json"]])
def test_a_warning_shown_in_the_report_is_not_repeated_on_the_same_terminal(tmp_path, extra):
    path = _inside_out_cube(tmp_path)
    screen, _ = _run(["analyze", str(path), "--units", "m", *extra], stderr_on_terminal=True)
    assert screen.count(WARNING) == 1, screen
    assert "inertia-tool: warning:" not in screen


def test_stderr_elsewhere_still_gets_every_warning(tmp_path):
    path = _inside_out_cube(tmp_path)
    screen, err = _run(["analyze", str(path), "--units", "m"], stderr_on_terminal=False)
    assert screen.count(WARNING) == 1, screen          # in the report
    assert err.count(WARNING) == 1 and err.startswith("inertia-tool: warning:"), err


def test_a_warning_the_report_does_not_show_is_still_printed(tmp_path):
    # --format cad has no warning lines: the terminal gets the warning from stderr, once
    path = _inside_out_cube(tmp_path)
    screen, _ = _run(["analyze", str(path), "--units", "m", "--format", "cad"], stderr_on_terminal=True)
    assert screen.count(WARNING) == 1, screen
    assert "inertia-tool: warning:" in screen
