"""What ``diagnose`` writes: the JSON ``discrepancy`` block and the DataTree groups (the sentence and the words:
:mod:`.diagnosis_words`)."""

from __future__ import annotations

import numpy as np

from ..models.parameters import effective_sample_size, summarize_draws
from ..stats import khat_threshold
from ..stats.streams import stream
from .candidates_mixture import STATIONARY
from .diagnosis import Diagnosis, ModelFit, Ranked
from .diagnosed_f import member_variants, mixture_label
from .cause_words import chain_gauge
from .diagnosis_words import baseline_hoop_gain, hoop_gain_off, hoop_prior_words, sentence
from .effective_prior import log_prior_f_effective
from .exact_model import IMPORTANCE_DRAWS
from .verdict import FORM_SHIFT

#: How the named model's posterior is obtained (the JSON's ``posterior_method`` says which route was taken).
POSTERIOR_NOTE = ("exact posterior of the model with the named causes: 200 draws of its normal approximation (robust "
                  "covariance) importance-weighted by the whole-record posterior (Pareto-smoothed; pareto_k judges the "
                  "normal), more of them while the weights' effective sample size is under 119 (the 90 % interval's "
                  "tails to 0.02); when k is over its limit or the effective size stays short, a Student-t proposal, "
                  "then emcee, run on while its chain has fewer than 119 effective draws (posterior_converged: false if "
                  "still short at 4 times its first length); the exact draws then mapped "
                  "to the robust (sandwich) covariance, keeping their shape (open-faced sandwich adjustment, Shaby "
                  "2014)")


def _ess(log_weights: np.ndarray) -> float:
    """Effective sample size of a fit's draws (independent normal draws, equally weighted unless
    importance-corrected)."""
    lw = np.asarray(log_weights, float)
    return effective_sample_size(np.exp(lw - np.max(lw)))


def kappa_draws(mf: ModelFit) -> np.ndarray:
    """kappa = f nu / (1 - nu) (eq. 17's product) for each draw of a fitted model, f its effective coefficient."""
    nu = np.asarray(mf.fit.draws["nu"], float)
    return mf.f_effective * nu / (1.0 - nu)


def _entry(r: Ranked, verdict=None) -> dict[str, object]:
    v = r.fit.variants[-1]
    params = {p.name: summarize_draws(r.fit.fit.draws[p.name]) for p in v.mechanism.parameters}
    judged = {} if verdict is None else next(({"decisive": c.decisive, "weight": c.weight,
                                               "delpd_trimmed": c.delpd_trimmed,
                                               "se_trimmed": c.se_trimmed, "spread": c.spread,
                                               "ruled_out_by_weight": c.label in verdict.by_weight}
                                              for c in verdict.candidates if c.label == r.fit.label), {})
    return {"name": v.mechanism.name, "channel": v.channel, "model": r.fit.label, "delpd": r.delpd, "se": r.se,
            "decisive": r.decisive, **judged, "parameters": params,  # judged: the naming rule's decisive
            "calibration_elpd": dict(zip(r.fit.elpd.calibration_names, map(float, r.fit.elpd.calibration))),
            "f_effective": summarize_draws(r.fit.f_effective), "f_from": r.fit.f_from,
            "draws": int(len(r.fit.f_effective)), "ess": _ess(r.fit.fit.log_weights)}


#: The naming rule in words (the JSON's ``rule``).
RULE_TEXT = ("a cause is named only of a misfit the whole-record check found, when its dELPD over the model without "
             "it exceeds 4 and 2 SE with the 5 % of blocks that favour it most left out (spread over the record; "
             "the whole record's sum is larger still), and rules out every other extended model (by the same "
             "margin, over the whole record or with the 5 % of blocks most in its favour against that model left "
             "out, or by the stacking weight: "
             "more than 4 behind with the 5 % of blocks that favour the best left out, under 0.1 of the weight with "
             "the models as far behind that predict alike); several it does not rule out are candidates, a misfit "
             "none explains is unexplained, and f is then the stacking mixture of the models that carry the weight "
             "(in equal parts with the stationary analysis' f when "
             "nothing is named, with run); after a named cause the search goes on with it in the model; a candidate "
             "fitted in turn is named when, with the later causes in the model, it rules out each rival its round "
             "left open by the same rule, and the model without it, which the whole-record check must then flag "
             "(where its round left no rival open, by the rule alone; swaps); else it is superfluous and not "
             "named; on an unexplained first round the two candidates with the most evidence (each decisive over "
             "the record, two mechanisms) are fitted together, and named together (named_together) when the pair "
             "passes the rule against the reference and against each alone, rules out every other extended model "
             "by dELPD, and the next round names the second on top of the first by the rule (pair_tried: the pair "
             "and, where it was not named, why); a later round whose "
             "reference the whole-record check does not flag names an entry of the "
             "measurement chain (a gain, a zero drift, a timing, a bandwidth, a bar's modulus) only if it moves "
             f"f's median by more than the whole-record models' form term allows ({100 * FORM_SHIFT:.1f} %), else "
             "the entry stays in the model within the check's tolerance (within_tolerance), not named")


def elpd_text(hoop: tuple[float, float] | None) -> str:
    """How the ELPD is computed, in words (the JSON's ``elpd``); ``hoop``: the hoop gauge's known factor and its
    relative sd where the models read the hoop gauge, else None."""
    data = "the header's sample modulus +- 10 %" if hoop is None else \
        f"hoop gauge factor {hoop[0]:.3g} +- {100 * hoop[1]:.0f} %, the header's sample modulus +- 10 %"
    return ("exact leave-one-block-out (10 us blocks per gauge) for AR(1) noise, first order around the mode, "
            f"plus the calibration data ({data}) each left out in turn (calibration_elpd per model)")


def to_json(dg: Diagnosis, f_without: dict[str, float], f_without_quoted: dict[str, float] | None = None
            ) -> dict[str, object]:
    """The JSON ``discrepancy`` block: the verdict and its rounds (:func:`_verdict_json`), the posteriors' summaries
    given the bars' header values (:func:`_posterior_json`), the rule, and the sentence, which quotes
    ``f_without_quoted`` (the stationary f with the bars' calibration, as the JSON's ``f``; default ``f_without``)
    where the stationary f stands."""
    return _verdict_json(dg) | _posterior_json(dg, f_without) | {
        "rule": RULE_TEXT,
        "reference_misfit": [{"statistic": m.statistic, "threshold": m.threshold, "detected": m.detected}
                             for m in dg.misfits],
        "elpd": elpd_text(dg.hoop_calibration if "tube_hoop" in dg.final.predicted else None),
        "seconds": dg.seconds,
        "sentence": sentence(dg, f_without if f_without_quoted is None else f_without_quoted),
    }


def named_together(dg: Diagnosis) -> list[dict[str, object]]:
    """The JSON's ``named_together``: each pair of causes named together (:mod:`.joint_round`), their round unexplained
    by either alone; the two fitted together against the round's reference and each alone (dELPD, SE; and without the
    5 % of blocks most in the pair's favour); the second named by the next round on top of the first."""
    return [{"round": k + 1, "causes": [dg.causes[k].label, v.joint.partner], "against": _against(v.joint)}
            for k, v in enumerate(dg.verdicts[:len(dg.causes)]) if v.joint is not None]


def _against(evidence) -> dict[str, dict[str, float]]:
    """A pair's evidence (:class:`.joint_round.JointEvidence`) against the round's reference and each alone."""
    return {m: {"delpd": d, "se": se, "delpd_rest": dt, "se_rest": st}
            for m, (d, se, dt, st) in evidence.against.items()}


def pair_tried(dg: Diagnosis) -> dict[str, object] | None:
    """The JSON's ``pair_tried``: the first round's two leading candidates fitted together where neither alone
    explained its misfit (:mod:`.joint_round`), their evidence as in ``named_together``, whether the pair passed its
    own tests (``admitted``), whether they were named together and, if not, why; None when no pair was tried."""
    t = dg.pair_tried
    if t is None:
        return None
    return {"round": t.round, "causes": list(t.causes), "admitted": t.admitted, "named_together": t.refused is None,
            "refused": t.refused, "against": _against(t.evidence)}


def _verdict_json(dg: Diagnosis) -> dict[str, object]:
    """What the rounds found: the verdict, the causes, the candidates and the rankings."""
    cause = dg.cause
    v = dg.verdict
    return {
        # the record's: named when a cause is (a round's candidates resolved by later rounds count); candidates
        # when none is but a candidate was fitted in turn (`fitted_in_turn`; `open_candidates`, f is `mixture`'s)
        "verdict": ("named" if dg.named_causes else "candidates" if dg.causes
                    else (v.kind if v is not None else None)),
        # a round whose chain entry stayed in the model within the check's tolerance says so (its kind is "named")
        "round_verdicts": ["within_tolerance" if r.within_tolerance else r.kind for r in dg.verdicts],
        "stacking_weights": dict(v.weights) if v is not None else {},
        "mixture": None if dg.mixture_f is None else {"weights": dict(dg.mixture_weights),
                                                      "f": summarize_draws(dg.mixture_f), "of": dg.mixture_of},
        "cause": cause.mechanism.name if cause else None,
        "cause_channel": cause.channel if cause else None,
        # a measurement-chain fault fitted on every gauge: the gauge whose parameter departs most from reading right
        "cause_gauge": (chain_gauge(cause, dg) or (None,))[0] if cause else None,
        # the first round's: said of the cause only when it is the one that round fitted
        "cause_channel_not_separable": list(dg.channels_not_separable) if cause is not None and cause is dg.causes[0]
        else [],
        "causes": [{"name": c.mechanism.name, "channel": c.channel} for c in dg.named_causes],
        "fitted_in_turn": [c.label for c in dg.causes],
        "open_candidates": list(dg.open_candidates),
        # candidates fitted in turn the later causes made superfluous (the model without them not ruled out, or, where
        # their round left a rival open, not flagged by the whole-record check): not named
        "superfluous": list(dg.superfluous),
        "named_together": named_together(dg),
        # the pair fitted together on an unexplained first round, named or refused (and why)
        "pair_tried": pair_tried(dg),
        # entries of the measurement chain a later round kept in the model while the whole-record check no longer
        # flagged its reference, and that move f by less than the whole-record models' form term: not named
        "within_tolerance": list(dg.within_tolerance),
        # the candidates fitted in turn against their rounds' open rivals, with the later causes in the model (a rival
        # of a later cause's group replaces that cause too)
        "swaps": [{"round": sw.round + 1, "rival": sw.rival, "model": sw.model, "delpd": sw.delpd, "se": sw.se,
                   "weight": sw.weight, "ruled_out": sw.ruling, "check_flags": sw.flagged} for sw in dg.swaps],
        "not_separable": list(dg.not_separable),
        "separate_by": dg.separate_by,
        # the delay on one gauge the candidates not told apart agree on, when they all delay its fronts (front_delay)
        "shared_delay": dg.shared_delay.to_json() if dg.shared_delay is not None else None,
        "ranking": [_entry(r, v) for r in dg.ranking],
        "rounds": [[_entry(r, dg.verdicts[k + 1] if k + 1 < len(dg.verdicts) else None) for r in rnd]
                   for k, rnd in enumerate(dg.rounds[1:])],
    }


def _posterior_json(dg: Diagnosis, f_without: dict[str, float]) -> dict[str, object]:
    """The final model's posterior and the baseline's beside it, the hoop gauge's factor, the residuals."""
    hoop = dg.final.hoop_gain
    return {
        "model": dg.final.label,
        "f_extended": dg.final.f_summary(),
        "posterior_method": dg.posterior_method,
        "posterior_note": POSTERIOR_NOTE,
        "pareto_k": dg.pareto_k,
        "pareto_k_threshold": khat_threshold(IMPORTANCE_DRAWS),
        "importance_ess": dg.importance_ess,
        "posterior_converged": dg.posterior_converged,
        "f_baseline_stationary": f_without,
        "f_baseline_whole_record": dg.baseline.f_summary(),
        "nu_extended": summarize_draws(dg.final.fit.draws["nu"]),
        "nu_source": ("the stationary windows' levels under the model (the cut: theta fitted to the whole record "
                      "given nu)"
                      if dg.final.cut is not None else "the whole-record fit"),
        "nu_whole_record": dg.final.fit.mode["nu"],
        "kappa_extended": summarize_draws(kappa_draws(dg.final)),
        "kappa_baseline_whole_record": summarize_draws(kappa_draws(dg.baseline)),
        "hoop_gain": None if "tube_hoop" not in dg.final.predicted else {  # no hoop gauge read: nothing to say
            "value": hoop, "without_causes": baseline_hoop_gain(dg), "finding": hoop_gain_off(dg),
            "meaning": "calibration factor of the tube hoop gauge (recorded / true) at the final model's whole-record "
                       f"fit: its most probable value under {hoop_prior_words(dg)}"},
        "residual_rms": {ch: {ph: {"before": b, "after": a} for ph, (b, a) in phases.items()}
                         for ch, phases in dg.rms.items()},
    }


def group_key(label: str) -> str:
    """The DataTree group name part of a fitted model's label (``discrepancy_<key>``)."""
    return label.replace("[", "_").replace("]", "").replace("+", "__")


def _mixture_dataset(dg: Diagnosis, f_prior, nu_prior):
    """The stacking mixture's draws of f_effective, each with the log density of the prior of the model it was
    drawn from (what a campaign divides out when it pools the f this record quotes)."""
    import xarray as xr

    labels = list(dg.mixture_weights)
    log_prior = np.empty(len(dg.mixture_f))
    notes = []
    for i, label in enumerate(labels):
        at = dg.mixture_source == i
        rng = stream(dg.seed, "effective prior", f"mixture {label}")
        log_prior[at], note = log_prior_f_effective(member_variants(dg, label), dg.context, f_prior,
                                                    dg.mixture_f[at], rng=rng, nu_prior=nu_prior)
        notes.append(f"{label}: {note}")
    return xr.Dataset({"f_effective": (("chain", "draw"), dg.mixture_f[None]),
                       "model": (("chain", "draw"), np.asarray(labels, dtype=object)[dg.mixture_source][None].astype(str)),
                       "log_prior_f_effective": (("chain", "draw"), log_prior[None],
                                                 {"description": "; ".join(notes)})},
                      attrs={"model": mixture_label(dg), "verdict": dg.verdict.kind,
                             "posterior_method": posterior_method_of(dg)})


def posterior_method_of(dg: Diagnosis) -> str | None:
    """How the draws of the f the record quotes were obtained: the final model's route (:data:`POSTERIOR_NOTE`)
    or, where f is a stacking mixture, what each member's draws are; where the f to quote also holds the stationary
    f from nu's prior alone (``Diagnosis.f_prior_nu``), that half too."""
    prior = ("" if dg.f_prior_nu is None else
             "; in equal parts with the stationary posterior's draws with nu from the prior file alone")
    if dg.mixture_f is None:
        return None if dg.posterior_method is None else dg.posterior_method + prior
    return (("stacking mixture: the final model's draws from its exact posterior where it is a member, the other "
             "members' normal approximations" if dg.causes else
             "stacking mixture of the candidates' normal approximations")
            + (", half of it the stationary posterior's draws" if STATIONARY in dg.mixture_weights else "") + prior)


def add_to_datatree(dt, dg: Diagnosis, f_prior, nu_prior) -> None:
    """One group per fitted model under ``discrepancy``: the draws (posterior: the normal approximation's, and
    for the model the headline f comes from its exact posterior's, :func:`.exact_model.exact_posterior`), beside
    f_effective the log density of its prior at each draw (``log_prior_f_effective``, :mod:`.effective_prior`;
    ``f_prior``, ``nu_prior``: the prior file's f and nu priors; nu's is read by a law whose f reads nu, the
    pressure family's, which every diagnosis fits), and the pointwise
    block elpd (log_likelihood)."""
    import xarray as xr

    fits: list[ModelFit] = [dg.baseline] + [dg.final if dg.causes and r.fit.label == dg.final.label else r.fit
                                            for rnd in dg.rounds for r in rnd]
    # the group of the model the headline f comes from (empty: no cause named, the stationary posterior's f)
    dt.attrs["discrepancy_final_group"] = f"discrepancy_{group_key(dg.final.label)}" if dg.causes else ""
    if dg.mixture_f is not None:
        dt.attrs["discrepancy_final_group"] = "discrepancy_mixture"
        dt["discrepancy_mixture/posterior"] = xr.DataTree(_mixture_dataset(dg, f_prior, nu_prior))
    for mf in fits:
        key = group_key(mf.label)
        post = {n: (("chain", "draw"), v[None]) for n, v in mf.fit.draws.items()}
        post["f_effective"] = (("chain", "draw"), mf.f_effective[None])
        rng = stream(dg.seed, "effective prior", mf.label)
        log_prior, prior_note = log_prior_f_effective(mf.variants, dg.context, f_prior, mf.f_effective, rng=rng,
                                                      nu_prior=nu_prior)
        post["log_prior_f_effective"] = (("chain", "draw"), log_prior[None], {"description": prior_note})
        ll = {"block_elpd": (("block",), mf.elpd.pointwise),
              "calibration_elpd": (("calibration",), mf.elpd.calibration)}
        method = dg.posterior_method if mf is dg.final and dg.causes else "normal approximation (robust covariance)"
        dt[f"discrepancy_{key}/posterior"] = xr.DataTree(xr.Dataset(post, attrs={
            "model": mf.label, "posterior_method": method, "f_from": mf.f_from}
            | ({"hoop_gain": mf.hoop_gain} if "tube_hoop" in mf.predicted else {})))
        dt[f"discrepancy_{key}/log_likelihood"] = xr.DataTree(xr.Dataset(
            ll, coords={"calibration": list(mf.elpd.calibration_names)}, attrs={
            "elpd": mf.elpd.total, "elpd_se": mf.elpd.se,
            "description": "leave-one-block-out log predictive density per 10 us block of each gauge, and of each "
                           "calibration datum left out"}))
