"""The bar legs: incident wave, transport along the bars, free far ends, gauge strains.

Each bar is a 1-D elastic waveguide: a wave keeps its shape (or disperses, with
:func:`friction_uq.dispersion.propagate`, when ``dispersive`` is set) and arrives after the exact
travel time distance / c. Strains are compression positive and refer to the wave's own direction
of travel. Time base of the simulator: t = 0 when the incident wave's foot reaches the input-bar
gauge; all series here are sampled on one uniform grid t_k = t_start + k dt.

Legs (d = gauge distance from the cell end, L = bar length):

* input bar: the striker pulse starts at the impact end at t = -(L - d) / c; it is read by the
  gauge after L - d and reaches the cell after L. The reflected wave eps_r leaves the cell, is
  read by the gauge after d, reflects inverted at the free impact end (the striker has left:
  2 L / c > 2 L_s / c_s, checked by the configuration) and returns to the gauge after 2 L - d
  and to the cell after 2 L.
* output bars: the transmitted wave eps_t is read by the gauge after d, reflects inverted at the
  free far end and returns to the gauge after 2 L - d and to the cell after 2 L.

A gauge reads the sum of the waves passing it: input gauge = incident (after L - d) + eps_r
(after d) - eps_r (after 2 L - d); output gauges = eps_t (after d) - eps_t (after 2 L - d). The
waves leaving the cell already contain its response to every returning wave.
"""

from __future__ import annotations

import numpy as np

from ..dispersion import propagate
from ..physics.bars import trapezoid_pulse
from ..record import Bar


def incident_amplitude(striker_velocity: float, *, striker: Bar, input_bar: Bar) -> float:
    """Incident strain eps_i = V_s Z_s / ((Z_s + Z_i) c_i) (compression positive).

    Reduces to eq. 14, eps_i = V_s / (2 C_i), for a striker of the bar's material and section.

    >>> from friction_uq.record import paper_apparatus
    >>> app = paper_apparatus()
    >>> round(incident_amplitude(10.0, striker=app.striker, input_bar=app.input_bar), 9)
    0.001097695
    """
    zs, zi = striker.impedance, input_bar.impedance
    return striker_velocity * zs / ((zs + zi) * input_bar.wave_speed)


def transport(signal: np.ndarray, *, dt: float, distance: float, bar: Bar, dispersive: bool) -> np.ndarray:
    """The wave as read ``distance`` (m, >= 0) further along the bar, same grid, zero before it.

    Non-dispersive: exact delay distance / c by linear interpolation between samples (no
    ringing). Dispersive: first-mode Pochhammer-Chree phase velocity (and the first mode's
    validity cut-off) of :func:`friction_uq.dispersion.propagate`.
    """
    if dispersive:
        return propagate(signal, sample_interval=dt, distance=distance, c0=bar.wave_speed,
                         diameter=bar.outer_diameter, nu=bar.poisson_ratio,
                         inner_diameter=bar.inner_diameter, dispersive=True)
    shift = distance / bar.wave_speed / dt  # samples
    k = np.arange(signal.size, dtype=np.float64) - shift
    return np.interp(k, np.arange(signal.size, dtype=np.float64), signal, left=0.0)


def incident_waves(*, amplitude: float, pulse_duration: float, rise_time: float, input_bar: Bar,
                   t_start: float, dt: float, n: int, dispersive: bool) -> tuple[np.ndarray, np.ndarray]:
    """Incident wave (at the cell end, at the gauge) on the grid t_k = t_start + k dt, k < n.

    The pulse is generated at the impact end (foot at t = -(L - d) / c) on a grid that starts
    before the impact and transported to the gauge (L - d) and to the cell (L).
    """
    length, d = input_bar.length, input_bar.gauge_distance
    t_impact = -(length - d) / input_bar.wave_speed
    lead = int(np.ceil((t_start - t_impact) / dt)) + 8  # the source grid starts 8 samples before impact
    tau = (t_start - t_impact) + (np.arange(n + lead) - lead) * dt  # time since impact
    source = trapezoid_pulse(tau, rise_time=rise_time, end=pulse_duration + rise_time, amplitude=amplitude)
    at_cell = transport(source, dt=dt, distance=length, bar=input_bar, dispersive=dispersive)[lead:]
    at_gauge = transport(source, dt=dt, distance=length - d, bar=input_bar, dispersive=dispersive)[lead:]
    return at_cell, at_gauge


def returning_wave(outgoing: np.ndarray, *, dt: float, bar: Bar, dispersive: bool) -> np.ndarray:
    """Wave arriving back at the cell end after a free far-end reflection: -eps_out after 2 L."""
    return -transport(outgoing, dt=dt, distance=2.0 * bar.length, bar=bar, dispersive=dispersive)


def gauge_strain_input(incident_at_gauge: np.ndarray, reflected: np.ndarray, *, dt: float, bar: Bar,
                       dispersive: bool) -> np.ndarray:
    """Input-bar gauge: incident + reflected after d - reflected after 2 L - d (free impact end)."""
    d = bar.gauge_distance
    return (incident_at_gauge
            + transport(reflected, dt=dt, distance=d, bar=bar, dispersive=dispersive)
            - transport(reflected, dt=dt, distance=2.0 * bar.length - d, bar=bar, dispersive=dispersive))


def gauge_strain_output(transmitted: np.ndarray, *, dt: float, bar: Bar, dispersive: bool) -> np.ndarray:
    """Output-bar gauge: transmitted wave after d - its far-end reflection after 2 L - d."""
    d = bar.gauge_distance
    return (transport(transmitted, dt=dt, distance=d, bar=bar, dispersive=dispersive)
            - transport(transmitted, dt=dt, distance=2.0 * bar.length - d, bar=bar, dispersive=dispersive))
