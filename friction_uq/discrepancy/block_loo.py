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
(Laplace). PSIS over importance-weighted draws (:func:`friction_uq.stats.elpd.psis_loo`) is the alternative when draws
are affordable; with tens of draws of a posterior this narrow its Pareto k exceeded 0.7 on most
blocks, which is why the first-order form is the default.

Calibration data. Some of what is known about a test is not in its gauges: the hoop gauge's
calibration (1 +- 5 %) and the sample's modulus (the header's, +- 10 %) are separate measurements,
which enter the fit as priors. A model that reads the record well only with a hoop factor of 0.75
or a sample 50 % stiffer than measured predicts those measurements badly, yet block LOO cannot see
it: the blocks left in pin the factor whatever the calibration said. So each calibration is one
more datum left out in turn: its predictive density given the record,
:func:`calibration_loo`. It has a closed form, since the datum is Gaussian: with the posterior
N(m, v) of the calibrated quantity (the datum included) and the datum c +- s,

    p(c | record) = N(c | m', V),  V = s^4 / (s^2 - v),  m' - c = (m - c) s^2 / (s^2 - v).

dELPD between two models is the sum over blocks of the difference of their pointwise elpd plus the
difference of their calibration terms. Its standard error: sqrt(B) times the standard deviation
of the blocks' differences (Vehtari, Gelman and Gabry 2017), combined with each calibration
datum's own spread: one datum gives no standard deviation of its own, but under Gaussian
predictives the difference of two log densities of a datum that scatters as predicted has
variance (m'_a - m'_b)^2 / V (V the two models' mean predictive variance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..stats.ar1 import LOG_2PI as _LOG_2PI
from ..stats.decision import paired_difference
from ..stats.trimmed import trimmed_difference

#: The smallest share of a calibration datum's variance s^2 taken as not yet told by the record (s^2 - v >=
#: this s^2): where the record says nothing of the quantity, its posterior is the datum and the left-out
#: predictive is flat; the floor keeps it a finite, equal-for-all-models density.
CALIBRATION_FLOOR = 0.1


def calibration_loo(m: float, v: float, c: float, s: float) -> tuple[float, float, float]:
    """Leave-the-datum-out predictive of a Gaussian calibration datum c +- s (module docstring).

    Parameters
    ----------
    m, v : float
        Posterior mean and variance of the calibrated quantity, the datum included.
    c, s : float
        The calibration's value and standard deviation.

    Returns
    -------
    (log density, predictive mean minus c, predictive variance)
    """
    r = max(s * s - v, CALIBRATION_FLOOR * s * s)
    var = s**4 / r
    mean = (m - c) * s * s / r
    return -0.5 * (_LOG_2PI + math.log(var)) - 0.5 * mean * mean / var, mean, var


@dataclass(frozen=True)
class Elpd:
    """Pointwise elpd of a model (one value per channel block), its calibration data's left-out densities
    (with their predictive means, relative to the datum, and variances: :func:`calibration_loo`) and
    its diagnostics."""

    pointwise: np.ndarray
    pareto_k_max: float
    calibration: np.ndarray = field(default_factory=lambda: np.zeros(0))
    calibration_mean: np.ndarray = field(default_factory=lambda: np.zeros(0))
    calibration_var: np.ndarray = field(default_factory=lambda: np.zeros(0))
    calibration_names: tuple[str, ...] = ()

    @property
    def total(self) -> float:
        return float(np.sum(self.pointwise) + np.sum(self.calibration))

    @property
    def se(self) -> float:
        return float(math.sqrt(len(self.pointwise)) * np.std(self.pointwise, ddof=1))


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


def with_calibration(e: Elpd, terms: dict[str, tuple[float, float, float]]) -> Elpd:
    """``e`` with calibration data's terms attached (name -> :func:`calibration_loo`'s triple)."""
    t = np.array(list(terms.values()), float).reshape(-1, 3)
    return replace(e, calibration=t[:, 0], calibration_mean=t[:, 1], calibration_var=t[:, 2],
                   calibration_names=tuple(terms))


def elpd_difference(a: Elpd, b: Elpd, *, drop: int = 0) -> tuple[float, float]:
    """elpd(a) - elpd(b) and its standard error (same pointwise layout; module docstring). Calibration data
    count when both models have the same ones. ``drop``: the blocks most in favour of ``a`` left out
    (:func:`friction_uq.stats.trimmed.trimmed_difference`; the calibration data are kept)."""
    total, se = (paired_difference(a.pointwise, b.pointwise) if drop == 0 else
                 trimmed_difference(a.pointwise, b.pointwise, drop=drop))
    var = se * se
    if len(a.calibration) and a.calibration_names == b.calibration_names:
        total += float(np.sum(a.calibration - b.calibration))
        spread = 0.5 * (a.calibration_var + b.calibration_var)
        var += float(np.sum((a.calibration_mean - b.calibration_mean) ** 2 / spread))
    return total, math.sqrt(var)
