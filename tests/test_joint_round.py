"""Two causes named together where neither alone explains the misfit (friction_uq.discrepancy.joint_round): the
rounds of ``diagnose`` on stand-in fits whose block ELPDs are set by hand."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest

from friction_uq.discrepancy import diagnose as dmod
from friction_uq.discrepancy import diagnosis_words, round_clauses
from friction_uq.discrepancy.block_loo import Elpd
from friction_uq.discrepancy.extended import Variant
from friction_uq.discrepancy.mechanisms import MECHANISMS
from friction_uq.discrepancy.outcome import named_together, pair_tried
from friction_uq.report.diagnose_pages import _ranking_axes
from friction_uq.report.style import figure
from stand_ins import StandInFit

N = 300
A_BLOCKS = np.arange(0, 100, 10)  # where the first effect's model gains alone (its fronts)
B_BLOCKS = np.arange(5, 105, 10)  # the second's


def _noise(seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(0.0, 0.3, N)


def _at(blocks, gain: float) -> np.ndarray:
    out = np.zeros(N)
    out[blocks] = gain
    return out


_Fit = StandInFit


class _Diagnoser:
    """A stand-in Diagnoser: each model's blocks by its label (``blocks``; a label not given: its reference's plus
    noise), f the same for all."""

    gauges = ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop")
    in_baseline = ()

    def __init__(self, blocks):
        self.blocks, self.made = blocks, []
        self.base = _Fit("baseline", (), Elpd(_noise(0), float("nan")), np.full(50, 0.05))

    def predictive(self, fit):
        return {}

    def resolved(self, fit):
        return fit

    def fit_many(self, jobs, workers=1, cut=True):
        out = []
        for variants, _, label in jobs:
            self.made.append(label)
            parent = "+".join(v.label for v in variants[:-1])
            ref = self.blocks.get(parent, self.base.elpd.pointwise) if parent else self.base.elpd.pointwise
            pts = self.blocks.get(label, ref + _noise(len(self.made)) * 0.1)
            out.append(_Fit(label, variants, Elpd(np.asarray(pts, float), float("nan")), np.full(50, 0.05)))
        return out


def _search(monkeypatch, blocks, flagged=(True, True)):
    """The rounds on ``blocks``; the whole-record check flags the rounds' references as ``flagged`` says, then no
    more."""
    flags = iter(flagged)
    monkeypatch.setattr(dmod, "compare_whole_record", lambda prep, predicted: None)
    monkeypatch.setattr(dmod, "decide", lambda comparison: SimpleNamespace(detected=next(flags, False)))
    monkeypatch.setattr(dmod, "candidates", lambda exclude=(), gauges=None: [
        Variant(MECHANISMS[m]) for m in ("dispersion", "clearance", "plug_friction") if m not in exclude])
    dg = _Diagnoser(blocks)
    st = dmod._search(dg, None, dmod._Search(dg.base, dg.base), max_causes=4, workers=1, seed=0,
                      say=lambda msg: None, t0=0.0)
    return dg, st


def _pair_blocks(second_round_rival=None):
    """Each effect's model alone gains 200 nats at its own ten blocks and nothing elsewhere (decisive, not spread:
    the round is unexplained); together they gain there and 1 nat on every block (spread)."""
    base = _noise(0)
    a, b = base + _at(A_BLOCKS, 200.0), base + _at(B_BLOCKS, 200.0)
    joint = base + _at(A_BLOCKS, 200.0) + _at(B_BLOCKS, 200.0) + 1.0
    out = {"dispersion": a, "clearance": b, "plug_friction": base + _noise(9) * 0.1,
           "dispersion+clearance": joint, "clearance+dispersion": joint}
    if second_round_rival is not None:
        out["dispersion+plug_friction"] = joint + second_round_rival
    return out


def _diagnosis(dg, st):
    return dmod.Diagnosis(baseline=dg.base, rounds=tuple(st.rounds), misfits=tuple(st.misfits),
                          causes=tuple(st.causes), not_separable=(), separate_by=None, final=st.reference,
                          verdicts=tuple(st.verdicts), pair_tried=st.pair_tried)


def test_two_effects_neither_of_which_explains_the_misfit_alone_are_named_together(monkeypatch):
    dg, st = _search(monkeypatch, _pair_blocks())
    first = st.verdicts[0]
    assert [c.passes for c in first.candidates[:2]] == [False, False]  # neither alone passes the rule
    assert [v.kind for v in st.verdicts] == ["named", "named", "none"]
    assert first.joint is not None and first.joint.partner == "clearance"
    assert [v.label for v in st.causes] == ["dispersion", "clearance"]
    dgn = _diagnosis(dg, st)
    assert [v.label for v in dgn.named_causes] == ["dispersion", "clearance"]
    said = round_clauses.joint_clause(dgn)
    assert said.startswith(" Named together: dispersion and clearance. In round 1 neither alone"), said
    d, se, dt, st_ = first.joint.against["clearance"]
    assert f"clearance alone by {d:.0f} +- {se:.0f} (" in said and f"and {dt:.0f} +- {st_:.0f} without" in said
    assert "round 2 named clearance on top of dispersion" in said
    d, se, _, _ = first.joint.against["reference"]  # the evidence that named them, not the first's alone
    assert diagnosis_words._evidence_said(dgn, "first cause", st.rounds[0][0]) == (
        f"the first two causes' evidence, fitted together, is {d:.0f} +- {se:.0f} nats")
    assert dg.made.count("dispersion+clearance") == 2  # the pair, then round 2's fit of the partner from its mode
    js = named_together(dgn)
    assert js[0]["round"] == 1 and js[0]["causes"] == ["dispersion", "clearance"]
    assert set(js[0]["against"]) == {"reference", "dispersion", "clearance"}
    tried = pair_tried(dgn)
    assert tried["named_together"] and tried["admitted"] and tried["refused"] is None
    assert tried["causes"] == ["dispersion", "clearance"]
    assert tried["against"] == js[0]["against"]
    assert round_clauses.pair_refused_clause(dgn) == ""
    fig, axes = figure("a ranking", nrows=1, ncols=2)  # the page's row for the pair, bold: named
    _ranking_axes(axes[0], dgn)
    rows = {t.get_text(): t.get_fontweight() for t in axes[0].get_yticklabels()}
    assert rows["1: dispersion + clearance together"] == "bold"
    plt.close(fig)


def test_a_pair_the_next_round_does_not_confirm_leaves_the_round_unexplained(monkeypatch):
    """With the first in the model, a rival explains the record as well as the second: round 2 does not name the
    partner, so round 1 is read as it was and nothing is named."""
    dg, st = _search(monkeypatch, _pair_blocks(second_round_rival=_noise(5) * 0.05))
    assert "dispersion+clearance" in dg.made and "dispersion+plug_friction" in dg.made  # admitted, round 2 fitted
    assert [v.kind for v in st.verdicts] == ["unexplained"]
    assert st.verdicts[0].joint is None and st.verdicts[0].named is None
    assert st.causes == [] and len(st.rounds) == 1 and len(st.misfits) == 1 and st.reference is st.base
    dgn = _diagnosis(dg, st)
    assert round_clauses.joint_clause(dgn) == ""
    # the trial is kept, with what round 2 found instead of the partner
    why = st.pair_tried.refused
    assert why == "round 2 did not name clearance on top of dispersion (clearance and its rivals stayed candidates)"
    assert round_clauses.pair_refused_clause(dgn) == (" Fitted together, dispersion and clearance pass the naming "
                                                      f"rule, but {why}.")
    js = pair_tried(dgn)
    assert js["admitted"] is True and js["named_together"] is False and js["refused"] == why


@pytest.mark.parametrize("gain", [1500.0, 1900.0])
def test_a_pair_that_does_not_rule_out_a_third_candidate_is_not_admitted(monkeypatch, gain):
    """A third mechanism, not decisive alone, gains at one block almost as much as the pair over the whole record:
    the pair does not rule it out by dELPD, so the round stays unexplained and no second round is fitted."""
    blocks = _pair_blocks()
    blocks["plug_friction"] = _noise(0) + _at([200], gain)
    dg, st = _search(monkeypatch, blocks)
    assert "dispersion+clearance" in dg.made and not st.verdicts[0].candidates[2].decisive
    assert [v.kind for v in st.verdicts] == ["unexplained"] and st.verdicts[0].joint is None
    assert not any(m.startswith("dispersion+") and m != "dispersion+clearance" for m in dg.made)
    assert st.pair_tried.refused == "does not rule out plug_friction" and not st.pair_tried.admitted
    # the ranking page draws the refused pair's row, not bold, beside the round's candidates
    fig, axes = figure("a ranking", nrows=1, ncols=2)
    _ranking_axes(axes[0], _diagnosis(dg, st))
    ticks = axes[0].get_yticklabels()
    assert ticks[-1].get_text() == "1: dispersion + clearance together (not named)"
    assert ticks[-1].get_fontweight() == "normal" and len(ticks) == 4
    plt.close(fig)
    # without it the same pair is named
    blocks["plug_friction"] = _noise(0) + _at([200], 0.0)
    _, st = _search(monkeypatch, blocks)
    assert [v.kind for v in st.verdicts][:2] == ["named", "named"]


def test_a_pair_carried_by_a_few_blocks_over_one_of_the_two_is_refused_and_says_why(monkeypatch):
    """Fitted together the two gain only at their own fronts: over the reference at twenty blocks, over the first
    alone at the second's ten, fewer than the 5 % of blocks the rule leaves out."""
    blocks = _pair_blocks()
    joint = _noise(0) + _at(A_BLOCKS, 200.0) + _at(B_BLOCKS, 200.0)
    blocks["dispersion+clearance"] = blocks["clearance+dispersion"] = joint
    dg, st = _search(monkeypatch, blocks)
    assert [v.kind for v in st.verdicts] == ["unexplained"] and st.causes == []
    why = st.pair_tried.refused
    assert why.startswith("their gain over dispersion alone is carried by a few blocks ("), why
    assert "without the 5 % most in its favour)" in why
    assert "; their gain over clearance alone is carried by a few blocks (" in why  # every comparison it fails
    assert "reference" not in why  # against the reference it passes: twenty blocks, more than the 5 % left out
    assert round_clauses.pair_refused_clause(_diagnosis(dg, st)).startswith(
        " Fitted together, dispersion and clearance do not explain it either: their gain over dispersion alone")


def test_a_pair_that_adds_nothing_to_the_first_alone_is_refused_as_not_decisive_against_it(monkeypatch):
    blocks = _pair_blocks()
    blocks["dispersion+clearance"] = blocks["clearance+dispersion"] = blocks["dispersion"] + _noise(7) * 1e-3
    _, st = _search(monkeypatch, blocks)
    why = st.pair_tried.refused
    assert why.startswith("their gain over the round's reference model is carried by a few blocks ("), why
    assert "; not decisive against dispersion alone (0 +- 0 nats); not decisive against clearance alone (" in why


def test_a_single_cause_that_passes_alone_is_named_without_a_joint_fit(monkeypatch):
    base = _noise(0)
    dg, st = _search(monkeypatch, {"dispersion": base + 1.0, "clearance": base + _noise(3) * 0.1})
    assert st.verdicts[0].kind == "named" and st.verdicts[0].joint is None
    assert dg.made.count("dispersion+clearance") == 1  # as round 2's candidate only
    assert [v.label for v in st.causes] == ["dispersion"]


def test_no_pair_is_tried_where_no_next_round_could_name_the_second(monkeypatch):
    monkeypatch.setattr(dmod, "compare_whole_record", lambda prep, predicted: None)
    monkeypatch.setattr(dmod, "decide", lambda comparison: SimpleNamespace(detected=True))
    monkeypatch.setattr(dmod, "candidates", lambda exclude=(), gauges=None: [
        Variant(MECHANISMS[m]) for m in ("dispersion", "clearance", "plug_friction") if m not in exclude])
    dg = _Diagnoser(_pair_blocks())
    st = dmod._search(dg, None, dmod._Search(dg.base, dg.base), max_causes=1, workers=1, seed=0,
                      say=lambda msg: None, t0=0.0)
    assert [v.kind for v in st.verdicts] == ["unexplained"] and "dispersion+clearance" not in dg.made


def test_two_friction_laws_are_never_paired(monkeypatch):
    """One model holds one friction law: with the velocity and the slip law leading, the pair is the velocity law and
    the next mechanism (a joint model of two laws cannot be built, and no later round could name the second)."""
    blocks = _pair_blocks()
    blocks = {"velocity_friction": blocks["dispersion"], "slip_friction": blocks["dispersion"] + 0.01,
              "clearance": blocks["clearance"] - 1e-3, "velocity_friction+clearance": blocks["dispersion+clearance"]}
    monkeypatch.setattr(dmod, "compare_whole_record", lambda prep, predicted: None)
    flags = iter([True, True])
    monkeypatch.setattr(dmod, "decide", lambda comparison: SimpleNamespace(detected=next(flags, False)))
    monkeypatch.setattr(dmod, "candidates", lambda exclude=(), gauges=None: [
        Variant(MECHANISMS[m]) for m in ("velocity_friction", "slip_friction", "clearance")
        if m not in exclude and not (m.endswith("_friction") and any(e.endswith("_friction") for e in exclude))])
    dg = _Diagnoser(blocks)
    st = dmod._search(dg, None, dmod._Search(dg.base, dg.base), max_causes=4, workers=1, seed=0,
                      say=lambda msg: None, t0=0.0)
    assert [r.fit.label for r in st.rounds[0]][:2] == ["slip_friction", "velocity_friction"]
    assert not any("slip_friction+velocity" in m or "velocity_friction+slip" in m for m in dg.made)
    assert "slip_friction+clearance" in dg.made  # the leading law with the next mechanism that one model can hold
