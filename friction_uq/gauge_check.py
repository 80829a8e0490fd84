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
  (:data:`BALANCE_TOL`).

The findings name the gauge and the evidence; :func:`friction_uq.analysis.prepare` refuses a
reversed output gauge with them, and says them instead of "no stationary phase" when a gauge fault
is what stops the window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .forces import Forces
from .record import Apparatus
from .signals import ar1_mean_sd

#: Largest |S - 1| of a sound record's force balance over the loading.
BALANCE_TOL = 0.05
#: Input force fraction of its peak that marks the loading.
LOADED_FRACTION = 0.5


@dataclass(frozen=True)
class GaugeFinding:
    """One disagreement: the channel suspected (or "" when the balance cannot say which), the kind
    ("reversed", "swapped" or "balance") and a sentence with the evidence."""

    channel: str
    kind: str
    sentence: str


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
    """Reversed output or input gauges and a force balance off by more than :data:`BALANCE_TOL`."""
    m = loading_mask(forces)
    n = int(m.sum())
    if n < 8:
        return []
    out = []
    ch = forces.channels
    for name, channel, F, bar in (("F_io", "internal_output_bar", forces.F_io, apparatus.internal_output_bar),
                                  ("F_eo", "external_output_bar", forces.F_eo, apparatus.external_output_bar)):
        noise = ch[channel].noise
        se = bar.area * bar.young_modulus * math.hypot(ar1_mean_sd(noise.sd, noise.rho_eff, n), noise.offset_sd)
        mean = float(np.mean(F[m]))
        if mean < -3.0 * se:
            out.append(GaugeFinding(channel, "reversed", (
                f"/signals/{channel} reads tension through the loading ({name} mean {mean:.0f} N while the input "
                f"force pushes with {float(np.mean(forces.F_i[m])):.0f} N): the gauge looks reversed (its wiring, "
                "its bridge or the sign convention, elongation positive)")))
    if float(np.mean(forces.F_i[m])) < 0.0:
        out.append(GaugeFinding("input_bar", "reversed", (
            "/signals/input_bar: the input force is tensile through the loading: the input bar's gauge looks "
            "reversed (the incident wave is a compression, negative strain in the record)")))
    if out:
        return out
    s = force_balance(forces)
    swapped = _swapped_balance(forces, apparatus, m)
    if math.isfinite(s) and abs(s - 1.0) > BALANCE_TOL and abs(swapped - 1.0) <= BALANCE_TOL:
        return [GaugeFinding("internal_output_bar", "swapped", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading, and to "
            f"{swapped * 100:.0f} % with /signals/internal_output_bar and /signals/external_output_bar exchanged: the two output channels "
            "look swapped"))]
    if math.isfinite(s) and abs(s - 1.0) > BALANCE_TOL:
        out.append(GaugeFinding("", "balance", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5: 100 % within "
            f"{BALANCE_TOL * 100:.0f} %): a gauge's gain, its strain_per_volt or a bar's modulus is off by about "
            f"{abs(s - 1.0) * 100:.0f} %")))
    return out


def _swapped_balance(forces: Forces, apparatus: Apparatus, m: np.ndarray) -> float:
    """The force balance with the two output gauges' strains exchanged (each read on the other bar)."""
    io, eo = apparatus.internal_output_bar, apparatus.external_output_bar
    k_io, k_eo = io.area * io.young_modulus, eo.area * eo.young_modulus
    F_io = forces.F_eo[m] / k_eo * k_io
    F_eo = forces.F_io[m] / k_io * k_eo
    return float(np.mean(F_io + F_eo) / np.mean(forces.F_i[m]))
