"""Hierarchical pooling from stored draws: the closed form for normal posteriors, the implied prior of
kappa against Monte Carlo, and the refusal when too few draws carry weight."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from friction_uq.campaigns.pooling import StoredDraws, implied_kappa_log_prior, pool
from friction_uq.prior_loader import PRIORS_DIR, load_priors


def _normal_tests(rng, means, sd, n):
    return [StoredDraws(f"T{i}", "A", rng.normal(m, sd, n), np.zeros(n)) for i, m in enumerate(means)]


def test_pooling_normal_posteriors_matches_the_closed_form():
    """Flat sampling prior and normal posteriors: L(mu, sigma) = prod_i N(m_i; mu, sqrt(sigma^2 + s^2))."""
    rng = np.random.default_rng(11)
    means = rng.normal(0.05, 0.006, 10)
    s = 0.002
    # draws made exactly normal (quantiles), so the Monte Carlo error does not blur the comparison
    z = stats.norm.ppf((np.arange(1000) + 0.5) / 1000)
    tests = [StoredDraws(f"T{i}", "A", m + s * z, np.zeros(z.size)) for i, m in enumerate(means)]
    p = pool(tests, "f")
    assert p.refused is None
    mu, sg = np.meshgrid(p.grid_mu, p.grid_sigma)
    exact = sum(stats.norm.logpdf(m, mu, np.sqrt(sg**2 + s**2)) for m in means)
    exact -= np.log(np.exp(exact - exact.max()).sum()) + exact.max()
    post_mu = np.exp(exact).sum(axis=0)
    assert p.mu["mean"] == pytest.approx(np.sum(post_mu * p.grid_mu), abs=2e-5)
    post_s = np.exp(exact).sum(axis=1)
    assert p.sigma["mean"] == pytest.approx(np.sum(post_s * p.grid_sigma), rel=0.02)
    assert p.mu["q05"] < 0.05 < p.mu["q95"] and p.sigma["q05"] < 0.006 < p.sigma["q95"]
    assert p.mc_variance < 0.01 and min(p.ess.values()) > 300


def test_too_few_draws_carrying_weight_is_refused_not_reported():
    rng = np.random.default_rng(2)
    tests = _normal_tests(rng, [0.05] * 30, 0.01, 40)  # identical tests, wide posteriors, few draws
    p = pool(tests, "f")
    assert p.refused is not None
    assert p.mc_variance > 1
    assert "pooling f refused: the Monte Carlo variance of the hyper-log-likelihood is" in p.refused


def test_one_test_is_not_pooled():
    p = pool(_normal_tests(np.random.default_rng(0), [0.05], 0.01, 100), "kappa")
    assert p.refused == "pooling kappa needs at least 2 analysed tests, 1 given"


def test_implied_prior_of_kappa_matches_monte_carlo():
    """pi(kappa) by quadrature against a histogram of f nu/(1-nu) from 5e5 prior draws."""
    priors = load_priors(PRIORS_DIR / "I1.toml")
    rng = np.random.default_rng(5)
    f = priors["f"].rvs(rng, 500_000)
    nu = priors["nu"].rvs(rng, 500_000)
    k = f * nu / (1 - nu)
    edges = np.array([0.01, 0.02, 0.03, 0.04, 0.06, 0.1, 0.2])
    hist, _ = np.histogram(k, bins=edges)
    mc = hist / k.size / np.diff(edges)
    centres = np.linspace(edges[:-1], edges[1:], 41)
    quad = np.exp(implied_kappa_log_prior(centres, priors)).mean(axis=0)
    np.testing.assert_allclose(quad, mc, rtol=0.04)


def test_pooling_draws_made_under_a_stored_prior_divides_it_out():
    """f under a diagnosed model drawn under a normal prior N(m0, s0) (its log density stored beside the draws):
    each test's posterior is then normal with the prior's pull; dividing the stored prior out gives back
    L(mu, sigma) = prod_i N(x_i; mu, sqrt(sigma^2 + s^2)) of the tests' own measurements x_i. Ignoring the prior
    pools the pulled posteriors and misses the population mean."""
    rng = np.random.default_rng(3)
    x = rng.normal(0.05, 0.004, 12)  # what each test measures, to s
    s, m0, s0 = 0.003, 0.03, 0.01
    post_sd = 1.0 / np.sqrt(1 / s**2 + 1 / s0**2)
    post_mean = (x / s**2 + m0 / s0**2) * post_sd**2
    z = stats.norm.ppf((np.arange(1000) + 0.5) / 1000)
    draws = [m + post_sd * z for m in post_mean]
    stored = [StoredDraws(f"T{i}", "A", d, stats.norm.logpdf(d, m0, s0)) for i, d in enumerate(draws)]
    p = pool(stored, "f", basis="diagnosed")
    assert p.refused is None and p.basis == "diagnosed" and p.to_json()["basis"] == "diagnosed"
    mu, sg = np.meshgrid(p.grid_mu, p.grid_sigma)
    exact = sum(stats.norm.logpdf(m, mu, np.sqrt(sg**2 + s**2)) for m in x)
    post = np.exp(exact - exact.max())
    post /= post.sum()
    assert p.mu["mean"] == pytest.approx(np.sum(post.sum(axis=0) * p.grid_mu), abs=2e-5)
    assert p.sigma["mean"] == pytest.approx(np.sum(post.sum(axis=1) * p.grid_sigma), rel=0.03)
    assert p.mu["q05"] < 0.05 < p.mu["q95"]
    ignored = pool([StoredDraws(t.label, t.setup, t.draws, np.zeros(t.draws.size)) for t in stored], "f")
    # off by the prior's pull on each test, (m0 - x_i) post_sd^2 / s0^2: about -0.0016, beside a population 0.004 wide
    pull = np.mean(post_mean - x)
    assert pull < -0.0015 and ignored.mu["mean"] - p.mu["mean"] == pytest.approx(pull, rel=0.1)


@pytest.mark.parametrize("means, s", [((0.30, 0.36, 0.33), 0.01), ((0.30, 0.33, 0.28, 0.35, 0.31), 0.02),
                                      ((0.30, 0.36), 0.01)])
def test_mu_posterior_is_not_cut_by_its_grid(means, s):
    """A wide scatter among few tests: mu's posterior reaches past the medians +- 2 sd (its sd runs to
    sigma / sqrt(N)). Its quantiles match the closed form on a grid far wider than the package's, to a twentieth
    of mu's posterior sd (the grid's spacing is under a tenth of it); the first grid alone missed q95 by 0.44 sd
    on the three tests."""
    z = stats.norm.ppf((np.arange(2000) + 0.5) / 2000)
    tests = [StoredDraws(f"T{i}", "A", m + s * z, np.zeros(z.size)) for i, m in enumerate(means)]
    p = pool(tests, "f")
    assert p.refused is None
    wide = np.linspace(min(means) - 1.0, max(means) + 1.0, 40001)
    ll = sum(stats.norm.logpdf(m, wide[None, :], np.sqrt(p.grid_sigma[:, None] ** 2 + s**2)) for m in means)
    post = np.exp(ll - ll.max()).sum(axis=0)
    post /= post.sum()
    sd = float(np.sqrt(np.sum(post * (wide - np.sum(post * wide)) ** 2)))
    exact = np.interp([0.05, 0.5, 0.95], np.cumsum(post), wide)
    got = np.array([p.mu["q05"], p.mu["q50"], p.mu["q95"]])
    assert np.all(np.abs(got - exact) < 0.05 * sd), (got, exact, sd)
    assert p.mu["sd"] == pytest.approx(sd, rel=0.05)
    assert np.diff(p.grid_mu)[0] < 0.1 * sd


def test_mu_posterior_past_every_grid_is_refused(monkeypatch):
    """Where no widening holds mu's posterior (here none is allowed), the pooling is refused, not cut."""
    from friction_uq.campaigns import pooling

    monkeypatch.setattr(pooling, "MU_WIDENINGS", 0)
    z = stats.norm.ppf((np.arange(2000) + 0.5) / 2000)
    p = pool([StoredDraws(f"T{i}", "A", m + 0.01 * z, np.zeros(z.size)) for i, m in enumerate((0.30, 0.36, 0.33))],
             "f")
    assert p.refused is not None and "population mean's posterior runs to the edge of its grid" in p.refused
