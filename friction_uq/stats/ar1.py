"""Stationary AR(1) Gaussian noise: exact log-likelihood, per-sample conditionals, a constant offset
error integrated out (rank-one term: matrix determinant lemma and Sherman-Morrison), and the density
of a block of the series given all the rest (the unit of a record's leave-one-block-out ELPD).

Pure algebra of the noise model, no physics: the stationary-phase likelihood (:mod:`friction_uq.likelihood`),
the whole-record ELPD (:mod:`friction_uq.discrepancy.block_loo`) and the two-bar balance
(:mod:`friction_uq.shpb`) read it here."""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

#: log(2 pi), the normal density's constant.
LOG_2PI = math.log(2.0 * math.pi)


def ar1_pointwise(
    resid: np.ndarray, sd: np.ndarray | float, rho: np.ndarray | float, offset: np.ndarray | float = 0.0,
) -> np.ndarray:
    """Conditional log densities of a stationary AR(1) Gaussian series; they sum to the exact log-likelihood.

    Parameters
    ----------
    resid : array, shape (..., n)
        Residuals, time along the last axis.
    sd : float or array broadcastable to shape (...,)
        Marginal standard deviation of the noise (same unit as ``resid``).
    rho : float or array broadcastable to shape (...,)
        Lag-1 coefficient, |rho| < 1.
    offset : float or array broadcastable to shape (...,)
        Standard deviation of an unknown constant added to the series (integrated out); 0: none.

    Returns
    -------
    array, shape (..., n)
        log p(e_1) = log N(e_1; 0, sd^2) and log p(e_t | e_{t-1}) = log N(e_t; rho e_{t-1}, sd^2 (1 - rho^2))
        (with an offset: the conditionals given all earlier samples).
    """
    resid = np.asarray(resid, float)
    sd = np.asarray(sd, float)
    rho = np.asarray(rho, float)
    offset = np.asarray(offset, float)
    if np.any(offset > 0.0):
        return _offset_pointwise_shift(resid, sd, rho, np.maximum(offset, 1e-150))
    var = sd**2
    var_c = var * (1.0 - rho**2)  # conditional variance of e_t given e_{t-1}
    out = np.empty(np.broadcast_shapes(resid.shape, sd.shape + (1,), rho.shape + (1,)))
    out[..., 0] = -0.5 * (LOG_2PI + np.log(var) + resid[..., 0] ** 2 / var)
    innov = resid[..., 1:] - rho[..., None] * resid[..., :-1]
    innov *= innov
    innov /= -2.0 * var_c[..., None]
    innov += (-0.5 * (LOG_2PI + np.log(var_c)))[..., None]
    out[..., 1:] = innov
    return out


def ar1_loglike(
    resid: np.ndarray, sd: np.ndarray | float, rho: np.ndarray | float, offset: np.ndarray | float = 0.0,
) -> np.ndarray:
    """Exact log-likelihood of a stationary AR(1) Gaussian series along the last axis.

    log L = -n/2 log(2 pi sd^2) - (n-1)/2 log(1 - rho^2)
            - [(1 - rho^2) e_1^2 + sum_{t>=2} (e_t - rho e_{t-1})^2] / (2 sd^2 (1 - rho^2)).

    Shapes and ``offset`` as :func:`ar1_pointwise`; returns shape (...,). With an offset, adds
    :func:`ar1_offset_correction`.
    """
    resid = np.asarray(resid, float)
    sd = np.asarray(sd, float)
    rho = np.asarray(rho, float)
    n = resid.shape[-1]
    one = 1.0 - rho**2
    d = resid[..., 1:] - rho[..., None] * resid[..., :-1]
    q = one * resid[..., 0] ** 2 + np.sum(d * d, axis=-1)
    out = -0.5 * n * (LOG_2PI + np.log(sd**2)) - 0.5 * (n - 1) * np.log(one) - q / (2.0 * sd**2 * one)
    if np.any(np.asarray(offset) > 0.0):
        out = out + ar1_offset_correction(resid.sum(-1), resid[..., 0] + resid[..., -1], n=n, sd=sd, rho=rho, offset=offset)
    return out


def ar1_mean_sd(sd: float, rho: float, n: int) -> float:
    """Standard deviation of the mean of ``n`` AR(1) samples, sd sqrt((1 + rho) / ((1 - rho) n)) (large n).

    >>> round(ar1_mean_sd(2.0, 0.0, 100), 6)
    0.2
    """
    return sd * math.sqrt((1.0 + rho) / ((1.0 - rho) * max(n, 1)))


def offset_sd(sd: float, rho: float, n_baseline: int) -> float:
    """Standard deviation of the mean of ``n_baseline`` AR(1) samples: the error of an offset removed
    with the mean of a pre-pulse segment (:func:`ar1_mean_sd`)."""
    return ar1_mean_sd(sd, rho, n_baseline)


def ar1_offset_correction(
    sum_u: np.ndarray, ends_u: np.ndarray, *, n: int, sd: np.ndarray | float, rho: np.ndarray | float,
    offset: np.ndarray | float,
) -> np.ndarray:
    """log N(u; 0, S + c^2 1 1') - log N(u; 0, S) for S the AR(1) covariance (sd, rho) and c = ``offset``.

    Needs only sum(u) and u_1 + u_n: with P = S^-1, 1'Pu = [(1-rho)^2 sum(u) + rho(1-rho)(u_1 + u_n)]
    / (sd^2 (1-rho^2)) and 1'P1 = [(1-rho^2) + (n-1)(1-rho)^2] / (sd^2 (1-rho^2)); the correction is
    c^2 (1'Pu)^2 / (2 (1 + c^2 1'P1)) - log(1 + c^2 1'P1) / 2 (Sherman-Morrison, determinant lemma).
    """
    sd, rho, c2 = np.asarray(sd, float), np.asarray(rho, float), np.asarray(offset, float) ** 2
    var_c = sd**2 * (1.0 - rho**2)
    g = ((1.0 - rho) ** 2 * sum_u + rho * (1.0 - rho) * ends_u) / var_c
    h = ((1.0 - rho**2) + (n - 1) * (1.0 - rho) ** 2) / var_c
    return 0.5 * c2 * g * g / (1.0 + c2 * h) - 0.5 * np.log1p(c2 * h)


def _offset_pointwise_shift(resid: np.ndarray, sd: np.ndarray, rho: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Per-sample conditional log densities of u = delta + AR(1), delta ~ N(0, offset^2) (recursive form).

    Innovations eta_1 = u_1 = delta + e_1 (variance sd^2), eta_t = u_t - rho u_{t-1} = (1-rho) delta + w_t
    (variance sd^2 (1-rho^2)): a regression on delta, whose predictive densities follow from running sums
    (:func:`_offset_pointwise_rows`). ``sd``, ``rho`` and ``offset`` broadcast to ``resid.shape[:-1]``.
    """
    shape = resid.shape
    rows = int(np.prod(shape[:-1], dtype=np.int64))
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape[:-1]), dtype=float).reshape(rows)
            for a in (sd, rho, offset)]
    out = np.empty((rows, shape[-1]))
    _offset_pointwise_rows(np.ascontiguousarray(resid, dtype=float).reshape(rows, shape[-1]), *flat, out)
    return out.reshape(shape)


@njit
def _offset_pointwise_rows(u, sd, rho, offset, out):  # pragma: no cover - compiled
    """Row by row: with delta's posterior after t-1 samples (precision b, b * mean = a), sample t's
    predictive is N(x_t a / b, var_t + x_t^2 / b), x_1 = 1, var_1 = sd^2, x_t = 1 - rho, var_t = sd^2 (1 - rho^2)."""
    n = u.shape[1]
    for i in range(u.shape[0]):
        var = sd[i] * sd[i]
        r = rho[i]
        var1 = var * (1.0 - r * r)
        c1 = 1.0 - r
        b = 1.0 / (offset[i] * offset[i])
        v = var + 1.0 / b
        eta = u[i, 0]
        out[i, 0] = -0.5 * (LOG_2PI + math.log(v) + eta * eta / v)
        a = eta / var
        b += 1.0 / var
        for t in range(1, n):
            eta = u[i, t] - r * u[i, t - 1]
            m = c1 * a / b
            v = var1 + c1 * c1 / b
            out[i, t] = -0.5 * (LOG_2PI + math.log(v) + (eta - m) * (eta - m) / v)
            a += c1 * eta / var1
            b += c1 * c1 / var1


def ar1_innovations(x: np.ndarray, rho: float) -> np.ndarray:
    """AR(1) innovations along the last axis: sqrt(1 - rho^2) x_1, x_t - rho x_{t-1}."""
    x = np.asarray(x, float)
    out = np.empty_like(x)
    out[..., 0] = math.sqrt(1.0 - rho**2) * x[..., 0]
    out[..., 1:] = x[..., 1:] - rho * x[..., :-1]
    return out


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
    """log p(e_b | e_-b) for consecutive blocks of an AR(1) residual series (derived in
    :mod:`friction_uq.discrepancy.block_loo`'s docstring).

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
        out[:, k] = -0.5 * L * (LOG_2PI + math.log(var_c)) + 0.5 * logdet - 0.5 * quad / var_c
    return out
