"""Which gauge disagrees: sign and balance of the bar forces over the loading, before any window.

A gauge wired the other way round, a gain off by some percent or two channels swapped shows in
the forces at the cell before anything else is fitted:

* swapped: the output forces balance the input force only with the two output channels exchanged;

* sign: over the loading (where the input force F_i exceeds half its peak) the transmitted forces
  F_io and F_eo push (compression, positive): a mean beyond 3 noise standard errors below zero is a
  reversed gauge (or an inverted bridge);
* balance (eq. 5): the output forces sum to the input force. Their ratio
  S = mean(F_io + F_eo) / mean(F_i) over the loading departs from 1 by a gauge's gain error; the
  plug's inertia and the waves' transit make it differ by a few percent at most on a sound record
  (:data:`BALANCE_TOL`). A departure is a gauge's only when the gauges' noise cannot make it: beyond
  :data:`NOISE_SIGMAS` of its noise standard deviation (:mod:`friction_uq.force_noise`). A short
  pre-trigger with strongly coloured noise leaves the input force's offset uncertain by tens of
  percent of F_i (a difference of two large waves); its balance then says nothing of a gain.

The findings name the gauge and the evidence; :func:`friction_uq.analysis.prepare` refuses a
reversed output gauge with them, and says them instead of "no stationary phase" when a gauge fault
is what stops the window.
"""

from __future__ import annotations

import math

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .force_noise import MeanForces, mean_forces
from .forces import Forces
from .record import Apparatus

#: Largest |S - 1| of a sound record's force balance over the loading.
BALANCE_TOL = 0.05
#: Input force fraction of its peak that marks the loading.
LOADED_FRACTION = 0.5
#: A mean force below zero, a balance or a channel's factor off, is the gauges' only beyond this many noise sd.
NOISE_SIGMAS = 3.0
#: How a balance note ends when the gauges' noise could make the imbalance (its finding's kind: "unchecked").
NOISE_CANNOT_TELL = "cannot be told from the gauges' noise"


@dataclass(frozen=True)
class GaugeFinding:
    """One finding: the channel suspected (or "" when the evidence cannot say which), the kind and a sentence with
    the evidence. Kinds that blame a gauge: "reversed", "swapped", "balance" (a gain off beyond the gauges' noise),
    "scale", "hoop", "signal". Kinds that blame none: "unchecked" (a balance off by more than its tolerance that the
    gauges' noise could make), "window" (the window found from the force ratio alone), "striker" (a striker speed
    at odds with gauges that agree), "flat" (a peak on one value), "ok" (the checks passed)."""

    channel: str
    kind: str
    sentence: str
    #: For a channel's scale (kind "scale", one channel named): the factor that multiplied into the channel restores
    #: the balance (:func:`~friction_uq.gauge_scale.scale_findings`); None otherwise.
    restoring_factor: float | None = None


def loading_mask(forces: Forces) -> np.ndarray:
    """Where every force is valid and the input force exceeds half its peak."""
    ok = np.isfinite(forces.F_i) & np.isfinite(forces.F_io) & np.isfinite(forces.F_eo)
    if not ok.any():
        return ok
    peak = float(np.max(np.abs(forces.F_i[ok])))
    return ok & (np.abs(forces.F_i) >= LOADED_FRACTION * peak)


def force_balance(forces: Forces) -> float:
    """S = mean(F_io + F_eo) / mean(F_i) over the loading (eq. 5: 1); nan without a loading."""
    m = loading_mask(forces)
    if m.sum() < 8:
        return float("nan")
    return float(np.mean(forces.F_io[m] + forces.F_eo[m]) / np.mean(forces.F_i[m]))


def gauge_findings(forces: Forces, apparatus: Apparatus) -> list[GaugeFinding]:
    """Reversed output or input gauges (a mean force beyond :data:`NOISE_SIGMAS` of its noise on the wrong side of zero),
    swapped output channels, and a force balance off by more than :data:`BALANCE_TOL`: blamed on a gauge beyond the
    gauges' noise, said as a balance the record cannot check within it (:func:`balance_departure`)."""
    m = loading_mask(forces)
    n = int(m.sum())
    if n < 8:
        return []
    out = []
    mf = mean_forces(forces, apparatus, m)
    for name, channel, mean, se in (("F_io", "internal_output_bar", mf.F_io, mf.sd_io),
                                    ("F_eo", "external_output_bar", mf.F_eo, mf.sd_eo)):
        if mean < -NOISE_SIGMAS * se:
            out.append(GaugeFinding(channel, "reversed", (
                f"/signals/{channel} reads tension through the loading ({name} mean {mean:.0f} N while the input "
                f"force pushes with {mf.F_i:.0f} N): the gauge looks reversed (its wiring, "
                "its bridge or the sign convention, elongation positive)")))
    if mf.F_i < -NOISE_SIGMAS * mf.sd_i:
        out.append(GaugeFinding("input_bar", "reversed", (
            "/signals/input_bar: the input force is tensile through the loading: the input bar's gauge looks "
            "reversed (the incident wave is a compression, negative strain in the record)")))
    if out:
        return out
    off = balance_departure(mf)
    s = mf.balance
    if off == "noise" and not mf.F_i > 0.0:
        return [GaugeFinding("", "unchecked", (
            f"the input force over the loading, {mf.F_i:.0f} N, is within its noise of zero (1 sd: {mf.sd_i:.0f} N, "
            f"the pre-pulse noise's colour at its upper bound): the output forces' sum against it (eq. 5) "
            f"{NOISE_CANNOT_TELL}"))]
    if off == "noise":  # beyond the tolerance, within what the noise makes of it: said, no gauge blamed
        return [GaugeFinding("", "unchecked", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5: 100 % within "
            f"{BALANCE_TOL * 100:.0f} %), but the gauges' noise alone makes that sum uncertain by "
            f"{percent_text(mf.balance_sd)} % (1 sd, the pre-pulse noise's colour at its upper bound): a gain off by "
            f"{abs(s - 1.0) * 100:.0f} % {NOISE_CANNOT_TELL}"))]
    if off != "gauge":
        return out
    swapped = _swapped_balance(forces, apparatus, m)
    if abs(swapped - 1.0) <= BALANCE_TOL:
        return [GaugeFinding("internal_output_bar", "swapped", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading, and to "
            f"{swapped * 100:.0f} % with /signals/internal_output_bar and /signals/external_output_bar exchanged: the "
            "two output channels look swapped"))]
    out.append(GaugeFinding("", "balance", balance_sentence(mf)))
    return out


def balance_sentence(loading: MeanForces, window: MeanForces | None = None) -> str:
    """A balance that blames a gauge: the sum over the loading (the check's), and what each gauge alone would read
    (:func:`one_gauge_alone`). Read over the stationary window where it is out of balance the same way, beyond the
    tolerance and the gauges' noise (:func:`attributed_over_window`); else over the loading, the window's sum said."""
    head = (f"the output forces sum to {loading.balance * 100:.0f} % of the input force over the loading (eq. 5: 100 % "
            f"within {BALANCE_TOL * 100:.0f} %; the gauges' noise, 1 sd: {percent_text(loading.balance_sd)} %): a "
            "gauge's gain, its strain_per_volt or a bar's modulus is off, and the balance cannot say whose")
    if window is None:
        return f"{head}; over the loading it is {one_gauge_alone(loading)}"
    if _same_fault(loading, window):
        return (f"{head}; over the stationary window, where they sum to {window.balance * 100:.0f} %, it is "
                f"{one_gauge_alone(window)}")
    return (f"{head}; over the stationary window they sum to {window.balance * 100:.0f} %, which a gain would not "
            f"leave (a gauge's timing or the window's place may), so over the loading it is {one_gauge_alone(loading)}")


def _same_fault(loading: MeanForces, window: MeanForces) -> bool:
    """The window out of balance as the loading is: beyond the tolerance and the gauges' noise, on the same side."""
    return balance_departure(window) == "gauge" and (window.balance - 1.0) * (loading.balance - 1.0) > 0.0


def attributed_over_window(findings: Sequence[GaugeFinding], forces: Forces, apparatus: Apparatus,
                           window: slice) -> tuple[GaugeFinding, ...]:
    """``findings`` with a balance finding's shares read over the stationary window, where it is out of balance the
    same way (:func:`balance_sentence`). Over the loading the sample's and the plug's inertia take 1-2 % of the input
    force on a sound record (its sum 98.4-99.9 % on the bundled 1-D records, 99.0-100.3 % on 20 clean records of
    the axisymmetric and perturbed 1-D simulations), over the window less than 1 % (99.2-100.4 %). The external
    output force is a tenth of the input force, so that percent is a tenth of its gauge's factor, and of f: eq. 17
    reads the window."""
    if not any(g.kind == "balance" for g in findings):
        return tuple(findings)
    loading = mean_forces(forces, apparatus, loading_mask(forces))
    over = mean_forces(forces, apparatus, window)
    return tuple(GaugeFinding(g.channel, g.kind, balance_sentence(loading, over)) if g.kind == "balance" else g
                 for g in findings)


def one_gauge_alone(mf: MeanForces) -> str:
    """What each gauge would read, were it alone to blame for the balance (eq. 5), and what that makes of f: the input
    gauge leaves f as it is; an output gauge moves eq. 17's ratio r = F_eo / F_io, and f with ln(1 + r) (eq. 17).
    The external output force is a tenth of the input force or less, so a balance a few per cent off is its gauge
    reading twice what it carries, or half: f by nearly that factor."""
    r = mf.F_eo / mf.F_io if mf.F_io > 0.0 else math.nan
    parts = [f"the input gauge reading {1.0 / mf.balance:.2g} times what it carries (f as it is)"]
    for name, own, other, true_ratio in (("internal", mf.F_io, mf.F_eo, lambda g: r * g),
                                         ("external", mf.F_eo, mf.F_io, lambda g: r / g)):
        if not mf.F_i > other:
            parts.append(f"not the {name} output gauge alone (the other output force reaches the input force)")
        elif not own > 0.0:
            parts.append(f"not the {name} output gauge alone (it reads no compression)")
        else:
            gain = own / (mf.F_i - other)
            moved = (f" (the true f {math.log1p(true_ratio(gain)) / math.log1p(r):.2g} times the f eq. 17 reads)"
                     if r > 0.0 else "")
            parts.append(f"the {name} output gauge {gain:.2g} times{moved}")
    return ", ".join(parts[:-1]) + " or " + parts[-1]


def percent_text(x: float) -> str:
    """A fraction as a percentage: whole numbers from 10 %, one decimal below."""
    return f"{x * 100:.0f}" if x >= 0.1 else f"{x * 100:.1f}"


def balance_departure(mf: MeanForces) -> str:
    """How the output forces' sum departs from the input force (eq. 5): "" within :data:`BALANCE_TOL`; "noise" beyond
    it but within :data:`NOISE_SIGMAS` times what the gauges' noise makes of S where eq. 5 holds
    (:attr:`~friction_uq.force_noise.MeanForces.balance_sd`), or with an input force not positive but within its noise
    of zero; "gauge" beyond both."""
    if not mf.F_i > 0.0:
        return "noise" if mf.F_i >= -NOISE_SIGMAS * mf.sd_i else ""  # below that, the input gauge is reversed
    s = mf.balance
    if abs(s - 1.0) <= BALANCE_TOL:
        return ""
    return "gauge" if abs(s - 1.0) > NOISE_SIGMAS * mf.balance_sd else "noise"


def _swapped_balance(forces: Forces, apparatus: Apparatus, m: np.ndarray) -> float:
    """The force balance with the two output gauges' strains exchanged (each read on the other bar)."""
    io, eo = apparatus.internal_output_bar, apparatus.external_output_bar
    k_io, k_eo = io.area * io.young_modulus, eo.area * eo.young_modulus
    F_io = forces.F_eo[m] / k_eo * k_io
    F_eo = forces.F_io[m] / k_io * k_eo
    return float(np.mean(F_io + F_eo) / np.mean(forces.F_i[m]))
