"""The one decision rule and the one standard error of an ELPD difference (friction_uq.stats.decision)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from friction_uq.campaigns.analysis import supported_laws
from friction_uq.campaigns.law_comparison import simplest_supported
from friction_uq.campaigns.flags import setup_flags
from friction_uq.campaigns.laws import LAWS, Elpd, best_law, rank
from friction_uq.discrepancy.diagnose import Ranked
from friction_uq.discrepancy.block_loo import Elpd as RecordElpd, elpd_difference
from friction_uq.shpb.balance_diagnosis import Candidate
from friction_uq.stats import RULE, DecisionRule, paired_difference


def test_paired_difference_is_the_sum_and_the_sample_sd_of_the_sum():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=25), rng.normal(size=25)
    d, se = paired_difference(a, b)
    assert d == pytest.approx(np.sum(a - b))
    assert se == pytest.approx(np.sqrt(25) * np.std(a - b, ddof=1))


def test_the_factor_is_students_t_over_n_paired_values_and_two_otherwise():
    assert RULE.factor() == 2.0
    assert RULE.factor(10) == pytest.approx(stats.t.ppf(0.975, 9))
    assert RULE.factor(1) == 2.0


GRID = [(d, se) for d in (0.5, 3.9, 4.1, 8.0, 30.0, 60.0, 500.0) for se in (0.1, 1.0, 3.0, 10.0, 45.0, 400.0)]


def _pointwise(d: float, se: float, n: int) -> np.ndarray:
    """n paired differences that sum to d with standard error se (sqrt(n) times their sample sd)."""
    z = np.linspace(-1.0, 1.0, n)
    return d / n + z / np.std(z, ddof=1) * se / np.sqrt(n)


def test_every_consumer_reads_the_same_rule():
    """diagnose ranking a mechanism, the two-bar selection step and the campaign's law choice give the rule's
    answer on a grid of (d, se)."""
    for d, se in GRID:
        assert Ranked(None, d, se, misfit=False).decisive == RULE.decisive(d, se)
        assert Ranked(None, d, se, misfit=True).decisive == RULE.decisive(d, se)  # no one-SE route after a misfit
        assert Candidate("gauge_gain", None, d, se).decisive == RULE.decisive(d, se)
        rows = [{"model": "velocity", "d_elpd": 0.0, "d_se": 0.0, "n_tests": 10},
                {"model": "constant", "d_elpd": d, "d_se": se, "n_tests": 10}]
        assert (best_law(rows, LAWS) == "velocity") == RULE.decisive(d, se, n=10)
        # the ELPD rule decides alone where the weights could not rule constant out: it has a share of them, or
        # the ranking does not say how far behind it is without its worst test
        assert (supported_laws({"constant": 0.1, "velocity": 0.9}, rows) == ["velocity"]) == RULE.decisive(d, se, n=10)
        assert (supported_laws({"constant": 0.0, "velocity": 1.0}, rows) == ["velocity"]) == RULE.decisive(d, se, n=10)
        assert (simplest_supported({"constant": 0.0, "velocity": 1.0}, rows) == "velocity") == RULE.decisive(d, se, n=10)
        # the weight route opens with the difference without the best test kept, for the verdict's named set only:
        # set-ups are still flagged under the simplest law the ELPD rule leaves
        rest = [r | {"d_elpd_rest": r["d_elpd"] - 1.0} for r in rows]
        by_weight = RULE.decisive(d, se, n=10) or d - 1.0 > RULE.min_delpd
        assert (supported_laws({"constant": 0.0, "velocity": 1.0}, rest) == ["velocity"]) == by_weight
        assert (simplest_supported({"constant": 0.0, "velocity": 1.0}, rest) == "velocity") == RULE.decisive(d, se, n=10)


def test_the_campaign_flags_a_setup_by_the_rule():
    """A set-up's offset model flagged exactly when its paired dELPD over the shared law decides over the tests."""
    base = Elpd("constant", 0.0, 0.0, np.zeros(10), np.zeros(10), 0)
    for d, se in GRID:
        off = Elpd("constant + offset B", d, 0.0, _pointwise(d, se, 10), np.zeros(10), 0)
        want = RULE.decisive(*paired_difference(off.pointwise, base.pointwise), n=10)
        flags = setup_flags(base, {"B": (off, {"q50": 0.1})}, ["A", "B", "C"], {})
        assert (len(flags) == 1) == want


def test_every_consumer_computes_the_same_standard_error():
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=12), rng.normal(size=12)
    want = paired_difference(a, b)
    top = Elpd("a", a.sum() + 100.0, 0.0, a, np.zeros(12), 0)  # ranked first
    law = [(r["d_elpd"], r["d_se"]) for r in rank([top, Elpd("b", b.sum(), 0.0, b, np.zeros(12), 0)])][1]
    rec = elpd_difference(RecordElpd(a, 0.0), RecordElpd(b, 0.0))
    assert law == pytest.approx(want) and rec == pytest.approx(want)


def test_a_rule_is_a_value():
    assert DecisionRule() == RULE and DecisionRule(min_delpd=6.0).decisive(5.0, 0.1) is False
