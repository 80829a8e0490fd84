"""A quantity's draws times an independent, uncertain scale factor: the summary of X G with log G ~ N(0, s^2).

Used where a number is quoted with an uncertainty the data do not inform (the output bars' calibration
on eq. 17's ratio: :data:`friction_uq.physics.bars.FORCE_RATIO_CALIBRATION_SD`). Exact for the draws given,
and deterministic (no random factor is drawn): ln(X G) is the mixture of normals N(ln x_j, s^2) over the
draws x_j, so its distribution function is the mean of Phi((y - ln x_j) / s), inverted for each quantile by
bracketing; the mean and sd follow from E G = exp(s^2 / 2), E G^2 = exp(2 s^2).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq
from scipy.special import ndtr

#: The summary's quantiles (as every output's: :func:`friction_uq.models.parameters.summarize_draws`).
LEVELS = {"q05": 0.05, "q50": 0.5, "q95": 0.95}


def times_lognormal_factor(draws: np.ndarray, log_sd: float) -> dict[str, float]:
    """mean, sd, q05, q50 and q95 of X G for positive draws of X and log G ~ N(0, log_sd^2), G independent of X.

    ``log_sd`` 0 gives the draws' own summary."""
    x = np.asarray(draws, float).reshape(-1)
    if x.size < 2 or not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError("the draws must be at least two finite positive numbers")
    if not (np.isfinite(log_sd) and log_sd >= 0):
        raise ValueError(f"log_sd must be finite and >= 0, got {log_sd!r}")
    s = float(log_sd)
    m1, m2 = float(np.mean(x)), float(np.mean(x * x))
    mean = m1 * np.exp(0.5 * s * s)
    n = x.size
    var = (m2 * np.exp(2 * s * s) - m1 * m1 * np.exp(s * s)) * n / (n - 1)  # ddof 1, as summarize_draws
    out = {"mean": float(mean), "sd": float(np.sqrt(max(var, 0.0)))}
    if s == 0.0:
        q = np.quantile(x, list(LEVELS.values()))
        return out | {k: float(v) for k, v in zip(LEVELS, q, strict=True)}
    y = np.log(x)

    def cdf(v: float) -> float:
        with np.errstate(over="ignore"):  # a factor of (nearly) no spread: the draws' own steps, ndtr(+-inf)
            return float(np.mean(ndtr((v - y) / s)))

    pad = 8 * s + 1e-12 * (1.0 + float(np.max(np.abs(y))))  # the mixture's whole mass lies inside the bracket
    lo, hi = float(y.min()) - pad, float(y.max()) + pad
    for key, p in LEVELS.items():
        out[key] = float(np.exp(brentq(lambda v, p=p: cdf(v) - p, lo, hi, xtol=1e-12)))
    return out
