"""Gauge noise for synthetic and simulated records: stationary AR(1), alone or with a white part.

The AR(1) process of the package's noise model (docs/physics.md, the likelihood's noise):

    e_0 ~ N(0, sd^2),   e_k = rho e_{k-1} + w_k,   w_k ~ N(0, sd^2 (1 - rho^2)),

so every sample has standard deviation ``sd`` and lag-1 correlation ``rho``. Randomness comes
from the caller's :class:`numpy.random.Generator` only; the same generator state gives the same
bits. The order of the draws is part of that contract (the bundled data are regenerated from
their seeds and compared by checksum), which is why :func:`ar1_noise` keeps the two orders its
callers were written with (``start``).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from scipy.signal import lfilter

__all__ = ["ar1_noise", "white_and_ar1_noise"]


def ar1_noise(
    shape: int | tuple[int, ...],
    *,
    sd: float,
    rho: float,
    rng: np.random.Generator,
    start: Literal["extra_draw", "first_draw"] = "extra_draw",
) -> np.ndarray:
    """Stationary AR(1) Gaussian noise along the last axis of ``shape``.

    Parameters
    ----------
    shape
        Number of samples (at least 1), or the array shape (series along the last axis).
    sd
        Marginal standard deviation of every sample (same unit as the result), >= 0.
    rho
        Lag-1 coefficient, in (-1, 1).
    rng
        Source of the normal draws.
    start
        Order of the draws. ``"extra_draw"`` (default): the innovations of every sample first, as
        ``rng.normal(0, sd sqrt(1 - rho^2), shape)``, then one more draw per series,
        ``rng.normal(0, sd, shape[:-1])``, for the stationary start e_0 (the first innovation is
        drawn and unused). ``"first_draw"``: one block of standard normals eta of ``shape``;
        e_0 = sd eta_0 and the innovations are sd sqrt(1 - rho^2) eta_k, k >= 1 (the simulator's
        measurement chain).

    Returns
    -------
    numpy.ndarray
        Noise of shape ``shape``.

    Examples
    --------
    >>> x = ar1_noise((400, 500), sd=2.0, rho=0.5, rng=np.random.default_rng(0))
    >>> round(float(x.std()), 1), round(float(np.mean(x[:, 1:] * x[:, :-1]) / x.var()), 1)
    (2.0, 0.5)
    """
    shape = (shape,) if isinstance(shape, (int, np.integer)) else tuple(shape)
    if start == "extra_draw":
        e = rng.normal(0.0, sd * math.sqrt(1.0 - rho**2), size=shape)
        e[..., 0] = rng.normal(0.0, sd, size=shape[:-1])
    elif start == "first_draw":
        eta = rng.standard_normal(shape)
        e = eta * (sd * np.sqrt(1.0 - rho * rho))
        e[..., 0] = eta[..., 0] * sd
    else:
        raise ValueError(f"start {start!r} is not understood, allowed values: 'extra_draw', 'first_draw'")
    return lfilter([1.0], [1.0, -rho], e, axis=-1)


def white_and_ar1_noise(
    n: int, *, sd: float, rho: float, white_fraction: float, rng: np.random.Generator
) -> np.ndarray:
    """White plus AR(1) Gaussian noise of total standard deviation ``sd``, ``n`` samples.

    ``white_fraction`` of the variance is white, the rest AR(1) with coefficient ``rho``
    (:func:`ar1_noise`, drawn first); the white part is drawn after it, even when its level is 0.
    """
    coloured = ar1_noise(n, sd=sd * math.sqrt(1.0 - white_fraction), rho=rho, rng=rng)
    return coloured + rng.normal(0.0, sd * math.sqrt(white_fraction), n)
