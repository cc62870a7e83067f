"""OBJ polygons: quads split and polygons of more than four corners ear-clipped as MuJoCo's OBJ loader does
(``inertia_tool.mesh.read``), checked against closed forms, trimesh's first-corner fan and MuJoCo itself."""

import itertools
import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.errors import NonPlanarPolygonWarning
from inertia_tool.mesh.polygons import clip_polygon_as_mujoco
from inertia_tool.mesh.read import load_mesh

_NAMES = itertools.count()


def _write_obj(path, vertices, polygons):
    with open(path, "w") as fh:
        for p in vertices:
            fh.write(f"v {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
        for q in polygons:
            fh.write("f " + " ".join(str(i + 1) for i in q) + "\n")


def _prism(radii, heights, offset=(0.0, 0.0, 0.0)):
    """A prism over a star-shaped polygon of ``len(radii)`` corners (even angles): a planar bottom at z = 0
    and a top whose corners are raised to ``1 + heights``; sides as triangles.  Vertices are the 9-digit
    decimals :func:`_write_obj` writes, so that the file holds exactly these numbers."""
    n = len(radii)
    angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = np.column_stack([radii * np.cos(angle), radii * np.sin(angle)])
    top = np.column_stack([ring, 1.0 + np.asarray(heights)])
    bottom = np.column_stack([ring, np.zeros(n)])
    vertices = np.vectorize(lambda x: float(f"{x:.9g}"))(np.vstack([top, bottom]) + offset)
    sides = []
    for i in range(n):
        j = (i + 1) % n
        sides += [(i, n + i, n + j), (i, n + j, j)]
    return vertices, [list(range(n)), [n + i for i in reversed(range(n))]] + sides


def _six_volume(vertices, triangles):
    p = vertices[np.asarray(triangles)]
    return float(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum())


def test_a_tie_of_the_quad_diagonals_takes_bd_as_mujoco_does(tmp_path):
    # a saddle quad a=(1,0,h) b=(0,1,-h) c=(-1,0,h) d=(0,-1,-h) over an apex at z=-5: |ac| = |bd| = 2.  MuJoCo
    # keeps ac only when it is strictly shorter, so it takes abd, bcd: volume 47/15 = 3.1333 (abc, acd:
    # 53/15 = 3.5333; the two differ by the tetrahedron abcd, 2·2·2h/6 = 0.4).  The reader kept ac on a tie.
    h = 0.3
    vertices = np.array([(1, 0, h), (0, 1, -h), (-1, 0, h), (0, -1, -h), (0, 0, -5)], dtype=float)
    sides = [(4, 1, 0), (4, 2, 1), (4, 3, 2), (4, 0, 3)]
    path = tmp_path / "saddle.obj"
    _write_obj(path, vertices, [[0, 1, 2, 3]] + sides)
    with pytest.warns(NonPlanarPolygonWarning):
        raw = load_mesh(str(path), units="m")
    bd_split = _six_volume(vertices, [(0, 1, 3), (1, 2, 3)] + sides) / 6
    ac_split = _six_volume(vertices, [(0, 1, 2), (0, 2, 3)] + sides) / 6
    assert bd_split == pytest.approx(47 / 15, rel=1e-14) and ac_split == pytest.approx(53 / 15, rel=1e-14)
    assert mass_properties(raw, density=1.0).volume == pytest.approx(bd_split, rel=1e-14)


def test_a_convex_polygon_is_fanned_from_its_first_corner():
    # on a convex polygon MuJoCo's clipping takes corners 0, 1, 2, removes 1, and so on: the first-corner fan
    corners = np.array([(np.cos(t), np.sin(t), 0.1 * np.sin(3 * t)) for t in np.linspace(0, 2 * np.pi, 7)[:-1]])
    triangles, dropped = clip_polygon_as_mujoco(corners + (5.0, 5.0, 0.0))
    assert triangles == [(0, j, j + 1) for j in range(1, 5)] and dropped == 0


@pytest.mark.parametrize("n", [5, 6, 9])
def test_planar_polygons_give_the_prism_volume_without_a_warning(tmp_path, n):
    # a planar star (concave): any triangulation of a planar polygon bounds the same solid, area × height
    radii = np.where(np.arange(n) % 2 == 0, 1.0, 0.5)
    vertices, polygons = _prism(radii, np.zeros(n))
    path = tmp_path / "star.obj"
    _write_obj(path, vertices, polygons)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        raw = load_mesh(str(path), units="m")
    ring = vertices[:n, :2]
    area = 0.5 * abs(float(np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1])))
    assert len(raw.faces) == 2 * (n - 2) + 2 * n
    assert mass_properties(raw, density=1.0).volume == pytest.approx(area * 1.0, rel=1e-12)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(n=st.integers(5, 10), heights=st.lists(st.floats(-0.4, 0.4), min_size=10, max_size=10),
       star=st.booleans(), inner=st.floats(0.3, 0.8))
def test_the_warning_bounds_what_the_first_corner_fan_changes(tmp_path, n, heights, star, inner):
    """trimesh fans every polygon from its first corner: the stated fraction (rounded up) bounds the change."""
    import trimesh
    radii = np.where((np.arange(n) % 2 == 1) & star, inner, 1.0)
    vertices, polygons = _prism(radii, heights[:n])
    path = tmp_path / f"p{next(_NAMES)}.obj"
    _write_obj(path, vertices, polygons)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        raw = load_mesh(str(path), units="m")
    ours = abs(_six_volume(raw.vertices, raw.faces)) / 6
    fan = abs(trimesh.load(str(path), process=False).volume)
    said = [str(w.message) for w in caught if issubclass(w.category, NonPlanarPolygonWarning)]
    if abs(fan - ours) > 1e-9 * ours:
        assert len(said) == 1, said
        stated = float(re.search(r"by up to ([0-9.e+-]+) %", said[0]).group(1)) / 100
        assert abs(fan - ours) / ours <= stated
    assert len(raw.faces) == 2 * (n - 2) + 2 * n            # nothing dropped: the surface stays closed


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(n=st.integers(5, 11), heights=st.lists(st.floats(-0.3, 0.3), min_size=11, max_size=11),
       star=st.booleans(), inner=st.floats(0.3, 0.8),
       offset=st.tuples(*[st.sampled_from([0.0, -2.5, 1.75, 3.0])] * 3))
def test_non_planar_polygons_give_mujocos_solid(tmp_path, n, heights, star, inner, offset):
    """Where MuJoCo's loader keeps every triangle, its exact mesh volume is the reader's (float32 vertices)."""
    mujoco = pytest.importorskip("mujoco")
    radii = np.where((np.arange(n) % 2 == 1) & star, inner, 1.0)
    vertices, polygons = _prism(radii, heights[:n], offset)
    path = tmp_path / f"m{next(_NAMES)}.obj"               # MuJoCo caches meshes by file name within a process
    _write_obj(path, vertices, polygons)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        raw = load_mesh(str(path), units="m")
    xml = (f'<mujoco><compiler inertiafromgeom="true"/><asset><mesh name="m" file="{path}" inertia="exact"/>'
           '</asset><worldbody><body><freejoint/><geom type="mesh" mesh="m" density="1"/></body></worldbody>'
           '</mujoco>')
    try:
        model = mujoco.MjModel.from_xml_string(xml)
    except ValueError:                                      # MuJoCo's dropped triangles left it no volume
        return
    _, dropped_top = clip_polygon_as_mujoco(vertices[:n])
    _, dropped_bottom = clip_polygon_as_mujoco(vertices[n:][::-1])
    assert int(model.mesh_facenum[0]) == len(raw.faces) - dropped_top - dropped_bottom   # drops predicted too
    if dropped_top or dropped_bottom:                       # MuJoCo's mesh is open there: no solid to compare
        return
    assert model.body_mass[1] == pytest.approx(abs(_six_volume(raw.vertices, raw.faces)) / 6, rel=2e-6)
