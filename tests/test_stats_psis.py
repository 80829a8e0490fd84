"""PSIS, the one implementation: against plain importance sampling on a conjugate normal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from friction_uq.stats import psis, weighted_quantiles


def test_psis_reweights_a_proposal_to_a_conjugate_normal_posterior():
    """Prior N(0, 1), one datum y = 1 with sd 1: posterior N(0.5, 1/2). Draws from a wider proposal
    N(0.3, 1.2^2), reweighted, give the posterior's mean and sd (tolerance: 5 Monte Carlo sd)."""
    rng = np.random.default_rng(1)
    x = rng.normal(0.3, 1.2, 4000)
    log_p = -0.5 * x**2 - 0.5 * (1.0 - x) ** 2
    log_q = -0.5 * ((x - 0.3) / 1.2) ** 2
    res = psis(log_p - log_q)
    assert res.pareto_k < 0.5
    w = np.exp(res.log_weights)
    assert w.sum() == pytest.approx(1.0)
    mean = float(np.sum(w * x))
    sd = math.sqrt(float(np.sum(w * (x - mean) ** 2)))
    mc = math.sqrt(0.5 / res.ess)
    assert mean == pytest.approx(0.5, abs=5 * mc)
    assert sd == pytest.approx(math.sqrt(0.5), rel=0.05)
    q = weighted_quantiles(x, res.log_weights, np.array([0.05, 0.95]))
    np.testing.assert_allclose(q, 0.5 + np.array([-1.0, 1.0]) * 1.6449 * math.sqrt(0.5), atol=0.06)


def test_a_proposal_narrower_than_the_target_has_a_large_k():
    """Wrong sign (the library's weights exp(-ary)) would give the reciprocal weights a small k here."""
    rng = np.random.default_rng(2)
    x = rng.normal(0.0, 0.3, 2000)  # target N(0, 1)
    res = psis(-0.5 * x**2 + 0.5 * (x / 0.3) ** 2)
    assert res.pareto_k > 0.7


def test_equal_and_non_finite_ratios():
    res = psis(np.array([[0.0, 0.0, 0.0, 0.0], [1.0, -np.inf, 1.0, 1.0]]))
    np.testing.assert_allclose(np.exp(res.log_weights[0]), 0.25)
    assert np.exp(res.log_weights[1, 1]) == 0.0 and np.exp(res.log_weights[1]).sum() == pytest.approx(1.0)


def test_a_tail_tied_at_its_smallest_value_is_unreliable_not_nan():
    """A density flat for 94 % of the draws (a parameter that acts in a few only): the tail's Pareto fit fails
    without an error (arviz_stats' k is nan). Its k is inf, which a ``k > threshold`` test and a maximum both see,
    and its weights are the raw ones."""
    from friction_uq.stats.elpd import psis_loo

    rng = np.random.default_rng(0)
    ll = np.zeros((1000, 1))
    ll[:60, 0] = -rng.exponential(3.0, 60)
    res = psis(-ll.T)
    assert res.pareto_k[0] == math.inf
    raw = -ll[:, 0] - np.logaddexp.reduce(-ll[:, 0])
    np.testing.assert_allclose(res.log_weights[0], raw, atol=1e-12)
    loo = psis_loo(ll, np.zeros(1000))
    assert loo.pareto_k_max == math.inf and bool(loo.pareto_k[0] > 0.7)


@pytest.mark.parametrize("n_finite", [1, 2, 3, 4])
def test_a_few_finite_ratios_keep_their_raw_weights_and_an_unreliable_k(n_finite):
    """An alternative prior whose support leaves out all but a few of the draws (nu's posterior at 0.49, a uniform
    prior up to 0.45): arviz_stats' tail of two to four draws was empty, an IndexError ending the run."""
    lr = np.full(400, -np.inf)
    lr[:n_finite] = np.linspace(-1.0, 0.5, n_finite)
    out = psis(lr)
    assert out.pareto_k == math.inf
    assert psis(np.where(np.isfinite(lr), 0.3, -np.inf)).pareto_k == math.inf  # equal, yet too few to trust
    w = np.exp(out.log_weights)
    assert np.isclose(w.sum(), 1.0) and np.all(w[n_finite:] == 0.0)
    assert np.allclose(w[:n_finite], np.exp(lr[:n_finite]) / np.exp(lr[:n_finite]).sum())
