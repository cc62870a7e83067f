"""Issue 23 (robots17): an estimate's bounds under ``--density model`` are the same relative bounds as under
``--density RHO``.

robots16 listed arx_l5 ``base_link``/``link6`` and G1's ankle and elbow bodies among "estimates outside their
bounds against MuJoCo".  Their meshes are welded (vertices up to ~3e-7 m apart merged, an ``estimate``); under the
description's own densities (``density="model"``, the bench's mode) the link's mass and centre bounds were
computed from the unit-density parts without the geom's density: 1000× too tight at MuJoCo's default 1000 kg/m³
(G1 ``left_ankle_pitch_link``: ±3.2e-10 stated where the mesh's bound is ±3.2e-7; MuJoCo's value lies 3.1e-9
away).  The geom density (or ``mass`` over the unit mass) now scales each part's bound.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from inertia_tool.robot import read_robot
from inertia_tool.robot.geometry import link_inertials

from conftest import box_arrays

EDGES = (0.1, 0.2, 0.3)


def _welded_box(path, corner_shift: float) -> None:
    """A 0.1 × 0.2 × 0.3 m box as a binary STL whose first triangle's first corner is moved by ``corner_shift``
    m along x (the reader welds it back: an estimate with bounds)."""
    vertices, faces = box_arrays(EDGES)
    triangles = vertices[faces].astype(np.float32)
    triangles[0, 0, 0] += np.float32(corner_shift)
    records = np.zeros(len(triangles), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    records["v"] = triangles
    with open(path, "wb") as fh:
        fh.write(b" " * 80 + np.uint32(len(triangles)).tobytes() + records.tobytes())


@pytest.mark.filterwarnings("ignore")
@settings(max_examples=15, deadline=None)
@given(density=st.floats(1.0, 50000.0), shift=st.floats(2e-9, 8e-8), second=st.booleans(),
       geom_mass=st.floats(0.01, 100.0))
def test_model_density_bounds_equal_the_uniform_densitys(tmp_path_factory, density, shift, second, geom_mass):
    """The same welded box at geom density ρ (``density="model"``) and at ``density=ρ``: the same relative mass
    bound and centre bound; with a second, exact geom of given ``mass`` beside it, the bound (absolute) is the
    box's alone; and the box's exact mass and centre (the unmoved box) lie within them."""
    folder = tmp_path_factory.mktemp("m")
    _welded_box(folder / "b.stl", shift)
    other = f'<geom type="sphere" size="0.05" pos="0.5 0 0" mass="{geom_mass!r}"/>' if second else ""
    (folder / "m.xml").write_text(f'<mujoco><asset><mesh file="b.stl"/></asset><worldbody><body name="b">'
                                  f'<geom type="mesh" mesh="b" density="{density!r}"/>{other}</body></worldbody>'
                                  '</mujoco>')
    robot = read_robot(str(folder / "m.xml"))
    (model,) = link_inertials(robot, density="model")
    (uniform,) = link_inertials(robot, density=density)
    assert model.method == uniform.method == "estimate"
    box_mass = density * float(np.prod(EDGES))
    if not second:
        assert model.uncertainty.mass == pytest.approx(uniform.uncertainty.mass, rel=1e-9)
        assert model.uncertainty.center_of_mass == pytest.approx(uniform.uncertainty.center_of_mass, rel=1e-6)
    else:
        # the box's absolute bound is the same; the link's relative one is it over the link's mass
        absolute = model.uncertainty.mass * model.properties.mass
        assert absolute == pytest.approx(uniform.uncertainty.mass * uniform.properties.mass, rel=1e-9)
    exact_mass = box_mass + (geom_mass if second else 0.0)
    centre = np.array([0.5 * geom_mass / exact_mass, 0.0, 0.0]) if second else np.zeros(3)
    bound = model.uncertainty
    assert abs(model.properties.mass - exact_mass) <= bound.mass * model.properties.mass
    assert np.linalg.norm(model.properties.center_of_mass - centre) <= bound.center_of_mass
