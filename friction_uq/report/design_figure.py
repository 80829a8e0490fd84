"""The paper's figure 4: mean wall pressure and sliding velocity against f (eq. 15-16)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np


from ..errors import SignalError
from ..physics import design
from ..record import Record
from ..signals import prepulse_noise
from .style import RC, figure, save_figure


def striker_velocity_from_incident(record: Record) -> float:
    """V_s = 2 C_i eps_i (eq. 14) from the median of the incident plateau on the input gauge."""
    x = record.strain("input_bar")
    ib = record.apparatus.input_bar
    span = int(record.apparatus.pulse_duration * record.sample_rate / 2)
    noise, arr = prepulse_noise(x, span=span, polarity=+1)
    i0 = int(arr)
    n_pulse = int(record.apparatus.pulse_duration * record.sample_rate)
    seg = x[i0 + n_pulse // 4: i0 + 3 * n_pulse // 4] - noise.offset
    if seg.size == 0:
        raise SignalError(f"{record.path}: /signals/input_bar: the incident pulse is cut by the end of the record")
    return float(2.0 * ib.wave_speed * np.median(seg))


def design_figure(record: Record, path: str | os.PathLike[str], *, nu: float = 0.4,
                  striker_velocity: float | None = None) -> Path:
    """Draw p_mean (eq. 15) and V (eq. 16) against f for the record's apparatus; write atomically."""
    import matplotlib.pyplot as plt

    a = record.apparatus
    vs = striker_velocity or record.striker_velocity or striker_velocity_from_incident(record)
    source = ("given" if striker_velocity else "measured" if record.striker_velocity else "from the incident wave")
    f = np.linspace(0.005, 0.5, 200)
    kw = dict(striker_velocity=vs, z_input=a.input_bar.impedance, z_internal=a.internal_output_bar.impedance,
              radius=a.sample.radius, length=a.sample.length)
    p = design.stationary_mean_pressure(f, nu, **kw)
    v = design.stationary_sliding_velocity(f, nu, z_external=a.external_output_bar.impedance, **kw)
    with plt.rc_context(RC):
        fig, ax = figure(f"Design relations (eq. 15-16): {record.campaign} {record.test_id}, "
                         f"V_s = {vs:.2f} m/s ({source}), nu = {nu:g}")
        ax.plot(f, p / 1e6, color="C0", label="mean wall pressure p_mean (eq. 15)")
        ax.set_xlabel("friction coefficient f (-)")
        ax.set_ylabel("p_mean (MPa)", color="C0")
        ax2 = ax.twinx()
        ax2.plot(f, v, color="C3", label="sliding velocity V (eq. 16)")
        ax2.set_ylabel("V (m/s)", color="C3")
        ax2.grid(False)
        h1, l1 = ax.get_legend_handles_labels()
        h2, l2 = ax2.get_legend_handles_labels()
        ax.legend(h1 + h2, l1 + l2, loc="center right")
        ax.set_xlim(0, 0.5)
    return save_figure(fig, path)
