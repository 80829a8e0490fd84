"""f when a record does not single out its causes: the stacking mixture of the candidates.

A round whose verdict is candidates, unexplained or unconfirmed (:mod:`.verdict`) gives f as the mixture of
the models that carry its stacking weight; a round of candidates whose best was fitted in turn (to look for a
second cause) but whose rivals no later round put in the model leaves them open: f is then the mixture of the
final model and those rivals (:func:`rival_mixture`), and the candidate fitted in turn is not named
(``Diagnosis.named_causes``). After the last cause, a round that names nothing more may still find that the
record's stacking weight lies on further mechanisms, none of which passes the naming rule, that are decisively
better than the model with the causes (their evidence sits in a few blocks) or that would move f beyond the
whole-record models' form term: f is then the mixture of the final model and those mechanisms
(:func:`further_mixture`), not the final model's alone, whose interval would hold the truth only if nothing more
were there. Where a round's rivals are left open as well, those further mechanisms stand for the final model in its
share of the rivals' mixture (:func:`further_members`): the record tells neither which candidate is right nor
whether the further mechanism is there. A model the record rules out against its round's reference is never a
member of a mixture (``Verdict.members``), whatever stacking weight its few blocks earn it.

When no cause is named at all (the first round's candidates, unexplained or unconfirmed, or candidates fitted
in turn whose rivals stay open and no cause besides), the whole-record models
are not the only answer: the stationary analysis reads f from the window's levels with eq. 17's model-form term,
while every whole-record model, the reference among them, carries the 1-D model's form over the whole record, and
on records of another simulation a mechanism may take the weight by absorbing that form (an input bar's gain, a
clearance) and move f with it. The two answers rest on different parts of the record and no likelihood weighs one
against the other, so f is then their equal mixture (:data:`STATIONARY_SHARE`, a convention, not a fitted value):
the stationary analysis' draws for one half, the stacking mixture of the candidates for the other
(:func:`mixture` and :func:`rival_mixture`, ``stationary_f``; measured in docs/trust.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..stats.streams import stream
from .extended import ModelFit, Variant
from .verdict import Verdict, mixture_draws, moves_f, round_weights, ruled_out_against, weights_kept

#: Draws of the stacking mixture that gives f when no single cause is named.
MIXTURE_DRAWS = 1000
#: The label of the stationary analysis' f as a member of a mixture (module docstring).
STATIONARY = "stationary"
#: Its share of the f to quote when no cause is named: the two analyses in equal parts (module docstring).
STATIONARY_SHARE = 0.5

#: A mixture member's model with its f as reported (``Diagnoser.resolved``: the cut posterior's under ``nu_cut``).
Resolve = Callable[[ModelFit], ModelFit]
#: A mixture's members before it is drawn: each label's draws of f, and its weight.
Members = tuple[dict[str, np.ndarray], dict[str, float]]


def _as_fitted(mf: ModelFit) -> ModelFit:
    """The model as fitted (no cut is made)."""
    return mf


def unresolved_rounds(causes, verdicts) -> tuple[int, ...]:
    """The rounds whose verdict was candidates and one of whose rivals is a mechanism no round put in the
    model (an alternative to the candidate fitted in turn, not a second cause): the record does not tell them
    apart; and the rounds whose candidate the later causes made superfluous (``Verdict.superfluous``,
    :mod:`.rival_swaps`). A rival that is the same mechanism on another gauge does not count (the mechanism is
    named, its gauge uncertain)."""
    return tuple(k for k, verdict in enumerate(verdicts) if verdict.superfluous or open_rivals(verdict, causes))


def open_rounds(causes, verdicts) -> tuple[int, ...]:
    """The rounds of candidates with a rival still open (:func:`open_rivals`): the record does not tell them apart."""
    return tuple(k for k, verdict in enumerate(verdicts) if open_rivals(verdict, causes))


def open_rivals(verdict: Verdict, causes) -> list[str]:
    """The labels of a round of candidates' rivals whose mechanism no round put in the model and that no later check
    ruled out (``Verdict.resolved``, :mod:`.rival_swaps`) ([] otherwise)."""
    if verdict.kind != "candidates":
        return []
    named = {v.mechanism.name for v in causes}
    by = {c.label: c.mechanism for c in verdict.candidates}
    return [label for label in verdict.rivals if by[label] not in named and label not in verdict.resolved]


def named_causes(causes, verdicts) -> list:
    """The causes a record names: all but the candidates fitted in turn whose rivals stay open
    (:func:`unresolved_rounds`; ``Diagnosis.named_causes``) and the mechanisms a later round kept in the model
    within the whole-record check's tolerance (``Verdict.within_tolerance``)."""
    open_rounds = set(unresolved_rounds(causes, verdicts))
    return [v for k, v in enumerate(causes) if k not in open_rounds and not verdicts[k].within_tolerance]


def rival_mixture(final: ModelFit, rounds: list, verdicts: list[Verdict], causes: list[Variant], seed: int,
                  stationary_f: np.ndarray | None = None, resolve: Resolve = _as_fitted,
                  further: Members | None = None) -> tuple[np.ndarray | None, dict[str, float], np.ndarray | None]:
    """When a round named its cause among candidates and a rival mechanism was never named in a later round (it
    is an alternative, not a second cause), f's draws from the mixture of the final model and those rivals'
    fits, weighted by the first such round's stacking weights; (None, {}, None) when every rival was resolved.
    ``stationary_f``: the stationary analysis' draws, given half the weight when the record names no cause
    (module docstring). ``resolve``: a member's model with its f as reported (``Diagnoser.resolved``).
    ``further``: the last round's further members (:func:`further_members`), which stand for the final model in
    its share: the record cannot tell whether they are in the model with the causes either, and they move its f."""
    for k in open_rounds(causes, verdicts)[:1]:
        verdict = verdicts[k]
        left = open_rivals(verdict, causes)
        fits = {r.fit.label: r.fit for r in rounds[k]}
        own = further or ({final.label: final.f_effective}, {final.label: 1.0})
        share = verdict.weights[verdict.named] / sum(own[1].values())
        draws = own[0] | {label: resolve(fits[label]).f_effective for label in left}
        w = {label: share * x for label, x in own[1].items()} | {label: verdict.weights[label] for label in left}
        if sum(w.values()) <= 0.0:
            w = {label: 1.0 for label in w}
        if not named_causes(causes, verdicts):
            draws, w = _with_stationary(draws, w, stationary_f)
        return draw_mixture(draws, w, seed)
    return None, {}, None


def superfluous_mixture(final: ModelFit, checked: Sequence[ModelFit], seed: int, resolve: Resolve = _as_fitted
                        ) -> tuple[np.ndarray | None, dict[str, float], np.ndarray | None]:
    """When a candidate fitted in turn is superfluous (:mod:`.rival_swaps`) and no round leaves a rival open: f's
    draws from the stacking mixture of the final model and ``checked``, the swap check's models of that round (the
    final model without the candidate, and the rivals swapped in), holding the later causes (a rival of a later
    cause's group replaces that cause too), weighted by one stacking over them, less the models the final model
    rules out by the package's rule (as :attr:`~.verdict.Verdict.members`: their weight from a few blocks gives them
    no share of f); (None, {}, None) without them."""
    if not checked:
        return None, {}, None
    kept = weights_kept(round_weights(final, list(checked), seed), worse := ruled_out_against(final, checked))
    kept = {final.label if k == "reference" else k: w for k, w in kept.items()}
    if sum(kept.values()) <= 0.0:
        kept = {final.label: 1.0} | {f.label: 1.0 for f in checked if f.label not in worse}
    draws = {final.label: final.f_effective} | {f.label: resolve(f).f_effective for f in checked if f.label in kept}
    return draw_mixture(draws, kept, seed)


def further_members(final: ModelFit, rounds: list, verdicts: list[Verdict], causes: list[Variant],
                    resolve: Resolve = _as_fitted) -> Members | None:
    """After at least one cause, when the last round named nothing (none, unexplained or unconfirmed) and the
    models that carry its stacking weight (``Verdict.members``) include further mechanisms that either have evidence
    over the model with the causes decisive by the package's rule (they fail the naming rule on its spread or on
    their rivals) or, without it, move f's median by more than the whole-record models' form term
    (:func:`~.verdict.moves_f`: the record cannot tell whether they are there, and f depends on it; on an
    axisymmetric pair record a plug friction behind a named slip law, 75 +- 43 nats, f 15 % lower and right): those
    mechanisms' fits and, where it carries weight (its own or lent, below), the final model (its exact posterior;
    the round's reference), as draws of f and the round's stacking weights; None when the final model carries the
    weight alone, when the models that share it with no decisive evidence give the final model's f (among models
    that predict alike stacking shares the weight at random), or when the last round named a cause.
    The weight of a member with neither (it predicts alike with the final model and gives its f) goes to the final
    model, so that a member that moves f keeps its own share and no more."""
    if not causes or len(verdicts) <= len(causes) or verdicts[-1].kind not in ("none", "unexplained", "unconfirmed"):
        return None
    verdict = verdicts[-1]
    decisive = {c.label for c in verdict.candidates if c.decisive}
    fits = {r.fit.label: r.fit for r in rounds[-1]}
    draws, alike = {}, 0.0  # heaviest first, as the weights; the weight of the members that give the final f
    for label in verdict.members:
        if label == "reference":
            alike += verdict.weights[label]
            continue
        f = resolve(fits[label]).f_effective
        if label in decisive or moves_f(final.f_effective, f):
            draws[label] = f
        else:  # it predicts alike with the final model and gives its f: the final model's exact posterior stands for it
            alike += verdict.weights[label]
    if not draws:
        return None
    w = {label: verdict.weights[label] for label in draws}
    if alike > 0.0:
        draws, w = {final.label: final.f_effective} | draws, {final.label: alike} | w
    return draws, w


def further_mixture(final: ModelFit, rounds: list, verdicts: list[Verdict], causes: list[Variant],
                    seed: int, resolve: Resolve = _as_fitted
                    ) -> tuple[np.ndarray | None, dict[str, float], np.ndarray | None]:
    """f's draws from the mixture of the last round's further members (:func:`further_members`), their weights and
    each draw's model; (None, {}, None) without them."""
    members = further_members(final, rounds, verdicts, causes, resolve)
    return (None, {}, None) if members is None else draw_mixture(*members, seed)


def mixture(base: ModelFit, ranked: Sequence, verdict: Verdict, seed: int, stationary_f: np.ndarray | None = None,
            resolve: Resolve = _as_fitted) -> tuple[np.ndarray | None, dict[str, float], np.ndarray | None]:
    """f's draws from the stacking mixture of the models that carry the weight (``Verdict.members``: not those the
    record rules out), their weights and each draw's model, when the first round named no single cause but found
    candidates, an unexplained misfit or an unconfirmed mechanism; (None, {}, None) otherwise. ``stationary_f``:
    the stationary analysis' draws of f, given :data:`STATIONARY_SHARE` of the weight beside the candidates' (module
    docstring)."""
    if verdict.kind not in ("candidates", "unexplained", "unconfirmed"):
        return None, {}, None
    fits = {"reference": base} | {r.fit.label: r.fit for r in ranked}
    keep = verdict.members
    w = {k: verdict.weights[k] for k in keep} if keep else {"reference": 1.0}  # all ruled out: the reference stands
    draws, w = _with_stationary({k: resolve(fits[k]).f_effective for k in w}, w, stationary_f)
    return draw_mixture(draws, w, seed)


def _with_stationary(draws: dict[str, np.ndarray], weights: dict[str, float], stationary_f: np.ndarray | None
                     ) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """The candidates' draws and weights with the stationary analysis' draws first, given
    :data:`STATIONARY_SHARE` of the weight, the candidates the rest in their proportions (unchanged without)."""
    if stationary_f is None:
        return draws, weights
    total = sum(weights.values())
    return ({STATIONARY: np.asarray(stationary_f, float)} | draws,
            {STATIONARY: STATIONARY_SHARE} | {k: (1.0 - STATIONARY_SHARE) * v / total for k, v in weights.items()})


def draw_mixture(draws: dict[str, np.ndarray], weights: dict[str, float],
                 seed: int) -> tuple[np.ndarray, dict[str, float], np.ndarray]:
    """:data:`MIXTURE_DRAWS` draws of the mixture (the "mixture" stream of ``seed``), the weights normalised, and
    each draw's model."""
    x, which = mixture_draws(draws, weights, n=MIXTURE_DRAWS, rng=stream(seed, "mixture"))
    total = sum(weights.values())
    return x, {k: v / total for k, v in weights.items()}, which
