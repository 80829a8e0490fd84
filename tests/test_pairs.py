"""Two hidden effects at once through every round of ``diagnose`` (slow and long: about 13 min, -m long): records of the pairs study
(``benchmarks/bench_pairs.py``, seed 29).

1d-0, a clearance with a velocity-weakening wall on the 1-D simulation. The clearance is named in the first round.
In the second the velocity law leads the pressure and slip laws, a channel's timing and an amplifier's bandwidth by tens of nats over the whole record and holds 0.96 of the
stacking weight, but within 2 SE of them: before the weight route (docs/methods.md) the round was candidates and
only the clearance was named. Now both are, and f's interval holds the truth. The pressure law is ruled out by the
evidence without the blocks most in the velocity law's favour (the rival ruling since the forty-fourth session), the
timing and the bandwidth, within 2 SE either way, by the weight. (That a cause named first stays
named when a later round's candidates stay open is tested on constructed verdicts in tests/test_diagnose.py.)

1d-5, dispersion with a clearance: dispersion, a channel's timing and an amplifier's bandwidth explain the first
misfit alike; dispersion is fitted in turn and the clearance named in the next round; the swap check
(:mod:`friction_uq.discrepancy.rival_swaps`) then finds the timing and the bandwidth in dispersion's place thousands
of nats worse, and the model without dispersion flagged by the whole-record check: both are named.

axisymmetric-3, a slip-weakening wall with plug friction: a zero drift on the hoop gauge is fitted in turn among
candidates, and gains over a hundred nats even with the slip law and the plug friction in the model (it absorbs
where the axisymmetric cell's hoop strain departs from the 1-D model's). The whole-record check does not flag the
model without it, so it is not named: only the two causes that are there."""

from __future__ import annotations

import os
import re
import sys

import numpy as np
import pytest

from friction_uq.discrepancy import outcome
from friction_uq.discrepancy.block_loo import elpd_difference
from friction_uq.stats import RULE
from friction_uq.stats.trimmed import points_to_drop
from friction_uq.discrepancy.diagnose import MAX_CAUSES
from friction_uq.prior_loader import default_prior_path, load_priors

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
from bench_diagnose import analyse  # noqa: E402
from bench_pairs import PAIRS_1D, PAIRS_AXISYMMETRIC, make_pair  # noqa: E402
from verdict_records import write  # noqa: E402

# long: the three records took 754 s in a CI run of the fifty-sixth session, and CI took 67 minutes with them (stop
# 72) where it is to stay under 60
pytestmark = [pytest.mark.slow, pytest.mark.long]


def test_both_causes_are_named_the_second_by_the_stacking_weight_and_f_holds_the_truth(tmp_path):
    from bench_diagnose import true_f

    from friction_uq.discrepancy.diagnosed_f import quoted_of

    rng = np.random.default_rng(29)  # the study's stream: record 0 of the 1-D pairs
    cfg, edit, header, note = make_pair(PAIRS_1D[0], False, 0, rng)
    sim_seed = int(rng.integers(2**31))
    path = str(tmp_path / "pair0.h5")
    write(cfg, path, sim_seed, edit, header)
    prep, dg = analyse(path, load_priors(default_prior_path("I1")), seed=0, max_causes=MAX_CAUSES)
    assert [v.kind for v in dg.verdicts][:2] == ["named", "named"], [v.kind for v in dg.verdicts]
    doc = outcome.to_json(dg, dg.baseline.f_summary())
    assert doc["verdict"] == "named"
    assert [c["name"] for c in doc["causes"]] == ["clearance", "velocity_friction"], doc["causes"]
    assert doc["open_candidates"] == [] and doc["mixture"] is None
    # the second round's rivals: behind within 2 SE over the whole record; the pressure law decisively behind without
    # the blocks most in the velocity law's favour, the timing by neither reading: ruled out by the weight, and said so
    second = {e["name"]: e for e in doc["rounds"][0]}
    light = [e for e in second.values() if e.get("ruled_out_by_weight")]
    assert "channel_timing" in {e["name"] for e in light}
    assert all(e["weight"] < 0.1 for e in light)
    fits = {r.fit.variants[-1].mechanism.name: r.fit.elpd for r in dg.rounds[1]}
    drop = points_to_drop(len(fits["velocity_friction"].pointwise), 0.05)
    lead, lead_rest = (elpd_difference(fits["velocity_friction"], fits["pressure_friction"], drop=d) for d in (0, drop))
    assert not RULE.decisive(*lead) and RULE.decisive(*lead_rest), (lead, lead_rest)
    assert not second["pressure_friction"].get("ruled_out_by_weight")
    assert "was preferred to" in doc["sentence"] and "by the stacking weight" in doc["sentence"], doc["sentence"]
    # the clearance first: it moves f most, or (shifts within f's sd, diagnosis_words.ordered_steps) it was named first
    assert re.match(r"Causes found, (the one that moves f most first|in the order named \([^)]*\)): a radial gap",
                    doc["sentence"]), doc["sentence"]
    assert "Candidates, not a cause" not in doc["sentence"]
    fx = quoted_of(dg)  # the f to quote: the JSON's f, the output bars' calibration folded in
    truth = true_f(cfg, prep)
    assert fx["q05"] <= truth <= fx["q95"], (fx, truth)


def _study_record(sim: str, k: int, tmp_path):
    """Record ``k`` of the study's ``sim`` list, seed 29 (its stream replayed), diagnosed as the study does."""
    rng = np.random.default_rng(29)
    for name, pairs in (("1d", PAIRS_1D), ("axisymmetric", PAIRS_AXISYMMETRIC)):
        for j, pair in enumerate(pairs):
            cfg, edit, header, _ = make_pair(pair, name == "axisymmetric", j, rng)
            sim_seed = int(rng.integers(2**31))
            if (name, j) == (sim, k):
                path = str(tmp_path / f"{sim}-{k}.h5")
                write(cfg, path, sim_seed, edit, header)
                prep, dg = analyse(path, load_priors(default_prior_path("I1")), seed=k, max_causes=MAX_CAUSES)
                return cfg, prep, dg
    raise AssertionError(f"no record {sim}-{k}")


def test_a_candidate_fitted_in_turn_is_named_when_the_later_cause_separates_it_from_its_rivals(tmp_path):
    from friction_uq.discrepancy.rival_swaps import WITHOUT

    _, _, dg = _study_record("1d", 5, tmp_path)
    assert dg.verdicts[0].kind == "candidates", [v.kind for v in dg.verdicts]
    assert [v.mechanism.name for v in dg.named_causes] == ["dispersion", "clearance"]
    first = [sw for sw in dg.swaps if sw.round == 0]
    assert {sw.rival for sw in first} >= {WITHOUT} and all(sw.ruling is not None for sw in first), first
    assert next(sw for sw in first if sw.rival == WITHOUT).flagged is True
    doc = outcome.to_json(dg, dg.baseline.f_summary())
    assert doc["open_candidates"] == [] and doc["not_separable"] == []
    assert "dispersion was one of the candidates of its round" in doc["sentence"], doc["sentence"]


def test_a_candidate_the_whole_record_check_does_not_need_is_not_named(tmp_path):
    from friction_uq.discrepancy.rival_swaps import WITHOUT

    _, _, dg = _study_record("axisymmetric", 3, tmp_path)
    assert "zero_drift" in {v.mechanism.name for v in dg.causes}  # fitted in turn
    assert {v.mechanism.name for v in dg.named_causes} == {"slip_friction", "plug_friction"}
    without = [sw for sw in dg.swaps if sw.rival == WITHOUT]
    assert without and all(not sw.flagged for sw in without), dg.swaps
