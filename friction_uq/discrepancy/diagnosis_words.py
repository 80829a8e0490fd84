"""What ``diagnose`` says in words: the sentence for the terminal and the summary page, each cause in an
experimentalist's words (a measurement-chain fault with its gauge and how much), and the hoop gauge's calibration
finding. The f it quotes (the named model's or the candidates' stacking mixture): :mod:`.diagnosed_f`. The JSON
and the DataTree groups: :mod:`.outcome`."""

from __future__ import annotations


import numpy as np

from ..models.parameters import Parameter
from .candidates_mixture import STATIONARY, open_rounds
from .diagnose import Diagnosis
from .diagnosed_f import further, headline, member_name, mixture_label, unresolved
from .extended import Variant
from .rival_swaps import WITHOUT
from .whole_record import CHANNEL_LABELS

#: A hoop gain this far from 1 (its most probable value under its 5 % prior) is reported as a calibration finding
#: (clean records: see benchmarks/bench_misfit.py for how often a right gauge reads this far off).
HOOP_GAIN_FINDING = 0.02


#: Each mechanism in an experimentalist's words (docs/glossary.md has the longer entries).
PLAIN_NAMES = {
    "velocity_friction": "wall friction that changes with the sliding speed",
    "pressure_friction": "wall friction that changes with the wall pressure",
    "slip_friction": "wall friction that changes with the distance slid",
    "clearance": "a radial gap between sample and tube",
    "plug_friction": "the plug rubbing on the tube",
    "gauge_gain": "a bar gauge's calibration",
    "dispersion": "wave dispersion in the bars",
    "end_friction": "friction on the sample's end faces",
    "zero_drift": "a gauge's zero drifting through the record",
    "channel_timing": "a channel read late or early (a gauge's position, a trigger's skew)",
    "bandwidth": "an amplifier too slow for the waves",
    "bar_modulus": "an output bar's modulus off its header",
}

#: How a measurement-chain parameter is said: unit -> (factor, unit in words)
CHAIN_UNITS = {"s": (1e6, "us"), "1/s": (1e3, "microstrain per ms"), "-": (1.0, "times the header's")}


def _describe(dg: Diagnosis) -> str:
    """Where the simple model (eq. 17 with the 1-D simulation) misses most, in words (largest level misfit)."""
    comp = dg.baseline_comparison
    worst = max(comp.figures, key=lambda f: abs(f.level))
    direction = "above" if worst.relative_level > 0 else "below"
    return (f"the {CHANNEL_LABELS[worst.channel]} gauge reads {abs(worst.relative_level) * 100:.1f} % {direction} the "
            f"simple model over the {worst.phase} phase")


def f_steps(dg: Diagnosis) -> list[tuple[Variant, float, float]]:
    """Each named cause with the median f before and after it was added, in the order named: round k's
    reference model is the one with the first k causes (diagnose.diagnose)."""
    out, before = [], float(np.median(dg.baseline.f_effective))
    for k, v in enumerate(dg.causes):
        chosen = next((r.fit for r in dg.rounds[k] if r.fit.variants[-1] == v), None) if k < len(dg.rounds) else None
        after = before if chosen is None else float(np.median(chosen.f_effective))
        out.append((v, before, after))
        before = after
    return out


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
    return "Cause found:" if n == 1 else f"Causes found, {order}:"


def chain_gauge(v: Variant, dg: Diagnosis | None) -> tuple[str, Parameter, float] | None:
    """For a measurement-chain fault fitted on every gauge (``per_gauge``): the gauge it names, the parameter and
    its posterior median, from the final model's draws when it holds the fault (else the round's fit)."""
    if dg is None or not v.mechanism.per_gauge:
        return None
    fit = dg.final if v in dg.final.variants else next(
        (r.fit for rk in dg.rounds for r in rk if r.fit.variants[-1] == v), None)
    if fit is None:
        return None
    medians = {k: float(np.median(d)) for k, d in fit.fit.draws.items()}
    gauge, p = v.mechanism.departing_gauge(medians)
    return gauge, p, medians[p.name]


def cause_words(v: Variant, dg: Diagnosis | None = None) -> str:
    where = f" on the {CHANNEL_LABELS.get(v.channel, v.channel)} gauge" if v.channel else ""
    chain = chain_gauge(v, dg)
    if chain is not None:  # say which gauge, and how much
        gauge, p, value = chain
        factor, unit = CHAIN_UNITS.get(p.unit, (1.0, p.unit))
        x = f"{value * factor:.3g}" if p.unit == "-" else f"{value * factor:+.2g}"
        where = f", mostly the {CHANNEL_LABELS.get(gauge, gauge)} gauge ({x} {unit})"
    return f"{PLAIN_NAMES.get(v.mechanism.name, v.mechanism.name)}{where} ({v.mechanism.name})"


def sentence(dg: Diagnosis, f_without: dict[str, float]) -> str:
    """One line for the terminal and the summary page, in an experimentalist's words: the causes, the one that
    moves f most first, with f before and after each; then f to quote (:func:`headline`'s); then where the simple
    model missed. ``f_without``: the stationary analysis' f to quote."""
    if not dg.causes and dg.mixture_f is not None:
        return _mixture_sentence(dg, f_without)
    if not dg.causes and dg.misfits and not dg.misfits[0].detected:
        return (f"The simulated test reproduces every gauge within what two simulators of the same test differ by: "
                f"nothing to explain (closest cause: {dg.ranking[0].fit.label}, evidence {dg.ranking[0].delpd:.1f} +- "
                f"{dg.ranking[0].se:.1f} nats, docs/glossary.md); f = {f_without['q50']:.3f} [{f_without['q05']:.3f}, "
                f"{f_without['q95']:.3f}] stands{'; ' + _hoop_finding(dg) if hoop_gain_off(dg) else ''}.")
    if not dg.causes:
        return (f"No cause of the catalogue explains the record clearly better than the simple model (closest: "
                f"{dg.ranking[0].fit.label}, evidence {dg.ranking[0].delpd:.1f} +- {dg.ranking[0].se:.1f} "
                f"nats, docs/glossary.md); f = {f_without['q50']:.3f} [{f_without['q05']:.3f}, "
                f"{f_without['q95']:.3f}] stands{'; ' + _hoop_finding(dg) if hoop_gain_off(dg) else ''}.")
    steps, order = ordered_steps(dg)
    opening = found(order, steps, dg)
    fitted = "; ".join(f"{cause_words(v, dg)}, f {a:.3f} -> {b:.3f}" for v, a, b in steps)
    named = "; ".join(f"{cause_words(v, dg)}, f {a:.3f} -> {b:.3f}" for v, a, b in steps if v in dg.named_causes)
    spare = _superfluous(dg)
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
        quote = f"from the {mixture_label(dg)} (the f to quote, wide enough for whichever is right)"
        evidence = "first cause" if named else "strongest candidate"
        sep = f" {dg.separate_by[:1].upper()}{dg.separate_by[1:]} would tell them apart." if dg.separate_by else ""
    elif more := further(dg):  # the last round's weight lies on further mechanisms it did not name: their mixture
        lead = f"{opening} {named}{gauges}.{spare}"
        shares = ", ".join(f"{'them' if k == dg.final.label else '+ ' + more[k]} {100 * w:.0f} %"
                           for k, w in dg.mixture_weights.items())
        with_them = "the model with them and " if dg.final.label in dg.mixture_weights else ""
        quote = (f"from {with_them}the further causes the record leans to without naming one, weighted by how well "
                 f"each predicts it ({shares}; the f to quote, wide enough for whichever is right)")
        evidence = "first cause"
        sep = f" This record does not tell apart {', '.join(dg.not_separable)}; {dg.separate_by} would." \
            if dg.not_separable else ""
    else:
        lead = f"{opening} {named}{gauges}.{spare}"
        quote = "with them (the f to quote)" if dg.mixture_of != "superfluous" else (
            f"from the {mixture_label(dg)}: the model with every mechanism fitted and the same without the one not "
            "named, weighted by how well each predicts the record (the f to quote)")
        evidence = "first cause"
        sep = f" This record does not tell apart {', '.join(dg.not_separable)}; {dg.separate_by} would." \
            if dg.not_separable else ""
    fx = headline(dg)[1]
    return (f"{lead} f = {fx['q50']:.3f} [{fx['q05']:.3f}, {fx['q95']:.3f}] {quote}, {f_without['q50']:.3f} from "
            f"the stationary analysis {'alone' if STATIONARY in dg.mixture_weights else 'without them'}. Why: "
            f"{_describe(dg)}; the {evidence}'s evidence is "
            f"{first.delpd:.0f} +- {first.se:.0f} nats.{_by_weight(dg)}{_swapped(dg)}{sep}{_remaining(dg)}"
            f"{f' Calibration: {_hoop_finding(dg)}.' if hoop_gain_off(dg) else ''}")


def _evidence_of(dg: Diagnosis, cause: Variant):
    """The ranking entry (dELPD +- SE over its round's reference) of a cause, from the round that fitted it."""
    k = dg.causes.index(cause)
    return next((r for r in dg.rounds[k] if r.fit.variants[-1] == cause), dg.ranking[0]) if k < len(dg.rounds) \
        else dg.ranking[0]


def _by_weight(dg: Diagnosis) -> str:
    """' X was preferred to Y, Z by the stacking weight ...' for each named cause that ruled rivals out only by the
    naming rule's weight route (:mod:`.verdict`, 3.); '' when none did."""
    out = []
    for k, v in enumerate(dg.verdicts[:len(dg.causes)]):
        if v.kind != "named" or not v.by_weight or dg.causes[k] not in dg.named_causes:
            continue
        by = {c.label: c.variant for c in v.candidates}
        out.append(f" {dg.causes[k].label} was preferred to {', '.join(by[x] for x in v.by_weight)} by the stacking "
                   f"weight, not by 2 SE of the evidence: each stays more than 4 nats behind it with the blocks that "
                   f"favour it most left out, and carries under 0.1 of the weight with the models that predict alike "
                   f"with it.")
    return "".join(out)


def _superfluous(dg: Diagnosis) -> str:
    """' Fitted in turn among the candidates of its round: X; with Y in the model the record does not need it (...):
    not named.' for each candidate fitted in turn that the swap check found superfluous (:mod:`.rival_swaps`); ''
    when none."""
    out = []
    steps = f_steps(dg)  # in the causes' order
    for k, v in enumerate(dg.verdicts[:len(dg.causes)]):
        without = next((s for s in dg.swaps if s.round == k and s.rival == WITHOUT), None)
        if not v.superfluous or without is None:
            continue
        cause, a, b = steps[k]
        others = _other_causes(dg, k)
        d = without.delpd
        gap = f"the model without it is {abs(d):.0f} +- {without.se:.0f} nats {'worse' if d >= 0 else 'better'}"
        why = (f"{gap}, not decisive by the naming rule" if without.ruling is None else
               f"{gap}, but within what two simulators of the same test differ by: the whole-record check does not "
               f"flag it")
        out.append(f" Fitted in turn among the candidates of its round: {cause_words(cause, dg)}, f {a:.3f} -> "
                   f"{b:.3f}; with {others} in the model the record does not need it ({why}): not named.")
    return "".join(out)


def _other_causes(dg: Diagnosis, k: int) -> str:
    """'clearance, plug_friction': the mechanisms of the final model besides round ``k``'s candidate fitted in turn."""
    return ", ".join(c.mechanism.name for j, c in enumerate(dg.causes) if j != k)


def _swapped(dg: Diagnosis) -> str:
    """' X was one of the candidates of its round; with the other causes in the model, each of its rivals explains the
    record worse (...).' for each named cause whose round's rivals the swap check resolved
    (:mod:`.rival_swaps`); '' when none."""
    out = []
    for k, v in enumerate(dg.verdicts[:len(dg.causes)]):
        done = [s for s in dg.swaps if s.round == k and s.ruling is not None and s.rival in v.resolved]
        if not done or dg.causes[k] not in dg.named_causes:
            continue
        by = {c.label: c.variant for c in v.candidates}
        others = _other_causes(dg, k)
        worse = ", ".join(f"{by[s.rival]}{_standing_in(dg, k, s)} {s.delpd:.0f} +- {s.se:.0f} nats"
                          + (" (by the weight)" if s.ruling == "weight" else "") for s in done)
        alone = next((f"; without it, {s.delpd:.0f} +- {s.se:.0f} nats worse"
                      f"{' (by the weight)' if s.ruling == 'weight' else ''}"
                      f"{', and a misfit the whole-record check flags' if s.flagged else ''}"
                      for s in dg.swaps if s.round == k and s.rival == WITHOUT), "")
        out.append(f" {dg.causes[k].mechanism.name} was one of the candidates of its round; with {others} in the model, "
                   f"each of its rivals explains the record worse ({worse}{alone}).")
    return "".join(out)


def _standing_in(dg: Diagnosis, k: int, s) -> str:
    """', which replaces Y too (one law of a group at a time),' when the swap took out a later cause of the rival's
    group as well (a second friction law: :func:`~.rival_swaps.swapped`); '' otherwise."""
    kept = set(s.model.split("+"))
    gone = [c.label for j, c in enumerate(dg.causes) if j != k and c.label not in kept]
    return f", which replaces {', '.join(gone)} too (one law of a group at a time)," if gone else ""


def _remaining(dg: Diagnosis) -> str:
    """' A misfit remains with them (on the ... gauge, ... phase) that no further cause explains clearly (candidates:
    ...).' when the round after the last cause found the misfit the check still flags unexplained; '' otherwise."""
    last = dg.verdicts[-1] if len(dg.verdicts) > 1 else None
    if last is None or last.kind != "unexplained":
        return ""
    cells = dg.misfits[-1].flagged() if dg.misfits else []
    where = f" on the {CHANNEL_LABELS.get(cells[0].channel, cells[0].channel)} gauge, {cells[0].phase} phase" \
        if cells else ""
    by = {c.label: c.variant for c in last.candidates}
    listed = [by[label] for label in last.supported if label in by]
    return (f" A misfit remains with them{where} that no further cause explains clearly"
            f"{' (candidates: ' + ', '.join(listed) + ')' if listed else ''}.")


def _mixture_sentence(dg: Diagnosis, f_without: dict[str, float]) -> str:
    """The sentence of a record whose misfit no single cause explains (candidates, or unexplained)."""
    fm = headline(dg)[1]
    shares = ", ".join(f"{_words_of(dg, k)} {100 * w:.0f} %" for k, w in dg.mixture_weights.items()
                       if k != STATIONARY)
    v = dg.verdict
    if v.kind == "unconfirmed":
        what = (f"{_words_of(dg, v.named)} predicts the record better than the simple model, but the simple model "
                "already reproduces every gauge within what two simulators of the same test differ by: not named.")
    elif v.kind == "candidates":
        what = (f"This record does not tell apart {', '.join(dg.not_separable) or 'the candidates'}"
                f"{'; ' + dg.separate_by + ' would' if dg.separate_by else ''}.")
    else:
        where = _where(dg)
        what = (f"Unexplained misfit{where}: no cause of the catalogue explains it clearly, over the whole record "
                "and better than every other.")
    if STATIONARY in dg.mixture_weights:  # half the stationary analysis' f (candidates_mixture)
        half = 100 * dg.mixture_weights[STATIONARY]
        return (f"{what} f = {fm['q50']:.3f} [{fm['q05']:.3f}, {fm['q95']:.3f}] from the stationary analysis "
                f"({half:.0f} %) and the candidates weighted by how well each predicts the record ({shares}): the f "
                f"to quote, wide enough for whichever is right; {f_without['q50']:.3f} from the stationary analysis "
                "alone.")
    return (f"{what} f = {fm['q50']:.3f} [{fm['q05']:.3f}, {fm['q95']:.3f}] from the candidates weighted by how well "
            f"each predicts the record ({shares}; the f to quote, wide enough for whichever is right), "
            f"{f_without['q50']:.3f} from the stationary analysis.")


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
    a, b = baseline_hoop_gain(dg) - 1.0, dg.final.hoop_gain - 1.0
    return abs(a) > HOOP_GAIN_FINDING and abs(b) > HOOP_GAIN_FINDING and a * b > 0


def _hoop_finding(dg: Diagnosis) -> str:
    if not hoop_gain_off(dg):
        return ""
    g = dg.final.hoop_gain
    return (f"the tube hoop gauge reads {g:.2f} times the model's strain, {baseline_hoop_gain(dg):.2f} without "
            "the causes (its calibration factor, most probable value under a 5 % prior)")
