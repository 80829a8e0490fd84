"""The clauses the sentence (:mod:`.diagnosis_words`) adds of the later rounds: two causes named together, a cause
preferred by the stacking weight, a candidate fitted in turn that the later causes made superfluous, a mechanism kept
in the model within the whole-record check's tolerance, the rivals the swap check ruled out, and a misfit left after
the causes. Each is '' when it has nothing to say."""

from __future__ import annotations

from .cause_words import cause_words, f_steps
from .diagnosis import Diagnosis
from .rival_swaps import WITHOUT
from .verdict import DROP_FRACTION, FORM_SHIFT
from .whole_record import CHANNEL_LABELS


def by_weight_clause(dg: Diagnosis) -> str:
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


def superfluous_clause(dg: Diagnosis) -> str:
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


def within_tolerance_clause(dg: Diagnosis) -> str:
    """' Also in the model, not named: X, f a -> b; ...' for each mechanism a later round kept in the model within the
    whole-record check's tolerance (``Verdict.within_tolerance``); '' when none."""
    kept = [(cause, a, b) for (cause, a, b), v in zip(f_steps(dg), dg.verdicts) if v.within_tolerance]
    if not kept:
        return ""
    what = "; ".join(f"{cause_words(cause, dg)}, f {a:.3f} -> {b:.3f}" for cause, a, b in kept)
    return (f" Also in the model, not named: {what}; the whole-record check no longer flagged the model without it "
            f"and it moves f by less than the {100 * FORM_SHIFT:.1f} % the whole-record models' form allows "
            f"(it takes up where two simulators of the same test differ).")


def _other_causes(dg: Diagnosis, k: int) -> str:
    """'clearance, plug_friction': the mechanisms of the final model besides round ``k``'s candidate fitted in turn."""
    return ", ".join(c.mechanism.name for j, c in enumerate(dg.causes) if j != k)


def swapped_clause(dg: Diagnosis) -> str:
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


def remaining_clause(dg: Diagnosis) -> str:
    """' A misfit remains with them (on the ... gauge, ... phase) that no further cause explains clearly (candidates:
    ...).' when the round after the last cause found the misfit the check still flags unexplained; '' otherwise."""
    last = dg.verdicts[-1] if len(dg.verdicts) > 1 else None
    if last is None or last.kind != "unexplained":
        return ""
    cells = dg.misfits[-1].flagged() if dg.misfits else []
    where = f" on the {CHANNEL_LABELS.get(cells[0].channel, cells[0].channel)} gauge, {cells[0].phase} phase" \
        if cells else ""
    by = {c.label: c.variant for c in last.candidates}
    listed = [by[label] for label in last.members if label in by]  # not a model the record rules out
    return (f" A misfit remains with them{where} that no further cause explains clearly"
            f"{' (candidates: ' + ', '.join(listed) + ')' if listed else ''}.")


def joint_clause(dg: Diagnosis) -> str:
    """' Named together: X and Y; ...' for a round whose two leading candidates, neither passing the naming rule alone,
    explain its misfit together and whose next round named the second on top of the first (:mod:`.joint_round`); ''
    when none."""
    out = []
    for k, v in enumerate(dg.verdicts[:len(dg.causes)]):
        if v.joint is None or k + 1 >= len(dg.causes):
            continue
        a, b = dg.causes[k].label, v.joint.partner
        ea, eb = v.joint.against[a], v.joint.against[b]
        alone = {c.variant: c for c in v.candidates}
        out.append(f" Named together: {a} and {b}. In round {k + 1} neither alone explained the misfit by the naming "
                   f"rule ({a} {alone[a].delpd:.0f} +- {alone[a].se:.0f} nats, {b} {alone[b].delpd:.0f} +- "
                   f"{alone[b].se:.0f}, each not decisive without the {100 * DROP_FRACTION:.0f} % of blocks most in its "
                   f"favour); fitted together they lead {a} alone by {ea[0]:.0f} +- {ea[1]:.0f} nats and {b} alone by "
                   f"{eb[0]:.0f} +- {eb[1]:.0f} ({ea[2]:.0f} +- {ea[3]:.0f} and {eb[2]:.0f} +- {eb[3]:.0f} without "
                   f"their best blocks), rule out every other mechanism, and round {k + 2} named {b} on top of {a} by "
                   f"the rule.")
    return "".join(out)


def pair_refused_clause(dg: Diagnosis) -> str:
    """' Fitted together, X and Y do not explain it either: ...' where the first round's two leading candidates were
    fitted together and refused (:mod:`.joint_round`), or ' ... pass the naming rule, but round 2 did not name Y on
    top of X (...)' where the next round did not confirm them; the round stayed unexplained. '' otherwise."""
    t = dg.pair_tried
    if t is None or t.refused is None:
        return ""
    if t.admitted:
        return f" Fitted together, {t.causes[0]} and {t.causes[1]} pass the naming rule, but {t.refused}."
    return f" Fitted together, {t.causes[0]} and {t.causes[1]} do not explain it either: {t.refused}."
