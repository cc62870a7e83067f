"""Issue 23: the certificate in the text reports, not only in the JSON.

The ``robot`` table says per link which user's assumptions its result rests on (``assumed``: ``none``, or
``flat-islands``) and lists the bounds of every estimate; spin-it's text report states the certificate of the part
before and after (an estimate stays an estimate, with the assumption it took), where it used to say that every
"after" number was "the exact re-analysis" whatever the certificate.
"""

from __future__ import annotations

import re

import pytest

from inertia_tool.cli import EXIT_OK, main

from test_assume_parameter import _lidless
from test_robot_assume_cache import _robot


def _table_row(out: str, name: str) -> list[str]:
    (row,) = [line for line in out.splitlines() if line.startswith(name + " ")]
    return row.split()


@pytest.mark.filterwarnings("ignore::inertia_tool.errors.InertiaToolWarning")
def test_the_robot_table_names_each_links_assumptions_and_an_estimates_bounds(tmp_path, capsys):
    robot = _robot(tmp_path)
    source = robot.source
    assert main(["robot", source, "--density", "1000", "--repair", "--assume", "flat-islands"]) == EXIT_OK
    taken = capsys.readouterr().out
    assert main(["robot", source, "--density", "1000", "--repair"]) == EXIT_OK
    plain = capsys.readouterr().out
    header = next(line for line in taken.splitlines() if line.startswith("link "))
    assert header.split()[:3] == ["link", "method", "assumed"]
    assert _table_row(taken, "plate")[1:3] == ["estimate", "flat-islands"]
    assert _table_row(plain, "plate")[1:3] == ["estimate", "none"]
    # the bounds are the link's own (LinkUncertainty), in per cent and mm
    from inertia_tool.robot import link_inertials
    (link,) = link_inertials(robot, density=1000.0, repair=True)
    bound = re.search(r"^  plate: mass ±(\S+) %, centre of mass ±(\S+) mm, inertia ±(\S+) %$", plain, re.M)
    assert bound is not None, plain
    assert float(bound.group(1)) == pytest.approx(link.uncertainty.mass * 100, rel=1e-2)
    assert float(bound.group(2)) == pytest.approx(link.uncertainty.center_of_mass * 1e3, rel=1e-2)
    assert float(bound.group(3)) == pytest.approx(link.uncertainty.inertia * 100, rel=1e-2)


def test_an_exact_link_assumes_nothing_and_has_no_bounds(tmp_path, capsys):
    (tmp_path / "box.urdf").write_text(
        '<robot name="b"><link name="cube"><collision><geometry><box size="1 2 3"/></geometry></collision>'
        '</link></robot>')
    assert main(["robot", str(tmp_path / "box.urdf"), "--density", "1000"]) == EXIT_OK
    out = capsys.readouterr().out
    assert _table_row(out, "cube")[1:3] == ["exact", "none"]
    assert "bounds of the estimates" not in out


@pytest.mark.filterwarnings("ignore::inertia_tool.errors.InertiaToolWarning")
def test_spin_it_text_states_the_certificate_before_and_after(tmp_path, capsys):
    import trimesh
    v, f = _lidless()
    path = tmp_path / "lidless.stl"
    trimesh.Trimesh(v, f, process=False).export(path)
    report = tmp_path / "spin.html"
    assert main(["spin-it", str(path), "--axis", "0,0,1", "--wall", "0.3", "--resolution", "12", "--repair",
                 "--assume", "flat-islands", "--density", "1000", "--report", str(report)]) == EXIT_OK
    out = capsys.readouterr().out
    (line,) = [x.strip() for x in out.splitlines() if x.strip().startswith("certificate:")]
    # the part is an estimate under the user's assumption, before and after: never called exact
    assert line.startswith("certificate: before estimate, assuming flat-islands (mass ±")
    assert "; after estimate, assuming flat-islands" in line
    assert "exact re-analysis" not in out
    # the HTML report says the same
    page = report.read_text("utf-8")
    assert "exact re-analysis" not in page and "certificate: before estimate, assuming flat-islands" in page
