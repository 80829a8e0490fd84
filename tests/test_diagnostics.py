"""Diagnostics: DataTree layout, derived variables against the closed forms, convergence numbers,
nu -> f propagation against the law of total variance, posterior predictive of the ratio."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from friction_uq import diagnostics as dg
from friction_uq.likelihood import Likelihood
from friction_uq.physics import cell
from friction_uq.prior_loader import default_prior_path, load_priors
from friction_uq.sampler import PosteriorSamples, sample_posterior
from test_sbc import closed_form_data

DEFAULT = load_priors(default_prior_path("I1"))
F_TRUE, NU_TRUE = 0.05, 0.4


@pytest.fixture(scope="module")
def data():
    return closed_form_data(F_TRUE, NU_TRUE, 1.0, seed=77)


@pytest.fixture(scope="module")
def run_hoop(data):
    return sample_posterior(data, DEFAULT, seed=7)


@pytest.fixture(scope="module")
def run_force(data):
    return sample_posterior(data, DEFAULT, seed=8, hoop=False)


@pytest.fixture(scope="module")
def tree(run_hoop, data):
    return dg.build_datatree(run_hoop, data, DEFAULT, seed=3, n_prior=2000)


def test_datatree_groups_dims_and_provenance(tree, run_hoop, data):
    for g in ("posterior", "log_likelihood", "observed_data", "sample_stats", "prior"):
        assert g in tree.children
    post = tree["posterior"]
    for v in ("f", "nu", "hoop_gain", "kappa", "ratio", "tau_mean", "p_mean"):
        assert post[v].dims == ("chain", "draw")
    assert post.attrs["sample_dims"] == ["chain", "draw"]
    assert post.sizes == {"chain": 4, "draw": run_hoop.n_draws}
    assert tree["prior"]["f"].shape == (1, 2000)
    assert tree["log_likelihood"]["F_eo"].dims == ("chain", "draw", "F_eo_observation")  # one level
    assert tree["observed_data"]["hoop"].shape == (data.n,)
    assert tree.attrs["seed"] == 7 and tree.attrs["prior_path"].endswith("I1.toml")
    # per draw, the observations add up to the total log-likelihood
    ll = tree["log_likelihood"]["F_eo"].sum("F_eo_observation") + tree["log_likelihood"]["hoop"].sum("hoop_observation")
    np.testing.assert_allclose(ll.values, run_hoop.log_likelihood, rtol=1e-9)


def test_derived_variables_follow_the_closed_forms(tree, data):
    post = tree["posterior"]
    f, nu = post["f"].values, post["nu"].values
    np.testing.assert_allclose(post["kappa"].values, f * nu / (1 - nu), rtol=1e-12)
    np.testing.assert_allclose(post["ratio"].values, np.expm1(f * cell.beta(nu, radius=data.radius, length=data.length)), rtol=1e-12)
    np.testing.assert_allclose(post["p_mean"].values, post["tau_mean"].values / f, rtol=1e-12)
    # tau_mean = F_eo / (2 pi R L) (eq. 18): the posterior agrees with the observed mean force
    tau = post["tau_mean"].values.ravel()
    tau_obs = float(cell.mean_friction_stress(np.mean(data.F_eo), radius=data.radius, length=data.length))
    assert abs(tau.mean() - tau_obs) < 3 * tau.std()
    # p_mean's 90 % interval holds the design value of eq. 15 for the true (f, nu): 91.68 MPa
    q = np.quantile(post["p_mean"].values, [0.05, 0.95])
    assert q[0] <= 91.68e6 <= q[1]


def test_convergence_and_summary(tree, run_hoop):
    c = dg.convergence(tree, run_hoop)
    assert c.ok and c.r_hat_max < 1.01 and c.ess_bulk_min > 400 and c.ess_per_second > 0
    json.dumps(c.to_json())
    s = dg.summarize(tree)
    assert list(s) == ["f", "nu", "kappa", "hoop_gain", "ratio", "p_mean", "tau_mean"]
    f = run_hoop.flat("f")
    assert s["f"].mean == pytest.approx(float(f.mean()), rel=1e-12)
    assert s["f"].q05 < s["f"].q50 < s["f"].q95
    assert s["f"].q05 <= F_TRUE * 0.98 <= s["f"].q95  # paper case: 0.049 inside the 90 % interval
    out = json.loads(json.dumps({k: v.to_json() for k, v in s.items()}))
    assert isinstance(out["nu"]["sd"], float)


# ---------------------------------------------------------------- nu -> f


def _fake(f: np.ndarray, nu: np.ndarray) -> PosteriorSamples:
    n = len(f) // 4
    return PosteriorSamples(
        names=("f", "nu"), draws={"f": f.reshape(4, n), "nu": nu.reshape(4, n)}, log_likelihood=np.zeros((4, n)),
        log_prior=np.zeros((4, n)), acceptance=np.full(4, 0.3), tau=np.ones((4, 2)), n_steps=1, burn=0, thin=1,
        converged=True, seconds=1.0, seed=0, hoop=False, nwalkers=4, map_estimate={},
    )


def test_variance_share_limits():
    rng = np.random.default_rng(0)
    nu = rng.normal(0.4, 0.03, 40000)
    # f independent of nu: the bin lines fit noise only, share ~ 2 n_bins / n_draws = 0.001
    assert dg.nu_variance_share(_fake(rng.normal(0.05, 0.01, 40000), nu)) < 5 * 2 * 20 / 40000
    # f a function of nu only: share 1 up to the curvature inside a bin
    assert dg.nu_variance_share(_fake(0.0334 * (1 - nu) / nu, nu)) > 0.999


def test_variance_share_matches_law_of_total_variance(run_force):
    """Force term only: kappa is independent of nu, so with h = (1-nu)/nu, E[f|nu] = E[kappa] h exactly and
    Var f = E[kappa^2] E[h^2] - E[kappa]^2 E[h]^2: the share from the marginal moments of kappa and h. (Taken
    from the joint draws instead, Var(E[kappa] h) / Var(f) carries the draws' chance kappa-nu correlation,
    +-0.005 from seed to seed, which this reference does not.)"""
    f, nu = run_force.flat("f"), run_force.flat("nu")
    kappa, h = f * cell.lateral_ratio(nu), (1 - nu) / nu
    ref = float(kappa.mean() ** 2 * np.var(h) / (np.mean(kappa**2) * np.mean(h**2) - kappa.mean() ** 2 * h.mean() ** 2))
    share = dg.nu_variance_share(run_force)
    # estimator noise ~ 2 n_bins / n_draws of Var(f|nu) / Var(f) (1e-4 here: the share of Var(f|nu) is ~1 %)
    assert share == pytest.approx(ref, abs=0.001)
    # the force data fix kappa to ~2.5 % (the ratio's model-form term), nu's prior sd 0.03 makes (1-nu)/nu
    # uncertain by ~12 %: nu dominates f's uncertainty (share ~ 0.125^2 / (0.125^2 + 0.025^2) = 0.96)
    assert share > 0.9


def test_f_given_nu_band(run_force):
    grid = np.array([0.2, 0.3, 0.4, 0.45])
    band = dg.f_given_nu(run_force, grid)
    # f = kappa (1-nu)/nu: the band times nu/(1-nu) is kappa's interval at every nu
    k = band.q50 * grid / (1 - grid)
    np.testing.assert_allclose(k, k[0], rtol=1e-12)
    assert np.all(np.diff(band.q50) < 0) and np.all(band.q05 < band.q95)
    # against the draws: f in a thin bin of nu around 0.4
    f, nu = run_force.flat("f"), run_force.flat("nu")
    sel = np.abs(nu - 0.4) < 0.001
    fb = f[sel]
    se = fb.std() / math.sqrt(sel.sum() / 4)  # thinned draws: ESS >= n/4
    assert abs(np.median(fb) - band.q50[2]) < 4 * se + fb.std() * 0.001 / 0.4


def test_nu_sensitivity_orders_the_widths(data, run_force):
    pri = {
        "default": DEFAULT,
        "nu-wide": load_priors(default_prior_path("I1-nu-wide")),
        "nu-tight": load_priors(default_prior_path("I1-nu-tight")),
    }
    out = dg.nu_sensitivity(data, pri, seed=4, hoop=False, done={"default": run_force})
    assert out["default"].mean == pytest.approx(float(run_force.flat("f").mean()), rel=1e-12)
    assert out["nu-tight"].sd < out["default"].sd < out["nu-wide"].sd
    # uniform nu on 0.2-0.45: f spans kappa (1-nu)/nu from nu = 0.45 to 0.2
    kap = float(cell.kappa(F_TRUE, NU_TRUE))
    assert out["nu-wide"].q05 < kap * 0.6 / 0.4 and out["nu-wide"].q95 > kap * 0.75 / 0.25
    assert len(out["nu-wide"].draws) <= 4000
    json.dumps({k: v.to_json() for k, v in out.items()})


# ---------------------------------------------------------------- posterior predictive


def test_the_analysis_likelihood_passed_down_gives_the_same_numbers(run_hoop, data):
    """run builds the likelihood once (hoop term on) and passes it to the diagnostics: the same
    pointwise log-likelihood and the same replicated forces as the ones built inside."""
    lk = Likelihood(data, hoop=True)
    a = dg.pointwise_log_likelihood(run_hoop, data)
    b = dg.pointwise_log_likelihood(run_hoop, data, likelihood=lk)
    assert a.keys() == b.keys() == {"F_eo", "hoop"}
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    np.testing.assert_array_equal(dg.ratio_ppc(run_hoop, data, seed=1).replicated,
                                  dg.ratio_ppc(run_hoop, data, seed=1, likelihood=lk).replicated)


def test_ratio_ppc_covers_a_well_specified_record_and_flags_a_drift(run_force, data):
    ppc = dg.ratio_ppc(run_force, data, seed=1)
    assert ppc.replicated.shape == (200, data.n)
    assert ppc.model_q05 < float(cell.force_ratio(F_TRUE, NU_TRUE, radius=data.radius, length=data.length)) < ppc.model_q95
    # 90 % pointwise band; the 10 us-smoothed ratio has ~n/50 independent values (~30): sd of the
    # coverage ~ sqrt(0.09/30) = 0.055, so a well-specified record stays above 0.9 - 4 * 0.055
    assert ppc.coverage > 0.68
    # a ratio drifting by +-30 % across the window is not what the stationary model predicts
    drift = np.linspace(0.7, 1.3, data.n)
    bad = replace(data, F_eo=data.F_eo * drift)
    bad_run = sample_posterior(bad, DEFAULT, seed=2, hoop=False, n_ensembles=1)
    assert dg.ratio_ppc(bad_run, bad, seed=1).coverage < 0.5
