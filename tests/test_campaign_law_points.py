"""The points a friction law's likelihood reads (friction_uq.campaigns.law_points), stacked into one evaluation:
the law at each point set is the law evaluated there alone, and a fit's likelihood on other data reads that data's
points (its own steps), as a fit on that data does."""

from __future__ import annotations

import numpy as np
import pytest

from friction_uq.campaigns.law_data import LawData
from friction_uq.campaigns.law_forms import law_mean
from friction_uq.campaigns.law_points import STEP, LawPoints
from friction_uq.campaigns.law_windows import halves_points
from friction_uq.campaigns.laws import Fit, Model


def _data(n: int = 4) -> LawData:
    V = np.linspace(5.0, 14.0, n)
    halves = np.stack([np.stack([V * 1.5e-4, V * 0.99, np.full(n, 1.01)], axis=1),
                       np.stack([V * 3.0e-4, V * 1.01, np.full(n, 0.99)], axis=1)], axis=1)
    return LawData([f"T{i}" for i in range(n)], ["A"] * n, 1.0 - 0.02 * np.arange(n), np.full(n, 0.01), V,
                   np.full(n, 0.1), np.linspace(60e6, 140e6, n), np.full(n, 2e6), slip=V * 2.2e-4,
                   trend=np.tile([[-0.01, 0.005]], (n, 1)), halves=halves)


THETA = {"d": np.array([[0.8], [1.1]]), "s": np.array([[1.3], [0.9]]), "log_vc": np.log([[8.0], [20.0]]),
         "log_pc": np.log([[0.7], [3.0]]), "amp_p": np.array([[0.1], [-0.2]]), "log_sc": np.log([[2e-3], [5e-4]]),
         "a": np.array([[1.0], [0.9]])}


@pytest.mark.parametrize("law", ["constant", "velocity", "pressure", "slip", "pressure+velocity"])
def test_each_point_set_is_the_law_evaluated_there_alone(law):
    d, p_ref = _data(), 100e6
    at = LawPoints(law, d, p_ref).evaluate(THETA)
    p_rel, hV = (d.p - p_ref) / p_ref, STEP * np.maximum(d.V, 1.0)
    S = d.slip if law == "slip" else None
    alone = {"mean": law_mean(law, THETA, d.V, p_rel, S), "V+": law_mean(law, THETA, d.V + hV, p_rel, S),
             "p-": law_mean(law, THETA, d.V, p_rel - STEP, S)}
    if law == "slip":
        alone["S+"] = law_mean(law, THETA, d.V, p_rel, d.slip + STEP * d.slip)
    alone["first"], alone["second"] = (law_mean(law, THETA, V, p, S_h if law == "slip" else None)
                                       for V, p, S_h in halves_points(d, p_ref))
    for key, want in alone.items():
        np.testing.assert_array_equal(at[key], np.broadcast_to(want, (2, d.n)))
    assert ("S+" in at) == (law == "slip")


def test_the_likelihood_on_other_data_reads_their_points():
    """Fit.pointwise(x, data) is the likelihood a fit on ``data`` computes (the LOO's held-out test): the slopes'
    steps are that data's, not the fitted data's."""
    d = _data(4)
    held_out = d.select(np.arange(4) == 3)
    model = Model("velocity")
    fit = Fit(model, d.drop(3), kbar=1.0, p_ref=100e6, seed=1, nsteps=2, burn=1, max_steps=2)
    other = Fit(model, held_out, kbar=1.0, p_ref=100e6, seed=1, nsteps=2, burn=1, max_steps=2)
    x = np.array([[0.8, 1.3, np.log(8.0), 0.02], [1.1, 0.9, np.log(20.0), 0.05]])
    np.testing.assert_array_equal(fit.pointwise(x, held_out), other.pointwise(x))


def test_the_prior_is_the_documented_one_at_and_beyond_each_support():
    """laws' docstring: levels uniform on (0, 5), amp_p on (-5, 5), log scales on their ranges, cal ~ N(0, 0.03),
    delta ~ N(0, 0.3) (both above -1), r half-normal(0.1) on [0, inf)."""
    from friction_uq.campaigns.law_forms import LOG_PC_RANGE

    d = _data(4)
    model = Model("pressure+velocity", "B", ("B",))
    fit = Fit(model, d, kbar=1.0, p_ref=100e6, seed=1, nsteps=2, burn=1, max_steps=2)
    assert model.params == ("d", "s", "log_vc", "amp_p", "log_pc", "delta", "r")
    x = np.array([0.8, 1.3, np.log(8.0), 0.1, 0.0, 0.06, 0.02])
    want = -0.5 * (0.06 / 0.3) ** 2 - 0.5 * (0.02 / 0.1) ** 2
    assert fit.log_prior(x[None])[0] == pytest.approx(want, rel=1e-12)
    at_zero = x.copy()
    at_zero[6] = 0.0
    assert np.isfinite(fit.log_prior(at_zero[None])[0])
    outside = [(0, 0.0), (1, 5.0), (2, np.log(300.0)), (3, -5.0), (4, LOG_PC_RANGE[1]), (5, -1.0), (6, -1e-9),
               (0, np.nan)]
    for k, v in outside:
        y = x.copy()
        y[k] = v
        assert fit.log_prior(y[None])[0] == -np.inf, (k, v)
