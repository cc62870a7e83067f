"""A link whose mesh is refused says what was tried (review 8): "mesh needs repair or cannot be read" without
``repair``, and, with it, that the mesh cannot be read or bounded even with repair (it said "needs repair" right
after a warning that repair was tried)."""

from __future__ import annotations

import warnings

import pytest

from inertia_tool.reports.robot_audit import left_unchanged
from inertia_tool.robot.geometry import REFUSED, REFUSED_REPAIRED, link_inertials
from inertia_tool.robot.description import read_robot


def _model(tmp_path):
    (tmp_path / "assets").mkdir()
    (tmp_path / "assets" / "broken.stl").write_bytes(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n")
    path = tmp_path / "robot.xml"
    path.write_text("""<mujoco model="refused">
  <compiler meshdir="assets"/>
  <asset><mesh file="broken.stl"/></asset>
  <worldbody><body name="link" pos="0 0 1"><geom type="mesh" mesh="broken"/></body></worldbody>
</mujoco>
""")
    return str(path)


@pytest.mark.parametrize("repair", [False, True])
def test_a_refused_link_names_what_was_tried(tmp_path, repair):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        (result,) = link_inertials(read_robot(_model(tmp_path)), density=1000.0, repair=repair)
    assert result.properties is None
    expected, other = (REFUSED_REPAIRED, REFUSED) if repair else (REFUSED, REFUSED_REPAIRED)
    assert result.problem.startswith(expected + ": ") and not result.problem.startswith(other), result.problem
    assert "broken.stl" in result.problem and "truncated" in result.problem
    assert left_unchanged([result], changed=set()) == f"link ({expected})"
