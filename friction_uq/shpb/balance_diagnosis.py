"""Name the bar-level causes of a two-bar record's force-balance misfit, by forward selection on ELPD.

Rule. Start from the nominal model (:mod:`.balance`). At each step fit the current model extended
by each mechanism of :data:`~.mechanisms.MECHANISMS` not yet in it (:func:`~.fit.fit_balance`) and
compare each with the current model by block-LOO ELPD. The best one is added, and named a cause,
only when the evidence is decisive under the package's rule (:data:`friction_uq.stats.RULE`: dELPD > 4
and > 2 standard errors). Another candidate that is also decisive against the current model but not decisively
worse than the best (its dELPD to the best within the same rule) is recorded as not separable
from it by this record. Selection stops at the first step where no candidate is decisive.

With the gauges at equal distances from the specimen, the balance tests the ratio of the two
channels' gains only (a gain common to both cancels): ``gauge_gain`` puts the error on the
transmitted channel because the file's two statements of the input gain agree (200, 200) and
those of the transmitted gain do not (200, 500).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..discrepancy.block_loo import elpd_difference
from ..stats import RULE
from .balance import BalanceObservation
from .balance_fit import BLOCK, N_DRAWS, BalanceFit, fit_balance
from .balance_mechanisms import MECHANISMS, combine


@dataclass(frozen=True)
class Candidate:
    """One mechanism tried on top of the current model at a selection step."""

    mechanism: str
    fit: BalanceFit
    delpd: float
    se: float

    @property
    def decisive(self) -> bool:
        return RULE.decisive(self.delpd, self.se)


@dataclass(frozen=True)
class Step:
    """One selection step: the model extended, the candidates (best first), what was added."""

    base: BalanceFit
    candidates: tuple[Candidate, ...]
    added: str | None
    not_separable: tuple[str, ...]


@dataclass(frozen=True)
class BalanceDiagnosis:
    """The result: the nominal and final fits, every step, the named causes."""

    nominal: BalanceFit
    final: BalanceFit
    steps: tuple[Step, ...]
    causes: tuple[str, ...]
    not_separable: tuple[str, ...]

    def gain(self) -> tuple[float, float]:
        """dELPD of the final model over the nominal one, and its standard error."""
        return elpd_difference(self.final.elpd, self.nominal.elpd)


def diagnose_balance(
    obs: BalanceObservation,
    *,
    mechanisms: Iterable[str] | None = None,
    seed: int = 0,
    n_draws: int = N_DRAWS,
    block: float = BLOCK,
    scaled_noise: bool = True,
) -> BalanceDiagnosis:
    """Forward selection of bar-level mechanisms (module docstring). Same seed, same result."""
    pool = list(MECHANISMS if mechanisms is None else mechanisms)
    combine(pool)  # refuses unknown names
    rng = np.random.default_rng(seed)

    def fit(names: list[str]) -> BalanceFit:
        return fit_balance(obs, combine(names), rng=rng, n_draws=n_draws, block=block, scaled_noise=scaled_noise)

    current: list[str] = []
    nominal = base = fit(current)
    steps: list[Step] = []
    not_separable: list[str] = []
    while len(current) < len(pool):
        cands = []
        for name in (m for m in pool if m not in current):
            f = fit([*current, name])
            d, se = elpd_difference(f.elpd, base.elpd)
            cands.append(Candidate(name, f, d, se))
        cands.sort(key=lambda c: -c.delpd)
        best = cands[0]
        if not best.decisive:
            steps.append(Step(base, tuple(cands), None, ()))
            break
        tied = tuple(c.mechanism for c in cands[1:]
                     if c.decisive and not RULE.decisive(*elpd_difference(best.fit.elpd, c.fit.elpd)))
        steps.append(Step(base, tuple(cands), best.mechanism, tied))
        not_separable.extend(tied)
        current.append(best.mechanism)
        base = best.fit
    return BalanceDiagnosis(nominal, base, tuple(steps), tuple(current), tuple(not_separable))
