"""The exact posterior behind a Laplace approximation and its sandwich adjustment (friction_uq.stats.exact),
against targets whose moments are known in closed form."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from friction_uq.stats import khat_threshold
from friction_uq.stats.exact import exact_draws, sandwich_map

K_MAX = khat_threshold(200)

MU = np.array([0.3, -1.0])
S = np.array([[0.04, 0.012], [0.012, 0.09]])
NORMAL = stats.multivariate_normal(MU, S)


def test_a_right_laplace_approximation_gives_the_normal_itself_and_no_adjustment():
    ex = exact_draws(NORMAL.logpdf, MU, S, S, rng=np.random.default_rng(1), n_out=4000)
    assert ex.method == "importance" and ex.pareto_k <= K_MAX
    # resampled draws: the mean within 4 Monte Carlo standard errors of ESS ~ the importance draws
    se = np.sqrt(np.diag(S) / ex.ess)
    assert np.all(np.abs(ex.z.mean(axis=0) - MU) < 4 * se)
    np.testing.assert_allclose(ex.z_adjusted, ex.z, atol=1e-12)


def test_the_sandwich_adjustment_gives_the_robust_covariance_and_keeps_the_mode():
    omega = sandwich_map(MU, S, 4.0 * S)
    np.testing.assert_allclose(omega @ S @ omega.T, 4.0 * S, rtol=1e-10)
    ex = exact_draws(NORMAL.logpdf, MU, S, 4.0 * S, rng=np.random.default_rng(2), n_out=4000)
    # a proposal twice as wide as the target: still importance, and the adjusted draws are 2x as spread
    assert ex.method.startswith("importance")
    ratio = np.std(ex.z_adjusted, axis=0) / np.std(ex.z, axis=0)
    np.testing.assert_allclose(ratio, 2.0, rtol=0.02)


def test_a_skewed_posterior_keeps_its_skew():
    """Target: z = log x with x ~ Gamma(3) (exact skewness of log-gamma: negative); Laplace at its mode."""
    a = 3.0
    logp = lambda z: float(a * z[0] - np.exp(z[0]))  # noqa: E731 - log density of log x, x ~ Gamma(a)
    mode, var = np.array([np.log(a)]), np.array([[1.0 / a]])
    ex = exact_draws(logp, mode, var, var, rng=np.random.default_rng(3), n_importance=400, n_out=8000)
    from scipy.special import digamma, polygamma

    assert ex.z.mean() == pytest.approx(digamma(a), abs=4 * np.sqrt(polygamma(1, a) / ex.ess))
    skew = stats.skew(ex.z[:, 0])
    exact_skew = polygamma(2, a) / polygamma(1, a) ** 1.5  # -0.73 for a = 3
    assert skew < -0.3 and skew == pytest.approx(exact_skew, abs=0.3)


def test_a_proposal_far_off_is_refused_by_pareto_k_and_sampled():
    """A Laplace approximation centred 6 sd away and 10 times too narrow: k is large, and the draws come
    from the second proposal or from emcee; either way the exact mean is recovered."""
    wrong = MU + np.array([1.2, 1.8])
    ex = exact_draws(NORMAL.logpdf, wrong, S / 100, S / 100, rng=np.random.default_rng(4), n_out=2000,
                     emcee_steps=400, emcee_burn=150)
    assert ex.pareto_k > K_MAX
    assert ex.method in ("importance (second proposal)", "emcee")
    assert np.all(np.abs(ex.z.mean(axis=0) - MU) < 0.15 * np.sqrt(np.diag(S)) + 0.1)


def test_same_seed_same_bits():
    a = exact_draws(NORMAL.logpdf, MU, S, 2 * S, rng=np.random.default_rng(7))
    b = exact_draws(NORMAL.logpdf, MU, S, 2 * S, rng=np.random.default_rng(7))
    assert np.array_equal(a.z_adjusted, b.z_adjusted)


def test_stacking_weights_go_to_the_model_that_predicts_better_and_are_shared_by_equals():
    from friction_uq.stats import stacking_weights

    rng = np.random.default_rng(0)
    a = rng.normal(-1.0, 0.3, 12)
    w = stacking_weights({"a": a, "b": a - 0.3 + rng.normal(0, 0.05, 12), "a_twin": a.copy()})
    assert w["b"] < 0.01 and w["a"] + w["a_twin"] == pytest.approx(1.0, abs=1e-4)
    # without the bootstrap the optimum is ArviZ's stacking
    from friction_uq.stats.weights import arviz_stacking

    pts = {"a": a, "b": a - 0.05 + rng.normal(0, 0.2, 12), "c": a + rng.normal(0, 0.3, 12)}
    ours, theirs = stacking_weights(pts, bootstrap=0), arviz_stacking(pts)
    assert all(ours[k] == pytest.approx(theirs[k], abs=0.02) for k in pts), (ours, theirs)


def test_bootstrapped_stacking_shares_the_weight_of_a_near_tie_and_keeps_a_clear_lead():
    from friction_uq.stats import WeightRule, stacking_weights

    rng = np.random.default_rng(3)
    base = rng.normal(-1.0, 0.5, 10)
    d = np.r_[np.full(5, 0.5), np.full(5, -0.45)]  # a ahead by 0.25 +- 1.5 nats: a tie
    tie = stacking_weights({"a": base + d, "b": base}, seed=1)
    assert 0.2 < tie["a"] < 0.8 and len(WeightRule().supported(tie)) == 2
    assert tie == stacking_weights({"a": base + d, "b": base}, seed=1)  # same seed, same weights
    far = stacking_weights({"a": base + 2.0, "b": base}, seed=1)  # 20 nats ahead on every point
    assert far["a"] > 0.99 and WeightRule().supported(far) == ["a"]


@pytest.mark.parametrize("wrong", [False, True])
def test_a_pool_sharing_the_evaluations_gives_the_same_bits(wrong):
    """The importance stage and emcee's (a proposal far off: ``wrong``) with the density's values from a pool
    of forked processes: the draws are the ones computed in turn."""
    from friction_uq._parallel import ForkedPool

    mode, cov = (MU + np.array([1.2, 1.8]), S / 100) if wrong else (MU, S)
    kw = dict(rng=np.random.default_rng(11), n_out=500, emcee_steps=40, emcee_burn=10)
    alone = exact_draws(NORMAL.logpdf, mode, cov, cov, **kw)
    with ForkedPool(NORMAL.logpdf, workers=2) as pool:
        kw["rng"] = np.random.default_rng(11)
        shared = exact_draws(NORMAL.logpdf, mode, cov, cov, map_rows=pool.map, **kw)
    assert shared.method == alone.method and (alone.method == "emcee") is wrong
    assert np.array_equal(shared.z_adjusted, alone.z_adjusted)


def test_a_wide_proposal_whose_k_passes_draws_on_until_the_tails_have_their_effective_size():
    """A robust covariance 16 times the posterior's (a model that misses, by far): k passes, but 200 draws keep an
    effective size of a few dozen; more are drawn (or the second proposal) until it reaches the floor, and the
    mean and sd are the target's within their Monte Carlo error at that size."""
    from friction_uq.stats.exact import ess_floor

    for seed in (1, 2, 3):
        ex = exact_draws(NORMAL.logpdf, MU, S, 16.0 * S, rng=np.random.default_rng(seed), n_out=4000)
        assert ex.method.startswith("importance") and ex.converged
        assert ex.ess >= ess_floor() == 119 and ex.log_post_calls > 200
        se = np.sqrt(np.diag(S) / ex.ess)
        assert np.all(np.abs(ex.z.mean(axis=0) - MU) < 4 * se)
        np.testing.assert_allclose(ex.z.std(axis=0), np.sqrt(np.diag(S)), rtol=4 / np.sqrt(2 * ex.ess))


def test_a_right_proposal_keeps_its_first_two_hundred_draws():
    """When the first 200 draws already have the floor's effective size, nothing more is drawn (the same bits as
    before the floor existed)."""
    ex = exact_draws(NORMAL.logpdf, MU, S, S, rng=np.random.default_rng(1), n_out=1000)
    assert ex.method == "importance" and ex.log_post_calls == 200 and ex.ess >= 119


def test_emcee_runs_its_chain_until_its_effective_size_reaches_the_floor_and_reports_the_chain_s():
    """A proposal far off (both importance stages refused): emcee's chain runs on by its first length until its
    ESS (walkers x kept steps / autocorrelation time) reaches the floor, or stops at four times that length and
    says it fell short. The ESS reported is the chain's, not the number of draws resampled from it (2000)."""
    from friction_uq.stats.exact import ess_floor

    wrong = MU + np.array([1.2, 1.8])
    short = exact_draws(NORMAL.logpdf, wrong, S / 100, S / 100, rng=np.random.default_rng(4), n_out=2000,
                        emcee_steps=10, emcee_burn=5)
    # 16 walkers, at most 40 steps of which half or more kept: never more effective draws than the chain holds
    assert short.method == "emcee" and short.ess <= 16 * 20 and short.converged == (short.ess >= ess_floor())
    long = exact_draws(NORMAL.logpdf, wrong, S / 100, S / 100, rng=np.random.default_rng(4), n_out=2000,
                       emcee_steps=400, emcee_burn=150)
    assert long.method == "emcee" and long.converged and ess_floor() <= long.ess < 2000
    se = np.sqrt(np.diag(S) / long.ess)
    assert np.all(np.abs(long.z.mean(axis=0) - MU) < 4 * se)


def test_a_short_exact_posterior_is_a_warning_that_names_its_effective_size():
    from types import SimpleNamespace

    from friction_uq.record_run.warnings import exact_posterior_warning

    dg = SimpleNamespace(causes=("clearance",), posterior_converged=False, posterior_method="emcee", importance_ess=64.2)
    text = exact_posterior_warning(dg)
    assert "kept only 64 effective draws, short of the 119" in text and "not reliable" in text
    assert exact_posterior_warning(SimpleNamespace(causes=("clearance",), posterior_converged=True)) is None
    assert exact_posterior_warning(SimpleNamespace(causes=(), posterior_converged=False)) is None
    assert exact_posterior_warning(None) is None


def test_exact_draws_go_on_where_one_draw_carries_every_weight():
    """A normal approximation a thousand times too wide: one draw of the first proposal carries all the weight (the
    others' underflow to 0), its weighted covariance was nan and the second proposal an internal error; now emcee
    takes over from the first proposal's draws (the second's scale would be the one that failed), as it does when
    the second proposal fails, and the draws are on the posterior's scale, not the proposal's."""
    from friction_uq.stats.exact import exact_draws

    def log_post(z):
        return float(-0.5 * np.sum((np.asarray(z) / 1e-3) ** 2))

    for seed in (1, 2, 3):
        ex = exact_draws(log_post, np.zeros(2), np.eye(2), np.eye(2), rng=np.random.default_rng(seed))
        assert ex.method == "emcee"
        sd = np.std(ex.z, axis=0)
        # a fallback from a degenerate start: within a factor 2 of the posterior's sd and its mean within one sd
        assert np.all((0.5e-3 < sd) & (sd < 2e-3)) and np.all(np.abs(ex.z.mean(axis=0)) < 1e-3), (seed, sd)
