"""Whole-record comparison: the simulated test against every gauge, channel by channel, phase by phase.

For posterior draws of a fitted model, the simulator driven by the measured incident wave
(:class:`~friction_uq.models.SimulatorModel`) predicts the reflected wave on the input-bar gauge,
both transmitted waves and the tube hoop gauge over the whole loading. Each channel is compared
from 10 us before its wave arrives until the first far-end echo reaches its gauge (the echo is
not part of the cell's physics), split into three phases by the stationary window carried to the
gauge: ``rise`` (before the window), ``stationary`` (the window), ``unloading`` (after it).

Residual e_t = measured - predicted (the mean prediction over the draws). The gauge's noise is
AR(1) (sd, effective lag-1 coefficient rho, from its pre-pulse segment,
:class:`~friction_uq.signals.NoiseEstimate`); the residual is whitened by the AR(1) innovation
operator, w_1 = e_1 / sd, w_t = (e_t - rho e_{t-1}) / (sd sqrt(1 - rho^2)), so that under "the
model is right" the w_t are independent standard normal. The predicted reflected wave is computed
from the measured incident wave, whose noise it carries (the plug reflects the incident wave almost
whole): its residual has twice the gauge's noise variance.

Per channel and phase: ``level`` (mean residual over its standard error, offset error of the
pre-pulse mean included), ``rms`` (RMS of e / sd), ``chi2_dof`` (mean of w^2) and ``longest_run``
(the longest run of same-sign whitened residuals; about log2(n) under the null).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis import Prepared
from ..signals import baseline_free
from ..stats.ar1 import ar1_mean_sd

#: Channels compared and their labels in reports.
CHANNEL_LABELS = {
    "input_bar": "reflected (input bar)",
    "internal_output_bar": "internal transmitted",
    "external_output_bar": "external transmitted",
    "tube_hoop": "tube hoop",
}
PHASES = ("rise", "stationary", "unloading")
#: Start of a channel's comparison before its wave arrives (s).
LEAD = 10e-6
#: Model tolerance per channel, relative to the signal: a bar gauge's calibration and the bar's E
#: and c are rarely better than 1 %; the tube's influence function is fitted to 2.4 % of its peak
#: (docs/physics.md section 6). The misfit decision forgives residuals within it; the whole-record
#: likelihood adds it to the noise, but on the hoop gauge its own, wider one
#: (:data:`~.record_likelihood.LIKELIHOOD_TOLERANCE`).
TOLERANCE = {"input_bar": 0.01, "internal_output_bar": 0.01, "external_output_bar": 0.01, "tube_hoop": 0.03}
#: Timing tolerance (s): a wave's arrival is known to about a sample (the bars' wave speeds to
#: ~0.05 %, the plug's impact on the incident front's curvature); it forgives tau |dm/dt| on fronts.
TIMING_TOLERANCE = 0.2e-6


def tolerance_sd(measured: np.ndarray, channel: str, *, sample_rate: float, relative: float | None = None,
                 timing: float | None = None) -> np.ndarray:
    """Standard deviation of the model's tolerated error at each sample (strain).

    sqrt((delta_c m_t)^2 + (tau m'_t)^2): m_t the measured |signal| averaged over 2 us, m'_t its
    largest slope within +-1 us, delta_c :data:`TOLERANCE` (or ``relative``), tau :data:`TIMING_TOLERANCE`
    (or ``timing``, s).
    """
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    m = np.asarray(measured, float)
    width = max(1, int(round(2e-6 * sample_rate)))
    level = uniform_filter1d(np.abs(m), width, mode="nearest")
    slope = maximum_filter1d(np.abs(np.gradient(uniform_filter1d(m, 3, mode="nearest"))) * sample_rate, width,
                             mode="nearest")
    delta = TOLERANCE.get(channel, 0.0) if relative is None else float(relative)
    tau = TIMING_TOLERANCE if timing is None else float(timing)
    return np.hypot(delta * level, tau * slope)


@dataclass(frozen=True)
class ChannelNoise:
    """AR(1) noise of a channel's residual (strain): sd, lag-1 coefficient, sd of the offset error."""

    sd: float
    rho: float
    offset_sd: float
    rho_long_run: float = 0.0


@dataclass(frozen=True)
class PhaseFigures:
    """The comparison figures of one channel over one phase."""

    channel: str
    phase: str
    t0: float
    t1: float
    n: int
    level: float
    rms: float
    chi2_dof: float
    longest_run: int
    mean_residual: float
    mean_measured: float

    @property
    def relative_level(self) -> float:
        """Mean residual over the mean measured signal (0 when the signal is ~0)."""
        return self.mean_residual / self.mean_measured if abs(self.mean_measured) > 0 else 0.0

    def to_json(self) -> dict[str, float | int | str]:
        return {"channel": self.channel, "phase": self.phase, "t0": self.t0, "t1": self.t1, "n": self.n,
                "level": self.level, "rms": self.rms, "chi2_dof": self.chi2_dof, "longest_run": self.longest_run,
                "mean_residual": self.mean_residual, "relative_level": self.relative_level}


@dataclass(frozen=True)
class WholeRecord:
    """Measured and simulated channels over the whole record, and the comparison figures."""

    time: np.ndarray
    measured: dict[str, np.ndarray]
    predicted: dict[str, np.ndarray]  # (ndraw, n) per channel
    spans: dict[str, tuple[int, int]]
    phase_bounds: dict[str, tuple[int, int, int, int]]  # i_start, i_window0, i_window1, i_end at the gauge
    noise: dict[str, ChannelNoise]
    figures: tuple[PhaseFigures, ...]
    window: tuple[float, float]

    def residual(self, channel: str) -> np.ndarray:
        """Measured minus mean prediction (strain), whole record."""
        return self.measured[channel] - self.predicted[channel].mean(axis=0)

    def standardised(self, channel: str) -> np.ndarray:
        """Residual over the channel's residual noise sd."""
        return self.residual(channel) / self.noise[channel].sd


def whiten(resid: np.ndarray, *, sd: float, rho: float) -> np.ndarray:
    """AR(1) innovations of ``resid`` scaled to unit variance (module docstring)."""
    e = np.asarray(resid, float)
    w = np.empty_like(e)
    if e.size == 0:
        return w
    w[0] = e[0] / sd
    w[1:] = (e[1:] - rho * e[:-1]) / (sd * math.sqrt(1.0 - rho * rho))
    return w


def longest_sign_run(x: np.ndarray) -> int:
    """Length of the longest run of consecutive values of the same sign (zeros break a run)."""
    s = np.sign(np.asarray(x, float))
    if s.size == 0:
        return 0
    change = np.flatnonzero((s[1:] != s[:-1]) | (s[1:] == 0)) + 1
    edges = np.concatenate([[0], change, [s.size]])
    lengths = np.diff(edges)
    starts = edges[:-1]
    lengths = np.where(s[starts] == 0, 0, lengths)
    return int(lengths.max())


def phase_figures(resid: np.ndarray, measured: np.ndarray, noise: ChannelNoise, *, channel: str, phase: str,
                  t0: float, t1: float) -> PhaseFigures:
    """Figures of one residual segment (module docstring)."""
    n = resid.size
    w = whiten(resid, sd=noise.sd, rho=noise.rho)
    se = math.hypot(ar1_mean_sd(noise.sd, noise.rho_long_run, n), noise.offset_sd)
    m = float(np.mean(resid))
    return PhaseFigures(channel=channel, phase=phase, t0=t0, t1=t1, n=n, level=m / se,
                        rms=float(np.sqrt(np.mean((resid / noise.sd) ** 2))), chi2_dof=float(np.mean(w * w)),
                        longest_run=longest_sign_run(w), mean_residual=m, mean_measured=float(np.mean(measured)))


def phases_of(bounds: tuple[int, int, int, int]) -> tuple[tuple[str, int, int], ...]:
    """(phase, first sample, end) of the rise, the stationary window and the unloading of a channel's span
    (start, window start, window end, end: :func:`channel_spans`)."""
    i0, i1, i2, i3 = bounds
    return tuple(zip(PHASES, (i0, i1, i2), (i1, i2, i3)))


def channel_spans(prep: Prepared, channels: tuple[str, ...]) -> dict[str, tuple[int, int, int, int]]:
    """Per channel: sample indices (start, window start, window end, end) at its gauge (module docstring)."""
    rec, forces = prep.record, prep.forces
    app = rec.apparatus
    fs, n = rec.sample_rate, rec.n_samples
    t = rec.time
    info = forces.channels
    ib = app.input_bar
    lead = LEAD * fs
    out: dict[str, tuple[int, int, int, int]] = {}
    w0, w1 = prep.window.t0, prep.window.t1
    for ch in channels:
        if ch == "input_bar":
            delay = ib.gauge_delay
            start = info["input_bar"].arrival + 2.0 * ib.gauge_delay * fs
            end = info["input_bar"].valid_until  # the reflected wave's far-end echo, less a margin
        elif ch == "tube_hoop":
            delay = 0.0
            start = info["incident"].arrival
            end = start + (app.pulse_duration + 100e-6) * fs
        else:
            bar = app.bars[ch]
            delay = bar.gauge_delay
            start = info[ch].arrival + delay * fs  # ChannelInfo.arrival is at the cell for output bars
            end = info[ch].valid_until + delay * fs
        i0 = max(0, int(math.floor(start - lead)))
        i3 = min(n, int(math.ceil(end)))
        iw0 = int(np.clip(np.searchsorted(t, w0 + delay), i0, i3))
        iw1 = int(np.clip(np.searchsorted(t, w1 + delay, side="right"), iw0, i3))
        out[ch] = (i0, iw0, iw1, i3)
    return out


def channel_noise(prep: Prepared, channel: str) -> ChannelNoise:
    """Noise of a channel's residual; the reflected wave's prediction carries the incident's noise."""
    nz = prep.forces.channels[channel].noise
    factor = math.sqrt(2.0) if channel == "input_bar" else 1.0
    return ChannelNoise(sd=factor * nz.sd, rho=nz.rho, offset_sd=factor * nz.offset_sd, rho_long_run=nz.rho_eff)


def compare_whole_record(prep: Prepared, predicted: dict[str, np.ndarray]) -> WholeRecord:
    """Compare simulated gauges (channel -> (ndraw, n), compression positive) with the record.

    ``predicted`` comes from :meth:`friction_uq.models.SimulatorModel.predict_draws` for posterior
    draws; channels the record lacks are ignored.
    """
    rec = prep.record
    chans = tuple(c for c in CHANNEL_LABELS if c in predicted and c in rec.channels)
    bounds = channel_spans(prep, chans)
    t = rec.time
    measured, figures, noise, spans = {}, [], {}, {}
    for ch in chans:
        meas = baseline_free(rec.strain(ch), prep.forces.channels[ch].noise)  # as the forces read it
        measured[ch] = meas
        noise[ch] = channel_noise(prep, ch)
        resid = meas - predicted[ch].mean(axis=0)
        i0, iw0, iw1, i3 = bounds[ch]
        spans[ch] = (i0, i3)
        for phase, (a, b) in zip(PHASES, ((i0, iw0), (iw0, iw1), (iw1, i3))):
            if b - a < 10:
                continue
            figures.append(phase_figures(resid[a:b], meas[a:b], noise[ch], channel=ch, phase=phase,
                                         t0=float(t[a]), t1=float(t[b - 1])))
    return WholeRecord(time=t, measured=measured, predicted=dict(predicted), spans=spans, phase_bounds=bounds,
                       noise=noise, figures=tuple(figures), window=(prep.window.t0, prep.window.t1))
