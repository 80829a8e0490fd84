"""The coordinates the friction laws are sampled in (friction_uq.campaigns.law_coordinates): a change of variables
with its Jacobian, so the same posterior; checked by a round trip, the Jacobian against finite differences, and
sampling the prior through the change."""

from __future__ import annotations

import emcee
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.campaigns.law_coordinates import LawCoordinates
from friction_uq.campaigns.laws import LOG_VC_RANGE

PARAMS = ("d", "s", "log_vc", "amp_p", "log_pc", "r")  # pressure+velocity's
V = np.array([5.5, 7.0, 9.0, 12.5])
P = np.array([0.45, 0.8, 1.1, 1.7])  # wall pressure over the campaign's mean


def _points(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(0.1, 4.9, n), rng.uniform(0.1, 4.9, n), rng.uniform(-0.5, 5.0, n),
                            rng.uniform(-4.9, 4.9, n), rng.uniform(-3.0, 3.0, n), rng.uniform(0.001, 0.3, n)])


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_change_goes_back_to_the_law_parameters(seed):
    x = _points(np.random.default_rng(seed), 20)
    c = LawCoordinates(PARAMS, V, P)
    back, _ = c.to_law(c.to_sampling(x))
    np.testing.assert_allclose(back, x, rtol=1e-8, atol=1e-10)
    pressure = LawCoordinates(("d", "s", "log_pc", "r"), V, P)
    xp = x[:, [0, 1, 4, 5]]
    np.testing.assert_allclose(pressure.to_law(pressure.to_sampling(xp))[0], xp, rtol=1e-8, atol=1e-10)


def test_the_jacobian_is_the_determinant_of_the_change():
    c = LawCoordinates(PARAMS, V, P)
    z0 = c.to_sampling(_points(np.random.default_rng(3), 5))
    h = 1e-6
    for z in z0:
        cols = [(c.to_law((z + h * e)[None])[0][0] - c.to_law((z - h * e)[None])[0][0]) / (2 * h)
                for e in np.eye(z.size)]
        numeric = np.log(abs(np.linalg.det(np.array(cols).T)))
        assert c.to_law(z[None])[1][0] == pytest.approx(numeric, abs=1e-5)


def test_the_velocity_law_takes_its_values_at_the_slowest_and_fastest_speed():
    c = LawCoordinates(("d", "s", "log_vc", "r"), V)
    d, s, vc = 0.6, 1.4, 8.0
    z = c.to_sampling(np.array([[d, s, np.log(vc), 0.05]]))[0]
    law = lambda v: d + (s - d) * np.exp(-v / vc)  # noqa: E731
    assert z[0] == pytest.approx(law(V.min())) and z[1] == pytest.approx(law(V.max()))
    assert z[3] == pytest.approx(np.log(0.05))


def test_the_pressure_law_and_term_take_their_values_at_the_lowest_and_highest_pressure():
    d, s, pc = 0.7, 1.5, 0.9
    law = lambda q: d + (s - d) * np.exp(-q / pc)  # noqa: E731
    z = LawCoordinates(("d", "s", "log_pc", "r"), V, P).to_sampling(np.array([[d, s, np.log(pc), 0.05]]))[0]
    assert z[0] == pytest.approx(law(P.min())) and z[1] == pytest.approx(law(P.max()))
    amp = -0.4  # pressure+velocity: the pressure term's change from the lowest to the highest tested pressure
    z = LawCoordinates(PARAMS, V, P).to_sampling(np.array([[d, s, np.log(8.0), amp, np.log(pc), 0.05]]))[0]
    assert z[3] == pytest.approx(amp * (np.exp(-P.min() / pc) - np.exp(-P.max() / pc)))


def test_laws_without_a_spread_keep_their_parameters_but_log_r():
    x = np.array([[1.1, 0.04]])
    z = LawCoordinates(("a", "r"), V, P).to_sampling(x)
    np.testing.assert_allclose(z, [[1.1, np.log(0.04)]])
    one = LawCoordinates(PARAMS, np.full(4, 8.0), np.full(4, 1.0))
    y = np.array([[0.6, 1.4, 2.0, 0.1, 0.3, 0.05]])
    np.testing.assert_allclose(one.to_sampling(y)[:, :5], y[:, :5])


@pytest.mark.slow  # the law's prior sampled: in the default suite it kept that suite over 10 minutes (16 s in a CI run)
def test_sampling_the_prior_through_the_change_gives_the_prior_back():
    """No data: the draws of d and s must be uniform on (0, 5), log v_c uniform on its range and r half-normal
    (sd 0.1), as the law's priors say. The walkers start from the prior itself (the ensemble's stationary state),
    so a wrong Jacobian shows as a drift away from it. Without data the ensemble crosses log v_c slowly (its ends
    are thin slivers in the sampling coordinates: an autocorrelation time of 150-750 steps here, where the law's
    fits to data, which fix the law's values, take tens), so each bound is four standard errors of the quantile
    from the chain's own effective sample size (64 walkers x kept steps / the integrated autocorrelation time)."""
    c = LawCoordinates(("d", "s", "log_vc", "r"), V)
    lo, hi = LOG_VC_RANGE

    def log_prior(z):
        x, log_jac = c.to_law(z)
        ok = (np.all((x[:, :2] > 0) & (x[:, :2] < 5), axis=1) & (x[:, 2] > lo)
              & (x[:, 2] < hi) & np.all(np.isfinite(x), axis=1))
        return np.where(ok, -0.5 * (x[:, 3] / 0.1) ** 2 + log_jac, -np.inf)

    rng = np.random.default_rng(11)
    x0 = np.column_stack([rng.uniform(0, 5, 64), rng.uniform(0, 5, 64), rng.uniform(lo, hi, 64),
                          np.abs(rng.normal(0, 0.1, 64))])
    sampler = emcee.EnsembleSampler(64, 4, log_prior, vectorize=True)
    sampler.random_state = np.random.RandomState(5).get_state()
    sampler.run_mcmc(c.to_sampling(x0), 12000)
    chain = c.to_law(sampler.get_chain(discard=2000, flat=True))[0]
    tau = emcee.autocorr.integrated_time(sampler.get_chain(discard=2000), quiet=True)
    ess = 64 * 10000 / np.maximum(tau, 1.0)
    q = np.array([0.1, 0.5, 0.9])
    uniform_se = np.sqrt(q * (1 - q))  # times the width over sqrt(ess): a quantile's se under a uniform law
    for k, (a, b) in enumerate(((0.0, 5.0), (0.0, 5.0), (lo, hi))):
        np.testing.assert_allclose(np.quantile(chain[:, k], q), a + (b - a) * q,
                                   atol=4 * (b - a) * uniform_se.max() / np.sqrt(ess[k]))
    half_normal = 0.1 * np.array([0.6745, 1.6449])  # its density there: 2 phi(q / 0.1) / 0.1
    se = np.sqrt(np.array([0.25, 0.09]) / ess[3]) / (2 * np.exp(-0.5 * (half_normal / 0.1) ** 2)
                                                       / np.sqrt(2 * np.pi) / 0.1)
    np.testing.assert_allclose(np.quantile(chain[:, 3], [0.5, 0.9]), half_normal, atol=float(4 * se.max()))
