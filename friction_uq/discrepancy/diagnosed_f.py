"""The f a diagnosis quotes: the named model's, or the stacking mixture of the candidates (:mod:`.verdict`), with
the output bars' calibration folded in (:mod:`friction_uq.quoted`), and the labels of a mixture's members. What
``diagnose`` says in words about it: :mod:`.diagnosis_words`."""

from __future__ import annotations

import numpy as np

from ..quoted import OUTPUT_BARS, WHOLE_RECORD_MODEL_FORM, folded_sd, quoted_summary
from ..stats.thinning import equal_parts
from .candidates_mixture import STATIONARY, open_rounds
from .diagnosis import Diagnosis
from .extended import Variant
from .record_likelihood import GAIN_SD

#: Mechanisms that fit an output bar's own calibration (its gauge's gain; the bars' moduli): a model with one reads
#: f partly against the input bar's force (:func:`folded_sd_of`).
BAR_CALIBRATION_FAULTS = ("gauge_gain", "bar_modulus")


def member_name(label: str) -> str:
    """A mixture member's label as printed: "reference" (the whole-record model without causes) is "no cause",
    :data:`~.candidates_mixture.STATIONARY` "stationary analysis", a model its label."""
    return {"reference": "no cause", STATIONARY: "stationary analysis"}.get(label, label)


def mixture_label(dg: Diagnosis) -> str:
    """'mixture of clearance (0.61), dispersion (0.33)': the models whose stacking mixture gives f, with their
    weights (:func:`member_name`)."""
    parts = [f"{member_name(k)} ({w:.2f})" for k, w in dg.mixture_weights.items()]
    return "mixture of " + ", ".join(parts)


def unresolved(dg: Diagnosis) -> bool:
    """A round of candidates whose rivals no later round named: the candidate fitted in turn is not named
    (``Diagnosis.named_causes`` holds the causes that are), and f is the mixture of the candidates
    (``Diagnosis.mixture_f``, ``Diagnosis.open_candidates``)."""
    return bool(open_rounds(dg.causes, dg.verdicts))


def further(dg: Diagnosis) -> dict[str, str]:
    """The further mechanisms the last round's stacking mixture gives f with, beside the model with the causes,
    none of which it named (:func:`~.candidates_mixture.further_mixture`): each member's label -> the mechanism it
    adds to the model with the causes (``gauge_gain[external_output_bar]``); {} when f is that model's alone."""
    if dg.mixture_of != "further":  # diagnose says which mixture gives f
        return {}
    added = {r.fit.label: r.fit.variants[-1].label for r in dg.rounds[-1]}
    return {k: added.get(k, k) for k in dg.mixture_weights if k != dg.final.label}


def folded_sd_of(variants, model_form: float = WHOLE_RECORD_MODEL_FORM) -> float:
    """The sd folded into the f of a whole-record model with these causes (:mod:`friction_uq.quoted`): the
    calibration its likelihood does not carry, and ``model_form`` beside it (the 1-D simulation's form, which its
    likelihood does not carry either: 2.5 %). Its likelihood carries a gain of :data:`~.record_likelihood.GAIN_SD`
    on each output gauge (2.0 % of calibration left). With one of :data:`BAR_CALIBRATION_FAULTS` fitted on an
    output bar, f is read partly against the input bar's force through the equilibrium, whose calibration no model
    carries: the whole budget is folded in (2.45 %, more than that bar's term swapped for the input bar's, 2.24 %).
    With the model form: 3.20 % and 3.50 %."""
    if any(v.mechanism.name == "bar_modulus" or (v.mechanism.name in BAR_CALIBRATION_FAULTS and v.channel in OUTPUT_BARS)
           for v in variants):
        return folded_sd(model_form=model_form)
    return folded_sd(GAIN_SD, model_form=model_form)


def member_variants(dg: Diagnosis, label: str) -> tuple[Variant, ...]:
    """The causes of the model ``label`` (a mixture's member; "reference" and the stationary analysis: none): what
    its calibration budget and its prior of f_effective are read from."""
    if label in ("reference", STATIONARY):
        return ()
    fits = [dg.final, dg.baseline] + [r.fit for rnd in dg.rounds for r in rnd] + list(dg.swap_models)
    return next((m.variants for m in fits if m.label == label), ())


def _folded_diagnosed(dg: Diagnosis, model_form: float) -> float | np.ndarray:
    """The sd folded into the diagnosed f: the final model's, or per draw of the mixture its model's (the
    stationary analysis' draws carry their model form already)."""
    if dg.mixture_f is None:
        return folded_sd_of(dg.final.variants, model_form)
    sds = np.array([folded_sd() if k == STATIONARY else folded_sd_of(member_variants(dg, k), model_form)
                    for k in dg.mixture_weights])
    return sds[np.asarray(dg.mixture_source, int)] if dg.mixture_source is not None else float(sds.max())


def _diagnosed_draws(dg: Diagnosis) -> np.ndarray:
    """The diagnosed f's draws: the stacking mixture's, else the final model's (given the bars' header values)."""
    return dg.mixture_f if dg.mixture_f is not None else dg.final.f_effective


def _folded(dg: Diagnosis, model_form: float = WHOLE_RECORD_MODEL_FORM) -> float | np.ndarray:
    """The sd folded into the f to quote, per draw of :func:`f_draws_to_quote` where it varies: the diagnosed
    f's, and the stationary analysis' own for the half from nu's prior alone (``Diagnosis.f_prior_nu``)."""
    sd = _folded_diagnosed(dg, model_form)
    if dg.f_prior_nu is None:
        return sd
    own = np.broadcast_to(np.asarray(sd, float), np.shape(_diagnosed_draws(dg)))
    return equal_parts(own, np.full(np.size(dg.f_prior_nu), folded_sd()))


def f_draws_to_quote(dg: Diagnosis) -> np.ndarray:
    """The draws the diagnosed f to quote comes from (given the bars' header values): the stacking mixture's, else
    the final model's; in equal parts with the stationary analysis' f from nu's prior alone when the hoop gauge,
    through which every model reads nu, and the prior file disagree (``Diagnosis.f_prior_nu``)."""
    f = _diagnosed_draws(dg)
    return f if dg.f_prior_nu is None else equal_parts(f, dg.f_prior_nu)


def readings_of_nu(dg: Diagnosis) -> dict[str, float] | None:
    """The medians of the two halves of the f to quote when it holds two readings of nu (``Diagnosis.f_prior_nu``):
    "diagnosed" (its models, nu read through the hoop gauge) and "prior" (the stationary analysis, nu from the
    prior file alone), given the bars' header values; None otherwise."""
    if dg.f_prior_nu is None:
        return None
    return {"diagnosed": float(np.median(_diagnosed_draws(dg))), "prior": float(np.median(dg.f_prior_nu))}


def stationary_member(dg: Diagnosis) -> str:
    """The name of a mixture's stationary member in words: the stationary analysis, with the hoop gauge where the
    f to quote also holds the reading from nu's prior alone (``Diagnosis.f_prior_nu``)."""
    return "the stationary analysis" if dg.f_prior_nu is None else "the stationary analysis with the hoop gauge"


def quoted_of(dg: Diagnosis, model_form: float = WHOLE_RECORD_MODEL_FORM) -> dict[str, float]:
    """The diagnosed f to quote (:func:`f_draws_to_quote`) with the output bars' calibration and the whole-record
    models' form (``model_form``; 0: the calibration alone, as before the form was folded in)."""
    return quoted_summary(f_draws_to_quote(dg), _folded(dg, model_form))


def folded_of(dg: Diagnosis) -> float:
    """The sd :func:`quoted_of` folded in (the largest over a mixture's models)."""
    return float(np.max(_folded(dg)))


def headline(dg: Diagnosis) -> tuple[str, dict[str, float]] | None:
    """The headline f of a diagnosed record: the final model's label and its f when a cause was named; the
    stacking mixture's when the record named candidates or an unexplained misfit (:mod:`.verdict`); None when
    nothing needed explaining (the headline is then the stationary analysis' f). The f's summary carries the output
    bars' calibration (:mod:`friction_uq.quoted`), as the JSON's ``f`` does, and, where the hoop gauge and nu's
    prior disagree, the stationary f from nu's prior alone for half (:func:`f_draws_to_quote`)."""
    if dg.mixture_f is not None:
        return mixture_label(dg), quoted_of(dg)
    if dg.causes:
        return dg.final.label, quoted_of(dg)
    return None
