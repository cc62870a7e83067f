"""Polhode on the inertia ellipsoid and herpolhode on the invariant plane (§4.4.1, Poinsot construction)."""

import numpy as np

import inertia_tool as it
from inertia_tool.dynamics import invariant_plane


def test_polhode_is_closed_and_on_the_ellipsoid_and_L_sphere():
    tensor = np.diag([1.0, 2.0, 3.0])
    w0 = np.array([0.1, 1.0, 0.05])
    t, w = it.dynamics.polhode(tensor, w0, samples=201)
    two_t = w0 @ tensor @ w0
    np.testing.assert_allclose(np.einsum("ni,ij,nj->n", w, tensor, w), two_t, rtol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(w @ tensor, axis=1), np.linalg.norm(tensor @ w0), rtol=1e-13)
    np.testing.assert_allclose(w[-1], w[0], atol=1e-12)  # one full period
    assert np.min(np.abs(w[:, 1] - w0[1])) < 1e-12 and np.min(w[:, 1]) < -0.9  # goes round axis 1


def test_herpolhode_on_invariant_plane_and_rate_for_symmetric_body():
    moments = [1.0, 1.0, 2.5]
    w0 = np.array([0.4, 0.0, 1.0])
    t = np.linspace(0, 10, 201)
    points, xy = it.dynamics.herpolhode(moments, w0, t)
    normal, distance = invariant_plane(moments, w0)
    np.testing.assert_allclose(points @ normal, distance, rtol=1e-13)
    radius = np.hypot(xy[:, 0], xy[:, 1])
    np.testing.assert_allclose(radius, radius[0], rtol=1e-12)  # a circle for a symmetric body
    omega = w0[2] * (moments[2] - moments[0]) / moments[0]
    phi_b = np.arctan(0.4 / 1.0)
    mom = np.linalg.norm(np.asarray(moments) * w0)
    phi_l = np.arccos((w0 @ (np.asarray(moments) * w0)) / (np.linalg.norm(w0) * mom))  # Eq. 4.28
    rate = np.gradient(np.unwrap(np.arctan2(xy[:, 1], xy[:, 0])), t)
    np.testing.assert_allclose(rate[1:-1], omega * np.sin(phi_b) / np.sin(phi_l), rtol=1e-4)
