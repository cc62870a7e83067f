"""Jacobi functions and Legendre integrals near m -> 1, against mpmath (high precision) and scipy."""

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipj

from inertia_tool.dynamics.elliptic import (complete_k, elliptic_f_from_sn_cn, elliptic_pi_of_argument,
                                            jacobi_sn_cn_dn)


@pytest.mark.parametrize("m", [0.0, 0.05, 0.5, 0.9, 0.999])
def test_jacobi_matches_scipy_ellipj(m):
    u = np.linspace(-40, 40, 801)
    ref = ellipj(u, m)[:3]
    for mine, theirs in zip(jacobi_sn_cn_dn(u, m, 1 - m), ref):
        np.testing.assert_allclose(mine, theirs, atol=1e-13)


@pytest.mark.parametrize("m1", [1e-3, 1e-8, 1e-12, 1e-15])
def test_jacobi_near_m_one_against_mpmath(m1):
    mp.mp.dps = 50
    m_exact = 1 - mp.mpf(m1)
    kk = complete_k(m1)
    assert abs(kk - float(mp.ellipk(m_exact))) < 1e-14 * kk
    for u in [0.25, 0.9 * kk, kk, 1.7 * kk, -2.6 * kk, 7.3 * kk]:
        sn, cn, dn = jacobi_sn_cn_dn(np.array([u]), 1 - m1, m1)
        for mine, name in zip((sn, cn, dn), ("sn", "cn", "dn")):
            assert abs(mine[0] - float(mp.ellipfun(name, u, m=m_exact))) < 5e-15 * max(1.0, abs(u))


def test_separatrix_limit_is_sech_tanh():
    u = np.linspace(-10, 10, 21)
    sn, cn, dn = jacobi_sn_cn_dn(u, 1.0, 0.0)
    np.testing.assert_allclose(sn, np.tanh(u), atol=1e-16)
    np.testing.assert_allclose(cn, 1 / np.cosh(u), atol=1e-16)
    np.testing.assert_allclose(dn, 1 / np.cosh(u), atol=1e-16)


@pytest.mark.parametrize("m1", [0.6, 1e-9, 0.0])
def test_elliptic_f_inverts_jacobi(m1):
    m = 1 - m1
    for u in [-3.5, -1.0, 0.0, 0.4, 2.2, 3.9]:
        if m1 == 0.0 and abs(u) > 3:
            continue
        sn, cn, _ = jacobi_sn_cn_dn(np.array([u]), m, m1)
        kk = np.inf if m1 == 0 else complete_k(m1)
        expected = u if abs(u) <= 2 * kk else u - 4 * kk * np.round(u / (4 * kk))
        assert elliptic_f_from_sn_cn(sn[0], cn[0], m, m1) == pytest.approx(expected, abs=1e-13)


@pytest.mark.parametrize("n,m1", [(-0.8, 0.4), (-6.0, 1e-6), (-0.3, 0.999), (-2.0, 0.0)])
def test_pi_of_argument_against_quadrature(n, m1):
    m = 1 - m1
    integrand = lambda v: 1.0 / (1.0 - n * jacobi_sn_cn_dn(np.array([v]), m, m1)[0][0] ** 2)
    for u in [0.3, 2.5, 11.0, -7.0]:
        ref, _ = quad(integrand, 0.0, u, limit=400, epsabs=1e-13, epsrel=1e-13)
        assert elliptic_pi_of_argument(np.array([u]), n, m, m1)[0] == pytest.approx(ref, rel=1e-12, abs=1e-13)
