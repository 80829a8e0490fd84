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
from friction_uq.campaigns.warned import pooled_without_warned, warned, warned_statement
from friction_uq.prior_loader import PRIORS_DIR, load_priors

PRIOR = str(PRIORS_DIR / "I1.toml")
Z = stats.norm.ppf((np.arange(1000) + 0.5) / 1000)


def _test(label: str, f: float, warnings=(), kinds=(), *, diagnosed: float | None = None) -> RecordPosterior:
    """A test whose stationary f reads ``f``; ``diagnosed``: f under its diagnosed model (drawn under the prior
    file's f prior, which the pooling divides out)."""
    x = f + 0.002 * Z
    nu = np.full(1000, 0.4)
    t = RecordPosterior(label, "A", x, x * nu / (1 - nu), nu, np.full(1000, 1e8),
                        {"mean": 9.0, "sd": 0.1, "q05": 9.0, "q50": 9.0, "q95": 9.0}, PRIOR,
                        warnings=tuple(warnings), warning_kinds=tuple(kinds))
    if diagnosed is not None:
        t.f_model = diagnosed + 0.002 * Z
        t.f_model_log_prior = np.asarray(load_priors(PRIOR)["f"].logpdf(t.f_model), float)
    return t


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
    assert ca.pooled_without_warned is None and warned_statement(tests, ca.pooled["f"], None) is None
    few = tests[:1] + [_test("A A-04", 0.07, ["x"]), _test("A A-05", 0.07, ["y"])]
    pooled_few = analyse_tests(few, tally_causes([]), seed=1).pooled["f"]
    alone = pooled_without_warned(few, pooled_few)
    said = warned_statement(few, pooled_few, alone)
    assert alone.refused and said.endswith(f"without them: {alone.refused}")
    every = [_test("A A-01", 0.05, ["x"]), _test("A A-02", 0.05, ["y", "z"])]
    assert warned_statement(every, None, pooled_without_warned(every, alone)).startswith(
        "every test's run warned (how many warnings: A A-01 (1), A A-02 (2);")


def test_a_records_result_carries_its_runs_warnings(tmp_path):
    doc = {"f_stationary": {}, "converged": True, "warnings": ["The tube's hoop gauge and the prior file disagree"],
           "warning_kinds": ["hoop_or_prior"]}
    for k in ("f", "kappa", "nu", "V", "p_mean"):
        doc[k] = {s: 1.0 for s in ("mean", "sd", "q05", "q50", "q95")}
    doc["f_stationary"] = doc["f"]
    taken = _from_run_json(doc)
    assert taken["warnings"] == doc["warnings"]
    r = RecordResult(path="A-03.h5", status="done", campaign="A", test_id="A-03", **taken)
    back = read_result(write_result(r, tmp_path / "A_A-03.result.json"))
    assert back.warnings == doc["warnings"] and back.warning_kinds == doc["warning_kinds"]
    text = summary_text(json.loads(json.dumps(campaign_doc([r], None, seed=1, settings={}))))
    assert text.splitlines()[0].split()[-2:] == ["warnings", "message"]
    assert text.splitlines()[1].split()[-1] == "1"


def test_a_diagnosed_campaign_counts_a_misfit_whose_causes_were_named_as_answered():
    """Under --diagnose a test whose misfit's causes were named keeps the misfit's warning (quote f under them).
    The campaign pools that f, so the warning is answered there: "without the warned tests" kept such tests out and
    rested on the tests with no misfit at all. A warning of another kind, or the same misfit pooled through the
    stationary f (a hoop gauge that disagrees with nu's prior), still counts."""
    misfit = ["The simulated test misses ... `diagnose` names clearance: f under them is ..."]
    tests = [_test("A A-01", 0.05, diagnosed=0.05), _test("A A-02", 0.05, diagnosed=0.05),
             _test("A A-03", 0.04, misfit, ["misfit_diagnosed"], diagnosed=0.05),
             _test("A A-04", 0.07, ["The force ratio is not stationary ..."], ["stationarity"], diagnosed=0.07)]
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    assert ca.pooled["f"].basis == "diagnosed"
    assert ca.pooled_without_warned.tests == ["A A-01", "A A-02", "A A-03"]
    said = [s for s in campaign_doc([], ca, seed=1, settings={})["statements"] if "warned" in s]
    assert len(said) == 1 and said[0].startswith("tests whose runs warned (how many warnings: A A-04 (1); "), said
    assert "1 test (A A-03) warned only of a misfit whose causes diagnose named" in said[0]
    tests[2].hoop_disagrees = True  # its stationary readings are pooled, not f under the causes named
    assert [t.label for t in warned(tests, "diagnosed")] == ["A A-03", "A A-04"]
    stationary = [_test("A A-03", 0.04, misfit, ["misfit_diagnosed"])]  # a campaign without --diagnose's basis
    assert warned(stationary, "stationary") == stationary
    unlabelled = [_test("A A-03", 0.04, misfit, diagnosed=0.05)]  # no kinds (a hand-made result): counted
    assert warned(unlabelled, "diagnosed") == unlabelled


def test_a_misfits_kind_says_whether_diagnose_named_its_causes():
    from types import SimpleNamespace

    from friction_uq.record_run.warnings import WARNING_KINDS, misfit_kind

    def dg(causes=(), mixture_of=None):
        final = SimpleNamespace(label="baseline+clearance")
        return SimpleNamespace(causes=causes, mixture_of=mixture_of, mixture_f=None if mixture_of is None else Z,
                               mixture_weights={"baseline+clearance": 0.5, "baseline+clearance+dispersion": 0.5},
                               final=final, rounds=[[]])

    assert misfit_kind(None) == "misfit"  # not diagnosed
    assert misfit_kind(dg()) == "misfit"  # unexplained or none: nothing named
    assert misfit_kind(dg(("clearance",))) == "misfit_diagnosed"  # "f under them ... is the f to quote"
    # f from a stacking mixture, "quote that, with this warning": a candidate fitted in turn whose rivals stay
    # open, a cause named beside open rivals or beside further causes the record leans to
    for mixed in ("candidates", "rivals", "further", "superfluous"):
        assert misfit_kind(dg(("clearance",), mixed)) == "misfit", mixed
    assert {"misfit", "misfit_diagnosed", "gauge", "gauge_unchecked", "equilibrium"} <= set(WARNING_KINDS)


def test_the_tests_spared_are_said_even_when_no_other_test_warned_and_counts_say_of_how_many():
    misfit = ["The simulated test misses ... `diagnose` names clearance: f under them is ..."]
    tests = [_test("A A-01", 0.05, diagnosed=0.05), _test("A A-02", 0.05, diagnosed=0.05),
             _test("A A-03", 0.05, misfit, ["misfit_diagnosed"], diagnosed=0.05)]
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    assert ca.pooled_without_warned is None
    said = warned_statement(tests, ca.pooled["f"], None)
    assert said == ("1 test (A A-03) warned only of a misfit whose causes diagnose named, and its f under them is "
                    "what is pooled; no other test's run warned")
    tests[1] = _test("A A-02", 0.05, misfit + ["The force ratio is not stationary ..."],
                     ["misfit_diagnosed", "stationarity"], diagnosed=0.05)
    assert "(how many warnings: A A-02 (1 of 2);" in warned_statement(tests, ca.pooled["f"], None)
