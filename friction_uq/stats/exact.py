"""The exact posterior behind a normal approximation, and its spread made robust to a model that misses.

A model fitted by a Laplace approximation (mode, Gauss-Newton covariance ``cov_laplace`` in unbounded
coordinates) is checked and corrected in two steps:

1. **Exact shape.** Draws of a normal at the mode with the robust covariance (wider than the exact
   posterior's when the model misses, equal when it does not: a proposal that covers the target)
   are weighted by the exact log posterior over the proposal's density and Pareto-smoothed
   (:func:`~.psis.psis`). When Pareto k is at most :func:`~.psis.khat_threshold` of the number of
   draws (0.57 for 200; never above 0.7) the weighted draws are the exact
   posterior, resampled to equal weights. Otherwise a second proposal, a Student-t (5 degrees of
   freedom) with the weighted draws' mean and 1.5 times their covariance, is tried; if its k too is
   above the limit, the posterior is sampled with emcee (affine-invariant ensemble, walkers started
   from the best-weighted draws).
2. **Robust spread.** A likelihood that misses the record is too sure of itself: its curvature
   understates how far the best-fitting parameters move from record to record (Huber 1967; White
   1982). The exact draws are mapped by the open-faced sandwich adjustment (Shaby 2014, J. Comput.
   Graph. Stat. 23:836; Ribatet, Cooley, Davison 2012): z -> m + Omega (z - m), with Omega =
   chol(cov_robust) chol(cov_laplace)^-1 and m the mode, so that the adjusted draws keep the exact
   posterior's shape (skew, bounds through the transforms) with the robust covariance. When the model
   describes the record, cov_robust = cov_laplace and nothing moves.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from .laplace import importance_weights, sym_cholesky
from .psis import khat_threshold
from .streams import legacy_state

@dataclass(frozen=True)
class ExactDraws:
    """Equal-weight draws of the exact posterior (``z``), the same after the sandwich adjustment
    (``z_adjusted``), how they were obtained and the diagnostics of the importance stage."""

    z: np.ndarray
    z_adjusted: np.ndarray
    method: str  # "importance", "importance (second proposal)" or "emcee"
    pareto_k: float  # of the first proposal (the normal approximation against the exact posterior)
    pareto_k_used: float  # of the stage whose draws are kept (nan for emcee)
    ess: float
    log_post_calls: int


def sandwich_map(mode: np.ndarray, cov_laplace: np.ndarray, cov_robust: np.ndarray) -> np.ndarray:
    """Omega of the open-faced sandwich adjustment (module docstring): Omega cov_laplace Omega^T = cov_robust."""
    return sym_cholesky(cov_robust) @ np.linalg.inv(sym_cholesky(cov_laplace))


def _weighted(log_post_rows: Callable[[np.ndarray], np.ndarray], dist, n: int, rng: np.random.Generator):
    z = np.atleast_2d(dist.rvs(size=n, random_state=rng)).reshape(n, -1)
    res = importance_weights(np.asarray(log_post_rows(z), float), dist.logpdf(z))
    return z, res.log_weights, float(res.pareto_k), float(res.ess)


def _resample(z: np.ndarray, log_w: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    w = np.exp(log_w - np.max(log_w))
    return z[rng.choice(len(z), size=n, p=w / w.sum())]


def _emcee(log_post_rows: Callable[[np.ndarray], np.ndarray], z: np.ndarray, log_w: np.ndarray, n: int,
           rng: np.random.Generator, *, steps: int, burn: int) -> np.ndarray:
    import emcee

    ndim = z.shape[1]
    nwalkers = max(16, 4 * ndim)
    start = z[np.argsort(log_w)[::-1][:nwalkers]]
    start = start + 1e-4 * rng.standard_normal(start.shape)  # distinct walkers even where draws repeat
    rs = legacy_state(rng)  # emcee's own stream, seeded from ours
    sampler = emcee.EnsembleSampler(nwalkers, ndim, log_post_rows, vectorize=True)
    sampler.run_mcmc(emcee.State(start, random_state=rs.get_state()), steps, progress=False)
    chain = sampler.get_chain(discard=burn, flat=True)
    return chain[rng.choice(len(chain), size=n, replace=len(chain) < n)]


def exact_draws(log_post: Callable[[np.ndarray], float], mode: np.ndarray, cov_laplace: np.ndarray,
                cov_robust: np.ndarray, *, rng: np.random.Generator, n_importance: int = 200, n_out: int = 1000,
                emcee_steps: int = 150, emcee_burn: int = 50,
                map_rows: Callable[[np.ndarray], list[float]] | None = None
                ) -> ExactDraws:
    """Exact posterior draws behind a Laplace approximation, and their sandwich-adjusted copy (module docstring).

    ``log_post(z)``: the exact log posterior density in the unbounded coordinates (Jacobians included), up to
    a constant; -inf outside the support. ``map_rows(z)``: ``log_post``'s values for the rows of ``z``, in
    order (default: one after the other; a pool of processes may share them out: the draws are the same bits).
    """
    mode = np.asarray(mode, float)
    mapped = map_rows or (lambda rows: [log_post(r) for r in rows])

    def log_post_rows(z: np.ndarray) -> np.ndarray:
        return np.asarray(mapped(np.atleast_2d(z)), float)

    z, lw, k1, ess = _weighted(log_post_rows, stats.multivariate_normal(mode, cov_robust, allow_singular=True),
                               n_importance, rng)
    calls, method, k_used = n_importance, "importance", k1
    k_max = khat_threshold(n_importance)
    if not k1 <= k_max:
        w = np.exp(lw - np.max(lw))
        w /= w.sum()
        mean = w @ z
        cov = np.atleast_2d(np.cov(z, rowvar=False, aweights=w)) * 1.5 + 1e-12 * np.eye(len(mode))
        z2, lw2, k2, ess2 = _weighted(log_post_rows, stats.multivariate_t(mean, cov, df=5, allow_singular=True),
                                      n_importance, rng)
        calls += n_importance
        if k2 <= k_max:
            z, lw, k_used, ess, method = z2, lw2, k2, ess2, "importance (second proposal)"
        else:
            zz, ll = np.concatenate([z, z2]), np.concatenate([lw, lw2])
            out = _emcee(log_post_rows, zz, ll, n_out, rng, steps=emcee_steps, burn=emcee_burn)
            calls += max(16, 4 * len(mode)) * emcee_steps
            omega = sandwich_map(mode, cov_laplace, cov_robust)
            return ExactDraws(out, mode + (out - mode) @ omega.T, "emcee", k1, math.nan, float(len(out)), calls)
    out = _resample(z, lw, n_out, rng)
    omega = sandwich_map(mode, cov_laplace, cov_robust)
    return ExactDraws(out, mode + (out - mode) @ omega.T, method, k1, k_used, ess, calls)
