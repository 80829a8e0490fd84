"""The noise-free axisymmetric model of one test: bars (1-D), plug, sample and tube (2-D), gauges.

Same time base, loading, bar legs and gauges as the 1-D simulator (:mod:`friction_uq.simulate.model_1d`):
the cell is advanced in blocks no longer than the shortest bar round trip, each block's returning
waves computed from the waves that left the cell before it (exact with or without dispersion). The
hoop gauge reads the tube's outer-face hoop strain u_r / b averaged over the gauge's width, on the
tube's own material points (the gauge is glued to the tube), whatever the sample does under it:
the tube's axial compression by the friction is in it by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import bars
from ..config import SimulationConfig
from ..friction import LAWS
from ..loading import Loading
from ..model_1d import ModelOutput
from . import solver as S
from .assembly import Cell, build_cell
from .coupling import N_FACE_STATE
from .mesh import SAMPLE

#: Most time steps of the cell per record sample.
MAX_SUBSTEPS = 400


@dataclass(frozen=True)
class AxisymmetricOutput(ModelOutput):
    """:class:`~friction_uq.simulate.model_1d.ModelOutput` plus the 2-D model's own fields.

    ``axial_stress`` (Pa, compression positive), shape (n, rows): the sample's axial stress averaged
    over each row of elements (row centres at ``row_z``, m from the input face). ``energy``: name ->
    series (J) of the balance (bars' work, kinetic, stress work, hourglass, viscous, contact).
    ``wall_pressure_nodes`` (Pa), shape (n, N + 1): pressure at the sample's outer nodes.
    """

    axial_stress: np.ndarray
    row_z: np.ndarray
    wall_pressure_nodes: np.ndarray
    energy: dict[str, np.ndarray]
    element_size: float
    elements: int
    critical_time_step: float


def time_grid(config: SimulationConfig, loading: Loading | None) -> tuple[float, int, float]:
    """(record sample interval, number of samples, start time) of the configuration or the loading."""
    if loading is None:
        return 1.0 / config.sample_rate, int(round(config.duration * config.sample_rate)), -config.pretrigger
    return loading.sample_interval, len(loading.time), float(loading.time[0])


def choose_step(cell: Cell, config: SimulationConfig, dt_out: float) -> int:
    """Substeps per record sample: the asked ``model.time_step``, else cfl x the stability limit."""
    ms = config.model
    target = ms.time_step if ms.time_step > 0.0 else ms.cfl * cell.critical_step
    if ms.time_step > cell.critical_step:
        from ...errors import ConfigError

        raise ConfigError(f"{config.source}: key 'model.time_step' is {ms.time_step:.3g} s, above the mesh's "
                          f"stability limit {cell.critical_step:.3g} s (element size "
                          f"{ms.element_size * 1e3:g} mm): leave it out or ask for less")
    n_sub = max(1, math.ceil(dt_out / target - 1e-9))
    if n_sub > MAX_SUBSTEPS:
        from ...errors import ConfigError

        raise ConfigError(f"{config.source}: key 'model.element_size' is {ms.element_size * 1e3:g} mm, which needs "
                          f"{n_sub} time steps per record sample (at most {MAX_SUBSTEPS}); use larger elements")
    return n_sub


def run_axisymmetric(config: SimulationConfig, *, loading: Loading | None = None,
                     cell: Cell | None = None) -> AxisymmetricOutput:
    """Integrate the test of ``config`` with the axisymmetric cell (deterministic, no noise)."""
    app = config.apparatus
    ib, iob, eob = app.input_bar, app.internal_output_bar, app.external_output_bar
    cell = build_cell(config) if cell is None else cell
    mesh = cell.mesh
    dt_out, n_out, t_start = time_grid(config, loading)
    n_sub = choose_step(cell, config, dt_out)
    dt = dt_out / n_sub
    n = n_out * n_sub
    disp = config.dispersion
    if loading is None:
        eps_i = bars.incident_amplitude(config.striker_velocity, striker=app.striker, input_bar=ib)
        inc_cell, inc_gauge = bars.incident_waves(amplitude=eps_i, pulse_duration=app.pulse_duration,
                                                  rise_time=config.rise_time, input_bar=ib, t_start=t_start, dt=dt,
                                                  n=n, dispersive=disp)
    else:
        inc_cell, inc_gauge = loading.on_grid(t_start + np.arange(n) * dt)
        eps_i = float(np.max(loading.at_cell))
    ms = config.model
    par = np.zeros(S.N_PAR)
    par[[S.DT, S.C_HG, S.DAMPING, S.END_F, S.OFF_SAMPLE, S.OFF_PLUG]] = (
        dt, ms.hourglass, ms.damping, config.end_friction, cell.offset_sample, cell.offset_plug)
    par[[S.Z_I, S.C_I, S.Z_IO, S.C_IO, S.Z_EO, S.C_EO, S.HOOP_R]] = (
        ib.impedance, ib.wave_speed, iob.impedance, iob.wave_speed, eob.impedance, eob.wave_speed, cell.hoop_radius)
    law = LAWS[config.friction_law]
    flag = np.array([cell.plug_front.size > 0, ms.tube, law.code], dtype=np.int64)
    n_nodes, n_el = mesh.n_nodes, mesh.n_elements
    ns, npl = cell.sample_outer.size, cell.plug_outer.size
    state = dict(u=np.zeros((n_nodes, 2)), v=np.zeros((n_nodes, 2)), sig=np.zeros((n_el, 4)), visc=np.zeros((n_el, 4)),
                 slip_s=np.zeros(ns), speed_s=np.zeros(ns), slip_p=np.zeros(npl), speed_p=np.zeros(npl),
                 faces=np.zeros((3, N_FACE_STATE)), acc=np.zeros(S.N_ACC))
    eps_in = [inc_cell.copy(), np.zeros(n), np.zeros(n)]
    eps_out = [np.zeros(n), np.zeros(n), np.zeros(n)]
    forces = [np.zeros(n), np.zeros(n), np.zeros(n)]
    rows = cell.sample_rows.shape[0]
    rec = dict(p=np.zeros((n_out, ns)), u=np.zeros((n_out, ns)), ff=np.zeros((n_out, ns)),
               sz=np.zeros((n_out, rows)), s=np.zeros((n_out, S.N_REC)))
    legs = (ib, iob, eob)
    block = min(int(2.0 * bar.length / bar.wave_speed / dt) for bar in legs)
    fprev = np.zeros(1)
    fpar_p = np.array([ms.plug_friction])
    k0 = 0
    while k0 < n:
        k1 = min(n, k0 + block)
        if k0 > 0:
            for j, bar in enumerate(legs):
                back = bars.returning_wave(eps_out[j], dt=dt, bar=bar, dispersive=disp)
                eps_in[j][k0:k1] = back[k0:k1] + (inc_cell[k0:k1] if j == 0 else 0.0)
        S.run_block(k0, k1, n_sub, par, flag, law.pack(config.friction_params), fpar_p, mesh.X, mesh.mass,
                    mesh.conn, mesh.geo, mesh.mat, mesh.axis, cell.body_nodes, cell.plug_front, cell.sample_in,
                    cell.sample_out, cell.sample_outer, cell.sample_area, cell.plug_outer, cell.plug_area,
                    cell.plug_extra, cell.tube_inner, cell.tube_end, cell.in_face, cell.share_in, cell.share_out,
                    cell.share_tube, cell.hoop_nodes, cell.hoop_w, cell.sample_rows,
                    state["u"], state["v"], state["sig"], state["visc"], state["slip_s"], state["speed_s"],
                    state["slip_p"], state["speed_p"], state["faces"], state["acc"],
                    config.plug_friction_coefficient, config.plug_friction_force, fprev,
                    *eps_in, *eps_out, *forces, rec["p"], rec["u"], rec["ff"], rec["sz"], rec["s"])
        k0 = k1
    return _output(config, cell, rec, eps_out, forces, inc_gauge, dt=dt, dt_out=dt_out, n_sub=n_sub,
                   n_out=n_out, t_start=t_start, eps_i=eps_i)


def _output(config: SimulationConfig, cell: Cell, rec: dict, eps_out: list, forces: list, inc_gauge: np.ndarray, *,
            dt: float, dt_out: float, n_sub: int, n_out: int, t_start: float, eps_i: float) -> AxisymmetricOutput:
    app = config.apparatus
    ib, iob, eob = app.input_bar, app.internal_output_bar, app.external_output_bar
    disp = config.dispersion
    strains = {
        "input_bar": bars.gauge_strain_input(inc_gauge, eps_out[0], dt=dt, bar=ib, dispersive=disp)[::n_sub],
        "internal_output_bar": bars.gauge_strain_output(eps_out[1], dt=dt, bar=iob, dispersive=disp)[::n_sub],
        "external_output_bar": bars.gauge_strain_output(eps_out[2], dt=dt, bar=eob, dispersive=disp)[::n_sub],
    }
    s = rec["s"]
    if config.channels["tube_hoop"].enabled and config.model.tube:  # no tube, no hoop gauge (optional channel)
        strains["tube_hoop"] = -s[:, S.R_HOOP].copy()  # compression positive inside the package
    t_c = ib.gauge_distance / ib.wave_speed
    tr, pulse = config.rise_time, app.pulse_duration
    p_nodes = rec["p"]
    mesh = cell.mesh
    blk = mesh.blocks[SAMPLE]
    dz = (blk.z1 - blk.z0) / blk.nz
    energy = {name: s[:, col].copy() for name, col in (
        ("bars", S.R_W_BARS), ("kinetic", S.R_KE), ("stress", S.R_W_STRESS), ("hourglass", S.R_E_HG),
        ("viscous", S.R_D_VISC), ("contact", S.R_D_CONTACT))}
    return AxisymmetricOutput(
        time=t_start + np.arange(n_out) * dt_out,
        strains=strains,
        force_input=forces[0][::n_sub].copy(),
        force_internal=forces[1][::n_sub].copy(),
        force_external=forces[2][::n_sub].copy(),
        plug_friction=s[:, S.R_PLUG_FRICTION].copy(),
        velocity_plug=s[:, S.R_V_PLUG].copy(),
        velocity_output_face=s[:, S.R_V_OUT].copy(),
        velocity_tube=s[:, S.R_V_TUBE].copy(),
        sliding_velocity=s[:, S.R_V_OUT] - s[:, S.R_V_TUBE],
        sliding_displacement=s[:, S.R_SLIP].copy(),
        wall_pressure=0.5 * (p_nodes[:, :-1] + p_nodes[:, 1:]),
        node_displacement=rec["u"],
        wall_friction=rec["ff"],
        momentum_sample=s[:, S.R_P_SAMPLE].copy(),
        momentum_plug=s[:, S.R_P_PLUG].copy(),
        momentum_tube=s[:, S.R_P_TUBE].copy(),
        impulse=s[:, S.R_IMPULSE].copy(),
        plateau=(t_c + tr + 0.75 * (pulse - tr), t_c + pulse),
        incident_strain=eps_i,
        time_step=dt,
        substeps=n_sub,
        axial_stress=-rec["sz"],
        row_z=(np.arange(blk.nz) + 0.5) * dz,
        wall_pressure_nodes=p_nodes,
        energy=energy,
        element_size=config.model.element_size,
        elements=mesh.n_elements,
        critical_time_step=cell.critical_step,
    )
