"""Forward models: named parameters, and the simulator driven by the measured incident wave."""

from __future__ import annotations

import dataclasses
import math
from types import MappingProxyType

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from friction_uq.analysis import prepare
from friction_uq.models import SimulatorModel, measured_loading
from friction_uq.models.parameters import F, HOOP_GAIN, NU, Parameter, ParameterSet
from friction_uq.record import read_record
from friction_uq.simulate import SimulationConfig, simulate_to_file
from friction_uq.simulate.model_1d import run_model
from simulated import noisy_config


ODDS = dataclasses.replace(NU, transform="logodds")
LOG = dataclasses.replace(F, transform="log")


@given(st.floats(-30, 30))
def test_interval_transform_round_trips(z):
    for p in (F, NU, HOOP_GAIN, Parameter("x", "m", -1.0, math.inf, "a half-line"), ODDS, LOG):
        v = p.from_unbounded(z)
        if p.contains(v):
            assert p.from_unbounded(p.to_unbounded(v)) == pytest.approx(v, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("p", [NU, HOOP_GAIN, Parameter("x", "m", -1.0, math.inf, "a half-line"), ODDS, LOG])
def test_log_jacobian_matches_a_finite_difference(p):
    z = np.linspace(-3, 3, 7)
    h = 1e-6
    fd = np.log((p.from_unbounded(z + h) - p.from_unbounded(z - h)) / (2 * h))
    np.testing.assert_allclose(p.log_jacobian(z), fd, rtol=1e-6, atol=1e-8)


def test_declared_transforms():
    assert ODDS.to_unbounded(0.25) == pytest.approx(math.log(1 / 3))
    assert LOG.to_unbounded(0.05) == pytest.approx(math.log(0.05))
    with pytest.raises(ValueError, match="log-odds transform needs a support inside"):
        Parameter("x", "m", 0.0, 2.0, "", transform="logodds")
    with pytest.raises(ValueError, match="unknown transform"):
        Parameter("x", "m", 0.0, 2.0, "", transform="probit")


def test_parameter_set_transforms_are_the_parameters_own():
    ps = ParameterSet((LOG, ODDS, HOOP_GAIN))
    theta = np.array([[0.05, 0.4, 1.0], [0.06, 0.35, 0.9]])
    z = ps.to_unbounded(theta)
    for i, p in enumerate(ps):
        np.testing.assert_allclose(z[:, i], p.to_unbounded(theta[:, i]))
    np.testing.assert_allclose(ps.from_unbounded(z), theta, rtol=1e-12)
    np.testing.assert_allclose(ps.log_jacobian(z), sum(p.log_jacobian(z[:, i]) for i, p in enumerate(ps)))


def test_parameters_are_addressed_by_name():
    ps = ParameterSet((F, NU, HOOP_GAIN))
    theta = np.array([[0.05, 0.4, 1.0], [0.06, 0.35, 0.9]])
    d = ps.as_dict(theta)
    assert list(d) == ["f", "nu", "hoop_gain"]
    np.testing.assert_array_equal(ps.vector(d), theta)
    with pytest.raises(KeyError, match="missing parameter"):
        ps.vector({"f": 0.05})
    with pytest.raises(ValueError, match="unique"):
        ParameterSet((F, F))


@pytest.fixture(scope="module")
def trapezoid_record(tmp_path_factory):
    cfg = noisy_config(striker_velocity=11.0, poisson_ratio=0.38,
                        friction_params=MappingProxyType({"f": 0.07}))
    path = tmp_path_factory.mktemp("sim") / "trap.h5"
    simulate_to_file(cfg, path, seed=11)
    rec = read_record(path)
    return cfg, rec, prepare(rec)


def test_measured_incident_wave_reproduces_the_other_channels_within_their_noise(trapezoid_record):
    """The record was made with a trapezoid; the model driven by its measured incident wave, at
    the generating parameters, leaves residuals of the size of each gauge's pre-pulse noise."""
    cfg, rec, prep = trapezoid_record
    model = SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces))
    pred = model.predict({"f": 0.07, "nu": 0.38, "hoop_gain": 1.0}).strains
    loaded = (rec.time > 0.0) & (rec.time < 0.9e-3)
    reflected = (rec.time > 0.56e-3) & (rec.time < 1.05e-3)  # after the incident has passed the gauge
    for ch in ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"):
        nz = prep.forces.channels[ch].noise
        resid = (rec.strain(ch) - nz.offset - pred[ch])[reflected if ch == "input_bar" else loaded]
        factor = math.sqrt(2.0) if ch == "input_bar" else 1.0  # the reflected prediction carries the incident's noise
        ratio = float(np.sqrt(np.mean(resid**2))) / (factor * nz.sd)
        assert 0.8 < ratio < 1.2, (ch, ratio)


def test_a_dispersive_record_is_reproduced_by_the_dispersive_model_fed_the_dispersed_incident_wave(tmp_path):
    """A record made with dispersion: the model whose bars disperse reproduces it within each gauge's noise
    only when the measured incident wave is also carried from its gauge to the cell with dispersion (a
    dispersion-free carry gives the cell an incident front too sharp and early)."""
    cfg = dataclasses.replace(noisy_config(striker_velocity=11.0, poisson_ratio=0.38,
                                           friction_params=MappingProxyType({"f": 0.07})), dispersion=True)
    path = tmp_path / "disp.h5"
    simulate_to_file(cfg, path, seed=12)
    rec = read_record(path)
    prep = prepare(rec)
    values = {"f": 0.07, "nu": 0.38, "hoop_gain": 1.0}
    loaded = (rec.time > 0.0) & (rec.time < 0.9e-3)
    ratios = {}
    for name, extra in (("dispersed", {"dispersive_loading": measured_loading(rec, prep.forces, dispersion=True)}),
                        ("carried without", {})):
        model = SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces), dispersion=True, **extra)
        pred = model.predict(values)
        for ch in ("internal_output_bar", "external_output_bar"):
            nz = prep.forces.channels[ch].noise
            resid = (rec.strain(ch) - nz.offset - pred.strains[ch])[loaded]
            ratios[name, ch] = float(np.sqrt(np.mean(resid**2))) / nz.sd
    for ch in ("internal_output_bar", "external_output_bar"):
        assert 0.8 < ratios["dispersed", ch] < 1.3, ratios
    # the internal bar's sharp transmitted front shows it (4.5 times the noise); the tube's slow force does not
    assert ratios["carried without", "internal_output_bar"] > 2.0 * ratios["dispersed", "internal_output_bar"], ratios


def test_noise_free_measured_loading_matches_the_trapezoid_run():
    cfg = SimulationConfig(striker_velocity=9.0)
    truth = run_model(cfg)
    from friction_uq.simulate.loading import Loading
    from friction_uq.simulate import bars

    app = cfg.apparatus
    ib = app.input_bar
    eps = bars.incident_amplitude(cfg.striker_velocity, striker=app.striker, input_bar=ib)
    dt = 1.0 / cfg.sample_rate
    at_cell, at_gauge = bars.incident_waves(amplitude=eps, pulse_duration=app.pulse_duration,
                                            rise_time=cfg.rise_time, input_bar=ib, t_start=float(truth.time[0]),
                                            dt=dt, n=len(truth.time), dispersive=False)
    driven = run_model(cfg, loading=Loading(truth.time, at_gauge, at_cell))
    for ch in ("internal_output_bar", "external_output_bar", "tube_hoop"):
        peak = np.max(np.abs(truth.strains[ch]))
        assert np.max(np.abs(driven.strains[ch] - truth.strains[ch])) < 0.01 * peak, ch


def test_extension_parameters_reach_the_simulator(trapezoid_record):
    _, rec, prep = trapezoid_record
    gap = Parameter("gap", "m", 0.0, 1e-4, "radial clearance")

    def apply(values, settings, gains):
        settings["gap"] = float(values["gap"])
        settings["tube_compliance"] = True

    model = SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces), extra=(gap,), apply=apply)
    assert model.parameters.names == ("f", "nu", "hoop_gain", "gap")
    base = model.predict({"f": 0.07, "nu": 0.38, "hoop_gain": 1.0, "gap": 0.0}).strains["tube_hoop"]
    wide = model.predict({"f": 0.07, "nu": 0.38, "hoop_gain": 1.0, "gap": 10e-6}).strains["tube_hoop"]
    # a clearance lowers the wall pressure: the tube swells less (compression positive: less negative)
    assert np.min(wide) > np.min(base) * 0.95


def test_a_start_beyond_a_bounded_support_is_moved_just_inside_it():
    """A clean axisymmetric record with its hoop gauge at twice its scale: the stationary nu, whose support reaches
    0.5, started the simulator's fits (nu below 0.49) at 0.495, and `run --diagnose` ended in an internal error
    ("Initial guess is outside of provided bounds")."""
    from friction_uq.models.simulator import NU as SIMULATOR_NU

    assert SIMULATOR_NU.nearest_inside(0.4) == 0.4
    for beyond in (0.49, 0.495, 0.5, 0.7):
        inside = SIMULATOR_NU.nearest_inside(beyond)
        assert inside == pytest.approx(0.49 - 0.49e-3) and np.isfinite(SIMULATOR_NU.to_unbounded(inside))
    assert SIMULATOR_NU.nearest_inside(-0.1) == pytest.approx(0.49e-3)
    half_line = Parameter("gap", "m", 0.0, math.inf, "a gap")
    assert half_line.nearest_inside(8e-6) == 8e-6  # no width to step in by: as given
