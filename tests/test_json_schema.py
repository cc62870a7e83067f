"""Every command's JSON output against the shipped JSON Schema (inertia_tool/schema/output-v1.json).

Each command runs through the command line (``inertia_tool.cli.main``) on the bundled meshes (meshes/*.stl) and
robot files of tests/data; its output must validate, carry ``schema``/``command``/``units``/``warnings`` (and
``method``/``uncertainty`` wherever a mass model is behind the numbers), and use only fields the schema declares
(so the schema documents everything printed).  The negative tests check that the schema is strict enough to
reject a wrong type, a missing required field, a units string in a batch row, an unknown version.
"""

import copy
import csv
import fnmatch
import io
import json
import math
import os


import numpy as np
import pytest
import trimesh

jsonschema = pytest.importorskip("jsonschema")

from conftest import write_binary_stl  # noqa: E402
from inertia_tool.batch.rows import open_results  # noqa: E402
from inertia_tool.batch.runner import ROW_FIELDS, ROW_FIELDS_V1, SCHEMA, SCHEMA_V1  # noqa: E402
from inertia_tool.cli import main  # noqa: E402
from inertia_tool.reports.serialize import OUTPUT_SCHEMA, output_schema  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(ROOT, "meshes")
ROBOTS = os.path.join(ROOT, "tests", "data", "robots")
ERD = os.path.join(ROBOTS, "example-robot-data")


@pytest.fixture(scope="module")
def schema():
    s = output_schema()
    jsonschema.Draft202012Validator.check_schema(s)
    return s


@pytest.fixture(scope="module")
def validator(schema):
    return jsonschema.Draft202012Validator(schema)


def _mesh(name):
    return os.path.join(MESHES, name)


def _open_sphere(path):
    """A 10 mm icosphere (320 triangles) with one triangle missing (an estimate under --repair); returns the path
    and the mass in kg of water of the closed polyhedron (trimesh's volume: the truth the bound must hold on)."""
    m = trimesh.creation.icosphere(subdivisions=2, radius=10.0)
    write_binary_stl(path, np.asarray(m.vertices), np.asarray(m.faces)[1:])
    return str(path), float(m.volume) * 1e-9 * 1000.0


#: (id, argv) of one run of each command, on bundled meshes and robot files.
COMMANDS = [
    ("analyze", ["analyze", _mesh("box.stl"), "--units", "mm", "--mass", "50g", "--json"]),
    ("analyze-format-json", ["analyze", _mesh("t_handle.stl"), "--units", "mm", "--material", "aluminium",
                             "--format", "json"]),
    ("analyze-assembly", ["analyze", _mesh("washer.stl") + ":steel", _mesh("box.stl") + ":abs", "--units", "mm",
                          "--json"]),
    ("analyze-shell", ["analyze", _mesh("hollow_sphere.stl"), "--units", "mm", "--model", "shell", "--thickness",
                       "1mm", "--json"]),
    ("spin", ["spin", _mesh("box.stl"), "--units", "mm", "--about", "intermediate", "--rate", "2rev/s", "--json"]),
    ("top", ["top", _mesh("spinning_top.stl"), "--units", "mm", "--pivot", "0,0,0", "--spin", "30rev/s", "--tilt",
             "10deg", "--json"]),
    ("top-no-simulate", ["top", _mesh("spinning_top.stl"), "--units", "mm", "--pivot", "0,0,0", "--spin", "30rev/s",
                         "--tilt", "10deg", "--no-simulate", "--json"]),
    ("balance", ["balance", _mesh("unbalanced_wheel.stl"), "--units", "mm", "--material", "steel", "--rpm", "3000",
                 "--planes", "-30,30", "--radius", "180", "--grade", "G6.3", "--bearings", "-120,120", "--json"]),
    ("balance-single-plane", ["balance", _mesh("unbalanced_wheel.stl"), "--units", "mm", "--material", "steel",
                              "--rpm", "3000", "--single-plane", "--radius", "180mm", "--json"]),
    ("robot-urdf", ["robot", os.path.join(ERD, "robots", "ur_description", "urdf", "ur5_robot.urdf"), "--package",
                    f"example-robot-data={ERD}", "--material", "aluminium", "--json"]),
    ("robot-mjcf", ["robot", os.path.join(ROBOTS, "gymnasium", "walker2d.xml"), "--material", "aluminium",
                    "--json"]),
    ("robot-corpus", ["robot", os.path.join(ROBOTS, "gymnasium"), "--material", "aluminium", "--json"]),
    ("robot-sdf", ["robot", os.path.join(ERD, "robots", "cassie_description", "robots", "cassie_simple.sdf"),
                   "--material", "aluminium", "--json"]),
    ("spin-it-yoyo", ["spin-it", _mesh("washer.stl"), "--units", "mm", "--material", "pla", "--axis", "0,0,1",
                      "--wall", "1.5mm", "--resolution", "16", "--json"]),
    ("spin-it-top", ["spin-it", _mesh("spinning_top.stl"), "--units", "mm", "--material", "pla", "--mode", "top",
                     "--pivot", "0,0,0", "--axis", "0,0,1", "--wall", "1.5mm", "--resolution", "16", "--json"]),
]


#: Runs that exit with another code than 0 on purpose: cassie_simple.sdf has 14 links without collision
#: geometry, so `robot` prints every result and exits 5 (links without a result, docs/usage.md).
EXIT_CODES = {"robot-sdf": 5}


def _run(argv, capsys):
    code = main(argv)
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return json.loads(captured.out)


@pytest.fixture(scope="module")
def outputs():
    """The JSON of every run of :data:`COMMANDS`, computed once for the module."""
    import contextlib
    got = {}
    for name, argv in COMMANDS:
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
        assert code == EXIT_CODES.get(name, 0), f"{name}: {err.getvalue()}"
        got[name] = (json.loads(out.getvalue()), err.getvalue())
    return got


def _resolve(schema, node):
    while isinstance(node, dict) and "$ref" in node:
        node = schema["$defs"][node["$ref"].rsplit("/", 1)[1]]
    return node


def _undeclared(schema, node, value, where="$"):
    """Paths of object keys in ``value`` that the schema ``node`` does not name in a ``properties`` (objects
    whose schema names no properties at all are open bags, e.g. ``brep``)."""
    node = _resolve(schema, node)
    found = []
    if not isinstance(node, dict):
        return found
    for branch in node.get("allOf", []):
        found += _undeclared(schema, branch, value, where)
    for key in ("anyOf", "oneOf"):
        for branch in node.get(key, []):
            if jsonschema.Draft202012Validator(schema).evolve(schema={**_resolve(schema, branch),
                                                                      "$defs": schema["$defs"]}).is_valid(value):
                found += _undeclared(schema, branch, value, where)
                break
    if isinstance(value, dict) and "properties" in node and node.get("additionalProperties", False) is not True \
            and not isinstance(node.get("additionalProperties"), dict):
        props = dict(node["properties"])
        for branch in node.get("allOf", []):
            props.update(_resolve(schema, branch).get("properties", {}))
        for k, v in value.items():
            if k not in props:
                found.append(f"{where}.{k}")
            else:
                found += _undeclared(schema, props[k], v, f"{where}.{k}")
    elif isinstance(value, list) and "items" in node:
        for i, v in enumerate(value[:3]):
            found += _undeclared(schema, node["items"], v, f"{where}[{i}]")
    return found


def _errors(validator, instance):
    return [f"{list(e.absolute_path)}: {e.message[:200]}" for e in validator.iter_errors(instance)]


# -- every command validates -------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", [c[0] for c in COMMANDS])
def test_every_command_output_validates_and_declares_every_field(name, outputs, validator, schema):
    data, _ = outputs[name]
    assert _errors(validator, data) == []
    subcommand = COMMANDS[[c[0] for c in COMMANDS].index(name)][1][0]
    # a robot run over a folder prints the corpus object (command robot-corpus)
    assert data["schema"] == OUTPUT_SCHEMA and data["command"] == ("robot-corpus" if name == "robot-corpus"
                                                                   else subcommand)
    assert list(data)[:2] == ["schema", "command"]
    assert data["units"]["length"] == "m" and data["units"]["mass"] == "kg"
    assert isinstance(data["warnings"], list)
    assert _undeclared(schema, schema["$defs"][data["command"]], data) == []


@pytest.mark.parametrize("name", ["analyze", "analyze-assembly", "spin", "top", "balance", "spin-it-yoyo"])
def test_method_and_uncertainty_wherever_a_mass_model_is_behind_the_numbers(name, outputs):
    data, _ = outputs[name]
    assert data["method"] == "exact" and data["uncertainty"] is None


def test_assembly_bodies_carry_their_own_method(outputs):
    data, _ = outputs["analyze-assembly"]
    assert [b["method"] for b in data["bodies"]] == ["exact", "exact"]
    assert math.isclose(sum(b["mass"] for b in data["bodies"]), data["mass"], rel_tol=1e-12)


def test_robot_links_carry_method_and_the_warnings_printed_on_stderr(outputs):
    data, err = outputs["robot-urdf"]
    with_geometry = [link for link in data["links"] if link["mass"] is not None]
    # the UR5's collision meshes: some links are one closed body, others overlapping bodies united by a boolean
    assert {link["method"] for link in with_geometry} == {"exact", "united"}
    assert all(link["uncertainty"] is None for link in with_geometry)
    assert all(link["method"] is None for link in data["links"] if link["mass"] is None)
    printed = [line.removeprefix("inertia-tool: warning: ") for line in err.splitlines()
               if line.startswith("inertia-tool: warning: ")]
    assert printed and data["warnings"] == printed       # the UR5's overlapping collision bodies


def test_spin_it_warnings_are_the_ones_printed(outputs):
    data, err = outputs["spin-it-yoyo"]
    assert any("equal within" in w for w in data["warnings"])          # the washer's two equal moments
    assert all(f"warning: {w}" in err for w in data["warnings"])


def test_an_estimate_carries_its_method_and_bounds(tmp_path, capsys, validator):
    path, truth = _open_sphere(tmp_path / "open.stl")
    data = _run(["analyze", path, "--units", "mm", "--repair", "--json"], capsys)
    assert _errors(validator, data) == []
    assert data["method"] in ("patched", "winding") and data["method"] == data["mesh"]["method"]
    u = data["uncertainty"]
    assert u is not None and u["mass"] > 0 and u["center_of_mass"] > 0 and u["inertia"] > 0
    assert abs(data["mass"] - truth) <= u["mass"] * data["mass"]          # the bound holds on this case


# -- batch rows ---------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def batch_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("batch")
    for name in ("box.stl", "cone.stl", "washer.stl"):
        os.symlink(_mesh(name), d / name)
    _open_sphere(d / "open.stl")
    (d / "bad.stl").write_bytes(b"solid x\nfacet normal 0 0 1\nendsolid\n")
    return d


@pytest.mark.parametrize("fmt", ["jsonl", "csv"])
def test_batch_rows_validate_in_both_formats(fmt, batch_dir, tmp_path, validator, schema):
    out = tmp_path / f"rows.{fmt}"
    code = main(["batch", str(batch_dir), "--units", "mm", "--repair", "--out", str(out), "-q"])
    assert code == 3                                 # bad.stl fails; the others are rows
    if fmt == "jsonl":
        rows = [json.loads(line) for line in out.read_text().splitlines()]
    else:
        table = list(csv.reader(io.StringIO(out.read_text())))
        documented = [k for k in schema["$defs"]["batch_row"]["properties"]
                      if k != "certificate" or k in ROW_FIELDS]     # the optional column, where it is written
        assert table[0] == list(ROW_FIELDS) == documented        # the schema lists the CSV columns in order
        rows = _rows(out)                             # the cells read back as the reader does on resume
    assert len(rows) == 5
    for row in rows:
        assert _errors(validator, row) == [], row["path"]
        assert row["schema"] == SCHEMA and row["mesh_length_unit"] == "mm"
        assert all(not isinstance(v, (dict, list)) for v in row.values())     # flat: the reader bounds nesting
    by_name = {os.path.basename(r["path"]): r for r in rows}
    assert by_name["bad.stl"]["status"] == "error" and by_name["bad.stl"]["method"] is None
    assert by_name["box.stl"]["method"] == "exact" and by_name["box.stl"]["uncertainty_mass"] is None
    open_row = by_name["open.stl"]
    assert open_row["method"] in ("patched", "winding")
    assert all(open_row[f"uncertainty_{k}"] > 0 for k in ("mass", "center_of_mass", "inertia", "volume_in_doubt"))
    assert "equal within" in by_name["cone.stl"]["warnings"]


def _rows(path):
    with open_results(path) as r:
        return r.previous_rows


def _v1_rows(batch_dir, tmp_path):
    """Rows as inertia_tool.batch/1 wrote them, built from this version's rows column by column."""
    out = tmp_path / "now.jsonl"
    main(["batch", str(batch_dir), "--units", "mm", "--out", str(out), "-q"])
    old = []
    for line in out.read_text().splitlines():
        row = json.loads(line)
        v1 = {k: row[k] for k in ROW_FIELDS_V1 if k != "units"}
        v1.update(schema=SCHEMA_V1, units="mm")
        old.append({k: v1[k] for k in ROW_FIELDS_V1})
    return old


@pytest.mark.parametrize("fmt", ["jsonl", "csv"])
def test_an_old_results_file_resumes_without_running_again(fmt, batch_dir, tmp_path, validator, capsys):
    old = _v1_rows(batch_dir, tmp_path)
    assert all(_errors(validator, r) == [] for r in old)          # the schema still describes the old rows
    done = [r for r in old if os.path.basename(r["path"]) != "washer.stl"]   # washer.stl is new
    out = tmp_path / f"old.{fmt}"
    if fmt == "jsonl":
        before = "".join(json.dumps(r) + "\n" for r in done)
    else:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(ROW_FIELDS_V1)
        w.writerows([["" if r[k] is None else ("true" if r[k] is True else "false" if r[k] is False else
                      repr(r[k]) if isinstance(r[k], float) else str(r[k])) for k in ROW_FIELDS_V1] for r in done])
        before = buf.getvalue()
    out.write_text(before)
    capsys.readouterr()
    code = main(["batch", str(batch_dir), "--units", "mm", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 3, err
    assert "1 ok, 0 failed in this run" in err       # only washer.stl ran: the old rows count as done
    text = out.read_text()
    assert text.startswith(before)                    # nothing of the old file changed
    rows = _rows(out)
    assert len(rows) == len(old)
    assert [r["path"] for r in rows[:-1]] == [r["path"] for r in done]
    assert os.path.basename(rows[-1]["path"]) == "washer.stl"
    for r in rows[:-1]:                               # read back with this version's columns, provenance kept
        assert r["schema"] == SCHEMA_V1 and r["mesh_length_unit"] == "mm" and set(r) == set(ROW_FIELDS)
        assert r["method"] is None and r["uncertainty_mass"] is None
    assert rows[-1]["mesh_length_unit"] == "mm"
    if fmt == "csv":      # the file keeps its own (old) layout: every record has the old header's cells
        table = list(csv.reader(io.StringIO(text)))
        assert table[0] == list(ROW_FIELDS_V1) and {len(t) for t in table} == {len(ROW_FIELDS_V1)}
        assert table[-1][0] == SCHEMA_V1
    else:                 # each line says its own schema and validates against it
        lines = [json.loads(line) for line in text.splitlines()]
        assert [r["schema"] for r in lines] == [SCHEMA_V1] * len(done) + [SCHEMA]
        assert all(_errors(validator, r) == [] for r in lines)
    assert next(r for r in rows if r["path"].endswith("cone.stl"))["warnings"] == \
        next(r for r in old if r["path"].endswith("cone.stl"))["warnings"]


# -- the schema is strict enough -----------------------------------------------------------------------------------

def _without(d, key):
    d = copy.deepcopy(d)
    del d[key]
    return d


def _with(d, **kw):
    d = copy.deepcopy(d)
    d.update(kw)
    return d


@pytest.mark.parametrize("command", ["analyze", "spin", "top", "balance", "robot-mjcf", "spin-it-yoyo"])
@pytest.mark.parametrize("required", ["units", "warnings", "schema", "command"])
def test_a_missing_envelope_field_is_rejected(command, required, outputs, validator):
    data, _ = outputs[command]
    assert _errors(validator, _without(data, required))


@pytest.mark.parametrize("command", ["analyze", "spin", "top", "balance", "spin-it-yoyo"])
@pytest.mark.parametrize("required", ["method", "uncertainty"])
def test_a_missing_method_or_uncertainty_is_rejected(command, required, outputs, validator):
    data, _ = outputs[command]
    assert _errors(validator, _without(data, required))


@pytest.mark.parametrize("mutate", [
    lambda d: _with(d, mass="50 g"),                                   # a number as text
    lambda d: _with(d, mass=None),                                     # a non-finite mass written as null
    lambda d: _with(d, center_of_mass=[0.0, 0.0]),                     # wrong shape
    lambda d: _with(d, inertia=[[1.0, 0, 0], [0, 1.0, 0]]),
    lambda d: _with(d, units="mm"),                                    # the old spelling of units
    lambda d: _with(d, units={"length": "mm", "mass": "kg", "inertia": "kg*m^2", "density": "kg/m^3"}),
    lambda d: _with(d, warnings="none"),
    lambda d: _with(d, uncertainty=0.01),
    lambda d: _with(d, uncertainty={"mass": 0.01}),                    # bounds missing
    lambda d: _with(d, certificate={"kind": "probably", "checks": []}),
    lambda d: _with(d, certificate={"kind": "exact"}),
    lambda d: _with(d, schema="inertia_tool/output/v0"),
    lambda d: _with(d, command="analyse"),
    lambda d: _with(d, principal_moments=[1.0, 2.0, "3"]),
])
def test_wrong_types_in_analyze_are_rejected(mutate, outputs, validator):
    data, _ = outputs["analyze"]
    assert _errors(validator, mutate(data))


def test_the_optional_certificate_is_accepted_where_it_applies(outputs, validator):
    data, _ = outputs["analyze"]
    cert = {"kind": "exact", "checks": ["closed", "consistently oriented"]}
    assert _errors(validator, _with(data, certificate=cert)) == []
    robot, _ = outputs["robot-mjcf"]
    robot = copy.deepcopy(robot)
    robot["links"][1]["certificate"] = cert
    assert _errors(validator, robot) == []
    robot["links"][1]["certificate"] = {"kind": "exact", "checks": "closed"}
    assert _errors(validator, robot)


@pytest.mark.parametrize("mutate", [
    lambda r: _with(r, units="mm"),                                    # a v2 row with the v1 column
    lambda r: _with(r, warnings=["a", "b"]),                           # rows are flat
    lambda r: _with(r, uncertainty_mass={"mass": 0.1}),
    lambda r: _without(r, "method"),
    lambda r: _without(r, "uncertainty_mass"),
    lambda r: _without(r, "mesh_length_unit"),
    lambda r: _with(r, method=None),                                   # an ok row says how it was obtained
    lambda r: _with(r, certificate="probably"),
    lambda r: _with(r, mass=None),                                     # an ok row needs its numbers
    lambda r: _with(r, faces=12.5),
    lambda r: _with(r, status="done"),
    lambda r: _with(r, sha256="xyz"),
    lambda r: _with(r, schema="inertia_tool.batch/4"),
    lambda r: _with(r, schema="inertia_tool.batch/2"),                 # a batch/3 row has the assumptions column
    lambda r: _with(r, assumptions="dome"),                            # only the user's assumptions
    lambda r: _with(r, assumptions=["flat-islands"]),                  # rows are flat
    lambda r: _without(r, "assumptions"),
])
def test_wrong_batch_rows_are_rejected(mutate, batch_dir, tmp_path, validator):
    out = tmp_path / "rows.jsonl"
    main(["batch", str(batch_dir / "box.stl"), "--units", "mm", "--out", str(out), "-q"])
    row = json.loads(out.read_text())
    assert _errors(validator, row) == []
    assert _errors(validator, mutate(row))


def test_robot_and_spin_output_rejects_wrong_types(outputs, validator):
    robot, _ = outputs["robot-mjcf"]
    bad = copy.deepcopy(robot)
    bad["links"][1]["inertia"] = "diagonal"
    assert _errors(validator, bad)
    bad = copy.deepcopy(robot)
    bad["format"] = "yaml"
    assert _errors(validator, bad)
    spin, _ = outputs["spin"]
    bad = copy.deepcopy(spin)
    bad["spin"]["rate"] = "2rev/s"
    assert _errors(validator, bad)
    bad = copy.deepcopy(spin)
    bad["stability"][0]["axis_name"] = "middle"
    assert _errors(validator, bad)


# -- shipped with the package --------------------------------------------------------------------------------------

def test_the_schema_file_is_package_data():
    tomllib = pytest.importorskip("tomllib")          # Python 3.11+
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        data = tomllib.load(fh)["tool"]["setuptools"]["package-data"]["inertia_tool"]
    assert any(fnmatch.fnmatch("schema/output-v1.json", pattern) for pattern in data)
    assert os.path.isfile(os.path.join(ROOT, "inertia_tool", "schema", "output-v1.json"))


def test_the_committed_schema_is_what_its_generator_writes():
    """The schema is edited in scripts/make_output_schema.py; the shipped file must be its output."""
    import subprocess
    import sys
    script = os.path.join(ROOT, "scripts", "make_output_schema.py")
    assert subprocess.run([sys.executable, script, "--check"]).returncode == 0, \
        "inertia_tool/schema/output-v1.json is out of date: run python scripts/make_output_schema.py"


def test_the_old_row_layout_is_frozen():
    """inertia_tool.batch/1 files have exactly these columns, whatever columns this version adds."""
    old = ("schema,path,status,error_type,error,sha256,options_key,units,density,density_source,mass,volume,"
           "surface_area,com_x,com_y,com_z,ixx,iyy,izz,ixy,ixz,iyz,i1,i2,i3,axis1_x,axis1_y,axis1_z,axis2_x,"
           "axis2_y,axis2_z,axis3_x,axis3_y,axis3_z,faces,bodies,cavities,watertight,repaired,warnings,seconds,worker")
    assert ",".join(ROW_FIELDS_V1) == old


def test_an_assembly_with_an_estimated_part_carries_the_bound_that_follows(tmp_path, capsys, validator):
    """An exact box and an estimated (open) sphere: method "mixed"; the mass bound of the sum is the largest
    relative bound of the parts (|sum of errors| <= sum r_k m_k <= max r_k * total), and it holds against the
    truth (the closed sphere's polyhedron and the exact 30 x 20 x 10 mm box, water)."""
    path, sphere = _open_sphere(tmp_path / "open.stl")
    data = _run(["analyze", path, _mesh("box.stl"), "--units", "mm", "--repair", "--json"], capsys)
    assert _errors(validator, data) == []
    assert _undeclared(validator.schema, validator.schema["$defs"]["analyze"], data) == []
    methods = [b["method"] for b in data["bodies"]]
    assert methods[1] == "exact" and methods[0] in ("patched", "winding") and data["method"] == "mixed"
    part = data["bodies"][0]["uncertainty"]
    assert data["uncertainty"]["mass"] == part["mass"]
    assert data["uncertainty"]["center_of_mass"] is None and data["uncertainty"]["inertia"] is None
    truth = sphere + 6e-3
    assert abs(data["mass"] - truth) <= data["uncertainty"]["mass"] * data["mass"]


def test_a_step_file_analysed_from_its_exact_brep_validates(tmp_path, capsys, validator, schema):
    """STEP: the headline is the exact B-rep (its own method) and the JSON carries the brep comparison."""
    pytest.importorskip("OCP")
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from inertia_tool.mesh import cad
    path = tmp_path / "box.step"
    with cad._quiet():
        writer = STEPControl_Writer()
        writer.Transfer(BRepPrimAPI_MakeBox(20.0, 10.0, 5.0).Shape(), STEPControl_AsIs)
        writer.Write(str(path))
    data = _run(["analyze", str(path), "--json"], capsys)
    assert _errors(validator, data) == []
    assert _undeclared(schema, schema["$defs"]["analyze"], data) == []
    assert data["method"].startswith("brep") and isinstance(data["brep"], dict)
    assert math.isclose(data["volume"], 1e-6, rel_tol=1e-9)           # 20 x 10 x 5 mm
