"""The delay the measurement chain's delay-like faults put on a gauge's fronts, and what a round's candidates agree
on (friction_uq/discrepancy/front_delay.py): closed forms of the delay, the low-pass and the bar's wave speed."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from friction_uq.apparatus import paper_apparatus
from friction_uq.discrepancy.diagnosis_words import delay_clause
from friction_uq.discrepancy.front_delay import (SharedDelay, front_delays, round_shared_delay, shared_delay,
                                                 wave_speed_delay)
from friction_uq.models.measurement_chain import delayed, low_passed

APP = paper_apparatus()
DT = 1e-7
T = np.arange(0.0, 400e-6, DT)


def _front(rise: float = 20e-6, start: float = 50e-6) -> np.ndarray:
    """A unit front rising as a half cosine over ``rise`` from ``start``."""
    s = np.clip((T - start) / rise, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(np.pi * s))


@settings(max_examples=40, deadline=None)
@given(k=st.floats(0.85, 1.15), bar=st.sampled_from(["internal_output_bar", "external_output_bar"]))
def test_a_bars_modulus_delays_its_gauge_by_the_travel_time_at_the_true_wave_speed(k, bar):
    header = getattr(APP, bar)
    true = replace(header, young_modulus=header.young_modulus * k, wave_speed=header.wave_speed * math.sqrt(k))
    assert wave_speed_delay(header.gauge_delay, k) == pytest.approx(true.gauge_delay - header.gauge_delay, rel=1e-9)
    d = front_delays("bar_modulus", {f"modulus_factor_{bar}": k}, APP)
    assert d[bar] == pytest.approx(true.gauge_delay - header.gauge_delay, rel=1e-9, abs=1e-15)
    assert (d[bar] > 0) == (k < 1)  # a softer bar carries the wave slower: its gauge reads late


def test_the_models_low_pass_delays_a_ramp_by_its_time_constant():
    tau = 3e-6
    ramp = np.maximum(T - 50e-6, 0.0) * 1e3
    y = low_passed(T, ramp, tau)
    late = T > 50e-6 + 20 * tau  # the start's transient has decayed as exp(-20)
    assert np.max(np.abs(y[late] - delayed(T, ramp, tau)[late])) < 1e-9 * ramp.max()
    assert front_delays("bandwidth", {"time_constant_tube_hoop": tau}, APP)["tube_hoop"] == tau


@pytest.mark.parametrize("fc", [50e3, 60e3, 80e3])
def test_a_second_order_butterworth_is_a_pure_delay_but_for_its_third_order_term(fc):
    """ln H of 1 / (1 + sqrt(2) s / w + s^2 / w^2) has no s^2 term: the amplifier is the delay sqrt(2) / w plus
    sqrt(2) / (3 w^3) times the third derivative; a first-order low-pass with the same lag rounds the front by its
    second-order term, tau^2 / 2 times the second derivative, several times more."""
    x = _front()
    w = 2 * math.pi * fc
    lag = math.sqrt(2.0) / w
    butter = signal.sosfilt(signal.butter(2, fc, fs=1.0 / DT, output="sos"), x)
    third = math.sqrt(2.0) / (3 * w ** 3) * 0.5 * (math.pi / 20e-6) ** 3  # the term's peak on this front
    off = np.max(np.abs(butter - delayed(T, x, lag)))
    assert off < 1.5 * third
    assert np.max(np.abs(low_passed(T, x, lag) - delayed(T, x, lag))) > 2.5 * off


def test_timing_reads_its_delays():
    d = front_delays("channel_timing", {"delay_internal_output_bar": 2e-6, "delay_tube_hoop": -1e-7}, APP)
    assert d == {"internal_output_bar": 2e-6, "external_output_bar": 0.0, "tube_hoop": -1e-7}
    assert front_delays("clearance", {"gap": 1e-5}, APP) == {}


# the fitted values of a channel timing fault of +4.69 us on the internal output bar (a stored study record)
TIMING = ("channel_timing", {"delay_internal_output_bar": 4.66e-6, "delay_external_output_bar": -0.47e-6,
                             "delay_tube_hoop": -0.08e-6})
MODULUS = ("bar_modulus", {"modulus_factor_internal_output_bar": 0.874, "modulus_factor_external_output_bar": 1.05})
LOW_PASS = ("bandwidth", {"time_constant_internal_output_bar": 5.06e-6, "time_constant_external_output_bar": 0.38e-6,
                          "time_constant_tube_hoop": 0.18e-6})


def test_candidates_that_delay_the_same_gauge_the_same_way_share_its_delay():
    sd = shared_delay([TIMING, MODULUS, LOW_PASS], APP)
    assert sd.gauge == "internal_output_bar" and sd.mechanisms == ("channel_timing", "bar_modulus", "bandwidth")
    modulus_delay = APP.internal_output_bar.gauge_delay * (1 / math.sqrt(0.874) - 1)
    assert (sd.low, sd.high) == pytest.approx((min(4.66e-6, modulus_delay), max(5.06e-6, modulus_delay)))
    assert sd.to_json() == {"gauge": "internal_output_bar", "low_s": sd.low, "high_s": sd.high,
                            "mechanisms": ["channel_timing", "bar_modulus", "bandwidth"]}


@pytest.mark.parametrize("fits", [
    [TIMING],  # one mechanism: nothing to agree on
    [TIMING, ("clearance", {"gap": 1e-5})],  # a cell's mechanism among them
    [TIMING, ("bandwidth", {"time_constant_tube_hoop": 5e-6})],  # another gauge
    [TIMING, ("bar_modulus", {"modulus_factor_internal_output_bar": 1.2})],  # the other way: early
    [("channel_timing", {}), LOW_PASS],  # a fault that delays nothing
])
def test_nothing_is_shared_unless_every_candidate_delays_one_gauge_one_way(fits):
    assert shared_delay(fits, APP) is None


def _fit(label, mechanism, values):
    draws = {k: np.full(5, v) for k, v in values.items()}
    return SimpleNamespace(label=label, variants=(SimpleNamespace(mechanism=SimpleNamespace(name=mechanism)),),
                           fit=SimpleNamespace(draws=draws))


def test_a_round_shares_the_delay_of_its_best_and_the_rivals_it_does_not_tell_apart():
    ranked = [SimpleNamespace(fit=_fit(m, m, v)) for m, v in (TIMING, MODULUS, ("clearance", {"gap": 1e-5}))]
    verdict = SimpleNamespace(named="channel_timing", rivals=("bar_modulus", "clearance"))
    sd = round_shared_delay(verdict, ranked, ("channel_timing", "bar_modulus"), APP)
    assert sd.mechanisms == ("channel_timing", "bar_modulus")  # the clearance is not among the names
    assert round_shared_delay(verdict, ranked, ("channel_timing", "bar_modulus", "clearance"), APP) is None
    assert round_shared_delay(verdict, ranked, (), APP) is None


def test_the_sentence_says_the_delay_the_record_shows():
    dg = SimpleNamespace(shared_delay=SharedDelay("internal_output_bar", 3.35e-6, 3.77e-6,
                                                  ("bandwidth", "channel_timing")))
    assert delay_clause(dg) == (" What the record does show: the internal transmitted gauge's fronts 3.4 to 3.8 us "
                                "late against the input bar's, by each of bandwidth, channel_timing.")
    dg = SimpleNamespace(shared_delay=SharedDelay("tube_hoop", -1.87e-6, -1.87e-6, ("bar_modulus", "channel_timing")))
    assert "tube hoop gauge's fronts 1.9 us early" in delay_clause(dg)
    assert delay_clause(SimpleNamespace(shared_delay=None)) == ""
