"""Pointwise expected log predictive density from posterior draws: PSIS leave-one-out, and the plain
and weighted Monte Carlo means of a density over draws.

The points are whatever a consumer leaves out (blocks of a record, tests of a campaign); the
per-draw log densities of each point are the consumer's. The difference of two models' pointwise
values and the rule that reads it are :mod:`.decision`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .psis import psis


@dataclass(frozen=True)
class Loo:
    """PSIS-LOO: each point's leave-one-out log predictive density and the Pareto k of its weights."""

    pointwise: np.ndarray
    pareto_k: np.ndarray

    @property
    def pareto_k_max(self) -> float:
        return float(np.nanmax(self.pareto_k))


def weighted_log_mean(log_density: np.ndarray, log_weights: np.ndarray) -> np.ndarray:
    """log sum_s w_s p_s along the last axis (draws), for normalised log weights: the posterior mean of a
    density over weighted draws."""
    return np.logaddexp.reduce(log_weights + log_density, axis=-1)


def psis_loo(log_lik: np.ndarray, log_weights: np.ndarray) -> Loo:
    """PSIS-LOO from per-draw pointwise log densities (S, P) and the draws' log importance weights (S,)
    (equal weights for posterior draws): the leave-one-out ratios are the weights over each point's density.

    >>> ll = np.log(np.full((4, 2), 0.5))
    >>> psis_loo(ll, np.zeros(4)).pointwise
    array([-0.69314718, -0.69314718])
    """
    ll = np.asarray(log_lik, float)
    res = psis((np.asarray(log_weights, float)[:, None] - ll).T)  # leave-one-out importance ratios, (P, S)
    return Loo(weighted_log_mean(ll.T, res.log_weights), np.asarray(res.pareto_k))
