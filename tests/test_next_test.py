"""The expected information of one more test on which law holds (friction_uq.campaigns.next_test_choice)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from friction_uq.campaigns.next_test_choice import Candidate, advice, information


def test_laws_that_predict_alike_gain_nothing_and_laws_far_apart_gain_the_weights_entropy():
    w = np.array([0.5, 0.5])
    same = information(np.array([1.0, 1.0]), np.array([0.01, 0.01]), w)
    apart = information(np.array([1.0, 2.0]), np.array([1e-4, 1e-4]), w)
    assert same == pytest.approx(0.0, abs=1e-6)
    assert apart == pytest.approx(math.log(2.0), abs=1e-3)  # a test that settles the question
    # unequal weights: at most their entropy
    w2 = np.array([0.9, 0.1])
    assert information(np.array([1.0, 2.0]), np.array([1e-4, 1e-4]), w2) == pytest.approx(
        -(0.9 * math.log(0.9) + 0.1 * math.log(0.1)), abs=1e-3)
    # in between: partly overlapping predictions bring part of it, more as they separate
    mid = [information(np.array([1.0, 1.0 + d]), np.array([0.01, 0.01]), w) for d in (0.05, 0.1, 0.2)]
    assert 0.0 < mid[0] < mid[1] < mid[2] < math.log(2.0)


def test_two_outcomes_independent_given_the_law_add_what_the_second_tells():
    """Slip and velocity predict the same level at every test and differ in the change across the window: the
    2-D information is the second outcome's alone; a second outcome the laws predict alike adds nothing."""
    w = np.array([0.5, 0.5])
    level_only = information(np.array([[1.0, 0.0], [1.0, 0.0]]), np.array([[0.01, 1e-4], [0.01, 1e-4]]), w)
    change_apart = information(np.array([[1.0, 0.0], [1.0, -0.1]]), np.array([[0.01, 1e-4], [0.01, 1e-4]]), w)
    assert level_only == pytest.approx(0.0, abs=1e-4)
    assert change_apart == pytest.approx(math.log(2.0), abs=2e-3)
    one = information(np.array([1.0, 1.1]), np.array([0.01, 0.01]), w)
    two = information(np.array([[1.0, 0.0], [1.1, 0.0]]), np.array([[0.01, 0.01], [0.01, 0.01]]), w)
    assert two == pytest.approx(one, abs=2e-3)  # the grid's resolution


def test_the_advice_names_the_best_candidate():
    cands = [Candidate("B", 12.0, 1.4e8, 0.41), Candidate("A", 6.0, 5e7, 0.02)]
    text = advice(cands, {"velocity": 0.5, "pressure": 0.45, "constant": 0.05})
    assert text.startswith("the most informative next test: set-up B at a sliding speed of 12.0 m/s")
    assert "0.41 nats" in text and advice([], {}) is None


def test_the_laws_the_verdict_names_are_asked_about_equally_whatever_stacking_says():
    """Stacking may give 0.99 to one of two laws whose ELPDs are not decisively apart; the verdict names both, and
    the advice must be about both (equal weights), not about nothing."""
    from friction_uq.campaigns.next_test_choice import _in_play

    weights = {"velocity": 0.99, "pressure": 0.001, "pressure+velocity": 0.009, "constant": 0.0}
    assert _in_play(weights, None) == ["velocity"]
    assert _in_play(weights, ["pressure", "velocity"]) == ["pressure", "velocity"]
    cands = [Candidate("B", 12.0, 1.4e8, 0.3)]
    assert "which of pressure, velocity holds" in advice(cands, weights, ["pressure", "velocity"])
