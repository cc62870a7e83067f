"""mesh/intersect.py, the C scan's certified patches (normal-cone self-collision culling made exact; module
docstring, "Patches") held against the pairs found without them, on the meshes issue 25 names as adversarial.

``test_mesh_intersect_patches.py`` and ``test_mesh_intersect_pinches.py`` draw folds, spiral ramps, ribbons,
slabs, pinched fans and nested rings.  The meshes here add what a culling certificate is most easily fooled by:

* *loops that pass through themselves with every face facing one way*: a ribbon round the z axis, a little more
  than one turn, tilted across so that its two layers cross along a line inside the strip; every face projects
  along z with one strict orientation, so only the boundary test can refuse it (its boundary winds past a
  full turn);
* *cylinder wraps*: a grid on an arc of a cylinder round any coordinate axis, of arc just under, at and over a
  half turn (its normal cone narrower or wider than a hemisphere), up to more than a full turn (lying on itself
  or a lattice step off), facing out or in, the seam closed by index, by coordinates only (an unwelded seam: the
  two columns' vertices equal under two indices) or not at all;
* *slivers*: lattice sheets with vertices moved onto the line of two neighbours (faces of zero area, or of zero
  projected area along the axis the sheet would be certified on) and one unit in the last place off it; sheets
  in a plane through a coordinate axis (zero projected area along that axis for every face);
* *duplicated faces*: faces listed twice, as written or reversed, next to or far from the original (both land
  in one leaf of the hierarchy: their boxes are equal).

Each mesh is compared pair for pair: the C scan as the analysis runs it, without patches (``_patches=False``),
without stars, the numpy twin, and for small meshes every pair against the rational classifier
(``intersect_reference.brute_kind``), by ``test_mesh_intersect_patches._check``.  The committed real parts
(``tests/data``) are compared the same way; the same comparison over every Menagerie, Gazebo and trimesh model
on this machine is ``benchmarks/bench_patches_agree.py``.
"""

import gzip
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from contact_scans import run_scan, same_pairs
from test_mesh_intersect_patches import _check, _grid, _push, _sheet

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")

DATA = Path(__file__).parent / "data"
#: Real parts of more faces are compared on the C scans only (the numpy twin takes seconds there).
TWIN_FACES = 5000


def _found(result) -> int:
    return len(result.crossing) + len(result.coplanar_opposite) + len(result.contact)


def _axes(p: np.ndarray, axis: int) -> np.ndarray:
    """Points (..., 3) built round z, turned so that their z is coordinate ``axis`` (a cyclic permutation)."""
    return np.roll(p, axis - 2, axis=-1)


def _loop(turn: float, tilt: float, rise: float, cells: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """A ribbon round the z axis over ``turn`` turns, ``width`` cells across (radius 8 to 8 + 2·width); its
    height ``rise``·t at angle t (in turns) plus ``tilt``·t·(r − r_mid) across, so that where it passes over
    itself (t and t + 1) its layers differ by ``rise + tilt·(r − r_mid)``: they cross inside the strip when
    |rise / tilt| < width.  Every face faces up (z-orientation +1) while the tilt stays moderate."""
    t = np.linspace(0.0, turn, cells + 1)
    r = 8.0 + 2.0 * np.arange(width + 1)
    tt, rr = np.meshgrid(t, r, indexing="ij")
    z = rise * tt + tilt * tt * (rr - r.mean())
    p = np.stack([rr * np.cos(2 * np.pi * tt), rr * np.sin(2 * np.pi * tt), z], -1)
    return _grid(np.round(p * 8) / 8)


def _wrap(arc_degrees: float, axis: int, sections: int, rows: int, rng, *, inward: bool, seam: str,
          pitch: float = 0.0, radius: float = 6.0) -> tuple[np.ndarray, np.ndarray]:
    """A grid on an arc of a cylinder of ``radius`` round coordinate ``axis`` (``sections`` x ``rows`` cells,
    coordinates on a 1/16 lattice); a full turn's ``seam`` is "index" (the last column is the first), "coords"
    (the last column a copy of the first under new indices) or "open" (the arc stops a hair short); ``pitch``
    lifts each turn along the axis."""
    closed = abs(arc_degrees - 360.0) < 1e-9
    start = rng.uniform(0, 2 * np.pi)
    if closed and seam == "index":
        t = start + 2 * np.pi * np.arange(sections) / sections
    else:
        stop = np.radians(arc_degrees) - (1e-3 if closed and seam == "open" else 0.0)
        t = start + np.linspace(0.0, stop, sections + 1)
    h = np.arange(rows + 1) * 2.0
    tt, hh = np.meshgrid(t, h, indexing="ij")
    p = np.stack([radius * np.cos(tt), radius * np.sin(tt), hh + pitch * (tt - start) / (2 * np.pi)], -1)
    p = np.round(p * 16) / 16
    if closed and seam == "coords":
        p[-1] = p[0]
    v, f = _grid(_axes(p, axis), closed_u=closed and seam == "index")
    return v, (f[:, ::-1].copy() if inward else f)


def _slivers(v: np.ndarray, f: np.ndarray, rng, count: int, ulps: int) -> np.ndarray:
    """``count`` vertices of a lattice sheet moved to the midpoint of two of their neighbours' (an exact float
    operation on the lattice: the faces round it flatten onto that line in 3-D or in projection), then one
    coordinate moved ``ulps`` units in the last place."""
    v = v.copy()
    for _ in range(count):
        face = f[int(rng.integers(len(f)))]
        a, b, c = (int(x) for x in rng.permutation(face))
        v[a] = (v[b] + v[c]) / 2
        if ulps:
            k = int(rng.integers(3))
            for _ in range(ulps):
                v[a, k] = np.nextafter(v[a, k], np.inf if rng.integers(2) else -np.inf)
    return v


def _duplicated(f: np.ndarray, rng, count: int, reverse: bool) -> np.ndarray:
    """``count`` faces listed again, as written or reversed, at a random place of the face list."""
    f = f.copy()
    for _ in range(count):
        row = f[int(rng.integers(len(f)))]
        row = row[::-1] if reverse else row
        at = int(rng.integers(len(f) + 1))
        f = np.insert(f, at, row, axis=0)
    return f


KINDS = ("loop", "wrap", "slivers", "plane", "duplicates")


@st.composite
def culling_adversaries(draw, kind: str):
    """One mesh of ``kind`` (module docstring), maybe with a vertex pushed by a few lattice steps."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if kind == "loop":
        v, f = _loop(draw(st.sampled_from([0.9, 1.0, 1.1, 1.25, 1.6])), draw(st.sampled_from([0.0, 0.5, -1.0, 2.0])),
                     draw(st.sampled_from([0.0, 0.5, 1.0, 3.0])), draw(st.integers(8, 40)), draw(st.integers(1, 3)))
    elif kind == "wrap":
        v, f = _wrap(draw(st.sampled_from([60.0, 150.0, 179.0, 180.0, 181.0, 270.0, 360.0, 400.0, 720.0])),
                     draw(st.integers(0, 2)), draw(st.integers(3, 36)), draw(st.integers(1, 4)), rng,
                     inward=draw(st.booleans()), seam=draw(st.sampled_from(["index", "coords", "open"])),
                     pitch=draw(st.sampled_from([0.0, 0.0, 1.0, 4.0])))
    elif kind == "slivers":
        v, f = _sheet(draw(st.integers(3, 9)), draw(st.integers(3, 9)), rng, bump=draw(st.integers(0, 1)))
        v = _slivers(v, f, rng, draw(st.integers(1, 4)), draw(st.sampled_from([0, 0, 1, 2])))
    elif kind == "plane":
        # a sheet in a plane holding one coordinate axis: every face has zero projected area along it
        v, f = _sheet(draw(st.integers(3, 8)), draw(st.integers(3, 8)), rng, bump=draw(st.integers(0, 1)))
        slope = draw(st.sampled_from([0.0, 1.0, -1.0, 0.5]))
        v = np.c_[v[:, 0], v[:, 1] * slope + v[:, 2], v[:, 1]]
        v = _axes(v, draw(st.integers(0, 2)))
        if draw(st.booleans()):
            v = _slivers(v, f, rng, 1, draw(st.sampled_from([0, 1])))
    else:
        v, f = _sheet(draw(st.integers(3, 8)), draw(st.integers(3, 8)), rng, bump=draw(st.integers(0, 1)))
        f = _duplicated(f, rng, draw(st.integers(1, 3)), draw(st.booleans()))
    v, f = _push(v, f, rng, draw(st.sampled_from([0, 0, 1])))
    return v, f


@pytest.mark.parametrize("kind", KINDS)
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_culling_leaves_out_no_pair_that_meets(kind, data):
    v, f = data.draw(culling_adversaries(kind))
    fast, unpatched = _check(v, f, brute=len(f) <= 36)
    event("patches left pairs out" if fast.candidate_pairs < unpatched.candidate_pairs else "no patch")


@pytest.mark.parametrize("rise, tilt, meets", [(1.0, 2.0, True), (0.0, 0.0, True), (3.0, 0.0, False)])
def test_loop_through_itself_facing_one_way_is_found(rise, tilt, meets):
    """A ribbon of 1.25 turns whose every face faces up: its layers cross along a line inside the strip (rise 1,
    tilt 2), lie on one another (coplanar, facing the same way) or are 3 apart.  The crossings are found as
    without patches, and the culling still leaves pairs out (the sections under a turn are certified)."""
    v, f = _loop(1.25, tilt, rise, 40, 2)
    fast, unpatched = _check(v, f)
    assert (len(fast.crossing) > 0) == meets
    assert fast.candidate_pairs < unpatched.candidate_pairs


@pytest.mark.parametrize("seam", ["index", "coords"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_closed_cylinder_wrap_is_culled_and_clean(axis, seam):
    """A full turn of a cylinder round each axis (no face pair meets beyond what it shares): closed by index
    nothing is found; closed by coordinates only (an unwelded seam) the seam's faces touch along their copied
    edges and are found as ``contact`` by every path.  Either way the patches leave out most pairs."""
    v, f = _wrap(360.0, axis, 48, 8, np.random.default_rng(axis), inward=False, seam=seam)
    fast, unpatched = _check(v, f)
    assert len(fast.crossing) == 0 and len(fast.coplanar_opposite) == 0
    assert (len(fast.contact) > 0) == (seam == "coords")
    assert fast.candidate_pairs < unpatched.candidate_pairs // 2


def test_duplicated_face_is_found_inside_a_certifiable_sheet():
    """A flat sheet is one certified patch; with one face listed twice (as written: ``crossing``, coplanar
    facing the same way) or reversed (``coplanar_opposite``) the copy's edges are not matched once each, so the
    patches round it are not certified and the pair is found."""
    v, f = _sheet(8, 8, np.random.default_rng(4))
    for reverse, field in ((False, "crossing"), (True, "coplanar_opposite")):
        g = np.r_[f, f[17:18, ::-1] if reverse else f[17:18]]
        fast, _ = _check(v, g)
        assert getattr(fast, field).tolist() == [[17, len(f)]]


def test_degenerate_projection_is_never_certified():
    """A sheet in the plane y = z: along x every face projects with one orientation and the sheet is one patch;
    with a face flattened onto a line (a vertex moved to its neighbours' midpoint: zero area, no strict
    orientation along any axis) no node holding that face can be certified, so pairs are enumerated again, and
    the pairs found are those of the unpatched scan and the numpy twin."""
    v, f = _sheet(6, 6, np.random.default_rng(5))
    v = np.c_[v[:, 0], v[:, 1], v[:, 1]]
    clean, unpatched = _check(v, f)
    assert clean.candidate_pairs == 0 < unpatched.candidate_pairs
    flat = v.copy()
    a, b, c = f[12]
    flat[a] = (flat[b] + flat[c]) / 2
    bent, _ = _check(flat, f, brute=False)
    assert bent.candidate_pairs > 0 and bent.degenerate_faces >= 1


def _real_parts() -> list[Path]:
    files = sorted(p for p in DATA.rglob("*") if p.suffix.lower() in (".stl", ".obj", ".ply", ".gz"))
    return [p for p in files if not p.name.endswith(".tar.gz")]


@pytest.mark.parametrize("path", _real_parts(), ids=lambda p: p.name)
def test_committed_real_parts_same_pairs(path, tmp_path):
    """The real parts committed under ``tests/data`` (Menagerie, trimesh, numpy-stl, robots' meshes): the same
    pairs with and without patches and without stars, and (up to ``TWIN_FACES`` faces) on the numpy twin."""
    import warnings

    from inertia_tool.mesh.read import load_mesh

    if path.suffix == ".gz":
        inner = tmp_path / path.stem
        inner.write_bytes(gzip.decompress(path.read_bytes()))
        path = inner
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = load_mesh(str(path))
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if len(f) <= TWIN_FACES:
        _check(v, f)
        return
    fast = run_scan(v, f, accel=True)
    same_pairs(fast, run_scan(v, f, accel=True, _patches=False))
    same_pairs(fast, run_scan(v, f, accel=True, _star_faces=0))
