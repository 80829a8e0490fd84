"""From a record to interface waves, forces and velocities (eq. 2-7), with each channel's noise.

Steps, per channel:

1. baseline offset, noise standard deviation and lag-1 autocorrelation from the pre-pulse
   segment (:func:`friction_uq.signals.prepulse_noise`), offset removed;
2. waves separated and transported to the bar end touching the cell: on the input bar the
   incident wave (from its arrival until the reflected wave reaches the gauge, 2 d / c later)
   forward by d, the reflected wave back by d; on the output bars the transmitted wave back by d;
3. each transported wave is valid until the first reflection from the bar's far (free) end
   reaches the gauge; outside its validity a wave is set to NaN, so nothing downstream mistakes a
   far-end echo for cell physics;
4. forces and velocities by eq. 2-4, sliding velocity (eq. 7), equilibrium (eq. 5) and
   stationarity (eq. 6) indicators.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .physics import bars as eq
from .record import Bar, Record
from .errors import ShortPreTrigger, SignalError
from .signals import NoiseEstimate, baseline_free, noise_estimate, prepulse_noise, transport, window_mask
from .stats.robust import padding


@dataclass(frozen=True)
class ChannelInfo:
    """What the processing found on one channel (indices are fractional samples)."""

    name: str
    noise: NoiseEstimate
    arrival: float
    valid_until: float
    detected: bool = True


@dataclass(frozen=True)
class Forces:
    """Interface waves, forces (N) and velocities (m/s) on the record's time base.

    Arrays are NaN where no valid wave is available.
    """

    time: np.ndarray
    eps_incident: np.ndarray
    eps_reflected: np.ndarray
    eps_internal: np.ndarray
    eps_external: np.ndarray
    hoop: np.ndarray | None
    F_i: np.ndarray
    F_io: np.ndarray
    F_eo: np.ndarray
    V_i: np.ndarray
    V_io: np.ndarray
    V_eo: np.ndarray
    channels: dict[str, ChannelInfo] = field(default_factory=dict)
    dispersion: bool = False

    @property
    def V(self) -> np.ndarray:
        """Sliding velocity V = V_io - V_eo (m/s). Eq. 7."""
        return eq.sliding_velocity(self.V_io, self.V_eo)

    @property
    def ratio(self) -> np.ndarray:
        """F_eo / F_io."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.F_eo / self.F_io

    @property
    def equilibrium(self) -> np.ndarray:
        """(F_i - F_io - F_eo) / F_i. Eq. 5."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return eq.equilibrium_error(self.F_i, self.F_io, self.F_eo)

    @property
    def stationarity(self) -> np.ndarray:
        """(V_i - V_io) / V_i. Eq. 6."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return eq.stationarity_error(self.V_i, self.V_io)

    @property
    def loading_start(self) -> float:
        """Time (s) the incident wave reaches the plug."""
        return float(np.interp(self.channels["incident"].arrival, np.arange(len(self.time)), self.time))



def _noise_and_arrival(
    x: np.ndarray, *, earliest: float, span: int, polarity: int
) -> tuple[NoiseEstimate, float, bool]:
    """Pre-pulse noise and arrival of a channel whose pulse cannot come before ``earliest`` (index).

    A channel whose pulse stays below its noise (a tiny friction force, say) still has a valid
    noise estimate: the segment then ends where the wave could arrive at the earliest, which is
    also taken as its arrival.
    """
    try:
        nz, arr = prepulse_noise(x, span=span, polarity=polarity)
    except SignalError:
        stop = int(np.floor(earliest)) - 8
        return noise_estimate(x, start=padding(x), stop=stop), float(earliest), False
    if nz.stop > earliest:  # a pulse "before" the earliest possible arrival: keep to physics
        nz = noise_estimate(x, start=nz.start, stop=int(np.floor(earliest)) - 8)
    return nz, arr, True


def _transported(x: np.ndarray, bar: Bar, distance: float, dt: float, dispersion: bool) -> np.ndarray:
    return transport(
        x,
        sample_interval=dt,
        distance=distance,
        wave_speed=bar.wave_speed,
        diameter=bar.outer_diameter,
        inner_diameter=bar.inner_diameter,
        poisson_ratio=bar.poisson_ratio,
        dispersion=dispersion,
    )


def compute_forces(record: Record, *, dispersion: bool = False) -> Forces:
    """Transport the waves of a record to the cell and compute eq. 2-7.

    Parameters
    ----------
    record
        A record read by :func:`friction_uq.record.read_record`.
    dispersion
        Apply the Pochhammer-Chree correction on the solid bars (and the Love estimate on the
        hollow external bar) when transporting; off by default.
    """
    app = record.apparatus
    span = int(app.pulse_duration * record.sample_rate / 2)
    info: dict[str, ChannelInfo] = {}
    eps_i, eps_r, incident_at_cell = _input_bar_waves(record, span, dispersion, info)
    out = {name: _transmitted_wave(record, name, span, incident_at_cell, dispersion, info)
           for name in ("internal_output_bar", "external_output_bar")}
    hoop = _hoop_strain(record, span, incident_at_cell, info) if record.has_hoop else None
    ib, io, eo = app.input_bar, app.internal_output_bar, app.external_output_bar
    eps_io, eps_eo = out["internal_output_bar"], out["external_output_bar"]
    return Forces(
        time=record.time,
        eps_incident=eps_i,
        eps_reflected=eps_r,
        eps_internal=eps_io,
        eps_external=eps_eo,
        hoop=hoop,
        F_i=eq.input_force(eps_i, eps_r, area=ib.area, young_modulus=ib.young_modulus),
        F_io=eq.transmitted_force(eps_io, area=io.area, young_modulus=io.young_modulus),
        F_eo=eq.transmitted_force(eps_eo, area=eo.area, young_modulus=eo.young_modulus),
        V_i=eq.input_velocity(eps_i, eps_r, wave_speed=ib.wave_speed),
        V_io=eq.transmitted_velocity(eps_io, wave_speed=io.wave_speed),
        V_eo=eq.transmitted_velocity(eps_eo, wave_speed=eo.wave_speed),
        channels=info,
        dispersion=dispersion,
    )


def _margin(record: Record) -> float:
    """Samples kept clear of each window's end: 2 % of the pulse."""
    return 0.02 * record.apparatus.pulse_duration * record.sample_rate


def _incident_arrival(record: Record, x: np.ndarray, span: int) -> tuple[NoiseEstimate, float]:
    """The input gauge's pre-pulse noise and the incident front's arrival; a reversed gauge (a tension first) or
    no front at all is refused, naming the file and the channel."""
    try:
        return prepulse_noise(x, span=span, polarity=+1)
    except ShortPreTrigger as exc:
        raise SignalError(f"{record.path}: /signals/input_bar: {exc}") from None
    except SignalError as exc:
        try:  # a compression front in the negated signal: the gauge (or its bridge) is wired the other way
            prepulse_noise(-np.asarray(x, float), span=span, polarity=+1)
        except SignalError:
            raise SignalError(f"{record.path}: /signals/input_bar: {exc} (no incident wave found)") from None
        raise SignalError(f"{record.path}: /signals/input_bar: the first pulse is a tension, where the incident wave "
                          "is a compression: the gauge looks reversed (its wiring, its bridge or the sign convention, "
                          "elongation positive)") from None


def _input_bar_waves(record: Record, span: int, dispersion: bool,
                     info: dict[str, ChannelInfo]) -> tuple[np.ndarray, np.ndarray, float]:
    """The incident and reflected waves at the cell (NaN outside their validity), their channels' entries put in
    ``info``, and the incident front's arrival at the cell (fractional samples)."""
    ib, n, dt, fs = record.apparatus.input_bar, record.n_samples, record.sample_interval, record.sample_rate
    x = record.strain("input_bar")
    noise_in, arr_inc = _incident_arrival(record, x, span)
    y = baseline_free(x, noise_in)
    sep = arr_inc + 2.0 * ib.gauge_delay * fs  # reflected wave's front at the gauge
    margin = _margin(record)
    echo = arr_inc + 2.0 * ib.length / ib.wave_speed * fs  # far-end echo of the reflected wave
    inc = np.where(window_mask(n, noise_in.start, sep - margin), y, 0.0)  # not an unfilled pre-trigger's samples
    ref = np.where(window_mask(n, sep - margin, echo - margin), y, 0.0)
    eps_i = _transported(inc, ib, +ib.gauge_distance, dt, dispersion)
    eps_r = _transported(ref, ib, -ib.gauge_distance, dt, dispersion)
    d_in = ib.gauge_delay * fs
    # far-end echo, end of the incident window, end of the record (the reflected wave brought back by d_in)
    valid_until_in = min(echo - d_in, sep + d_in, n - d_in) - margin
    valid_in = window_mask(n, arr_inc + d_in - margin, valid_until_in)
    info["incident"] = ChannelInfo("incident", noise_in, arr_inc + d_in, valid_until_in)
    info["input_bar"] = ChannelInfo("input_bar", noise_in, arr_inc, echo - margin)
    return np.where(valid_in, eps_i, np.nan), np.where(valid_in, eps_r, np.nan), arr_inc + d_in


def _transmitted_wave(record: Record, name: str, span: int, incident_at_cell: float, dispersion: bool,
                      info: dict[str, ChannelInfo]) -> np.ndarray:
    """Output bar ``name``'s transmitted wave back by its gauge distance (NaN once its far-end echo is in), its
    channel's entry put in ``info``."""
    bar, n, fs = record.apparatus.bars[name], record.n_samples, record.sample_rate
    x = record.strain(name)
    d = bar.gauge_delay * fs
    margin = _margin(record)
    nz, arr, found = _noise_and_arrival(x, earliest=incident_at_cell + d, span=span, polarity=+1)
    echo = arr + 2.0 * (bar.length - bar.gauge_distance) / bar.wave_speed * fs
    y = np.where(window_mask(n, nz.start, echo - margin), baseline_free(x, nz), 0.0)
    eps = _transported(y, bar, -bar.gauge_distance, record.sample_interval, dispersion)
    valid_until = min(echo, n) - d - margin  # its far-end echo, or the record's end, brought back by d
    info[name] = ChannelInfo(name, nz, arr - d, valid_until, found)
    return np.where(window_mask(n, 0, valid_until), eps, np.nan)


def _hoop_strain(record: Record, span: int, incident_at_cell: float, info: dict[str, ChannelInfo]) -> np.ndarray:
    """The tube's hoop strain, offset removed (the tube swells: compression-positive hoop strain goes negative),
    its channel's entry put in ``info``."""
    x = record.strain("tube_hoop")
    nz, arr, found = _noise_and_arrival(x, earliest=incident_at_cell, span=span, polarity=-1)
    info["tube_hoop"] = ChannelInfo("tube_hoop", nz, arr, float(record.n_samples), found)
    return baseline_free(x, nz)
