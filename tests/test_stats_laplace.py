"""The shared pieces of a Laplace fit, of PSIS-LOO and of the named random streams (friction_uq.stats)."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from scipy import stats

from friction_uq.stats.elpd import psis_loo, weighted_log_mean
from friction_uq.stats.laplace import central_jacobian, draw_normal, fd_hessian, importance_weights, normal_draws
from friction_uq.stats.streams import PURPOSES, legacy_state, stream


def test_fd_hessian_of_a_quadratic_is_its_matrix():
    A = np.array([[4.0, 1.0], [1.0, 0.25]])
    H = fd_hessian(lambda z: 0.5 * z @ A @ z + z.sum(), np.array([0.3, -2.0]))
    np.testing.assert_allclose(H, A, rtol=1e-6)


def test_central_jacobian_of_a_linear_map_is_its_matrix():
    M = np.array([[1.0, 2.0], [0.0, -3.0], [5.0, 0.5]])
    np.testing.assert_allclose(central_jacobian(lambda z: M @ z, np.array([1.0, 2.0]), 1e-3), M, rtol=1e-9)


def test_normal_draws_have_the_covariance_and_the_density_up_to_a_constant():
    cov = np.array([[2.0, 0.6], [0.6, 0.5]])
    mode = np.array([1.0, -1.0])
    z, log_q = draw_normal(mode, cov, np.random.default_rng(4), 20000)
    np.testing.assert_allclose(np.cov(z, rowvar=False), cov, rtol=0.05, atol=0.02)
    exact = stats.multivariate_normal(mode, cov).logpdf(z)
    assert np.ptp(exact - log_q) < 1e-9  # the same density, up to its normalising constant
    z2, _ = normal_draws(mode, np.linalg.cholesky(cov), np.zeros((1, 2)))
    np.testing.assert_array_equal(z2[0], mode)


def test_importance_weights_of_the_proposal_itself_are_equal_and_outside_the_support_zero():
    log_q = -0.5 * np.random.default_rng(1).normal(size=50) ** 2
    same = importance_weights(log_q, log_q)
    np.testing.assert_allclose(np.exp(same.log_weights), 1 / 50)
    cut = importance_weights(np.where(np.arange(50) < 10, -np.inf, log_q), log_q)
    assert np.all(np.exp(cut.log_weights[:10]) == 0.0)
    assert np.exp(cut.log_weights).sum() == pytest.approx(1.0)


def test_psis_loo_of_a_normal_mean_matches_the_exact_leave_one_out_predictive():
    """Data y_i ~ N(mu, 1), prior N(0, 10^2): the posterior without y_i is normal and the left-out
    predictive is N(y_i; m_-i, 1 + v_-i) in closed form; PSIS-LOO over exact posterior draws matches it."""
    rng = np.random.default_rng(7)
    y = rng.normal(0.4, 1.0, 12)
    v = 1.0 / (1.0 / 100.0 + y.size)
    mu = rng.normal(v * y.sum(), math.sqrt(v), 4000)
    ll = stats.norm.logpdf(y[None, :], mu[:, None], 1.0)
    loo = psis_loo(ll, np.zeros(mu.size))
    v_i = 1.0 / (1.0 / 100.0 + y.size - 1)
    m_i = v_i * (y.sum() - y)
    exact = stats.norm.logpdf(y, m_i, np.sqrt(1.0 + v_i))
    np.testing.assert_allclose(loo.pointwise, exact, atol=0.01)
    assert loo.pareto_k_max < 0.5


def test_weighted_log_mean_is_the_log_of_the_weighted_mean_density():
    lw = np.log(np.array([0.5, 0.25, 0.25]))
    assert weighted_log_mean(np.log(np.array([1.0, 2.0, 4.0])), lw) == pytest.approx(math.log(2.0))


def test_streams_are_the_seed_sequences_the_results_were_drawn_from():
    """A stream's key is part of what a seed means: these are the keys every stored result was drawn with."""
    want = np.random.default_rng(np.random.SeedSequence([3, 9, zlib.crc32(b"baseline")])).random(4)
    np.testing.assert_array_equal(stream(3, "extended fit", "baseline").random(4), want)
    want = np.random.default_rng(np.random.SeedSequence([3, 8])).random(4)
    np.testing.assert_array_equal(stream(3, "whole-record check").random(4), want)
    assert len(set(PURPOSES.values())) == len(PURPOSES)
    assert stream(3, "exact posterior", "a").random() != stream(3, "effective prior", "a").random()


def test_legacy_state_is_seeded_by_one_draw_of_the_generator():
    a, b = np.random.default_rng(5), np.random.default_rng(5)
    rs = legacy_state(a)
    assert rs.randint(1 << 30) == np.random.RandomState(int(b.integers(2**31))).randint(1 << 30)
    assert a.random() == b.random()  # one draw taken from each
