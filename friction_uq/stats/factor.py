"""A quantity's draws times an independent, uncertain scale factor: the summary of X G with log G ~ N(0, s^2).

Used where a number is quoted with an uncertainty the data do not inform (the output bars' calibration
on eq. 17's ratio: :mod:`friction_uq.quoted`). Exact for the draws given, and deterministic (no random factor
is drawn): ln(X G) is the mixture over the draws x_j of N(ln x_j, s_j^2) (a point at ln x_j where s_j = 0; a
draw x_j = 0 stays at 0 whatever G), so its distribution function is the mean of Phi((y - ln x_j) / s_j),
inverted for each quantile by bracketing; the mean and sd follow from E G = exp(s^2 / 2), E G^2 = exp(2 s^2).
The factor's sd may differ from draw to draw (a mixture of models that carry different shares of the
calibration).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq
from scipy.special import ndtr

#: The summary's quantiles (as every output's: :func:`friction_uq.models.parameters.summarize_draws`).
LEVELS = {"q05": 0.05, "q50": 0.5, "q95": 0.95}


def times_lognormal_factor(draws: np.ndarray, log_sd: float | np.ndarray) -> dict[str, float]:
    """mean, sd, q05, q50 and q95 of X G for draws of X >= 0 and log G ~ N(0, log_sd^2), G independent of X;
    ``log_sd`` one number or one per draw. A factor of sd 0 everywhere gives the draws' own summary."""
    x = np.asarray(draws, float).reshape(-1)
    s = np.broadcast_to(np.asarray(log_sd, float), x.shape) if np.ndim(log_sd) else np.full(x.shape, float(log_sd))
    if x.size < 2 or not np.all(np.isfinite(x)) or np.any(x < 0):
        raise ValueError("the draws must be at least two finite numbers >= 0")
    if s.shape != x.shape or not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ValueError("log_sd must be finite and >= 0, one number or one per draw")
    n = x.size
    m1, m2 = float(np.mean(x * np.exp(0.5 * s * s))), float(np.mean(x * x * np.exp(2 * s * s)))
    var = (m2 - m1 * m1) * n / (n - 1)  # ddof 1, as summarize_draws
    out = {"mean": m1, "sd": float(np.sqrt(max(var, 0.0)))}
    if not np.any(s > 0):
        q = np.quantile(x, list(LEVELS.values()))
        return out | {k: float(v) for k, v in zip(LEVELS, q, strict=True)}
    pos = x > 0
    zero_share = 1.0 - float(np.mean(pos))
    if not pos.any():  # every draw 0: so is XG
        return out | {k: 0.0 for k in LEVELS}
    y, sp = np.log(x[pos]), s[pos]
    spread = sp > 0

    def cdf(v: float) -> float:  # P(ln XG <= v), the zeros below every v
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            z = np.where(spread, ndtr((v - y) / np.where(spread, sp, 1.0)), (y <= v).astype(float))
        return zero_share + float(np.sum(z)) / n

    pad = 8 * float(sp.max()) + 1e-12 * (1.0 + float(np.max(np.abs(y))))  # the whole mass inside the bracket
    lo, hi = float(y.min()) - pad, float(y.max()) + pad
    for key, p in LEVELS.items():
        out[key] = 0.0 if p <= zero_share else float(np.exp(brentq(lambda v, p=p: cdf(v) - p, lo, hi, xtol=1e-12)))
    return out
