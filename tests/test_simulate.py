"""Validation of the simulator against independent references (docs/physics.md), not its own output."""

from __future__ import annotations

import math
from dataclasses import replace
from types import MappingProxyType

import numpy as np
import pytest

from friction_uq.physics.tube import lame_hoop_strain
from friction_uq.record import paper_apparatus, read_record, read_truth
from friction_uq.simulate import ChannelSpec, SimulationConfig, run_model, simulate, simulate_to_file
from friction_uq.simulate.hoop import hoop_strain

# docs/physics.md section 4, Table 1 (V_s = 10 m/s, nu = 0.4): f -> (F_io N, F_eo N, V m/s), literal values
TABLE_1 = {
    0.01: (10201.0, 276.0, 9.072),
    0.05: (10097.0, 1440.0, 8.926),
    0.10: (9954.0, 3042.0, 8.726),
    0.20: (9620.0, 6779.0, 8.257),
    0.50: (8184.0, 22863.0, 6.241),
}


def coulomb(f: float, **kw: object) -> SimulationConfig:
    """Base model: Coulomb friction, no clearance, rigid tube, paper's set-up, V_s = 10 m/s, nu = 0.4."""
    return replace(SimulationConfig(), friction_params=MappingProxyType({"f": f}), **kw)


def plateau_mean(out, series: np.ndarray) -> float:
    a, b = out.plateau
    m = (out.time >= a) & (out.time <= b)
    return float(series[m].mean())


@pytest.mark.parametrize("f", sorted(TABLE_1))
def test_stationary_state_matches_table_1(f: float) -> None:
    out = run_model(coulomb(f))
    f_io, f_eo, v = TABLE_1[f]
    assert plateau_mean(out, out.force_internal) == pytest.approx(f_io, rel=0.01)
    assert plateau_mean(out, out.force_external) == pytest.approx(f_eo, rel=0.01)
    assert plateau_mean(out, out.sliding_velocity) == pytest.approx(v, rel=0.01)


@pytest.mark.parametrize("f", [0.05, 0.5])
def test_halving_the_element_size_changes_stationary_forces_by_less_than_half_a_percent(f: float) -> None:
    coarse, fine = run_model(coulomb(f, elements=20)), run_model(coulomb(f, elements=40))
    assert fine.substeps > coarse.substeps or fine.time_step <= coarse.time_step
    for name in ("force_internal", "force_external", "force_input"):
        a, b = plateau_mean(coarse, getattr(coarse, name)), plateau_mean(fine, getattr(fine, name))
        assert abs(a / b - 1.0) < 0.005, name


def test_momentum_balance_of_the_cell_closes() -> None:
    # every option that adds a force path is on: clearance, compliant tube, plug friction
    cfg = coulomb(0.1, gap=5e-6, tube_compliance=True, plug_friction_force=300.0)
    out = run_model(cfg)
    momentum = out.momentum_sample + out.momentum_plug + out.momentum_tube
    scale = np.max(np.abs(momentum))
    assert scale > 0.01  # kg m/s: the cell did move
    for t in (out.plateau[1], out.time[-1]):
        j = int(np.searchsorted(out.time, t)) - 1
        assert abs(momentum[j] - out.impulse[j]) < 0.01 * scale
    # and the impulse is that of the reported forces (trapezoid of the sampled forces, 1 % of its range)
    dt = out.time[1] - out.time[0]
    net = out.force_input - out.force_internal - out.force_external
    j = int(np.searchsorted(out.time, out.plateau[1]))
    assert np.sum(net[:j]) * dt == pytest.approx(out.impulse[j - 1], rel=0.01)


def test_without_friction_the_external_bar_sees_only_noise() -> None:
    noise = 2e-6
    cfg = coulomb(0.0)
    cfg = replace(cfg, channels=MappingProxyType({**cfg.channels,
                                                  "external_output_bar": ChannelSpec(white=noise)}))
    sim = simulate(cfg, seed=5)
    assert np.max(np.abs(sim.force_external)) == 0.0
    assert np.max(np.abs(sim.clean["external_output_bar"])) == 0.0
    rec = sim.noisy["external_output_bar"]
    assert np.std(rec) == pytest.approx(noise, rel=0.1)
    a, b = sim.plateau
    m = (sim.time >= a) & (sim.time <= b)
    assert abs(rec[m].mean()) < 5 * noise / math.sqrt(m.sum())
    # the internal bar carries the whole load: equilibrium F_i = F_io in the plateau
    assert plateau_mean(sim.model, sim.force_internal) == pytest.approx(plateau_mean(sim.model, sim.force_input),
                                                                        rel=1e-3)


def test_gauges_carry_the_interface_forces_after_the_travel_times() -> None:
    """Eq. 2-4 applied to the simulated gauges, time-shifted by d / c, give the interface forces."""
    out = run_model(coulomb(0.1))
    app = paper_apparatus()
    t = out.time
    a, b = out.plateau
    m = (t >= a) & (t <= b)
    t_cell = app.input_bar.gauge_delay  # the incident foot reaches the cell
    for name, force in (("internal_output_bar", out.force_internal), ("external_output_bar", out.force_external)):
        bar = app.bars[name]
        eps_at_end = np.interp(t + bar.gauge_delay, t, out.strains[name])
        # until the far-end reflection of the front passes the gauge, 2 (L - d) / c after it left the cell
        mb = m & (t < t_cell + 2 * (bar.length - bar.gauge_distance) / bar.wave_speed)
        assert mb.sum() > 100
        assert np.allclose(bar.area * bar.young_modulus * eps_at_end[mb], force[mb], rtol=2e-3), name
    ib = app.input_bar
    g = out.strains["input_bar"]
    eps_inc = np.interp(t - ib.gauge_delay, t, g)  # the incident passed the gauge d/c before
    eps_ref = np.interp(t + ib.gauge_delay, t, g)  # the reflected passes it d/c after
    f_i = ib.area * ib.young_modulus * (eps_inc[m] + eps_ref[m])
    assert np.allclose(f_i, out.force_input[m], rtol=0.01)
    assert out.incident_strain == pytest.approx(10.0 / (2 * 4555.0), rel=1e-12)  # eq. 14


@pytest.mark.parametrize("distance, expected", [(0.0, 0.77), (0.005, 0.52), (0.010, 0.14), (0.015, 0.0)])
def test_hoop_gauge_reads_physics_md_band_values(distance: float, expected: float) -> None:
    """A uniform 10 mm band, point gauge: 0.77, 0.52, 0.14, ~0 of the Lame strain (docs/physics.md section 6,
    exact elastic solution; the kernel is fitted to it within 2.4 % of the peak, hence abs=0.02)."""
    tube = replace(paper_apparatus().tube, gauge_offset=distance, gauge_width=0.0)
    p = np.full((1, 40), 50e6)
    eps = hoop_strain(p, np.zeros((1, 41)), tube=tube, sample_length=0.010, beta=192.0)
    lame = lame_hoop_strain(50e6, inner_radius=0.005, outer_radius=0.012, young_modulus=200e9)
    assert float(eps[0] / lame) == pytest.approx(expected, abs=0.02)


def test_hoop_channel_is_negative_in_compression_convention_and_reads_the_wall_pressure() -> None:
    out = run_model(coulomb(0.05))
    j = int(np.searchsorted(out.time, out.plateau[1])) - 1
    hoop = -out.strains["tube_hoop"][j]  # physical hoop strain, swelling positive
    p_mean = out.wall_pressure[j].mean()
    lame = lame_hoop_strain(p_mean, inner_radius=0.005, outer_radius=0.012, young_modulus=200e9)
    assert 0.3 * lame < hoop < lame


def test_same_seed_same_signals_and_file(tmp_path) -> None:
    cfg = replace(coulomb(0.05), channels=MappingProxyType(
        {n: ChannelSpec(white=2e-6, ar1=1e-6, ar1_coef=0.5, offset=1e-5) for n in SimulationConfig().channels}))
    a, b, c = simulate(cfg, seed=11), simulate(cfg, seed=11), simulate(cfg, seed=12)
    for name in a.noisy:
        assert np.array_equal(a.noisy[name], b.noisy[name])
        assert not np.array_equal(a.noisy[name], c.noisy[name])
    p1 = simulate_to_file(cfg, tmp_path / "a.h5", seed=11)
    p2 = simulate_to_file(cfg, tmp_path / "b.h5", seed=11)
    assert p1.read_bytes() == p2.read_bytes()
    rec = read_record(p1)
    assert np.allclose(rec.strain("input_bar"), a.noisy["input_bar"])
    truth = read_truth(p1)
    assert truth["seed"] == 11 and truth["f"] == 0.05 and truth["friction_law"] == "coulomb"
    assert truth["noise_white_sd_input_bar"] == 2e-6 and truth["ar1_coef_input_bar"] == 0.5


def test_ar1_noise_has_the_requested_level_and_correlation() -> None:
    cfg = replace(coulomb(0.05), duration=0.02, channels=MappingProxyType(
        {**SimulationConfig().channels, "input_bar": ChannelSpec(ar1=3e-6, ar1_coef=0.6)}))
    sim = simulate(cfg, seed=3)
    e = sim.noisy["input_bar"] - sim.clean["input_bar"]
    assert np.std(e) == pytest.approx(3e-6, rel=0.05)
    assert np.corrcoef(e[:-1], e[1:])[0, 1] == pytest.approx(0.6, abs=0.03)
