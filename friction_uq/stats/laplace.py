"""The pieces of a Laplace fit in unbounded coordinates, shared by the whole-record fits and the two-bar fits.

* the curvature at the mode: a finite-difference Hessian of the negative log posterior
  (:func:`fd_hessian`), or the Gauss-Newton precision J^T J of whitened residuals, J by central
  differences (:func:`central_jacobian`);
* the spread made robust to a model that misses (:func:`robust_covariance`: the sandwich, with the
  score summed per block and Bartlett-weighted across neighbouring blocks);
* normal draws around the mode from standard normal ones (:func:`normal_draws`, :func:`draw_normal`),
  with their log density up to a constant, and their importance weights against the exact posterior,
  Pareto-smoothed (:func:`importance_weights`).

What the model is (its forward simulation, its priors, its parameters' transforms) stays with each
consumer; the exact posterior behind the approximation is :mod:`.exact`'s.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .psis import PSIS, psis

#: Blocks apart whose scores are taken as correlated in :func:`robust_covariance` (Bartlett weights).
ROBUST_LAGS = 4


def sym_cholesky(cov: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor of a covariance, symmetrised first (a numerical inverse is symmetric only to rounding)."""
    return np.linalg.cholesky(0.5 * (cov + cov.T))


def central_jacobian(fun: Callable[[np.ndarray], np.ndarray], z: np.ndarray, step: float) -> np.ndarray:
    """Jacobian (n, k) of a vector function at ``z`` by central differences over ``step`` in each coordinate."""
    return np.stack([(fun(z + step * e) - fun(z - step * e)) / (2.0 * step) for e in np.eye(len(z))], axis=1)


def fd_hessian(fun: Callable[[np.ndarray], float], z: np.ndarray) -> np.ndarray:
    """Finite-difference Hessian of a scalar function at ``z``, steps a tenth of each coordinate's sd (the
    curvature's, from two first passes along the axes)."""
    k = len(z)
    f0 = fun(z)
    h = np.full(k, 1e-3)
    for _ in range(2):
        curv = np.array([(fun(z + h[i] * np.eye(k)[i]) - 2 * f0 + fun(z - h[i] * np.eye(k)[i])) / h[i] ** 2
                         for i in range(k)])
        h = 0.1 / np.sqrt(np.maximum(curv, 1e-12))
    e = np.eye(k) * h
    H = np.empty((k, k))
    for i in range(k):
        H[i, i] = (fun(z + e[i]) - 2.0 * f0 + fun(z - e[i])) / h[i] ** 2
        for j in range(i + 1, k):
            H[i, j] = H[j, i] = (fun(z + e[i] + e[j]) - fun(z + e[i] - e[j]) - fun(z - e[i] + e[j])
                                 + fun(z - e[i] - e[j])) / (4.0 * h[i] * h[j])
    return H


def robust_covariance(jacobian: np.ndarray, whitened: np.ndarray, cov: np.ndarray, blocks: np.ndarray, *,
                      lags: int = ROBUST_LAGS) -> np.ndarray:
    """Posterior covariance widened for a model that misses the record: the Laplace covariance ``cov``
    plus the positive part of (sandwich - cov).

    The sandwich H^-1 B H^-1 (H^-1 = ``cov``) is the spread of the best-fitting parameters when the
    model is wrong (Huber; White 1982); B is the covariance of the score summed per block of the
    record (``blocks``: the block of each whitened residual), with the products of blocks up to
    ``lags`` apart weighted by Bartlett's kernel (Newey-West), since a model's error is correlated
    over longer than one block. When the model is right, B ~ H and nothing changes; where it
    misses, the residual's structure that the parameters had to absorb widens their posterior
    (Muller 2013, "Risk of Bayesian inference in misspecified models").
    """
    g = jacobian * whitened[:, None]
    G = np.zeros((int(blocks.max()) + 1, jacobian.shape[1]))
    np.add.at(G, blocks, g)
    B = G.T @ G
    for lag in range(1, lags + 1):
        C = G[:-lag].T @ G[lag:]
        B += (1.0 - lag / (lags + 1.0)) * (C + C.T)
    D = cov @ B @ cov - cov
    w, V = np.linalg.eigh(0.5 * (D + D.T))
    return cov + (V * np.clip(w, 0.0, None)) @ V.T


def normal_draws(mode: np.ndarray, chol: np.ndarray, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Draws mode + chol eps of N(mode, chol chol^T) from standard normal ``eps`` (n, k), and their log
    density up to a constant (the same for every covariance: -|eps|^2 / 2)."""
    return mode + eps @ chol.T, -0.5 * np.sum(eps * eps, axis=1)


def draw_normal(mode: np.ndarray, cov: np.ndarray, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` draws of N(mode, cov) and their log density up to a constant (:func:`normal_draws`)."""
    chol = sym_cholesky(cov)
    return normal_draws(mode, chol, rng.standard_normal((n, len(mode))))


def importance_weights(log_target: np.ndarray, log_proposal: np.ndarray) -> PSIS:
    """Pareto-smoothed, normalised log weights of draws of a proposal against a target (log densities up to
    constants); a draw where the target is not finite (outside its support) gets weight 0."""
    log_target = np.asarray(log_target, float)
    return psis(np.where(np.isfinite(log_target), log_target - log_proposal, -np.inf))
