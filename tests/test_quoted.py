"""The f to quote: draws times an independent lognormal factor (the output bars' calibration)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import norm

from friction_uq.models.parameters import summarize_draws
from friction_uq.physics.bars import BAR_FORCE_CALIBRATION_SD, FORCE_RATIO_CALIBRATION_SD
from friction_uq.quoted import folded_sd, quoted_summary
from friction_uq.stats.factor import times_lognormal_factor


def _lognormal_grid(mu: float, a: float, n: int) -> np.ndarray:
    """n draws at the quantiles (j - 1/2)/n of a lognormal: a deterministic stand-in for its draws."""
    return np.exp(mu + a * norm.ppf((np.arange(n) + 0.5) / n))


def test_calibration_budget():
    # three independent 1 % terms per bar (modulus, section, gauge), two bars in the ratio
    assert BAR_FORCE_CALIBRATION_SD == pytest.approx(0.01732, abs=1e-5)
    assert FORCE_RATIO_CALIBRATION_SD == pytest.approx(0.0245, abs=1e-4)


def test_no_factor_is_the_draws_own_summary():
    x = _lognormal_grid(np.log(0.05), 0.04, 4001)
    assert times_lognormal_factor(x, 0.0) == pytest.approx(summarize_draws(x), rel=1e-12)


@pytest.mark.parametrize(("a", "s"), [(0.02, 0.0245), (0.06, 0.0245), (0.01, 0.05)])
def test_lognormal_times_lognormal_is_lognormal(a, s):
    """ln X ~ N(mu, a^2) and ln G ~ N(0, s^2): ln XG ~ N(mu, a^2 + s^2), its quantiles, mean and sd in closed form.
    The tolerance is the grid's own error (20001 draws: the grid's quantiles are within 1e-4 of the exact ones)."""
    mu, n = np.log(0.05), 20001
    got = times_lognormal_factor(_lognormal_grid(mu, a, n), s)
    b = np.hypot(a, s)
    for key, p in (("q05", 0.05), ("q50", 0.5), ("q95", 0.95)):
        assert got[key] == pytest.approx(np.exp(mu + b * norm.ppf(p)), rel=2e-4), key
    mean = np.exp(mu + b * b / 2)
    assert got["mean"] == pytest.approx(mean, rel=2e-4)
    assert got["sd"] == pytest.approx(mean * np.sqrt(np.expm1(b * b)), rel=5e-3)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.01, 0.2), min_size=2, max_size=60), st.floats(0.0, 0.1))
def test_ordered_and_inside_the_factors_reach(values, s):
    x = np.asarray(values)
    got = times_lognormal_factor(x, s)
    assert got["q05"] <= got["q50"] <= got["q95"]
    reach = np.exp(8 * s) * (1 + 1e-9)
    assert x.min() / reach <= got["q05"] and got["q95"] <= x.max() * reach
    mean_x = got["mean"] / np.exp(s * s / 2)  # E XG / E G: the draws' mean, inside their range to rounding
    assert got["sd"] >= 0 and x.min() * (1 - 1e-9) <= mean_x <= x.max() * (1 + 1e-9)


@pytest.mark.parametrize("bad", [[0.05], [0.05, -0.01], [0.05, np.nan], [0.05, np.inf]])
def test_bad_draws_are_refused(bad):
    with pytest.raises(ValueError):
        times_lognormal_factor(np.asarray(bad), 0.02)


def test_quoted_summary_uses_the_ratio_calibration():
    x = _lognormal_grid(np.log(0.05), 0.02, 4001)
    assert quoted_summary(x) == times_lognormal_factor(x, folded_sd())


def test_zero_draws_stay_at_zero():
    """A friction law clipped at 0 (pressure_friction's f_effective) gives draws of exactly 0: 0 times G is 0."""
    x = np.concatenate([np.zeros(100), _lognormal_grid(np.log(0.05), 0.02, 900)])
    got = times_lognormal_factor(x, 0.02)
    assert got["q05"] == 0.0 and 0.0 < got["q50"] < got["q95"]
    assert got["mean"] == pytest.approx(np.mean(x) * np.exp(0.02 ** 2 / 2))
    all_zero = times_lognormal_factor(np.zeros(10), 0.02)
    assert all_zero["q05"] == all_zero["q95"] == all_zero["mean"] == 0.0


def test_a_factor_per_draw_is_the_mixture_of_the_two():
    """Draws of two models with their own factors: the quantiles of the mixture of the two lognormals."""
    a, b = _lognormal_grid(np.log(0.05), 0.02, 4001), _lognormal_grid(np.log(0.06), 0.02, 4001)
    got = times_lognormal_factor(np.concatenate([a, b]), np.concatenate([np.full(a.size, 0.03), np.zeros(b.size)]))
    sa = np.hypot(0.02, 0.03)
    for key, p in (("q05", 0.05), ("q50", 0.5), ("q95", 0.95)):
        v = np.log(got[key])
        mix = 0.5 * norm.cdf((v - np.log(0.05)) / sa) + 0.5 * norm.cdf((v - np.log(0.06)) / 0.02)
        assert mix == pytest.approx(p, abs=2e-4), key


def test_what_a_model_carries_is_not_folded_in_again():
    """The stationary analysis carries none of the bars' calibration (2.45 % folded in); the whole-record fits a
    1 % gain per output gauge (2.0 %); a model with an output bar's calibration fault fitted reads f partly against
    the input bar, whose calibration none carries (the whole budget again). A mixture's draws each take their
    model's, found by the draw's source index in the weights' order; a label not found, the whole-record fits'."""
    from types import SimpleNamespace

    from friction_uq.discrepancy.diagnosed_f import folded_sd_of, headline
    from friction_uq.discrepancy.extended import Variant
    from friction_uq.discrepancy.mechanisms import MECHANISMS

    assert folded_sd() == pytest.approx(FORCE_RATIO_CALIBRATION_SD)
    # the calibration alone (model_form=0), then with the whole-record models' form (2.5 %) in quadrature
    assert folded_sd_of((), model_form=0.0) == pytest.approx(0.0200, abs=1e-4)
    assert folded_sd_of(()) == pytest.approx(math.hypot(folded_sd_of((), model_form=0.0), 0.025), rel=1e-12)
    clearance = Variant(MECHANISMS["clearance"])
    gain = Variant(MECHANISMS["gauge_gain"], "internal_output_bar")
    assert folded_sd_of((clearance,)) == folded_sd_of(())
    whole = math.hypot(folded_sd(), 0.025)  # the whole budget (3.50 %)
    assert folded_sd_of((clearance, gain)) == folded_sd_of((Variant(MECHANISMS["bar_modulus"]),)) == whole
    assert folded_sd_of((clearance, gain), model_form=0.0) == folded_sd()
    assert folded_sd_of((Variant(MECHANISMS["gauge_gain"], "input_bar"),)) == folded_sd_of(())
    x = _lognormal_grid(np.log(0.05), 0.02, 4001)
    fits = [SimpleNamespace(label="clearance", variants=(clearance,)),
            SimpleNamespace(label="gauge_gain[internal_output_bar]", variants=(gain,))]
    dg = SimpleNamespace(swap_models=(), f_prior_nu=None, mixture_f=np.concatenate([x, 1.2 * x, 0.9 * x]), causes=(), final=fits[0],
                         mixture_weights={"clearance": 0.5, "gauge_gain[internal_output_bar]": 0.3, "unknown": 0.2},
                         mixture_source=np.repeat([0, 1, 2], x.size),
                         baseline=SimpleNamespace(label="reference", variants=()),
                         rounds=[[SimpleNamespace(fit=f) for f in fits]])
    label, fx = headline(dg)
    assert label == "mixture of clearance (0.50), gauge_gain[internal_output_bar] (0.30), unknown (0.20)"
    per_draw = np.repeat([folded_sd_of(()), whole, folded_sd_of(())], x.size)
    assert fx == times_lognormal_factor(dg.mixture_f, per_draw)
    assert fx != times_lognormal_factor(dg.mixture_f, folded_sd_of(()))  # the gain model's draws fold in more
