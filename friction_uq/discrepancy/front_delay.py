"""What the measurement chain's delay-like faults agree on when a record does not tell them apart.

Three faults of the catalogue (:mod:`.chain_faults`) move one output gauge's fronts in time against the input bar's:

* ``channel_timing``: the channel reads ``delay`` late (a gauge not where the header puts it, digitisers triggered
  apart);
* ``bandwidth``: a first-order low-pass of time constant tau lags a front slower than tau by tau (its group delay at
  low frequency; :func:`~friction_uq.models.measurement_chain.low_passed` delays a ramp by exactly tau). A
  second-order Butterworth amplifier at f_c is a pure delay of sqrt(2) / (2 pi f_c) up to the third order in
  frequency (the second-order terms of ln H cancel; the third, sqrt(2) / (3 w_c^3) times the wave's third
  derivative, is under 2 % of a front rising over 20 us at 60 kHz, against 6 % for a first-order low-pass with
  the same lag): it delays a front more than it rounds it;
* ``bar_modulus``: a bar whose modulus is k times its header's carries the wave at sqrt(k) times the header's speed,
  so its gauge, ``gauge_distance`` from the cell, reads the fronts ``gauge_distance / c (1 / sqrt(k) - 1)`` late
  (and its force per microstrain k times the header's, which eq. 17 reads as another f).

Where a round's candidates are all of these and each puts the largest delay on the same gauge, with the same sign,
the record shows that delay, not which of them makes it: ``diagnose`` says so (:class:`SharedDelay`), beside what
would tell them apart (:data:`.separability.SEPARATE_BY`). The delays are read from each fit's posterior medians.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .chain_faults import OUTPUT_BARS, OUTPUT_GAUGES

#: The catalogue's faults that act on a gauge as a delay of its fronts.
DELAY_LIKE = frozenset({"channel_timing", "bandwidth", "bar_modulus"})


def timing_delay(values: Mapping[str, float], gauge: str) -> float:
    """A channel's timing fault: the fitted delay itself (s)."""
    return float(values.get(f"delay_{gauge}", 0.0))


def low_pass_delay(values: Mapping[str, float], gauge: str) -> float:
    """An amplifier's bandwidth: the first-order time constant, the lag of a front slower than it (s)."""
    return float(values.get(f"time_constant_{gauge}", 0.0))


def wave_speed_delay(gauge_delay: float, modulus_factor: float) -> float:
    """A bar's modulus ``modulus_factor`` times its header's: the gauge reads the fronts this much later than the
    header's travel time ``gauge_delay`` (gauge distance over the header's wave speed, s) says, the wave speed being
    sqrt(modulus_factor) times the header's (density kept): gauge_delay (1 / sqrt(k) - 1)."""
    return gauge_delay * (1.0 / math.sqrt(modulus_factor) - 1.0)


def front_delays(mechanism: str, values: Mapping[str, float], apparatus) -> dict[str, float]:
    """The delay (s, positive late) a fitted delay-like fault (``values``: its parameters) puts on each output
    gauge's fronts against the input bar's; {} for a mechanism that is not delay-like."""
    if mechanism == "channel_timing":
        return {g: timing_delay(values, g) for g in OUTPUT_GAUGES}
    if mechanism == "bandwidth":
        return {g: low_pass_delay(values, g) for g in OUTPUT_GAUGES}
    if mechanism == "bar_modulus":
        return {b: wave_speed_delay(getattr(apparatus, b).gauge_delay, float(values.get(f"modulus_factor_{b}", 1.0)))
                for b in OUTPUT_BARS}
    return {}


@dataclass(frozen=True)
class SharedDelay:
    """The delay a round's delay-like candidates agree on: the gauge, the smallest and largest of their delays (s)
    and the mechanisms, in the round's order."""

    gauge: str
    low: float
    high: float
    mechanisms: tuple[str, ...]

    def to_json(self) -> dict[str, object]:
        return {"gauge": self.gauge, "low_s": self.low, "high_s": self.high, "mechanisms": list(self.mechanisms)}


def shared_delay(fits: Sequence[tuple[str, Mapping[str, float]]], apparatus) -> SharedDelay | None:
    """What ``fits`` (mechanism, its parameters' posterior medians) agree on: every one delay-like, at least two
    mechanisms, each putting its largest delay (in size) on the same gauge, with the same sign. None otherwise."""
    names = tuple(dict.fromkeys(m for m, _ in fits))
    if len(names) < 2 or not set(names) <= DELAY_LIKE:
        return None
    worst = []
    for mechanism, values in fits:
        delays = front_delays(mechanism, values, apparatus)
        gauge = max(delays, key=lambda g: abs(delays[g]))
        worst.append((gauge, delays[gauge]))
    gauges = {g for g, _ in worst}
    signs = {math.copysign(1.0, d) for _, d in worst}
    if len(gauges) != 1 or len(signs) != 1 or any(d == 0.0 for _, d in worst):
        return None
    delays = [d for _, d in worst]
    return SharedDelay(gauges.pop(), min(delays), max(delays), names)


def round_shared_delay(verdict, ranked: Sequence, names: Sequence[str], apparatus) -> SharedDelay | None:
    """:func:`shared_delay` of a round's models that the record does not tell apart: its best candidate and those of
    its rivals whose mechanism is among ``names`` (``diagnose``'s ``not_separable``), each read at its draws'
    medians (``ranked``: the round's :class:`~.diagnosis.Ranked`)."""
    if verdict is None or verdict.named is None or not names:
        return None
    fits = {r.fit.label: r.fit for r in ranked}
    chosen = [fits[label] for label in (verdict.named, *verdict.rivals) if label in fits]
    return shared_delay([(f.variants[-1].mechanism.name, {k: float(np.median(d)) for k, d in f.fit.draws.items()})
                         for f in chosen if f.variants[-1].mechanism.name in names], apparatus)
