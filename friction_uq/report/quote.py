"""The f to quote, in one line: which f, from which model, and whether to trust it.

The terminal's first result line and the report's first line both come from :func:`quote_line`, so
that a person reading either sees the same number first: f under the named causes when ``diagnose``
named any (the JSON's ``f``), the stationary analysis' f otherwise, and the count of the
warnings to read before quoting it.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..discrepancy.candidates_mixture import STATIONARY
from ..discrepancy.diagnosed_f import further, headline, readings_of_nu, stationary_member


def f_to_quote(f_stationary: Mapping[str, float], diagnosis=None, *, hoop: bool = True,
               both: Mapping[str, float] | None = None) -> tuple[str, Mapping[str, float]]:
    """(where it comes from, its summary: q05, q50, q95, ...). ``f_stationary``: the stationary analysis' f to
    quote (its posterior with the output bars' calibration, :mod:`friction_uq.quoted`), as the diagnosis's is;
    ``hoop``: whether the stationary analysis used the hoop gauge (it is left out when it shows no usable pulse);
    ``both``: the two readings' medians ("prior", "hoop") when ``f_stationary`` is the analysis with the hoop gauge
    and with nu from the prior alone in equal parts (they disagree: :mod:`friction_uq.hoop_or_prior`)."""
    named = None if diagnosis is None else headline(diagnosis)
    if named is not None:
        label, fx = named
        said = _diagnosed_source(diagnosis, label)
        if diagnosis.f_prior_nu is not None:  # its models read nu through a hoop gauge the prior file disputes
            said += (", in equal parts with the stationary analysis with nu from the prior file alone (the hoop "
                     "gauge, through which every model reads nu, and the prior file disagree)")
        return said, fx
    if both:
        return ("the stationary analysis with the hoop gauge and with nu from the prior file alone, in equal parts "
                "(they disagree)"), f_stationary
    return ("the stationary analysis (eq. 17 and the hoop gauge)" if hoop else
            "the stationary analysis (eq. 17; the hoop gauge left out)"), f_stationary


def _diagnosed_source(diagnosis, label: str) -> str:
    """Where a diagnosed f to quote comes from (:func:`f_to_quote`), before any second reading of nu."""
    if more := further(diagnosis):  # the causes named, and further ones the last round leaned to unnamed
        named = ", ".join(v.label for v in diagnosis.named_causes) or "none"
        alike = "no further cause, or one that leaves f as it is,"  # a member giving the final f lends its weight
        shares = ", ".join(f"{alike if k == diagnosis.final.label else '+ ' + more[k]} {w:.2f}"
                           for k, w in diagnosis.mixture_weights.items())
        return (f"the causes diagnose named ({named}) mixed with the further causes the record leans to "
                f"without naming one ({shares})")
    if diagnosis.mixture_of == "superfluous":  # a candidate fitted in turn the later causes did not need
        named = ", ".join(v.label for v in diagnosis.named_causes) or "none"
        return (f"the {label}: the causes diagnose named ({named}) with and without "
                f"{', '.join(diagnosis.superfluous)}, fitted in turn and not needed")
    if diagnosis.mixture_f is not None:  # unexplained, or candidates the record does not tell apart
        named = ", ".join(v.label for v in diagnosis.named_causes)
        if named:  # a cause named, a later round's candidates left open
            return f"the {label}: the causes diagnose named ({named}) and candidates it could not tell apart"
        if STATIONARY in diagnosis.mixture_weights:  # nothing named: half the stationary analysis' f
            return (f"{stationary_member(diagnosis)} and the candidates diagnose could not tell apart, in equal "
                    f"parts ({label})")
        return f"the {label}, candidates diagnose could not tell apart"
    if diagnosis.within_tolerance:  # a later round's mechanism kept in the model, not named
        named = ", ".join(v.label for v in diagnosis.named_causes) or "none"
        return (f"the model with the causes diagnose named ({named}) and "
                f"{', '.join(diagnosis.within_tolerance)} within the check's tolerance, not named ({label})")
    return f"the model with the causes diagnose named ({label})"


def f_from_diagnosis(diagnosis) -> bool:
    """Whether the f to quote is a diagnosed model's (a cause named, or a mixture with candidates)."""
    return diagnosis is not None and headline(diagnosis) is not None


def quote_line(f_stationary: Mapping[str, float], diagnosis=None, n_warnings: int = 0, *, hoop: bool = True,
               both: Mapping[str, float] | None = None) -> str:
    """'Headline f = 0.0487 [0.0445, 0.0531] (90 %, the output bars' calibration included), from ...; every check
    passed' (or the warnings' count). From two readings that disagree (``both``), the interval and each reading's
    median: the mixture's own median may sit between them, where neither puts weight."""
    source, fx = f_to_quote(f_stationary, diagnosis, hoop=hoop, both=both)
    trust = ("every check passed" if n_warnings == 0 else
             f"{n_warnings} warning{'s' if n_warnings > 1 else ''}: read {'them' if n_warnings > 1 else 'it'} "
             "before quoting it")
    if (two := None if diagnosis is None else readings_of_nu(diagnosis)) and f_from_diagnosis(diagnosis):
        return (f"Headline f from {fx['q05']:.4f} to {fx['q95']:.4f} (90 %, the output bars' calibration included): "
                f"{_diagnosed_source(diagnosis, headline(diagnosis)[0])}, nu read through the hoop gauge "
                f"({two['diagnosed']:.4f}), and the stationary analysis with nu from the prior file alone "
                f"({two['prior']:.4f}), which disagree, in equal parts; {trust}.")
    if both and not f_from_diagnosis(diagnosis):  # the stationary analysis' two readings are the f quoted
        return (f"Headline f from {fx['q05']:.4f} to {fx['q95']:.4f} (90 %, the output bars' calibration included): "
                f"the stationary analysis with nu from the prior file alone ({both['prior']:.4f}) and with the hoop "
                f"gauge ({both['hoop']:.4f}), which disagree, in equal parts; {trust}.")
    return (f"Headline f = {fx['q50']:.4f} [{fx['q05']:.4f}, {fx['q95']:.4f}] (90 %, the output bars' calibration "
            f"included), from {source}; {trust}.")
