"""Two hidden effects at once through every round of ``diagnose`` (slow: about 2 min): the first record of the
pairs study (``benchmarks/bench_pairs.py``, seed 29), a clearance with a velocity-weakening wall on the 1-D
simulation. The clearance is named in the first round; the second round finds the velocity law among candidates
the record does not tell apart (the pressure and slip laws, a channel's timing, an amplifier's bandwidth). The
record's verdict stays "named" with the clearance its cause, the candidates are listed as open and f comes from
their mixture; before, the open second round made the whole record "Candidates, not a cause" and dropped the
clearance."""

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


def test_a_cause_named_first_stays_named_when_a_second_rounds_candidates_stay_open(tmp_path):
    rng = np.random.default_rng(29)  # the study's stream: record 0 of the 1-D pairs
    cfg, edit, header, note = make_pair(PAIRS_1D[0], False, 0, rng)
    sim_seed = int(rng.integers(2**31))
    path = str(tmp_path / "pair0.h5")
    write(cfg, path, sim_seed, edit, header)
    prep, dg = analyse(path, load_priors(default_prior_path("I1")), seed=0, max_causes=MAX_CAUSES)
    assert [v.kind for v in dg.verdicts][:2] == ["named", "candidates"], [v.kind for v in dg.verdicts]
    doc = outcome.to_json(dg, dg.baseline.f_summary())
    assert doc["verdict"] == "named" and [c["name"] for c in doc["causes"]] == ["clearance"], doc["causes"]
    assert doc["cause"] == "clearance"
    assert "velocity_friction" in doc["open_candidates"] and doc["mixture"] is not None
    assert doc["fitted_in_turn"][0] == "clearance" and len(doc["fitted_in_turn"]) == 2
    assert doc["sentence"].startswith("Causes found, the one that moves f most first: a radial gap"), doc["sentence"]
    assert "A further cause this record does not tell apart: " in doc["sentence"]
    assert "Candidates, not a cause" not in doc["sentence"]
