"""The three waves of a two-bar record at their gauges: incident, reflected, transmitted.

Volts to strain (:meth:`BarProperties.strain`), each channel's baseline offset and AR(1) noise
from its pre-pulse segment (:func:`~friction_uq.signals.prepulse_noise`), and the separation of
the input gauge's signal into the incident and the reflected wave. This is data processing, done
once per record: the forward models of :mod:`.balance` and :mod:`.face_forces` start from its output.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ..errors import SignalError
from ..signals import NoiseEstimate, baseline_free, prepulse_noise, pulse_arrival, window_mask
from .record import BarProperties, TwoBarRecord

#: Fraction of its peak below which a wave has ended (after its peak): where its window stops.
PULSE_END_FRACTION = 0.1


@dataclass(frozen=True)
class GaugeWaves:
    """Baseline-free waves at the gauges (strain, compression positive), zero outside their spans.

    Attributes
    ----------
    incident, reflected, transmitted : numpy.ndarray
        The windowed waves, shape (n,), on the record's time base.
    input_gain, transmitted_gain : float
        Amplifier gains used to convert volts to strain (V/V).
    noise : Mapping[str, NoiseEstimate]
        Pre-pulse noise of the "input" and "transmitted" channels (strain).
    arrivals : Mapping[str, float]
        Foot of the "incident", "reflected" and "transmitted" waves (fractional sample index).
    spans : Mapping[str, tuple[float, float]]
        [start, stop) of each wave's window (fractional sample index).
    """

    incident: np.ndarray
    reflected: np.ndarray
    transmitted: np.ndarray
    input_gain: float
    transmitted_gain: float
    noise: Mapping[str, NoiseEstimate]
    arrivals: Mapping[str, float]
    spans: Mapping[str, tuple[float, float]]


def stated_gain(bar: BarProperties) -> float:
    """The bar's amplifier gain when all its gain fields agree (V/V)."""
    values = set(bar.gains.values())
    if len(values) != 1:
        raise SignalError(
            f"the {bar.name} bar's gain fields disagree ({dict(bar.gains)}): pass the gain explicitly"
        )
    return values.pop()


def pulse_end(y: np.ndarray, *, start: float) -> float:
    """First index after the peak of ``y[start:]`` where ``y`` falls below PULSE_END_FRACTION of it."""
    i0 = int(np.floor(start))
    k = i0 + int(np.argmax(y[i0:]))
    below = np.flatnonzero(y[k:] < PULSE_END_FRACTION * y[k])
    return float(k + below[0]) if below.size else float(y.size)


def gauge_waves(
    record: TwoBarRecord, *, gain: float, input_gain: float | None = None, reflection_speed: float
) -> GaugeWaves:
    """Separate and window the waves at the gauges.

    On the input gauge, the incident wave is what comes before the reflected front (2 d / c after
    the incident's foot, c = ``reflection_speed``, less a margin of 1 % of that time, at least 8
    samples); the reflected wave is what comes after, from its measured foot. Each wave (and the
    transmitted one) is kept until it has fallen below 10 % of its peak, plus the margin, and set
    to zero elsewhere (this cuts the far-end echoes, whose timing the file does not give).

    Parameters
    ----------
    record
        A record read by :func:`~friction_uq.shpb.read_lanl_raw`.
    gain, input_gain
        Amplifier gains of the transmitted and input channels (V/V); ``input_gain`` defaults to
        the file's value when all its fields for that bar agree.
    reflection_speed
        Wave speed (m/s) that places the search for the reflected front.
    """
    ib, tb = record.input_bar, record.transmitted_bar
    g_in = stated_gain(ib) if input_gain is None else float(input_gain)
    n, dt = record.n_samples, record.sample_interval

    # a pulse must end before its reflection comes back to the input gauge: search peaks within that
    span = int(2.0 * ib.gauge_distance / reflection_speed / dt)
    x_in = ib.strain(record.input_volts, gain=g_in)
    noise_in, arr_inc = prepulse_noise(x_in, polarity=+1, span=span)
    y_in = baseline_free(x_in, noise_in)
    x_tr = tb.strain(record.transmitted_volts, gain=float(gain))
    noise_tr, arr_tr = prepulse_noise(x_tr, polarity=+1, span=span)
    y_tr = baseline_free(x_tr, noise_tr)

    sep = arr_inc + 2.0 * ib.gauge_distance / reflection_speed / dt  # reflected front at the input gauge
    margin = max(8.0, 0.01 * (sep - arr_inc))
    arr_ref = pulse_arrival(
        x_in, offset=noise_in.offset, sd=noise_in.sd, start=int(sep - margin), span=span, polarity=-1
    )
    end_inc = pulse_end(np.where(window_mask(n, 0, sep - margin), y_in, 0.0), start=arr_inc)
    end_ref = pulse_end(-y_in, start=arr_ref)
    end_tra = pulse_end(y_tr, start=arr_tr)
    spans = {
        "incident": (float(noise_in.start), min(end_inc + margin, sep - margin)),  # not an unfilled pre-trigger
        "reflected": (sep - margin, end_ref + margin),
        "transmitted": (float(noise_tr.start), end_tra + margin),
    }
    waves = {k: np.where(window_mask(n, *s), y, 0.0) for (k, s), y in zip(spans.items(), (y_in, y_in, y_tr))}
    for a in waves.values():
        a.setflags(write=False)
    return GaugeWaves(
        incident=waves["incident"],
        reflected=waves["reflected"],
        transmitted=waves["transmitted"],
        input_gain=g_in,
        transmitted_gain=float(gain),
        noise=MappingProxyType({"input": noise_in, "transmitted": noise_tr}),
        arrivals=MappingProxyType({"incident": arr_inc, "reflected": arr_ref, "transmitted": arr_tr}),
        spans=MappingProxyType(spans),
    )
