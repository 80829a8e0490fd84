"""The candidate fitted in turn against its round's open rivals, with the later causes in the model
(friction_uq.discrepancy.rival_swaps): which swaps are fitted, and which rivals the final model rules out."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from friction_uq.discrepancy.candidates_mixture import named_causes, unresolved_rounds
from friction_uq.discrepancy.block_loo import Elpd, elpd_difference
from friction_uq.discrepancy.extended import Variant
from friction_uq.discrepancy.mechanisms import MECHANISMS
from friction_uq.discrepancy.rival_swaps import WITHOUT, check_swaps, swap_jobs, swap_start
from friction_uq.discrepancy.verdict import Candidate, NamingRule, Verdict

N = 200


def _fit(label, blocks):
    variants = tuple(Variant(MECHANISMS[x]) for x in label.split("+"))
    return SimpleNamespace(label=label, variants=variants, elpd=Elpd(np.asarray(blocks, float), float("nan")),
                           f_effective=np.full(50, 0.05), fit=SimpleNamespace(mode={"f": 0.05, "nu": 0.4}))


def _cand(label):
    return Candidate(label, label.split("+")[-1], None, 100.0, 10.0, 90.0, 10.0, 0.3, True, True)


def _record(first_rivals=("channel_timing", "bandwidth"), second="clearance", first="dispersion"):
    """Round 1: candidates, ``first`` fitted in turn, ``first_rivals`` open; round 2: ``second`` named."""
    noise = np.random.default_rng(0).normal(0.0, 0.3, N)
    r1 = [_fit(x, noise) for x in (first, *first_rivals)]
    r2 = [_fit(f"{first}+{second}", noise + 1.0)]
    v1 = Verdict("candidates", tuple(_cand(f.label) for f in r1), {"reference": 0.0} | {f.label: 0.3 for f in r1},
                 named=first, rivals=tuple(first_rivals))
    v2 = Verdict("named", (_cand(r2[0].label),), {"reference": 0.0, r2[0].label: 1.0}, named=r2[0].label)
    rounds = [tuple(SimpleNamespace(fit=f) for f in r1), tuple(SimpleNamespace(fit=f) for f in r2)]
    causes = [Variant(MECHANISMS[first]), Variant(MECHANISMS[second])]
    return causes, [v1, v2], rounds, r2[0]


def test_each_open_rival_is_swapped_in_for_the_candidate_with_the_later_cause_kept():
    causes, verdicts, rounds, _ = _record()
    jobs = swap_jobs(causes, verdicts, rounds)
    assert [(k, label, tuple(v.label for v in variants)) for k, label, variants in jobs] == [
        (0, WITHOUT, ("clearance",)),  # the candidate must still earn its place
        (0, "channel_timing", ("channel_timing", "clearance")), (0, "bandwidth", ("bandwidth", "clearance"))]
    # without a later cause the swap is the round's own comparison: nothing to ask
    assert swap_jobs(causes[:1], verdicts[:1], rounds[:1]) == []
    # a second friction law cannot join the model beside the one named later: it stands in for the candidate and
    # that law together
    causes, verdicts, rounds, _ = _record(first_rivals=("velocity_friction",), first="clearance",
                                          second="pressure_friction")
    assert [(k, label, tuple(v.label for v in variants)) for k, label, variants in swap_jobs(causes, verdicts, rounds)
            ] == [(0, WITHOUT, ("pressure_friction",)), (0, "velocity_friction", ("velocity_friction",))]
    # the last cause's round: its swaps would be its own comparison again, with no later cause in the model
    causes, verdicts, rounds, final = _record()
    rival = _fit("dispersion+bandwidth", final.elpd.pointwise)
    last = Verdict("candidates", verdicts[1].candidates + (_cand(rival.label),), verdicts[1].weights,
                   named=verdicts[1].named, rivals=(rival.label,))
    rounds = [rounds[0], rounds[1] + (SimpleNamespace(fit=rival),)]
    assert swap_jobs(causes, [replace(verdicts[0], kind="named", rivals=()), last], rounds) == []
    assert swap_jobs(causes + [Variant(MECHANISMS["plug_friction"])],  # with a cause after it, it is asked
                     [replace(verdicts[0], kind="named", rivals=()), last, verdicts[1]], rounds + [()])[0][:2] == (
        1, WITHOUT)


def test_a_second_friction_law_stands_in_for_the_candidate_and_the_later_law_and_keeps_the_round_open_if_it_can():
    """Round 1: clearance fitted in turn, the velocity law and a bandwidth open; round 2: the pressure law named. The
    velocity law is swapped in for the clearance and the pressure law at once. Ruled out, the round is resolved and
    the clearance named (before, such a rival could not be asked and kept the round open); not ruled out, it keeps
    the round open whatever the bandwidth does."""
    causes, verdicts, rounds, final = _record(first_rivals=("velocity_friction", "bandwidth"), first="clearance",
                                              second="pressure_friction")
    good = np.asarray(final.elpd.pointwise)
    for law, resolved, open_rounds in ((good - 1.0, ("velocity_friction", "bandwidth"), ()),
                                       (good, ("bandwidth",), (0,))):
        fitter = _Fitter({"pressure_friction": good - 1.0, "bandwidth": good - 1.0, "velocity_friction": law})
        out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                    flagged=lambda fit: True)
        assert fitter.asked == ["pressure_friction", "velocity_friction", "bandwidth+pressure_friction"]
        assert [s.rival for s in swaps] == [WITHOUT, "velocity_friction", "bandwidth"]
        assert out[0].resolved == resolved and unresolved_rounds(causes, out) == open_rounds
        named = [v.mechanism.name for v in named_causes(causes, out)]
        assert named == (["clearance", "pressure_friction"] if not open_rounds else ["pressure_friction"])


def test_a_law_swapped_in_for_another_starts_from_its_own_fit_and_its_round_may_be_superfluous():
    """f and a law's parameters mean other things under another law: the velocity law swapped in for the clearance and
    the pressure law starts from its own round-1 fit; other swaps from the final model's mode. And where the model
    without the candidate is ruled out but not flagged by the check, with a rival left open that could stand in, the
    candidate is superfluous (the gate of rounds with an open rival)."""
    causes, verdicts, rounds, final = _record(first_rivals=("velocity_friction", "bandwidth"), first="clearance",
                                              second="pressure_friction")
    rounds[0][1].fit.fit = SimpleNamespace(mode={"f": 0.07, "nu": 0.41, "f_s": 0.09, "v_c": 3.0})
    final.fit = SimpleNamespace(mode={"f": 0.05, "nu": 0.4, "gap": 1e-6, "p0": 1e8})
    jobs = swap_jobs(causes, verdicts, rounds)
    starts = {label: swap_start(final, rounds, causes, k, label, v) for k, label, v in jobs}
    assert starts[WITHOUT] == starts["bandwidth"] == final.fit.mode
    assert starts["velocity_friction"] == {"f": 0.07, "nu": 0.4, "gap": 1e-6, "p0": 1e8, "f_s": 0.09, "v_c": 3.0}
    good = np.asarray(final.elpd.pointwise)
    fitter = _Fitter({"pressure_friction": good - 1.0, "bandwidth": good, "velocity_friction": good})
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                flagged=lambda fit: False)
    assert swaps[0].ruling == "elpd" and swaps[0].flagged is False and out[0].superfluous and out[0].resolved == ()
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["pressure_friction"]


def test_the_weight_never_rules_out_a_model_among_those_that_carry_90_percent_of_it():
    """The naming rule's guard, which the swaps take through the same method: 91 nats ahead but within 2 SE (two
    blocks carry 80 of them), still ahead without those blocks but within 2 SE there too; a light rival is ruled out
    by the weight, one the stacking carries is not."""
    other = np.zeros(N)
    best = other + 0.05 + np.random.default_rng(8).normal(0.0, 0.3, N)
    best[:2] += 40.0
    for drop_ in (0, 10):
        d, se = elpd_difference(Elpd(best, float("nan")), Elpd(other, float("nan")), drop=drop_)
        assert 4 < d < 2 * se
    rule, drop = NamingRule(), 10
    a, b = Elpd(best, float("nan")), Elpd(other, float("nan"))
    assert rule.ruling(a, b, weight=0.05, drop=drop) == "weight"
    assert rule.ruling(a, b, weight=0.05, drop=drop, carried=True) is None


def _as_is(model):
    """The model as fitted (no cut posterior): what ``_mixture_after_causes`` draws f from here."""
    return model


class _Fitter:
    """Stands in for the Diagnoser: each swapped model's pointwise ELPD given by the rival it holds."""

    def __init__(self, blocks):
        self.blocks = blocks
        self.asked = []

    def fit_many(self, jobs, workers, cut=True):
        assert not cut  # the swaps' models are judged on their evidence; the cut waits for a mixture that reports f
        self.asked += [label for _, _, label in jobs]
        return [_fit(label, self.blocks[label.split("+")[0]]) for _, _, label in jobs]


def test_a_rival_the_final_model_rules_out_is_resolved_and_the_candidate_named_only_when_all_are():
    causes, verdicts, rounds, final = _record()
    good = np.asarray(final.elpd.pointwise)
    fitter = _Fitter({"clearance": good - 1.0, "channel_timing": good - 1.0, "bandwidth": good - 1.0})  # 200 nats
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                  flagged=lambda fit: True)
    assert fitter.asked == ["clearance", "channel_timing+clearance", "bandwidth+clearance"]
    assert [s.ruling for s in swaps] == ["elpd", "elpd", "elpd"] and swaps[1].delpd > 100
    assert out[0].resolved == ("channel_timing", "bandwidth")
    assert unresolved_rounds(causes, out) == ()
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["dispersion", "clearance"]
    # before the check, dispersion was a candidate fitted in turn, not named
    assert [v.mechanism.name for v in named_causes(causes, verdicts)] == ["clearance"]

    # a rival that explains the record as well with the clearance in the model stays open: dispersion is not named
    alike = good + np.random.default_rng(1).normal(0, 0.05, N)
    fitter = _Fitter({"clearance": good - 1.0, "channel_timing": good - 1.0, "bandwidth": alike})
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                  flagged=lambda fit: True)
    assert [s.ruling for s in swaps] == ["elpd", "elpd", None]
    assert out[0].resolved == ("channel_timing",) and unresolved_rounds(causes, out) == (0,)
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["clearance"]

    # a candidate the later cause makes superfluous (the model without it predicts as well) resolves nothing, however
    # much worse its rivals are: a rival named in a later round may have been what it stood for
    fitter = _Fitter({"clearance": alike, "channel_timing": good - 1.0, "bandwidth": good - 1.0})
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                  flagged=lambda fit: True)
    assert [s.ruling for s in swaps] == [None, "elpd", "elpd"]
    assert out[0].resolved == () and unresolved_rounds(causes, out) == (0,)
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["clearance"]


def test_a_swap_the_final_model_rules_out_pushes_no_other_out_of_the_mass_the_weight_guards(monkeypatch):
    """As in a round (verdict.weights_kept): the swaps the final model rules out by the ELPD rule are set aside before
    the 90 % of the stacking weight the weight route never rules out is counted."""
    from friction_uq.discrepancy import rival_swaps

    causes, verdicts, rounds, final = _record()
    good = np.asarray(final.elpd.pointwise)
    lead = np.full(N, 0.05) + np.random.default_rng(8).normal(0.0, 0.3, N)
    lead[:2] += 40.0  # 91 nats behind the final model, within 2 SE; 6 +- 4 with the spread test's blocks left out
    weights = {"reference": 0.6, "clearance": 0.2, "bandwidth+clearance": 0.12, "channel_timing+clearance": 0.08}
    monkeypatch.setattr(rival_swaps, "round_weights", lambda reference, fits, seed: dict(weights))
    fitter = _Fitter({"clearance": good - 1.0, "channel_timing": good - lead, "bandwidth": good - 1.0})
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                flagged=lambda fit: True)
    # without the 0.32 of the two swaps ruled out, the timing swap is inside the guarded mass: it stays open
    assert [s.ruling for s in swaps] == ["elpd", None, "elpd"]
    assert out[0].resolved == ("bandwidth",) and unresolved_rounds(causes, out) == (0,)
    # counted with their weight, the same comparison would rule it out by the weight and name the dispersion
    timing = next(s for s in swaps if s.rival == "channel_timing")
    behind = {"reference": 0.0, timing.model: timing.delpd}
    assert NamingRule().rulings(final.elpd, {timing.model: Elpd(good - lead, float("nan"))}, weights, behind,
                                10)[timing.model] == "weight"


def test_a_model_without_the_candidate_within_the_check_s_tolerance_resolves_nothing():
    """The ELPD rule sees a flexible transient that absorbs model form as evidence; the whole-record check's tolerance
    (what two simulators differ by) forgives it. Without the candidate the model must miss by more than that."""
    causes, verdicts, rounds, final = _record()
    good = np.asarray(final.elpd.pointwise)
    fitter = _Fitter({"clearance": good - 1.0, "channel_timing": good - 1.0, "bandwidth": good - 1.0})
    asked = []

    def within(fit):
        asked.append(fit.label)
        return False

    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                             flagged=within)
    assert asked == ["clearance"]  # only the model without the candidate is checked
    assert out[0].superfluous  # not needed beyond the tolerance: not named, its round open
    assert [(s.ruling, s.flagged) for s in swaps] == [("elpd", False), ("elpd", None), ("elpd", None)]
    assert out[0].resolved == () and unresolved_rounds(causes, out) == (0,)
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["clearance"]
    # not asked when the model without the candidate is not ruled out in the first place
    alike = good + np.random.default_rng(1).normal(0, 0.05, N)
    out, swaps, _ = check_swaps(_Fitter({"clearance": alike, "channel_timing": good - 1.0, "bandwidth": good - 1.0}),
                             final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0, flagged=within)
    assert asked == ["clearance"] and swaps[0].flagged is None and out[0].resolved == ()


def test_the_sentence_says_which_rivals_the_swaps_ruled_out():
    from friction_uq.discrepancy.diagnose import Diagnosis
    from friction_uq.discrepancy.round_clauses import swapped_clause as _swapped

    causes, verdicts, rounds, final = _record()
    good = np.asarray(final.elpd.pointwise)
    fitter = _Fitter({"clearance": good - 0.5, "channel_timing": good - 1.0, "bandwidth": good - 1.0})
    out, swaps, _ = check_swaps(fitter,
                             final, causes,
                             verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                  flagged=lambda fit: True)
    dg = Diagnosis(baseline=None, rounds=tuple(rounds), misfits=(), causes=tuple(causes), not_separable=(),
                   separate_by=None, final=final, verdicts=tuple(out), swaps=swaps)
    words = _swapped(dg)
    assert words.startswith(" dispersion was one of the candidates of its round; with clearance in the model, each of "
                            "its rivals explains the record worse (channel_timing 200 +- "), words
    assert words.endswith("bandwidth 200 +- 0 nats; without it, 100 +- 0 nats worse, and a misfit the whole-record "
                          "check flags)."), words
    # without the swaps, nothing is said
    assert _swapped(Diagnosis(baseline=None, rounds=tuple(rounds), misfits=(), causes=tuple(causes), not_separable=(),
                              separate_by=None, final=final, verdicts=tuple(verdicts))) == ""


def test_the_sentence_says_when_a_rival_stood_in_for_a_later_cause_too():
    from friction_uq.discrepancy.diagnose import Diagnosis
    from friction_uq.discrepancy.round_clauses import swapped_clause as _swapped

    causes, verdicts, rounds, final = _record(first_rivals=("velocity_friction",), first="clearance",
                                              second="pressure_friction")
    good = np.asarray(final.elpd.pointwise)
    fitter = _Fitter({"pressure_friction": good - 1.0, "velocity_friction": good - 1.0})
    out, swaps, _ = check_swaps(fitter, final, causes, verdicts, rounds, rule=NamingRule(), workers=1, seed=0,
                                flagged=lambda fit: True)
    words = _swapped(Diagnosis(baseline=None, rounds=tuple(rounds), misfits=(), causes=tuple(causes),
                               not_separable=(), separate_by=None, final=final, verdicts=tuple(out), swaps=swaps))
    assert ("with pressure_friction in the model, each of its rivals explains the record worse (velocity_friction"
            ", which replaces pressure_friction too (one law of a group at a time), 200 +- 0 nats; without it"
            ) in words, words


def test_a_candidate_whose_rivals_later_rounds_all_named_must_still_earn_its_place():
    """Round 1: dispersion fitted in turn among candidates whose only rival, the clearance, round 2 names. No rival is
    left to swap in, but the rival named later may be what the candidate stood for: the model without it is fitted
    alone and must be ruled out by the naming rule (as a later round's cause is, by evidence alone: the check's flag
    is recorded, not asked), or the candidate is superfluous, not named, and f the mixture of the final model and the
    model without it."""
    from friction_uq.discrepancy.candidates_mixture import open_rounds
    from friction_uq.discrepancy.diagnose import _mixture_after_causes

    causes, verdicts, rounds, final = _record(first_rivals=("clearance",))
    assert [(k, label, tuple(v.label for v in variants)) for k, label, variants in
            swap_jobs(causes, verdicts, rounds)] == [(0, WITHOUT, ("clearance",))]
    good = np.asarray(final.elpd.pointwise)
    # needed: without it the model is 200 nats worse and the check flags it; both are named, as before the check
    out, swaps, checked = check_swaps(_Fitter({"clearance": good - 1.0}), final, causes, verdicts, rounds,
                                      rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: True)
    assert [(s.rival, s.ruling, s.flagged) for s in swaps] == [(WITHOUT, "elpd", True)]
    assert [m.label for m in checked] == ["clearance"]
    assert not out[0].superfluous and unresolved_rounds(causes, out) == ()
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["dispersion", "clearance"]
    # 200 nats worse and within what two simulators differ by: named all the same, the check's answer recorded
    out, swaps, checked = check_swaps(_Fitter({"clearance": good - 1.0}), final, causes, verdicts, rounds,
                                      rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: False)
    assert [(s.ruling, s.flagged) for s in swaps] == [("elpd", False)] and not out[0].superfluous
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["dispersion", "clearance"]
    # the model without it predicts as well: superfluous, and the check is not asked
    alike = good + np.random.default_rng(1).normal(0, 0.05, N)
    out, swaps, checked = check_swaps(_Fitter({"clearance": alike}), final, causes, verdicts, rounds,
                                      rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: True)
    assert [(s.ruling, s.flagged) for s in swaps] == [(None, None)] and out[0].superfluous
    assert unresolved_rounds(causes, out) == (0,) and open_rounds(causes, out) == ()
    assert [v.mechanism.name for v in named_causes(causes, out)] == ["clearance"]
    # f is then the stacking mixture of the final model and the model without the candidate, both with the clearance
    final.f_effective = np.full(50, 0.04)  # the final model's f apart from the model without the candidate's 0.05
    asked = []

    def resolve(model):  # the cut posterior is asked of the members whose f the mixture draws from, and only of them
        asked.append(model.label)
        return model

    x, w, _, kind = _mixture_after_causes(final, rounds, out, causes, swaps, checked, 0, None, resolve)
    assert kind == "superfluous" and list(w) == [final.label, "clearance"] and abs(sum(w.values()) - 1.0) < 1e-9
    assert asked == ["clearance"]  # the final model has its own already
    assert set(np.unique(x)) <= {0.04, 0.05}  # drawn from these two models only, in their weights' shares
    assert abs(np.mean(x == 0.05) - w["clearance"]) <= 1.0 / len(x)
    # a round whose rival stays open gives f from that round's rivals, as before the check was asked of it
    causes, verdicts, rounds, final = _record(first_rivals=("clearance", "bandwidth"))
    out, swaps, checked = check_swaps(_Fitter({"clearance": alike, "bandwidth": good - 1.0}), final, causes,
                                      verdicts, rounds, rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: True)
    assert out[0].superfluous and open_rounds(causes, out) == (0,)
    assert _mixture_after_causes(final, rounds, out, causes, swaps, checked, 0, None, _as_is)[3] == "rivals"
    # the last cause's round is not asked, whether its rivals were named or not
    causes, verdicts, rounds, _ = _record(first_rivals=("clearance",))
    last = [replace(verdicts[0], kind="named", rivals=()), replace(verdicts[1], kind="candidates", rivals=())]
    assert swap_jobs(causes, last, rounds) == []


def test_a_superfluous_candidate_s_mixture_has_no_swap_the_final_model_rules_out(monkeypatch):
    """As in a round (verdict.Verdict.members): a swapped model 200 nats worse than the final model, whatever stacking
    weight its few blocks earn it, gives f no share; the others keep their proportions."""
    from friction_uq.discrepancy import candidates_mixture

    _, _, _, final = _record()
    final.f_effective = np.full(50, 0.04)
    good = np.asarray(final.elpd.pointwise)
    without = _fit("clearance", good + np.random.default_rng(1).normal(0, 0.05, N))  # as good: f 0.05
    worse = _fit("bandwidth+clearance", good - 1.0)
    worse.f_effective = np.full(50, 0.2)
    monkeypatch.setattr(candidates_mixture, "round_weights", lambda reference, fits, seed: {
        "reference": 0.4, "clearance": 0.3, "bandwidth+clearance": 0.3})
    x, w, _ = candidates_mixture.superfluous_mixture(final, [without, worse], seed=0)
    assert w == pytest.approx({final.label: 4 / 7, "clearance": 3 / 7})
    assert set(np.unique(x)) <= {0.04, 0.05}


def test_the_sentence_says_a_superfluous_candidate_is_not_named():
    from friction_uq.discrepancy.diagnose import Diagnosis
    from friction_uq.discrepancy.round_clauses import superfluous_clause as _superfluous

    causes, verdicts, rounds, final = _record(first_rivals=("clearance",))
    good = np.asarray(final.elpd.pointwise)
    alike = good + np.random.default_rng(1).normal(0, 0.05, N)
    out, swaps, checked = check_swaps(_Fitter({"clearance": alike}), final, causes, verdicts, rounds,
                                      rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: False)
    dg = Diagnosis(baseline=SimpleNamespace(f_effective=np.full(50, 0.06)), rounds=tuple(rounds), misfits=(),
                   causes=tuple(causes), not_separable=("dispersion", "clearance"), separate_by=None, final=final,
                   verdicts=tuple(out), swaps=swaps, swap_models=checked)
    assert dg.superfluous == ("dispersion",) and [v.label for v in dg.named_causes] == ["clearance"]
    assert dg.open_candidates == ()  # nothing is left open: the candidate is not needed, its rival is named
    words = _superfluous(dg)
    assert words == (" Fitted in turn among the candidates of its round: wave dispersion in the bars (dispersion), f "
                     "0.060 -> 0.050; with clearance in the model the record does not need it (the model without it "
                     "is 1 +- 1 nats worse, not decisive by the naming rule): not named."), words
    # a candidate that earned its place: nothing said
    out, swaps, _ = check_swaps(_Fitter({"clearance": good - 0.5}), final, causes, verdicts, rounds,
                                rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: True)
    assert _superfluous(replace(dg, verdicts=tuple(out), swaps=swaps)) == ""


def test_a_superfluous_candidate_in_the_sentence_the_f_to_quote_and_the_warning():
    """The whole chain of words for a record whose candidate fitted in turn was not needed: the lead names only the
    causes named, says the candidate was not needed, and f comes from the mixture of the final model and the model
    without it, which the f's source and the warning say too."""
    from friction_uq.discrepancy.diagnose import Diagnosis, _mixture_after_causes
    from friction_uq.discrepancy.diagnosis_words import sentence
    from friction_uq.report.quote import f_to_quote
    from friction_uq.record_run.warnings import _next_step

    causes, verdicts, rounds, final = _record(first_rivals=("clearance",))
    good = np.asarray(final.elpd.pointwise)
    alike = good + np.random.default_rng(1).normal(0, 0.05, N)
    out, swaps, checked = check_swaps(_Fitter({"clearance": alike}), final, causes, verdicts, rounds,
                                      rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: False)
    final.f_effective, final.predicted = np.full(50, 0.04), {}
    rounds = [tuple(SimpleNamespace(fit=r.fit, delpd=100.0, se=10.0) for r in rnd) for rnd in rounds]
    mix, w, src, kind = _mixture_after_causes(final, rounds, out, causes, swaps, checked, 0, None, _as_is)
    worst = SimpleNamespace(channel="tube_hoop", level=-5.0, relative_level=-0.06, phase="unloading")
    dg = Diagnosis(baseline=SimpleNamespace(f_effective=np.full(50, 0.06), label="baseline", variants=()),
                   rounds=tuple(rounds), misfits=(), causes=tuple(causes), not_separable=(), separate_by=None,
                   final=final, verdicts=tuple(out), swaps=swaps, swap_models=checked, mixture_f=mix,
                   mixture_weights=w, mixture_source=src, mixture_of=kind,
                   baseline_comparison=SimpleNamespace(figures=[worst]))
    said = sentence(dg, {"q05": 0.055, "q50": 0.060, "q95": 0.065})
    # one cause named (dispersion superfluous): no order to say
    assert said.startswith("Cause found: a radial gap between sample and tube "
                           "(clearance), f 0.050 -> 0.040. Fitted in turn among the candidates of its round: wave "
                           "dispersion in the bars (dispersion)"), said
    assert "the same without the one not named, weighted by how well each predicts the record (the f to quote)" in said
    source, _ = f_to_quote({"q05": 0.0, "q50": 0.0, "q95": 0.0}, dg)
    assert "the causes diagnose named (clearance) with and without dispersion, fitted in turn and not needed" in source
    assert "it names clearance; dispersion, fitted in turn, is not needed with them and not named" in _next_step(dg,
                                                                                                               None)

    # with a rival of its round left open, f is that round's mixture and the sentence says both
    causes, verdicts, rounds, final = _record(first_rivals=("clearance", "bandwidth"))
    good = np.asarray(final.elpd.pointwise)
    out, swaps, checked = check_swaps(_Fitter({"clearance": alike, "bandwidth": good - 1.0}), final, causes, verdicts,
                                      rounds, rule=NamingRule(), workers=1, seed=0, flagged=lambda fit: True)
    final.f_effective, final.predicted = np.full(50, 0.04), {}
    rounds = [tuple(SimpleNamespace(fit=r.fit, delpd=100.0, se=10.0) for r in rnd) for rnd in rounds]
    mix, w, src, kind = _mixture_after_causes(final, rounds, out, causes, swaps, checked, 0, None, _as_is)
    dg = replace(dg, rounds=tuple(rounds), causes=tuple(causes), final=final, verdicts=tuple(out), swaps=swaps,
                 swap_models=checked, mixture_f=mix, mixture_weights=w, mixture_source=src, mixture_of=kind)
    said = sentence(dg, {"q05": 0.055, "q50": 0.060, "q95": 0.065})
    assert kind == "rivals" and dg.open_candidates == ("dispersion", "bandwidth"), (kind, dg.open_candidates)
    assert "A further cause this record does not tell apart: dispersion, bandwidth (fitted in turn: wave dispersion" \
        in said and "with clearance in the model the record does not need it" in said, said
