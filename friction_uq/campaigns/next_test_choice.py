"""Which test to run next: the expected information one more test brings on which law holds.

For a campaign whose laws are not separated, each candidate test (a set-up of the campaign at a
striker speed giving a sliding speed V within the tested range, its wall pressure p read from the
set-up's own (V, p) line) is scored by the mutual information between the law K and the test's
outcome y (Lindley 1956; for telling models apart, Box and Hill 1967):

    I(K; y) = H(sum_k w_k p_k(y)) - sum_k w_k H(p_k(y)),

with w_k equal over the laws the verdict names (the data do not separate them: the question is which of
them holds; without such a list, the stacking weights of the laws still in play, renormalised) and p_k the law's
posterior predictive of the new test's value: the law's draws at (V, p) for that set-up (with its
calibration offset), widened by the law's test-to-test scatter and by a test's own uncertainty (the
median of the campaign's), each taken as normal. H of the mixture is integrated on a grid (the
outcome is one number: a quadrature is exact to the grid's resolution and has no Monte Carlo noise
to rank candidates by). I is in nats, at most the entropy of the weights (log 2 for two laws equally
weighted): a test where the laws predict the same value brings nothing, one where their predictions
do not overlap settles the question.

When the laws read each test's change across its window (the slip law is compared, :mod:`.laws`), the
outcome is two numbers, the level and that change, independent given the law: a slip law and a velocity
law predict the same level at every candidate and differ only in the change. Each law's predictive of the
change is its draws' ln(y(S_2) / y(S_1)) over the new window's halves (the set-up's slip per speed, and its
windows' slip across the halves per speed), widened by a test's own error of the change (the median of the
set-up's), the floor and the relative term of the laws' likelihood. H is then integrated on a 2-D grid.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.special import logsumexp

from .laws import TREND_FLOOR, TREND_REL, Fit, law_mean

#: Laws with at least this stacking weight are still in play.
IN_PLAY = 0.05
#: Sliding speeds tried per set-up, over the campaign's tested range.
GRID = 9


@dataclass(frozen=True)
class Candidate:
    setup: str
    V: float
    p: float
    information: float  # nats


def _draws(fit: Fit) -> dict[str, np.ndarray]:
    x = fit.draws[:: max(1, len(fit.draws) // 400)]
    return {k: x[:, i:i + 1] for i, k in enumerate(fit.model.params)}


def _predictive(fit: Fit, setup: str, V: float, p: float, test_sd: float) -> tuple[float, float]:
    """Mean and variance of the law's predictive of one new test (in the fit's units, y = kappa / kappa_bar)."""
    th = _draws(fit)
    y = law_mean(fit.model.law, th, np.array([V]), np.array([(p - fit.p_ref) / fit.p_ref]),
                 fit.data.slip_at(setup, np.array([V])))
    y = (y * fit.model.setup_scale(th, [setup]))[:, 0]
    var = float(np.var(y) + np.mean((th["r"][:, 0] * y) ** 2) + test_sd**2)
    return float(np.mean(y)), var


def _change_predictive(fit: Fit, setup: str, V: float, p: float) -> tuple[float, float]:
    """Mean and variance of the law's predictive of the new test's change across its window (module docstring)."""
    d = fit.data
    on = np.array([s == setup for s in d.setups])
    spread = float(np.median(((d.halves[:, 1, 0] - d.halves[:, 0, 0]) / d.V)[on])) * V  # slip across the halves
    S = float(d.slip_at(setup, V))
    th = _draws(fit)
    halves = [law_mean(fit.model.law, th, np.array([V]), np.array([(p - fit.p_ref) / fit.p_ref]),
                       np.array([S + sign * spread / 2])) for sign in (-1.0, 1.0)]
    with np.errstate(divide="ignore", invalid="ignore"):
        pred = np.log(halves[1][:, 0] / halves[0][:, 0])
    pred = pred[np.isfinite(pred)] if np.isfinite(pred).any() else np.zeros(1)
    own = float(np.median(d.trend[on, 1]))
    var = float(np.var(pred) + own**2 + TREND_FLOOR**2 + np.mean((TREND_REL * pred) ** 2))
    return float(np.mean(pred)), var


def information(means: np.ndarray, variances: np.ndarray, weights: np.ndarray, *, points: int = 4001) -> float:
    """I(K; y) for a mixture of normals (module docstring), the mixture's entropy by the trapezoid rule; ``means``
    and ``variances`` (K,) for one outcome, (K, 2) for two independent given the law (a 2-D grid of
    ``points // 20`` per axis)."""
    m, v = np.asarray(means, float), np.asarray(variances, float)
    w = weights / weights.sum()
    if m.ndim == 1:
        m, v = m[:, None], v[:, None]
    n = points if m.shape[1] == 1 else max(101, points // 20)
    sd = np.sqrt(v)
    axes = [np.linspace(float(np.min(m[:, j] - 10 * sd[:, j])), float(np.max(m[:, j] + 10 * sd[:, j])), n)
            for j in range(m.shape[1])]
    # log density of each law's normal on the grid: the sum over independent outcomes
    log_comp = sum(np.reshape(-0.5 * (ax[:, None] - m[None, :, j]) ** 2 / v[None, :, j]
                              - 0.5 * np.log(2 * np.pi * v[None, :, j]), (1,) * j + (n,) + (1,) * (m.shape[1] - 1 - j)
                              + (len(w),)) for j, ax in enumerate(axes))
    log_mix = logsumexp(log_comp + np.log(w), axis=-1)
    integrand = np.exp(log_mix) * log_mix
    for ax in reversed(axes):
        integrand = np.trapezoid(integrand, ax, axis=-1)
    h_mix = -float(integrand)
    h_each = float(np.sum(w * 0.5 * np.sum(np.log(2 * np.pi * np.e * v), axis=1)))
    return max(0.0, h_mix - h_each)


def _in_play(weights: dict[str, float], named: Sequence[str] | None) -> list[str]:
    """The laws the question is about: those the verdict names, else those with :data:`IN_PLAY` of the weight."""
    return list(named) if named and len(named) > 1 else [k for k, w in weights.items() if w >= IN_PLAY]


def rank_next_tests(fits: dict[str, Fit], weights: dict[str, float],
                    named: Sequence[str] | None = None) -> list[Candidate]:
    """Every candidate test, the most informative first; empty when fewer than two laws are in play. ``named``:
    the laws the verdict does not separate (equally weighted; module docstring). Stacking can put nearly all
    its weight on one of laws whose ELPDs are not decisively apart, which would leave nothing to ask."""
    play = [k for k in _in_play(weights, named) if k in fits]
    if len(play) < 2:
        return []
    w = np.ones(len(play)) if named and len(named) > 1 else np.array([weights[k] for k in play])
    data = fits[play[0]].data
    test_sd = float(np.median(data.kappa_sd)) / fits[play[0]].kbar
    out = []
    for setup in sorted(set(data.setups)):
        on = np.array([s == setup for s in data.setups])
        coef = np.polyfit(data.V[on], data.p[on], 1) if on.sum() > 1 else np.array([0.0, data.p[on][0]])
        for V in np.linspace(data.V.min(), data.V.max(), GRID):
            p = float(np.polyval(coef, V))
            pred = [_predictive(fits[k], setup, float(V), p, test_sd) for k in play]
            m, v = np.array([a for a, _ in pred]), np.array([b for _, b in pred])
            if data.reads_window_changes:  # the change across the window: a second outcome
                change = [_change_predictive(fits[k], setup, float(V), p) for k in play]
                m = np.column_stack([m, [a for a, _ in change]])
                v = np.column_stack([v, [b for _, b in change]])
            out.append(Candidate(setup, float(V), p, information(m, v, w)))
    return sorted(out, key=lambda c: -c.information)


def advice(cands: list[Candidate], weights: dict[str, float], named: Sequence[str] | None = None) -> str | None:
    """One sentence for the summary, or None when the laws are separated already."""
    if not cands:
        return None
    best = cands[0]
    play = _in_play(weights, named)
    return (f"the most informative next test: set-up {best.setup} at a sliding speed of {best.V:.1f} m/s "
            f"(wall pressure about {best.p * 1e-6:.0f} MPa): it is expected to bring {best.information:.2f} nats "
            f"on which of {', '.join(play)} holds (the least informative candidate: {cands[-1].information:.2f})")
