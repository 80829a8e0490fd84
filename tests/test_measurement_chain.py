"""A gauge's measurement chain (gain, drift, timing, bandwidth): the pure functions against closed forms and
properties, the simulator's readings, and the catalogue's chain faults recovered from simulated records (a
channel shifted, a channel through a Butterworth filter the model's first-order low-pass does not share, an
output bar stiffer than its header)."""

from __future__ import annotations

import math
from dataclasses import replace
import os
import sys
from types import MappingProxyType

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from friction_uq.models.measurement_chain import Reading, delayed, low_passed, zero_drift
from friction_uq.models.parameters import Parameter

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))

DT = 2e-7
T = np.arange(2000) * DT


def _pulse(t: np.ndarray, t0: float = 1e-4, rise: float = 10e-6, width: float = 150e-6) -> np.ndarray:
    """A trapezoid: rise, plateau, fall (strain)."""
    return 5e-4 * np.clip(np.minimum((t - t0) / rise, (t0 + width - t) / rise), 0.0, 1.0)


finite = st.floats(-1e-3, 1e-3, allow_nan=False)


@given(st.lists(finite, min_size=3, max_size=60))
def test_neutral_chain_reads_the_strain_itself(x):
    x = np.array(x)
    t = np.arange(len(x)) * DT
    np.testing.assert_array_equal(Reading().applied(t, x), x)
    np.testing.assert_array_equal(delayed(t, x, 0.0), x)
    np.testing.assert_array_equal(low_passed(t, x, 0.0), x)


@given(st.integers(0, 50), st.lists(finite, min_size=60, max_size=120))
def test_a_delay_of_whole_samples_shifts_the_samples(k, x):
    x = np.array(x)
    t = np.arange(len(x)) * DT
    y = delayed(t, x, k * DT)
    np.testing.assert_allclose(y[k:], x[:len(x) - k], rtol=0, atol=1e-15)
    np.testing.assert_allclose(y[:k], x[0])  # before the record: its first value held


@given(st.floats(1e-8, 1e-5), st.floats(-1e-3, 1e-3))
def test_the_low_pass_keeps_a_constant_and_answers_a_ramped_step_exactly(tau, level):
    const = np.full(200, level)
    np.testing.assert_allclose(low_passed(T[:200], const, tau), const, rtol=1e-12, atol=1e-18)
    # a step from 0 to 1 between samples 9 and 10, linear in between: y' = (x - y) / tau solved by hand
    step = np.r_[np.zeros(10), np.ones(190)]
    y = low_passed(T[:200], step, tau)
    a, r = math.exp(-DT / tau), tau / DT
    n = np.arange(190)
    np.testing.assert_allclose(y[10:], 1.0 - r * (1.0 - a) * a ** n, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(y[:10], 0.0, atol=1e-18)


def test_the_low_pass_and_the_delay_tend_to_the_strain_and_do_not_lead():
    x = _pulse(T)
    assert np.max(np.abs(low_passed(T, x, 1e-12) - x)) < 1e-6 * np.max(x)
    assert np.max(np.abs(delayed(T, x, 1e-12) - x)) < 1e-6 * np.max(x)
    # through a slow low-pass a long ramp lags by tau exactly (no half-sample lead): x - tau x'
    ramp = T.copy()
    tau = 1e-6
    np.testing.assert_allclose(low_passed(T, ramp, tau)[200:], ramp[200:] - tau, rtol=0, atol=1e-12)


def test_the_low_pass_and_its_minus_3_db_frequency():
    """A sine at 1 / (2 pi tau) comes out at 1/sqrt(2) of its amplitude (first order), once settled."""
    tau = 1e-6
    t = np.arange(200_000) * 2e-8
    x = np.sin(t / tau)
    y = low_passed(t, x, tau)[100_000:]
    assert np.max(np.abs(y)) == pytest.approx(1.0 / math.sqrt(2.0), rel=2e-3)


def test_a_drift_is_a_straight_line_from_the_first_sample():
    d = zero_drift(T + 3e-4, 0.01)
    assert d[0] == 0.0 and d[-1] == pytest.approx(0.01 * (T[-1] - T[0]))
    assert np.allclose(np.diff(d, 2), 0.0, atol=1e-18)


def test_the_chain_adds_its_drift_after_the_gain():
    """Gain, low-pass and delay are linear and commute; the drift is the amplifier's zero, not scaled by the
    bridge's gain."""
    zero = np.zeros_like(T)
    np.testing.assert_allclose(Reading(gain=2.0, drift=0.02).applied(T, zero), 0.02 * (T - T[0]), rtol=1e-12)
    r = Reading(gain=1.1, delay=1.3e-6, time_constant=0.4e-6)
    x = _pulse(T)
    np.testing.assert_allclose(r.applied(T, x), 1.1 * low_passed(T, delayed(T, x, 1.3e-6), 0.4e-6),
                               rtol=1e-9, atol=1e-15)
    assert not r.exact and Reading().exact


@given(st.floats(-50.0, 50.0), st.floats(1e-9, 1e3))
def test_a_scaled_parameter_round_trips_with_its_jacobian(z, scale):
    p = Parameter("x", "-", -math.inf, math.inf, "x", scale=scale)
    assert float(p.to_unbounded(p.from_unbounded(z))) == pytest.approx(z, rel=1e-12, abs=1e-12)
    h = 1e-6
    slope = (float(p.from_unbounded(z + h)) - float(p.from_unbounded(z - h))) / (2 * h)
    assert float(p.log_jacobian(z)) == pytest.approx(math.log(slope), rel=1e-6, abs=1e-6)


def test_a_parameter_on_the_real_line_steps_in_its_own_scale():
    p = Parameter("delay", "s", -math.inf, math.inf, "a delay", scale=1e-6)
    assert p.to_unbounded(2e-6) == pytest.approx(2.0)
    assert p.from_unbounded(-0.5) == pytest.approx(-0.5e-6)
    assert p.log_jacobian(0.3) == pytest.approx(math.log(1e-6))
    with pytest.raises(ValueError, match="whole real line"):
        Parameter("gap", "m", 0.0, 1.0, "a gap", scale=1e-6)


def test_the_simulator_reads_the_input_bar_through_its_chain(chain_records):
    """A delay on the input bar's reading: the measured incident wave stays where it was read (it drives the
    simulation from where it truly was), the other gauges move against it."""
    from friction_uq.analysis import prepare
    from friction_uq.models import SimulatorModel, measured_loading
    from friction_uq.record import read_record

    rec = read_record(chain_records["clean"])
    loading = measured_loading(rec, prepare(rec).forces)
    delay = 2e-6

    def late(values, settings, readings):
        readings["input_bar"].delay = delay

    base = SimulatorModel(rec.apparatus, loading).predict({"f": 0.05, "nu": 0.4})
    moved = SimulatorModel(rec.apparatus, loading, apply=late).predict({"f": 0.05, "nu": 0.4})
    t = loading.time
    peak = np.max(np.abs(base.strains["input_bar"]))
    assert np.max(np.abs(moved.strains["input_bar"] - base.strains["input_bar"])) < 0.02 * peak
    early = delayed(t, base.strains["external_output_bar"], -delay)
    assert np.max(np.abs(moved.strains["external_output_bar"] - early)) < 0.02 * np.max(early)
    assert np.max(np.abs(base.strains["external_output_bar"] - early)) > 0.1 * np.max(early)  # it did move


@pytest.fixture(scope="module")
def chain_records(tmp_path_factory):
    """One clean simulated record and the same record with its external output gauge read 4 us late and,
    separately, through a 2nd-order Butterworth low-pass at 60 kHz."""
    from bench_trust import write_strains
    from simulated import noisy_config

    from friction_uq.simulate import simulate

    cfg = noisy_config(striker_velocity=10.0, friction_params=MappingProxyType({"f": 0.05}))
    sim = simulate(cfg, seed=7)
    t, ch = sim.time, "external_output_bar"
    made = {"clean": dict(sim.noisy), "late": dict(sim.noisy), "slow": dict(sim.noisy)}
    made["late"][ch] = np.interp(t - 4e-6, t, sim.noisy[ch])
    made["slow"][ch] = signal.sosfilt(signal.butter(2, 60e3, fs=1.0 / (t[1] - t[0]), output="sos"), sim.noisy[ch])
    folder = tmp_path_factory.mktemp("chain")
    out = {}
    for name, noisy in made.items():
        path = str(folder / f"{name}.h5")
        write_strains(cfg, path, sim, noisy, campaign="X")
        out[name] = path
    # the external output bar 6 % stiffer than the header the record carries (its wave speed 3 % faster)
    bar = cfg.apparatus.external_output_bar
    stiff = replace(cfg, apparatus=replace(cfg.apparatus, external_output_bar=replace(
        bar, young_modulus=1.06 * bar.young_modulus, wave_speed=math.sqrt(1.06) * bar.wave_speed)))
    sim = simulate(stiff, seed=7)
    out["stiff"] = str(folder / "stiff.h5")
    write_strains(cfg, out["stiff"], sim, dict(sim.noisy), campaign="X")
    return out


def _fits(path, names):
    from friction_uq.analysis import prepare
    from friction_uq.discrepancy.block_loo import elpd_difference
    from friction_uq.discrepancy.extended import Diagnoser, Variant
    from friction_uq.discrepancy.mechanisms import MECHANISMS
    from friction_uq.prior_loader import default_prior_path, load_priors
    from friction_uq.record import read_record

    priors = load_priors(default_prior_path("I1"))

    def log_prior(v):
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    dg = Diagnoser(prepare(read_record(path)), log_prior, hoop=True, seed=5, n_draws=60)
    start = {"f": 0.05, "nu": 0.4}
    base = dg.fit((), start, "reference")
    out = {}
    for name in names:
        mf = dg.fit((Variant(MECHANISMS[name]),), start, name)
        out[name] = (mf, *elpd_difference(mf.elpd, base.elpd))
    return out


def test_a_late_channel_is_measured_where_the_fault_was_made_by_other_code(chain_records):
    fits = _fits(chain_records["late"], ("channel_timing",))
    mf, delpd, se = fits["channel_timing"]
    d = mf.fit.draws["delay_external_output_bar"]
    lo, hi = np.quantile(d, [0.005, 0.995])
    assert lo <= 4e-6 <= hi and lo > 0.0, (lo, hi)  # the truth inside, no delay outside
    for other in ("delay_internal_output_bar", "delay_tube_hoop"):  # the gauges that read right stay near 0
        assert abs(np.median(mf.fit.draws[other])) < 0.5e-6
    assert delpd > 4.0, (delpd, se)  # evidence at the fronts only: whether it names the cause is the verdict's
    assert np.quantile(mf.fit.draws["f"], 0.05) <= 0.05 <= np.quantile(mf.fit.draws["f"], 0.95)


@pytest.mark.slow  # five whole-record fits: in the default suite it kept that suite over 10 minutes (12 s in a CI run)
def test_a_slow_amplifier_is_seen_on_its_channel_and_a_clean_record_gains_nothing(chain_records):
    mf, delpd, se = _fits(chain_records["slow"], ("bandwidth",))["bandwidth"]
    tc = {c: float(np.median(mf.fit.draws[f"time_constant_{c}"]))
          for c in ("internal_output_bar", "external_output_bar", "tube_hoop")}
    # a 2nd-order Butterworth at 60 kHz delays a front like a first-order chain of about 1/(2 pi 60 kHz) ... 2x that
    assert 1e-6 < tc["external_output_bar"] < 6e-6 and max(tc["internal_output_bar"], tc["tube_hoop"]) < 0.5e-6, tc
    assert delpd > 4.0, (delpd, se)
    clean = _fits(chain_records["clean"], ("bandwidth", "channel_timing", "zero_drift", "bar_modulus"))
    for name, (_, d, s) in clean.items():
        assert d < 4.0, (name, d, s)  # nothing to gain on a clean record


def test_a_chain_fault_fitted_on_every_gauge_says_which_gauge():
    from friction_uq.discrepancy.mechanisms import MECHANISMS

    m = MECHANISMS["channel_timing"]
    gauge, p = m.departing_gauge({"delay_internal_output_bar": 0.1e-6, "delay_external_output_bar": -3e-6,
                                  "delay_tube_hoop": 0.5e-6})
    assert gauge == "external_output_bar" and p.name == "delay_external_output_bar"
    for right in (1e-9, 0.1e-6, 0.3e-6):  # gauges that read right, at any time constant near 0
        gauge, _ = MECHANISMS["bandwidth"].departing_gauge({"time_constant_internal_output_bar": right,
                                                            "time_constant_external_output_bar": right,
                                                            "time_constant_tube_hoop": 2.5e-6})
        assert gauge == "tube_hoop", right
    gauge, _ = MECHANISMS["bar_modulus"].departing_gauge({"modulus_factor_internal_output_bar": 0.999,
                                                          "modulus_factor_external_output_bar": 0.95})
    assert gauge == "external_output_bar"
    assert MECHANISMS["clearance"].departing_gauge({"gap": 1e-6}) is None


def test_the_chain_faults_are_fitted_on_the_gauges_a_record_has():
    from friction_uq.discrepancy.extended import candidates
    from friction_uq.discrepancy.mechanisms import MECHANISMS

    bars = ("input_bar", "internal_output_bar", "external_output_bar")
    drift = MECHANISMS["zero_drift"].on_gauges(bars)
    assert drift.per_gauge == bars and [p.name for p in drift.parameters] == [f"drift_{g}" for g in bars]
    assert set(drift.priors) == set(drift.start) == {f"drift_{g}" for g in bars}
    assert MECHANISMS["bandwidth"].on_gauges(("input_bar",)) is None  # read against the input bar: nothing left
    assert MECHANISMS["clearance"].on_gauges(("input_bar",)) is MECHANISMS["clearance"]  # the cell's own: whole
    assert MECHANISMS["gauge_gain"].on_gauges(bars[:2]).channels == bars[:2]
    every = {p.name for v in candidates() for p in v.mechanism.parameters}
    without = {p.name for v in candidates(gauges=bars) for p in v.mechanism.parameters}
    assert every - without == {"drift_tube_hoop", "delay_tube_hoop", "time_constant_tube_hoop"}
    assert [v.label for v in candidates()] == [v.label for v in candidates(gauges=bars)]


def test_a_record_read_without_its_hoop_gauge_gets_no_hoop_parameter(chain_records):
    from friction_uq.analysis import prepare
    from friction_uq.discrepancy.extended import Diagnoser, candidates
    from friction_uq.prior_loader import default_prior_path, load_priors
    from friction_uq.record import read_record

    priors = load_priors(default_prior_path("I1"))

    def log_prior(v):
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    dg = Diagnoser(prepare(read_record(chain_records["late"])), log_prior, hoop=False, seed=5, n_draws=60)
    assert "tube_hoop" not in dg.gauges
    timing = next(v for v in candidates(gauges=dg.gauges) if v.mechanism.name == "channel_timing")
    mf = dg.fit((timing,), {"f": 0.05, "nu": 0.4}, "channel_timing")
    assert "delay_tube_hoop" not in mf.fit.draws and "delay_internal_output_bar" in mf.fit.draws
    d = mf.fit.draws["delay_external_output_bar"]
    assert np.quantile(d, 0.005) <= 4e-6 <= np.quantile(d, 0.995)


def test_an_output_bar_stiffer_than_its_header_is_measured(chain_records):
    mf, delpd, se = _fits(chain_records["stiff"], ("bar_modulus",))["bar_modulus"]
    k = mf.fit.draws["modulus_factor_external_output_bar"]
    lo, hi = np.quantile(k, [0.005, 0.995])
    assert lo <= 1.06 <= hi and lo > 1.0, (lo, hi)
    assert abs(np.median(mf.fit.draws["modulus_factor_internal_output_bar"]) - 1.0) < 0.01
    assert delpd > 4.0, (delpd, se)
    assert np.quantile(mf.fit.draws["f"], 0.05) <= 0.05 <= np.quantile(mf.fit.draws["f"], 0.95)
