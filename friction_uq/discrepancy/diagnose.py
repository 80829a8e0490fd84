"""Name the cause of a misfit: fit each mechanism's extended model, compare by block-LOO ELPD.

For each mechanism of the catalogue (:mod:`.mechanisms`; ``gauge_gain`` once per bar gauge) the
simulator driven by the measured incident wave, extended by the mechanism, is fitted to the whole
record (:mod:`.fit`: posterior by a Laplace approximation with importance weights; f, nu and the
sample's modulus stay free, the hoop gauge's gain is profiled) and scored by its expected log
predictive density over blocks of 10 us of every gauge (:mod:`.elpd`: exact leave-one-block-out
for AR(1) noise). The baseline is the same simulator without extension.

Rule (documented in README.md):

* a mechanism is *decisive* when its dELPD over the reference model exceeds 4 (below that the
  normal approximation of its error is unreliable) and either twice its standard error, or both
  40 and one standard error (a strong effect lives in a few blocks, the fronts, the rise: its
  pointwise differences are heavy-tailed and their SE, which assumes exchangeable blocks,
  overstates chance; a clean record's model-to-simulator differences, which a mechanism with a few
  parameters can partly absorb, gave up to ~50 +- 60 in the calibration study);
* the cause is the decisive mechanism with the largest dELPD; every other decisive mechanism whose
  dELPD is within the same margin of it (4, and 2 SE of the pairwise difference, or one SE and
  max(40, 10 % of the best dELPD)) explains the record about as well: the two are named together
  as ``not_separable`` from this record, with what would separate them;
* then the search goes on with the named cause in the model (the reference becomes baseline +
  cause), for at most three causes, so that a record with several effects gets them in order of
  evidence.

The headline f under the extended model is the wall's coefficient at the stationary window's mean
sliding speed, pressure and slip (``f_effective`` of the mechanism), summarised over the draws.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy import stats

from ..analysis import Prepared
from ..models import Parameter, SimulatorModel, measured_loading
from ..models.parameters import summarize_draws
from .elpd import Elpd, ar1_block_loo, elpd_difference, takeuchi_block_loo
from .fit import WholeRecordFit, WholeRecordLikelihood, fit_whole_record
from .mechanisms import MECHANISMS, Context, Mechanism
from .whole_record import WholeRecord, compare_whole_record

#: Block of the leave-one-block-out ELPD (s).
BLOCK = 10e-6
#: Decisive evidence: dELPD above DECISIVE_ELPD and above DECISIVE_SE standard errors or STRONG_ELPD.
DECISIVE_ELPD, DECISIVE_SE, STRONG_ELPD = 4.0, 2.0, 40.0
MAX_CAUSES = 3
#: Further starting values of nu for the baseline's mode search.
NU_STARTS = (0.33, 0.45)
SAMPLE_MODULUS_SD_LOG = 0.1

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
}
DEFAULT_SEPARATION = "another test of the campaign (another striker speed or another internal output bar)"


@dataclass(frozen=True)
class Variant:
    """A mechanism as fitted (gauge_gain: on one gauge)."""

    mechanism: Mechanism
    channel: str | None = None

    @property
    def label(self) -> str:
        return self.mechanism.name + (f"[{self.channel}]" if self.channel else "")


@dataclass(frozen=True)
class ModelFit:
    """One fitted model (baseline or baseline + causes + a variant) and its ELPD."""

    label: str
    variants: tuple[Variant, ...]
    fit: WholeRecordFit
    hoop_gain: float
    elpd: Elpd
    f_effective: np.ndarray
    predicted: dict[str, np.ndarray]
    lik: WholeRecordLikelihood | None = None

    def f_summary(self) -> dict[str, float]:
        return summarize_draws(self.f_effective)


@dataclass(frozen=True)
class Ranked:
    """A candidate against the reference model of its round."""

    fit: ModelFit
    delpd: float
    se: float

    @property
    def decisive(self) -> bool:
        return beyond(self.delpd, self.se, STRONG_ELPD)


def beyond(d: float, se: float, strong: float) -> bool:
    """dELPD d (with SE se) is decisive evidence (module docstring)."""
    return d > DECISIVE_ELPD and (d > DECISIVE_SE * se or (d > strong and d > se))


@dataclass(frozen=True)
class Diagnosis:
    """Everything ``diagnose`` found (module docstring)."""

    baseline: ModelFit
    rounds: tuple[tuple[Ranked, ...], ...]
    causes: tuple[Variant, ...]
    not_separable: tuple[str, ...]
    separate_by: str | None
    final: ModelFit
    rms: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)
    seconds: float = 0.0
    baseline_comparison: WholeRecord | None = None
    final_comparison: WholeRecord | None = None

    @property
    def cause(self) -> Variant | None:
        return self.causes[0] if self.causes else None

    @property
    def ranking(self) -> tuple[Ranked, ...]:
        return self.rounds[0] if self.rounds else ()


class Diagnoser:
    """Fits and scores extended models of one record (module docstring)."""

    def __init__(self, prep: Prepared, log_prior_f_nu: Callable[[Mapping[str, float]], float], *, hoop: bool,
                 seed: int, n_draws: int = 60, base_scales: Mapping[str, tuple[float, float]] | None = None) -> None:
        self.prep = prep
        rec = prep.record
        self.loading = measured_loading(rec, prep.forces)
        self.hoop = hoop and rec.has_hoop
        self.log_prior_f_nu = log_prior_f_nu
        self.seed = seed
        self.n_draws = n_draws
        E0 = rec.apparatus.sample.young_modulus
        self.E0 = E0
        self.modulus = Parameter("sample_modulus", "Pa", E0 / 4.0, 4.0 * E0, "Young's modulus of the sample")
        self.modulus_prior = stats.lognorm(s=SAMPLE_MODULUS_SD_LOG, scale=E0)
        self.block = max(1, int(round(BLOCK * rec.sample_rate)))
        d = prep.data
        self.context = Context(V=float(np.mean(d.V)), p_mean=float(np.nan), slip=float(np.mean(d.slip)))
        self._n_fit = 0
        self.base_scales = dict(base_scales or {})

    def _model(self, variants: tuple[Variant, ...]) -> SimulatorModel:
        extra = [self.modulus] + [p for v in variants for p in v.mechanism.parameters]
        def apply(values: Mapping[str, float], settings: dict[str, Any], gains: dict[str, float]) -> None:
            app = settings["apparatus"]
            settings["apparatus"] = replace(app, sample=replace(app.sample, young_modulus=float(values["sample_modulus"])))
            for v in variants:
                v.mechanism.apply(values, settings, gains, v.channel)

        return SimulatorModel(self.prep.record.apparatus, self.loading, hoop=self.hoop, extra=tuple(extra), apply=apply)

    def fit(self, variants: tuple[Variant, ...], start: Mapping[str, float], label: str) -> ModelFit:
        model = self._model(variants)
        lik = WholeRecordLikelihood(self.prep, model)

        def log_prior(values: Mapping[str, float]) -> float:
            out = self.log_prior_f_nu(values) + float(self.modulus_prior.logpdf(values["sample_modulus"]))
            for v in variants:
                out += v.mechanism.log_prior(values)
            return out

        st = {"f": start["f"], "nu": start["nu"], "sample_modulus": start.get("sample_modulus", self.E0)}
        for v in variants:
            for p in v.mechanism.parameters:
                st[p.name] = start.get(p.name, v.mechanism.start[p.name])
        self._n_fit += 1
        rng = np.random.default_rng(np.random.SeedSequence([self.seed, 9, self._n_fit]))
        scales = {"sample_modulus": self.modulus.gaussian_stand_in(self.modulus_prior), **self.base_scales}
        for v in variants:
            scales.update(v.mechanism.prior_z())
        # the baseline from several nu (the closed form's, and either side of the prior): see fit.py
        extra = () if variants else tuple({"nu": nu, "sample_modulus": self.E0} for nu in NU_STARTS)
        fit = fit_whole_record(lik, log_prior, st, n_draws=self.n_draws, rng=rng, importance=False,
                               prior_scale=scales, extra_starts=extra)
        pred, gain = lik.strains(fit.mode)
        dens, blocks, offset = [], [], 0
        for c in lik.channels:
            i0, _, _, i3 = lik.bounds[c]
            nz = lik.noise[c]
            w = lik.weight[c]
            logw = np.add.reduceat(np.log(w), np.arange(0, i3 - i0, self.block))
            dens.append(ar1_block_loo(lik.scaled_residual(c, pred[c])[None], sd=nz.sd, rho=nz.rho_long_run,
                                      block=self.block)[0] + logw)
            blocks.append(offset + np.arange(i3 - i0) // self.block)
            offset += len(dens[-1])
        # the offsets' pseudo-residuals (one per channel, last) belong to no block: give them the first
        n_pseudo = len(fit.whitened) - sum(len(b) for b in blocks)
        block_of = np.concatenate(blocks + [np.zeros(n_pseudo, int)])
        elpd = takeuchi_block_loo(np.concatenate(dens), fit.jacobian, fit.whitened, fit.cov_z, block_of)
        names = list(fit.draws)
        S = len(fit.draws["f"])
        f_eff = np.array([self._f_effective(variants, {n: float(fit.draws[n][s]) for n in names}) for s in range(S)])
        return ModelFit(label=label, variants=variants, fit=fit, hoop_gain=gain, elpd=elpd, f_effective=f_eff,
                        predicted={c: v[None] for c, v in pred.items()}, lik=lik)

    def predictive(self, mf: ModelFit, n: int = 30) -> dict[str, np.ndarray]:
        """Simulated gauges for the first ``n`` draws of a fitted model (channel -> (n, samples)), hoop gain
        profiled."""
        names = list(mf.fit.draws)
        rows: dict[str, list[np.ndarray]] = {}
        for s in range(min(n, len(mf.fit.draws["f"]))):
            pred, _ = mf.lik.strains({n: float(mf.fit.draws[n][s]) for n in names})
            for c, v in pred.items():
                rows.setdefault(c, []).append(v)
        return {c: np.array(v) for c, v in rows.items()}

    def _f_effective(self, variants: tuple[Variant, ...], values: Mapping[str, float]) -> float:
        ctx = self.context
        if not math.isfinite(ctx.p_mean):
            # mean wall pressure of the window: tau_mean / f (eq. 18, 20) under this draw's f
            d = self.prep.data
            tau = float(np.mean(d.F_eo)) / (2.0 * math.pi * d.radius * d.length)
            ctx = Context(V=ctx.V, p_mean=tau / max(float(values["f"]), 1e-6), slip=ctx.slip)
        f = float(values["f"])
        for v in variants:
            f = v.mechanism.f_effective({**values, "f": f}, ctx)
        return f


def candidates(exclude: tuple[str, ...] = ()) -> list[Variant]:
    """Every mechanism of the catalogue as fitted (gauge_gain once per gauge), minus ``exclude`` and
    the other members of an excluded mechanism's group (one friction law at a time)."""
    out: list[Variant] = []
    groups = {MECHANISMS[n].group for n in exclude if MECHANISMS[n].group}
    for m in MECHANISMS.values():
        if m.name in exclude or (m.group is not None and m.group in groups):
            continue
        out += [Variant(m, ch) for ch in m.channels] if m.channels else [Variant(m)]
    return out


def rank(reference: ModelFit, fits: list[ModelFit]) -> tuple[Ranked, ...]:
    out = [Ranked(f, *elpd_difference(f.elpd, reference.elpd)) for f in fits]
    return tuple(sorted(out, key=lambda r: -r.delpd))


def diagnose(prep: Prepared, log_prior_f_nu: Callable[[Mapping[str, float]], float], start: Mapping[str, float], *,
             hoop: bool, seed: int, n_draws: int = 1000, progress: Callable[[str], None] | None = None,
             base_scales: Mapping[str, tuple[float, float]] | None = None, max_causes: int = MAX_CAUSES) -> Diagnosis:
    """Fit the baseline and every mechanism, rank them and name the cause(s) (module docstring).

    ``base_scales``: Gaussian stand-ins (centre, sd in the unbounded coordinate) of the f and nu
    priors for the mode search.
    """
    t0 = time.perf_counter()
    say = progress or (lambda msg: None)
    dg = Diagnoser(prep, log_prior_f_nu, hoop=hoop, seed=seed, n_draws=n_draws, base_scales=base_scales)
    say("baseline")
    base = dg.fit((), start, "baseline")
    reference = base
    causes: list[Variant] = []
    rounds: list[tuple[Ranked, ...]] = []
    not_sep: tuple[str, ...] = ()
    separate_by = None
    for k in range(max_causes):
        fits = []
        used = tuple(v.mechanism.name for v in causes)
        for cand in candidates(exclude=used):
            say(cand.label)
            mode = dict(reference.fit.mode)
            fits.append(dg.fit(tuple(causes) + (cand,), mode, "+".join([v.label for v in causes] + [cand.label])))
        ranked = rank(reference, fits)
        rounds.append(ranked)
        decisive = [r for r in ranked if r.decisive]
        if not decisive:
            break
        best = decisive[0]
        if k == 0:
            close = []
            for r in decisive[1:]:
                d, se = elpd_difference(best.fit.elpd, r.fit.elpd)
                if not beyond(d, se, max(STRONG_ELPD, 0.1 * best.delpd)):
                    close.append(r.fit.variants[-1].mechanism.name)
            if close:
                names = [best.fit.variants[-1].mechanism.name] + [c for c in close if c != best.fit.variants[-1].mechanism.name]
                not_sep = tuple(dict.fromkeys(names))
                key = frozenset(not_sep[:2])
                separate_by = SEPARATE_BY.get(key, DEFAULT_SEPARATION)
        causes.append(best.fit.variants[-1])
        reference = best.fit
    final = reference
    say("posterior predictive of the baseline and the final model")
    base = replace(base, predicted=dg.predictive(base))
    final = replace(final, predicted=dg.predictive(final)) if causes else base
    a = compare_whole_record(prep, base.predicted)
    b = compare_whole_record(prep, final.predicted)
    return Diagnosis(baseline=base, rounds=tuple(rounds), causes=tuple(causes), not_separable=not_sep,
                     separate_by=separate_by, final=final, rms=residual_rms(a, b), seconds=time.perf_counter() - t0,
                     baseline_comparison=a, final_comparison=b)


def residual_rms(a: WholeRecord, b: WholeRecord) -> dict[str, dict[str, tuple[float, float]]]:
    """RMS of residual / noise sd per channel and phase: (baseline, final model)."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    fb = {(f.channel, f.phase): f.rms for f in b.figures}
    for f in a.figures:
        out.setdefault(f.channel, {})[f.phase] = (f.rms, fb.get((f.channel, f.phase), float("nan")))
    return out

