"""Name the cause of a misfit: rank the extended models (:mod:`.extended`) by block-LOO ELPD, and read
each round's verdict with the naming rule of :mod:`.verdict`.

* a mechanism is named only when its dELPD over the reference model is decisive by the package's rule
  (above 4 and 2 standard errors), when it stays decisive with the blocks that favour it most left out
  (the evidence is spread over the record, not a few blocks at a front where two simulators of the same
  test differ), and when it rules out every other mechanism: by the same rule, or by the stacking weight
  (:mod:`.verdict`, 3.);
* several mechanisms that pass but do not rule each other out are *candidates*: the record does not tell
  them apart (``not_separable``, with what would separate them), and f is then the stacking mixture of
  the models that carry the weight; the same mechanism on another gauge (a gain) is named, its gauge
  listed as uncertain;
* a misfit of the reference model (the whole-record check's decision, :mod:`.misfit`) that no mechanism
  explains by that rule is *unexplained*: the candidates are listed with their stacking weights and f is
  their mixture's; a mechanism that passes without such a misfit is *unconfirmed*: not named, f from the
  mixture of it and the reference;
* after a named cause the search goes on with it in the model (the reference becomes baseline + cause),
  for at most four causes, so that a record with several effects gets them in order of evidence; it stops
  at the first round that names nothing. When that round's stacking weight lies on further mechanisms none of
  which it names, f is the mixture of them and the model with the causes (``further_mixture``): the final
  model alone would be quoted as if nothing more were there (on the bundled B-05 its interval sat 5 % above
  the true f, while the weight lay on the plug friction and the velocity weakening it hides).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from ..analysis import Prepared
from ..stats import RULE
from .elpd import elpd_difference
from .exact_model import exact_posterior
from .extended import Diagnoser, ModelFit, Variant, candidates
from .mechanisms import Context
from .misfit import MisfitDecision, decide, misfit_detected
from .candidates_mixture import (Resolve, further_mixture, mixture, named_causes, open_rivals, open_rounds,
                                 rival_mixture, superfluous_mixture)
from .rival_swaps import Swap, check_swaps, swap_jobs
from .verdict import NamingRule, Verdict
from .whole_record import WholeRecord, compare_whole_record

#: The naming rule of every round (:mod:`.verdict`).
NAMING = NamingRule()

MAX_CAUSES = 4
#: Processes fitting one round's extended models by default.
MAX_WORKERS = 4

#: What would separate two mechanisms that one record cannot.
SEPARATE_BY = {
    frozenset({"velocity_friction", "pressure_friction"}):
        "tests at another striker speed on another internal output bar (p and V rise together in one set-up)",
    frozenset({"velocity_friction", "slip_friction"}):
        "a test at another striker speed (slip and speed grow together through one test)",
    frozenset({"pressure_friction", "slip_friction"}):
        "a test at another striker speed (the load and the slip grow together through one test)",
    frozenset({"clearance", "end_friction"}):
        "the hoop gauge's start (a clearance delays it) or a test with another sample length",
    frozenset({"channel_timing", "bandwidth"}):
        "the amplifier's response to a sharp step (a calibration pulse through the channel) and the digitisers' "
        "trigger times",
    frozenset({"gauge_gain", "bar_modulus"}):
        "the bar's wave speed timed on the bar itself (a striker on the bar alone), and a shunt calibration of the "
        "gauge",
    frozenset({"channel_timing", "bar_modulus"}):
        "the bar's wave speed timed on the bar itself and the gauge's distance measured again",
    frozenset({"bandwidth", "dispersion"}):
        "the amplifier's response to a sharp step (dispersion is the bar's, the same on every amplifier)",
}
DEFAULT_SEPARATION = "another test of the campaign (another striker speed or another internal output bar)"


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
    #: carry the weight, their labels and weights ("reference": the model without causes; "stationary": the
    #: stationary analysis' draws, half the weight when nothing is named and run gave them)
    mixture_f: np.ndarray | None = None
    mixture_weights: dict[str, float] = field(default_factory=dict)
    #: for each mixture draw, the index (in mixture_weights' order) of the model it was drawn from
    mixture_source: np.ndarray | None = None
    #: the candidates fitted in turn against the rivals their rounds left open and against the model without them,
    #: with the later causes in the model (:mod:`.rival_swaps`; the verdicts' ``resolved`` holds the rivals ruled out,
    #: ``superfluous`` whether the candidate was needed)
    swaps: tuple[Swap, ...] = ()
    #: each swap's fitted model, in ``swaps``' order (members of f's mixture when a candidate is superfluous)
    swap_models: tuple[ModelFit, ...] = ()
    #: which mixture gives f: "candidates" (the first round names none), "rivals" (a round's rivals left open),
    #: "further" (the last round's weight on further mechanisms), "superfluous" (a candidate fitted in turn not
    #: needed: the final model and the swap check's models of its round), or None (f is the final model's)
    mixture_of: str | None = None

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
    def cause(self) -> Variant | None:
        """The first named cause (None when the record names none)."""
        named = self.named_causes
        return named[0] if named else None

    @property
    def ranking(self) -> tuple[Ranked, ...]:
        return self.rounds[0] if self.rounds else ()


def rank(reference: ModelFit, fits: list[ModelFit], *, misfit: bool = False) -> tuple[Ranked, ...]:
    out = [Ranked(f, *elpd_difference(f.elpd, reference.elpd), misfit=misfit) for f in fits]
    return tuple(sorted(out, key=lambda r: -r.delpd))


def separability(verdict: Verdict) -> tuple[tuple[str, ...], tuple[str, ...], str | None]:
    """Who explains the record about as well as the named model (the verdict's rivals): the mechanisms not
    separable from it (with it first; empty when none), the other gauges on which the same mechanism does (a
    gauge_gain: the mechanism is named, its gauge is not certain), and what would separate the mechanisms."""
    by = {c.label: c for c in verdict.candidates}
    best = by[verdict.named]
    close = [by[label] for label in verdict.rivals]
    channels = tuple(c.channel for c in close if c.mechanism == best.mechanism and c.channel)
    others = [c.mechanism for c in close if c.mechanism != best.mechanism]
    if not others:
        return (), channels, None
    names = tuple(dict.fromkeys([best.mechanism, *others]))
    return names, channels, SEPARATE_BY.get(frozenset(names[:2]), DEFAULT_SEPARATION)


@dataclass
class _Search:
    """The rounds of one diagnosis as they go: the reference model, the causes in it, each round's ranking,
    verdict and misfit decision, and what round 1 could not separate."""

    base: ModelFit
    reference: ModelFit
    causes: list[Variant] = field(default_factory=list)
    rounds: list[tuple[Ranked, ...]] = field(default_factory=list)
    verdicts: list[Verdict] = field(default_factory=list)
    misfits: list[MisfitDecision] = field(default_factory=list)
    not_sep: tuple[str, ...] = ()
    other_channels: tuple[str, ...] = ()
    separate_by: str | None = None


def diagnose(prep: Prepared, log_prior_f_nu: Callable[[Mapping[str, float]], float], start: Mapping[str, float], *,
             hoop: bool, seed: int, n_draws: int = 1000, progress: Callable[[str], None] | None = None,
             base_scales: Mapping[str, tuple[float, float]] | None = None, max_causes: int = MAX_CAUSES,
             workers: int | None = None, stationary_f: np.ndarray | None = None, nu_cut: bool = False) -> Diagnosis:
    """Fit the baseline and every mechanism, rank them and name the cause(s) (module docstring).

    ``base_scales``: Gaussian stand-ins (centre, sd in the unbounded coordinate) of the f and nu
    priors for the mode search. ``workers``: processes fitting a round's extended models and sharing the
    exact posterior's evaluations (None: the machine's cores, at most :data:`MAX_WORKERS`); the result does
    not depend on it. ``stationary_f``: the stationary analysis' draws of f, half of the f to quote when no cause
    is named (:mod:`.candidates_mixture`); None: the candidates' mixture alone. ``nu_cut``: the f of every model
    that f is reported from (the baseline, each round's reference, the final model, the mixtures' members) from the
    cut posterior, nu read from the record's stationary windows under the model (:mod:`.nu_cut`; the names are the
    joint fits'), the other candidates' f their joint fits' (``ModelFit.f_from``: the cut is made only where f is
    reported, half of a model's fitting time); False: f is each model's joint fit's.
    """
    t0 = time.perf_counter()
    if workers is None:
        workers = min(MAX_WORKERS, os.cpu_count() or 1)
    say = progress or (lambda msg: None)
    dg = Diagnoser(prep, log_prior_f_nu, hoop=hoop, seed=seed, n_draws=n_draws, base_scales=base_scales,
                   nominal=start, nu_cut=nu_cut)
    say(f"baseline (up to {max_causes} rounds of up to {len(candidates())} extended models follow)")
    base = dg.fit((), start, "baseline")
    st = _search(dg, prep, _Search(base, base), max_causes=max_causes, workers=workers, seed=seed, say=say, t0=t0)
    final, causes, rounds, verdicts = st.reference, st.causes, st.rounds, st.verdicts
    swaps: tuple[Swap, ...] = ()
    checked: tuple[ModelFit, ...] = ()
    if swap_jobs(causes, verdicts, rounds):
        say("the candidates fitted in turn against their open rivals and without them, with the later causes in the "
            "model")
        verdicts, swaps, checked = check_swaps(
            dg, final, causes, verdicts, rounds, rule=NAMING, workers=workers, seed=seed + len(rounds),
            flagged=lambda fit: misfit_detected(prep, dg.predictive(fit)))
    if st.not_sep and verdicts and 0 not in open_rounds(causes, verdicts):
        # the rivals of round 1 were second causes, named in later rounds, or ruled out with them in the model
        st.not_sep, st.separate_by = (), None
    say("posterior predictive of the final model")
    if causes and len(next(iter(final.predicted.values()))) == 1:  # the mode only: a cause of the last round
        final = replace(final, predicted=dg.predictive(final))
    a = compare_whole_record(prep, st.base.predicted)
    b = compare_whole_record(prep, final.predicted)
    k = ess = float("nan")
    method, converged = None, True
    mix, mix_w, mix_src = (None, {}, None) if causes or not verdicts else \
        mixture(st.base, rounds[0], verdicts[0], seed, stationary_f, resolve=dg.resolved)
    mixture_of = "candidates" if mix is not None else None
    if causes:
        say("the exact posterior of the model with the causes (importance sampling, emcee if it must)")
        final, ex = exact_posterior(dg, final, workers=workers)
        k, ess, method, converged = ex.pareto_k, ex.ess, ex.method, ex.converged
        mix, mix_w, mix_src, mixture_of = _mixture_after_causes(final, rounds, verdicts, causes, swaps, checked,
                                                                seed, stationary_f, dg.resolved)
    # the models whose f is reported (the reference models, the mixtures' members) with their cut posterior
    rounds = [[replace(r, fit=dg.known(r.fit)) for r in rnd] for rnd in rounds]
    checked = tuple(dg.known(m) for m in checked)
    return Diagnosis(baseline=st.base, rounds=tuple(rounds), misfits=tuple(st.misfits), causes=tuple(causes),
                     not_separable=st.not_sep, channels_not_separable=st.other_channels, separate_by=st.separate_by,
                     final=final, rms=residual_rms(a, b), seconds=time.perf_counter() - t0,
                     baseline_comparison=a, final_comparison=b, pareto_k=k, importance_ess=ess,
                     posterior_method=method, posterior_converged=converged, context=dg.context, seed=seed,
                     verdicts=tuple(verdicts), mixture_f=mix, mixture_weights=mix_w, mixture_source=mix_src, swaps=swaps,
                     swap_models=checked, mixture_of=mixture_of)


def _mixture_after_causes(final: ModelFit, rounds: list, verdicts: list, causes: list, swaps: tuple, checked: tuple,
                          seed: int, stationary_f: np.ndarray | None, resolve: Resolve) -> tuple:
    """f's mixture once causes were fitted, and which: a round's open rivals first, else the last round's further
    mechanisms, else a superfluous candidate's round (:mod:`.candidates_mixture`); (None, {}, None, None): f is the
    final model's."""
    mix, w, src = rival_mixture(final, rounds, verdicts, causes, seed, stationary_f, resolve)
    if mix is not None:
        return mix, w, src, "rivals"
    mix, w, src = further_mixture(final, rounds, verdicts, causes, seed, resolve)
    if mix is not None:
        return mix, w, src, "further"
    k = next((j for j, v in enumerate(verdicts[:len(causes)]) if v.superfluous), None)
    mix, w, src = superfluous_mixture(final, [m for s, m in zip(swaps, checked) if s.round == k], seed, resolve)
    return mix, w, src, ("superfluous" if mix is not None else None)


def _search(dg: Diagnoser, prep: Prepared, st: _Search, *, max_causes: int, workers: int, seed: int,
            say: Callable[[str], None], t0: float) -> _Search:
    """The rounds: each fits every mechanism not yet in the reference model on top of it, ranks them, and the
    naming rule judges; a named cause (or the best of candidates) joins the model and the next round begins."""
    fit_seconds, fitted = 0.0, 0  # process-seconds per extended model, for the progress lines' estimates
    for k in range(max_causes):
        say("misfit of the reference model")
        st.reference = replace(st.reference, predicted=dg.predictive(st.reference))
        if k == 0:
            st.base = st.reference
        st.misfits.append(decide(compare_whole_record(prep, st.reference.predicted)))
        used = tuple(v.mechanism.name for v in st.causes)
        jobs = [(tuple(st.causes) + (cand,), dict(st.reference.fit.mode),
                 "+".join([v.label for v in st.causes] + [cand.label])) for cand in candidates(exclude=used)]
        per_model = fit_seconds / fitted if fitted else None
        eta = f", about {per_model * len(jobs) / max(1, min(workers, len(jobs))):.0f} s" if per_model else ""
        say(f"round {k + 1}: {len(jobs)} extended models ({', '.join(j[2] for j in jobs)}) on {workers} "
            f"process(es){eta}; {time.perf_counter() - t0:.0f} s so far")
        t_round = time.perf_counter()
        fits = dg.fit_many(jobs, workers=workers, cut=False)  # the cut for the models whose f is reported only
        fit_seconds += (time.perf_counter() - t_round) * max(1, min(workers, len(jobs)))
        fitted += len(jobs)
        ranked = rank(st.reference, fits, misfit=st.misfits[-1].detected)
        st.rounds.append(ranked)
        verdict = NAMING.judge(st.reference, ranked, misfit=st.misfits[-1].detected, seed=seed + k, first=k == 0)
        st.verdicts.append(verdict)
        say(f"round {k + 1}: {verdict.kind}" + (f" ({verdict.named})" if verdict.named else ""))
        if verdict.named is not None and k == 0:
            st.not_sep, st.other_channels, st.separate_by = separability(verdict)
        if verdict.kind not in ("named", "candidates"):
            break
        # candidates: the best goes into the model all the same; a rival that is a second cause passes again in a
        # later round, one that is an alternative does not (then f is the mixture of the two, below)
        best = next(r for r in ranked if r.fit.label == verdict.named)
        st.causes.append(best.fit.variants[-1])
        st.reference = dg.resolved(best.fit)
    return st


def residual_rms(a: WholeRecord, b: WholeRecord) -> dict[str, dict[str, tuple[float, float]]]:
    """RMS of residual / noise sd per channel and phase: (baseline, final model)."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    fb = {(f.channel, f.phase): f.rms for f in b.figures}
    for f in a.figures:
        out.setdefault(f.channel, {})[f.phase] = (f.rms, fb.get((f.channel, f.phase), float("nan")))
    return out

