"""Each cause in an experimentalist's words (a measurement-chain fault with its gauge and how much) and the steps
of f as the causes went into the model: what the sentence (:mod:`.diagnosis_words`) and its clauses
(:mod:`.round_clauses`) say of a cause."""

from __future__ import annotations

import numpy as np

from ..models.parameters import Parameter
from .diagnosis import Diagnosis
from .extended import Variant
from .whole_record import CHANNEL_LABELS


#: Each mechanism in an experimentalist's words (docs/glossary.md has the longer entries).
PLAIN_NAMES = {
    "velocity_friction": "wall friction that changes with the sliding speed",
    "pressure_friction": "wall friction that changes with the wall pressure",
    "slip_friction": "wall friction that changes with the distance slid",
    "clearance": "a radial gap between sample and tube",
    "plug_friction": "the plug rubbing on the tube",
    "gauge_gain": "a bar gauge's calibration",
    "dispersion": "wave dispersion in the bars",
    "end_friction": "friction on the sample's end faces",
    "zero_drift": "a gauge's zero drifting through the record",
    "channel_timing": "a channel read late or early (a gauge's position, a trigger's skew)",
    "bandwidth": "an amplifier too slow for the waves",
    "bar_modulus": "an output bar's modulus off its header",
}


#: How a measurement-chain parameter is said: unit -> (factor, unit in words)
CHAIN_UNITS = {"s": (1e6, "us"), "1/s": (1e3, "microstrain per ms"), "-": (1.0, "times the header's")}


def chain_gauge(v: Variant, dg: Diagnosis | None) -> tuple[str, Parameter, float] | None:
    """For a measurement-chain fault fitted on every gauge (``per_gauge``): the gauge it names, the parameter and
    its posterior median, from the final model's draws when it holds the fault (else the round's fit)."""
    if dg is None or not v.mechanism.per_gauge:
        return None
    fit = dg.final if v in dg.final.variants else next(
        (r.fit for rk in dg.rounds for r in rk if r.fit.variants[-1] == v), None)
    if fit is None:
        return None
    medians = {k: float(np.median(d)) for k, d in fit.fit.draws.items()}
    gauge, p = v.mechanism.departing_gauge(medians)
    return gauge, p, medians[p.name]


def cause_words(v: Variant, dg: Diagnosis | None = None) -> str:
    where = f" on the {CHANNEL_LABELS.get(v.channel, v.channel)} gauge" if v.channel else ""
    chain = chain_gauge(v, dg)
    if chain is not None:  # say which gauge, and how much
        gauge, p, value = chain
        factor, unit = CHAIN_UNITS.get(p.unit, (1.0, p.unit))
        x = f"{value * factor:.3g}" if p.unit == "-" else f"{value * factor:+.2g}"
        where = f", mostly the {CHANNEL_LABELS.get(gauge, gauge)} gauge ({x} {unit})"
    return f"{PLAIN_NAMES.get(v.mechanism.name, v.mechanism.name)}{where} ({v.mechanism.name})"


def f_steps(dg: Diagnosis) -> list[tuple[Variant, float, float]]:
    """Each named cause with the median f before and after it was added, in the order named: round k's
    reference model is the one with the first k causes (diagnose.diagnose)."""
    out, before = [], float(np.median(dg.baseline.f_effective))
    for k, v in enumerate(dg.causes):
        chosen = next((r.fit for r in dg.rounds[k] if r.fit.variants[-1] == v), None) if k < len(dg.rounds) else None
        after = before if chosen is None else float(np.median(chosen.f_effective))
        out.append((v, before, after))
        before = after
    return out
