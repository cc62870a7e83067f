"""free_flow_step (one exact free step on floats) against the vectorised closed form torque_free_motion."""

import numpy as np
import pytest

from inertia_tool.dynamics.free_flow import free_flow_step
from inertia_tool.dynamics.torque_free import torque_free_motion
from inertia_tool.rotations import quaternion_to_matrix


@pytest.mark.parametrize("seed", range(6))
def test_matches_torque_free_motion_for_short_and_multi_period_steps(seed):
    rng = np.random.default_rng(seed)
    for trial in range(30):
        moments = np.sort(rng.uniform(0.5, 3.0, 3))
        if trial % 7 == 0:
            moments[1] = moments[0]
        if trial % 11 == 0:
            moments[1] = moments[2]
        w = rng.normal(size=3) * rng.uniform(0.1, 5.0)
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        h = float(rng.choice([1e-3, 0.1, 0.7, 5.0, 40.0]))
        w_ref, q_ref, _ = torque_free_motion(moments, w, np.array([0.0, h]), orientation=q)
        w1, q1 = free_flow_step(tuple(moments), tuple(w), tuple(q), h)
        assert np.max(np.abs(np.array(w1) - w_ref[1])) < 1e-12 * max(1.0, np.linalg.norm(w))
        np.testing.assert_allclose(quaternion_to_matrix(np.array(q1)), quaternion_to_matrix(q_ref[1]), atol=1e-11)
        # a negative step runs the flow back to the start
        w0, q0 = free_flow_step(tuple(moments), w1, q1, -h)
        np.testing.assert_allclose(w0, w, atol=1e-11 * max(1.0, np.linalg.norm(w)))
        np.testing.assert_allclose(quaternion_to_matrix(np.array(q0)), quaternion_to_matrix(q), atol=1e-10)
