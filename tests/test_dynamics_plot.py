"""plot_trajectory writes a figure, or raises UsageError when matplotlib is missing."""

import builtins

import numpy as np
import pytest

import inertia_tool as it
from inertia_tool.errors import UsageError


def test_plot_writes_png(tmp_path):
    pytest.importorskip("matplotlib")
    traj = it.simulate([1.0, 2.0, 3.0], [0.1, 1.0, 0.05], np.linspace(0, 20, 81))
    path = tmp_path / "traj.png"
    it.dynamics.plot_trajectory(traj, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000


def test_plot_without_matplotlib_raises_usage_error(monkeypatch, tmp_path):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError("no matplotlib")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    traj = it.simulate([1.0, 2.0, 3.0], [0.1, 1.0, 0.05], np.linspace(0, 1, 3))
    with pytest.raises(UsageError, match="matplotlib"):
        it.dynamics.plot_trajectory(traj, tmp_path / "x.png")
