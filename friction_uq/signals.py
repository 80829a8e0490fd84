"""Generic gauge-signal processing: baseline and noise, pulse arrival, transport to an interface.

Nothing here knows about the friction cell: these functions work on any split Hopkinson bar
record (the tests run them on a real two-bar SHPB record too). Signals are strain, compression
positive, sampled uniformly.

Conventions
-----------
*Pre-pulse segment*: the samples before a channel's first pulse, less a safety margin. The gauge
is at rest there, so its mean is the amplifier offset and its spread is the electrical noise of
the channel; this is the segment the whole package uses to estimate noise, because it is the only
part of a record where the true signal is known (zero). The noise is summarised by its standard
deviation, its lag-1 autocorrelation, and the *effective* AR(1) coefficient: the one whose AR(1)
process has the same long-run variance (sum of all autocorrelations) as the measured noise.
Real gauge noise is a mixture (white electronics plus coloured amplifier noise), whose lag-1
coefficient understates the variance of a mean; the effective coefficient does not. The
long-run variance is estimated with Geyer's initial positive sequence on the autocorrelation
of the segment.

*Arrival*: the foot of the first pulse, where the line through the front's 10 % and 50 %
crossings (linearly interpolated between samples) meets the baseline. Exact for a linear front,
sub-sample for any smooth one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as scipy_fft

from .dispersion import propagate
from .errors import ShortPreTrigger, SignalError
from .stats.ar1 import ar1_mean_sd
from .record.contract import HEAD_FRACTION
from .stats.robust import (SPIKE_FILTER, SPIKE_SIGMAS, despiked, median_and_sd, padding, quantisation_step,
                           running_median)

#: Threshold, in noise standard deviations, for the first crossing that starts an arrival search.
ARRIVAL_SIGMAS = 8.0
#: The crossing must also exceed this fraction of the channel's largest excursion.
ARRIVAL_FRACTION = 0.05
#: A head whose median departs from its first 32 samples' by this fraction of the channel's swing holds the pulse.
HEAD_MEDIAN_SHIFT = 0.25
#: Minimum pre-pulse segment (samples) for a noise estimate.
MIN_BASELINE_SAMPLES = 32


@dataclass(frozen=True)
class NoiseEstimate:
    """Baseline statistics of one channel from its pre-pulse segment.

    Attributes
    ----------
    offset : float
        Mean of the segment (strain): the amplifier offset.
    sd : float
        Standard deviation of the segment (strain).
    rho : float
        Lag-1 autocorrelation of the segment, in (-1, 1).
    rho_eff : float
        AR(1) coefficient with the segment's long-run variance, (tau - 1) / (tau + 1) with tau
        the integrated autocorrelation (1 + 2 sum of autocorrelations), in [0, 1).
    start, stop : int
        Sample indices of the segment, ``x[start:stop]``.
    """

    offset: float
    sd: float
    rho: float
    start: int
    stop: int
    rho_eff: float = 0.0

    @property
    def n(self) -> int:
        return self.stop - self.start

    @property
    def offset_sd(self) -> float:
        """Standard error of ``offset`` (the segment's mean): sd sqrt(tau / n)."""
        return ar1_mean_sd(self.sd, self.rho_eff, self.n)

    def window_mean_sd(self, n: int, *, scale: float = 1.0) -> float:
        """Standard error of the mean of ``n`` offset-corrected samples, times ``scale`` (units).

        Noise of the mean (effective AR(1)) and the error of the removed offset, which is
        constant over the window.
        """
        return scale * math.hypot(ar1_mean_sd(self.sd, self.rho_eff, n), self.offset_sd)


def noise_estimate(x: np.ndarray, *, start: int = 0, stop: int) -> NoiseEstimate:
    """Offset, standard deviation and lag-1 autocorrelation of ``x[start:stop]``, its spikes left out
    (:func:`friction_uq.stats.robust.despiked`). When the channel is quantised
    (:func:`~friction_uq.stats.robust.quantisation_step`) and the segment holds two values or fewer (its noise not
    resolved), the standard deviation is at least the rounding's, step / sqrt(12).

    >>> rng = np.random.default_rng(1)
    >>> e = noise_estimate(3.0 + rng.normal(0, 2.0, 20000), stop=20000)
    >>> round(e.offset, 1), round(e.sd, 1), abs(e.rho) < 0.05
    (3.0, 2.0, True)
    """
    seg = np.asarray(x[start:stop], dtype=float)
    if seg.size < MIN_BASELINE_SAMPLES:
        raise SignalError(
            f"the pre-pulse segment has {seg.size} samples, at least {MIN_BASELINE_SAMPLES} are needed "
            "to estimate the baseline and noise"
        )
    step = quantisation_step(x)
    seg = despiked(seg, width=SPIKE_FILTER, sigmas=SPIKE_SIGMAS, step=step)
    offset = float(seg.mean())
    d = seg - offset
    var = float(np.mean(d * d))
    sd = float(np.sqrt(var * seg.size / (seg.size - 1)))
    if step > 0.0 and np.unique(seg).size <= 2:  # noise not resolved; a wave read through many codes carries rounding
        sd = max(sd, step / math.sqrt(12.0))
    rho = float(np.sum(d[1:] * d[:-1]) / (var * seg.size)) if var > 0 else 0.0
    rho = float(np.clip(rho, -0.99, 0.99))
    tau = integrated_autocorrelation(d)
    rho_eff = float(np.clip((tau - 1.0) / (tau + 1.0), 0.0, 0.99))
    return NoiseEstimate(offset=offset, sd=sd, rho=rho, start=int(start), stop=int(stop), rho_eff=rho_eff)


def integrated_autocorrelation(d: np.ndarray) -> float:
    """tau = 1 + 2 sum_k rho_k of a zero-mean series, Geyer's initial positive sequence (>= 1).

    Autocorrelations from the FFT; pairs rho_{2m} + rho_{2m+1} are summed while positive, at lags
    below a quarter of the length.
    """
    n = len(d)
    var = float(np.dot(d, d)) / n
    if var == 0.0 or n < 8:
        return 1.0
    m = scipy_fft.next_fast_len(2 * n)
    spec = np.fft.rfft(d, m)
    acov = np.fft.irfft(spec * np.conj(spec), m)[: n // 4] / n
    r = acov / var
    total = -1.0  # r[0] = 1 counted once in 1 + 2 sum_{k>=1}: pairs start at lag 0
    for k in range(0, len(r) - 1, 2):
        pair = r[k] + r[k + 1]
        if pair <= 0.0:
            break
        total += 2.0 * pair
    return max(1.0, total)


def first_crossing(y: np.ndarray, level: float, *, start: int = 0) -> float | None:
    """Fractional index where ``y`` first rises through ``level`` at or after ``start`` (None if never); ``start``
    itself when ``y`` is already at the level there (nothing to interpolate: the sample before may be above it too)."""
    above = np.flatnonzero(y[start:] >= level)
    if above.size == 0:
        return None
    i = start + int(above[0])
    if i == 0 or not y[i - 1] < level:
        return float(i)
    y0, y1 = y[i - 1], y[i]
    return (i - 1) + float((level - y0) / (y1 - y0))


def pulse_arrival(
    x: np.ndarray,
    *,
    offset: float,
    sd: float,
    start: int = 0,
    span: int | None = None,
    polarity: int = 0,
) -> float:
    """Fractional sample index of the foot of the first pulse after ``start``.

    Parameters
    ----------
    x
        Signal (strain).
    offset, sd
        Baseline offset and noise standard deviation of the channel.
    start
        First index searched.
    span
        Samples after the first threshold crossing searched for the pulse's peak (default: to the
        end of the signal).
    polarity
        +1 for a compressive pulse, -1 for a tensile one, 0 for whichever comes first.

    Raises
    ------
    SignalError
        If no sample rises above the noise.
    """
    return pulse_front(x, offset=offset, sd=sd, start=start, span=span, polarity=polarity)[0]


def pulse_front(
    x: np.ndarray,
    *,
    offset: float,
    sd: float,
    start: int = 0,
    span: int | None = None,
    polarity: int = 0,
) -> tuple[float, float, float]:
    """Foot, 10 % and 50 % crossings (fractional indices) of the first pulse; see :func:`pulse_arrival`."""
    y = np.asarray(x, dtype=float) - offset
    if polarity == 0:
        excursion = np.abs(y[start:])
    else:
        excursion = polarity * y[start:]
    # a spike (EMI, a trigger's pick-up) is no pulse: a running median keeps the fronts, as they are monotone
    excursion = running_median(excursion, SPIKE_FILTER)
    peak_all = float(excursion.max()) if excursion.size else 0.0
    level = max(ARRIVAL_SIGMAS * sd, ARRIVAL_FRACTION * peak_all)
    hit = np.flatnonzero(excursion >= level)
    if hit.size == 0 or peak_all <= ARRIVAL_SIGMAS * sd:
        raise SignalError("no pulse rises above the noise")
    i0 = start + int(hit[0])
    sign = polarity if polarity != 0 else (1 if y[i0] > 0 else -1)
    s = sign * y
    stop = len(s) if span is None else min(len(s), i0 + span)
    peak = float(running_median(s[i0:stop], SPIKE_FILTER).max())  # a spike on the pulse is not its peak either
    j50 = max(start, i0 - 1)
    while j50 > start and s[j50] >= 0.5 * peak:  # a noisy, slow front may be past half its peak already: back to
        j50 -= 1                                 # the last sample below it, so the crossing straddles two samples
    t50 = first_crossing(s, 0.5 * peak, start=j50)
    t10_start = start
    # walk back from the 50 % crossing to the last sample below 10 % of the peak
    j = int(np.floor(t50)) if t50 is not None else i0
    while j > t10_start and s[j] >= 0.1 * peak:
        j -= 1
    t10 = first_crossing(s, 0.1 * peak, start=j)
    if t10 is None or t50 is None or t50 <= t10:
        return float(i0), float(i0), float(i0)
    # line through (t10, 0.1 peak) and (t50, 0.5 peak) meets zero at:
    return t10 - 0.25 * (t50 - t10), t10, t50


def prepulse_noise(
    x: np.ndarray, *, margin: int = 8, initial_fraction: float = HEAD_FRACTION, span: int | None = None,
    polarity: int = 0,
) -> tuple[NoiseEstimate, float]:
    """Noise estimate from the pre-pulse segment, and the first pulse's arrival (fractional index).

    A provisional, robust baseline (median and median absolute deviation of the first
    ``initial_fraction`` of the record, at least 32 samples) locates the first pulse; when the pulse's
    front is in that head (a pre-trigger shorter than it) or no front is found from it, the head is
    cut where a first look from the first 32 samples finds the front, and the pulse located again.
    The segment then runs from the start to ``margin`` samples before that arrival and is estimated
    again.
    """
    n = len(x)
    lead = padding(x)  # an unfilled pre-trigger: the baseline starts after it
    n0 = min(n - lead, max(MIN_BASELINE_SAMPLES, int(initial_fraction * n)))

    def front(head: int) -> tuple[float, float, float]:
        med, sd = median_and_sd(x[lead:lead + head])
        return pulse_front(x, offset=med, sd=max(sd, 1e-300), start=lead, span=span, polarity=polarity)

    def clear_of(arrival: float, t10: float, t50: float) -> int:
        """Samples before the front less the margin (a smooth front starts one 10-50 % rise before its foot), from
        the baseline's start."""
        return int(np.floor(arrival - (t50 - t10))) - margin - lead

    med_first, _ = median_and_sd(x[lead:lead + MIN_BASELINE_SAMPLES])
    swing = float(np.max(np.abs(np.asarray(x[lead:], dtype=float) - med_first))) if n > lead else 0.0
    try:
        arrival, t10, t50 = front(n0)
        # the front beyond the head, and the head's median its first samples' (a pulse filling most of a short
        # pre-trigger's head, quantised more coarsely than its noise, makes the median the pulse's and the MAD 0)
        head_clean = clear_of(arrival, t10, t50) >= n0 and abs(median_and_sd(x[lead:lead + n0])[0] - med_first) <= (
            HEAD_MEDIAN_SHIFT * swing)
    except SignalError:
        head_clean = False
    if not head_clean:  # a pre-trigger shorter than the head: cut it where a first look from 32 samples finds the front
        first = front(MIN_BASELINE_SAMPLES)
        arrival, t10, t50 = front(max(MIN_BASELINE_SAMPLES, min(n0, clear_of(*first))))
    if clear_of(arrival, t10, t50) < MIN_BASELINE_SAMPLES:
        unfilled = f" after {lead} samples that all repeat the first (an unfilled pre-trigger)" if lead else ""
        raise ShortPreTrigger(
            f"the first pulse arrives at sample {arrival:.0f}, its front rising from sample "
            f"{arrival - (t50 - t10):.0f}, leaving {max(clear_of(arrival, t10, t50), 0)} samples of pre-pulse "
            f"baseline{unfilled} where at least {MIN_BASELINE_SAMPLES} are needed: record a longer pre-trigger"
        )
    est = noise_estimate(x, start=lead, stop=lead + clear_of(arrival, t10, t50))
    # a second pass with the refined baseline
    arrival = pulse_arrival(x, offset=est.offset, sd=max(est.sd, 1e-300), start=lead, span=span, polarity=polarity)
    return est, arrival


def baseline_free(x: np.ndarray, noise: NoiseEstimate) -> np.ndarray:
    """``x`` less its offset, the spikes of its pre-pulse segment left out as they are of its noise (a spike before a
    front is no wave) and zero before the segment's start (an unfilled pre-trigger is no wave either)."""
    x = np.asarray(x, dtype=float)
    seg = x[noise.start:noise.stop]
    clean = despiked(seg, step=quantisation_step(x))
    if clean is not seg and not np.array_equal(clean, seg):
        x = np.concatenate([x[:noise.start], clean, x[noise.stop:]])
    return np.where(np.arange(x.size) >= noise.start, x - noise.offset, 0.0)


def window_mask(n: int, start: float, stop: float) -> np.ndarray:
    """Boolean mask of the samples with start <= index < stop (fractional bounds allowed)."""
    i = np.arange(n)
    return (i >= start) & (i < stop)


def transport(
    x: np.ndarray,
    *,
    sample_interval: float,
    distance: float,
    wave_speed: float,
    diameter: float | None = None,
    inner_diameter: float = 0.0,
    poisson_ratio: float | None = None,
    dispersion: bool = False,
) -> np.ndarray:
    """Move a wave recorded at a gauge by ``distance`` along its direction of travel.

    ``distance`` > 0 carries a wave forward (incident: gauge -> interface); ``distance`` < 0
    brings a wave back to where it came from (reflected and transmitted: interface <- gauge).
    Without dispersion this is an exact sub-sample delay by distance / wave_speed; with it, each
    frequency travels at the first-mode Pochhammer-Chree phase velocity of the bar (see
    :mod:`friction_uq.dispersion`). The signal must be baseline-free (zero at both ends).
    """
    return propagate(
        np.asarray(x, dtype=float),
        sample_interval=sample_interval,
        distance=distance,
        c0=wave_speed,
        diameter=diameter,
        nu=poisson_ratio,
        inner_diameter=inner_diameter,
        dispersive=dispersion,
    )


def moving_average(x: np.ndarray, width: int) -> np.ndarray:
    """Centred moving average over ``width`` samples (edges averaged over what exists)."""
    width = max(1, int(width))
    kernel = np.ones(width)
    num = np.convolve(x, kernel, mode="same")
    den = np.convolve(np.ones_like(x), kernel, mode="same")
    return num / den
