"""What one round of ``diagnose`` may say: a cause named, a few candidates none of which the record
separates, an unexplained misfit, or nothing to explain.

A reviewer of a paper that says "the cause was plug friction" asks three things, and the verdict
answers each before it names a mechanism:

1. **Is the evidence decisive against the simple model?** dELPD over the reference model beyond the
   package's rule (:data:`friction_uq.stats.RULE`: above 4 and above 2 standard errors), over the whole
   record or over the record without the blocks that favour the mechanism most (the comparison of 2.). A
   mechanism that gains thousands of nats at a few fronts has a standard error as large (axisymmetric
   records: a clearance 9995 +- 5702 nats, 463 +- 119 without its 5 % best blocks); asked over the whole
   record only, more evidence at the fronts would turn a pass into a fail.
2. **Is it spread over the record?** The same comparison with the blocks that favour the mechanism
   most left out (:func:`friction_uq.stats.trimmed.trimmed_difference`, ``drop_fraction`` of the
   blocks) must still pass the rule. Two simulators of the same test differ in a few blocks (the
   fronts' timing, the plug's impact); a mechanism with a flexible transient collects thousands of
   nats there from a record that has nothing of it, with a standard error as large as the estimate.
3. **Is it decisive against every rival?** The best such mechanism must rule out each other mechanism:
   beat it by the same rule, over the whole record or without the blocks most in its favour against that rival
   (as in 1.: an axisymmetric clearance led a zero drift by 1124 +- 652 nats over the record and by 57 +- 25 without
   its 5 % best blocks against it; asked over the whole record only, more evidence at the fronts would keep the rival
   open), or (``by_weight``) lead it by more than 4 nats with the blocks that favour the
   best most left out (the spread test's share) while the rival, with the mechanisms as far behind that
   predict alike with it, carries less than 0.1 of the stacking weight and is not among the models that carry
   90 % of it (:meth:`friction_uq.stats.WeightRule.ruled_out`, the route the campaign's law comparison takes),
   the weight of the models the record rules out against the reference set aside (:func:`weights_kept`).
   Otherwise the record does not separate them.
   The SE of a sum over hundreds of blocks is dominated by the few where two mechanisms part (a front, the
   unloading): a second cause behind a first one leads its rivals by tens of nats spread over the record and
   holds the whole weight, yet stays within 2 SE.

Beside dELPD, the stacking weights of the reference and every candidate (stacking over the blocks,
:func:`friction_uq.stats.stacking_weights`) say how the record shares its support among them.

A mechanism is named only of a misfit: the whole-record check must find that the reference misses the
record beyond what two simulators of the same test differ by (its tolerance). On clean records of the
axisymmetric simulation a mechanism passes 1-3 on 2 of 32 records without such a misfit (a clearance, a
dispersion on strongly coloured noise), and a real one does too (a plug friction the check missed).

Verdicts (:class:`Verdict`): ``named`` (one mechanism passes all three, of a misfit); ``candidates``
(several pass 1 and 2, none beats the others); ``unexplained`` (the whole-record check says the reference
misses the record, no mechanism passes); ``unconfirmed`` (a mechanism passes, but the check finds no
misfit: not named); ``none`` (no mechanism passes, no misfit: the simple model stands). Under
``candidates``, ``unexplained`` and ``unconfirmed`` the f to quote is the stacking mixture of the models
that carry the weight, less those the record rules out (:attr:`Verdict.members`; :func:`mixture_draws`), mixed in
equal parts with the stationary analysis' f when ``run`` gives its draws (:mod:`.candidates_mixture`): its
interval holds the truth whichever of them is right.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import norm

from ..quoted import WHOLE_RECORD_MODEL_FORM
from ..stats import RULE, WeightRule, stacking_weights
from ..stats.trimmed import points_to_drop
from .joint_round import JointEvidence

#: The share of a record's blocks that the spread test leaves out (the most favourable to the mechanism):
#: set on clean records of the axisymmetric simulation and of the perturbed 1-D one against records with one
#: hidden mechanism (``benchmarks/verdict_records.py``, ``benchmarks/bench_verdict.py``; docs/trust.md).
DROP_FRACTION = 0.05
REQUIRE_MISFIT = True
AGAINST_ALL = True
BY_WEIGHT = True
#: How the stacking weights read (mass 0.9 supported, under 0.1 little): the campaign's values.
WEIGHT_RULE = WeightRule()
#: How far a later round's entry of the measurement chain must move f's median, relative, to be named where the
#: whole-record check no longer flags the round's reference: the 90 % half-width of the whole-record models' form term in f
#: (:data:`friction_uq.quoted.WHOLE_RECORD_MODEL_FORM`, 2.5 %, set on clean records of the axisymmetric simulation).
FORM_SHIFT = float(norm.ppf(0.95)) * WHOLE_RECORD_MODEL_FORM


@dataclass(frozen=True)
class Candidate:
    """One extended model against the round's reference: evidence, its spread, its stacking weight."""

    label: str
    mechanism: str
    channel: str | None
    delpd: float
    se: float
    delpd_trimmed: float
    se_trimmed: float
    weight: float
    #: decisive against the reference by the package's rule over the whole record, or without the blocks that
    #: favour it most (module docstring, 1.)
    decisive: bool
    #: decisive without the blocks that favour it most (module docstring, 2.)
    spread: bool

    @property
    def passes(self) -> bool:
        return self.decisive and self.spread

    @property
    def decisively_worse(self) -> bool:
        """The record rules the model out against the round's reference: its dELPD is decisively negative by the
        package's rule. Stacking may still give such a model weight, from the few blocks it alone predicts (a bars'
        dispersion at sharp fronts, 5000 nats worse over the record), but its f, fitted to a record it misses, is no
        answer for the record: it is no member of f's mixture (:attr:`Verdict.members`)."""
        return RULE.decisive(-self.delpd, self.se)

    @property
    def variant(self) -> str:
        """The mechanism as fitted, a gain with its gauge (``gauge_gain[input_bar]``; ``Variant.label``'s form)."""
        return self.mechanism + (f"[{self.channel}]" if self.channel else "")


@dataclass(frozen=True)
class Verdict:
    """One round's verdict (module docstring)."""

    kind: str  # "named" | "candidates" | "unexplained" | "unconfirmed" | "none"
    candidates: tuple[Candidate, ...]  # every extended model, by dELPD
    weights: Mapping[str, float] = field(default_factory=dict)  # stacking weights: "reference" and each label
    named: str | None = None  # the label of the named model
    rivals: tuple[str, ...] = ()  # labels: under "candidates", the models that pass but are not separated
    dropped: int = 0  # blocks left out by the spread test
    #: labels of the models the named one rules out only by the weight route (not by 2 SE of dELPD)
    by_weight: tuple[str, ...] = ()
    #: labels of rivals a later check ruled out with the later causes in the model (:mod:`.rival_swaps`)
    resolved: tuple[str, ...] = ()
    #: the candidate fitted in turn is not needed with the later causes in the model: the model without it is not
    #: ruled out, or, where its round left a rival open, the whole-record check does not flag it
    #: (:mod:`.rival_swaps`); it is then not named
    superfluous: bool = False
    #: a later round's entry of the measurement chain that passes while the whole-record check does not flag the
    #: round's reference, and that moves f by less than the whole-record models' form term
    #: (:meth:`NamingRule.matters_for_f`): it stays in the model (the later rounds and the swap check see it), and is
    #: not named
    within_tolerance: bool = False
    #: the round was unexplained, and its two leading candidates fitted together explain it (:mod:`.joint_round`):
    #: ``named`` is the first of them, named with the next round's cause (the partner); None otherwise
    joint: JointEvidence | None = None

    @property
    def supported(self) -> list[str]:
        """The labels (``reference`` included) that carry the stacking weight (:class:`WeightRule`)."""
        return WEIGHT_RULE.supported(self.weights)

    @property
    def members(self) -> list[str]:
        """The labels (``reference`` among them) that may give f in the round's stacking mixture
        (:mod:`.candidates_mixture`): those that carry its weight, heaviest first, once the models the record rules
        out against the reference (:attr:`Candidate.decisively_worse`) are set aside (:func:`weights_kept`)."""
        kept = weights_kept(self.weights, (c.label for c in self.candidates if c.decisively_worse))
        return [k for k in WEIGHT_RULE.supported(kept) if kept[k] > 0.0]


def weights_kept(weights: Mapping[str, float], worse: Iterable[str]) -> dict[str, float]:
    """A round's stacking weights without the models the record rules out against the round's reference
    (``worse``: their labels, :attr:`Candidate.decisively_worse`), the rest scaled to sum to 1 (empty if nothing is
    left). Such a model's weight comes from a few blocks it alone predicts: it neither gives it a share of f
    (:attr:`Verdict.members`) nor pushes another model out of the mass that carries the weight, where the naming rule
    would no longer guard it (:meth:`NamingRule.rulings`)."""
    worse = set(worse)
    kept = {k: w for k, w in weights.items() if k not in worse}
    total = sum(kept.values())
    return {k: w / total for k, w in kept.items()} if total > 0.0 else {}


def ruled_out_against(reference, models: Sequence) -> list[str]:
    """The labels of ``models`` the record rules out against ``reference`` (each a fit with ``elpd`` and ``label``):
    the reference's dELPD over each decisive by the package's rule (:attr:`Candidate.decisively_worse` of a round's
    candidates); the swap check's models against the final model."""
    from .block_loo import elpd_difference

    return [m.label for m in models if RULE.decisive(*elpd_difference(reference.elpd, m.elpd))]


def _points(elpd) -> np.ndarray:
    """A model's pointwise values for stacking: its blocks, then its calibration data."""
    return np.concatenate([np.asarray(elpd.pointwise, float), np.asarray(elpd.calibration, float)])


@dataclass(frozen=True)
class NamingRule:
    """Reads a :class:`Verdict` from a round's fits (module docstring)."""

    drop_fraction: float = DROP_FRACTION
    #: name a cause only of a misfit the whole-record check found (its tolerance is what two simulators of the
    #: same test may differ by): without one, the simple model stands whatever a mechanism gains
    require_misfit: bool = REQUIRE_MISFIT
    #: the named model must beat every other extended model, not only those that pass the first two tests
    against_all: bool = AGAINST_ALL
    #: a rival may also be ruled out by the stacking weight (module docstring, 3.)
    by_weight: bool = BY_WEIGHT

    #: a later round names a mechanism its unflagged reference does not need only if it moves f by more than this
    form_shift: float = FORM_SHIFT

    def matters_for_f(self, reference_f: np.ndarray, f: np.ndarray) -> bool:
        """Whether an entry of the measurement chain that passes in a later round, while the whole-record check does
        not flag the round's reference, is named: only if it moves f's median (``f``: its model's draws,
        ``reference_f``: the reference's, both as reported) by more than :data:`FORM_SHIFT`. Such a round's evidence
        lies within what two simulators of the same test differ by, and an entry that changes one gauge's reading
        takes up that gauge's departure from the 1-D model: on records of the axisymmetric simulation such entries
        moved f by 0.5-2 % and were not there, where real second causes moved it by 16-41 % (docs/trust.md). One
        that does not matter for f stays in the model, not named (:attr:`Verdict.within_tolerance`)."""
        return moves_f(reference_f, f, self.form_shift)

    def candidate(self, fit, reference, delpd: float, se: float, weight: float) -> Candidate:
        """One model against the reference, with the spread test."""
        from .block_loo import elpd_difference

        drop = points_to_drop(len(reference.elpd.pointwise), self.drop_fraction)
        dt, set_ = elpd_difference(fit.elpd, reference.elpd, drop=drop)
        v = fit.variants[-1]
        spread = RULE.decisive(dt, set_)  # the left-out blocks favour it most: the whole record's sum is larger
        return Candidate(fit.label, v.mechanism.name, v.channel, delpd, se, dt, set_, weight,
                         RULE.decisive(delpd, se) or spread, spread)

    def judge(self, reference, ranked: Sequence, *, misfit: bool, seed: int = 0, first: bool = True) -> Verdict:
        """The verdict of one round: ``ranked`` the round's :class:`~.diagnose.Ranked` (fit, delpd, se), sorted
        by dELPD; ``misfit`` the whole-record check's decision on the reference; ``first``: the first round (the
        misfit gate decides whether there is anything to explain; once a cause is named, the next are judged by
        their evidence: on the bundled B-02 the misfit after two of its four causes is within the check's
        tolerance while the other two still move f by 10 %; ``diagnose`` names such a later cause only if it
        matters for f, :meth:`matters_for_f`)."""
        weights = round_weights(reference, [r.fit for r in ranked], seed)
        cands = tuple(self.candidate(r.fit, reference, r.delpd, r.se, weights[r.fit.label]) for r in ranked)
        drop = points_to_drop(len(reference.elpd.pointwise), self.drop_fraction)
        passing = [c for c in cands if c.passes]
        if not passing:
            return Verdict("unexplained" if misfit else "none", cands, weights, dropped=drop)
        best = passing[0]
        if self.require_misfit and first and not misfit:
            return Verdict("unconfirmed", cands, weights, named=best.label, dropped=drop)
        rivals, by_weight = self._rivals(best, cands, passing, {r.fit.label: r.fit for r in ranked}, weights, drop)
        # the same mechanism on another gauge is a doubt about the gauge, not about the cause
        others = [c for c in rivals if c.mechanism != best.mechanism]
        kind = "candidates" if others else "named"
        return Verdict(kind, cands, weights, named=best.label, rivals=tuple(c.label for c in rivals), dropped=drop,
                       by_weight=by_weight)

    def _rivals(self, best: Candidate, cands, passing, fits, weights, drop: int) -> tuple[list, tuple[str, ...]]:
        """The models ``best`` does not rule out (module docstring, 3.), and the labels of those it rules out
        only by the weight route."""
        behind = {"reference": best.delpd} | {c.label: best.delpd - c.delpd for c in cands}
        others = [c for c in (cands if self.against_all else passing) if c.label != best.label]
        how_each = self.rulings(fits[best.label].elpd, {c.label: fits[c.label].elpd for c in others}, weights,
                                behind, drop, worse=[c.label for c in cands if c.decisively_worse])
        rivals, light = [], []
        for c in others:
            how = how_each[c.label]
            if how is None:
                rivals.append(c)
            elif how == "weight":
                light.append(c.label)
        return rivals, tuple(light)

    def rulings(self, best, others: Mapping, weights: Mapping[str, float], behind: Mapping[str, float],
                drop: int, worse: Iterable[str] = ()) -> dict[str, str | None]:
        """How model ``best`` rules out each of ``others`` (label -> :class:`~.elpd.Elpd`), by :meth:`ruling`: each
        with the weight of the models that predict alike with it (``behind``: each label's ELPD behind the best),
        the models that carry 90 % of ``weights`` guarded (as in the campaign: the weight never rules them out).
        ``worse``: the labels of the models the record rules out against the reference, whose weight is set aside
        first (:func:`weights_kept`)."""
        weights = weights_kept(weights, worse) or weights
        carried = set(WEIGHT_RULE.supported(weights))
        return {label: self.ruling(best, other, weight=WEIGHT_RULE.alike_weight(weights, behind, label), drop=drop,
                                   carried=label in carried) for label, other in others.items()}

    def ruling(self, best, other, *, weight: float, drop: int, carried: bool = False) -> str | None:
        """How model ``best`` rules out ``other`` (their :class:`~.elpd.Elpd`): "elpd" (decisively, by the package's
        rule, over the whole record or without the ``drop`` blocks most in ``best``'s favour against ``other``: the
        whole record's sum is then larger still), "weight" (the weight route, module docstring 3.; ``weight``:
        ``other``'s with the models that predict alike with it) or None (it does not). ``carried``: ``other`` is
        among the models that carry 90 % of the weight (:meth:`WeightRule.supported`), which, as in the campaign,
        the weight never rules out."""
        from .block_loo import elpd_difference

        d, se = elpd_difference(best, other)
        rest, se_rest = elpd_difference(best, other, drop=drop)
        if RULE.decisive(d, se) or RULE.decisive(rest, se_rest):
            return "elpd"
        if carried:
            return None
        return "weight" if WEIGHT_RULE.ruled_out(weight, d, se, d_rest=rest if self.by_weight else None) else None


def moves_f(reference_f: np.ndarray, f: np.ndarray, shift: float = FORM_SHIFT) -> bool:
    """Whether a model's draws of f (``f``) put its median further from the reference's (``reference_f``) than
    ``shift``, relative: by default more than the 90 % half-width of the whole-record models' form term in f
    (:data:`FORM_SHIFT`), what two simulators of the same test may differ by."""
    ref = float(np.median(reference_f))
    return abs(float(np.median(f)) - ref) > shift * abs(ref)


def round_weights(reference, fits: Sequence, seed: int) -> dict[str, float]:
    """Stacking weights of the reference ("reference") and each fit, over the blocks and the calibration data
    they share (the calibration data are left out where the models do not all have the same)."""
    same = all(tuple(f.elpd.calibration_names) == tuple(reference.elpd.calibration_names) for f in fits)
    pts = _points if same else (lambda e: np.asarray(e.pointwise, float))
    pointwise = {"reference": pts(reference.elpd)} | {f.label: pts(f.elpd) for f in fits}
    # a record has hundreds of blocks: the plain stacking optimum is as steady as its Bayesian-bootstrap average
    # (within 0.03 on the calibration records), which a campaign of ten tests needs and which costs a minute here
    return stacking_weights(pointwise, bootstrap=0, seed=seed)


def mixture_draws(draws: Mapping[str, np.ndarray], weights: Mapping[str, float], *, n: int,
                  rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` draws of the stacking mixture: from each model a share of ``n`` in proportion to its weight
    (largest remainders), drawn without replacement where it has enough (with, where not). Returns the draws
    and, for each, the index of its model in ``draws``' order."""
    names = [k for k in draws if weights.get(k, 0.0) > 0.0]
    w = np.array([weights[k] for k in names], float)
    w = w / w.sum()
    counts = np.floor(w * n).astype(int)
    rest = n - counts.sum()
    counts[np.argsort(-(w * n - counts))[:rest]] += 1
    out, which = [], []
    order = list(draws)
    for k, c in zip(names, counts):
        x = np.asarray(draws[k], float)
        if c == 0:
            continue
        out.append(rng.choice(x, size=c, replace=c > x.size))
        which.append(np.full(c, order.index(k)))
    return np.concatenate(out), np.concatenate(which)
