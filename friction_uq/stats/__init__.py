"""Statistics shared by every consumer: Pareto-smoothed importance sampling (:mod:`.psis`).

One implementation, tested once, used by the whole-record fits, the leave-one-out ELPDs and the
prior sensitivity, so that the sign convention of the underlying library is handled in one place.
"""

from .psis import PSIS, khat_threshold, psis, weighted_quantiles

__all__ = ["PSIS", "khat_threshold", "psis", "weighted_quantiles"]
