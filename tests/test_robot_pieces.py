"""A part split into one mesh file per material (Menagerie's Stretch: ``link_arm_l1_0.obj`` carbon fibre and
``link_arm_l1_1.obj`` printed plastic): each file is open where it meets the other and was refused; the link's
pieces with one placement and one density are integrated as one surface (``inertia_tool.robot.geometry``).
The truth is the closed form of the solid the pieces bound."""

import numpy as np
import pytest

from inertia_tool.robot import link_inertials, read_robot

# a box 0.2 × 0.1 × 0.05 m; its 12 triangles split into the 4 of the two ends (x = ±a) and the 8 of the sides
SIZE = np.array([0.2, 0.1, 0.05])
CORNERS = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
TRIANGLES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),                     # x = -a, x = +a
             (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def _write_piece(path, triangles):
    with open(path, "w") as fh:
        for c in CORNERS:
            fh.write("v {:.17g} {:.17g} {:.17g}\n".format(*(np.array(c) * SIZE / 2)))
        for t in triangles:
            fh.write("f {} {} {}\n".format(*(i + 1 for i in t)))


def _model(tmp_path, geoms, *, drop_one=False):
    (tmp_path / "assets").mkdir(exist_ok=True)
    _write_piece(tmp_path / "assets" / "ends.obj", TRIANGLES[:4][: 3 if drop_one else 4])
    _write_piece(tmp_path / "assets" / "sides.obj", TRIANGLES[4:])
    path = tmp_path / "robot.xml"
    path.write_text(f"""<mujoco model="pieces">
  <compiler meshdir="assets"/>
  <asset><mesh file="ends.obj"/><mesh file="sides.obj"/></asset>
  <worldbody><body name="link" pos="0 0 1">{geoms}</body></worldbody>
</mujoco>
""")
    return str(path)


PLACED = 'pos="0.1 0.2 0.3" euler="30 0 45"'


def _rotation():
    from scipy.spatial.transform import Rotation
    return Rotation.from_euler("XYZ", [30, 0, 45], degrees=True).as_matrix()     # MJCF: intrinsic x, y, z


@pytest.mark.parametrize("repair", [False, True])
def test_two_open_pieces_of_one_box_are_the_box(tmp_path, repair):
    path = _model(tmp_path, f'<geom type="mesh" mesh="ends" {PLACED}/><geom type="mesh" mesh="sides" {PLACED}/>')
    (result,) = link_inertials(read_robot(path), density=2000.0, repair=repair)
    a, b, c = SIZE
    mass = 2000.0 * a * b * c
    assert result.method == "exact" and result.uncertainty is None
    assert result.properties.mass == pytest.approx(mass, rel=1e-14)
    np.testing.assert_allclose(result.properties.center_of_mass, [0.1, 0.2, 0.3], atol=1e-15)
    box = mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(result.properties.inertia, _rotation() @ box @ _rotation().T, rtol=0, atol=1e-15)
    assert any("close together" in w and "ends.obj, sides.obj" in w for w in result.warnings)


def test_pieces_that_do_not_close_stay_refused_without_repair_and_are_bounded_with_it(tmp_path):
    path = _model(tmp_path, '<geom type="mesh" mesh="ends"/><geom type="mesh" mesh="sides"/>', drop_one=True)
    (refused,) = link_inertials(read_robot(path), density=1000.0)
    assert refused.properties is None and "mesh needs repair" in refused.problem
    (repaired,) = link_inertials(read_robot(path), density=1000.0, repair=True)
    assert repaired.method == "estimate"
    truth = 1000.0 * float(np.prod(SIZE))       # the hole is half an end: the box is one filling of it
    assert abs(repaired.properties.mass - truth) <= repaired.uncertainty.mass * repaired.properties.mass
    assert any("repaired together" in w for w in repaired.warnings)


@pytest.mark.parametrize("geoms", [
    # differently placed pieces do not bound one solid
    '<geom type="mesh" mesh="ends"/><geom type="mesh" mesh="sides" pos="0 0 0.01"/>',
    # with the model's densities, pieces of different materials are not one body
    '<geom type="mesh" mesh="ends" density="900"/><geom type="mesh" mesh="sides" density="7800"/>',
    # a piece with a mass of its own: how the mass splits between the pieces is not known
    '<geom type="mesh" mesh="ends" mass="1"/><geom type="mesh" mesh="sides"/>',
])
def test_pieces_that_are_not_one_body_are_not_joined(tmp_path, geoms):
    (result,) = link_inertials(read_robot(_model(tmp_path, geoms)), density="model")
    assert result.properties is None and "mesh needs repair" in result.problem


def test_one_open_mesh_used_twice_is_not_joined_with_itself(tmp_path):
    path = _model(tmp_path, '<geom type="mesh" mesh="sides"/><geom type="mesh" mesh="sides"/>')
    (result,) = link_inertials(read_robot(path), density=1000.0)
    assert result.properties is None and "mesh needs repair" in result.problem


def test_open_pieces_without_a_common_seam_are_repaired_apart(tmp_path):
    # two boxes 1 m apart, each missing one triangle: two separate holes, no seam in common, so each box is
    # repaired on its own (joined, the two would be one surface repaired together)
    (tmp_path / "assets").mkdir()
    for name, shift in (("a", 0.0), ("b", 1.0)):
        with open(tmp_path / "assets" / f"{name}.obj", "w") as fh:
            for c in CORNERS:
                fh.write("v {:.17g} {:.17g} {:.17g}\n".format(*(np.array(c) * SIZE / 2 + [shift, 0, 0])))
            for t in TRIANGLES[1:]:
                fh.write("f {} {} {}\n".format(*(i + 1 for i in t)))
    path = tmp_path / "robot.xml"
    path.write_text("""<mujoco model="apart"><compiler meshdir="assets"/>
  <asset><mesh file="a.obj"/><mesh file="b.obj"/></asset>
  <worldbody><body name="link"><geom type="mesh" mesh="a"/><geom type="mesh" mesh="b"/></body></worldbody>
</mujoco>""")
    (result,) = link_inertials(read_robot(str(path)), density=1000.0, repair=True)
    assert result.method == "estimate"
    assert not any("together" in w for w in result.warnings)
    truth = 2 * 1000.0 * float(np.prod(SIZE))
    assert abs(result.properties.mass - truth) <= result.uncertainty.mass * result.properties.mass


def _refused_pieces(folder, scale="1 1 1"):
    """A model whose two open pieces share a seam but bound no solid, even repaired (3 of a box's 12 faces)."""
    (folder / "assets").mkdir(parents=True)
    _write_piece(folder / "assets" / "ends.obj", [TRIANGLES[4]])
    _write_piece(folder / "assets" / "sides.obj", [TRIANGLES[5], TRIANGLES[8]])
    path = folder / "robot.xml"
    path.write_text(f"""<mujoco model="pieces">
  <compiler meshdir="assets"/>
  <asset><mesh file="ends.obj" scale="{scale}"/><mesh file="sides.obj" scale="{scale}"/></asset>
  <worldbody><body name="link"><geom type="mesh" mesh="ends"/><geom type="mesh" mesh="sides"/></body></worldbody>
</mujoco>
""")
    return str(path)


def test_a_refused_join_of_copied_files_is_not_joined_again(tmp_path, monkeypatch):
    """Issue 25 (corpus12): Stretch and Stretch 3 ship byte-identical pieces whose join is refused after ~17 s.
    The run's MeshCache keeps the refusal by content and placement: a copy in another folder is refused with the
    same answer without joining again; the same files at another scale are joined again."""
    from inertia_tool.robot import geometry
    from inertia_tool.robot.geometry import MeshCache

    joins = []
    real = geometry.mass_properties

    def counted(raw, *args, **kwargs):
        if " + " in str(getattr(raw, "source", "")):
            joins.append(raw.source)
        return real(raw, *args, **kwargs)

    monkeypatch.setattr(geometry, "mass_properties", counted)
    paths = [_refused_pieces(tmp_path / name) for name in ("a", "b")] + [_refused_pieces(tmp_path / "c", "2 2 2")]
    alone = []
    for path in paths:                                       # each without a shared cache: the reference
        (result,) = link_inertials(read_robot(path), density=1000.0, repair=True)
        alone.append(result)
    assert len(joins) == 6 and all(r.properties is None and r.problem for r in alone)   # 2 attempts each
    joins.clear()
    cache = MeshCache()
    for path, reference in zip(paths, alone):
        (result,) = link_inertials(read_robot(path), density=1000.0, repair=True, mesh_cache=cache)
        assert (result.properties, result.method, result.problem) == (None, reference.method, reference.problem)
        assert result.warnings == reference.warnings
    assert len(joins) == 4                 # folder b's copy not joined again; c (scaled) joined again
    assert all("/b/" not in source for source in joins)


def test_a_join_of_copied_files_that_closes_is_taken_from_the_first_copy_placed_as_its_own(tmp_path, monkeypatch):
    """Issue 25 (corpus19): Stretch and Stretch 3 join byte-identical pieces that close (``link_arm_l0``,
    ``link_head_tilt``); the run's MeshCache keeps the join by content: a copy in another folder, placed
    elsewhere, gets the body placed as its own geoms place it, and its warnings and mesh report name its own
    files, exactly as when it is joined alone; the same files at another scale are joined again."""
    from inertia_tool.robot import geometry
    from inertia_tool.robot.geometry import MeshCache

    joins = []
    real = geometry.mass_properties

    def counted(raw, *args, **kwargs):
        if " + " in str(getattr(raw, "source", "")):
            joins.append(raw.source)
        return real(raw, *args, **kwargs)

    monkeypatch.setattr(geometry, "mass_properties", counted)
    placements = {"a": PLACED, "b": 'pos="-0.3 0.05 0.7" euler="10 -20 95"', "c": PLACED}
    paths = []
    for name, placed in placements.items():
        (tmp_path / name).mkdir()
        scale = ' scale="2 2 2"' if name == "c" else ""
        path = _model(tmp_path / name, f'<geom type="mesh" mesh="ends" {placed}/>'
                                       f'<geom type="mesh" mesh="sides" {placed}/>')
        if scale:
            text = open(path).read().replace('file="ends.obj"/>', f'file="ends.obj"{scale}/>')
            open(path, "w").write(text.replace('file="sides.obj"/>', f'file="sides.obj"{scale}/>'))
        paths.append(path)
    alone = []
    for path in paths:                                       # each without a shared cache: the reference
        (result,) = link_inertials(read_robot(path), density=1000.0, repair=True)
        alone.append(result)
    assert len(joins) == 3 and all(r.method == "exact" for r in alone)
    joins.clear()
    cache = MeshCache()
    for path, reference in zip(paths, alone):
        (result,) = link_inertials(read_robot(path), density=1000.0, repair=True, mesh_cache=cache)
        assert result.properties.mass == reference.properties.mass
        np.testing.assert_array_equal(result.properties.center_of_mass, reference.properties.center_of_mass)
        np.testing.assert_array_equal(result.properties.inertia, reference.properties.inertia)
        assert (result.method, result.uncertainty, result.warnings) == \
            (reference.method, reference.uncertainty, reference.warnings)
    assert len(joins) == 2                 # folder b's copy not joined again; c (scaled) joined again
    assert all("/b/" not in source for source in joins)
    assert alone[1].properties.mass == alone[0].properties.mass
    assert not np.allclose(alone[1].properties.center_of_mass, alone[0].properties.center_of_mass)
