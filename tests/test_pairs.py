"""Two hidden effects at once through every round of ``diagnose`` (slow: about 2 min): the first record of the
pairs study (``benchmarks/bench_pairs.py``, seed 29), a clearance with a velocity-weakening wall on the 1-D
simulation. The clearance is named in the first round. In the second the velocity law leads the pressure and slip
laws, a channel's timing and an amplifier's bandwidth by tens of nats over the whole record and holds 0.96 of the
stacking weight, but within 2 SE of them: before the weight route (docs/methods.md) the round was candidates and
only the clearance was named. Now both are, and f's interval holds the truth. (That a cause named first stays
named when a later round's candidates stay open is tested on constructed verdicts in tests/test_diagnose.py.)"""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

from friction_uq.discrepancy import outcome
from friction_uq.discrepancy.diagnose import MAX_CAUSES
from friction_uq.priors import default_prior_path, load_priors

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
from bench_diagnose import analyse  # noqa: E402
from bench_pairs import PAIRS_1D, make_pair  # noqa: E402
from verdict_records import write  # noqa: E402

pytestmark = pytest.mark.slow


def test_both_causes_are_named_the_second_by_the_stacking_weight_and_f_holds_the_truth(tmp_path):
    from bench_diagnose import true_f

    from friction_uq.discrepancy.diagnosis_words import quoted_of

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
    # the second round's rivals: behind within 2 SE, ruled out by the weight route, and said so
    second = {e["name"]: e for e in doc["rounds"][0]}
    light = [e for e in second.values() if e.get("ruled_out_by_weight")]
    assert "pressure_friction" in {e["name"] for e in light}
    assert all(e["weight"] < 0.1 for e in light)
    assert "was preferred to" in doc["sentence"] and "by the stacking weight" in doc["sentence"], doc["sentence"]
    assert doc["sentence"].startswith("Causes found, the one that moves f most first: a radial gap"), doc["sentence"]
    assert "Candidates, not a cause" not in doc["sentence"]
    fx = quoted_of(dg)  # the f to quote: the JSON's f, the output bars' calibration folded in
    truth = true_f(cfg, prep)
    assert fx["q05"] <= truth <= fx["q95"], (fx, truth)
