"""What ``diagnose`` says in words: the sentence for the terminal and the summary page, in which each cause is said in
an experimentalist's words (:mod:`.cause_words`) and the later rounds add their clauses (:mod:`.round_clauses`), and
the hoop gauge's calibration finding. The f it quotes (the named model's or the candidates' stacking mixture): :mod:`.diagnosed_f`. The JSON
and the DataTree groups: :mod:`.outcome`."""

from __future__ import annotations

import numpy as np

from .candidates_mixture import STATIONARY, open_rounds
from .cause_words import cause_words, f_steps
from .diagnosed_f import further, headline, member_name, mixture_label, stationary_member, unresolved
from .diagnosis import Diagnosis
from .extended import Variant
from .round_clauses import (by_weight_clause, joint_clause, pair_refused_clause, remaining_clause, superfluous_clause,
                            swapped_clause, within_tolerance_clause)
from .whole_record import CHANNEL_LABELS

#: A hoop gain this far from 1 (its most probable value under its 5 % prior) is reported as a calibration finding
#: (clean records: see benchmarks/bench_misfit.py for how often a right gauge reads this far off).
HOOP_GAIN_FINDING = 0.02


def _describe(dg: Diagnosis) -> str:
    """Where the simple model (eq. 17 with the 1-D simulation) misses most, in words (largest level misfit)."""
    comp = dg.baseline_comparison
    worst = max(comp.figures, key=lambda f: abs(f.level))
    direction = "above" if worst.relative_level > 0 else "below"
    return (f"the {CHANNEL_LABELS[worst.channel]} gauge reads {abs(worst.relative_level) * 100:.1f} % {direction} the "
            f"simple model over the {worst.phase} phase")


def ordered_steps(dg: Diagnosis) -> tuple[list[tuple[Variant, float, float]], str]:
    """The named causes' steps of f (:func:`f_steps`), the one that moves f most first, and how the sentence says
    the order: when the shifts of f differ by no more than the final model's posterior sd of f, the order says
    nothing about which matters more (a tie would be broken by the sampler's bits), and the causes keep the order
    they were named in."""
    steps = f_steps(dg)
    shifts = [abs(b - a) for _, a, b in steps]
    if len(steps) > 1 and max(shifts) - min(shifts) <= float(np.std(dg.final.f_effective)):
        return steps, "in the order named (their shifts of f differ by less than f's posterior sd)"
    by_shift = sorted(range(len(steps)), key=lambda k: -shifts[k])
    return [steps[k] for k in by_shift], "the one that moves f most first"


def found(order: str, steps: list[tuple[Variant, float, float]], dg: Diagnosis) -> str:
    """The sentence's opening on the named causes: "Cause found:" for one (an order says nothing then), else
    "Causes found, <order>:" (:func:`ordered_steps`)."""
    n = sum(v in dg.named_causes for v, _, _ in steps)
    if n == 0:  # every mechanism of the model superfluous or within the check's tolerance
        return "No cause named; in the model:"
    return "Cause found:" if n == 1 else f"Causes found, {order}:"


def sentence(dg: Diagnosis, f_without: dict[str, float]) -> str:
    """One line for the terminal and the summary page, in an experimentalist's words: the causes, the one that
    moves f most first, with f before and after each; then f to quote (:func:`headline`'s); then where the simple
    model missed. ``f_without``: the stationary analysis' f to quote."""
    if not dg.causes and dg.mixture_f is not None:
        return _mixture_sentence(dg, f_without)
    if not dg.causes and dg.misfits and not dg.misfits[0].detected:
        return (f"The simulated test reproduces every gauge within what two simulators of the same test differ by: "
                f"nothing to explain (closest cause: {dg.ranking[0].fit.label}, evidence {dg.ranking[0].delpd:.1f} +- "
                f"{dg.ranking[0].se:.1f} nats, docs/glossary.md); {_f_said(dg, f_without, BOTH_READINGS)} "
                f"stands{'; ' + _hoop_finding(dg) if hoop_gain_off(dg) else ''}.")
    if not dg.causes:
        return (f"No cause of the catalogue explains the record clearly better than the simple model (closest: "
                f"{dg.ranking[0].fit.label}, evidence {dg.ranking[0].delpd:.1f} +- {dg.ranking[0].se:.1f} "
                f"nats, docs/glossary.md); {_f_said(dg, f_without, BOTH_READINGS)} "
                f"stands{'; ' + _hoop_finding(dg) if hoop_gain_off(dg) else ''}.")
    steps, order = ordered_steps(dg)
    opening = found(order, steps, dg)
    fitted = "; ".join(f"{cause_words(v, dg)}, f {a:.3f} -> {b:.3f}" for v, a, b in steps)
    named = "; ".join(f"{cause_words(v, dg)}, f {a:.3f} -> {b:.3f}" for v, a, b in steps if v in dg.named_causes)
    spare = superfluous_clause(dg) + within_tolerance_clause(dg)
    gauges = ""  # the first round's cause, a gain, about as good on another gauge
    if dg.channels_not_separable and dg.cause is dg.causes[0]:
        alt = " or ".join(f"the {CHANNEL_LABELS.get(c, c)}" for c in dg.channels_not_separable)
        gauges = f" (the same on {alt} gauge explains the record about as well)"
    first = _evidence_of(dg, dg.cause) if dg.cause is not None else dg.ranking[0]
    if unresolved(dg):  # candidates no later round told apart: the one fitted in turn is no more the cause than
        # its rivals, and f is their mixture
        open_ = [dg.causes[k] for k in open_rounds(dg.causes, dg.verdicts)[:1]]  # a Variant holds dicts: no set
        turn = "; ".join(f"{cause_words(v, dg)}, f {a:.3f} -> {b:.3f}" for v, a, b in steps if v in open_)
        rivals = ", ".join(dg.open_candidates)
        if named:
            lead = (f"{opening} {named}{gauges}. A further cause this record "
                    f"does not tell apart: {rivals} (fitted in turn: {turn}).{spare}")
        else:
            lead = ("Candidates, not a cause: this record does not tell apart "
                    f"{', '.join(dg.not_separable) or rivals}; fitted in turn: {fitted}.{spare}")
        quote = f"from the {mixture_label(dg)} (the f to quote, wide enough for whichever of them is right)"
        evidence = "first cause" if named else "strongest candidate"
        sep = f" {dg.separate_by[:1].upper()}{dg.separate_by[1:]} would tell them apart." if dg.separate_by else ""
    elif more := further(dg):  # the last round's weight lies on further mechanisms it did not name: their mixture
        lead = f"{opening} {named or fitted}{gauges}.{spare}"
        shares = ", ".join(f"{'them' if k == dg.final.label else '+ ' + more[k]} {_percent(dg, w)}"
                           for k, w in dg.mixture_weights.items())
        with_them = "the model with them and " if dg.final.label in dg.mixture_weights else ""
        quote = (f"from {with_them}the further causes the record leans to without naming one, weighted by how well "
                 f"each predicts it ({shares}; the f to quote, wide enough for whichever of them is right)")
        evidence = "first cause"
        sep = f" This record does not tell apart {', '.join(dg.not_separable)}; {dg.separate_by} would." \
            if dg.not_separable else ""
    else:
        lead = f"{opening} {named or fitted}{gauges}.{spare}"
        quote = "with them (the f to quote)" if dg.mixture_of != "superfluous" else (
            f"from the {mixture_label(dg)}: the model with every mechanism fitted and the same without the one not "
            "named, weighted by how well each predicts the record (the f to quote)")
        evidence = "first cause"
        sep = f" This record does not tell apart {', '.join(dg.not_separable)}; {dg.separate_by} would." \
            if dg.not_separable else ""
    fx = headline(dg)[1]
    return (f"{lead} {_f_said(dg, fx)} {quote}, {_median(dg, f_without)} from "
            f"the stationary analysis {'alone' if STATIONARY in dg.mixture_weights else 'without them'}. Why: "
            f"{_describe(dg)}; {_evidence_said(dg, evidence, first)}.{joint_clause(dg)}{by_weight_clause(dg)}{swapped_clause(dg)}{sep}{delay_clause(dg)}"
            f"{remaining_clause(dg)}"
            f"{f' Calibration: {_hoop_finding(dg)}.' if hoop_gain_off(dg) else ''}")


def _evidence_said(dg: Diagnosis, evidence: str, first) -> str:
    """"the first cause's evidence is D +- SE nats" (``first``: its ranking entry); for a first round's pair named
    together (:mod:`.joint_round`), the pair's, which is what named them: each alone did not pass."""
    joint = dg.verdicts[0].joint if dg.verdicts and dg.causes else None
    if joint is not None and dg.cause is dg.causes[0]:
        d, se, _, _ = joint.against["reference"]
        return f"the first two causes' evidence, fitted together, is {d:.0f} +- {se:.0f} nats"
    return f"the {evidence}'s evidence is {first.delpd:.0f} +- {first.se:.0f} nats"


def _evidence_of(dg: Diagnosis, cause: Variant):
    """The ranking entry (dELPD +- SE over its round's reference) of a cause, from the round that fitted it."""
    k = dg.causes.index(cause)
    return next((r for r in dg.rounds[k] if r.fit.variants[-1] == cause), dg.ranking[0]) if k < len(dg.rounds) \
        else dg.ranking[0]


def _percent(dg: Diagnosis, w: float) -> str:
    """A mixture member's share of the f to quote: its stacking weight, halved where the f to quote holds the
    stationary f from nu's prior alone for the other half (``Diagnosis.f_prior_nu``)."""
    return f"{100 * w * (1.0 if dg.f_prior_nu is None else 0.5):.0f} %"


def _median(dg: Diagnosis, f: dict[str, float]) -> str:
    """The stationary analysis' f to quote by its median, or by its interval where it holds two readings of nu."""
    return f"{f['q50']:.3f}" if dg.f_prior_nu is None else f"{f['q05']:.3f} to {f['q95']:.3f} (two readings of nu)"


#: Why a diagnosed f to quote is said by its interval (:func:`_f_said`): half of it is the reading from nu's prior.
PRIOR_HALF = ("half of it the stationary analysis with nu from the prior file alone, the hoop gauge and the prior file "
              "disagreeing")
#: Why the stationary analysis' f to quote is: it holds both readings of nu.
BOTH_READINGS = "the hoop gauge's and the prior's readings of nu"


def _f_said(dg: Diagnosis, fx: dict[str, float], why: str = PRIOR_HALF) -> str:
    """'f = 0.049 [0.044, 0.054]'; by its interval alone, and ``why``, when it holds two readings of nu
    (``Diagnosis.f_prior_nu``: the hoop gauge and the prior file disagree), its median between them."""
    if dg.f_prior_nu is None:
        return f"f = {fx['q50']:.3f} [{fx['q05']:.3f}, {fx['q95']:.3f}]"
    return f"f from {fx['q05']:.3f} to {fx['q95']:.3f} ({why})"


def _mixture_sentence(dg: Diagnosis, f_without: dict[str, float]) -> str:
    """The sentence of a record whose misfit no single cause explains (candidates, or unexplained)."""
    fm = headline(dg)[1]
    shares = ", ".join(f"{_words_of(dg, k)} {_percent(dg, w)}" for k, w in dg.mixture_weights.items()
                       if k != STATIONARY)
    v = dg.verdict
    if v.kind == "unconfirmed":
        what = (f"{_words_of(dg, v.named)} predicts the record better than the simple model, but the simple model "
                "already reproduces every gauge within what two simulators of the same test differ by: not named.")
    elif v.kind == "candidates":
        what = (f"This record does not tell apart {', '.join(dg.not_separable) or 'the candidates'}"
                f"{'; ' + dg.separate_by + ' would' if dg.separate_by else ''}.{delay_clause(dg)}")
    else:
        where = _where(dg)
        what = (f"Unexplained misfit{where}: no cause of the catalogue explains it clearly, over the whole record "
                f"and better than every other.{pair_refused_clause(dg)}")
    if STATIONARY in dg.mixture_weights:  # half the stationary analysis' f (candidates_mixture)
        return (f"{what} {_f_said(dg, fm)} from {stationary_member(dg)} "
                f"({_percent(dg, dg.mixture_weights[STATIONARY])}) and the candidates weighted by how well each "
                f"predicts the record ({shares}): the f to quote, wide enough for whichever of them is right; "
                f"{_median(dg, f_without)} from the stationary analysis alone.")
    return (f"{what} {_f_said(dg, fm)} from the candidates weighted by how well "
            f"each predicts the record ({shares}; the f to quote, wide enough for whichever of them is right), "
            f"{_median(dg, f_without)} from the stationary analysis.")


def delay_clause(dg: Diagnosis) -> str:
    """' What the record does show: the internal transmitted gauge's fronts 3.4 to 3.8 us late against the input
    bar's, by each of channel_timing, bandwidth.' where the candidates the record does not tell apart are faults of
    the chain that agree on one gauge's delay (:mod:`.front_delay`); '' otherwise."""
    sd = dg.shared_delay
    if sd is None:
        return ""
    lo, hi = sorted((abs(sd.low) * 1e6, abs(sd.high) * 1e6))
    amount = f"{lo:.1f} us" if f"{lo:.1f}" == f"{hi:.1f}" else f"{lo:.1f} to {hi:.1f} us"
    return (f" What the record does show: the {CHANNEL_LABELS.get(sd.gauge, sd.gauge)} gauge's fronts {amount} "
            f"{'late' if sd.high > 0 else 'early'} against the input bar's, by each of {', '.join(sd.mechanisms)}.")


def _words_of(dg: Diagnosis, label: str) -> str:
    if label in ("reference", STATIONARY):
        return member_name(label)
    fit = next((r.fit for r in dg.ranking if r.fit.label == label), None)
    return label if fit is None else cause_words(fit.variants[-1], dg)


def _where(dg: Diagnosis) -> str:
    """' on the internal transmitted gauge, rise phase': the first cell the whole-record check flagged."""
    cells = dg.misfits[0].flagged() if dg.misfits else []
    if not cells:
        return ""
    c = cells[0]
    return f" on the {CHANNEL_LABELS.get(c.channel, c.channel)} gauge, {c.phase} phase"


def baseline_hoop_gain(dg: Diagnosis) -> float:
    """The hoop factor without the causes: the whole-record check's (f and nu free) when run made one, else
    diagnose's own baseline's (which also frees the sample's modulus, and lets it absorb part of it)."""
    return dg.baseline.hoop_gain if dg.check_hoop_gain is None else dg.check_hoop_gain


def hoop_gain_off(dg: Diagnosis) -> bool:
    """The hoop calibration factor (most probable under its prior) is more than HOOP_GAIN_FINDING from 1, on
    the same side, without the causes and under the final model. A mechanism that changes the hoop's
    level (a clearance) moves the factor with it: on the bundled set-up A (a right hoop gauge, a
    clearance) the check read 0.96-0.97 and the final models 1.01-1.12; only a reading both agree on
    is a calibration finding."""
    if "tube_hoop" not in dg.final.predicted:
        return False
    known = dg.hoop_calibration[0]  # a factor the prior file states is no finding: its departure from it is
    a, b = baseline_hoop_gain(dg) / known - 1.0, dg.final.hoop_gain / known - 1.0
    return abs(a) > HOOP_GAIN_FINDING and abs(b) > HOOP_GAIN_FINDING and a * b > 0


def _hoop_finding(dg: Diagnosis) -> str:
    if not hoop_gain_off(dg):
        return ""
    g = dg.final.hoop_gain
    return (f"the tube hoop gauge reads {g:.2f} times the model's strain, {baseline_hoop_gain(dg):.2f} without "
            f"the causes (its calibration factor, most probable value under {hoop_prior_words(dg)})")


def hoop_prior_words(dg: Diagnosis) -> str:
    """The hoop factor's prior in words: "a 5 % prior" (the package's), or with the median a prior file states."""
    median, sd = dg.hoop_calibration
    return f"a {100 * sd:.0f} % prior" + ("" if median == 1.0 else f" about {median:.3g}")
