"""Hostile and broken input: every corpus file ends in a correct result or a one-line error (exit 3).

The corpus is written by ``tests/corpus/make_corpus.py`` into a temporary directory.  Each entry runs
through ``inertia_tool.cli.main(["analyze", FILE, "--json"])``; accepted files' numbers are checked against
the exact engine on a clean copy of the same solid (clean arrays, outward wound, no file in between).
Inputs that once crashed the fuzz harness live in ``tests/regressions/`` and are replayed here.
"""

import io
import json
import math
import os
import re
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

from corpus.make_corpus import (ENTRIES, box, exact_reference, make_corpus, prism, write_ascii_stl, write_binary_stl,
                                write_obj)
from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import InvalidMeshError, MeshReadError, NonFiniteResultError, UsageError
from inertia_tool.mesh.read import load_mesh

REGRESSIONS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "regressions")


# every test runs on the C extension (when built) and on the pure-numpy path
pytestmark = pytest.mark.usefixtures("engine_path")


def run_cli(*argv):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return {e.name: e for e in make_corpus(tmp_path_factory.mktemp("corpus"))}



def check_contract(path, code, out, err):
    """What every run must satisfy: exit 0 with finite JSON, or exit 3 with one error line naming the file."""
    assert "Traceback" not in err and "internal error" not in err, err
    shown = os.fsencode(path).decode("utf-8", "replace")
    if code == 3:
        errors = [line for line in err.splitlines() if line.startswith("inertia-tool: error:")]
        assert len(errors) == 1 and shown in errors[0], err
        assert out == ""
        return None
    assert code == 0, err
    result = json.loads(out)
    for key in ("mass", "volume", "surface_area"):
        assert math.isfinite(result[key]) and result[key] > 0
    values = np.array([result["center_of_mass"], *result["inertia"], result["principal_moments"]], dtype=float)
    assert np.all(np.isfinite(values))
    return result


@pytest.mark.parametrize("name", [e.name for e in ENTRIES], ids=[e.name.encode("ascii", "replace").decode()
                                                                  for e in ENTRIES])
def test_corpus_entry(corpus, name):
    e = corpus[name]
    code, out, err = run_cli("analyze", e.path, "--json", *e.args)
    assert code == e.exit_code, err
    result = check_contract(e.path, code, out, err)
    if code == 3:
        assert re.search(e.says, err), err
        return
    warnings = result["warnings"]
    if e.says == r"^$":
        assert not [w for w in warnings if "principal moments" not in w], warnings
    else:
        assert any(re.search(e.says, w) for w in warnings), warnings
    assert all(os.fsencode(e.path).decode("utf-8", "replace") in w for w in warnings)
    want = exact_reference(e.reference)
    assert result["mass"] == pytest.approx(want.mass, rel=1e-12)
    assert result["volume"] == pytest.approx(want.volume, rel=1e-12)
    size = float(np.linalg.norm(np.ptp(np.concatenate([v for v, _ in e.reference]), axis=0)))
    np.testing.assert_allclose(result["center_of_mass"], want.center_of_mass, rtol=0, atol=1e-12 * size)
    np.testing.assert_allclose(result["inertia"], want.inertia, rtol=0,
                               atol=1e-12 * float(np.max(np.abs(want.inertia))))


def test_corpus_covers_the_issue_list():
    kinds = " ".join(e.kind for e in ENTRIES)
    for needed in ("zero-byte", "directory", "PNG", "10⁹", "mid-record", "trailing bytes", "\"solid\"",
                   "garbage", "NaN", "infinite", "1e308", "endloop", "Windows", "old-Mac", "non-UTF-8",
                   "negative", "past the last vertex", "quads and n-gons", "claims more faces", "empty mesh",
                   "point cloud", "flat",
                   "degenerate", "open box", "face flipped", "inside-out box", "non-manifold",
                   "one inside out", "overlapping cubes", "zip bomb", "1 µm", "1 km", "float32", "1e8",
                   "axisymmetric", "needle", "--max-faces"):
        assert needed in kinds, needed


def test_non_utf8_file_name_prints_in_one_line(tmp_path, capsys):
    raw = os.path.join(os.fsencode(tmp_path), b"bad-\xff\xfe.stl")
    open(raw, "wb").close()
    assert main(["analyze", os.fsdecode(raw), "--json"]) == 3
    err = capsys.readouterr().err
    assert "bad-\ufffd\ufffd.stl: empty file" in err and len(err.splitlines()) == 1


# -- streaming and limits -------------------------------------------------------------------------------

@pytest.mark.parametrize("newline", [b"\n", b"\r\n", b"\r"])
def test_ascii_stl_streams_across_block_boundaries(tmp_path, monkeypatch, newline):
    """Tiny read blocks split lines (and \\r\\n pairs) everywhere; the result must not change."""
    import inertia_tool.mesh.read_base as mesh_io
    v, f = prism(n=20)
    p = tmp_path / "p.stl"
    write_ascii_stl(p, v, f, newline=newline)
    whole = load_mesh(p)
    monkeypatch.setattr(mesh_io, "_BLOCK_BYTES", 7)
    pieces = load_mesh(p)
    np.testing.assert_array_equal(whole.vertices, pieces.vertices)
    np.testing.assert_array_equal(whole.faces, pieces.faces)
    assert len(whole.faces) == len(f)


def test_old_mac_file_is_read_in_bounded_blocks(tmp_path, monkeypatch):
    """A CR-only file is many lines, not one giant line: no block ever exceeds the block size + a line."""
    import inertia_tool.mesh.read_stl as mesh_io
    v, f = prism(n=200)
    p = tmp_path / "mac.stl"
    write_ascii_stl(p, v, f, newline=b"\r")
    seen = []
    real = mesh_io._text_blocks

    def spy(fh, path, **kw):
        for block in real(fh, path, block_bytes=4096, max_line=256):
            seen.append(len(block))
            yield block
    monkeypatch.setattr(mesh_io, "_text_blocks", spy)
    raw = load_mesh(p)
    assert len(raw.faces) == len(f) and len(seen) > 10 and max(seen) <= 4096 + 256


def test_obj_relative_and_absolute_indices_agree(tmp_path):
    v, f = prism(n=9)
    a, b = tmp_path / "abs.obj", tmp_path / "rel.obj"
    write_obj(a, v, f)
    write_obj(b, v, f, relative=True)
    pa, pb = mass_properties(a), mass_properties(b)
    assert pa.volume == pb.volume and np.array_equal(pa.inertia, pb.inertia)


def test_obj_relative_indices_refer_to_vertices_defined_so_far(tmp_path):
    """Interleaved v/f lines: -1 is the last vertex *before* the face line."""
    v, f = box()
    p = tmp_path / "interleaved.obj"
    with open(p, "w") as fh:
        fh.write("".join("v {} {} {}\n".format(*x) for x in v[:4]))
        fh.write("f -4 -2 -3\nf -4 -1 -2\n")                 # bottom face (0 2 1), (0 3 2)
        fh.write("".join("v {} {} {}\n".format(*x) for x in v[4:]))
        fh.write("".join("f {} {} {}\n".format(*(t + 1)) for t in f[2:]))
    got = mass_properties(p)
    want = mass_properties((v, f))
    assert got.volume == pytest.approx(want.volume, rel=1e-15)
    np.testing.assert_allclose(got.inertia, want.inertia, rtol=1e-14, atol=1e-15)


def test_max_faces_guards_every_format(tmp_path):
    v, f = box()
    paths = {"stl": tmp_path / "b.stl", "obj": tmp_path / "b.obj", "ply": tmp_path / "b.ply"}
    write_binary_stl(paths["stl"], v, f)
    write_obj(paths["obj"], v, f)
    from corpus.make_corpus import write_ply
    write_ply(paths["ply"], v, f)
    ascii_path = tmp_path / "a.stl"
    write_ascii_stl(ascii_path, v, f)
    for p in [*paths.values(), ascii_path]:
        with pytest.raises(MeshReadError, match="`max_faces`"):
            load_mesh(p, max_faces=11)
        assert len(load_mesh(p, max_faces=12).faces) == 12


def test_binary_header_claim_is_checked_before_allocation(tmp_path):
    """A lying count must be refused before anything it would size is allocated: the peak of traced memory
    (numpy reports its buffers to tracemalloc) stays far below the 200 GB the header announces."""
    import tracemalloc
    p = tmp_path / "liar.stl"
    write_binary_stl(p, *box(), count=4_000_000_000)
    tracemalloc.start()
    try:
        with pytest.raises(MeshReadError, match="announces 4,000,000,000 triangles"):
            load_mesh(p)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 8 << 20, f"{peak / 2**20:.1f} MiB allocated before refusing"


# -- numerical edge cases ---------------------------------------------------------------------------------

@pytest.mark.parametrize("size, offset", [(1e-6, 0.0), (1e-6, 1e-3), (1e3, 0.0), (1.0, 1e8), (1e3, 1e8)])
def test_box_closed_form_at_any_scale_and_offset(size, offset):
    """Box a × 2a × 3a at an offset: mass a³·6ρ and moments m(b²+c²)/12 (Eq. 4.13 integrated)."""
    ext = np.array([1.0, 2.0, 3.0]) * size
    v, f = box(ext, center=(offset, -offset, 0.5 * offset))
    p = mass_properties((v, f), density=1000.0)
    m = 1000.0 * np.prod(ext)
    want = m * np.array([ext[1]**2 + ext[2]**2, ext[0]**2 + ext[2]**2, ext[0]**2 + ext[1]**2]) / 12
    # the corners themselves are only known to |offset|·eps: the tolerance follows from that rounding
    rel = 1e-13 + 10 * np.finfo(float).eps * (abs(offset) / size)
    assert p.mass == pytest.approx(m, rel=rel)
    np.testing.assert_allclose(np.diag(p.inertia), want, rtol=rel)
    np.testing.assert_allclose(p.center_of_mass, [offset, -offset, 0.5 * offset], rtol=0,
                               atol=rel * size + 4 * np.finfo(float).eps * abs(offset))


def test_float32_vertices_give_the_float32_polyhedron_exactly(tmp_path):
    """A binary STL stores float32: the result is exact for those rounded corners (compared in float64)."""
    v, f = prism(n=30, radius=0.013, height=0.041)
    v = v + np.array([120.0, -35.0, 7.0])
    p = tmp_path / "f32.stl"
    write_binary_stl(p, v, f)
    got = mass_properties(p, density=2700.0)
    want = mass_properties((np.asarray(v, dtype=np.float32).astype(float), f), density=2700.0)
    assert got.mass == pytest.approx(want.mass, rel=1e-13)
    np.testing.assert_allclose(got.inertia, want.inertia, rtol=1e-10, atol=1e-12 * np.abs(want.inertia).max())


def test_axisymmetric_part_warns_and_keeps_the_symmetry_axis():
    from inertia_tool.errors import NearlyEqualMomentsWarning
    v, f = prism(n=64, radius=0.5, height=3.0)
    with pytest.warns(NearlyEqualMomentsWarning, match="I2 and I3"):
        p = mass_properties((v, f))
    axis = p.principal.axes[:, 0]              # the distinct (smallest, axial) moment lies along z
    assert abs(abs(axis[2]) - 1) < 1e-12


def test_needle_warns_and_its_moments_match_the_prism_closed_form():
    from inertia_tool.errors import PhysicalValidityWarning
    n, r, h = 6, 3e-5, 10.0
    v, f = prism(n=n, radius=r, height=h)
    with pytest.warns(PhysicalValidityWarning, match="needle"):
        p = mass_properties((v, f), density=1000.0)
    # regular hexagonal prism: area A = 3√3/2 r², polar second moment of area J = 5√3/8 r⁴
    area = 1.5 * np.sqrt(3) * r**2
    m = 1000.0 * area * h
    axial = 1000.0 * h * 5 * np.sqrt(3) / 8 * r**4
    transverse = m * h**2 / 12 + axial / 2
    np.testing.assert_allclose(p.principal.moments, [axial, transverse, transverse], rtol=1e-5)


def test_overflowing_and_underflowing_sizes_are_refused():
    v, f = box()
    with pytest.raises(InvalidMeshError, match="overflow"):
        mass_properties((v * 1e200, f))
    with pytest.raises(InvalidMeshError, match="underflow"):
        mass_properties((v * 1e-200, f))


def test_result_with_huge_density_overflowing_is_refused():
    """The mass overflows because of the density: a named physics error (exit 4), not a mesh error."""
    v, f = box()
    with pytest.raises(NonFiniteResultError, match="the mass is inf"):
        mass_properties((v * 1e29, f), density=1e300)


# -- regressions found by fuzzing -----------------------------------------------------------------------

REGRESSION_FILES = sorted(os.listdir(REGRESSIONS)) if os.path.isdir(REGRESSIONS) else []


@pytest.mark.parametrize("name", REGRESSION_FILES)
def test_fuzz_regression(name):
    path = os.path.join(REGRESSIONS, name)
    code, out, err = run_cli("analyze", path, "--json")
    check_contract(path, code, out, err)


def test_regressions_directory_is_not_empty():
    assert REGRESSION_FILES, "every input that once crashed must be kept in tests/regressions/"


# -- property-based mutation of valid files (bounded, part of the normal suite) -------------------------

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402


def _valid_bytes(kind: str) -> bytes:
    import tempfile
    v, f = prism(n=5, radius=0.02, height=0.05)
    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "x")
        {"binary": write_binary_stl, "ascii": write_ascii_stl, "obj": write_obj}[kind](p, v, f)
        return open(p, "rb").read()


_SEEDS = {kind: _valid_bytes(kind) for kind in ("binary", "ascii", "obj")}

_edit = st.one_of(
    st.tuples(st.just("flip"), st.integers(0, 1 << 16), st.integers(1, 255)),
    st.tuples(st.just("insert"), st.integers(0, 1 << 16), st.binary(min_size=1, max_size=40)),
    st.tuples(st.just("delete"), st.integers(0, 1 << 16), st.integers(1, 200)),
    st.tuples(st.just("truncate"), st.integers(0, 1 << 16), st.just(0)),
    st.tuples(st.just("duplicate"), st.integers(0, 1 << 16), st.integers(1, 300)),
    st.tuples(st.just("token"), st.integers(0, 1 << 16),
              st.sampled_from([b"nan", b"inf", b"-1e308", b"1e39", b"-0", b"\r", b"\xff\xfe", b"\x00",
                               b"facet", b"vertex", b"endloop", b"f -1 -2 -99", b"f 0 1 2", b"v 1 2",
                               b"4294967295", b"solid"])),
)


def _mutate(data: bytes, edits) -> bytes:
    buf = bytearray(data)
    for op, pos, arg in edits:
        pos = pos % (len(buf) + 1)
        if op == "flip" and pos < len(buf):
            buf[pos] ^= arg
        elif op == "insert":
            buf[pos:pos] = arg
        elif op == "delete":
            del buf[pos:pos + arg]
        elif op == "truncate":
            del buf[pos:]
        elif op == "duplicate":
            buf[pos:pos] = buf[pos:pos + arg]
        elif op == "token":
            buf[pos:pos] = arg
    return bytes(buf)


@pytest.mark.parametrize("kind, suffix", [("binary", ".stl"), ("ascii", ".stl"), ("obj", ".obj")])
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.lists(_edit, min_size=1, max_size=4))
def test_mutated_files_give_a_result_or_a_one_line_error(tmp_path, kind, suffix, edits):
    path = str(tmp_path / ("mutant" + suffix))
    with open(path, "wb") as fh:
        fh.write(_mutate(_SEEDS[kind], edits))
    code, out, err = run_cli("analyze", path, "--json")
    result = check_contract(path, code, out, err)
    if result is not None:
        # a mutation that left the triangles intact (a comment, a header byte) must not move the numbers
        raw = load_mesh(path)
        if _triangle_set(raw) == _SEED_TRIANGLES[kind]:
            assert result["mass"] == pytest.approx(_SEED_MASS[kind], rel=1e-12)


def _triangle_set(raw):
    corners = raw.vertices[raw.faces]
    return sorted(tuple(sorted(map(tuple, t.tolist()))) for t in corners)


def _seed_facts():
    import tempfile
    triangles, mass = {}, {}
    with tempfile.TemporaryDirectory() as d:
        for kind, suffix in (("binary", ".stl"), ("ascii", ".stl"), ("obj", ".obj")):
            p = os.path.join(d, kind + suffix)
            open(p, "wb").write(_SEEDS[kind])
            triangles[kind] = _triangle_set(load_mesh(p))
            mass[kind] = mass_properties(p, density=1000.0).mass
    return triangles, mass


_SEED_TRIANGLES, _SEED_MASS = _seed_facts()


# -- issue 11: edge numbers -----------------------------------------------------------------------------

WHEEL = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "meshes", "unbalanced_wheel.stl")
BALANCE = ["balance", WHEEL, "--units", "mm", "--planes=-40,40", "--radius", "180"]


@pytest.mark.parametrize("argv, option", [
    (BALANCE + ["--rpm", "1e300"], "--rpm must be between"),                  # was an internal OverflowError
    (BALANCE + ["--rpm", "3000", "--density", "5e-324"], "--density must be between 0.1 and 100000 kg/m³"),
    (BALANCE + ["--rpm", "3000", "--density", "1e300"], "--density must be"),
    (BALANCE + ["--rpm", "3000", "--mass", "1e300"], "--mass must be between 1e-12 and 1e+09 kg"),
    (BALANCE + ["--rpm", "3000", "--radius", "1e-300"], "--radius must be between 1e-09 and 1e+06 m"),
    (BALANCE + ["--rpm", "3000", "--axis-point", "1e300,0,0"], "--axis-point must be at most 1e+06 m"),
    (BALANCE + ["--rpm", "3000", "--bearings", "0,1e307"], "--bearings must be at most"),
    (["analyze", WHEEL + ":5e-324"], "the density of " + WHEEL + " must be between"),
    (["analyze", WHEEL, "--model", "shell", "--thickness", "1e-300"], "--thickness must be between"),
    (["analyze", WHEEL, "--max-faces", "1000000000"], "--max-faces must be between 1 and 715,827,882"),
    (["spin", WHEEL, "--rate", "1e300"], "--rate must be between"),
    (["spin", WHEEL, "--duration", "1e300"], "--duration must be between"),
    (["top", WHEEL, "--pivot", "0,0,0", "--spin", "1e300"], "--spin must be at most"),
    (["top", WHEEL, "--pivot", "0,0,1e300", "--spin", "5rev/s"], "--pivot must be at most"),
    (["top", WHEEL, "--pivot", "0,0,0", "--spin", "5rev/s", "--gravity", "1e300"], "--gravity must be between"),
    (["batch", WHEEL, "--out", "never.jsonl", "--density", "5e-324"], "--density must be between"),
    (["batch", WHEEL, "--out", "never.jsonl", "--jobs", "100000"], "--jobs must be between 1 and 1,024"),
])
def test_numeric_options_outside_their_physical_range_exit_2_in_one_line(argv, option, capsys):
    from inertia_tool.cli import main
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0] and "internal error" not in err[0]
    assert not os.path.exists("never.jsonl")


def test_option_table_bounds_are_finite_and_ordered():
    from inertia_tool.cli.options import OPTION_RANGES
    for name, rng in OPTION_RANGES.items():
        assert 0 <= rng.low < rng.high < 1e300 and rng.reason, name


def test_engine_refuses_overflowing_results_with_a_named_error():
    """Through the Python API, where no option table stands in front: a named error, never inf or a bare
    OverflowError."""
    import importlib
    balance_mod = importlib.import_module("inertia_tool.balancing.rotor")
    props = mass_properties(WHEEL, units="mm", material="steel")
    with pytest.raises(NonFiniteResultError, match="Ω²"):
        balance_mod.balance(props, axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=1e300, planes=[-0.04, 0.04],
                            radius=0.18)
    with pytest.raises(NonFiniteResultError, match="mass underflows"):
        mass_properties(WHEEL, units="mm", density=5e-324)
    from inertia_tool.dynamics.experiment import spin_experiment
    from inertia_tool.dynamics.top import heavy_top
    with pytest.raises(NonFiniteResultError, match="kinetic energy"):        # returned inf energies before
        spin_experiment(props, "intermediate", 1e300, duration=1.0, samples=2001)
    with pytest.raises(NonFiniteResultError, match="largest rate"):          # a bare OverflowError before
        heavy_top(1.0, 2.0, 1.0, 0.1, theta0=0.3, omega3=1e300)
    from inertia_tool.cli import exit_code
    assert issubclass(NonFiniteResultError, OverflowError) and exit_code(NonFiniteResultError("x")) == 4


def test_stl_announcing_more_triangles_than_32_bit_indices_hold_is_refused_from_its_header(tmp_path, monkeypatch):
    """A binary STL claiming 715,827,883 triangles with max_faces raised: refused from the header (a sparse
    file of the right size; nothing read or allocated), not an internal error in the welder."""
    import inertia_tool.mesh.read as io_mod
    import inertia_tool.mesh.read_stl as stl_mod
    from inertia_tool.mesh.read import MAX_SUPPORTED_FACES, read_stl
    n = MAX_SUPPORTED_FACES + 1
    path = tmp_path / "huge.stl"
    with open(path, "wb") as fh:
        fh.write(b"\0" * 80 + n.to_bytes(4, "little"))
        fh.truncate(84 + 50 * n)                                   # sparse: ~36 GB that take no space
    def no_weld(*a, **k):
        raise AssertionError("welding started")
    monkeypatch.setattr(stl_mod, "weld_exact_stream", no_weld)
    with pytest.raises(MeshReadError, match=r"715,827,883 triangles, more than the 715,827,882 this reader"):
        read_stl(path, max_faces=10**12)
    with pytest.raises(UsageError, match="max_faces"):
        io_mod.load_mesh(path, max_faces=10**12)
