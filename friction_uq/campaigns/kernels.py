"""A test's stored posterior draws as its likelihood: a weighted Gaussian kernel mixture.

For a law that predicts the test's quantity y with a normal spread of variance v (the law's
scatter and the measured V and p through its slopes), the test's likelihood from its draws y_j,
each drawn under a prior pi, is

    p(test | law) = sum_j w_j N(y_j; law, sqrt(v + h^2)),   w_j = (1 / pi(y_j)) / sum_k (1 / pi(y_k)),

with h the draws' kernel bandwidth (scipy's ``gaussian_kde``, Scott's rule) and the draws shrunk
towards their mean by sqrt(1 - h^2/sd^2), so that the mixture keeps their variance (the kernel
shrinkage of West 1993 and Liu and West 2001). The mixture is evaluated for every walker and test
in one compiled loop (:func:`log_kernel_mixture`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.special import logsumexp

from .._jit import njit


def draw_kernels(draws: Sequence[np.ndarray], log_prior: Sequence[np.ndarray] | None,
                 scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per test: its draws over ``scale``, shrunk (n, J; zero-padded where a test has fewer), their
    normalised log weights 1/prior (n, J; -inf on padding), and the squared bandwidth (n,)."""
    from scipy.stats import gaussian_kde

    n, J = len(draws), max(len(x) for x in draws)
    y, logw, h2 = np.zeros((n, J)), np.full((n, J), -np.inf), np.zeros(n)
    for k, x in enumerate(draws):
        yk = np.asarray(x, float) / scale
        lp = np.zeros(yk.size) if log_prior is None else np.asarray(log_prior[k], float)
        if np.ptp(yk) > 0:  # shrink the draws to their mean so that the mixture keeps their variance
            kde = gaussian_kde(yk)
            yk = yk.mean() + np.sqrt(1.0 - kde.factor**2) * (yk - yk.mean())
            h2[k] = float(kde.covariance[0, 0])
        y[k, :yk.size], logw[k, :yk.size] = yk, -lp - logsumexp(-lp)
    return y, logw, h2


@njit
def log_kernel_mixture(mean: np.ndarray, var: np.ndarray, y: np.ndarray, logw: np.ndarray) -> np.ndarray:
    """log sum_j exp(logw[i, j]) N(y[i, j]; mean[w, i], var[w, i]) for every walker w and test i: (W, n)."""
    W, n = mean.shape
    J = y.shape[1]
    out = np.empty((W, n))
    wmax = np.empty(n)
    for i in range(n):
        wmax[i] = logw[i].max()
    for w in range(W):
        for i in range(n):
            m, v = mean[w, i], var[w, i]
            acc = 0.0
            for j in range(J):  # each term <= exp(0): one pass, unless every term underflows
                acc += np.exp(logw[i, j] - wmax[i] - 0.5 * (y[i, j] - m) ** 2 / v)
            top = wmax[i]
            if acc < 1e-250:  # the law far out in every draw's tail: shift by the largest term
                top = -np.inf
                for j in range(J):
                    top = max(top, logw[i, j] - 0.5 * (y[i, j] - m) ** 2 / v)
                acc = 0.0
                for j in range(J):
                    acc += np.exp(logw[i, j] - 0.5 * (y[i, j] - m) ** 2 / v - top)
            out[w, i] = top + np.log(acc) - 0.5 * np.log(2.0 * np.pi * v)
    return out


def warm_up_kernels() -> None:
    """Load the compiled :func:`log_kernel_mixture` in this process (from numba's cache, or compiled): called
    before forking workers, so that each child does not load it again (0.5-1 s each)."""
    log_kernel_mixture(np.zeros((1, 1)), np.ones((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)))
