"""MJCF ``<mesh inertia="convex|exact|legacy|shell">`` taken as MuJoCo takes it with the model's own densities
(``inertia_tool.robot.mesh_inertia``): closed forms for an L-shaped block, and MuJoCo's compiled bodies."""

import numpy as np
import pytest

from inertia_tool.errors import RobotDescriptionError
from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.mesh_inertia import convex_hull_properties, legacy_properties

# an L-shaped prism (10 m³): a 3 × 3 square less the 2 × 2 square at its corner (3, 3), 2 m deep along z (the
# centre of its surface lies in the notch, so tetrahedra from it overlap); 6 outline corners at z = 0 and z = 2
OUTLINE = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]


def _l_block():
    vertices = np.array([(x, y, z) for z in (0.0, 2.0) for x, y in OUTLINE], dtype=float)
    bottom = [(0, 2, 1), (0, 3, 2), (0, 5, 3), (3, 5, 4)]          # wound downwards (outward at z = 0)
    top = [(6 + a, 6 + c, 6 + b) for a, b, c in bottom]
    sides = []
    for i in range(6):
        j = (i + 1) % 6
        sides += [(i, j, 6 + j), (i, 6 + j, 6 + i)]
    return vertices, np.array(bottom + top + sides)


def _write_obj(path, vertices, faces):
    with open(path, "w") as fh:
        fh.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in vertices)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)


def test_the_convex_hull_of_the_l_block_is_the_2_by_2_prism_less_a_corner_prism():
    vertices, _ = _l_block()
    hull = convex_hull_properties(vertices, source="L")
    # hull outline (0,0) (3,0) (3,1) (1,3) (0,3): the 3 × 3 square less the triangle (3,1) (3,3) (1,3), area 7
    assert hull.volume == pytest.approx(14.0, rel=1e-14)
    # centroid of the outline: (9·(3/2, 3/2) − 2·(7/3, 7/3)) / 7
    centre = (9 * 1.5 - 2 * 7 / 3) / 7
    np.testing.assert_allclose(hull.center_of_mass, [centre, centre, 1.0], rtol=1e-14)


def test_legacy_volume_of_a_convex_box_is_its_volume_and_more_for_the_l_block():
    box = np.array([(x, y, z) for x in (0, 3) for y in (0, 2) for z in (0, 1)], dtype=float)
    faces = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                      (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])
    legacy = legacy_properties(box, faces, source="box")
    assert legacy.volume == pytest.approx(6.0, rel=1e-14)            # convex: every tetrahedron positive
    np.testing.assert_allclose(legacy.center_of_mass, [1.5, 1.0, 0.5], rtol=1e-14)
    np.testing.assert_allclose(np.diag(legacy.inertia), 6.0 / 12 * np.array([4 + 1, 9 + 1, 9 + 4]), rtol=1e-13)
    vertices, faces = _l_block()
    assert legacy_properties(vertices, faces, source="L").volume > 10.0 * (1 + 1e-3)   # non-convex: overcounts


@pytest.mark.parametrize("mode", ["convex", "exact", "legacy", "shell"])
def test_each_mode_gives_mujocos_body(tmp_path, mode):
    pytest.importorskip("mujoco")
    from mujoco_reference import assert_like_mujoco
    vertices, faces = _l_block()
    _write_obj(tmp_path / "l.obj", vertices, faces)
    path = tmp_path / "robot.xml"
    path.write_text(f"""<mujoco model="modes">
  <compiler inertiafromgeom="true"/>
  <asset><mesh name="l" file="l.obj" inertia="{mode}" scale="0.1 0.2 0.05"/></asset>
  <worldbody>
    <body name="link"><geom type="mesh" mesh="l" density="2700" pos="0.1 0 0" euler="10 20 30"/></body>
  </worldbody>
</mujoco>
""")
    results = link_inertials(read_robot(str(path)), density="model")
    assert_like_mujoco(path, results, rtol=1e-6)                     # MuJoCo keeps vertices in float32
    assert results[0].method == {"legacy": "unverified"}.get(mode, "exact")
    if mode in ("convex", "legacy"):
        assert any(f'inertia="{mode}"' in w for w in results[0].warnings)


def test_a_mode_is_used_only_with_the_models_densities(tmp_path):
    vertices, faces = _l_block()
    _write_obj(tmp_path / "l.obj", vertices, faces)
    path = tmp_path / "robot.xml"
    path.write_text("""<mujoco><asset><mesh name="l" file="l.obj" inertia="legacy"/></asset>
  <worldbody><body name="link"><geom type="mesh" mesh="l"/></body></worldbody></mujoco>""")
    (solid,) = link_inertials(read_robot(str(path)), density=1000.0)
    assert solid.method == "exact" and solid.properties.mass == pytest.approx(10000.0, rel=1e-14)


def test_an_unknown_mode_is_refused(tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text("""<mujoco><asset><mesh name="l" file="l.obj" inertia="solid"/></asset>
  <worldbody><body name="link"><geom type="mesh" mesh="l"/></body></worldbody></mujoco>""")
    with pytest.raises(RobotDescriptionError, match="inertia must be one of convex, exact, legacy, shell"):
        read_robot(str(path))
