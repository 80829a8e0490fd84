"""The force balance of a two-bar record as a forward model: the transmitted gauge predicted from the input gauge.

Observation. The transmitted gauge's strain over the transmitted wave's span (from ``LEAD``
before its foot until it has fallen below 10 % of its peak, plus the separation margin), as read
with the header gain: the same data for every model compared.

Prediction. A specimen in equilibrium carries the same force on both faces, F_1 = F_2 (eq. 2-3,
Durand et al. 2016). So the input gauge's waves, carried to the input face, give the force the
output face passes on, and carried on to the transmitted gauge they predict what it reads:

    eps_t,pred(t) = gamma T_tr[+d_t] ( (A_i E_i) / (A_t E_t) (T_in[+d_i] eps_I + T_in[-d_i] eps_R) )

with T[z] the transport over a signed distance z (:func:`~friction_uq.signals.transport`, a delay
z / c or the Pochhammer-Chree first mode), gamma the transmitted channel's gain error (true gain
over the gain used) and c = s c0 with s the wave-speed factor (the travel times only: E is the
stated one). The nominal model is gamma = 1, s = 1, no dispersion.

Noise. The residual carries the transmitted gauge's noise and the input gauge's twice (incident
and reflected windows, 156 us apart, independent), times the impedance ratio: variance
sd_t^2 + 2 r^2 sd_i^2, lag-1 coefficient the variance-weighted mean of the two channels' (the
sum of two AR(1) series is close to AR(1) when their coefficients are close: 0.18 and 0.28 on
the LANL record); with a gain factor gamma the input gauge's part is scaled by gamma.
Dispersion low-passes the transported noise a little; the same noise model is kept for every
model so that all are scored on the same footing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..discrepancy.whole_record import longest_sign_run, whiten
from ..signals import transport
from ..stats.ar1 import ar1_loglike, ar1_mean_sd
from .record import BarProperties, TwoBarRecord
from .waves import GaugeWaves, gauge_waves, stated_gain

#: Start of the observed span before the transmitted wave's foot (s).
LEAD = 10e-6


@dataclass(frozen=True)
class BarSettings:
    """Values of the bar-level mechanisms: the nominal model is ``BarSettings()``."""

    gain_factor: float = 1.0
    speed_factor: float = 1.0
    dispersion: bool = False


def transmitted_from_input(
    incident: np.ndarray,
    reflected: np.ndarray,
    *,
    sample_interval: float,
    input_bar: BarProperties,
    transmitted_bar: BarProperties,
    speed_factor: float = 1.0,
    dispersion: bool = False,
) -> np.ndarray:
    """Transmitted gauge strain predicted by force balance, F_1 = F_2 (eq. 2-3; module docstring)."""

    def moved(wave: np.ndarray, bar: BarProperties, distance: float) -> np.ndarray:
        return transport(wave, sample_interval=sample_interval, distance=distance,
                         wave_speed=speed_factor * bar.wave_speed, diameter=bar.diameter,
                         poisson_ratio=bar.poisson_ratio, dispersion=dispersion)

    ib, tb = input_bar, transmitted_bar
    face = moved(incident, ib, +ib.gauge_distance) + moved(reflected, ib, -ib.gauge_distance)
    ratio = (ib.area * ib.young_modulus) / (tb.area * tb.young_modulus)
    return moved(ratio * face, tb, +tb.gauge_distance)


@dataclass(frozen=True)
class Misfit:
    """How far a prediction is from the observation (figures of the whole-record comparison).

    ``level``: mean residual over its standard error; ``rms``: RMS of e / sd; ``chi2_dof``: mean
    of the squared whitened residual; ``longest_run``: longest run of same-sign whitened
    residuals; ``rms_force`` (N) and ``relative_rms`` (over the peak transmitted force).
    """

    level: float
    rms: float
    chi2_dof: float
    longest_run: int
    rms_force: float
    relative_rms: float

    def to_json(self) -> dict[str, float]:
        return {k: float(v) for k, v in self.__dict__.items()}


class BalanceObservation:
    """The observed transmitted span of a record, its noise and the balance prediction.

    Parameters
    ----------
    record
        A record read by :func:`~friction_uq.shpb.read_lanl_raw`.
    gain
        The transmitted channel's gain used to read it (V/V); default the header's "Transmitted
        Bar Gain" (the nominal model's).
    """

    def __init__(self, record: TwoBarRecord, *, gain: float | None = None) -> None:
        tb = record.transmitted_bar
        self.record = record
        self.header_gain = float(gain) if gain is not None else _header_gain(record)
        ib = record.input_bar
        speed = ib.timing_wave_speed or ib.wave_speed  # only places the search for the reflected front
        self.waves: GaugeWaves = gauge_waves(record, gain=self.header_gain, input_gain=stated_gain(ib),
                                             reflection_speed=speed)
        dt = record.sample_interval
        start = max(0, int(math.floor(self.waves.arrivals["transmitted"] - LEAD / dt)))
        stop = int(math.ceil(self.waves.spans["transmitted"][1]))
        self.span = slice(start, min(stop, record.n_samples))
        self.observed = np.asarray(self.waves.transmitted[self.span])
        self.force_scale = tb.area * tb.young_modulus  # N per unit strain on the transmitted bar
        ratio = (ib.area * ib.young_modulus) / self.force_scale
        nt, ni = self.waves.noise["transmitted"], self.waves.noise["input"]
        var_t, var_i = nt.sd**2, 2.0 * (ratio * ni.sd) ** 2
        self._var = (var_t, var_i)
        self.sd = math.sqrt(var_t + var_i)
        self.rho = (var_t * nt.rho + var_i * ni.rho) / (var_t + var_i)
        self.rho_long_run = (var_t * nt.rho_eff + var_i * ni.rho_eff) / (var_t + var_i)
        self.peak_force = self.force_scale * float(self.observed.max())

    @property
    def n(self) -> int:
        return int(self.observed.size)

    @property
    def time(self) -> np.ndarray:
        return self.record.time[self.span]

    def predict(self, settings: BarSettings) -> np.ndarray:
        """Predicted transmitted gauge strain over the span (read with the header gain)."""
        w, rec = self.waves, self.record
        full = transmitted_from_input(w.incident, w.reflected, sample_interval=rec.sample_interval,
                                      input_bar=rec.input_bar, transmitted_bar=rec.transmitted_bar,
                                      speed_factor=settings.speed_factor, dispersion=settings.dispersion)
        return settings.gain_factor * full[self.span]

    def residual(self, settings: BarSettings) -> np.ndarray:
        return self.observed - self.predict(settings)

    def noise_sd(self, gain_factor: float = 1.0) -> float:
        """Residual noise sd (strain): the prediction carries the input gauge's noise times gamma."""
        var_t, var_i = self._var
        return math.sqrt(var_t + gain_factor**2 * var_i)

    def loglike(self, settings: BarSettings, *, noise_scale: float = 1.0) -> float:
        """Exact AR(1) Gaussian log-likelihood of the residual, noise sd times ``noise_scale``."""
        sd = noise_scale * self.noise_sd(settings.gain_factor)
        return float(ar1_loglike(self.residual(settings), sd, self.rho))

    def misfit(self, resid: np.ndarray, *, gain_factor: float = 1.0) -> Misfit:
        e = np.asarray(resid, float)
        sd = self.noise_sd(gain_factor)
        w = whiten(e, sd=sd, rho=self.rho)
        rms_force = self.force_scale * float(np.sqrt(np.mean(e * e)))
        return Misfit(
            level=float(e.mean()) / ar1_mean_sd(sd, self.rho_long_run, e.size),
            rms=float(np.sqrt(np.mean((e / sd) ** 2))),
            chi2_dof=float(np.mean(w * w)),
            longest_run=longest_sign_run(w),
            rms_force=rms_force,
            relative_rms=rms_force / self.peak_force,
        )


def _header_gain(record: TwoBarRecord) -> float:
    """The transmitted bar's "Transmitted Bar Gain" field (LANL's own analysis reads this one)."""
    gains = record.transmitted_bar.gains
    for key, value in gains.items():
        if "calibrated" not in key.lower():
            return float(value)
    return stated_gain(record.transmitted_bar)
