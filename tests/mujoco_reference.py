"""MuJoCo's own compiled body inertias, the reference the MJCF tests compare the reader with."""

import numpy as np
import pytest

from conftest import assert_tensor_close


def mujoco_bodies(path):
    """name → (mass, centre, tensor in body axes) of every body but the world, from MuJoCo's compiler (an
    unnamed body is ``body N``, as the reader names it)."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    out = {}
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out[model.body(i).name or f"body {i}"] = (model.body_mass[i], model.body_ipos[i].copy(),
                                                  rot @ np.diag(model.body_inertia[i]) @ rot.T)
    return out


def assert_like_mujoco(path, results, *, rtol=1e-9):
    """Every body of ``results`` (``link_inertials``) has MuJoCo's mass, centre and tensor within ``rtol``."""
    reference = mujoco_bodies(path)
    ours = {r.name: r for r in results}
    assert set(ours) == set(reference)
    for name, (mass, com, tensor) in reference.items():
        props = ours[name].properties
        assert props is not None, (name, ours[name].problem)
        assert props.mass == pytest.approx(mass, rel=rtol), name
        scale = max(np.linalg.norm(com), np.sqrt(np.trace(tensor) / mass))
        np.testing.assert_allclose(props.center_of_mass, com, atol=rtol * scale, err_msg=name)
        assert_tensor_close(props.inertia, tensor, rtol)
