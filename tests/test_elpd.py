"""Exact block LOO for AR(1) noise, against the dense Gaussian conditional."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from friction_uq.discrepancy.block_loo import CALIBRATION_FLOOR, Elpd, calibration_loo, elpd_difference, with_calibration
from friction_uq.stats.ar1 import ar1_block_loo
from friction_uq.stats.elpd import psis_loo


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


@pytest.mark.parametrize("mu_d,v_d,c,s", [(1.2, 0.01, 1.0, 0.05), (0.7, 0.002, 1.0, 0.05), (3.1, 0.04, 3.0, 0.1)])
def test_calibration_left_out_is_the_record_alone_predictive(mu_d, v_d, c, s):
    """The record alone says N(mu_d, v_d) of the quantity; with the datum c +- s the posterior is N(m, v). Left
    out, the datum's predictive is N(c | mu_d, v_d + s^2): the closed form must give it from (m, v) alone."""
    v = 1.0 / (1.0 / v_d + 1.0 / s**2)
    m = v * (mu_d / v_d + c / s**2)
    logp, mean, var = calibration_loo(m, v, c, s)
    assert logp == pytest.approx(stats.norm(mu_d, math.sqrt(v_d + s**2)).logpdf(c), rel=1e-9)
    assert mean == pytest.approx(mu_d - c, rel=1e-9) and var == pytest.approx(v_d + s**2, rel=1e-9)


def test_a_record_silent_on_the_quantity_gives_the_floored_equal_density():
    a = calibration_loo(1.0, 0.05**2, 1.0, 0.05)
    b = calibration_loo(1.0, 0.05**2 * 0.999, 1.0, 0.05)
    assert a == b and math.isfinite(a[0])
    assert a[2] == pytest.approx(0.05**2 / CALIBRATION_FLOOR)


def test_calibration_terms_enter_the_difference_with_their_spread():
    blocks = np.array([1.0, 2.0, 3.0, 4.0])
    a = with_calibration(Elpd(blocks, 0.1), {"hoop_gain": calibration_loo(1.0, 0.001, 1.0, 0.05)})
    b = with_calibration(Elpd(np.zeros(4), 0.1), {"hoop_gain": calibration_loo(0.8, 0.001, 1.0, 0.05)})
    d, se = elpd_difference(a, b)
    assert d == pytest.approx(10.0 + a.calibration[0] - b.calibration[0])
    assert a.total == pytest.approx(10.0 + a.calibration[0])
    # the spread of a log-density difference of one datum drawn from a's predictive, by simulation
    z = np.random.default_rng(0).standard_normal(200_000)
    y = 1.0 + a.calibration_mean[0] + math.sqrt(a.calibration_var[0]) * z
    diff = (stats.norm(1.0 + a.calibration_mean[0], math.sqrt(a.calibration_var[0])).logpdf(y)
            - stats.norm(1.0 + b.calibration_mean[0], math.sqrt(b.calibration_var[0])).logpdf(y))
    block_var = 4 * np.var(blocks, ddof=1)
    assert se**2 - block_var == pytest.approx(np.var(diff), rel=0.05)
    # a model without the calibration data (another likelihood) is compared on the blocks alone
    assert elpd_difference(a, Elpd(np.zeros(4), 0.1)) == (10.0, pytest.approx(math.sqrt(block_var)))
