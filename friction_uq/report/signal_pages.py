"""Report pages about the record itself: raw gauges, transported waves and forces, the window."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..forces import Forces
from ..record import Record
from ..signals import moving_average
from ..window import Window
from .style import figure

US = 1e6  # seconds -> microseconds
LABELS = {
    "input_bar": "input bar",
    "internal_output_bar": "internal output bar",
    "external_output_bar": "external output bar",
    "tube_hoop": "tube hoop gauge",
}


def page_raw(record: Record) -> Figure:
    """Page: the four gauges as recorded (converted to strain, compression positive)."""
    names = list(record.channels)
    fig, axes = figure(
        f"2. Record {record.campaign} {record.test_id}: gauges as recorded "
        f"({record.sample_rate / 1e6:g} MHz, {record.duration * US:.0f} us)",
        nrows=len(names), ncols=1, sharex=True,
    )
    t = record.time * US
    for ax, name in zip(np.atleast_1d(axes), names):
        ch = record.channels[name]
        ax.plot(t, ch.strain * US, lw=0.7, color="k")
        ax.set_ylabel("strain (ue)")
        stored = ch.units + (f", {ch.strain_per_volt:g} strain/V" if ch.strain_per_volt else "")
        sign = "compression positive" + ("; the tube swelling reads negative" if name == "tube_hoop" else "")
        ax.set_title(f"{LABELS[name]} (stored in {stored}); {sign}", loc="left", fontsize=10)
    np.atleast_1d(axes)[-1].set_xlabel("time on the record's time base (us)")
    fig.text(0.01, 0.01, f"file {record.path}  sha256 {record.sha256[:16]}...", fontsize=8)
    return fig


def page_forces(record: Record, forces: Forces, window: Window) -> Figure:
    """Page: waves transported to the cell, forces (eq. 2-4), equilibrium (eq. 5) and velocities."""
    fig, axes = figure(
        "3. Waves transported to the cell, forces and equilibrium" + (" (dispersion corrected)" if forces.dispersion else ""),
        nrows=2, ncols=2, sharex=True,
    )
    t = forces.time * US
    ax = axes[0, 0]
    ax.plot(t, forces.eps_incident * US, label="incident eps_i")
    ax.plot(t, forces.eps_reflected * US, label="reflected eps_r")
    ax.plot(t, forces.eps_internal * US, label="internal transmitted eps_it")
    ax.plot(t, forces.eps_external * US, label="external transmitted eps_et")
    ax.set_ylabel("strain at the interface (ue)")
    ax.set_title("waves at the cell", loc="left")
    ax.legend()
    ax = axes[0, 1]
    ax.plot(t, forces.F_i / 1e3, label="F_i (input, eq. 2)", color="0.5")
    ax.plot(t, forces.F_io / 1e3, label="F_io (internal, eq. 3)")
    ax.plot(t, forces.F_eo / 1e3, label="F_eo (external, eq. 4)")
    ax.plot(t, (forces.F_io + forces.F_eo) / 1e3, "--", label="F_io + F_eo", color="k", lw=0.8)
    ax.set_ylabel("force (kN)")
    ax.set_title("forces", loc="left")
    ax.legend()
    ax = axes[1, 0]
    w = max(1, int(10e-6 * record.sample_rate))
    eq = moving_average(np.nan_to_num(forces.equilibrium), w)
    ok = np.isfinite(forces.equilibrium) & (forces.F_i > 0.3 * np.nanmax(forces.F_i))
    ax.plot(t[ok], 100 * eq[ok], label="(F_i - F_io - F_eo) / F_i")
    st = moving_average(np.nan_to_num(forces.stationarity), w)
    ax.plot(t[ok], 100 * st[ok], label="(V_i - V_io) / V_i (eq. 6)")
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel("relative error (%)")
    ax.set_ylim(-30, 30)
    ax.set_xlabel("time (us)")
    ax.set_title("eq. 5 and 6 (10 us smoothing)", loc="left")
    ax.legend()
    ax = axes[1, 1]
    ax.plot(t, forces.V_i, label="V_i (input end)", color="0.5")
    ax.plot(t, forces.V_io, label="V_io (internal bar)")
    ax.plot(t, forces.V_eo, label="V_eo (external bar)")
    ax.plot(t, forces.V, label="V = V_io - V_eo (sliding, eq. 7)", color="k")
    ax.set_ylabel("velocity (m/s)")
    ax.set_xlabel("time (us)")
    ax.set_title("velocities", loc="left")
    ax.legend()
    for a in axes.flat:
        a.axvspan(window.t0 * US, window.t1 * US, color="C2", alpha=0.12)
    return fig


def page_window(record: Record, forces: Forces, window: Window) -> Figure:
    """Page: the stationary window (ratio F_eo/F_io) and the segments the noise was estimated on."""
    import matplotlib.pyplot as plt

    from .style import A4_LANDSCAPE, RC

    with plt.rc_context(RC):
        fig = plt.figure(figsize=A4_LANDSCAPE)
        gs = fig.add_gridspec(2, 4, height_ratios=[1.3, 1], hspace=0.45, wspace=0.35)
        ax = fig.add_subplot(gs[0, :])
    fig.suptitle(
        f"4. Stationary window {window.t0 * US:.1f} - {window.t1 * US:.1f} us "
        f"({'automatic' if window.automatic else 'given by hand'}) and noise segments"
    )
    t = forces.time * US
    w = max(1, int(10e-6 * record.sample_rate))
    valid = np.isfinite(forces.F_io) & (np.nan_to_num(forces.F_io) > 0.2 * np.nanmax(forces.F_io))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = moving_average(np.nan_to_num(forces.F_eo), w) / moving_average(np.nan_to_num(forces.F_io), w)
    ax.plot(t[valid], forces.ratio[valid], lw=0.4, color="0.75", label="F_eo / F_io (raw samples)")
    ax.plot(t[valid], r[valid], color="C0", label="F_eo / F_io (10 us smoothing)")
    ax.axvspan(window.t0 * US, window.t1 * US, color="C2", alpha=0.15, label="stationary window")
    seg = window.slice
    ax.axhline(np.mean(forces.F_eo[seg]) / np.mean(forces.F_io[seg]), color="C3", ls="--",
               label="ratio of the window means")
    lo, hi = np.nanpercentile(r[valid], [2, 98])
    pad = 0.5 * (hi - lo) + 0.01
    ax.set_ylim(lo - pad, hi + pad)
    ax.set_ylabel("F_eo / F_io (-)")
    ax.set_xlabel("time (us)")
    ax.legend(loc="upper right", ncols=2)
    ax.set_title("window: loaded, ratio and V_i - V_io steady within their noise over 40 us (README)", loc="left")

    for k, (name, ch) in enumerate(record.channels.items()):
        info = forces.channels.get(name)
        if info is None or k > 3:
            continue
        nz = info.noise
        with plt.rc_context(RC):
            a = fig.add_subplot(gs[1, k])
        i = np.arange(nz.start, nz.stop)
        a.plot(t[i], (ch.strain[i] - nz.offset) * US, lw=0.5, color=f"C{k}")
        a.set_title(f"{LABELS[name]}\nsd {nz.sd * US:.2f} ue, rho {nz.rho:.2f}, offset {nz.offset * US:+.1f} ue",
                    fontsize=9, loc="left")
        a.set_xlabel("time (us)")
        if k == 0:
            a.set_ylabel("pre-pulse strain - offset (ue)")
    fig.text(0.01, 0.01, "Noise is estimated before each channel's first pulse: the gauge is at rest there, "
             "the only part of a record where the true signal is known (zero).", fontsize=8)
    return fig
