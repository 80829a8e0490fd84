"""Exact block LOO for AR(1) noise, against the dense Gaussian conditional."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from friction_uq.discrepancy.elpd import Elpd, ar1_block_loo, elpd_difference, psis_loo


@pytest.mark.parametrize("n,block", [(23, 5), (20, 5), (7, 7), (9, 4)])
def test_block_conditionals_match_the_dense_gaussian(n, block):
    rng = np.random.default_rng(n)
    sd, rho = 1.7, 0.55
    e = rng.normal(size=(3, n))
    i = np.arange(n)
    C = sd**2 * rho ** np.abs(i[:, None] - i[None, :])
    got = ar1_block_loo(e, sd=sd, rho=rho, block=block)
    for k, a in enumerate(range(0, n, block)):
        b = np.arange(a, min(a + block, n))
        o = np.setdiff1d(i, b)
        for s in range(3):
            if len(o):
                K = C[np.ix_(b, o)] @ np.linalg.inv(C[np.ix_(o, o)])
                mu = K @ e[s, o]
                cov = C[np.ix_(b, b)] - K @ C[np.ix_(o, b)]
            else:
                mu, cov = np.zeros(len(b)), C[np.ix_(b, b)]
            ref = stats.multivariate_normal(mu, cov).logpdf(e[s, b])
            assert got[s, k] == pytest.approx(ref, rel=1e-9, abs=1e-9)


def test_psis_loo_of_identical_draws_is_the_plug_in_density():
    ll = np.tile(np.array([-1.0, -2.0, -0.5]), (50, 1))
    res = psis_loo(ll, np.zeros(50))
    np.testing.assert_allclose(res.pointwise, [-1.0, -2.0, -0.5], atol=1e-12)


def test_difference_and_its_standard_error():
    a = Elpd(np.array([1.0, 2.0, 3.0, 4.0]), 0.1)
    b = Elpd(np.array([0.0, 0.0, 0.0, 0.0]), 0.1)
    d, se = elpd_difference(a, b)
    assert d == 10.0
    assert se == pytest.approx(math.sqrt(4) * np.std([1, 2, 3, 4], ddof=1))
