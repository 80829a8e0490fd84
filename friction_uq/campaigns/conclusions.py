"""What a campaign's analysis concludes, in one object: the tests' draws, the pooled values, the laws'
comparison and fits, the flags and the sentences (filled by :func:`friction_uq.campaigns.analysis.analyse_tests`,
read by the outputs, the report and the law comparison)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .draws import RecordPosterior
from .laws import Fit, LawData, law_mean
from .next_test_choice import Candidate
from .pooling import Pooled


@dataclass
class CampaignAnalysis:
    tests: list[RecordPosterior]
    pooled: dict[str, Pooled]
    tallies: dict[str, dict[str, object]]
    law_data: LawData | None = None
    ranking: list[dict[str, object]] = field(default_factory=list)
    best: str | None = None
    chosen: str | None = None
    law_posterior: dict[str, dict[str, float]] = field(default_factory=dict)
    law_draws: dict[str, np.ndarray] = field(default_factory=dict)
    fits: dict[str, Fit] = field(default_factory=dict)
    nu: tuple[float, float] = (float("nan"), float("nan"))
    flagged: list[dict[str, object]] = field(default_factory=list)
    sentences: list[str] = field(default_factory=list)
    #: each law's stacking weight (friction_uq.stats.stacking_weights)
    weights: dict[str, float] = field(default_factory=dict)
    #: candidate next tests, the most informative first (.next_test_choice), when the laws are not separated
    next_tests: list[Candidate] = field(default_factory=list)
    #: law -> the name of its model in ``fits`` that the weights are of (the law, or with set-ups left out)
    law_models: dict[str, str] = field(default_factory=dict)
    #: the stationary analysis's pooled f when ``pooled["f"]`` is f under the diagnosed models (else empty)
    pooled_stationary: dict[str, Pooled] = field(default_factory=dict)
    #: two set-ups, none flagged by the ELPD: every law with and without the second set-up's offset, compared
    #: (:meth:`~.law_comparison.LawComparison.offset_alternative`), with the sentence where a law with a pressure term
    #: is named or the set-up is flagged by every law with and without the offset (those without ruled out); else empty
    pressure_or_setup: dict[str, object] = field(default_factory=dict)
    #: f pooled on ``pooled["f"]``'s basis without the tests whose runs warned (:mod:`.warned`); None when none did
    pooled_without_warned: Pooled | None = None

    def f_curve(self, model: str, V: np.ndarray, p: np.ndarray, setup: str, *, n: int = 400,
                slip: np.ndarray | None = None) -> np.ndarray:
        """Draws of f along (V, p) for one set-up under a fitted model, at the campaign's nu: (draws, len(V)).
        ``slip`` (m): the mean slips along the curve; without it, V times the set-up's slip per speed."""
        fit = self.fits[model]
        x = fit.draws[:: max(1, len(fit.draws) // n)]
        th = {k: x[:, i:i + 1] for i, k in enumerate(fit.model.params)}
        y = law_mean(fit.model.law, th, np.asarray(V, float), (np.asarray(p, float) - fit.p_ref) / fit.p_ref,
                     fit.data.slip_at(setup, V) if slip is None else np.asarray(slip, float))
        y = y * fit.model.setup_scale(th, [setup] * len(np.atleast_1d(V)))
        return y * fit.kbar * fit.data.to_f(self.nu[0])
