"""Checks that can fail, said loudly: the warnings of one analysis.

Each check asks whether the model behind eq. 17 describes this record; when one says it does not,
a one-sentence warning says what was seen, what f is then worth and which estimate is safer. The
list is empty when every check passes; ``run`` prints it before the table, writes it first in the
JSON (``warnings``) and on the report's first page.

Checks and their limits (``docs/trust.md`` gives the calibration):

* stationarity: the 10 us-smoothed force ratio stays inside its noise band about the window's
  level less than :data:`PPC_COVERAGE_MIN` of the time, or the window's batch means scatter more
  than the gauges' noise allows (their variance ratio beyond the 99.9 % point of chi-square / dof);
* the whole-record check misses a gauge: over the *stationary* phase (the phase eq. 17 reads) on a
  gauge f depends on, or anywhere else (a cause such as a plug friction shows outside that phase
  and biases f inside it);
* a gauge's peak sits on one value for a run its noise cannot tell from a saturated digitiser;
* a gauge disagrees over the loading (:mod:`friction_uq.gauge_balance`, :mod:`friction_uq.gauge_scale`), or the
  output forces do not sum to the input force over the window (eq. 5) within the same tolerance and noise;
* convergence of the sampler; the prior-data check, and the hoop gauge against nu's prior
  (:mod:`friction_uq.hoop_or_prior`: f both ways, the f quoted from both);
* with ``diagnose``: the named model's normal approximation against its exact posterior (Pareto k).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from scipy import stats

from ..analysis import Identification
from ..gauge_balance import BALANCE_TOL, GaugeFinding, balance_departure
from ..diagnostics import Convergence, VariableSummary
from ..diagnostics.ppc import RatioPPC
from ..discrepancy.check import WholeRecordCheck
from ..discrepancy.diagnosed_f import further, headline
from ..discrepancy.whole_record import CHANNEL_LABELS
from ..hoop_or_prior import HoopOrPrior, TwoReadings
from ..prior_sensitivity import PriorDataConflict
from ..report.quote import f_from_diagnosis
from ..stats.exact import ess_floor

#: Least fraction of the window where the smoothed ratio lies in its 90 % noise band (about 0.9 on a
#: record the model describes; its sd over records is ~0.06, so 0.5 is more than six sd below).
PPC_COVERAGE_MIN = 0.5
#: Tail probability of the batch-means spread test (chi-square with batches - 1 degrees of freedom).
SPREAD_ALPHA = 1e-3
#: Channels whose stationary-phase misfit bears on f.
F_CHANNELS = ("internal_output_bar", "external_output_bar", "tube_hoop")


def _stat(x: float) -> str:
    """A misfit statistic as printed: whole numbers from 10 up, one decimal below (a cell tested at 2.5 reads 2.7)."""
    return f"{x:.0f}" if x >= 10 else f"{x:.1f}"


def _f_text(f: VariableSummary) -> str:
    """f as a warning quotes it; two readings in equal parts (:class:`~friction_uq.hoop_or_prior.TwoReadings`) by
    their interval alone, their mixture's median sitting between them."""
    if isinstance(f, TwoReadings):
        return f"f (from {f.q05:.4g} to {f.q95:.4g}, two readings)"
    return f"f = {f.q50:.4g} [{f.q05:.4g}, {f.q95:.4g}]"


def stationarity_warning(ppc: RatioPPC, excess_spread: float, dof: int, f: VariableSummary,
                         lab: Identification) -> str | None:
    """The ratio wanders over the window more than the noise explains (module docstring)."""
    limit = float(stats.chi2(dof).ppf(1.0 - SPREAD_ALPHA) / dof) ** 0.5
    if ppc.coverage >= PPC_COVERAGE_MIN and excess_spread <= limit:
        return None
    return (f"The force ratio is not stationary over the window: its smoothed course stays in the noise band "
            f"about its level {ppc.coverage * 100:.0f} % of the time (about 90 % expected) and its level "
            f"wanders {excess_spread:.1f} times what the gauges' noise allows; eq. 17 then reads an average "
            f"over a varying friction, so {_f_text(f)} is the mean ratio's f, its interval widened to the "
            f"window's own scatter (the lab's eq. 17 on the window means: f = {lab.f:.4g} at nu {lab.nu:g}); a "
            "steadier window (--window) or `friction-uq diagnose` is safer.")


def _diagnosed_text(fm: dict[str, float], diagnosis) -> str:
    """The diagnosed f to quote as a warning says it: by its interval alone when it holds two readings of nu
    (``Diagnosis.f_prior_nu``), whose mixture's median sits between them."""
    if diagnosis.f_prior_nu is not None:
        return f"from {fm['q05']:.4g} to {fm['q95']:.4g} (the JSON's f, half of it with nu from the prior file alone)"
    return f"{fm['q50']:.4g} [{fm['q05']:.4g}, {fm['q95']:.4g}] (the JSON's f)"


def _next_step(diagnosis, f: VariableSummary) -> str:
    """What to do about a misfit: diagnose it, or (diagnosed) quote f under the causes it named."""
    if diagnosis is None:
        return "`friction-uq diagnose` names the cause and gives f under it."
    from ..discrepancy.candidates_mixture import STATIONARY

    if more := further(diagnosis):  # causes named, and further ones the record leans to without naming one
        fm = headline(diagnosis)[1]
        names = ", ".join(v.label for v in diagnosis.named_causes) or "none"
        return (f"`diagnose` names {names}, and the record leans to a further cause without naming one "
                f"({', '.join(more.values())}); "
                f"f from the stacking mixture is {_diagnosed_text(fm, diagnosis)}, "
                "wide enough for whichever of them is right: quote that, with this warning.")
    if diagnosis.mixture_f is not None:  # unexplained, or candidates (fitted in turn or not) the record leaves open
        fm = headline(diagnosis)[1]
        named = ", ".join(v.label for v in diagnosis.named_causes)
        open_ = diagnosis.open_candidates if named else (diagnosis.not_separable or diagnosis.open_candidates)
        listed = f" ({', '.join(open_)})" if open_ else ""
        if not diagnosis.causes and diagnosis.verdict.kind == "unexplained":
            what = "no single cause explains it"
        elif named and diagnosis.mixture_of == "superfluous":
            what = (f"it names {named}; {', '.join(diagnosis.superfluous)}, fitted in turn, is not needed with them "
                    "and not named")
        elif named:
            what = f"it names {named}, and a further cause among candidates the record does not tell apart{listed}"
        else:
            what = f"the record does not tell its candidate causes apart{listed}"
        half = " and the stationary analysis in equal parts" if STATIONARY in diagnosis.mixture_weights else ""
        return (f"`diagnose`: {what}; f from their stacking mixture{half} is {_diagnosed_text(fm, diagnosis)}, "
                "wide enough for whichever of them is right: quote that, with this warning.")
    if not diagnosis.causes:
        return "`diagnose` named no cause: f is then to be quoted with this warning, or not at all."
    fx = headline(diagnosis)[1]  # the JSON's f: the named model's, with the bars' calibration
    names = ", ".join(v.label for v in diagnosis.named_causes) or "none"
    if diagnosis.within_tolerance:  # in the model, not named: f is that model's
        names += f" (with {', '.join(diagnosis.within_tolerance)} in the model within the check's tolerance, not named)"
    return (f"`diagnose` names {names}: f under them is {_diagnosed_text(fx, diagnosis)}, "
            "which is the f to quote.")


def misfit_warning(check: WholeRecordCheck | None, f: VariableSummary, diagnosis=None) -> str | None:
    """The whole-record check misses a gauge that f depends on over the stationary phase."""
    if check is None:
        return None
    d = check.decision
    if not d.detected:
        return None
    cells = [c for c in d.flagged() if c.phase == "stationary" and c.channel in F_CHANNELS]
    if not cells:
        w = d.flagged()[0]
        return (f"The simulated test misses the {CHANNEL_LABELS[w.channel]} gauge over the {w.phase} phase (statistic "
                f"{_stat(w.statistic)} > {w.threshold:g}): something in this test is not in the model (a plug "
                f"friction, a clearance, a gauge's calibration, ...) and may bias {_f_text(f)} although the stationary "
                f"phase looks right; {_next_step(diagnosis, f)}")
    w = cells[0]
    how = (f"reads {abs(w.relative_level) * 100:.1f} % {'above' if w.relative_level > 0 else 'below'} the simulated "
           "test" if abs(w.level_z) >= w.shape_z else
           f"departs from the simulated test's shape (chi2/dof {w.chi2_dof:.1f})")
    return (f"The {CHANNEL_LABELS[w.channel]} gauge {how} over the stationary phase "
            f"(statistic {_stat(w.statistic)} > {w.threshold:g}): the model behind eq. 17 misses something there, "
            f"so {_f_text(f)} may be biased by about as much; {_next_step(diagnosis, f)}")


def equilibrium_warning(lab: Identification, f: VariableSummary) -> str | None:
    """The output forces do not balance the input force over the window (eq. 5), beyond the tolerance and the gauges'
    noise (:func:`friction_uq.gauge_balance.balance_departure`, as the gauge check over the loading): a gauge's gain,
    sign or place is off."""
    if lab.means is None or balance_departure(lab.means) != "gauge":
        return None
    return (f"The output forces sum to {(1.0 - lab.equilibrium_error) * 100:.0f} % of the input force over the window "
            f"(eq. 5 wants 100 % within {BALANCE_TOL * 100:.0f} %): a gauge's gain, sign or distance is off, and "
            f"{_f_text(f)} rests on the output gauges' ratio, off by as much as their gains are; check the "
            "gauges' calibration (`friction-uq inspect`).")


def _no_gauge_blamed(findings: Sequence[GaugeFinding]) -> bool:
    """The gauge check found only balances the gauges' noise could make (kind "unchecked"), beside the window note."""
    found = [g for g in findings if g.kind != "window"]
    return bool(found) and all(g.kind == "unchecked" for g in found)


def gauge_warning(findings: Sequence[GaugeFinding], f: VariableSummary) -> str | None:
    """What the gauge check found over the loading (:mod:`friction_uq.gauge_balance`): a gauge that disagrees, or a
    balance off by more than its tolerance that the gauges' noise could make (kind "unchecked": no gauge blamed);
    the window found from the ratio alone (kind "window") is said with either."""
    notes = [g.sentence for g in findings]
    if not notes:
        return None
    if _no_gauge_blamed(findings):
        return (f"The force balance cannot check the gauges on this record: {'; '.join(notes)}. {_f_text(f)} rests "
                "on the output gauges' ratio, whose gains it then leaves unchecked.")
    return (f"A gauge disagrees with the others: {'; '.join(notes)}. {_f_text(f)} rests on the output gauges' "
            "ratio and is off by as much as their gains are; `friction-uq diagnose` fits a gauge's gain.")


def hoop_silence_warning(reason: str | None, f: VariableSummary) -> str | None:
    """The hoop gauge, the record's only witness of nu, left out because it reads nothing a swelling tube makes
    (:func:`friction_uq.record_run.inputs.hoop_silence`): nu then comes from the prior file alone, and f with it."""
    if not reason:
        return None
    return (f"The hoop gauge is left out: {reason}. It is the record's only witness of nu, so nu comes from the "
            f"prior file alone and {_f_text(f)} follows it (f = kappa (1 - nu) / nu, eq. 17); a dead bridge and a "
            "sample that hardly swells (nu near 0) read alike: if the sample's nu may be far from the prior's, so may "
            "f.")


def flat_run_warning(notes: Sequence[str], f: VariableSummary) -> str | None:
    """A gauge's peak on one value that may be a saturated digitiser
    (:func:`friction_uq.gauge_check.flat_run_findings`)."""
    if not notes:
        return None
    return (f"{'; '.join(notes)}. A clipped gauge reads less than it carried, and {_f_text(f)} with it: check the "
            "scope's range at that value, or re-record with the gauge's peak well inside it.")


def speed_warning(notes: Sequence[str]) -> str | None:
    """The incident wave at odds with the striker's recorded speed while the gauges agree with each other
    (:func:`friction_uq.gauge_scale.scale_findings`, kind "striker")."""
    if not notes:
        return None
    return (f"{'; '.join(notes)[:1].upper()}{'; '.join(notes)[1:]}. f reads the output forces' ratio and does not "
            "move with a scale all the gauges share; the forces, the wall pressure and the sliding velocity do: check "
            "striker_velocity and the gauges' strain_per_volt before quoting them.")


def convergence_warning(conv: Convergence) -> str | None:
    if conv.ok:
        return None
    return (f"The sampler did not converge (R-hat max {conv.r_hat_max:.3f}, ESS min "
            f"{min(conv.ess_bulk_min, conv.ess_tail_min):.0f}): the interval of f is not reliable; run again "
            "with another --seed and compare.")


def exact_posterior_warning(diagnosis) -> str | None:
    """The exact posterior of the model with the named causes fell short of its effective sample size's floor
    within the caps (:mod:`friction_uq.stats.exact`): its interval's tails rest on too few independent draws."""
    if diagnosis is None or not diagnosis.causes or diagnosis.posterior_converged:
        return None
    return (f"The exact posterior under the named causes ({diagnosis.posterior_method}) kept only "
            f"{diagnosis.importance_ess:.0f} effective draws, short of the {ess_floor()} that the 90 % interval's tails "
            "need: the interval of f under them is not reliable; run `diagnose` "
            "again with another --seed and compare.")


def conflict_warning(conflict: PriorDataConflict | None, hoop_or_prior: HoopOrPrior | None = None) -> str | None:
    """The prior-data check's flags, unless the hoop gauge's disagreement with the prior says them already."""
    if conflict is None or not conflict.flagged or hoop_or_prior is not None:
        return None
    said = conflict.sentence().removeprefix("WARNING: ").rstrip(".")  # each warning is printed after "WARNING: " once
    return (said[:1].upper() + said[1:] + ": f then follows the prior file as much as the record; "
            "quote it with f under the other nu priors (the report's nu page).")


#: Each warning's kind (the run JSON's ``warning_kinds``), in the order :func:`run_warnings` gives them: "gauge" (the
#: balance or a channel's scale blames a gauge), "gauge_unchecked" (a balance off that the gauges' noise could make),
#: "equilibrium" (the window's balance, where the loading's passed); a misfit is "misfit_diagnosed" when ``diagnose``
#: named its causes and f under them is the f to quote (:func:`misfit_kind`), "misfit" otherwise.
WARNING_KINDS = ("flat_run", "gauge", "gauge_unchecked", "equilibrium", "striker_speed", "hoop_silent", "stationarity",
                 "misfit", "misfit_diagnosed", "convergence", "exact_posterior", "hoop_or_prior", "prior_conflict")


@dataclass(frozen=True)
class RunWarning:
    """One warning: its kind (:data:`WARNING_KINDS`) and its sentence."""

    kind: str
    text: str


def misfit_kind(diagnosis) -> str:
    """A misfit's kind: "misfit_diagnosed" where the warning says f under the causes ``diagnose`` named is the f to
    quote (:func:`_next_step`'s last case: causes in the model, no stacking mixture of rivals or further causes),
    else "misfit" (not diagnosed; no cause named; or f from a mixture, to be quoted with the warning)."""
    answered = diagnosis is not None and diagnosis.causes and not further(diagnosis) and diagnosis.mixture_f is None
    return "misfit_diagnosed" if answered else "misfit"


def _gauge_kind(gauges: Sequence[GaugeFinding], lab: Identification, f: VariableSummary) -> tuple[str, str | None]:
    """The gauge check's warning over the loading with its kind, or else the window's balance (eq. 5)."""
    said = gauge_warning(gauges, f)
    if said is None:
        return "equilibrium", equilibrium_warning(lab, f)
    return ("gauge_unchecked" if _no_gauge_blamed(gauges) else "gauge"), said


def run_warnings(*, ppc: RatioPPC, excess_spread: float, dof: int, f: VariableSummary, lab: Identification,
                 conv: Convergence, conflict: PriorDataConflict | None,
                 check: WholeRecordCheck | None, findings: Sequence[GaugeFinding] = (),
                 diagnosis=None, hoop_silent: str | None = None,
                 hoop_or_prior: HoopOrPrior | None = None) -> list[RunWarning]:
    """Every check's warning with its kind, in the order a reader should see them; empty when all pass.
    ``findings``: the gauge checks' (:attr:`friction_uq.analysis.Prepared.findings`), told apart by kind."""
    flat = [g.sentence for g in findings if g.kind == "flat"]
    speed = [g.sentence for g in findings if g.kind == "striker"]
    gauges = [g for g in findings if g.kind not in ("flat", "striker")]
    found: Sequence[tuple[str, str | None]] = (
        ("flat_run", flat_run_warning(flat, f)), _gauge_kind(gauges, lab, f),
        ("striker_speed", speed_warning(speed)), ("hoop_silent", hoop_silence_warning(hoop_silent, f)),
        ("stationarity", stationarity_warning(ppc, excess_spread, dof, f, lab)),
        (misfit_kind(diagnosis), misfit_warning(check, f, diagnosis)),
        ("convergence", convergence_warning(conv)), ("exact_posterior", exact_posterior_warning(diagnosis)),
        ("hoop_or_prior", None if hoop_or_prior is None else hoop_or_prior.sentence(
            diagnosed=headline(diagnosis)[1] if f_from_diagnosis(diagnosis) else None)),
        ("prior_conflict", conflict_warning(conflict, hoop_or_prior)),
    )
    return [RunWarning(kind, text) for kind, text in found if text]
