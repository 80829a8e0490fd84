"""A likelihood asks the simulator for each gauge's span only: the run stops where those samples need it, and they
are the whole run's to the bit (the 1-D model is causal), for the baseline and every entry of the catalogue, a
channel read early (a negative delay) and a bar's modulus among them. The rest (past a few samples' margin) is
NaN, so that nothing reads it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from friction_uq.analysis import prepare
from friction_uq.discrepancy.extended import candidates
from friction_uq.discrepancy.fit import WholeRecordLikelihood
from friction_uq.models import SimulatorModel, measured_loading
from friction_uq.record import read_record
from friction_uq.simulate import SimulationConfig
from friction_uq.simulate.model_1d import run_model

RECORD = Path(__file__).resolve().parents[1] / "data" / "A" / "A-03.h5"

#: values away from each mechanism's start, so that each changes the record (a delay of -6 us reads 30 samples early)
AWAY = {"gap": 10e-6, "plug_force": 300.0, "plug_coefficient": 0.01, "p0": 7e7, "n_p": 8.0, "n_d": 0.5, "f_s": 0.09,
        "v_c": 4.0, "d_c": 5e-4, "f_e": 0.4, "gain": 1.12}


def _away(name: str, start: float) -> float:
    for prefix, value in (("delay_", -6e-6), ("time_constant_", 4e-6), ("drift_", 0.02), ("modulus_factor_", 1.07)):
        if name.startswith(prefix):
            return value
    return AWAY.get(name, start)


@pytest.fixture(scope="module")
def prepared():
    return prepare(read_record(RECORD))


def _model(prep, variant) -> SimulatorModel:
    rec = prep.record

    def apply(values, settings, readings):
        variant.mechanism.apply(values, settings, readings, variant.channel)

    return SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces), extra=variant.mechanism.parameters,
                          apply=apply,
                          dispersive_loading=measured_loading(rec, prep.forces, dispersion=True))


def test_each_gauges_span_is_the_whole_runs_to_the_bit(prepared):
    lik = WholeRecordLikelihood(prepared, _model(prepared, candidates()[0]))
    until = {c: b[3] for c, b in lik.bounds.items()}
    checked = 0
    for variant in candidates():
        model = _model(prepared, variant)
        values = {"f": 0.06, "nu": 0.41, "hoop_gain": 1.0}
        values |= {p.name: _away(p.name, variant.mechanism.start[p.name]) for p in variant.mechanism.parameters}
        whole = model.predict(values).strains
        cfg, _ = model.config(values)
        # all four spans (the hoop's, read at once, then sets where the cell stops), then each gauge's alone: its own
        # lag behind the cell (a bar's gauge distance over its wave speed, a delay read early) sets it
        for asked in (until, *({c: k} for c, k in until.items())):
            spans = model.predict(values, until=asked).strains
            for c, k in asked.items():
                assert np.array_equal(spans[c][:k], whole[c][:k]), (variant.label, asked, c)
                if not cfg.dispersion:  # a dispersive configuration runs over the whole record
                    assert np.isnan(spans[c][-1]) and len(spans[c]) == len(whole[c]), (variant.label, c)
                    checked += 1
    assert checked >= 2 * 4 * (len(candidates()) - 1)


def test_the_likelihood_reads_the_spans_as_it_read_the_whole_run(prepared):
    lik = WholeRecordLikelihood(prepared, SimulatorModel(prepared.record.apparatus,
                                                         measured_loading(prepared.record, prepared.forces)))
    values = {"f": 0.05, "nu": 0.39}
    assert np.array_equal(lik.whitened(values), lik.whitened_from(lik.unit_strains(values)))


@pytest.mark.parametrize("substeps", [1, 3])
def test_the_simulation_stops_short_only_where_asked(substeps):
    cfg = SimulationConfig(duration=1.2e-3, pretrigger=80e-6, sample_rate=5e6, min_substeps=substeps)
    whole = run_model(cfg)
    for gauge in ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"):
        short = run_model(cfg, until={gauge: 3000})
        assert np.array_equal(short.strains[gauge][:3000], whole.strains[gauge][:3000]), gauge
        assert np.isnan(short.strains[gauge][-1]) and not np.isnan(whole.strains[gauge][-1]), gauge
        assert all(np.isnan(x).all() for c, x in short.strains.items() if c != gauge)  # not asked for
        assert np.isnan(short.force_internal[-1]) and not np.isnan(whole.force_internal[-1])
    with pytest.raises(ValueError, match="dispersive"):
        run_model(SimulationConfig(duration=1.2e-3, pretrigger=80e-6, sample_rate=5e6, dispersion=True),
                  until={"internal_output_bar": 3000})
