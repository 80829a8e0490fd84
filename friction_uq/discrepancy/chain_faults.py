"""The catalogue's faults of the measurement chain beside the gain (:mod:`.mechanisms` holds the cell's
mechanisms and the gain), registered after them by :func:`chain_faults`.

The measurement chain beside the gain (each fitted once, on every gauge it may act on at once: a
parameter per gauge, the gauges that read right keep theirs near the neutral value):

* ``zero_drift``: a rate per gauge ~ normal(0, 10 microstrain per ms): a bridge warming or an
  amplifier's zero creeping moves a few microstrain over a record of 1-2 ms; the constant part of a
  zero is the likelihood's own offset.
* ``channel_timing``: the output bars' and the hoop gauge's delays against the input bar ~ normal(0,
  2 us): a gauge 1 cm from where the header puts it on a 5000 m/s bar reads 2 us late, two digitisers
  triggered apart by a few samples as much (a delay common to every channel changes nothing).
* ``bandwidth``: an equivalent first-order time constant per output gauge ~ half-normal(1 us): a bridge
  amplifier of 100 kHz (older SHPB chains) has 1.6 us, one of 1 MHz 0.16 us. The input bar is left
  out: its reading, low-pass and all, drives the simulation, so the output gauges' time constants are
  read against the input bar's (exactly so where the cell responds linearly to the wave's shape).
* ``bar_modulus``: each output bar's modulus over its header's ~ lognormal(0, 3 %), its density kept (the
  wave speed moves by half as much): a supplier's modulus is good to 2-3 %, a wave speed timed on the
  bar to 1 %. The bar's force per microstrain and the wave's travel to its gauge both change. The input
  bar is left out: its measured wave drives the simulation, transported to the cell once.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from scipy import stats

from ..models.measurement_chain import Reading
from ..models.parameters import Parameter
from .mechanism_registry import Mechanism, lognormal

#: The gauges read against the input bar's (its reading drives the simulation), and the outputs' own
OUTPUT_GAUGES = ("internal_output_bar", "external_output_bar", "tube_hoop")
ALL_GAUGES = ("input_bar", *OUTPUT_GAUGES)


def _chain_fault(name: str, field: str, gauges: tuple[str, ...], *, unit: str, low: float, prior: Any, start: float,
                 what: str, meaning: str, signature: str, scale: float = 1.0) -> Mechanism:
    """A measurement-chain fault fitted on every gauge of ``gauges`` at once: one parameter ``<field>_<gauge>`` per
    gauge (the :class:`~friction_uq.models.measurement_chain.Reading` field it sets; ``what``: its meaning, with
    ``{gauge}`` for the gauge), the same prior and start for each."""
    def apply(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
        for gauge in gauges:  # the gauges the record has (:meth:`Mechanism.on_gauges` drops the others' parameters)
            if f"{field}_{gauge}" in v:
                setattr(g[gauge], field, float(v[f"{field}_{gauge}"]))

    return Mechanism(
        name=name, meaning=meaning, signature=signature,
        parameters=tuple(Parameter(f"{field}_{c}", unit, low, math.inf, what.format(gauge=c), scale=scale)
                         for c in gauges),
        priors={f"{field}_{c}": prior for c in gauges}, start={f"{field}_{c}": start for c in gauges},
        apply=apply, per_gauge=gauges)


OUTPUT_BARS = ("internal_output_bar", "external_output_bar")


def _bar_modulus(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
    app = s["apparatus"]
    for name in OUTPUT_BARS:  # both output bars' gauges are in every record
        k = float(v[f"modulus_factor_{name}"])
        bar = getattr(app, name)
        app = replace(app, **{name: replace(bar, young_modulus=bar.young_modulus * k,
                                            wave_speed=bar.wave_speed * math.sqrt(k))})
    s["apparatus"] = app


def chain_faults() -> tuple[Mechanism, ...]:
    """The four faults of the chain, in the catalogue's order (module docstring)."""
    return (
        _chain_fault(
            "zero_drift", "drift", ALL_GAUGES, unit="1/s", low=-math.inf, prior=stats.norm(0.0, 0.01), start=0.0,
            scale=1e-2, what="zero drift of {gauge} (strain per second)",
            meaning="a gauge's zero drifting through the record: the channel reads the strain plus rate x time",
            signature="a residual growing steadily with time on one channel, before the waves as after them"),
        _chain_fault(
            "channel_timing", "delay", OUTPUT_GAUGES, unit="s", low=-math.inf, prior=stats.norm(0.0, 2e-6),
            start=0.0, scale=1e-6, what="delay of {gauge} against the input bar",
            meaning="a channel read late or early against the input bar's: a gauge not where the header puts it, or "
                    "digitisers triggered apart",
            signature="residuals shaped like the derivative of the wave at every front of one channel, opposite in "
                      "sign at its rise and its fall"),
        _chain_fault(
            "bandwidth", "time_constant", OUTPUT_GAUGES, unit="s", low=0.0, prior=stats.halfnorm(scale=1e-6),
            start=0.1e-6, what="low-pass time constant of {gauge}",
            meaning="an amplifier too slow for the waves: a gauge's reading through a low-pass (equivalent first-order "
                    "time constant)",
            signature="fronts of one channel late and rounded, the plateau right: residuals at every front, none "
                      "between"),
        Mechanism(
            name="bar_modulus",
            meaning="an output bar's modulus (and with it its wave speed) not the header's: its force per microstrain "
                    "and the wave's travel time to its gauge both off",
            signature="one output channel scaled by a constant factor and its fronts early or late by a fraction of a "
                      "microsecond per per cent",
            parameters=tuple(Parameter(f"modulus_factor_{b}", "-", 0.0, math.inf,
                                       f"Young's modulus of the {b} over the header's") for b in OUTPUT_BARS),
            priors={f"modulus_factor_{b}": lognormal(1.0, 0.03) for b in OUTPUT_BARS},
            start={f"modulus_factor_{b}": 1.0 for b in OUTPUT_BARS},
            apply=_bar_modulus,
            per_gauge=OUTPUT_BARS,
            neutral=1.0,
        ),
    )
