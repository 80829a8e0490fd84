"""A candidate fitted in turn, checked against the rivals its round left open, with the later causes in the model.

A round of candidates puts its best in the model and the search goes on (:mod:`.diagnose`). When a later round
names a further cause, the first round's question (which of the candidates explains the record?) can be asked
again with that cause in the model. On a 1-D record with a clearance and dispersion, dispersion, a channel's
timing and an amplifier's bandwidth explain the first misfit about alike, since the clearance's own signature sits
at the same fronts; with the clearance in the model, the candidates part.

For each rival a round left open, :func:`check_swaps` fits the final model with the candidate fitted in turn
replaced by the rival (the other causes kept, but a later cause of the rival's group: below) and asks the
naming rule's question of the final model against each such swap (:meth:`.verdict.NamingRule.ruling`: decisively
better, or by the weight route, the stacking weights taken over the final model and its swaps). A rival ruled out
is resolved (``Verdict.resolved``); when every open rival of a round is, the candidate fitted in turn is named
(``Diagnosis.named_causes``).

The candidate must also still earn its place: the final model without it (:data:`WITHOUT`, the other causes
kept) must be ruled out the same way, or no rival of its round is resolved. On an axisymmetric record with a slip
law and plug friction, a zero drift was fitted in turn among candidates (the plug friction, a channel's timing),
the plug friction was named in the next round, and the timing swapped in explained the record worse; but with the
plug friction in the model the zero drift was not needed, and without this test it would have been named.

And the model without it must miss the record by more than two simulators of the same test differ: the whole-record
check (:mod:`.misfit`, the first round's misfit gate, its tolerance calibrated on records the 1-D model did not make)
must flag it (``flagged``). On another axisymmetric record with the same pair, the zero drift still gained
125 +- 33 nats with the slip law and the plug friction in the model: a flexible transient on the hoop gauge absorbs
where the axisymmetric cell's hoop strain departs from the 1-D model's, which the ELPD rule sees as evidence and the
check's tolerance forgives.

Asked only of a round followed by a later cause: for the last cause's round the swap is the round's own
comparison, already judged. The weight route is the naming rule's own, its 90 % guard included (the weight of the
swaps the final model rules out set aside first, :meth:`.verdict.NamingRule.rulings`). A rival of the
same group as a later cause (a second friction law) cannot join the model beside it: it is swapped in for the
candidate *and* that cause, and must stand in for both (on the bundled B-02, the slip law, a rival of the first
round's dispersion, against the velocity law named later). Before, such a rival could not be asked and kept its
round open. A rival the final model does not rule out stays open.

A round whose rivals later rounds all named has no rival to swap in, but its candidate must earn its place just the
same: a rival named later may be what the candidate stood for. The model without it is then fitted alone and must
be ruled out by the naming rule; the check's flag is recorded but not asked. With every rival in the model the round
is a later round of its own, and later rounds name by evidence alone: on the bundled records of set-up B the third
round's candidates are the plug friction and the velocity weakening, both there, and the fourth names the one not
fitted in turn by its evidence alone; the one fitted in turn is 133-165 (+- 24-35) nats better than the model
without it, which the check does not flag. Asking the gate of it alone would name one of two real causes and drop
the other by the order they were fitted in. A candidate that fails its test is *superfluous*
(``Verdict.superfluous``): not named. Where no round leaves a rival open, f is then the stacking mixture of the
final model and the check's models of its round (the model without it, the rivals swapped in), every one of which
holds the later causes, less those the final model rules out by the package's rule
(:func:`~.candidates_mixture.superfluous_mixture`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from ..stats import RULE
from ..stats.trimmed import points_to_drop
from .candidates_mixture import open_rivals
from .block_loo import elpd_difference
from .extended import Diagnoser, ModelFit, Variant
from .verdict import NamingRule, Verdict, round_weights

#: The ``rival`` of the swap that leaves the candidate out (the final model without it).
WITHOUT = "(without it)"


@dataclass(frozen=True)
class Swap:
    """The final model against one swap: the round, the rival (its label in that round), the swapped model's label,
    the final model's dELPD over it +- SE, the swap's stacking weight beside the final model and the other swaps,
    how the final model rules it out ("elpd", "weight" or None: it does not), and for the model without the
    candidate whether the whole-record check flags it (None: not asked, for a rival or when it is not ruled out)."""

    round: int
    rival: str
    model: str
    delpd: float
    se: float
    weight: float
    ruling: str | None
    flagged: bool | None = None


def swap_jobs(causes: list[Variant], verdicts: list[Verdict],
              rounds: list) -> list[tuple[int, str, tuple[Variant, ...]]]:
    """(round, rival label, the final model's variants with the round's candidate replaced by the rival:
    :func:`swapped`) for each rival a round of candidates left open, after (round, :data:`WITHOUT`, the variants
    without the candidate) for each round of candidates followed by a later cause (module docstring)."""
    if len(causes) < 2:
        return []
    out = []
    for k, verdict in enumerate(verdicts[:len(causes) - 1]):  # the last cause's round has no later cause
        if verdict.kind != "candidates":
            continue
        fits = {r.fit.label: r.fit for r in rounds[k]}
        swaps = [(k, label, swapped(causes, k, fits[label].variants[-1])) for label in open_rivals(verdict, causes)]
        out += [(k, WITHOUT, tuple(causes[:k]) + tuple(causes[k + 1:])), *swaps]
    return out


def swapped(causes: list[Variant], k: int, rival: Variant) -> tuple[Variant, ...]:
    """The causes with the k-th replaced by ``rival``; a later cause of the rival's group (a second friction law)
    leaves with it, since one model holds one law of a group: the rival must then stand in for both."""
    group = rival.mechanism.group
    return tuple(rival if j == k else v for j, v in enumerate(causes)
                 if j == k or group is None or v.mechanism.group != group)


def swap_start(final: ModelFit, rounds: list, causes: list[Variant], k: int, label: str,
               variants: tuple[Variant, ...]) -> dict[str, float]:
    """Where a swap's mode search starts: the final model's mode; where the swap took out a cause of the rival's group
    (one friction law for another: f and the law's parameters mean other things), f and the rival's parameters from
    the rival's own fit in round k."""
    start = dict(final.fit.mode)
    if label == WITHOUT or len(variants) == len(causes):
        return start
    own = next(r.fit for r in rounds[k] if r.fit.label == label)
    names = ("f", *(p.name for p in own.variants[-1].mechanism.parameters))
    return start | {n: own.fit.mode[n] for n in names if n in own.fit.mode}


def check_swaps(dg: Diagnoser, final: ModelFit, causes: list[Variant], verdicts: list[Verdict], rounds: list, *,
                rule: NamingRule, flagged: Callable[[ModelFit], bool], workers: int,
                seed: int) -> tuple[list[Verdict], tuple[Swap, ...], tuple[ModelFit, ...]]:
    """The verdicts with each round's rivals that the final model rules out against their swaps marked resolved, or
    the round marked superfluous, every swap's comparison and each swap's fitted model, in the same order (module
    docstring). ``flagged``: the whole-record check's decision on a fitted model (True: a misfit beyond the
    tolerance), asked of a model without a candidate that the final model rules out."""
    jobs = swap_jobs(causes, verdicts, rounds)
    if not jobs:
        return verdicts, (), ()
    fits = dg.fit_many([(variants, swap_start(final, rounds, causes, k, label, variants),
                         "+".join(v.label for v in variants)) for k, label, variants in jobs], workers=workers,
                       cut=False)  # the cut for a swap's model only where a mixture reports its f
    weights = round_weights(final, fits, seed)
    against = {f.label: elpd_difference(final.elpd, f.elpd) for f in fits}  # the final model's lead on each swap
    behind = {"reference": 0.0} | {label: d for label, (d, _) in against.items()}
    drop = points_to_drop(len(final.elpd.pointwise), rule.drop_fraction)
    # as in a round: a swap the final model rules out pushes no other out of the mass the weight guards
    how_each = rule.rulings(final.elpd, {f.label: f.elpd for f in fits}, weights, behind, drop,
                            worse=[label for label, (d, se) in against.items() if RULE.decisive(d, se)])
    swaps = []
    for (k, label, _), f in zip(jobs, fits):
        d, se = against[f.label]
        how = how_each[f.label]
        misfit = flagged(f) if label == WITHOUT and how is not None else None
        swaps.append(Swap(k, label, f.label, d, se, weights[f.label], how, misfit))
    out = list(verdicts)
    for k in sorted({s.round for s in swaps}):
        mine = [s for s in swaps if s.round == k]
        without = next(s for s in mine if s.rival == WITHOUT)
        if without.ruling is None or (len(mine) > 1 and not without.flagged):
            # the candidate is not needed with the later causes in the model: nothing is resolved (the check's gate
            # is asked only where its round left a rival open that could stand in its place; module docstring)
            out[k] = replace(out[k], superfluous=True)
            continue
        done = tuple(s.rival for s in mine if s.rival != WITHOUT and s.ruling is not None)
        out[k] = replace(out[k], resolved=out[k].resolved + done)
    return out, tuple(swaps), tuple(fits)
