"""Sampler: against a posterior computed independently on a grid, the paper's case, seeds, resuming."""

from __future__ import annotations

import math
import re

import emcee
import numpy as np
import pytest

from friction_uq.errors import PriorError, SamplingError
from friction_uq.likelihood import Likelihood
from friction_uq.physics import cell
from friction_uq.prior_loader import default_prior_path, load_priors, parse_priors
from friction_uq.sampler import (
    ConvergenceWarning,
    LogPosterior,
    Progress,
    integrated_time,
    sample_posterior,
    start_ball,
    stderr_progress,
)
from test_sbc import closed_form_data

DEFAULT = load_priors(default_prior_path("I1"))
WIDE = load_priors(default_prior_path("I1-nu-wide"))


@pytest.fixture(scope="module")
def paper_data():
    return closed_form_data(0.05, 0.4, 1.0, seed=2016)


@pytest.fixture(scope="module")
def paper_force_run(paper_data):
    return sample_posterior(paper_data, DEFAULT, seed=1, hoop=False)


# ---------------------------------------------------------------- building blocks


def test_integrated_time_matches_emcee():
    rng = np.random.default_rng(0)
    x = np.zeros((3000, 8, 2))
    for t in range(1, 3000):
        x[t] = np.array([0.9, 0.5]) * x[t - 1] + rng.normal(size=(8, 2))
    ref = [emcee.autocorr.integrated_time(x[:, :, i], tol=0)[0] for i in range(2)]
    np.testing.assert_allclose(integrated_time(x), ref, rtol=1e-10)


def test_parametrisation_roundtrip_and_jacobian(paper_data):
    params = LogPosterior(Likelihood(paper_data, hoop=True), WIDE.subset(("f", "nu", "hoop_gain"))).parameters
    assert params.names == ("f", "nu", "hoop_gain")
    theta = np.array([[0.05, 0.4, 1.02], [0.5, 0.2, 0.9]])
    np.testing.assert_allclose(params.from_unbounded(params.to_unbounded(theta)), theta, rtol=1e-13)
    for z in params.to_unbounded(theta):
        h = 1e-6
        J = np.array([(params.from_unbounded(z + h * e) - params.from_unbounded(z - h * e)) / (2 * h)
                      for e in np.eye(3)]).T
        assert params.log_jacobian(z) == pytest.approx(math.log(abs(np.linalg.det(J))), rel=1e-7)
    # the closed form's coordinates: eq. 17's ridge log f + log(nu/(1-nu)) = log kappa is a straight line
    z = params.to_unbounded(theta)
    np.testing.assert_allclose(z[:, 0] + z[:, 1], np.log(theta[:, 0] * theta[:, 1] / (1 - theta[:, 1])), rtol=1e-12)


def test_log_posterior_refuses_priors_over_other_parameters(paper_data):
    with pytest.raises(ValueError, match="the likelihood's parameters are f, nu, hoop_gain"):
        LogPosterior(Likelihood(paper_data, hoop=True), WIDE.subset(("f", "nu")))


def test_start_ball_inside_support_when_map_sits_on_a_bound(paper_data):
    """Uniform nu prior: in z the density rises toward nu = 0.45, the optimum is on the bound."""
    lk = Likelihood(paper_data, hoop=False)
    lp = LogPosterior(lk, WIDE.subset(lk.names))
    _, ball = start_ball(lp, WIDE.subset(lk.names), nwalkers=32, n_ensembles=4, rng=np.random.default_rng(0))
    assert ball.shape == (4, 32, 2)
    assert np.all(np.isfinite(lp(ball.reshape(-1, 2))))
    assert len(np.unique(ball[..., 1])) == 128  # no clumped start


# ---------------------------------------------------------------- against an independent posterior


def grid_posterior(data, priors):
    """Posterior moments by quadrature in (kappa, nu): p = L(kappa) p_f(kappa/lat) p_nu(nu) / lat."""
    lk = Likelihood(data, hoop=False)
    k0 = float(cell.kappa_from_ratio(lk.force.r0, radius=data.radius, length=data.length))
    kap = np.linspace(0.9 * k0, 1.1 * k0, 801)
    lo, hi = priors["nu"].support
    nu = np.linspace(max(lo, 0.15), min(hi, 0.499), 801)
    K, N = np.meshgrid(kap, nu, indexing="ij")
    lat = cell.lateral_ratio(N)
    F = K / lat
    ll = lk.force.loglike(np.expm1(2 * K * data.length / data.radius)[:, :1])  # depends on kappa only
    logp = ll + priors["f"].logpdf(F) + priors["nu"].logpdf(N) - np.log(lat)
    w = np.exp(logp - logp.max())
    w /= w.sum()
    out = {}
    for name, x in (("f", F), ("nu", N), ("kappa", K)):
        m = float(np.sum(w * x))
        out[name] = (m, math.sqrt(float(np.sum(w * (x - m) ** 2))))
    return out


@pytest.mark.parametrize("priors", [DEFAULT, WIDE], ids=["default", "nu-wide"])
def test_sampler_reproduces_grid_posterior(paper_data, paper_force_run, priors):
    """Means and sds of f, nu, kappa within 4 Monte Carlo standard errors of the quadrature."""
    import arviz_stats

    s = paper_force_run if priors is DEFAULT else sample_posterior(paper_data, priors, seed=3, hoop=False)
    assert s.converged
    ref = grid_posterior(paper_data, priors)
    draws = {"f": s.draws["f"], "nu": s.draws["nu"], "kappa": s.draws["f"] * cell.lateral_ratio(s.draws["nu"])}
    for name, (m, sd) in ref.items():
        x = draws[name]
        ess = float(arviz_stats.ess(x, method="mean"))
        ess_sd = float(arviz_stats.ess(x, method="sd"))
        mcse_mean = x.std() / math.sqrt(ess)
        mcse_sd = x.std() / math.sqrt(2 * ess_sd)
        assert abs(x.mean() - m) < 4 * mcse_mean, f"{name}: mean {x.mean():.6g} vs grid {m:.6g}"
        assert abs(x.std() - sd) < 4 * mcse_sd, f"{name}: sd {x.std():.6g} vs grid {sd:.6g}"


# ---------------------------------------------------------------- the paper's case


def test_paper_case_interval_contains_0_049_without_hoop(paper_force_run):
    q = np.quantile(paper_force_run.flat("f"), [0.05, 0.95])
    assert q[0] <= 0.049 <= q[1]


def test_paper_case_with_hoop_is_narrower_and_contains_0_049(paper_data, paper_force_run):
    s = sample_posterior(paper_data, DEFAULT, seed=2)
    assert s.hoop and s.names == ("f", "nu", "hoop_gain") and s.converged
    q = np.quantile(s.flat("f"), [0.05, 0.95])
    assert q[0] <= 0.049 <= q[1]
    # the hoop gauge measures nu/(1-nu) up to its 5 % calibration: nu's sd drops well below the prior's 0.03
    assert s.flat("nu").std() < 0.5 * paper_force_run.flat("nu").std()


# ---------------------------------------------------------------- result, seeds, cap, progress


def test_result_shapes_and_log_likelihood(paper_data, paper_force_run):
    s = paper_force_run
    assert s.draws["f"].shape == (4, s.n_draws) == s.log_likelihood.shape
    assert s.tau.shape == (4, 2) and s.acceptance.shape == (4,)
    assert np.all((s.acceptance > 0.1) & (s.acceptance < 0.9))
    assert s.n_steps > 50 * s.tau.mean()
    lk = Likelihood(paper_data, hoop=False)
    np.testing.assert_allclose(s.log_likelihood[1, :50], lk(s.array()[1, :50]), rtol=1e-12)
    assert np.all(s.flat("f") > 0) and np.all((s.flat("nu") > 0) & (s.flat("nu") < 0.5))


def test_same_seed_same_numbers_other_seed_other_numbers(paper_data):
    kw = dict(hoop=False, max_steps=200, n_ensembles=2)
    with pytest.warns(ConvergenceWarning, match=r"sampler stopped at max_steps=200 before convergence"):
        a = sample_posterior(paper_data, DEFAULT, seed=5, **kw)
    with pytest.warns(ConvergenceWarning, match=r"max_steps=200"):
        b = sample_posterior(paper_data, DEFAULT, seed=5, **kw)
    with pytest.warns(ConvergenceWarning, match=r"max_steps=200"):
        c = sample_posterior(paper_data, DEFAULT, seed=6, **kw)
    np.testing.assert_array_equal(a.array(), b.array())
    assert not np.array_equal(a.array(), c.array())
    assert not a.converged
    # independent ensembles: different streams
    assert not np.array_equal(a.draws["f"][0], a.draws["f"][1])


def test_a_likelihood_built_once_gives_the_same_draws(paper_data):
    """run builds the likelihood once and passes it down; the draws equal those of one built inside."""
    kw = dict(hoop=False, max_steps=200, n_ensembles=2)
    lk = Likelihood(paper_data, hoop=False)
    with pytest.warns(ConvergenceWarning, match=r"max_steps=200"):
        a = sample_posterior(paper_data, DEFAULT, seed=5, **kw)
    with pytest.warns(ConvergenceWarning, match=r"max_steps=200"):
        b = sample_posterior(paper_data, DEFAULT, seed=5, likelihood=lk, **kw)
    np.testing.assert_array_equal(a.array(), b.array())
    with pytest.raises(SamplingError, match="has the hoop term off against hoop=True"):
        sample_posterior(paper_data, DEFAULT, seed=5, hoop=True, likelihood=lk)


def test_progress_callback_and_stderr_line(paper_data, capsys):
    seen: list[Progress] = []
    with pytest.warns(ConvergenceWarning, match="max_steps=300"):
        sample_posterior(paper_data, DEFAULT, seed=5, hoop=False, max_steps=300, n_ensembles=1, progress=seen.append)
    assert [p.steps for p in seen] == [100, 200, 300]
    stderr_progress(seen[-1])
    err = capsys.readouterr().err
    # the share of what the stopping rule needs (capped by max_steps), not "step 300/20000"
    assert err.startswith("sampling: ") and "of the steps the stopping rule needs (300 of ~" in err
    assert "acceptance" in err and not seen[-1].done
    done = Progress(600, 20000, 10.0, 0.01, 60.0, 0.3, 1.0, 50.0, 0.05)
    assert done.done and done.line().startswith("sampling: done at step 600 (tau 10.0, steady within 1.0 %)")
    early = Progress(100, 20000, 10.0, float("inf"), 10.0, 0.3, 1.0, 50.0, 0.05)
    assert "20 % of the steps the stopping rule needs (100 of ~500, tau 10.0 not yet measured twice)" in early.line()
    # long enough but tau not yet steady: not "100 %" of a rule that is not met
    settling = Progress(600, 20000, 10.0, 0.07, 60.0, 0.3, 1.0, 50.0, 0.05)
    assert settling.line().startswith("sampling: 600 steps, more than 50 tau (500); waiting for tau 10.0 to settle "
                                      "(still moving 7.0 %, needs < 5 %)")


def test_hoop_without_hoop_gain_prior_is_refused(paper_data):
    bare = parse_priors(
        {"f": {"distribution": "halfnormal", "scale": 0.3},
         "nu": {"distribution": "uniform", "lower": 0.2, "upper": 0.45}}, path="bare.toml")
    with pytest.raises(PriorError, match=r"bare\.toml: \[hoop_gain\]: no prior .*\(the hoop likelihood needs f, nu, hoop_gain\)"):
        sample_posterior(paper_data, bare, seed=1)


def test_bad_settings_are_refused(paper_data):
    with pytest.raises(SamplingError, match="nwalkers must be an even number >= 4, got 5"):
        sample_posterior(paper_data, DEFAULT, seed=1, nwalkers=5)


# ---------------------------------------------------------------- resuming


class Interrupt(Exception):
    pass


def test_interrupted_run_resumes_to_the_uninterrupted_result(paper_data, tmp_path):
    kw = dict(seed=11, hoop=False, n_ensembles=2, checkpoint_seconds=0.0)
    full = sample_posterior(paper_data, DEFAULT, backend_path=tmp_path / "full.npz", **kw)

    def stop_at_300(p: Progress) -> None:
        if p.steps >= 300:
            raise Interrupt

    path = tmp_path / "run.npz"
    with pytest.raises(Interrupt):
        sample_posterior(paper_data, DEFAULT, backend_path=path, progress=stop_at_300, **kw)
    steps = []
    resumed = sample_posterior(paper_data, DEFAULT, backend_path=path, progress=lambda p: steps.append(p.steps), **kw)
    assert steps[:2] == [300, 400]  # checked the saved 300 steps, then continued (not from scratch)
    assert resumed.n_steps == full.n_steps and resumed.converged
    np.testing.assert_array_equal(resumed.array(), full.array())
    # resuming a finished run steps no further and gives the same draws
    again = sample_posterior(paper_data, DEFAULT, backend_path=tmp_path / "full.npz", **kw)
    assert again.n_steps == full.n_steps
    np.testing.assert_array_equal(again.array(), full.array())
    # and the run without checkpoints gives the same numbers as the checkpointed one
    mem = sample_posterior(paper_data, DEFAULT, **kw)
    np.testing.assert_array_equal(mem.array(), full.array())


def test_checkpoint_of_another_run_is_replaced_with_a_notice(paper_data, tmp_path):
    path = tmp_path / "b.npz"
    kw = dict(hoop=False, backend_path=path, max_steps=100, n_ensembles=1)
    with pytest.warns(ConvergenceWarning, match="max_steps=100"):
        first = sample_posterior(paper_data, DEFAULT, seed=1, **kw)
    assert path.exists()
    notes: list[str] = []
    with pytest.warns(ConvergenceWarning, match="max_steps=100"):
        other = sample_posterior(paper_data, DEFAULT, seed=2, notify=notes.append, **kw)
    assert len(notes) == 1
    assert re.fullmatch(r"the checkpoint .*b\.npz was written for other data, priors, seed, window or settings; "
                        r"it is removed and sampling starts afresh", notes[0])
    with pytest.warns(ConvergenceWarning):
        fresh = sample_posterior(paper_data, DEFAULT, seed=2, hoop=False, max_steps=100, n_ensembles=1)
    np.testing.assert_array_equal(other.array(), fresh.array())  # started afresh, not from seed 1's chain
    assert not np.array_equal(other.array(), first.array())


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04 truncated zip", b"\x89HDF\r\n\x1a\n old emcee backend"])
def test_corrupt_checkpoint_is_removed_and_sampling_starts_afresh(paper_data, tmp_path, content):
    path = tmp_path / "c.npz"
    path.write_bytes(content)
    notes: list[str] = []
    with pytest.warns(ConvergenceWarning):
        got = sample_posterior(paper_data, DEFAULT, seed=3, hoop=False, backend_path=path, max_steps=100,
                               n_ensembles=1, notify=notes.append)
    assert len(notes) == 1 and re.match(r"the checkpoint .*c\.npz cannot be read \(", notes[0])
    with pytest.warns(ConvergenceWarning):
        fresh = sample_posterior(paper_data, DEFAULT, seed=3, hoop=False, max_steps=100, n_ensembles=1)
    np.testing.assert_array_equal(got.array(), fresh.array())


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, True])
def test_bad_seed_is_refused_before_sampling(paper_data, seed):
    with pytest.raises(SamplingError, match=r"seed must be an integer in \[0, 2\*\*64\)"):
        sample_posterior(paper_data, DEFAULT, seed=seed, hoop=False)
