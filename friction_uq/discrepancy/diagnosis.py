"""What ``diagnose`` found (:mod:`.diagnose`): each round's ranking of the extended models against its reference
(:class:`Ranked`), and the whole result (:class:`Diagnosis`) that the words, the f to quote, the JSON and the report
read."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..stats import RULE
from .candidates_mixture import named_causes, open_rivals, open_rounds
from .extended import ModelFit, Variant
from .front_delay import SharedDelay
from .joint_round import PairTrial
from .mechanisms import Context
from .misfit import MisfitDecision
from .record_likelihood import HOOP_GAIN_SD
from .rival_swaps import Swap
from .verdict import Verdict
from .whole_record import WholeRecord


@dataclass(frozen=True)
class Ranked:
    """A candidate against the reference model of its round; ``misfit``: the reference misses the
    record (the misfit decision), which admits the strong-evidence route of the rule."""

    fit: ModelFit
    delpd: float
    se: float
    misfit: bool = False

    @property
    def decisive(self) -> bool:
        """Decisive against the round's reference by the package's rule (the naming rule also asks that the
        evidence be spread over the record and beat every rival: :mod:`.verdict`)."""
        return RULE.decisive(self.delpd, self.se)


@dataclass(frozen=True)
class Diagnosis:
    """Everything ``diagnose`` found (module docstring)."""

    baseline: ModelFit
    rounds: tuple[tuple[Ranked, ...], ...]
    misfits: tuple[MisfitDecision, ...]
    causes: tuple[Variant, ...]
    not_separable: tuple[str, ...]
    separate_by: str | None
    final: ModelFit
    #: other gauges on which the first cause (a gauge_gain) explains the record about as well
    channels_not_separable: tuple[str, ...] = ()
    rms: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)
    seconds: float = 0.0
    baseline_comparison: WholeRecord | None = None
    final_comparison: WholeRecord | None = None
    #: the hoop gauge's calibration factor as the whole-record check reads it (f and nu free only: the model
    #: the misfit decision judges), when ``run`` made the check
    check_hoop_gain: float | None = None
    #: the hoop gauge's factor known beforehand (median, relative sd) every model read it with (a prior file's)
    hoop_calibration: tuple[float, float] = (1.0, HOOP_GAIN_SD)
    #: the final model's normal approximation against its exact posterior (:func:`.exact_model.exact_posterior`),
    #: when a cause was named: Pareto k, the kept draws' effective sample size, how the exact draws were obtained
    #: (friction_uq.stats.exact: "importance", "importance (second proposal)" or "emcee") and whether they reached
    #: the floor on their effective sample size within the caps
    pareto_k: float = float("nan")
    importance_ess: float = float("nan")
    posterior_method: str | None = None
    posterior_converged: bool = True
    #: the stationary window's means the mechanisms' f_effective is stated at, and the seed: what the prior of
    #: f_effective (:mod:`.effective_prior`) is computed from when the draws are written
    context: Context | None = None
    seed: int = 0
    #: each round's verdict (:mod:`.verdict`): the first says whether a cause was named, or candidates, or an
    #: unexplained misfit
    verdicts: tuple[Verdict, ...] = ()
    #: no cause named but candidates or an unexplained misfit, a cause fitted in turn whose rivals stay open, or
    #: further mechanisms carrying the last round's weight: f's draws from the stacking mixture of the models that
    #: carry the weight less those the record rules out (``Verdict.members``), their labels and weights
    #: ("reference": the model without causes; "stationary": the stationary analysis' draws, half the weight when
    #: nothing is named and run gave them)
    mixture_f: np.ndarray | None = None
    mixture_weights: dict[str, float] = field(default_factory=dict)
    #: for each mixture draw, the index (in mixture_weights' order) of the model it was drawn from
    mixture_source: np.ndarray | None = None
    #: the candidates fitted in turn against the rivals their rounds left open and against the model without them,
    #: with the later causes in the model (:mod:`.rival_swaps`; the verdicts' ``resolved`` holds the rivals ruled out,
    #: ``superfluous`` whether the candidate was needed)
    swaps: tuple[Swap, ...] = ()
    #: each swap's fitted model, in ``swaps``' order (when a candidate is superfluous, those the final model does not
    #: rule out are members of f's mixture)
    swap_models: tuple[ModelFit, ...] = ()
    #: which mixture gives f: "candidates" (the first round names none), "rivals" (a round's rivals left open),
    #: "further" (the last round's weight on further mechanisms), "superfluous" (a candidate fitted in turn not
    #: needed: the final model and the swap check's models of its round), or None (f is the final model's)
    mixture_of: str | None = None
    #: the delay on one gauge that the first round's candidates agree on, when the record does not tell apart
    #: delay-like faults of the measurement chain (:mod:`.front_delay`); None otherwise
    shared_delay: SharedDelay | None = None
    #: the stationary analysis' draws of f with nu from the prior file alone (given the bars' header values), when
    #: ``run`` found the hoop gauge and nu's prior in disagreement (friction_uq.hoop_or_prior): every model here
    #: reads nu through the hoop gauge as well, so the f to quote holds the diagnosed f and these in equal parts
    #: (:func:`.diagnosed_f.f_draws_to_quote`); None otherwise
    f_prior_nu: np.ndarray | None = None
    #: the first round's two leading candidates fitted together where neither alone explained its misfit, named
    #: together or not, and why not (:mod:`.joint_round`); None when no pair was tried
    pair_tried: PairTrial | None = None

    @property
    def verdict(self) -> Verdict | None:
        return self.verdicts[0] if self.verdicts else None

    @property
    def named_causes(self) -> tuple[Variant, ...]:
        """The causes the record names: each round's named cause, and a round's best candidate whose rivals
        later rounds named (they were second causes, not alternatives); not a candidate fitted in turn whose
        rivals stay open or that the later causes made superfluous (``causes`` holds every mechanism of the final
        model)."""
        return tuple(named_causes(self.causes, self.verdicts))

    @property
    def open_candidates(self) -> tuple[str, ...]:
        """The mechanisms (a gain with its gauge: ``gauge_gain[input_bar]``) of the first round of candidates no
        later round told apart, the one fitted in turn first, then its open rivals (not named in a later round nor
        ruled out by the swap check), whose stacking mixture gives f; () when none."""
        rounds = open_rounds(self.causes, self.verdicts)
        if not rounds:
            return ()
        v = self.verdicts[rounds[0]]
        by = {c.label: c.variant for c in v.candidates}
        return tuple(by[label] for label in (v.named, *open_rivals(v, self.causes)))

    @property
    def superfluous(self) -> tuple[str, ...]:
        """The candidates fitted in turn that the later causes made superfluous (:mod:`.rival_swaps`; not named), as
        their variants' labels."""
        return tuple(self.causes[k].label for k, v in enumerate(self.verdicts[:len(self.causes)]) if v.superfluous)

    @property
    def within_tolerance(self) -> tuple[str, ...]:
        """The mechanisms later rounds kept in the model within the whole-record check's tolerance, not named
        (``Verdict.within_tolerance``), as their variants' labels."""
        return tuple(self.causes[k].label for k, v in enumerate(self.verdicts[:len(self.causes)])
                     if v.within_tolerance)

    @property
    def cause(self) -> Variant | None:
        """The first named cause (None when the record names none)."""
        named = self.named_causes
        return named[0] if named else None

    @property
    def ranking(self) -> tuple[Ranked, ...]:
        return self.rounds[0] if self.rounds else ()
