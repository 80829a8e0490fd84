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
from dataclasses import dataclass

import numpy as np

from .force_noise import MeanForces, mean_forces
from .forces import Forces
from .plausible import out_of_range
from .record import Apparatus, Record

#: Largest |S - 1| of a sound record's force balance over the loading.
BALANCE_TOL = 0.05
#: Input force fraction of its peak that marks the loading.
LOADED_FRACTION = 0.5
#: A mean force below zero, a balance or a channel's factor off, is the gauges' only beyond this many noise sd.
NOISE_SIGMAS = 3.0
#: How a balance note ends when the gauges' noise could make the imbalance (the warnings tell it by this).
NOISE_CANNOT_TELL = "cannot be told from the gauges' noise"


@dataclass(frozen=True)
class GaugeFinding:
    """One finding: the channel suspected (or "" when the evidence cannot say which), the kind ("reversed",
    "swapped", "balance", "scale", "hoop", "signal"; notes: "striker" for a striker speed at odds with gauges
    that agree, "flat" for a peak on one value, "ok" for the checks passed) and a sentence with the evidence."""

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
    mf = mean_forces(forces, apparatus, m)
    for name, channel, mean, se in (("F_io", "internal_output_bar", mf.F_io, mf.sd_io),
                                    ("F_eo", "external_output_bar", mf.F_eo, mf.sd_eo)):
        if mean < -NOISE_SIGMAS * se:
            out.append(GaugeFinding(channel, "reversed", (
                f"/signals/{channel} reads tension through the loading ({name} mean {mean:.0f} N while the input "
                f"force pushes with {mf.F_i:.0f} N): the gauge looks reversed (its wiring, "
                "its bridge or the sign convention, elongation positive)")))
    if mf.F_i < 0.0:
        out.append(GaugeFinding("input_bar", "reversed", (
            "/signals/input_bar: the input force is tensile through the loading: the input bar's gauge looks "
            "reversed (the incident wave is a compression, negative strain in the record)")))
    if out:
        return out
    off = balance_departure(mf)
    s = mf.balance
    if off == "noise":  # beyond the tolerance, within what the noise makes of it: said, no gauge blamed
        return [GaugeFinding("", "balance", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5: 100 % within "
            f"{BALANCE_TOL * 100:.0f} %), but the gauges' noise alone makes that sum uncertain by "
            f"{_percent(mf.balance_log_sd)} % (1 sd, the pre-pulse noise's colour at its upper bound): a gain off by "
            f"{abs(s - 1.0) * 100:.0f} % {NOISE_CANNOT_TELL}"))]
    if off != "gauge":
        return out
    swapped = _swapped_balance(forces, apparatus, m)
    if abs(swapped - 1.0) <= BALANCE_TOL:
        return [GaugeFinding("internal_output_bar", "swapped", (
            f"the output forces sum to {s * 100:.0f} % of the input force over the loading, and to "
            f"{swapped * 100:.0f} % with /signals/internal_output_bar and /signals/external_output_bar exchanged: the two output channels "
            "look swapped"))]
    out.append(GaugeFinding("", "balance", (
        f"the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5: 100 % within "
        f"{BALANCE_TOL * 100:.0f} %; the gauges' noise, 1 sd: {_percent(mf.balance_log_sd)} %): a gauge's gain, its "
        f"strain_per_volt or a bar's modulus is off by about {abs(s - 1.0) * 100:.0f} %")))
    return out


def _percent(x: float) -> str:
    """A fraction as a percentage: whole numbers from 10 %, one decimal below."""
    return f"{x * 100:.0f}" if x >= 0.1 else f"{x * 100:.1f}"


def balance_departure(mf: MeanForces) -> str:
    """How the output forces' sum departs from the input force (eq. 5): "" within :data:`BALANCE_TOL`; "noise" beyond
    it but within :data:`NOISE_SIGMAS` times what the gauges' noise makes of the ratio; "gauge" beyond both."""
    if not (mf.F_i > 0.0 and mf.F_io + mf.F_eo > 0.0) or abs(mf.balance - 1.0) <= BALANCE_TOL:
        return ""
    return "gauge" if abs(math.log(mf.balance)) > NOISE_SIGMAS * mf.balance_log_sd else "noise"


def _swapped_balance(forces: Forces, apparatus: Apparatus, m: np.ndarray) -> float:
    """The force balance with the two output gauges' strains exchanged (each read on the other bar)."""
    io, eo = apparatus.internal_output_bar, apparatus.external_output_bar
    k_io, k_eo = io.area * io.young_modulus, eo.area * eo.young_modulus
    F_io = forces.F_eo[m] / k_eo * k_io
    F_eo = forces.F_io[m] / k_io * k_eo
    return float(np.mean(F_io + F_eo) / np.mean(forces.F_i[m]))


#: A channel scale within this factor of the others' is not named (the balance's own spread is a few %).
SCALE_FACTOR = 1.5
#: Largest |log| departure of the ends' velocity ratio (eq. 6) that a corrected scale may leave.
VELOCITY_LOG_TOL = math.log(1.25)
#: Incident plateau against the striker's speed (eq. 14) within this factor: the input gauge is sound.
STRIKER_LOG_TOL = math.log(1.15)


def incident_plateau(forces: Forces) -> float:
    """Mean incident strain (compression positive) where it exceeds half its peak; nan without one."""
    e = forces.eps_incident
    ok = np.isfinite(e)
    if not ok.any():
        return float("nan")
    peak = float(np.max(e[ok]))
    return float(np.mean(e[ok & (e >= 0.5 * peak)])) if peak > 0 else float("nan")


def _off(a: float) -> str:
    """'k times too large' or 'k times too small' for a channel that multiplied by ``a`` would agree."""
    return f"{1 / a:.3g} times too large" if a < 1 else f"{a:.3g} times too small"


def scale_findings(forces: Forces, apparatus: Apparatus, *,
                   striker_velocity: float | None = None) -> list[GaugeFinding]:
    """A channel whose scale contradicts the others' (a gauge factor, gain or strain_per_volt off), named.

    The force balance (eq. 5) says a scale is off; which channel is found from a second relation each
    candidate enters differently: the ends' velocities (eq. 6: V_io = V_i in the stationary state) take
    the input and internal output gauges but not the external one, and the incident wave's plateau
    against the striker's speed (eq. 14: eps_i = V_s / (2 c)) takes the input gauge alone. The
    channel is named when the balance is off (:func:`balance_departure`: "gauge"), it alone, rescaled, satisfies both
    relations, and its factor is beyond :data:`SCALE_FACTOR` (an error of a gauge factor or a unit, not
    the few % a gain drifts) and beyond :data:`NOISE_SIGMAS` times the factor's noise.
    """
    m = loading_mask(forces)
    if m.sum() < 8:
        return []
    mf = mean_forces(forces, apparatus, m)
    Fi, Fio, Feo = mf.F_i, mf.F_io, mf.F_eo
    Vi, Vio = float(np.mean(forces.V_i[m])), float(np.mean(forces.V_io[m]))
    if not (Fi > 0 and Fio > 0 and Feo > 0 and Vi > 0 and Vio > 0):
        return []  # signs are the reversed-gauge check's business
    s, r = (Fio + Feo) / Fi, Vio / Vi
    cands = {"input_bar": (s, r / s), "internal_output_bar": ((Fi - Feo) / Fio, r * (Fi - Feo) / Fio),
             "external_output_bar": ((Fi - Fio) / Feo, r)}
    ok = {c: a for c, (a, rr) in cands.items() if a > 0 and rr > 0 and abs(math.log(rr)) < VELOCITY_LOG_TOL}
    evidence = (f"the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5) and the "
                f"sample's ends move at {r:.2f} times each other's speed (eq. 6)")
    q = float("nan")
    if striker_velocity:
        q = incident_plateau(forces) / (striker_velocity / (2.0 * apparatus.input_bar.wave_speed))
        implied = q * striker_velocity
        if abs(math.log(q)) > math.log(SCALE_FACTOR) and abs(s - 1.0) <= BALANCE_TOL and abs(
                math.log(r)) < VELOCITY_LOG_TOL and not out_of_range("striker_velocity", implied):
            # the gauges agree with each other at a speed a gas gun fires: the speed recorded is the odd one out
            return [GaugeFinding("", "striker", (
                f"the incident wave stands for a striker at {implied:.3g} m/s (eq. 14) where the record's "
                f"striker_velocity says {striker_velocity:g} m/s; as {evidence}, the gauges agree with each other: "
                f"the speed recorded looks wrong (f does not use it), or every gauge's scale is off by {q:.3g} (the "
                "forces and pressures with it, not f's ratio)"))]
        if abs(math.log(q)) > math.log(SCALE_FACTOR):
            return [GaugeFinding("input_bar", "scale", (
                f"/signals/input_bar reads an incident wave {q:.3g} times what the striker's {striker_velocity:g} m/s "
                "gives (eq. 14): its scale (strain_per_volt, gauge factor, gain or units) looks off by that factor"))]
        if abs(math.log(q)) < STRIKER_LOG_TOL:
            ok.pop("input_bar", None)
            evidence += f", while the incident wave matches the striker's speed within {abs(q - 1) * 100:.0f} %"
    if balance_departure(mf) != "gauge":
        return []  # no imbalance beyond the tolerance and the gauges' noise: no channel's scale to find from it

    def beyond(channel: str) -> bool:  # off by more than SCALE_FACTOR and by more than the noise makes of the factor
        return abs(math.log(ok[channel])) > max(math.log(SCALE_FACTOR), NOISE_SIGMAS * mf.rescaled_log_sd(channel))

    if set(ok) == {"input_bar", "internal_output_bar"} and all(beyond(c) for c in ok):
        v_s = 2.0 * apparatus.input_bar.wave_speed * incident_plateau(forces)
        return [GaugeFinding("", "scale", (
            f"either /signals/input_bar looks {_off(ok['input_bar'])} or /signals/internal_output_bar "
            f"{_off(ok['internal_output_bar'])}: {evidence}; the input gauge's incident wave stands for a "
            f"striker at {v_s:.3g} m/s (eq. 14): if that is not the speed fired, the input gauge is the one off "
            "(record the striker's speed as striker_velocity and the check names the channel)"))]
    if len(ok) != 1:
        return []
    ((channel, a),) = ok.items()
    if not beyond(channel):
        return []
    return [GaugeFinding(channel, "scale", (
        f"/signals/{channel} looks {_off(a)}: {evidence}; multiplying that channel by {a:.3g} "
        "restores both (check its strain_per_volt, gauge factor, amplifier gain or units)"))]


def gauge_and_speed(findings: list[GaugeFinding]) -> tuple[list[GaugeFinding], list[GaugeFinding]]:
    """:func:`scale_findings` split into a gauge's faults and the note on the striker's recorded speed (kind
    "striker": no gauge is off)."""
    return [g for g in findings if g.kind != "striker"], [g for g in findings if g.kind == "striker"]


def flat_run_notes(record: Record) -> tuple[str, ...]:
    """Channels whose peak sits on one value for a run their pre-trigger noise cannot tell from a saturated digitiser
    (:mod:`friction_uq.record.saturation`; the reader refuses the runs it can tell): one sentence each."""
    from .record.saturation import flat_run

    notes = []
    for name, channel in record.channels.items():
        run = flat_run(channel.strain)
        if run is None or run.saturated:
            continue
        noise = ("is not resolved (its pre-trigger holds two values or fewer)" if math.isinf(run.needed) else
                 f"({run.noise_steps:.1f} digitiser steps) leaves runs that long on one code by chance (one "
                 f"of {run.needed:.0f} would not be)")
        notes.append(f"/signals/{name} sits on one value for {run.run} consecutive samples at its peak, and its noise "
                     f"{noise}: a plateau on one digitiser code cannot be told from a saturated digitiser there; if "
                     "the scope's range ends at that value, the channel is clipped")
    return tuple(notes)


def record_gauge_check(record: Record) -> tuple[list[GaugeFinding], list[GaugeFinding]]:
    """(faults, notes) of a record's gauges, for ``inspect`` and ``import``.

    Faults: a gauge wired the other way round, two output channels swapped, a channel's scale off
    by a factor (:func:`scale_findings`), or no incident wave to check against; notes: a force
    balance a few percent off (:func:`gauge_findings`), which the analysis reports itself.
    """
    from .errors import SignalError
    from .forces import compute_forces

    try:
        forces = compute_forces(record)
    except SignalError as exc:
        text = str(exc).removeprefix(f"{record.path}: ")
        kind = "reversed" if "looks reversed" in text else "signal"
        return [GaugeFinding("input_bar" if text.startswith("/signals/input_bar") else "", kind, text)], []
    found = gauge_findings(forces, record.apparatus)
    faults = [g for g in found if g.kind in ("reversed", "swapped")]
    if faults:
        return faults, []
    faults, speed = gauge_and_speed(scale_findings(forces, record.apparatus, striker_velocity=record.striker_velocity))
    found += speed  # the speed recorded, not a gauge: a note
    if "tube_hoop" in forces.channels:
        faults += hoop_findings(forces, record.apparatus, forces.channels["tube_hoop"].noise.sd)
    if faults:
        return faults, []
    found += [GaugeFinding("", "flat", note) for note in flat_run_notes(record)]
    if any(g.kind == "balance" for g in found):  # the balance said with its finding
        return [], found
    s = force_balance(forces)
    if not np.isfinite(s):  # no loading to weigh (a spike as the input bar's peak): nothing was checked
        return [], [GaugeFinding("", "ok", (
            "not checked: neither the gauges' signs nor the output forces against the input force (no loading "
            "above half the input force's peak for 8 samples: a spike on the input bar?)"))] + found
    noise = mean_forces(forces, record.apparatus, loading_mask(forces)).balance_log_sd
    return [], [GaugeFinding("", "ok", (
        f"signs agree and the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5; the "
        f"gauges' noise, 1 sd: {_percent(noise)} %)"))] + found


#: Largest hoop-gauge kernel factor: a uniform band as long as the sample, read at its middle (docs/physics.md
#: section 6: 0.77 of Lame for the paper's tube; 0.8 leaves room for another tube).
HOOP_KERNEL_MAX = 0.8
#: nu / (1 - nu) the hoop gauge may imply at most (nu < 0.5 gives < 1), with room for the kernel's spread.
HOOP_K_MAX = 1.5


def hoop_findings(forces: Forces, apparatus: Apparatus, hoop_noise_sd: float) -> list[GaugeFinding]:
    """The tube's hoop gauge against the forces: it must read a swelling, and no more than nu < 0.5 allows.

    Over the loading the wall pressure is nu / (1 - nu) times the axial stress (eq. 8), and the gauge
    reads at most :data:`HOOP_KERNEL_MAX` of Lame's strain for it (docs/physics.md section 6). A
    mean hoop strain of the wrong sign beyond 3 noise standard errors is a reversed gauge; one that
    implies nu / (1 - nu) above :data:`HOOP_K_MAX` with the gauge at its most sensitive is a scale off
    by a factor (a gauge too small by a factor cannot be told from a weak wall pressure, and is not
    named).
    """
    if forces.hoop is None:
        return []
    m = loading_mask(forces)
    n = int(m.sum())
    if n < 8:
        return []
    h = float(np.mean(forces.hoop[m]))  # compression positive: a swelling tube reads negative
    se = hoop_noise_sd / math.sqrt(n) * 10.0  # a generous allowance for correlated noise
    if h > 3.0 * se:
        return [GaugeFinding("tube_hoop", "reversed", (
            f"/signals/tube_hoop reads the tube contracting through the loading (mean {h * 1e6:+.1f} microstrain "
            "compression-positive while the sample is pushed): the gauge looks reversed (a swelling tube reads "
            "positive, elongation positive)"))]
    s = apparatus.sample
    sigma = float(np.mean(forces.F_io[m] + 0.5 * forces.F_eo[m])) / s.area
    lame = apparatus.tube.lame_hoop_strain_per_pressure
    if sigma <= 0:
        return []
    k = -h / (lame * HOOP_KERNEL_MAX * sigma)
    if k > HOOP_K_MAX:
        return [GaugeFinding("tube_hoop", "scale", (
            f"/signals/tube_hoop reads {-h * 1e6:.0f} microstrain of swelling where the sample's axial stress "
            f"({sigma / 1e6:.0f} MPa over the loading) gives at most "
            f"{lame * HOOP_KERNEL_MAX * sigma * 1e6:.0f} for any "
            f"nu < 0.5 (eq. 8, the tube's Lame factor): it reads at least {k:.3g} times too much; check its "
            "strain_per_volt, gauge factor, amplifier gain or units"))]
    return []
