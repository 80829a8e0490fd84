"""The one statistics layer under the data flow: every stage that weighs evidence uses it, none has its own.

* :mod:`.ar1`: stationary AR(1) Gaussian noise: exact log-likelihood, conditionals, an offset error
  integrated out, a block's density given the rest of its series, the sd of a mean of AR(1) samples;
* :mod:`.psis`: Pareto-smoothed importance sampling, the one wrapper of ``arviz_stats``' ``psislw``
  (whose sign convention is handled there and nowhere else), weighted quantiles;
* :mod:`.laplace`: a Laplace fit's pieces in unbounded coordinates: finite-difference Hessian,
  central-difference Jacobian (Gauss-Newton), the robust sandwich covariance, normal draws and
  their importance weights against the exact posterior;
* :mod:`.exact`: the exact posterior behind a Laplace approximation (importance sampling, a second
  proposal, emcee) with the sandwich adjustment;
* :mod:`.elpd`: PSIS leave-one-out ELPD from per-draw pointwise log densities, and the weighted mean
  of a density over draws;
* :mod:`.decision`: the rule that says when an ELPD difference decides (:data:`RULE`) and the standard
  error of a paired difference;
* :mod:`.trimmed`: an ELPD difference with the points most in the first model's favour left out (is the
  evidence spread over the data, or carried by a few points?);
* :mod:`.weights`: stacking weights and the rule that reads a verdict from them;
* :mod:`.streams`: named random streams (one seeded Generator per purpose and model) and the
  legacy seeding emcee needs.

Used by the stationary likelihood, the whole-record fits, the leave-one-out ELPDs, the prior
sensitivity, ``diagnose``, the two-bar diagnosis and the campaign's law comparison. What is physics
(forward models, mechanisms, priors of a test) stays with them.
"""

from .decision import RULE, DecisionRule, paired_difference
from .psis import PSIS, khat_threshold, psis, weighted_quantiles
from .weights import WeightRule, stacking_weights

__all__ = ["PSIS", "RULE", "DecisionRule", "WeightRule", "khat_threshold", "paired_difference", "psis",
           "stacking_weights", "weighted_quantiles"]
