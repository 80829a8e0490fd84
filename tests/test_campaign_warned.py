"""A campaign lists the tests whose runs warned and pools f without them beside the pooled f
(friction_uq.campaigns.warned): the pooled f held every test with nothing said of the warnings their runs gave."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import stats

from friction_uq.campaigns import RecordResult
from friction_uq.campaigns.analysis import RecordPosterior, analyse_tests
from friction_uq.campaigns.flags import tally_causes
from friction_uq.campaigns.job import _from_run_json, read_result, write_result
from friction_uq.campaigns.outputs import campaign_doc, summary_text
from friction_uq.campaigns.warned import pooled_without_warned, warned_statement
from friction_uq.prior_loader import PRIORS_DIR

PRIOR = str(PRIORS_DIR / "I1.toml")
Z = stats.norm.ppf((np.arange(1000) + 0.5) / 1000)


def _test(label: str, f: float, warnings=()) -> RecordPosterior:
    x = f + 0.002 * Z
    nu = np.full(1000, 0.4)
    return RecordPosterior(label, "A", x, x * nu / (1 - nu), nu, np.full(1000, 1e8),
                           {"mean": 9.0, "sd": 0.1, "q05": 9.0, "q50": 9.0, "q95": 9.0}, PRIOR,
                           warnings=tuple(warnings))


def test_the_pooled_f_without_the_warned_tests_is_said_beside_it():
    """Two sound tests at 0.050 and two warned ones at 0.070 (a stick-slip's or a misfit's bias; four tests, below
    the law comparison's five): the pooled f holds them all; without them it is the sound tests' 0.050, and the
    statement names the warned tests."""
    tests = [_test(f"A A-0{k}", 0.050) for k in range(1, 3)]
    tests += [_test("A A-04", 0.070, ["The force ratio is not stationary ..."]),
              _test("A A-05", 0.070, ["a", "b"])]
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    allf, sound = ca.pooled["f"], ca.pooled_without_warned
    assert sound is not None and sound.tests == ["A A-01", "A A-02"] and sound.basis == allf.basis
    assert sound.mu["q95"] < allf.mu["q50"] and sound.mu["q50"] == pytest.approx(0.050, abs=0.001)
    said = [s for s in campaign_doc([], ca, seed=1, settings={})["statements"] if "warning" in s]
    assert len(said) == 1 and said[0].startswith("tests whose runs warned (how many warnings: A A-04 (1), A A-05 (2); "
                                                 "each run's JSON"), said
    assert f"pooled f of the stationary analysis without them: population mean {sound.mu['q50']:.4g}" in said[0]


def test_nothing_is_said_when_no_run_warned_and_too_few_tests_left_are_said_so():
    tests = [_test(f"A A-0{k}", 0.05) for k in range(1, 4)]
    assert pooled_without_warned(tests, None) is None
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    assert ca.pooled_without_warned is None and warned_statement(tests, None) is None
    few = tests[:1] + [_test("A A-04", 0.07, ["x"]), _test("A A-05", 0.07, ["y"])]
    alone = pooled_without_warned(few, analyse_tests(few, tally_causes([]), seed=1).pooled["f"])
    said = warned_statement(few, alone)
    assert alone.refused and said.endswith(f"without them: {alone.refused}")
    every = [_test("A A-01", 0.05, ["x"]), _test("A A-02", 0.05, ["y", "z"])]
    assert warned_statement(every, pooled_without_warned(every, alone)).startswith(
        "every test's run warned (how many warnings: A A-01 (1), A A-02 (2);")


def test_a_records_result_carries_its_runs_warnings(tmp_path):
    doc = {"f_stationary": {}, "converged": True, "warnings": ["The tube's hoop gauge and the prior file disagree"]}
    for k in ("f", "kappa", "nu", "V", "p_mean"):
        doc[k] = {s: 1.0 for s in ("mean", "sd", "q05", "q50", "q95")}
    doc["f_stationary"] = doc["f"]
    taken = _from_run_json(doc)
    assert taken["warnings"] == doc["warnings"]
    r = RecordResult(path="A-03.h5", status="done", campaign="A", test_id="A-03", **taken)
    assert read_result(write_result(r, tmp_path / "A_A-03.result.json")).warnings == doc["warnings"]
    text = summary_text(json.loads(json.dumps(campaign_doc([r], None, seed=1, settings={}))))
    assert text.splitlines()[0].split()[-2:] == ["warnings", "message"]
    assert text.splitlines()[1].split()[-1] == "1"
