"""The coordinates the friction laws are sampled in (friction_uq.campaign.law_coordinates): a change of variables
with its Jacobian, so the same posterior; checked by a round trip, the Jacobian against finite differences, and
sampling the prior through the change."""

from __future__ import annotations

import emcee
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.campaign.law_coordinates import LawCoordinates
from friction_uq.campaign.laws import LOG_VC_RANGE

PARAMS = ("d", "s", "log_vc", "c", "r")
V = np.array([5.5, 7.0, 9.0, 12.5])


def _points(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(0.1, 4.9, n), rng.uniform(0.1, 4.9, n), rng.uniform(-0.5, 5.0, n),
                            rng.normal(0, 1, n), rng.uniform(0.001, 0.3, n)])


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_change_goes_back_to_the_law_parameters(seed):
    x = _points(np.random.default_rng(seed), 20)
    c = LawCoordinates(PARAMS, V)
    back, _ = c.to_law(c.to_sampling(x))
    np.testing.assert_allclose(back, x, rtol=1e-8, atol=1e-10)


def test_the_jacobian_is_the_determinant_of_the_change():
    c = LawCoordinates(PARAMS, V)
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


def test_laws_without_a_speed_term_or_one_speed_keep_their_parameters_but_log_r():
    x = np.array([[1.1, 0.2, 0.04]])
    z = LawCoordinates(("a", "c", "r"), V).to_sampling(x)
    np.testing.assert_allclose(z, [[1.1, 0.2, np.log(0.04)]])
    one = LawCoordinates(PARAMS, np.full(4, 8.0))
    y = np.array([[0.6, 1.4, 2.0, 0.1, 0.05]])
    np.testing.assert_allclose(one.to_sampling(y)[:, :4], y[:, :4])


def test_sampling_the_prior_through_the_change_gives_the_prior_back():
    """No data: the draws of d and s must be uniform on (0, 5), log v_c uniform on its range and r half-normal
    (sd 0.1), as the law's priors say. 64 walkers x 4000 steps, the first 1000 left out; each walker's draws are
    correlated over tens of steps, so the bounds below are a few times the standard error of a quantile from a
    few thousand independent draws (about 0.05 on (0, 5))."""
    c = LawCoordinates(("d", "s", "log_vc", "r"), V)

    def log_prior(z):
        x, log_jac = c.to_law(z)
        ok = (np.all((x[:, :2] > 0) & (x[:, :2] < 5), axis=1) & (x[:, 2] > LOG_VC_RANGE[0])
              & (x[:, 2] < LOG_VC_RANGE[1]) & np.all(np.isfinite(x), axis=1))
        return np.where(ok, -0.5 * (x[:, 3] / 0.1) ** 2 + log_jac, -np.inf)

    rng = np.random.default_rng(11)
    x0 = np.column_stack([rng.uniform(0.5, 4.5, 64), rng.uniform(0.5, 4.5, 64), rng.uniform(0, 4, 64),
                          np.abs(rng.normal(0, 0.1, 64))])
    sampler = emcee.EnsembleSampler(64, 4, log_prior, vectorize=True)
    sampler.random_state = np.random.RandomState(5).get_state()
    sampler.run_mcmc(c.to_sampling(x0), 4000)
    x = c.to_law(sampler.get_chain(discard=1000, flat=True))[0]
    for k in (0, 1):
        np.testing.assert_allclose(np.quantile(x[:, k], [0.1, 0.5, 0.9]), [0.5, 2.5, 4.5], atol=0.25)
    lo, hi = LOG_VC_RANGE
    np.testing.assert_allclose(np.quantile(x[:, 2], [0.1, 0.5, 0.9]), lo + (hi - lo) * np.array([0.1, 0.5, 0.9]),
                               atol=0.35)
    np.testing.assert_allclose(np.quantile(x[:, 3], [0.5, 0.9]), 0.1 * np.array([0.6745, 1.6449]), atol=0.012)
