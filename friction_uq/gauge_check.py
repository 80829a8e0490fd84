"""What ``inspect`` and ``import`` say of a record's gauges: a wiring or scale fault (refused), or notes (a balance
a few percent off, the striker's speed, a peak on one value that may be a rail), and the hoop gauge against the
forces. The checks themselves: :mod:`friction_uq.gauge_balance` (signs, swapped channels, the balance) and
:mod:`friction_uq.gauge_scale` (a channel's scale, the striker's speed)."""

from __future__ import annotations

import math

import numpy as np

from .force_noise import mean_forces
from .forces import Forces
from .gauge_balance import NOISE_SIGMAS, GaugeFinding, gauge_findings, loading_mask, percent_text
from .gauge_scale import gauge_and_speed, scale_findings
from .record import Apparatus, Record


def flat_run_findings(record: Record) -> tuple[GaugeFinding, ...]:
    """Channels whose peak sits on one value for a run their pre-trigger noise cannot tell from a saturated digitiser
    (:mod:`friction_uq.record.saturation`; the reader refuses the runs it can tell): one finding of kind "flat"
    each."""
    from .record.saturation import flat_run

    notes = []
    for name, channel in record.channels.items():
        run = flat_run(channel.strain)
        if run is None or run.saturated:
            continue
        noise = ("is not resolved (its pre-trigger holds two values or fewer)" if math.isinf(run.needed) else
                 f"({run.noise_steps:.1f} digitiser steps) leaves runs that long on one code by chance (one "
                 f"of {run.needed:.0f} would not be)")
        notes.append(GaugeFinding(name, "flat", (
            f"/signals/{name} sits on one value for {run.run} consecutive samples at its peak, and its noise {noise}: "
            "a plateau on one digitiser code cannot be told from a saturated digitiser there; if the scope's range "
            "ends at that value, the channel is clipped")))
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
    found += flat_run_findings(record)
    if any(g.kind in ("balance", "unchecked") for g in found):  # the balance said with its finding
        return [], found
    m = loading_mask(forces)
    if m.sum() < 8:  # no loading to weigh (a spike as the input bar's peak): nothing was checked
        return [], [GaugeFinding("", "ok", (
            "not checked: neither the gauges' signs nor the output forces against the input force (no loading "
            "above half the input force's peak for 8 samples: a spike on the input bar?)"))] + found
    means = mean_forces(forces, record.apparatus, m)
    s, noise = means.balance, means.balance_sd
    return [], [GaugeFinding("", "ok", (
        f"signs agree and the output forces sum to {s * 100:.0f} % of the input force over the loading (eq. 5; the "
        f"gauges' noise, 1 sd: {percent_text(noise)} %)"))] + found


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
    means = mean_forces(forces, apparatus, m)
    sigma = (means.F_io + 0.5 * means.F_eo) / s.area
    lame = apparatus.tube.lame_hoop_strain_per_pressure
    if sigma <= NOISE_SIGMAS * math.hypot(means.sd_io, 0.5 * means.sd_eo) / s.area:
        return []  # no axial stress beyond the output gauges' noise (dead output gauges): nothing to weigh it against
    k = -h / (lame * HOOP_KERNEL_MAX * sigma)
    if k > HOOP_K_MAX:
        return [GaugeFinding("tube_hoop", "scale", (
            f"/signals/tube_hoop reads {-h * 1e6:.0f} microstrain of swelling where the sample's axial stress "
            f"({sigma / 1e6:.0f} MPa over the loading) gives at most "
            f"{lame * HOOP_KERNEL_MAX * sigma * 1e6:.0f} for any "
            f"nu < 0.5 (eq. 8, the tube's Lame factor): it reads at least {k:.3g} times too much; check its "
            "strain_per_volt, gauge factor, amplifier gain or units"))]
    return []
