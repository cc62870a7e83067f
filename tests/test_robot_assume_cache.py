"""The user's assumption ``flat-islands`` is part of what a robot's cached mesh bodies are keyed by: a body prepared
under ``--assume flat-islands`` is never handed to an audit without it (or the other way round) through the run's
shared :class:`~inertia_tool.robot.geometry.MeshCache` or the process's memo of fitted bodies.  Island14 keyed them
by ``repair`` alone (documented, not enforced): the second audit of a run could get the first's narrow bound with
the first's assumption named nowhere in its call."""

from __future__ import annotations

import struct

import numpy as np

from inertia_tool.robot import link_inertials, read_robot
from inertia_tool.robot.geometry import MeshCache

from test_hole_flat_islands import grid_plate


def _binary_stl(path, v: np.ndarray, f: np.ndarray) -> None:
    tri = v[f]
    with open(path, "wb") as out:
        out.write(b"\0" * 80 + struct.pack("<I", len(f)))
        for t in tri:
            out.write(struct.pack("<12fH", 0, 0, 0, *t.ravel(), 0))


def _robot(tmp_path):
    v, f = grid_plate(6, 1.0, {(2, 2), (2, 3), (3, 2)})      # an L-shaped island in the top face of a grid plate
    _binary_stl(tmp_path / "plate.stl", v, f)      # integer corners: exact in float32
    (tmp_path / "r.urdf").write_text(
        '<robot name="r"><link name="plate"><visual><geometry><mesh filename="plate.stl"/></geometry></visual>'
        '<collision><geometry><mesh filename="plate.stl"/></geometry></collision>'
        '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
        '</link></robot>')
    return read_robot(str(tmp_path / "r.urdf"))


def _plate(results):
    (link,) = [r for r in results if r.name == "plate"]
    return link


def test_a_shared_cache_keeps_bodies_prepared_under_an_assumption_apart(tmp_path):
    robot = _robot(tmp_path)
    shared = MeshCache()
    assumed = _plate(link_inertials(robot, density=1000.0, repair=True, mesh_cache=shared,
                                    assume=("flat-islands",)))
    plain = _plate(link_inertials(robot, density=1000.0, repair=True, mesh_cache=shared))
    again = _plate(link_inertials(robot, density=1000.0, repair=True, mesh_cache=shared,
                                  assume=("flat-islands",)))
    # with the assumption the island is filled flat: the plate's whole volume, 6 x 6 x 1 m
    assert assumed.properties is not None and assumed.method == "estimate"
    assert abs(assumed.properties.volume - 36.0) <= 1e-9
    assert any("flat-islands" in w for w in assumed.warnings)
    assert assumed.uncertainty is not None and assumed.uncertainty.mass < 1e-9
    # without it, the same file through the same cache keeps the whole ball over the island's rim (never the
    # assumed body with its narrow bound, nor its note)
    assert plain.properties is not None and plain.uncertainty is not None
    assert plain.uncertainty.mass > 1e-3
    assert not any("as the user assumed" in w for w in plain.warnings)
    # and the assumed body is still there for a call that states it
    assert again.properties is not None and again.properties.volume == assumed.properties.volume
