"""What the gauges' electrical noise alone leaves in the bar forces' means over a span (eq. 2-4), for the checks
that compare those means: the force balance (eq. 5) and a channel's scale (:mod:`friction_uq.gauge_balance`,
:mod:`friction_uq.gauge_scale`), the equilibrium over the window (:func:`friction_uq.analysis.identify`).

A mean over ``n`` samples of an offset-corrected wave carries the noise of its samples and the error of the offset
removed from its channel, constant over the span. The input force F_i = E A (eps_i + eps_r) holds two waves of the
same gauge, read one reflection apart (their noises independent, their offset errors the same): twice the offset's
error. The noise is the channel's pre-pulse AR(1) model (:class:`~friction_uq.signals.NoiseEstimate`) with its colour
at an upper bound (:func:`colour_upper`): a pre-trigger only a few correlation times long looks whiter than its noise
is (from 330 samples of lag-1 0.99 noise rho_eff comes out near 0.97, and the offset's error is estimated at less
than half its size), and a check that takes the noise's own wander for a gauge's fault blames a sound gauge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .forces import Forces
from .record import Apparatus
from .signals import NoiseEstimate
from .stats.ar1 import ar1_mean_sd

#: The colour's upper bound: rho_eff, less its small-sample bias, plus this many of its standard errors.
COLOUR_BOUND_SE = 3.0
#: ... and at most this (a correlation time of 2000 samples).
COLOUR_CEILING = 0.999


def colour_upper(noise: NoiseEstimate) -> float:
    """Upper bound of a channel's effective AR(1) coefficient from its pre-pulse segment of n samples: rho_eff with the
    bias of an autocorrelation whose mean is estimated from the same samples taken back, (1 + 3 rho) / n (Kendall's
    first-order bias of the lag-1 coefficient), plus :data:`COLOUR_BOUND_SE` times sqrt((1 - rho^2) / n) (its
    large-sample standard error); at most :data:`COLOUR_CEILING`."""
    n = max(noise.n, 1)
    r = min(COLOUR_CEILING, noise.rho_eff + (1.0 + 3.0 * noise.rho_eff) / n)
    return min(COLOUR_CEILING, r + COLOUR_BOUND_SE * math.sqrt(max(1.0 - r * r, 0.0) / n))


def wave_mean_sd(sd: float, rho: float, n: int, n_baseline: int, *, waves: int = 1) -> float:
    """Noise standard deviation (strain) of the mean over ``n`` samples of the sum of ``waves`` offset-corrected waves
    of one gauge read at times far apart: each wave's AR(1) noise (independent) and the offset's error, the mean of
    ``n_baseline`` pre-pulse samples, taken ``waves`` times.

    >>> round(wave_mean_sd(1.0, 0.0, 100, 100), 6)  # white noise: sqrt(1/100 + 1/100)
    0.141421
    >>> round(wave_mean_sd(1.0, 0.0, 100, 100, waves=2), 6)  # sqrt(2/100 + 4/100)
    0.244949
    """
    return math.hypot(math.sqrt(waves) * ar1_mean_sd(sd, rho, n), waves * ar1_mean_sd(sd, rho, n_baseline))


@dataclass(frozen=True)
class MeanForces:
    """Means (N) of the input and output forces over a span and the noise standard deviation of each."""

    F_i: float
    F_io: float
    F_eo: float
    sd_i: float
    sd_io: float
    sd_eo: float

    @property
    def balance(self) -> float:
        """S = (F_io + F_eo) / F_i (eq. 5: 1); nan when F_i is 0."""
        return (self.F_io + self.F_eo) / self.F_i if self.F_i != 0.0 else math.nan

    @property
    def balance_log_sd(self) -> float:
        """Noise standard deviation of log S (first order); inf when either side is 0. For a channel's factor
        (:meth:`rescaled_log_sd`), not for the balance's own test (:attr:`balance_sd`)."""
        out = self.F_io + self.F_eo
        if out == 0.0 or self.F_i == 0.0:
            return math.inf
        return math.sqrt((self.sd_io ** 2 + self.sd_eo ** 2) / out ** 2 + (self.sd_i / self.F_i) ** 2)

    @property
    def imbalance_sd(self) -> float:
        """Noise standard deviation (N) of F_io + F_eo - F_i (the three gauges' noises independent)."""
        return math.sqrt(self.sd_i ** 2 + self.sd_io ** 2 + self.sd_eo ** 2)

    @property
    def balance_sd(self) -> float:
        """Noise standard deviation of S where eq. 5 holds: :attr:`imbalance_sd` over |F_i| (inf when F_i is 0). The
        balance is weighed under the hypothesis it tests, so that an output sum near zero (dead output gauges) does
        not take the huge relative noise of a small number, and S - 1 is judged the same on either side of 1."""
        return self.imbalance_sd / abs(self.F_i) if self.F_i != 0.0 else math.inf

    def rescaled_log_sd(self, channel: str) -> float:
        """Noise standard deviation of the log of the factor that makes ``channel`` balance the others: F_i / (F_io +
        F_eo) for the input bar, (F_i - F_eo) / F_io and (F_i - F_io) / F_eo for the output bars (inf where the
        difference is not positive)."""
        if channel == "input_bar":
            return self.balance_log_sd
        own, own_sd, other_sd = ((self.F_io, self.sd_io, self.sd_eo) if channel == "internal_output_bar" else
                                 (self.F_eo, self.sd_eo, self.sd_io))
        rest = self.F_i - (self.F_eo if channel == "internal_output_bar" else self.F_io)
        if rest <= 0.0 or own <= 0.0:
            return math.inf
        return math.sqrt((self.sd_i ** 2 + other_sd ** 2) / rest ** 2 + (own_sd / own) ** 2)


def mean_forces(forces: Forces, apparatus: Apparatus, where: np.ndarray | slice) -> MeanForces:
    """The forces' means over ``where`` (a mask or a slice of samples where all three are valid) and their noise
    (:func:`wave_mean_sd`, the colour at :func:`colour_upper`)."""
    n = int(np.size(forces.F_i[where]))
    ch = forces.channels
    means, sds = [], []
    for F, channel, bar, waves in ((forces.F_i, "incident", apparatus.input_bar, 2),
                                   (forces.F_io, "internal_output_bar", apparatus.internal_output_bar, 1),
                                   (forces.F_eo, "external_output_bar", apparatus.external_output_bar, 1)):
        noise = ch[channel].noise
        means.append(float(np.mean(F[where])))
        sds.append(bar.area * bar.young_modulus * wave_mean_sd(noise.sd, colour_upper(noise), n, noise.n, waves=waves))
    return MeanForces(*means, *sds)
