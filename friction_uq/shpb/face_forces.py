"""Waves at the specimen faces of a two-bar SHPB test, the forces on both faces and their balance.

Quarter-bridge strain from volts (:meth:`BarProperties.strain`), the generic signal code of
:mod:`friction_uq.signals` (baseline, noise, arrivals, transport) and eq. 2-3 of
:mod:`friction_uq.physics.bars`.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

import numpy as np

from ..physics import bars as eq
from ..signals import NoiseEstimate, transport
from .record import BarProperties, TwoBarRecord
from .waves import PULSE_END_FRACTION, gauge_waves  # noqa: F401 - PULSE_END_FRACTION handed on by the package

#: Fraction of the peak transmitted force above which the balance is assessed (the loading).
BALANCE_LEVEL = 0.5

#: Which wave speeds set the gauge-to-face travel times (see :func:`transport_speeds`).
WaveSpeed = Literal["timing", "rod"]


@dataclass(frozen=True)
class TwoBarForces:
    """Waves at the specimen faces, forces and their balance, on the record's time base.

    Attributes
    ----------
    time : numpy.ndarray
        Time (s), shape (n,).
    eps_incident, eps_reflected, eps_transmitted : numpy.ndarray
        Baseline-free waves transported to the specimen faces (strain, compression positive).
    front_force, back_force : numpy.ndarray
        F_1 = A E (eps_i + eps_r) on the input face (eq. 2) and F_2 = A E eps_t on the output
        face (eq. 3), in N.
    input_gain, transmitted_gain : float
        Amplifier gains used (V/V).
    wave_speeds : tuple[float, float]
        Speeds (input, transmitted) that set the gauge-to-face travel times (m/s).
    noise : Mapping[str, NoiseEstimate]
        Pre-pulse baseline of the "input" and "transmitted" channels (strain).
    arrivals : Mapping[str, float]
        Arrival (foot, :func:`friction_uq.signals.pulse_arrival`) of the "incident" and
        "reflected" waves on the input gauge and of the "transmitted" wave on its gauge (s).
    window : tuple[float, float]
        Loading window [start, stop) (s): the contiguous run of samples around the peak of F_2
        where F_2 >= ``BALANCE_LEVEL`` times its peak.
    balance_error : float
        mean |F_1 - F_2| / mean F_2 over the loading window (dimensionless).
    impulse_error : float
        (integral F_1 - integral F_2) / integral F_2 over the loading window (signed).
    dispersion : bool
        Whether the Pochhammer-Chree correction was applied in the transport.
    """

    time: np.ndarray
    eps_incident: np.ndarray
    eps_reflected: np.ndarray
    eps_transmitted: np.ndarray
    front_force: np.ndarray
    back_force: np.ndarray
    input_gain: float
    transmitted_gain: float
    wave_speeds: tuple[float, float]
    noise: Mapping[str, NoiseEstimate]
    arrivals: Mapping[str, float]
    window: tuple[float, float]
    balance_error: float
    impulse_error: float
    dispersion: bool

    @property
    def loading(self) -> np.ndarray:
        """Boolean mask of the loading window."""
        return (self.time >= self.window[0]) & (self.time < self.window[1])


def _loading_window(force: np.ndarray) -> tuple[int, int]:
    """[start, stop) of the contiguous run around the peak where force >= BALANCE_LEVEL * peak."""
    k = int(np.argmax(force))
    above = force >= BALANCE_LEVEL * force[k]
    start = k
    while start > 0 and above[start - 1]:
        start -= 1
    stop = k + 1
    while stop < force.size and above[stop]:
        stop += 1
    return start, stop


def transport_speeds(record: TwoBarRecord, *, wave_speed: WaveSpeed = "timing") -> tuple[float, float]:
    """Wave speeds (input, transmitted) that set the gauge-to-face travel times d / c (m/s).

    ``"rod"``: the stated rod speeds c0. ``"timing"``: the speed from the input bar's calibrated
    reflection time, 2 d / t_reflected (a direct measurement of the travel time over 2 d); the
    transmitted bar, for which the file gives none, takes its c0 times the same ratio (the same
    speed for identical bars). Falls back to c0 when the file has no calibrated reflection time.
    """
    ib, tb = record.input_bar, record.transmitted_bar
    if wave_speed == "rod" or (wave_speed == "timing" and ib.timing_wave_speed is None):
        return ib.wave_speed, tb.wave_speed
    if wave_speed == "timing":
        ratio = ib.timing_wave_speed / ib.wave_speed
        return ib.timing_wave_speed, tb.wave_speed * ratio
    raise ValueError(f"wave_speed {wave_speed!r} is not understood, allowed values: 'timing', 'rod'")


def two_bar_forces(
    record: TwoBarRecord,
    *,
    gain: float,
    input_gain: float | None = None,
    dispersion: bool = False,
    wave_speed: WaveSpeed = "timing",
) -> TwoBarForces:
    """Forces on both faces of the specimen and their balance.

    Steps:

    1. volts to strain (:meth:`BarProperties.strain`); each channel's baseline offset and noise
       from its pre-pulse segment (:func:`~friction_uq.signals.prepulse_noise`), offset removed;
    2. on the input gauge, the incident wave is what comes before the reflected front (2 d / c
       after the incident's foot, less a margin of 1 % of that time, at least 8 samples); the
       reflected wave is what comes after. Each wave (and the transmitted one) is kept until it has
       fallen below 10 % of its peak, plus the margin, and set to zero elsewhere (this cuts the
       far-end echoes, whose timing the file does not give);
    3. the incident wave is transported forward by d, the reflected and transmitted waves back by
       their d (:func:`~friction_uq.signals.transport`, speeds from :func:`transport_speeds`);
    4. F_1 = A E (eps_i + eps_r) (eq. 2), F_2 = A E eps_t (eq. 3; Durand et al. 2016);
    5. loading window: the contiguous samples around the peak of F_2 where F_2 >= 50 % of it.
       Balance error: mean |F_1 - F_2| / mean F_2 over it; impulse error: (sum F_1 - sum F_2) /
       sum F_2 over it.

    Parameters
    ----------
    record
        A record read by :func:`read_lanl_raw`.
    gain
        Amplifier gain of the transmitted-bar channel (V/V). This is the disputed one: the LANL
        file says 200 ("Transmitted Bar Gain") and 500 ("Transmitted Bar Calibrated Gain"). A
        gain common to both channels cancels from the balance error, so only the ratio of the two
        gains can be tested by the balance. (LANL's own analysis code, HopPyBar.py, reads the
        "... Bar Gain" fields, 200 and 200, and keeps the "Calibrated Gain" ones as information.)
    input_gain
        Amplifier gain of the input-bar channel (V/V); by default the file's value, when all its
        fields for that bar agree (200 in both for the LANL copper record).
    dispersion
        Transport with the Pochhammer-Chree first-mode correction (which also low-passes at the
        first-mode cut-off, about 270 kHz for these 9.47 mm bars) instead of a pure delay; the
        phase velocity curve is scaled by the transport speed of ``wave_speed``.
    wave_speed
        ``"timing"`` (default) or ``"rod"``: which speeds set the travel times d / c, see
        :func:`transport_speeds`.

    Returns
    -------
    TwoBarForces

    Raises
    ------
    SignalError
        If a pulse cannot be found, or the input bar's gain fields disagree and ``input_gain`` is
        not given.
    ValueError
        If a gain is not a positive finite number or ``wave_speed`` is not understood.
    """
    for name, g in (("gain", gain), ("input_gain", input_gain)):
        valid = isinstance(g, numbers.Real) and not isinstance(g, bool) and math.isfinite(g) and g > 0
        if g is not None and not valid:
            raise ValueError(f"{name} must be a positive finite number (V/V), received {g!r}")
    ib, tb = record.input_bar, record.transmitted_bar
    c_in, c_tr = transport_speeds(record, wave_speed=wave_speed)
    gw = gauge_waves(record, gain=gain, input_gain=input_gain, reflection_speed=c_in)
    dt = record.sample_interval
    g_in = gw.input_gain

    def moved(wave: np.ndarray, bar: BarProperties, speed: float, distance: float) -> np.ndarray:
        return transport(
            wave,
            sample_interval=dt,
            distance=distance,
            wave_speed=speed,
            diameter=bar.diameter,
            poisson_ratio=bar.poisson_ratio,
            dispersion=dispersion,
        )

    eps_i = moved(gw.incident, ib, c_in, +ib.gauge_distance)
    eps_r = moved(gw.reflected, ib, c_in, -ib.gauge_distance)
    eps_t = moved(gw.transmitted, tb, c_tr, -tb.gauge_distance)
    f1 = eq.input_force(eps_i, eps_r, area=ib.area, young_modulus=ib.young_modulus)
    f2 = eq.transmitted_force(eps_t, area=tb.area, young_modulus=tb.young_modulus)

    start, stop = _loading_window(f2)
    w = slice(start, stop)
    balance = float(np.mean(np.abs(f1[w] - f2[w])) / np.mean(f2[w]))
    impulse = float((np.sum(f1[w]) - np.sum(f2[w])) / np.sum(f2[w]))
    t0 = float(record.time[0])
    for a in (eps_i, eps_r, eps_t, f1, f2):
        a.setflags(write=False)
    return TwoBarForces(
        time=record.time,
        eps_incident=eps_i,
        eps_reflected=eps_r,
        eps_transmitted=eps_t,
        front_force=f1,
        back_force=f2,
        input_gain=g_in,
        transmitted_gain=float(gain),
        wave_speeds=(c_in, c_tr),
        noise=gw.noise,
        arrivals=MappingProxyType({k: t0 + v * dt for k, v in gw.arrivals.items()}),
        window=(t0 + start * dt, t0 + stop * dt),
        balance_error=balance,
        impulse_error=impulse,
        dispersion=dispersion,
    )
