"""Which channel's scale is off by a factor (a gauge factor, a gain or strain_per_volt mistyped, a unit), or the
striker's recorded speed: the balance (eq. 5, :mod:`friction_uq.gauge_balance`), the ends' velocities (eq. 6) and the
incident wave against the striker's speed (eq. 14), each of which the candidate channels enter differently."""

from __future__ import annotations

import math

import numpy as np

from .force_noise import mean_forces
from .forces import Forces
from .gauge_balance import NOISE_SIGMAS, GaugeFinding, balance_departure, loading_mask
from .plausible import out_of_range
from .record import Apparatus

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
        departure = balance_departure(mf)
        if abs(math.log(q)) > math.log(SCALE_FACTOR) and departure == "noise":
            # the balance cannot say whether the input gauge disagrees with the others: neither is blamed
            return [GaugeFinding("", "striker", (
                f"the incident wave stands for a striker at {implied:.3g} m/s (eq. 14) where the record's "
                f"striker_velocity says {striker_velocity:g} m/s; {evidence}, a sum the gauges' noise could make: "
                "whether the speed recorded or the input gauge's scale is off cannot be told from this record "
                "(f, from the output gauges' ratio, uses neither)"))]
        if abs(math.log(q)) > math.log(SCALE_FACTOR) and departure == "" and abs(
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
        own, own_sd = {"input_bar": (Fi, mf.sd_i), "internal_output_bar": (Fio, mf.sd_io),
                       "external_output_bar": (Feo, mf.sd_eo)}[channel]
        if own <= NOISE_SIGMAS * own_sd:
            return False  # a channel reading nothing beyond its noise is dead, not off by a factor: the balance says so
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
        "restores both (check its strain_per_volt, gauge factor, amplifier gain or units)"), restoring_factor=a)]


def gauge_and_speed(findings: list[GaugeFinding]) -> tuple[list[GaugeFinding], list[GaugeFinding]]:
    """:func:`scale_findings` split into a gauge's faults and the note on the striker's recorded speed (kind
    "striker": no gauge is off)."""
    return [g for g in findings if g.kind != "striker"], [g for g in findings if g.kind == "striker"]
