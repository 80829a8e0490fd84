"""The one decision rule and the one standard error of an ELPD difference (friction_uq.stats.decision)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from friction_uq.campaign.laws import Elpd, decisive as law_decisive, difference as law_difference
from friction_uq.discrepancy.diagnose import beyond
from friction_uq.discrepancy.elpd import Elpd as RecordElpd, elpd_difference
from friction_uq.shpb.diagnose import decisive as balance_decisive
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


def test_every_consumer_reads_the_same_rule():
    """diagnose, the two-bar diagnosis and the campaign give the rule's answer on a grid of (d, se)."""
    grid = [(d, se) for d in (0.5, 3.9, 4.1, 8.0, 30.0, 60.0, 500.0) for se in (0.1, 1.0, 3.0, 10.0, 45.0, 400.0)]
    for d, se in grid:
        assert beyond(d, se, None) == RULE.decisive(d, se)
        assert beyond(d, se, 40.0) == RULE.decisive(d, se, strong=40.0)
        assert balance_decisive(d, se) == RULE.decisive(d, se)
        assert law_decisive(d, se, 10) == RULE.decisive(d, se, n=10)


def test_every_consumer_computes_the_same_standard_error():
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=12), rng.normal(size=12)
    want = paired_difference(a, b)
    law = law_difference(Elpd("a", a.sum(), 0.0, a, np.zeros(12), 0), Elpd("b", b.sum(), 0.0, b, np.zeros(12), 0))
    rec = elpd_difference(RecordElpd(a, 0.0), RecordElpd(b, 0.0))
    assert law == pytest.approx(want) and rec == pytest.approx(want)


def test_a_rule_is_a_value():
    assert DecisionRule() == RULE and DecisionRule(min_delpd=6.0).decisive(5.0, 0.1) is False
