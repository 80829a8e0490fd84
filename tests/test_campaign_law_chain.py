"""How long a friction law's emcee chain runs (friction_uq.campaigns.law_chain, read by laws.Fit): on from its first
length until the part kept is TAU_MULTIPLE autocorrelation times long, up to MAX_STEPS. The time estimate is checked on an AR(1)
chain, whose integrated autocorrelation time is (1 + rho) / (1 - rho) in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from friction_uq.campaigns.law_chain import (BURN_TAUS, MAX_STEPS, TAU_MULTIPLE, chain_length_needed,
                                            max_autocorr_time)
from friction_uq.campaigns.laws import Fit, LawData, Model


def _ar1_chain(rho: float, steps: int, walkers: int, dims: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    e = rng.standard_normal((steps, walkers, dims)) * np.sqrt(1 - rho**2)
    x = np.empty_like(e)
    x[0] = rng.standard_normal((walkers, dims))
    for t in range(1, steps):
        x[t] = rho * x[t - 1] + e[t]
    return x


def test_the_time_of_an_ar1_chain_is_its_closed_form():
    """rho = 0.8: tau = 9 steps. From 20000 steps of 16 walkers the estimate's relative sd is about
    sqrt(2 (2 c tau) / (N W)) ~ 1 % (Sokal's window, c = 5); 5 % allowed."""
    tau = max_autocorr_time(_ar1_chain(0.8, 20000, 16, 2, seed=4))
    assert tau == pytest.approx((1 + 0.8) / (1 - 0.8), rel=0.05)


def test_the_largest_time_over_the_parameters_is_taken_and_a_still_one_left_out():
    chain = _ar1_chain(0.5, 8000, 8, 2, seed=5)
    chain[:, :, 1] = _ar1_chain(0.9, 8000, 8, 1, seed=6)[:, :, 0]
    still = np.concatenate([chain, np.ones((8000, 8, 1))], axis=2)  # a parameter that never moves
    assert max_autocorr_time(still) == pytest.approx(19.0, rel=0.1)
    assert np.isnan(max_autocorr_time(np.ones((100, 4, 1))))
    assert np.isnan(max_autocorr_time(chain[:1]))


def test_the_length_asked_is_the_burn_in_and_fifty_times_the_time():
    for tau, burn in ((3.0, 300), (40.0, 300), (250.0, 100)):
        length, discard = chain_length_needed(tau, burn)
        assert discard == max(burn, int(np.ceil(BURN_TAUS * tau)))
        assert length - discard == int(np.ceil(TAU_MULTIPLE * tau))
    assert chain_length_needed(float("nan"), 300) == (0, 300)


def _data(n: int = 6, seed: int = 2) -> LawData:
    rng = np.random.default_rng(seed)
    k = 0.04 * (1 + 0.02 * rng.standard_normal(n))
    return LawData([f"T{i}" for i in range(n)], ["A"] * n, k, 0.001 * np.ones(n), np.linspace(6, 12, n),
                   0.01 * np.ones(n), np.linspace(8e7, 1.2e8, n), 1e6 * np.ones(n))


def test_a_chain_stops_once_long_enough_and_never_beyond_its_cap():
    """The constant law on six tests mixes in tens of steps: its chain stops before the cap, with the part kept at
    least 50 of its times long. Capped at 1500 steps, a chain stops there whatever it would ask."""
    data = _data()
    fit = Fit(Model("constant"), data, kbar=0.04, p_ref=1e8, seed=3, nsteps=500, burn=100)
    assert 500 <= fit.steps < MAX_STEPS
    assert fit.steps - fit.discarded >= TAU_MULTIPLE * fit.tau
    assert fit.draws.shape[0] == len(range(0, fit.steps - fit.discarded, 5)) * 32
    capped = Fit(Model("velocity"), data, kbar=0.04, p_ref=1e8, seed=3, nsteps=500, burn=100, max_steps=1500)
    assert capped.steps <= 1500


def test_the_chain_and_its_draws_follow_the_seed():
    data = _data()
    a, b = (Fit(Model("constant"), data, kbar=0.04, p_ref=1e8, seed=9, nsteps=500, burn=100) for _ in range(2))
    assert a.steps == b.steps and np.array_equal(a.draws, b.draws)
