"""Statistics shared by every consumer: Pareto-smoothed importance sampling (:mod:`.psis`), the exact
posterior behind a Laplace approximation with its sandwich adjustment (:mod:`.exact`), and stacking
weights with the rule that reads a verdict from them (:mod:`.weights`), and the rule that says when a
difference in ELPD decides, with its standard error (:mod:`.decision`).

One implementation, tested once, used by the whole-record fits, the leave-one-out ELPDs, the
prior sensitivity, ``diagnose`` and the campaign's law comparison, so that the sign convention of the
underlying library is handled in one place.
"""

from .decision import RULE, DecisionRule, paired_difference
from .psis import PSIS, khat_threshold, psis, weighted_quantiles
from .weights import WeightRule, stacking_weights

__all__ = ["PSIS", "RULE", "DecisionRule", "WeightRule", "khat_threshold", "paired_difference", "psis",
           "stacking_weights", "weighted_quantiles"]
