"""The noise-free model of one test: striker, bars, cell and gauges, from a configuration.

Time base: t = 0 when the incident wave's foot reaches the input-bar gauge; the record starts at
t0 = -pretrigger. The cell is integrated on a grid of step dt = (1 / sample_rate) / n_sub, n_sub
the smallest integer that keeps dt below ``cfl`` times the column's CFL limit
(:func:`.cell.critical_time_step`); everything is reported on the record's grid (every n_sub-th
step). The bar legs feed the cell through waves that return after free far-end reflections, so
the cell is advanced in blocks no longer than the shortest bar round trip 2 L / c: each block's
returning waves depend only on waves that left the cell in earlier blocks, which makes the
coupling exact with or without dispersion.

Stationary window (:attr:`ModelOutput.plateau`): the last quarter of the incident plateau as it
acts on the cell, [t_c + t_r + 3 (T - t_r)/4, t_c + T], with t_c = d_i / c_i the arrival of the
incident foot at the cell, t_r the rise time and T = 2 L_s / c_s the pulse length (the plateau's
fall starts at t_c + T). The forces approach their stationary values exponentially: the soft sample
(a spring of stiffness k = M A / L, M the confined modulus) is compressed through the two bar
impedances, with time constant tau ~ 1 / (k_eff (1/Z_i + 1/(e Z_io))), e = exp(f beta), about
30 us at f = 0.01 and 90 us at f = 0.5 for the paper's set-up (docs/physics.md section 4: the paper's
stationary phase came 300-400 us after the start of loading). In the last quarter of the plateau
the forces are within 0.1 % of eq. 15-16 for f <= 0.5; the cell's fast transients (sample
transit ~7 us, tube m_t / Z_eo ~5 us) are long over and the output bars' far-end reflections
(2 L / c ~ 570 us) arrive later.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..physics.tube import bore_compliance_factor
from ..plausible import MAX_SIMULATION_STEPS
from ..record import Apparatus
from . import bars, cell
from .config import SimulationConfig
from .friction import LAWS
from .hoop import hoop_strain
from .loading import Loading


def cell_horizon(until: Mapping[str, int], *, apparatus: Apparatus, dt: float) -> int:
    """Record samples of the cell's history that gauges asked for their first ``until[gauge]`` samples read:
    a bar's gauge reads what left the cell d / c earlier (the input bar's: its reflected wave), the hoop gauge
    the cell at once; two samples more for the interpolation between samples."""
    lag = {"input_bar": apparatus.input_bar.gauge_delay, "internal_output_bar": apparatus.internal_output_bar.gauge_delay,
           "external_output_bar": apparatus.external_output_bar.gauge_delay, "tube_hoop": 0.0}
    return max((k - math.floor(lag[c] / dt) for c, k in until.items()), default=0) + 2


def _unread_to_nan(until: Mapping[str, int], strains: dict[str, np.ndarray], *, fine: list[np.ndarray],
                   recorded: tuple[np.ndarray, ...], steps: int, n_sub: int) -> None:
    """NaN where a run stopped at ``steps`` time steps was not asked to be right: each gauge's strain after its own
    ``until`` (a gauge not named: all of it), the per-step series after ``steps``, the recorded ones after
    ``steps / n_sub`` samples."""
    for c, x in strains.items():
        x[until.get(c, 0):] = np.nan
    for x in fine:
        x[steps:] = np.nan
    for x in recorded:
        x[steps // n_sub:] = np.nan


#: Most time steps of the cell per record sample (a stiffer column would need more memory than a record is worth).
MAX_SUBSTEPS = 200


@dataclass(frozen=True)
class ModelOutput:
    """Noise-free result on the record's grid (n samples). SI units, compression positive.

    Forces at the cell (N): ``force_input`` F_i (input bar on plug), ``force_internal`` F_io
    (sample on internal output bar), ``force_external`` F_eo (tube on external output bar),
    ``plug_friction`` (tube on plug, negative while the plug slides forward).
    Velocities (m/s, towards the output bars): ``velocity_plug`` (plug and input face),
    ``velocity_output_face`` (sample face on the internal bar), ``velocity_tube``,
    ``sliding_velocity`` V = velocity_output_face - velocity_tube (eq. 7).
    ``sliding_displacement`` (m): mean displacement of the sample's nodes relative to the tube.
    ``wall_pressure`` (Pa), shape (n, N): pressure on each element's wall; ``node_displacement``
    (m), shape (n, N + 1): nodes relative to the tube; ``wall_friction`` (N), shape (n, N + 1):
    friction force on each node of the sample.
    Momenta (kg m/s) of the sample, the plug and the tube, and ``impulse`` (N s), the running
    integral of F_i - F_io - F_eo (the cell's momentum balance).
    ``strains``: gauge strains, true (no gain, no noise), channel name -> array.
    """

    time: np.ndarray
    strains: dict[str, np.ndarray]
    force_input: np.ndarray
    force_internal: np.ndarray
    force_external: np.ndarray
    plug_friction: np.ndarray
    velocity_plug: np.ndarray
    velocity_output_face: np.ndarray
    velocity_tube: np.ndarray
    sliding_velocity: np.ndarray
    sliding_displacement: np.ndarray
    wall_pressure: np.ndarray
    node_displacement: np.ndarray
    wall_friction: np.ndarray
    momentum_sample: np.ndarray
    momentum_plug: np.ndarray
    momentum_tube: np.ndarray
    impulse: np.ndarray
    plateau: tuple[float, float]
    incident_strain: float
    time_step: float
    substeps: int


def run_model(config: SimulationConfig, *, loading: Loading | None = None,
              until: Mapping[str, int] | None = None) -> ModelOutput:
    """Integrate the test described by ``config`` (deterministic, no noise).

    With ``loading`` (a measured incident wave, :mod:`.loading`), the cell is driven by that wave
    on the loading's time grid instead of the configuration's trapezoid (striker velocity and rise
    time are then unused; sample rate, duration and pre-trigger come from the loading's grid).

    ``until`` (gauge -> samples): only each named gauge's first samples are asked for (a likelihood's
    spans). The cell is then integrated only as long as they need (:func:`cell_horizon`), and everything
    after is NaN: each gauge's strain after its own count (a gauge not named: all of it), the cell's series
    after the horizon. The samples asked for are those of the whole run, to the bit (the model is causal).
    Not with dispersive bars, whose Fourier transfer reads the whole series.
    """
    if until is not None and config.dispersion:
        raise ValueError("a dispersive simulation runs over the whole record (until must be None)")
    app = config.apparatus
    ib, iob, eob, tube, sample = app.input_bar, app.internal_output_bar, app.external_output_bar, app.tube, app.sample
    plug = app.plug
    assert plug is not None  # the configuration always sets one
    nu, n_el = config.poisson_ratio, config.elements
    if loading is None:
        dt_out = 1.0 / config.sample_rate
        n_out = int(round(config.duration * config.sample_rate))
        t_start = -config.pretrigger
    else:
        dt_out = loading.sample_interval
        n_out = len(loading.time)
        t_start = float(loading.time[0])

    # sample column, tube, plug
    h = sample.length / n_el
    radius, area = sample.radius, sample.area
    a, b = tube.inner_diameter / 2, tube.outer_diameter / 2
    c_t = bore_compliance_factor(inner_radius=a, outer_radius=b, poisson_ratio=tube.poisson_ratio)
    den = (1.0 - nu) + (sample.young_modulus * c_t / tube.young_modulus if config.tube_compliance else 0.0)
    egr = sample.young_modulus * config.gap / radius
    c_max = cell.max_wave_speed(young_modulus=sample.young_modulus, density=sample.density, nu=nu, den=den)
    dt_crit = cell.critical_time_step(element_length=h, wave_speed=c_max, damping=config.damping)
    n_sub = max(1, math.ceil(dt_out / (config.cfl * dt_crit)), config.min_substeps)
    if n_sub > MAX_SUBSTEPS:
        raise ConfigError(f"{config.source}: the sample's wave speed {c_max:.0f} m/s with numerics.cfl = {config.cfl:g} "
                          f"needs {n_sub} time steps per sample (at most {MAX_SUBSTEPS}): check cfl, and the sample's "
                          "modulus, density and Poisson ratio")
    dt = dt_out / n_sub
    n = n_out * n_sub
    if n > MAX_SIMULATION_STEPS:  # checked before any array is made (docs/limits.md)
        raise ConfigError(f"{config.source}: {n_out} samples x {n_sub} time steps per sample = {n} time steps, more "
                          f"than the {MAX_SIMULATION_STEPS} a simulation may take: lower measurement.sample_rate or "
                          "measurement.duration, or raise numerics.cfl")
    m_plug = plug.density * math.pi * a * a * plug.length
    mass = np.full(n_el + 1, sample.density * area * h)
    mass[0] = 0.5 * mass[0] + m_plug
    mass[-1] *= 0.5
    par = np.zeros(cell.N_PAR)
    par[[cell.DT, cell.H, cell.AREA, cell.WALL]] = dt, h, area, math.pi * radius * h
    par[[cell.E, cell.NU, cell.DEN, cell.EGR, cell.SIGSTAR]] = (
        sample.young_modulus, nu, den, egr, egr / nu)
    par[[cell.ZI, cell.CI, cell.ZIO, cell.CIO, cell.ZEO, cell.CEO]] = (
        ib.impedance, ib.wave_speed, iob.impedance, iob.wave_speed, eob.impedance, eob.wave_speed)
    par[cell.MT] = config.tube_density * tube.area * tube.length
    par[[cell.PF_FORCE, cell.PF_COEF, cell.MPLUG]] = (
        config.plug_friction_force, config.plug_friction_coefficient, m_plug)
    par[cell.ETA] = config.damping * sample.density * c_max * h
    par[cell.END_F] = config.end_friction
    law = LAWS[config.friction_law]
    fpar = law.pack(config.friction_params)

    # incident wave
    pulse = app.pulse_duration
    disp = config.dispersion
    if loading is None:
        eps_i = bars.incident_amplitude(config.striker_velocity, striker=app.striker, input_bar=ib)
        inc_cell, inc_gauge = bars.incident_waves(amplitude=eps_i, pulse_duration=pulse, rise_time=config.rise_time,
                                                  input_bar=ib, t_start=t_start, dt=dt, n=n, dispersive=disp)
    else:
        inc_cell, inc_gauge = loading.on_grid(t_start + np.arange(n) * dt)
        eps_i = float(np.max(loading.at_cell))

    # state and outputs
    u, v, slip, st = np.zeros(n_el + 1), np.zeros(n_el + 1), np.zeros(n_el + 1), np.zeros(cell.N_STATE)
    eps_in = [inc_cell.copy(), np.zeros(n), np.zeros(n)]
    eps_out = [np.zeros(n), np.zeros(n), np.zeros(n)]
    forces = [np.zeros(n), np.zeros(n), np.zeros(n)]
    rec_p = np.zeros((n_out, n_el))
    rec_u = np.zeros((n_out, n_el + 1))
    rec_ff = np.zeros((n_out, n_el + 1))
    rec_s = np.zeros((n_out, cell.N_REC))
    legs = (ib, iob, eob)
    block = min(int(2.0 * bar.length / bar.wave_speed / dt) for bar in legs)
    n_cell = n if until is None else min(n, n_sub * cell_horizon(until, apparatus=app, dt=dt_out))
    k0 = 0
    while k0 < n_cell:
        k1 = min(n_cell, k0 + block)
        if k0 > 0:  # waves back from the free far ends, from what left the cell before k0
            for j, bar in enumerate(legs):
                back = bars.returning_wave(eps_out[j], dt=dt, bar=bar, dispersive=disp)
                eps_in[j][k0:k1] = back[k0:k1] + (inc_cell[k0:k1] if j == 0 else 0.0)
        cell.run_block(k0, k1, n_sub, par, law.code, fpar, mass, u, v, slip, st, *eps_in, *eps_out, *forces,
                       rec_p, rec_u, rec_ff, rec_s)
        k0 = k1

    # gauges
    strains = {
        "input_bar": bars.gauge_strain_input(inc_gauge, eps_out[0], dt=dt, bar=ib, dispersive=disp)[::n_sub],
        "internal_output_bar": bars.gauge_strain_output(eps_out[1], dt=dt, bar=iob, dispersive=disp)[::n_sub],
        "external_output_bar": bars.gauge_strain_output(eps_out[2], dt=dt, bar=eob, dispersive=disp)[::n_sub],
    }
    if config.channels["tube_hoop"].enabled:
        tube_force = -rec_ff.copy()
        tube_force[:, 0] -= rec_s[:, cell.R_PLUG_FRICTION]
        hoop = hoop_strain(rec_p, rec_u, tube=tube, sample_length=sample.length, beta=config.hoop_beta,
                           tube_force=tube_force if config.hoop_axial_term else None)
        strains["tube_hoop"] = -hoop  # compression positive inside the package
    if until is not None:
        _unread_to_nan(until, strains, fine=forces, recorded=(rec_p, rec_u, rec_ff, rec_s), steps=n_cell, n_sub=n_sub)
    t_c = ib.gauge_distance / ib.wave_speed
    tr = config.rise_time
    plateau = (t_c + tr + 0.75 * (pulse - tr), t_c + pulse)
    s = rec_s
    return ModelOutput(
        time=t_start + np.arange(n_out) * dt_out,
        strains=strains,
        force_input=forces[0][::n_sub].copy(),
        force_internal=forces[1][::n_sub].copy(),
        force_external=forces[2][::n_sub].copy(),
        plug_friction=s[:, cell.R_PLUG_FRICTION].copy(),
        velocity_plug=s[:, cell.R_V0].copy(),
        velocity_output_face=s[:, cell.R_VN].copy(),
        velocity_tube=s[:, cell.R_VT].copy(),
        sliding_velocity=s[:, cell.R_VN] - s[:, cell.R_VT],
        sliding_displacement=s[:, cell.R_SLIP].copy(),
        wall_pressure=rec_p,
        node_displacement=rec_u,
        wall_friction=rec_ff,
        momentum_sample=s[:, cell.R_P_SAMPLE].copy(),
        momentum_plug=s[:, cell.R_P_PLUG].copy(),
        momentum_tube=s[:, cell.R_P_TUBE].copy(),
        impulse=s[:, cell.R_IMPULSE].copy(),
        plateau=plateau,
        incident_strain=eps_i,
        time_step=dt,
        substeps=n_sub,
    )
