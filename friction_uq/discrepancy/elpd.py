"""Expected log predictive density of a whole record: exact block LOO for AR(1) noise.

Why blocks, and why exact. A gauge's noise is AR(1): neighbouring samples are correlated, so
leaving one sample out while keeping its neighbours tests almost nothing (the neighbours predict
it). The unit left out is a block of ``block`` consecutive samples (10 us, 50 samples at 5 MHz:
several correlation times) of one channel. For a Gaussian AR(1) series the density of a block
given *all* the other samples of its channel is exact and cheap, because the precision matrix Q
is tridiagonal (the "non-factorized" LOO of Buerkner, Gabry and Vehtari 2021): with
sigma_c^2 = sd^2 (1 - rho^2), Q = T / sigma_c^2, T tridiagonal with -rho off the diagonal and
1 + rho^2 on it (1 at the two ends of the series), the block b = [a, a + L) given the rest is

    e_b | e_-b ~ N(mu_b, sigma_c^2 T_bb^-1),  mu_b = rho T_bb^-1 (e_{a-1} u_first + e_{a+L} u_last),

so only the samples just before and after the block enter. Leave-future-out would answer another
question (forecasting); block LOO asks how well the model explains each part of the record from
the rest, which is what comparing physical mechanisms needs.

Integration over the posterior. The whole-record posterior is close to normal and very narrow
(thousands of samples per parameter), so the leave-one-block-out predictive density is taken to
first order around the posterior mode (Takeuchi's correction, which equals LOO asymptotically
also for a misspecified model):

    elpd_b = log p(e_b | e_-b, theta_hat) - g_b^T Sigma g_b,

g_b the gradient of the block's log density in the unbounded parameters (from the Jacobian of the
whitened residuals that the fit already has: g_b = -J_b^T w_b) and Sigma the posterior covariance
(Laplace). PSIS over importance-weighted draws (:func:`psis_loo`) is the alternative when draws
are affordable; with tens of draws of a posterior this narrow its Pareto k exceeded 0.7 on most
blocks, which is why the first-order form is the default.

dELPD between two models is the sum over blocks of the difference of their pointwise elpd, its
standard error sqrt(B) times the standard deviation of the differences (Vehtari, Gelman and Gabry
2017).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_LOG_2PI = math.log(2.0 * math.pi)


def _block_constants(length: int, rho: float, first: bool, last: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Diagonal of T_bb, rho T_bb^-1 u_first, rho T_bb^-1 u_last and log det T_bb for one block."""
    diag = np.full(length, 1.0 + rho * rho)
    if first:
        diag[0] = 1.0
    if last:
        diag[-1] = 1.0
    if length == 1 and first and last:
        diag[0] = 1.0 - rho * rho  # a one-sample series: its marginal
    T = np.diag(diag) - rho * (np.eye(length, k=1) + np.eye(length, k=-1))
    inv = np.linalg.inv(T)
    sign, logdet = np.linalg.slogdet(T)
    return diag, rho * inv[:, 0], rho * inv[:, -1], float(logdet)


def ar1_block_loo(resid: np.ndarray, *, sd: float, rho: float, block: int) -> np.ndarray:
    """log p(e_b | e_-b) for consecutive blocks of an AR(1) residual series (module docstring).

    Parameters
    ----------
    resid : array, shape (S, n)
        Residual series (one row per posterior draw).
    sd, rho : float
        Marginal standard deviation and lag-1 coefficient of the noise.
    block : int
        Block length (samples); the last block takes what is left.

    Returns
    -------
    array, shape (S, ceil(n / block))
    """
    e = np.atleast_2d(np.asarray(resid, float))
    S, n = e.shape
    var_c = sd * sd * (1.0 - rho * rho)
    starts = np.arange(0, n, block)
    out = np.empty((S, len(starts)))
    for k, a in enumerate(starts):
        L = min(block, n - a)
        diag, g, h, logdet = _block_constants(L, rho, a == 0, a + L == n)
        mu = np.zeros((S, L))
        if a > 0:
            mu += e[:, a - 1, None] * g
        if a + L < n:
            mu += e[:, a + L, None] * h
        r = e[:, a:a + L] - mu
        quad = np.sum(diag * r * r, axis=1) - 2.0 * rho * np.sum(r[:, 1:] * r[:, :-1], axis=1)
        out[:, k] = -0.5 * L * (_LOG_2PI + math.log(var_c)) + 0.5 * logdet - 0.5 * quad / var_c
    return out


@dataclass(frozen=True)
class Elpd:
    """Pointwise elpd of a model (one value per channel block) and its diagnostics."""

    pointwise: np.ndarray
    pareto_k_max: float

    @property
    def total(self) -> float:
        return float(np.sum(self.pointwise))

    @property
    def se(self) -> float:
        return float(math.sqrt(len(self.pointwise)) * np.std(self.pointwise, ddof=1))


def psis_loo(log_lik: np.ndarray, log_weights: np.ndarray) -> Elpd:
    """PSIS-LOO from per-draw pointwise log densities (S, P) and the draws' log importance weights (S,)."""
    from arviz_stats.base import array_stats

    ll = np.asarray(log_lik, float)
    lw = (np.asarray(log_weights, float)[:, None] - ll).T  # leave-one-out importance ratios, (P, S)
    smoothed = lw.copy()
    k = np.full(lw.shape[0], -np.inf)
    spread = np.ptp(lw, axis=-1) > 1e-12  # equal ratios need no smoothing (and PSIS refuses them)
    if spread.any():
        smoothed[spread], k[spread] = array_stats.psislw(lw[spread], axis=-1)
    smoothed = smoothed - np.logaddexp.reduce(smoothed, axis=-1, keepdims=True)
    point = np.logaddexp.reduce(smoothed + ll.T, axis=-1)
    return Elpd(pointwise=point, pareto_k_max=float(np.nanmax(k)))


def takeuchi_block_loo(log_density_mode: np.ndarray, jacobian: np.ndarray, whitened: np.ndarray,
                       cov: np.ndarray, blocks: np.ndarray) -> Elpd:
    """First-order leave-one-block-out elpd (module docstring).

    Parameters
    ----------
    log_density_mode : array, shape (P,)
        log p(e_b | e_-b) at the mode, one per block.
    jacobian, whitened : arrays, shapes (n, k) and (n,)
        Jacobian of the whitened residuals in the unbounded parameters, and the residuals.
    cov : array, shape (k, k)
        Posterior covariance in the unbounded parameters.
    blocks : array of int, shape (n,)
        Block index (0 .. P-1) of each whitened residual.
    """
    P = len(log_density_mode)
    g = np.zeros((P, jacobian.shape[1]))
    np.add.at(g, blocks, -jacobian * whitened[:, None])
    penalty = np.einsum("pi,ij,pj->p", g, cov, g)
    return Elpd(pointwise=np.asarray(log_density_mode, float) - penalty, pareto_k_max=float("nan"))


def elpd_difference(a: Elpd, b: Elpd) -> tuple[float, float]:
    """elpd(a) - elpd(b) and its standard error (same pointwise layout)."""
    d = a.pointwise - b.pointwise
    return float(np.sum(d)), float(math.sqrt(len(d)) * np.std(d, ddof=1))
