"""A confident wrong f is never reported: stick-slip read by levels, warnings that can fail, a gauge
that disagrees named rather than hidden behind "no stationary phase"."""

from __future__ import annotations

import json
import math
import os
import sys
from types import MappingProxyType

import numpy as np
import pytest
from simulated import noisy_config

from friction_uq.analysis import prepare
from friction_uq.errors import SignalError
from friction_uq.physics import cell
from friction_uq.record import read_record, write_record
from friction_uq.record_run.pipeline import run_file
from friction_uq.simulate import simulate

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
from bench_misfit import with_gain  # noqa: E402
from bench_trust import effective_f, make_record  # noqa: E402


def _record(tmp_path, name, cfg, how=None):
    path = str(tmp_path / f"{name}.h5")
    model, _ = make_record(cfg, path, 7, how, np.random.default_rng(1))
    return path, model


def test_stick_slip_f_is_eq17_of_the_window_means_and_holds_the_truth(tmp_path):
    """A steep velocity weakening makes the forces oscillate through the plateau (stick-slip): f agrees
    with eq. 17 on the window's mean ratio within its sd, its 90 % interval holds the wall's effective
    coefficient, and a warning says the phase is not stationary."""
    law = MappingProxyType({"f_s": 0.2, "f_d": 0.03, "v_c": 8.0})
    cfg = noisy_config(friction_law="velocity", friction_params=law, test_id="SS", campaign="T")
    path, model = _record(tmp_path, "ss", cfg)
    res = run_file(path, out_dir=tmp_path / "out", window=(450e-6, 700e-6), pdf=False, progress=False,
                   table=False, notes=False, whole_record=False)
    d = res.prepared.data
    f = res.summary["f"]
    nu = res.summary["nu"].q50
    ratio = float(np.mean(d.F_eo) / np.mean(d.F_io))
    f_eq17 = math.log1p(ratio) / float(cell.beta(nu, radius=d.radius, length=d.length))
    assert abs(f.q50 - f_eq17) <= f.sd
    truth = effective_f(model, d.window[0], d.window[1], d.radius, d.length)
    assert f.q05 <= truth <= f.q95
    assert any("not stationary" in w for w in res.warnings)
    doc = json.loads(res.outputs["json"].read_text())
    assert list(doc)[:5] == ["schema", "schema_version", "warnings", "warning_kinds", "f"]
    assert doc["warnings"] == list(res.warnings) and doc["warning_kinds"] == list(res.warning_kinds)
    assert [k for k, w in zip(res.warning_kinds, res.warnings) if "not stationary" in w] == ["stationarity"]
    # no diagnosis: the f to quote is the stationary f, with the output bars' calibration folded in
    assert doc["f"]["model"] == "stationary"
    assert doc["f"]["given_bar_headers"]["q50"] == doc["f_stationary"]["q50"] == f.q50
    assert doc["f"]["q05"] < f.q05 < f.q50 < f.q95 < doc["f"]["q95"]
    assert doc["f"]["q50"] == pytest.approx(f.q50, rel=0.005)  # a median moved only by the draws' discreteness


def test_a_clean_record_has_no_warning(tmp_path):
    path, _ = _record(tmp_path, "clean", noisy_config(test_id="C", campaign="T"))
    res = run_file(path, out_dir=tmp_path / "out", pdf=False, progress=False, table=False, notes=False)
    assert res.warnings == ()


def test_an_internal_gauge_reading_7_percent_low_is_named_not_refused(tmp_path):
    cfg = with_gain(noisy_config(test_id="G", campaign="T"), "internal_output_bar", 0.93)
    path, _ = _record(tmp_path, "gain", cfg)
    prep = prepare(read_record(path))
    assert prep.gauge_notes and "sum to 93 % of the input force" in prep.gauge_notes[0]
    res = run_file(path, out_dir=tmp_path / "out", pdf=False, progress=False, table=False, notes=False,
                   whole_record=False)
    assert res.warnings
    assert res.warnings[0].startswith("A gauge disagrees with the others: the output forces sum to 93 %")


@pytest.mark.parametrize("channel", ["internal_output_bar", "external_output_bar", "input_bar"])
def test_a_reversed_gauge_is_named_with_the_file(tmp_path, channel):
    cfg = noisy_config(test_id="R", campaign="T")
    path = str(tmp_path / "rev.h5")
    sim = simulate(cfg, seed=3)
    noisy = dict(sim.noisy)
    noisy[channel] = -noisy[channel]
    write_record(path, test_id="R", campaign="T", sample_rate=cfg.sample_rate, strains=noisy, apparatus=cfg.apparatus,
                 t0=float(sim.time[0]))
    with pytest.raises(SignalError, match=rf"^{path}: /signals/{channel}.*reversed"):
        prepare(read_record(path))


def test_swapped_output_channels_are_named(tmp_path):
    cfg = noisy_config(test_id="S", campaign="T")
    sim = simulate(cfg, seed=4)
    noisy = dict(sim.noisy)
    io, eo = noisy["internal_output_bar"], noisy["external_output_bar"]
    noisy["internal_output_bar"], noisy["external_output_bar"] = eo, io
    path = str(tmp_path / "swap.h5")
    write_record(path, test_id="S", campaign="T", sample_rate=cfg.sample_rate, strains=noisy, apparatus=cfg.apparatus,
                 t0=float(sim.time[0]))
    with pytest.raises(SignalError, match=rf"^{path}: the output forces sum to .* look swapped"):
        prepare(read_record(path))
