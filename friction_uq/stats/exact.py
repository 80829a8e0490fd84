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

   **Enough draws for the interval's tails.** A k under the limit says the weights are reliable, not
   that there are enough of them: 200 draws of a proposal twice as wide as the posterior in a few
   directions keep an effective sample size (ESS, 1 / sum w^2) of a few dozen, and the 5 % and 95 %
   quantiles of the 90 % interval are then read from a handful of draws. A stage is kept only when
   its ESS reaches :func:`ess_floor` (119: the tail probability 0.05 estimated to a Monte Carlo
   standard error of 0.02, sqrt(p (1 - p) / ESS)); short of it, more draws of the same proposal are
   added (its k computed again over all of them, against the first batch's limit), up to
   :data:`MAX_IMPORTANCE_FACTOR` times the first batch, before the next stage is tried. emcee's chain
   is run on, by its own length again, until its ESS (walkers x kept steps / the integrated
   autocorrelation time, burn-in 3 of those times) reaches the floor, or the chain is
   :data:`MAX_EMCEE_FACTOR` times its first length; ``converged`` says which. The ESS reported is
   the chain's, never the number of draws resampled from it. On a chain of a few hundred steps the
   autocorrelation time is underestimated (emcee's documentation trusts it from 50 times its length),
   so this ESS is optimistic; running on to that length costs four times the steps or more, and on
   the one record measured (docs/trust.md) it moved the 90 % interval's ends of f by 0.5 %.
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
from dataclasses import dataclass, field

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
    ess: float  # of the kept draws: the weights' 1 / sum w^2, or emcee's chain's (module docstring)
    log_post_calls: int
    converged: bool = True  # False: the floor on the ESS not reached within the caps (module docstring)


def sandwich_map(mode: np.ndarray, cov_laplace: np.ndarray, cov_robust: np.ndarray) -> np.ndarray:
    """Omega of the open-faced sandwich adjustment (module docstring): Omega cov_laplace Omega^T = cov_robust."""
    return sym_cholesky(cov_robust) @ np.linalg.inv(sym_cholesky(cov_laplace))


#: The tail probability of the 90 % interval and the Monte Carlo standard error allowed on it (module docstring).
TAIL_PROBABILITY, TAIL_MCSE = 0.05, 0.02
#: An importance stage whose k passes may draw up to this many times its first batch to reach the ESS floor.
MAX_IMPORTANCE_FACTOR = 5
#: emcee's chain may run up to this many times its first length to reach the ESS floor.
MAX_EMCEE_FACTOR = 4


def ess_floor(tail: float = TAIL_PROBABILITY, mcse: float = TAIL_MCSE) -> int:
    """Effective sample size at which a tail probability ``tail`` is estimated to a Monte Carlo standard error
    ``mcse``: p (1 - p) / mcse^2 (119 for the 90 % interval's tails to 0.02).

    >>> ess_floor()
    119
    """
    return math.ceil(tail * (1.0 - tail) / mcse ** 2)


@dataclass(frozen=True)
class _Stage:
    """An importance stage's draws of one proposal, their log target and log proposal densities, and the
    smoothed weights over all of them (computed on construction)."""

    z: np.ndarray
    log_target: np.ndarray
    log_proposal: np.ndarray
    first_batch: int
    log_weights: np.ndarray = field(init=False)
    k: float = field(init=False)
    ess: float = field(init=False)

    def __post_init__(self) -> None:
        res = importance_weights(self.log_target, self.log_proposal)
        for name, value in (("log_weights", res.log_weights), ("k", float(res.pareto_k)), ("ess", float(res.ess))):
            object.__setattr__(self, name, value)

    @property
    def k_ok(self) -> bool:
        """k within the limit for the first batch's draws (the limit the JSON states; more draws allow a higher
        one, not taken)."""
        return bool(self.k <= khat_threshold(self.first_batch))

    def kept(self, floor: int) -> bool:
        """The stage's draws are the exact posterior: k within its limit and the ESS at the floor."""
        return self.k_ok and self.ess >= floor


def _draw(log_post_rows: Callable[[np.ndarray], np.ndarray], dist, n: int, rng: np.random.Generator):
    z = np.atleast_2d(dist.rvs(size=n, random_state=rng)).reshape(n, -1)
    return z, np.asarray(log_post_rows(z), float), np.asarray(dist.logpdf(z), float).reshape(n)


def _importance(log_post_rows: Callable[[np.ndarray], np.ndarray], dist, n: int, rng: np.random.Generator,
                floor: int) -> _Stage:
    """One proposal's stage: ``n`` draws, then more of the same (k weighed again over all) while k passes and
    the ESS is under ``floor``, up to :data:`MAX_IMPORTANCE_FACTOR` x ``n`` draws (module docstring)."""
    st = _Stage(*_draw(log_post_rows, dist, n, rng), n)
    cap = MAX_IMPORTANCE_FACTOR * n
    while st.k_ok and st.ess < floor and len(st.z) < cap:
        per_draw = max(st.ess / len(st.z), 1.0 / cap)
        extra = int(min(cap - len(st.z), max(n // 2, math.ceil(1.2 * floor / per_draw) - len(st.z))))
        z, lt, lq = _draw(log_post_rows, dist, extra, rng)
        st = _Stage(np.concatenate([st.z, z]), np.concatenate([st.log_target, lt]),
                    np.concatenate([st.log_proposal, lq]), n)
    return st


def _resample(z: np.ndarray, log_w: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    w = np.exp(log_w - np.max(log_w))
    return z[rng.choice(len(z), size=n, p=w / w.sum())]


def _emcee(log_post_rows: Callable[[np.ndarray], np.ndarray], z: np.ndarray, log_w: np.ndarray, n: int,
           rng: np.random.Generator, *, steps: int, burn: int, floor: int) -> tuple[np.ndarray, float, int, bool]:
    """emcee's draws (``n``, resampled from the kept chain), the chain's ESS, the density's evaluations and whether
    that ESS reached ``floor``: run on by ``steps`` at a time until it does, or the chain is
    :data:`MAX_EMCEE_FACTOR` x ``steps`` long (module docstring)."""
    import emcee

    ndim = z.shape[1]
    nwalkers = max(16, 4 * ndim)
    start = z[np.argsort(log_w)[::-1][:nwalkers]]
    start = start + 1e-4 * rng.standard_normal(start.shape)  # distinct walkers even where draws repeat
    rs = legacy_state(rng)  # emcee's own stream, seeded from ours
    sampler = emcee.EnsembleSampler(nwalkers, ndim, log_post_rows, vectorize=True)
    sampler.run_mcmc(emcee.State(start, random_state=rs.get_state()), steps, progress=False)
    while True:
        chain = sampler.get_chain()
        total = len(chain)
        tau = float(np.max(emcee.autocorr.integrated_time(chain[min(burn, total // 2):], tol=0, quiet=True)))
        cut = min(max(burn, math.ceil(3.0 * tau)), total // 2)
        ess = nwalkers * (total - cut) / max(tau, 1.0)
        converged = ess >= floor
        if converged or total >= MAX_EMCEE_FACTOR * steps:
            break
        sampler.run_mcmc(None, steps, progress=False)
    flat = chain[cut:].reshape(-1, ndim)
    return flat[rng.choice(len(flat), size=n, replace=len(flat) < n)], float(ess), nwalkers * total, converged


def _second_proposal(first: _Stage) -> tuple[np.ndarray, np.ndarray] | None:
    """Centre and scale of the second proposal: the first's weighted draws' mean and covariance (x 1.5); None where
    one draw carries every weight (the others' underflow to 0: the covariance is nan, and the first proposal's scale
    is the one that failed), and emcee takes over from the first's draws."""
    top = float(np.max(first.log_weights))
    if not math.isfinite(top):
        return None
    w = np.exp(first.log_weights - top)
    w /= w.sum()
    if float(w @ w) >= 1.0 - 1e-12:
        return None
    cov = np.atleast_2d(np.cov(first.z, rowvar=False, aweights=w)) * 1.5 + 1e-12 * np.eye(first.z.shape[1])
    return w @ first.z, cov


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
    floor = ess_floor()

    def log_post_rows(z: np.ndarray) -> np.ndarray:
        return np.asarray(mapped(np.atleast_2d(z)), float)

    first = _importance(log_post_rows, stats.multivariate_normal(mode, cov_robust, allow_singular=True),
                        n_importance, rng, floor)
    calls, st, method = len(first.z), first, "importance"
    omega = sandwich_map(mode, cov_laplace, cov_robust)
    if not first.kept(floor):
        second = _second_proposal(first)
        if second is not None:
            st = _importance(log_post_rows, stats.multivariate_t(*second, df=5, allow_singular=True),
                             n_importance, rng, floor)
            calls += len(st.z)
            method = "importance (second proposal)"
        if second is None or not st.kept(floor):
            zz, ll = (first.z, first.log_weights) if second is None else (
                np.concatenate([first.z, st.z]), np.concatenate([first.log_weights, st.log_weights]))
            out, ess, n_calls, ok = _emcee(log_post_rows, zz, ll, n_out, rng, steps=emcee_steps, burn=emcee_burn,
                                           floor=floor)
            return ExactDraws(out, mode + (out - mode) @ omega.T, "emcee", first.k, math.nan, ess,
                              calls + n_calls, ok)
    out = _resample(st.z, st.log_weights, n_out, rng)
    return ExactDraws(out, mode + (out - mode) @ omega.T, method, first.k, st.k, st.ess, calls)
