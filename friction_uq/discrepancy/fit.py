"""Fit a forward model of the whole test to the whole record: Laplace approximation and draws.

The likelihood is :mod:`.record_likelihood`'s. The posterior is approximated by a normal
distribution in the unbounded coordinates of the parameters
(:meth:`~friction_uq.models.Parameter.to_unbounded`) around its mode, found by Levenberg-Marquardt
on the whitened residuals (with Gaussian stand-ins of the priors), with the Gauss-Newton matrix
J^T J as precision (J by central differences over :data:`JACOBIAN_STEP`; no finite-difference
Hessian, which fails when the posterior is narrower than its step), and the draws are corrected by
Pareto-smoothed importance sampling against the exact posterior (the k diagnostic is returned;
k > 0.7 says the normal approximation is poor). A simulator run costs ~10 ms, so a fit of two or
three parameters costs about 1 s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..models.parameters import summarize_draws
from ..stats.laplace import central_jacobian, importance_weights, normal_draws, robust_covariance, sym_cholesky
from .record_likelihood import GAIN_SD, WholeRecordLikelihood

__all__ = ["GAIN_SD", "WholeRecordFit", "WholeRecordLikelihood", "fit_whole_record"]

LogPrior = Callable[[Mapping[str, float]], float]
#: Step (unbounded coordinate) of the central differences giving the Laplace precision.
JACOBIAN_STEP = 1e-3
#: Mode search stops when a step changes the cost (half the squared whitened residuals, ~ samples / 2) by less
#: than FTOL of it, or the parameters (unbounded) by less than XTOL: 1e-8 of a cost of 1e4-1e5 is 1e-4 to 1e-3
#: nats, far below what the ELPD's SE resolves, where a stick-slip model's cost is a staircase in f that a
#: stricter tolerance chased for thousands of simulator runs.
FTOL, XTOL = 1e-8, 1e-8


@dataclass(frozen=True)
class WholeRecordFit:
    """Laplace fit of a model to the whole record."""

    names: tuple[str, ...]
    mode: dict[str, float]
    draws: dict[str, np.ndarray]
    log_weights: np.ndarray
    pareto_k: float
    loglike_mode: float
    n_calls: int
    cov_z: np.ndarray | None = None
    jacobian: np.ndarray | None = None  # d(whitened data residual)/dz at the mode, (n_data, n_par)
    whitened: np.ndarray | None = None  # whitened data residual at the mode
    laplace_draws: dict[str, np.ndarray] | None = None  # the normal approximation's, when ``draws`` are robust

    def summary(self, name: str) -> dict[str, float]:
        return summarize_draws(self.draws[name])


def fit_whole_record(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], *,
                     n_draws: int = 30, rng: np.random.Generator,
                     prior_scale: Mapping[str, tuple[float, float]] | None = None,
                     importance: bool = True, extra_starts: tuple[Mapping[str, float], ...] = (),
                     score_blocks: np.ndarray | None = None) -> WholeRecordFit:
    """Posterior mode, Laplace approximation and importance-weighted draws (module docstring).

    ``start`` gives a value for every free parameter (``hoop_gain``, marginalised by the likelihood, is not one).
    ``prior_scale`` (name -> (centre, sd) in the parameter's unbounded coordinate) gives the
    Gaussian stand-ins of the priors used while searching the mode (Levenberg-Marquardt on the
    whitened residuals); the exact ``log_prior`` weights the draws. Without ``importance`` the
    draws are the normal approximation's, unweighted (no simulator run per draw). ``extra_starts``
    (partial value sets overriding ``start``) are further starting points of the mode search; the
    best mode is kept (the rise of the record pins the sample's confined modulus, which a low nu with
    a stiff sample matches as well as the right nu: two modes). ``score_blocks`` (the block of each
    whitened residual, :meth:`WholeRecordLikelihood.whitened`): the draws are taken from
    :func:`~friction_uq.stats.laplace.robust_covariance` (the normal approximation's are kept in ``laplace_draws``).
    """
    params = [lik.model.parameters[n] for n in start if n != "hoop_gain"]
    names = tuple(p.name for p in params)
    calls = 0

    def values_of(z: np.ndarray) -> dict[str, float]:
        return {p.name: float(p.from_unbounded(zi)) for p, zi in zip(params, z)}

    z0 = np.array([float(p.to_unbounded(p.nearest_inside(start[p.name]))) for p in params])
    scale = {n: (float(z0[i]), 3.0) for i, n in enumerate(names)}
    scale.update(prior_scale or {})
    centre = np.array([scale[n][0] for n in names])
    width = np.array([scale[n][1] for n in names])

    n_data: list[int] = []

    def residuals(z: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        try:
            r = lik.whitened(values_of(z))
            n_data[:] = [len(r)]
        except ValueError:  # parameters the simulator cannot run (a column too stiff to integrate)
            r = np.full(n_data[0] if n_data else lik.n_samples, 1e3)
        return np.concatenate([r, (z - centre) / width])

    starts = [np.array([float(p.to_unbounded(p.nearest_inside(alt.get(p.name, start[p.name])))) for p in params])
              for alt in ({}, *extra_starts)]
    res = _best_mode(residuals, starts, width)
    zm = res.x
    # the precision from central differences over JACOBIAN_STEP: the explicit stick-slip integration makes
    # the prediction jump by a time step's worth where a slip starts one step earlier or later, and a
    # derivative over the optimiser's 1e-6 step can read such a jump as information
    J = central_jacobian(residuals, zm, JACOBIAN_STEP)
    cov, chol = _gauss_newton_covariance(J)

    def log_post(z: np.ndarray) -> float:
        vals = values_of(z)
        lp = log_prior(vals)
        if not np.isfinite(lp):
            return -np.inf
        jac = sum(float(p.log_jacobian(zi)) for p, zi in zip(params, z))
        return lik.loglike(vals) + lp + jac

    eps = rng.standard_normal((n_draws, len(zm)))
    n_data = len(res.fun) - len(zm)  # the whitened residuals' count (the rest are the priors' stand-ins)
    laplace = None
    if score_blocks is not None and cov is not None:
        laplace = {p.name: np.asarray(p.from_unbounded(zm[i] + eps @ chol[i]), float) for i, p in enumerate(params)}
        try:
            chol = np.linalg.cholesky(robust_covariance(J[:n_data], res.fun[:n_data], cov, score_blocks))
        except np.linalg.LinAlgError:
            pass
    z, log_q = normal_draws(zm, chol, eps)
    if importance:
        smoothed = importance_weights(np.array([log_post(zi) for zi in z]), log_q)
        log_w, k = smoothed.log_weights, float(smoothed.pareto_k)
    else:
        log_w, k = np.full(n_draws, -math.log(n_draws)), math.nan
    draws = {p.name: np.asarray(p.from_unbounded(z[:, i]), float) for i, p in enumerate(params)}
    mode = values_of(zm)
    return WholeRecordFit(names=names, mode=mode, draws=draws, log_weights=log_w, pareto_k=k,
                          loglike_mode=lik.loglike(mode), n_calls=calls + (n_draws if importance else 0),
                          cov_z=cov, jacobian=J[:n_data], whitened=res.fun[:n_data], laplace_draws=laplace)


def _best_mode(residuals: Callable[[np.ndarray], np.ndarray], starts: list[np.ndarray],
               width: np.ndarray) -> optimize.OptimizeResult:
    """The least-squares mode from each start (trust-region reflective, scaled by the priors' widths); the lowest
    cost kept."""
    res = None
    for za in starts:
        r = optimize.least_squares(residuals, za, method="trf", x_scale=width, diff_step=1e-6, xtol=XTOL, ftol=FTOL,
                                   max_nfev=60 * (len(za) + 1))
        if res is None or r.cost < res.cost:
            res = r
    return res


def _gauss_newton_covariance(J: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """The covariance in z from the Gauss-Newton precision J^T J (data and the Gaussian stand-ins of the priors)
    and its symmetric square root; (None, a 1e-3 diagonal) where the precision is singular."""
    try:
        cov = np.linalg.inv(J.T @ J)
        return cov, sym_cholesky(cov)
    except np.linalg.LinAlgError:
        return None, np.diag(np.full(J.shape[1], 1e-3))
