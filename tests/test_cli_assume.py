"""``--assume flat-islands`` on ``analyze``, ``batch`` and ``robot``: only with ``--repair``, known names only
(usage errors, exit 2, one line), the default refusal naming the option (exit 3), and with it an estimate whose
note names the assumption as the user's."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh

from inertia_tool.cli import EXIT_MESH, EXIT_OK, EXIT_USAGE, main

from robot_data import ERD, UR5
from test_hole_flat_islands import _polygon, cad_box_with_feature

USER = "assumed by the user: flat-islands"


@pytest.fixture(scope="module")
def lidless(tmp_path_factory):
    """An STL of a CAD-tessellated box whose pocket (walls and floor) is gone: an island hole in its top face."""
    extents = (4.0, 3.0, 2.5)
    v, f, feature = cad_box_with_feature(_polygon(11, extents), extents, -1.0)
    path = tmp_path_factory.mktemp("assume") / "lidless.stl"
    trimesh.Trimesh(v, np.delete(f, feature, axis=0), process=False).export(path)
    return str(path)


def _one_line(err: str) -> str:
    lines = [line for line in err.strip().splitlines() if line.startswith("inertia-tool")]
    assert len(lines) == 1, err
    return lines[0]


def test_analyze_refuses_by_default_and_names_the_option(lidless, capsys):
    assert main(["analyze", lidless, "--repair"]) == EXIT_MESH
    assert _one_line(capsys.readouterr().err).endswith("if the lost surface was flat, --assume flat-islands")


def test_analyze_with_the_assumption_is_an_estimate_naming_it(lidless, capsys):
    assert main(["analyze", lidless, "--repair", "--assume", "flat-islands", "--json"]) == EXIT_OK
    out = json.loads(capsys.readouterr().out)
    assert out["volume"] == pytest.approx(4.0 * 3.0 * 2.5, rel=1e-12)
    assert USER in json.dumps(out)


@pytest.mark.parametrize("command", ["analyze", "batch"])
def test_assume_without_repair_or_unknown_is_a_usage_error(lidless, tmp_path, capsys, command):
    extra = ["--out", str(tmp_path / "rows.csv")] if command == "batch" else []
    assert main([command, lidless, "--assume", "flat-islands", *extra]) == EXIT_USAGE
    assert "--repair" in _one_line(capsys.readouterr().err)
    assert main([command, lidless, "--repair", "--assume", "flat", *extra]) == EXIT_USAGE
    assert "expected one of flat-islands, smooth-holes, faceted-holes, got flat" in _one_line(capsys.readouterr().err)


def test_batch_takes_the_assumption(lidless, tmp_path, capsys):
    out = tmp_path / "rows.csv"
    assert main(["batch", lidless, "--repair", "--assume", "flat-islands", "--out", str(out), "-q"]) == EXIT_OK
    assert "1 ok, 0 failed" in capsys.readouterr().err


def test_help_names_the_engines_assumptions():
    from inertia_tool.cli.model_options import ASSUME_NAMES
    from inertia_tool.mesh.hole_assumptions import USER_ASSUMPTIONS
    assert ASSUME_NAMES == tuple(a.name for a in USER_ASSUMPTIONS)


def test_robot_assume_without_repair_is_a_usage_error(capsys):
    argv = ["robot", str(UR5), "--package", f"example-robot-data={ERD}", "--material", "aluminium"]
    assert main([*argv, "--assume", "flat-islands"]) == EXIT_USAGE
    assert "--repair" in _one_line(capsys.readouterr().err)
    assert main([*argv, "--repair", "--assume", "dome"]) == EXIT_USAGE
    assert "flat-islands" in _one_line(capsys.readouterr().err)


def test_batch_options_key_changes_only_when_something_is_assumed():
    """Result files written before `assume` existed resume unchanged (the key of no assumption is the old one:
    the same hash of the old fields), and a run with the assumption is not mistaken for one without."""
    import hashlib
    from dataclasses import asdict

    from inertia_tool.batch.runner import BatchOptions
    from inertia_tool.mesh.options import LoadOptions

    plain = BatchOptions(load=LoadOptions(repair=True))
    flat = {**asdict(plain.load), "density": None, "material": None, "mass": None, "units": "m"}
    for name in ("declared_units_win", "assume"):
        flat.pop(name)
    old = hashlib.sha256(json.dumps(flat, sort_keys=True, default=str).encode()).hexdigest()[:16]
    assert plain.key() == old
    assert BatchOptions(load=LoadOptions(repair=True, assume=("flat-islands",))).key() != old
