"""Name the cause of a misfit: rank the extended models (:mod:`.extended`) by block-LOO ELPD, and read
each round's verdict with the naming rule of :mod:`.verdict`.

* a mechanism is named only when its dELPD over the reference model is decisive by the package's rule
  (above 4 and 2 standard errors) with the blocks that favour it most left out (the evidence is spread over
  the record, not a few blocks at a front where two simulators of the same test differ; the whole record's
  sum is then larger still, whatever its standard error), and when it rules out every other mechanism: by
  the same rule, or by the stacking weight (:mod:`.verdict`, 3.);
* several mechanisms that pass but do not rule each other out are *candidates*: the record does not tell
  them apart (``not_separable``, with what would separate them, and, where they are all faults of the chain
  that delay one gauge's fronts, the delay they agree on: :mod:`.front_delay`), and f is then the stacking
  mixture of the models that carry the weight; the same mechanism on another gauge (a gain) is named, its gauge
  listed as uncertain;
* a misfit of the reference model (the whole-record check's decision, :mod:`.misfit`) that no mechanism
  explains by that rule is *unexplained*: the candidates are listed with their stacking weights and f is
  their mixture's; a mechanism that passes without such a misfit is *unconfirmed*: not named, f from the
  mixture of it and the reference;
* a first round that no mechanism explains alone, whose two leading candidates explain it together, names both
  (:mod:`.joint_round`): the first joins the model, and the next round must name the second by the rule, or the round
  is read as unexplained after all;
* after a named cause the search goes on with it in the model (the reference becomes baseline + cause),
  for at most four causes, so that a record with several effects gets them in order of evidence; it stops
  at the first round that names nothing. A later round whose reference the whole-record check no longer flags
  names an entry of the measurement chain (``Mechanism.measurement_chain``: a gain, a zero drift, a channel's
  timing, a bandwidth, a bar's modulus) only if it moves f by more than the whole-record models' form term
  (:meth:`.verdict.NamingRule.matters_for_f`); otherwise the entry stays in the model, not named
  (``Verdict.within_tolerance``): it changes one gauge's reading, so within the check's tolerance it takes up
  where the record's waveform on that gauge departs from the 1-D model's (an input bar's gain on a clean
  axisymmetric cell), while the cell's mechanisms act on every gauge at once and are named by their evidence
  (a mild velocity weakening behind a clearance that moves f by 1 %, the bundled B-02's fourth cause).
  When that round's stacking weight lies on further mechanisms none of which it names, f is the mixture of them
  and the model with the causes (``further_mixture``): the final model alone would be quoted as if nothing more
  were there (on the bundled B-05 its interval sat 5 % above
  the true f, while the weight lay on the plug friction and the velocity weakening it hides). Where a round's
  rivals are left open, f is their mixture with the final model, whose share those further mechanisms then share.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from ..analysis import Prepared
from .block_loo import elpd_difference
from .exact_model import exact_posterior
from .extended import Diagnoser, ModelFit, Variant, candidates
from .front_delay import round_shared_delay
from .joint_round import PairTrial, admitted, confirms, joint_job, leads, not_confirmed
from .misfit import MisfitDecision, decide, misfit_detected
from .record_likelihood import HOOP_GAIN_SD
from .candidates_mixture import (Resolve, draw_mixture, further_members, mixture, open_rounds, rival_mixture,
                                 superfluous_mixture)
from .diagnosis import Diagnosis, Ranked
from .rival_swaps import Swap, check_swaps, swap_jobs
from .separability import separability
from .verdict import NamingRule, Verdict
from .whole_record import WholeRecord, compare_whole_record

#: The naming rule of every round (:mod:`.verdict`).
NAMING = NamingRule()

MAX_CAUSES = 4
#: Processes fitting one round's extended models by default.
MAX_WORKERS = 4


def rank(reference: ModelFit, fits: list[ModelFit], *, misfit: bool = False) -> tuple[Ranked, ...]:
    out = [Ranked(f, *elpd_difference(f.elpd, reference.elpd), misfit=misfit) for f in fits]
    return tuple(sorted(out, key=lambda r: -r.delpd))


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
    #: a first round's pair (:mod:`.joint_round`): the joint fit's mode, where the next round's fit of the pair starts,
    #: and the round's verdict without the pair, restored if the next round does not name the second
    pair_mode: dict[str, float] | None = None
    alone: Verdict | None = None
    #: the pair fitted together, named or not, and why not
    pair_tried: PairTrial | None = None


def diagnose(prep: Prepared, log_prior_f_nu: Callable[[Mapping[str, float]], float], start: Mapping[str, float], *,
             hoop: bool, seed: int, n_draws: int = 1000, progress: Callable[[str], None] | None = None,
             base_scales: Mapping[str, tuple[float, float]] | None = None, max_causes: int = MAX_CAUSES,
             workers: int | None = None, stationary_f: np.ndarray | None = None, nu_cut: bool = False,
             hoop_calibration: tuple[float, float] = (1.0, HOOP_GAIN_SD)) -> Diagnosis:
    """Fit the baseline and every mechanism, rank them and name the cause(s) (module docstring).

    ``base_scales``: Gaussian stand-ins (centre, sd in the unbounded coordinate) of the f and nu
    priors for the mode search. ``workers``: processes fitting a round's extended models and sharing the
    exact posterior's evaluations (None: the machine's cores, at most :data:`MAX_WORKERS`); the result does
    not depend on it. ``stationary_f``: the stationary analysis' draws of f, half of the f to quote when no cause
    is named (:mod:`.candidates_mixture`); None: the candidates' mixture alone. ``nu_cut``: the f of every model
    that f is reported from (the baseline, each round's reference, the final model, the mixtures' members) from the
    cut posterior, nu read from the record's stationary windows under the model (:mod:`.nu_cut`; the names are the
    joint fits'), the other candidates' f their joint fits' (``ModelFit.f_from``: the cut is made only where f is
    reported, half of a model's fitting time); False: f is each model's joint fit's. ``hoop_calibration``: the hoop
    gauge's factor known beforehand (median, relative sd; the run's prior file:
    :func:`.record_likelihood.hoop_calibration`).
    """
    t0 = time.perf_counter()
    if workers is None:
        workers = min(MAX_WORKERS, os.cpu_count() or 1)
    say = progress or (lambda msg: None)
    dg = Diagnoser(prep, log_prior_f_nu, hoop=hoop, seed=seed, n_draws=n_draws, base_scales=base_scales,
                   nominal=start, nu_cut=nu_cut, hoop_calibration=hoop_calibration)
    n_models = len(candidates(dg.in_baseline, dg.gauges))
    say(f"baseline (up to {max_causes} rounds of up to {n_models} extended models follow)")
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
    shared = round_shared_delay(verdicts[0], rounds[0], st.not_sep, prep.record.apparatus) if st.not_sep else None
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
                     swap_models=checked, mixture_of=mixture_of, shared_delay=shared,
                     hoop_calibration=dg.hoop_calibration, pair_tried=st.pair_tried)


def _mixture_after_causes(final: ModelFit, rounds: list, verdicts: list, causes: list, swaps: tuple, checked: tuple,
                          seed: int, stationary_f: np.ndarray | None, resolve: Resolve) -> tuple:
    """f's mixture once causes were fitted, and which: a round's open rivals first (the last round's further
    mechanisms standing for the final model in its share), else those further mechanisms, else a superfluous
    candidate's round (:mod:`.candidates_mixture`); (None, {}, None, None): f is the final model's."""
    further = further_members(final, rounds, verdicts, causes, resolve)
    mix, w, src = rival_mixture(final, rounds, verdicts, causes, seed, stationary_f, resolve, further=further)
    if mix is not None:
        return mix, w, src, "rivals"
    if further is not None:
        return *draw_mixture(*further, seed), "further"
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
        used = dg.in_baseline + tuple(v.mechanism.name for v in st.causes)
        pair = st.verdicts[-1].joint if k > 0 else None  # the partner's fit starts where the pair's joint fit ended
        jobs = [(tuple(st.causes) + (cand,), dict(st.pair_mode if pair and cand.label == pair.partner
                                                  else st.reference.fit.mode),
                 "+".join([v.label for v in st.causes] + [cand.label]))
                for cand in candidates(exclude=used, gauges=dg.gauges)]
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
        verdict, best = _verdict(dg, st, ranked, k, max_causes=max_causes, seed=seed, say=say)
        if pair is not None and not confirms(verdict, ranked, pair.partner):
            why = not_confirmed(verdict, ranked, pair.partner, st.causes[-1].label, k + 1)
            say(f"{why}: round {k} stays unexplained")
            _unjoin(st, k - 1, why)
            break
        if best is None:
            st.verdicts.append(verdict)
            say(f"round {k + 1}: {verdict.kind}")
            break
        st.verdicts.append(verdict)
        say(f"round {k + 1}: {verdict.kind} ({verdict.named}" + (", in the model within the check's tolerance, not "
            "named" if verdict.within_tolerance else "") + (f", {verdict.joint.partner} to be named next with it"
                                                             if verdict.joint is not None else "") + ")")
        st.causes.append(best.fit.variants[-1])
        st.reference = dg.resolved(best.fit)
    return st


def _verdict(dg: Diagnoser, st: _Search, ranked: tuple[Ranked, ...], k: int, *, max_causes: int, seed: int,
             say: Callable[[str], None]) -> tuple[Verdict, Ranked | None]:
    """Round ``k``'s verdict by the naming rule (a first round's pair where neither alone explains the misfit:
    :func:`_joint`), and the candidate that joins the model (None when none does). A named entry of the measurement
    chain in a later round whose reference the whole-record check no longer flags is kept within the check's
    tolerance unless it matters for f (module docstring)."""
    misfit = st.misfits[-1].detected
    verdict = NAMING.judge(st.reference, ranked, misfit=misfit, seed=seed + k, first=k == 0)
    if k == 0 and k + 1 < max_causes and (pair := leads(verdict, ranked)) is not None:
        st.alone = verdict
        verdict, st.pair_mode, st.pair_tried = _joint(dg, st.reference, ranked, verdict, pair, say)
    if verdict.named is not None and k == 0 and verdict.joint is None:
        st.not_sep, st.other_channels, st.separate_by = separability(verdict)
    if verdict.kind not in ("named", "candidates"):
        return verdict, None
    # candidates: the best goes into the model all the same; a rival that is a second cause passes again in a
    # later round, one that is an alternative does not (then f is the mixture of the two, below)
    best = next(r for r in ranked if r.fit.label == verdict.named)
    if verdict.kind == "named" and k > 0 and not misfit and best.fit.variants[-1].mechanism.measurement_chain:
        resolved = dg.resolved(best.fit)
        verdict = replace(verdict, within_tolerance=not NAMING.matters_for_f(st.reference.f_effective,
                                                                             resolved.f_effective))
    return verdict, best


def _joint(dg: Diagnoser, reference: ModelFit, ranked: tuple[Ranked, ...], verdict: Verdict, pair: tuple,
           say: Callable[[str], None]) -> tuple[Verdict, dict[str, float] | None, PairTrial]:
    """An unexplained round's verdict, or, when its two leading candidates fitted together explain it
    (:mod:`.joint_round`), the first of them named with the second to be named by the next round; the joint fit's
    mode where the pair is admitted (None otherwise); and the trial, with why it was refused."""
    a, b = pair
    job = joint_job(a, b)
    say(f"round 1 unexplained: {job[2]} fitted together")
    joint = dg.fit_many([job], cut=False)[0]
    evidence, refused = admitted(joint, reference, a, b, ranked, NAMING)
    trial = PairTrial(1, (a.fit.variants[-1].label, evidence.partner), evidence, refused, admitted=refused is None)
    if refused is not None:
        say(f"round 1: {job[2]} not admitted, {refused} (docs/methods.md, two causes named together)")
        return verdict, None, trial
    return replace(verdict, kind="named", named=a.fit.label, joint=evidence), dict(joint.fit.mode), trial


def _unjoin(st: _Search, k: int, why: str) -> None:
    """Round ``k``'s pair not confirmed by the next round (``why``): the round read as it was (unexplained), the
    first of the pair out of the model, the next round's ranking and misfit decision dropped. Only a first round
    names a pair: its reference is the baseline."""
    st.verdicts[k] = st.alone
    del st.causes[k:], st.rounds[k + 1:], st.misfits[k + 1:]
    st.reference, st.pair_mode = st.base, None
    st.pair_tried = replace(st.pair_tried, refused=why)


def residual_rms(a: WholeRecord, b: WholeRecord) -> dict[str, dict[str, tuple[float, float]]]:
    """RMS of residual / noise sd per channel and phase: (baseline, final model)."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    fb = {(f.channel, f.phase): f.rms for f in b.figures}
    for f in a.figures:
        out.setdefault(f.channel, {})[f.phase] = (f.rms, fb.get((f.channel, f.phase), float("nan")))
    return out

