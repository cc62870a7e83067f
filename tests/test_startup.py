"""What a run imports (issue #15, "small files: instant small runs"; issue 25 item 4, within 1.3x ``import numpy``).

``inertia-tool analyze`` on a closed STL imports only the layers it uses: no scipy, trimesh, matplotlib or
manifold3d, and none of the other subcommands, the balancing, design, batch, simulation, thin-wall or HTML
modules; each of those loads when the input or an option needs it.  These tests are behavioural (which
modules are in ``sys.modules`` after a run in a fresh interpreter), not timed: ``benchmarks/bench_startup.py``
measures the time.  The lazily loaded names of the packages are checked against what type checkers and the
API docs read (their ``if TYPE_CHECKING:`` imports).
"""

import ast
import importlib
import inspect
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import HAVE_ACCEL, write_binary_stl

ROOT = Path(__file__).resolve().parents[1]
BOX = "meshes/box.stl"

#: A fresh interpreter runs the console script's entry point and lists its exit code and every module loaded.
_PROBE = """
import contextlib, io, sys
from inertia_tool.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    code = main(sys.argv[1:])
print(code)
print("\\n".join(sorted(sys.modules)))
"""

#: Never imported by ``analyze`` of a closed single-shell STL (scipy: when the C extension is built).  Besides
#: the heavy third-party packages: the repair stages (a closed surface never reaches them), the CAD reader, the
#: robot inertial frames, the file writers (tempfile, shutil: argparse's help width is read without shutil)
#: and HTML escaping; issue 25 item 4 found most of them imported on every run.
NOT_FOR_A_CLOSED_STL = [
    "scipy", "trimesh", "matplotlib", "manifold3d", "networkx", "lxml", "jsonschema", "dask", "distributed",
    "OCP", "mujoco", "tempfile", "shutil", "html", "inertia_tool.mesh.holes",
    "inertia_tool.mesh.grid_estimate", "inertia_tool.mesh.seal",
    "inertia_tool.mesh.merge", "inertia_tool.mesh.orient", "inertia_tool.mesh.winding", "inertia_tool.mesh.cad",
    "inertia_tool.robot.inertial", "inertia_tool.output", "inertia_tool.isolate", "inertia_tool.reports.frame",
    "inertia_tool.mass.materials", "inertia_tool.mesh.parts", "inertia_tool.mesh.overlap",
    "inertia_tool.balancing", "inertia_tool.batch", "inertia_tool.design", "inertia_tool.dynamics.simulation",
    "inertia_tool.dynamics.top", "inertia_tool.mass.shapes", "inertia_tool.mass.thinwall",
    "inertia_tool.mass.surface", "inertia_tool.mass.brep", "inertia_tool.reports.html",
    "inertia_tool.robot.description", "inertia_tool.robot.write", "inertia_tool.mesh.union",
    "inertia_tool.mesh.nesting", "inertia_tool.cli.balance", "inertia_tool.cli.spin", "inertia_tool.cli.top",
    "inertia_tool.cli.spin_it", "inertia_tool.cli.batch", "inertia_tool.cli.robot",
]


def imported_by(*argv, cwd=ROOT, no_accel=False) -> tuple[int, set]:
    """Exit code of ``inertia-tool ARGV`` run in a fresh interpreter, and the modules it imported."""
    env = {k: v for k, v in os.environ.items() if k != "INERTIA_TOOL_NO_ACCEL"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])   # this checkout's package
    if no_accel:
        env["INERTIA_TOOL_NO_ACCEL"] = "1"
    done = subprocess.run([sys.executable, "-c", _PROBE, *map(str, argv)], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    code, *modules = done.stdout.split()
    return int(code), set(modules)


def loaded(modules: set, name: str) -> bool:
    """``name`` or any of its submodules was imported."""
    return any(m == name or m.startswith(name + ".") for m in modules)


@pytest.mark.parametrize("options", [["--json"], [], ["--units", "mm"]], ids=["json", "text", "units-mm"])
def test_analyze_of_a_closed_stl_imports_only_what_it_uses(options):
    code, modules = imported_by("analyze", BOX, *options)
    assert code == 0
    expected_absent = [n for n in NOT_FOR_A_CLOSED_STL if HAVE_ACCEL or n != "scipy"]
    assert [n for n in expected_absent if loaded(modules, n)] == []
    # what it does use is there: the run went through the engine, not around it
    assert {"numpy", "inertia_tool.mass.pipeline", "inertia_tool.mesh.read", "inertia_tool.mesh.intersect",
            "inertia_tool.dynamics.spin_stability"} <= modules
    assert ("json" in modules) == ("--json" in options)          # the text report needs no JSON encoder


def test_the_face_pair_check_ran_on_the_lean_path():
    """The imports were cut, not the checks: the report of the same run certifies the box exact."""
    import json
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "inertia_tool", "analyze", BOX, "--json"], cwd=ROOT,
                          capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    mesh = json.loads(done.stdout)["mesh"]
    assert mesh["certificate"]["kind"] == "exact" and "no-crossing-faces" in mesh["certificate"]["checks"]


@pytest.mark.parametrize("suffix", [".step", ".STP", ".iges", ".igs"])
def test_brep_suffixes_are_those_the_reader_routes_to_opencascade(suffix):
    from inertia_tool.mesh import cad, read
    assert cad.BREP_SUFFIXES is read.BREP_SUFFIXES
    assert suffix.lower() in read.BREP_SUFFIXES and suffix.lower() in read.SUPPORTED_SUFFIXES


def test_the_numpy_path_imports_scipy_sparse_for_the_shells():
    code, modules = imported_by("analyze", BOX, "--json", no_accel=True)
    assert code == 0
    assert "scipy.sparse.csgraph" in modules


def test_formats_trimesh_reads_import_it_and_obj_does_not(tmp_path, box_mesh):
    ply, obj = tmp_path / "box.ply", tmp_path / "box.obj"
    box_mesh.export(ply, encoding="ascii")
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in box_mesh.vertices.tolist())
                   + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in box_mesh.faces.tolist()))
    code, modules = imported_by("analyze", ply, "--json")
    assert code == 0 and "trimesh" in modules
    code, modules = imported_by("analyze", obj, "--json")      # OBJ has its own reader (mesh/read.py)
    assert code == 0 and not loaded(modules, "trimesh")


def test_options_that_need_a_layer_import_it(tmp_path):
    code, modules = imported_by("analyze", BOX, "--units", "mm", "--report", tmp_path / "box.html")
    assert code == 0 and "inertia_tool.reports.html" in modules
    code, modules = imported_by("analyze", BOX, "--units", "mm", "--model", "shell", "--thickness", "1mm")
    assert code == 0 and "inertia_tool.mass.thinwall" in modules
    code, modules = imported_by("analyze", BOX, "--units", "mm", "--format", "urdf")
    assert code == 0 and {"inertia_tool.robot.formats", "inertia_tool.robot.inertial"} <= modules


def test_a_mesh_of_two_shells_imports_the_nesting_test(tmp_path):
    from conftest import box_arrays
    v1, f1 = box_arrays((1.0, 1.0, 1.0))
    v2, f2 = box_arrays((1.0, 1.0, 1.0), center=(3.0, 0.0, 0.0))
    path = tmp_path / "two.stl"
    write_binary_stl(path, list(v1) + list(v2), list(f1) + list(f2 + len(v1)))
    code, modules = imported_by("analyze", path, "--json")
    assert code == 0 and "inertia_tool.mesh.nesting" in modules


def test_each_command_imports_its_own_module_only():
    code, modules = imported_by("balance", "meshes/unbalanced_wheel.stl", "--units", "mm", "--rpm", "3000",
                                "--single-plane", "--radius", "180mm", "--json")
    assert code == 0
    assert "inertia_tool.cli.balance" in modules and "inertia_tool.balancing.rotor" in modules
    assert not loaded(modules, "inertia_tool.cli.analyze")
    code, modules = imported_by("--help")
    assert code == 0
    assert [m for m in modules if m.startswith("inertia_tool.cli.") and m != "inertia_tool.cli.help"] == []
    assert not loaded(modules, "numpy")


def test_analyze_help_loads_neither_numpy_nor_the_engine():
    """Issue 25 item 4: ``analyze --help`` built the whole engine (0.12 s, numpy included) to list options whose
    choices and defaults are constants; now only the parser's modules load, and the help is the same."""
    code, modules = imported_by("analyze", "--help")
    assert code == 0
    assert not loaded(modules, "numpy")
    assert [m for m in modules if m.startswith(("inertia_tool.mesh", "inertia_tool.mass", "inertia_tool.dynamics",
                                                "inertia_tool.integrals", "inertia_tool.values"))] == []


def test_limits_moved_for_the_parser_are_the_same_objects():
    """The face limits live in ``tolerances`` (so a parser states them without the mesh layer); the mesh layer
    and its readers use the very same values."""
    from inertia_tool import tolerances
    from inertia_tool.mesh import options, read
    assert options.DEFAULT_MAX_FACES is tolerances.DEFAULT_MAX_FACES == 50_000_000
    assert read.MAX_SUPPORTED_FACES is options.MAX_SUPPORTED_FACES is tolerances.MAX_SUPPORTED_FACES
    assert options.LoadOptions().max_faces == tolerances.DEFAULT_MAX_FACES


def test_a_run_leaves_out_the_other_commands_but_top_level_help_lists_them(capsys):
    """``analyze FILE`` builds no placeholder for the other commands (nothing reads them); an option before the
    command (``--help analyze``) prints the top-level help, which lists every command."""
    from inertia_tool.cli import SUBCOMMANDS, build_parser, main
    lean = build_parser(("analyze",), others=False)
    assert list(lean._defaults["_subparsers"]) == ["analyze"]
    full = build_parser(("analyze",))
    argv = ["analyze", BOX, "--json", "--units", "mm"]
    assert vars(lean.parse_args(argv)).keys() == vars(full.parse_args(argv)).keys()
    assert main(["--help", "analyze"]) == 0
    listed = capsys.readouterr().out
    assert all(name in listed for name in SUBCOMMANDS)


def _program(code: str, *argv, cwd=ROOT) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", code, *map(str, argv)], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=120)


@pytest.mark.parametrize("argv, exit_code", [(["analyze", BOX, "--json", "--units", "mm"], 0),
                                             (["analyze", BOX, "--units", "parsec"], 2),
                                             (["analyze", "no_such_file.stl"], 3)],
                         ids=["json", "usage-error", "missing-file"])
def test_the_program_ends_itself_with_everything_written(argv, exit_code, capsys):
    """``main()`` as the program ends the process once the command is done (no interpreter teardown): standard
    output and error are flushed first, so they are exactly what ``main(argv)`` prints in process, with the
    same exit code; nothing after ``main()`` runs."""
    from inertia_tool.cli import main
    assert main(argv) == exit_code
    expected = capsys.readouterr()
    done = _program("import sys; from inertia_tool.cli import main; code = main(); print('after main')", *argv)
    assert done.returncode == exit_code
    assert done.stdout == expected.out and done.stderr == expected.err
    assert "after main" not in done.stdout


def test_the_program_runs_the_exit_callbacks_and_skips_the_teardown():
    """An ``atexit`` callback (logging, multiprocessing, Pillow, libigl, a temporary directory's cleanup register
    one) is run, each once, last registered first, with its output flushed; the interpreter's teardown (which
    finalises the objects still alive: here one whose ``__del__`` prints) is still skipped (issue 23: ~0.3 s of
    CPU of a UR5e run, which had three callbacks and so was torn down)."""
    done = _program("import atexit, sys\n"
                    "class Alive:\n"
                    "    def __del__(self): print('torn down')\n"
                    "alive = Alive()\n"
                    "atexit.register(print, 'first registered'); atexit.register(print, 'last registered')\n"
                    "from inertia_tool.cli import main; sys.exit(main())", "analyze", BOX, "--units", "mm")
    assert done.returncode == 0
    assert done.stdout.splitlines()[-2:] == ["last registered", "first registered"]
    assert "torn down" not in done.stdout


def test_the_program_exits_normally_when_a_thread_runs():
    """A running thread means the normal exit, which joins it: one started before the command ends, and one
    that an ``atexit`` callback starts (the callbacks ran already and are not run a second time; a normal exit
    that ran them itself would not wait for that thread)."""
    # the thread prints once the main thread has finished, which only a normal exit lets it see
    done = _program("import sys, threading; t = threading.Thread(target=lambda: (threading.main_thread().join(), "
                    "print('thread done'))); t.start(); from inertia_tool.cli import main; sys.exit(main())",
                    "analyze", BOX, "--units", "mm")
    assert done.returncode == 0 and done.stdout.rstrip().endswith("thread done")
    done = _program("import atexit, sys, threading, time\n"
                    "def later():\n"
                    "    print('callback ran')\n"
                    "    threading.Thread(target=lambda: (time.sleep(0.2), print('thread done'))).start()\n"
                    "atexit.register(later)\n"
                    "from inertia_tool.cli import main; sys.exit(main())", "analyze", BOX, "--units", "mm")
    assert done.returncode == 0
    assert done.stdout.splitlines()[-2:] == ["callback ran", "thread done"]


def test_the_xacro_child_imports_neither_numpy_nor_the_description_readers(tmp_path):
    """The isolated child that expands a xacro file (``python -I``, :mod:`inertia_tool.isolate`) imports the
    child's side of ``isolate`` and the expansion (:mod:`inertia_tool.robot.xacro_expand`), not numpy, scipy or
    the description readers: the function lived in ``robot.description`` and the limits were a ``frozen_value``,
    so the child imported numpy and the readers, ~0.1 s of a UR5e run's CPU (issue 23)."""
    pytest.importorskip("xacro")
    source = tmp_path / "r.urdf.xacro"
    source.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="s" '
                      'value="0.5"/><link name="a"><collision><geometry><box size="${s} 1 1"/></geometry>'
                      '</collision></link></robot>')
    code = ("import sys, json; sys.path[:] = json.loads(sys.argv[1]); from inertia_tool.isolate import _child_main; "
            "from inertia_tool.robot.xacro_expand import expand_here; "
            "out = expand_here(sys.argv[2], {}, {}); print(b'size=\"0.5 1 1\"' in out); print(' '.join(sys.modules))")
    done = subprocess.run([sys.executable, "-I", "-c", code, json.dumps([str(ROOT), *sys.path]), str(source)],
                          capture_output=True, text=True, timeout=120, check=True)
    expanded, modules = done.stdout.splitlines()
    assert expanded == "True"
    loaded_here = set(modules.split())
    assert {"numpy", "scipy", "inertia_tool.values", "inertia_tool.robot.description"}.isdisjoint(loaded_here)


def test_importing_the_package_imports_only_its_errors():
    done = subprocess.run([sys.executable, "-c", "import sys, inertia_tool; print(' '.join(sys.modules))"],
                          cwd=ROOT, capture_output=True, text=True, timeout=60, check=True)
    assert sorted(m for m in done.stdout.split() if m.startswith("inertia_tool")) == ["inertia_tool",
                                                                                     "inertia_tool.errors"]


# -- the lazily loaded names (PEP 562) are what type checkers and the docs see ----------------------------------

#: Packages whose public names load on first use, and the name of their ``name → module`` table.
LAZY_PACKAGES = [("inertia_tool", "_LAZY"), ("inertia_tool.mass", "_PUBLIC"), ("inertia_tool.mesh", "_PUBLIC"),
                 ("inertia_tool.robot", "_PUBLIC")]


def type_checking_imports(module) -> dict:
    """``name → relative module`` of the ``from .x import name`` statements under ``if TYPE_CHECKING:``."""
    tree = ast.parse(inspect.getsource(module))
    found = {}
    for node in tree.body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            for stmt in node.body:
                assert isinstance(stmt, ast.ImportFrom) and stmt.level == 1, ast.dump(stmt)
                for alias in stmt.names:
                    found[alias.asname or alias.name] = "." + (stmt.module or alias.name)
    return found


@pytest.mark.parametrize("package, table", LAZY_PACKAGES, ids=[p for p, _ in LAZY_PACKAGES])
def test_lazy_names_match_the_type_checking_imports(package, table):
    module = importlib.import_module(package)
    lazy = getattr(module, table)
    assert type_checking_imports(module) == lazy
    assert set(lazy) <= set(module.__all__) and set(module.__all__) <= set(dir(module))
    for name, where in lazy.items():
        value = getattr(module, name)
        source = importlib.import_module(where, package)
        assert value is (source if inspect.ismodule(value) else getattr(source, name)), name


def test_placeholder_subcommands_give_the_same_help():
    from inertia_tool.cli import SUBCOMMANDS, build_parser
    full = build_parser()
    assert build_parser(()).format_help() == full.format_help()
    for name in SUBCOMMANDS:
        alone = build_parser((name,))
        assert (alone._defaults["_subparsers"][name].format_help()
                == full._defaults["_subparsers"][name].format_help()), name


@pytest.mark.parametrize("command", ["spin", "top", "balance", "batch", "robot", "spin-it"])
def test_command_help_loads_neither_numpy_nor_the_engine(command):
    """Issue 25 item 4: ``spin``, ``top``, ``balance``, ``batch``, ``robot`` and ``spin-it --help`` loaded numpy and
    the engine (0.13-0.26 s of CPU) to state a few constants; now, like ``analyze --help``, only the parser's
    modules load."""
    code, modules = imported_by(command, "--help")
    assert code == 0
    assert not loaded(modules, "numpy")
    assert [m for m in modules if m.startswith((
        "inertia_tool.mesh", "inertia_tool.mass", "inertia_tool.dynamics", "inertia_tool.integrals",
        "inertia_tool.values", "inertia_tool.balancing", "inertia_tool.robot", "inertia_tool.batch",
        "inertia_tool.output", "inertia_tool.reports.serialize", "inertia_tool.reports.stability"))] == []


def test_the_parsers_constants_are_the_engines():
    """What the light parsers state (choices, defaults, limits) is what the engine uses: the same objects where
    they moved to ``tolerances``/``units``, equal copies where the engine keeps its own."""
    from inertia_tool import tolerances, units
    from inertia_tool.balancing.rotor import ISO_GRADES
    from inertia_tool.cli import balance, robot, spin, top
    from inertia_tool.dynamics import experiment, spin_stability
    from inertia_tool.dynamics import top as heavy_top
    from inertia_tool.mass.principal import DEFAULT_EQUAL_RTOL
    from inertia_tool.robot.description import GEOMETRY_KINDS
    from inertia_tool.robot.geometry import MODEL_DENSITY
    assert spin.MAX_SAMPLES is experiment.MAX_SAMPLES is heavy_top.MAX_TOP_SAMPLES is top.MAX_SAMPLES \
        is tolerances.MAX_TRAJECTORY_SAMPLES
    assert heavy_top.STANDARD_GRAVITY is units.STANDARD_GRAVITY == 9.80665
    assert spin.DEFAULT_EQUAL_RTOL is DEFAULT_EQUAL_RTOL
    assert spin.AXIS_NAMES == spin_stability.AXIS_NAMES
    assert balance.ISO_GRADE_NAMES == tuple(g.name.replace(" ", "") for g in ISO_GRADES)
    assert robot.GEOMETRY_KINDS == GEOMETRY_KINDS and robot.MODEL_DENSITY == MODEL_DENSITY
