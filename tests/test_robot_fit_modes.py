"""robot: a primitive fitted to a mesh follows the mesh's MJCF ``inertia`` mode, as MuJoCo's compiler fits it
(issue 23, item 4); checked against MuJoCo 4.0's body mass, centre and inertia on a non-convex mesh."""

import numpy as np
import pytest

from inertia_tool.robot import link_inertials, read_robot

mujoco = pytest.importorskip("mujoco")


def _l_shape(path):
    """A closed L-shaped prism (an L of arms 0.10 and 0.08 m, 0.03 m wide, 0.02 m thick): not convex, so the three
    modes differ."""
    ring = [(0.0, 0.0), (0.10, 0.0), (0.10, 0.03), (0.03, 0.03), (0.03, 0.08), (0.0, 0.08)]
    v = [(x, y, 0.0) for x, y in ring] + [(x, y, 0.02) for x, y in ring]
    cap = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]
    f = [(a, c, b) for a, b, c in cap] + [(a + 6, b + 6, c + 6) for a, b, c in cap]
    for i in range(6):
        j = (i + 1) % 6
        f += [(i, j, j + 6), (i, j + 6, i + 6)]
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("kind", ["capsule", "box", "cylinder", "ellipsoid"])
@pytest.mark.parametrize("mode", ["convex", "legacy", "exact"])
def test_fitted_primitive_matches_mujoco_for_every_inertia_mode(tmp_path, kind, mode):
    _l_shape(tmp_path / "l.obj")
    xml = tmp_path / "robot.xml"
    xml.write_text(f'<mujoco><compiler inertiafromgeom="true"/><asset><mesh name="m" file="l.obj" '
                   f'inertia="{mode}"/></asset><worldbody><body name="link"><geom type="{kind}" mesh="m" '
                   'density="1000"/></body></worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_path(str(xml))
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[1])
    rot = rot.reshape(3, 3)
    tensor = rot @ np.diag(model.body_inertia[1]) @ rot.T
    (link,) = link_inertials(read_robot(str(xml)), density="model")
    props = link.properties
    assert props.mass == pytest.approx(float(model.body_mass[1]), rel=1e-5)
    assert np.allclose(props.center_of_mass, model.body_ipos[1], atol=1e-7)
    assert np.linalg.norm(props.inertia - tensor) <= 1e-4 * np.linalg.norm(tensor)
