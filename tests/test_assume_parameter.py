"""The user's assumptions are a parameter of the repair stage, not hidden state (issues 21/23).

``assume`` travels as a frozen :class:`~inertia_tool.mesh.hole_assumptions.UserAssumptions` from the API through
``prepare_mesh`` → ``close_surface`` → ``resolve_surface`` → ``holes.patched_estimate``.  Before, a context
variable carried it (``hole_assumptions.assuming``), and an enclosing block stayed in force inside a call with
``assume=()``.  Shown here: no module on that chain holds a context variable; a call without the assumption after
one with it (in one process, on generated plates) gives the default answer; two threads with different
assumptions each get their own; the certificate names the assumptions taken (``Certificate.assumptions``, JSON
``certificate.assumptions``, per robot link ``assumptions``, text and HTML "assuming flat-islands"); and
``spin_it`` takes ``assume`` like ``mass_properties``.

Meshes: the grid plate with a polyomino island hole and the CAD box that lost a pocket of
``tests/test_hole_flat_islands.py`` (whose truths those tests check); the answers here are compared with each
other, call against call.
"""

from __future__ import annotations

import contextvars
import importlib
import json
import threading

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError, UsageError
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.hole_assumptions import NOTHING_ASSUMED, USER_ASSUMPTIONS, UserAssumptions
from inertia_tool.mesh.holes import patched_estimate
from inertia_tool.mesh.policy import Certificate
from inertia_tool.mesh.prepare import prepare_mesh
from inertia_tool.mesh.read import load_mesh

from test_hole_flat_islands import _polygon, cad_box_with_feature, grid_plate

FLAT = ("flat-islands",)

#: Every module from the API to the one place that reads the assumptions.
CHAIN = ("inertia_tool.mesh.hole_assumptions", "inertia_tool.mesh.holes", "inertia_tool.mesh.resolve",
         "inertia_tool.mesh.surface", "inertia_tool.mesh.prepare", "inertia_tool.mass.pipeline",
         "inertia_tool.mass.thinwall", "inertia_tool.robot.geometry", "inertia_tool.design.hollow")


def _answer(v, f, assume):
    """``(volume, mass bound, certificate)`` of ``mass_properties(repair=True, assume=assume)``, or the refusal's
    message."""
    try:
        props = mass_properties((v, f), density=1.0, repair=True, assume=assume)
    except InvalidMeshError as exc:
        return str(exc)
    return props.volume, props.mesh.uncertainty.mass, props.mesh.certificate


def _lidless():
    """A CAD-tessellated box whose pocket (walls and floor) is gone: an island hole in its top face, refused
    without ``flat-islands`` (its footprint) and closed flat with it."""
    extents = (4.0, 3.0, 2.5)
    v, f, feature = cad_box_with_feature(_polygon(11, extents), extents, -1.0)
    return v, np.delete(f, feature, axis=0)


def test_no_module_on_the_chain_holds_a_context_variable():
    for name in CHAIN:
        module = importlib.import_module(name)
        held = [k for k, value in vars(module).items() if isinstance(value, contextvars.ContextVar)]
        assert held == [], f"{name} holds {held}"
    hole_assumptions = importlib.import_module("inertia_tool.mesh.hole_assumptions")
    assert not hasattr(hole_assumptions, "assuming") and not hasattr(hole_assumptions, "user_assumed")


def test_user_assumptions_are_a_checked_frozen_value():
    assert UserAssumptions(["flat-islands", "flat-islands"]).names == FLAT
    assert UserAssumptions(FLAT) == UserAssumptions(["flat-islands"])
    assert hash(UserAssumptions(FLAT)) == hash(UserAssumptions(["flat-islands"]))
    assert not NOTHING_ASSUMED and UserAssumptions(FLAT) and "flat-islands" in UserAssumptions(FLAT)
    with pytest.raises(ValueError, match="flat-islands"):
        UserAssumptions(("flat",))
    with pytest.raises(TypeError):
        UserAssumptions("flat-islands")                     # a bare string would be read letter by letter
    with pytest.raises(AttributeError):
        UserAssumptions(FLAT).names = ()                    # type: ignore[misc]
    with pytest.raises(ValueError):
        Certificate("estimate", assumptions=("dome",))
    assert Certificate("estimate", assumptions=FLAT).describe() == "estimate, assuming flat-islands"


def test_prepare_mesh_takes_only_the_typed_value_and_only_with_repair():
    v, f = _lidless()
    raw = load_mesh((v, f))
    with pytest.raises(UsageError, match="UserAssumptions"):
        prepare_mesh(raw, repair=True, assume=FLAT)          # type: ignore[arg-type]
    with pytest.raises(UsageError, match="repair=True"):
        prepare_mesh(raw, assume=UserAssumptions(FLAT))
    with pytest.raises(InvalidMeshError, match="`assume` flat-islands"):
        prepare_mesh(raw, repair=True)
    taken = prepare_mesh(raw, repair=True, assume=UserAssumptions(FLAT)).report
    assert taken.certificate.kind == "estimate" and taken.certificate.assumptions == FLAT


def test_patched_estimate_reads_the_parameter():
    v, f = grid_plate(6, 1.0, {(2, 2), (2, 3), (3, 2)})      # an L-shaped island in the top face
    plain = patched_estimate(v, f, volume_moments)
    taken = patched_estimate(v, f, volume_moments, assume=UserAssumptions(FLAT))
    assert "flat-islands" not in plain.assumptions and "flat-islands" in taken.assumptions
    assert plain.uncertainty.volume_in_doubt > 1e-3 and taken.uncertainty.volume_in_doubt < 1e-9
    assert abs(taken.volume - 36.0) <= 1e-9


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 3), st.integers(1, 3), st.integers(0, 2 ** 16), st.sampled_from([(), []]))
def test_a_call_without_the_assumption_after_one_with_it_gives_the_default_answer(width, depth, seed, nothing):
    """default → assumed → default, in one process: the third call is the first, bit for bit (the island keeps
    its ball, or is refused naming the option), and only the second names the assumption."""
    rng = np.random.default_rng(seed)
    n = 6
    x0, y0 = int(rng.integers(1, n - width)), int(rng.integers(1, n - depth))
    hole = {(x0 + i, y0 + j) for i in range(width) for j in range(depth)}
    v, f = grid_plate(n, 0.5, hole)
    first = _answer(v, f, nothing)
    taken = _answer(v, f, FLAT)
    again = _answer(v, f, nothing)
    assert again == first
    assert not isinstance(taken, str) and taken[2].assumptions == FLAT and taken[1] < 1e-9
    assert abs(taken[0] - n * n * 0.5) <= 1e-9 * n * n
    if isinstance(first, str):
        assert "`assume` flat-islands" in first
    else:
        assert first[2].assumptions == () and first[1] > 1e-6


def test_two_threads_with_different_assumptions_get_their_own_answers():
    """Started together (a barrier before each round), three rounds each: every answer is the one the same call
    gives alone."""
    v, f = grid_plate(6, 1.0, {(2, 2), (2, 3), (3, 2)})
    alone = {assume: _answer(v, f, assume) for assume in ((), FLAT)}
    assert alone[()] != alone[FLAT]
    barrier = threading.Barrier(2)
    got: dict = {(): [], FLAT: []}

    def run(assume):
        for _ in range(3):
            barrier.wait(timeout=120)
            got[assume].append(_answer(v, f, assume))

    threads = [threading.Thread(target=run, args=(assume,)) for assume in ((), FLAT)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=600)
    assert not any(t.is_alive() for t in threads)
    assert got[()] == [alone[()]] * 3 and got[FLAT] == [alone[FLAT]] * 3


# -- the structured field --------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def lidless_stl(tmp_path_factory):
    import trimesh
    v, f = _lidless()
    path = tmp_path_factory.mktemp("assume_json") / "lidless.stl"
    trimesh.Trimesh(v, f, process=False).export(path)
    return str(path)


def test_the_json_certificate_names_the_assumption_taken(lidless_stl, tmp_path, capsys):
    from inertia_tool.cli import EXIT_OK, main
    from inertia_tool.reports.serialize import output_schema
    assert main(["analyze", lidless_stl, "--repair", "--assume", "flat-islands", "--json"]) == EXIT_OK
    data = json.loads(capsys.readouterr().out)
    assert data["certificate"] == {"kind": "estimate", "checks": [], "assumptions": ["flat-islands"]}
    assert data["mesh"]["certificate"] == data["certificate"]
    # a patched hole that is no island: an estimate resting on no assumption of the user's, even when stated
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    open_path = tmp_path / "open.stl"
    trimesh.Trimesh(sphere.vertices, sphere.faces[1:], process=False).export(open_path)
    assert main(["analyze", str(open_path), "--repair", "--assume", "flat-islands", "--json"]) == EXIT_OK
    other = json.loads(capsys.readouterr().out)
    assert other["certificate"]["kind"] == "estimate" and other["certificate"]["assumptions"] == []
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(output_schema())
    assert list(validator.iter_errors(data)) == [] and list(validator.iter_errors(other)) == []
    bad = {**data, "certificate": {**data["certificate"], "assumptions": ["dome"]}}
    assert list(validator.iter_errors(bad))
    schema_names = output_schema()["$defs"]["certificate"]["properties"]["assumptions"]["items"]["enum"]
    assert schema_names == [a.name for a in USER_ASSUMPTIONS]


def test_text_and_html_reports_say_the_assumption_with_the_certificate(lidless_stl, tmp_path, capsys):
    from inertia_tool.cli import EXIT_OK, main
    report = tmp_path / "r.html"
    assert main(["analyze", lidless_stl, "--repair", "--assume", "flat-islands", "--report", str(report)]) == EXIT_OK
    text = capsys.readouterr().out
    assert "certificate: estimate, assuming flat-islands" in text
    assert "estimate, assuming flat-islands" in report.read_text("utf-8")
    # an assembly: the parts table says it of the part that took it, and only of that one
    box = tmp_path / "box.stl"
    import trimesh
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(box)
    both = tmp_path / "both.html"
    assert main(["analyze", f"{lidless_stl}:steel", f"{box}:abs", "--repair", "--assume", "flat-islands",
                 "--report", str(both)]) == EXIT_OK
    table = [line.strip() for line in capsys.readouterr().out.splitlines()
             if line.startswith("    ") and ".stl " in line]
    assert len(table) == 2 and "lidless.stl" in table[0] and "box.stl" in table[1]
    assert table[0].endswith("estimate, assuming flat-islands") and table[1].endswith("exact")
    assert both.read_text("utf-8").count("assuming flat-islands") == 1


def test_robot_links_name_the_assumption_their_meshes_took(tmp_path):
    from inertia_tool.reports.robot_audit import robot_report_dict
    from inertia_tool.robot import link_inertials
    from inertia_tool.robot.audit import audit_links
    from test_robot_assume_cache import _plate, _robot
    robot = _robot(tmp_path)
    taken = link_inertials(robot, density=1000.0, repair=True, assume=FLAT)
    plain = link_inertials(robot, density=1000.0, repair=True)
    assert _plate(taken).assumptions == FLAT and _plate(plain).assumptions == ()
    links = robot_report_dict(robot, taken, audit_links(robot, taken))["links"]
    assert [link["assumptions"] for link in links if link["name"] == "plate"] == [["flat-islands"]]


# -- spin-it ---------------------------------------------------------------------------------------------------

def test_spin_it_takes_the_assumption():
    from inertia_tool.design.hollow import spin_it
    v, f = _lidless()
    with pytest.raises(InvalidMeshError, match="`assume` flat-islands"):
        spin_it((v, f), axis=(0, 0, 1), wall=0.3, resolution=12, repair=True)
    with pytest.raises(UsageError, match="repair=True"):
        spin_it((v, f), axis=(0, 0, 1), wall=0.3, resolution=12, assume=FLAT)
    result = spin_it((v, f), axis=(0, 0, 1), wall=0.3, resolution=12, repair=True, assume=FLAT)
    assert abs(result.before.volume - 4.0 * 3.0 * 2.5) <= 1e-9 * 30.0     # the pocket's mouth closed flat
    assert result.before.mesh.certificate.assumptions == FLAT


# -- batch rows ------------------------------------------------------------------------------------------------

#: The columns of inertia_tool.batch/2 files (the layout before ``assumptions``), frozen.
BATCH_V2 = ("schema,path,status,error_type,error,sha256,options_key,mesh_length_unit,density,density_source,method,"
            "uncertainty_mass,uncertainty_center_of_mass,uncertainty_inertia,uncertainty_volume_in_doubt,mass,volume,"
            "surface_area,com_x,com_y,com_z,ixx,iyy,izz,ixy,ixz,iyz,i1,i2,i3,axis1_x,axis1_y,axis1_z,axis2_x,"
            "axis2_y,axis2_z,axis3_x,axis3_y,axis3_z,faces,bodies,cavities,watertight,repaired,certificate,warnings,"
            "seconds,worker")


@pytest.fixture(scope="module")
def two_parts(lidless_stl, tmp_path_factory):
    """The lidless box (an island: filled under the assumption) and an icosphere less one face (a hole that is
    no island: an estimate resting on no assumption of the user's)."""
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    path = tmp_path_factory.mktemp("assume_batch") / "open.stl"
    trimesh.Trimesh(sphere.vertices, sphere.faces[1:], process=False).export(path)
    return lidless_stl, str(path)


def _read(path):
    from inertia_tool.batch.rows import open_results
    with open_results(path) as results:
        return {r["path"].rsplit("/", 1)[-1]: r for r in results.previous_rows}


@pytest.mark.parametrize("fmt", ["jsonl", "csv"])
def test_batch_rows_name_the_assumption_taken(two_parts, tmp_path, fmt):
    from inertia_tool.batch.runner import ROW_FIELDS, SCHEMA
    from inertia_tool.cli import EXIT_OK, main
    from inertia_tool.reports.serialize import output_schema
    out = tmp_path / f"rows.{fmt}"
    assert main(["batch", *two_parts, "--repair", "--assume", "flat-islands", "--out", str(out), "-q"]) == EXIT_OK
    rows = _read(out)
    assert rows["lidless.stl"]["assumptions"] == "flat-islands" and rows["open.stl"]["assumptions"] == "none"
    assert all(r["schema"] == SCHEMA and r["certificate"] == "estimate" for r in rows.values())
    if fmt == "csv":
        assert out.read_text().splitlines()[0] == ",".join(ROW_FIELDS)
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(output_schema())
    assert all(list(validator.iter_errors(r)) == [] for r in rows.values())


def test_a_batch2_csv_file_resumes_in_its_own_layout(two_parts, tmp_path, capsys):
    """A results file written before the column: its rows count as done (read back with ``assumptions`` unknown),
    and the file keeps its header, new rows written in its layout."""
    import csv
    import io
    from inertia_tool.batch.runner import ROW_FIELDS, ROW_FIELDS_V2, SCHEMA_V2, downgrade_row
    from inertia_tool.cli import main
    assert ",".join(ROW_FIELDS_V2) == BATCH_V2
    now = tmp_path / "now.jsonl"
    main(["batch", two_parts[0], "--repair", "--assume", "flat-islands", "--out", str(now), "-q"])
    (done,) = [downgrade_row(json.loads(line), SCHEMA_V2) for line in now.read_text().splitlines()]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(ROW_FIELDS_V2)
    writer.writerow(["" if done[k] is None else "true" if done[k] is True else "false" if done[k] is False
                     else repr(done[k]) if isinstance(done[k], float) else str(done[k]) for k in ROW_FIELDS_V2])
    old = tmp_path / "old.csv"
    old.write_text(buf.getvalue())
    capsys.readouterr()
    assert main(["batch", *two_parts, "--repair", "--assume", "flat-islands", "--out", str(old)]) == 0
    assert "1 ok, 0 failed in this run" in capsys.readouterr().err          # the old row counted as done
    text = old.read_text()
    assert text.startswith(buf.getvalue())
    table = list(csv.reader(io.StringIO(text)))
    assert {len(t) for t in table} == {len(ROW_FIELDS_V2)} and table[-1][0] == SCHEMA_V2
    rows = _read(old)
    assert all(set(r) == set(ROW_FIELDS) and r["assumptions"] is None for r in rows.values())


def test_a_printed_part_keeps_the_assumption_in_its_certificate():
    """The skin-and-infill model adds its own bound to a repaired mesh's: the certificate it makes still names
    the user's assumption the mesh took (it was dropped when the model rebuilt the certificate)."""
    from inertia_tool.mass.thinwall import printed_part
    v, f = _lidless()
    part = printed_part((v, f), skin=0.6, infill=0.3, density=1000.0, repair=True, assume=FLAT)
    cert = part.properties.mesh.certificate
    assert cert.kind == "estimate" and "inward-offset-bound" in cert.checks and cert.assumptions == FLAT
