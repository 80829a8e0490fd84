"""When a difference in expected log predictive density (ELPD) decides: one rule, one standard error.

Every comparison of models in the package (``diagnose`` naming a cause, the two-bar diagnosis naming a
mechanism, the campaign choosing a friction law and flagging a set-up) reads its verdict here (the campaign's
naming of laws opens one more route beside it, on the stacking weights: :meth:`.weights.WeightRule.ruled_out`):

* :func:`paired_difference`: ELPD(a) - ELPD(b) from the two models' pointwise values over the same
  observations (blocks of a record, tests of a campaign), with the standard error of a sum of paired
  differences, sqrt(n var(d)) with the sample variance (``ddof=1``; Vehtari, Gelman & Gabry 2017, eq. 24
  uses the sample variance too);
* :class:`DecisionRule`: the difference counts only when it is large in itself (above ``min_delpd``, 4 by
  default: below that two models predict about alike, Sivula et al. 2022) and large against its standard
  error: above ``n_se`` standard errors, or, when the number ``n`` of paired values is small and given, the
  97.5 % quantile of Student's t with n - 1 degrees of freedom (the SE is itself estimated from those n
  differences: ten tests need 2.26 SE where many need 1.96). A caller may open a *strong* route for a
  difference above ``strong`` and above one SE (``diagnose`` after the whole-record check found a misfit:
  evidence concentrated in a few blocks of a record that the model demonstrably misses).

>>> RULE.decisive(10.0, 4.0), RULE.decisive(10.0, 6.0), RULE.decisive(3.9, 0.1)
(True, False, False)
>>> RULE.decisive(4.3, 2.1, n=10), RULE.decisive(500.0, 400.0, strong=40.0)
(False, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import t as student_t


def paired_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """ELPD(a) - ELPD(b) and its standard error from pointwise values over the same observations.

    >>> paired_difference(np.array([1.0, 3.0]), np.array([0.0, 0.0]))
    (4.0, 2.0)
    """
    d = np.asarray(a, float) - np.asarray(b, float)
    if d.shape != np.shape(b) or d.ndim != 1:
        raise ValueError(f"pointwise ELPDs of shapes {np.shape(a)} and {np.shape(b)}: need two equal 1-d arrays")
    if d.size < 2:
        return float(d.sum()), float("nan")
    return float(d.sum()), math.sqrt(d.size * float(np.var(d, ddof=1)))


@dataclass(frozen=True)
class DecisionRule:
    """A difference in ELPD is decisive (module docstring)."""

    min_delpd: float = 4.0
    n_se: float = 2.0

    def factor(self, n: int | None = None) -> float:
        """How many standard errors the difference must exceed: ``n_se``, or t(0.975, n - 1) for ``n`` paired
        values (n >= 2)."""
        return self.n_se if n is None or n < 2 else float(student_t.ppf(0.975, n - 1))

    def decisive(self, d: float, se: float, *, n: int | None = None, strong: float | None = None) -> bool:
        """Whether ELPD difference ``d`` with standard error ``se`` decides; ``strong``: the strong route's
        threshold (None: closed)."""
        if not d > self.min_delpd:
            return False
        return bool(d > self.factor(n) * se or (strong is not None and d > strong and d > se))


#: The package's rule: dELPD > 4 and > 2 SE (t(0.975, n - 1) SE over n paired values when n is given).
RULE = DecisionRule()
