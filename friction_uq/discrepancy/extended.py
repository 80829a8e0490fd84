"""Extended models of one record: each mechanism of the catalogue added to the baseline simulator,
fitted to the whole record and scored by its expected log predictive density.

For each mechanism (:mod:`.mechanisms`; ``gauge_gain`` once per bar gauge) the simulator driven by
the measured incident wave, extended by the mechanism, is fitted to the whole record (:mod:`.fit`:
posterior by a Laplace approximation; f, nu and the sample's modulus stay free, a nuisance with a
10 % lognormal prior, the hoop gauge's calibration factor marginalised under its 5 % prior) and scored by its expected log predictive
density over blocks of 10 us of every gauge (:mod:`.block_loo`: exact leave-one-block-out for AR(1)
noise) and over the calibration data the fit takes as priors (the hoop gauge's factor, the sample's
modulus), each left out in turn. The baseline is the same simulator without extension. What is
named from these scores is :mod:`.diagnose`'s rule.

The headline f under an extended model is the wall's coefficient at the stationary window's mean
sliding speed, pressure and slip (``f_effective`` of the mechanism), summarised over the draws: with ``nu_cut``
(as ``run`` has it) the cut posterior's, nu read from the stationary windows under the model (:mod:`.nu_cut`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import stats

from .._parallel import can_fork, forked_map
from ..analysis import Prepared
from ..models import Parameter, SimulatorModel, measured_loading
from ..models.parameters import summarize_draws
from ..physics.cell import mean_friction_stress
from ..models.measurement_chain import Reading
from ..stats.ar1 import ar1_block_loo
from ..stats.streams import stream
from .block_loo import Elpd, calibration_loo, takeuchi_block_loo, with_calibration
from .fit import WholeRecordFit, WholeRecordLikelihood, fit_whole_record
from .record_likelihood import HOOP_GAIN_SD
from .mechanisms import MECHANISMS, Context, Mechanism
from .nu_cut import CutFit, conditional_fit, window_nu
from .whole_record import CHANNEL_LABELS

#: Block of the leave-one-block-out ELPD (s).
BLOCK = 10e-6
#: Further starting values of nu for the baseline's mode search.
NU_STARTS = (0.33, 0.45)
SAMPLE_MODULUS_SD_LOG = 0.1
#: Draws of nu's normal approximation from the stationary windows (:func:`.nu_cut.window_nu`).
NU_WINDOW_DRAWS = 2000


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
    #: the fit at the windows' nu, when f is the cut posterior's (:mod:`.nu_cut`); None: f is the joint fit's
    cut: CutFit | None = None

    def f_summary(self) -> dict[str, float]:
        return summarize_draws(self.f_effective)

    @property
    def f_from(self) -> str:
        """Whose draws f_effective holds: the cut posterior's (:mod:`.nu_cut`) or the whole-record fit's."""
        return "cut posterior" if self.cut is not None else "whole-record fit"


def _key(mf: ModelFit) -> tuple:
    """A fitted model's identity: its label and its mode (a swap check may fit a round's label again from another
    start, :mod:`.rival_swaps`)."""
    return (mf.label, tuple(sorted(mf.fit.mode.items())))


def nominal_starts(variants: tuple[Variant, ...]) -> tuple[dict[str, float], ...]:
    """The mechanisms' own nominal start (``Mechanism.start``) as one further start of a search (none for the
    reference model): a search from the joint fit's mode alone can stop in a shallow dip of a rough surface."""
    if not variants:
        return ()
    return ({p.name: v.mechanism.start[p.name] for v in variants for p in v.mechanism.parameters},)


class Diagnoser:
    """Fits and scores extended models of one record (module docstring)."""

    def __init__(self, prep: Prepared, log_prior_f_nu: Callable[[Mapping[str, float]], float], *, hoop: bool,
                 seed: int, n_draws: int = 60, base_scales: Mapping[str, tuple[float, float]] | None = None,
                 nominal: Mapping[str, float] | None = None, nu_cut: bool = False,
                 hoop_calibration: tuple[float, float] = (1.0, HOOP_GAIN_SD)) -> None:
        self.prep = prep
        #: the hoop gauge's known factor (median, relative sd) every model's likelihood reads it with
        self.hoop_calibration = hoop_calibration
        #: a model's f from the cut posterior, nu from the record's stationary window (:mod:`.nu_cut`); else the joint fit's
        self.nu_cut = nu_cut
        rec = prep.record
        self.loading = measured_loading(rec, prep.forces)
        self.dispersive_loading = measured_loading(rec, prep.forces, dispersion=True)  # for ``dispersion``
        #: an analysis with the dispersion correction (``--dispersion``): every model's bars disperse, as the
        #: whole-record check's (:mod:`.check`) and the forces' do; the ``dispersion`` entry, that model again, is then
        #: no candidate (:attr:`in_baseline`)
        self.dispersion = prep.forces.dispersion
        #: the catalogue's entries the baseline already holds
        self.in_baseline: tuple[str, ...] = ("dispersion",) if self.dispersion else ()
        self.hoop = hoop and rec.has_hoop
        #: the gauges the record is read by: the measurement chain's entries are fitted on these
        self.gauges = tuple(c for c in CHANNEL_LABELS if c in rec.channels and (c != "tube_hoop" or self.hoop))
        self.log_prior_f_nu = log_prior_f_nu
        self.seed = seed
        self.n_draws = n_draws
        E0 = rec.apparatus.sample.young_modulus
        self.E0 = E0
        self.modulus = Parameter("sample_modulus", "Pa", E0 / 4.0, 4.0 * E0, "Young's modulus of the sample")
        self.modulus_prior = stats.lognorm(s=SAMPLE_MODULUS_SD_LOG, scale=E0)
        self.block = max(1, int(round(BLOCK * rec.sample_rate)))
        d = prep.data
        tau = float(mean_friction_stress(np.mean(d.F_eo), radius=d.radius, length=d.length))  # eq. 18, 20
        # a sample that does not slide has a window mean V and slip of either sign within the noise; the laws of the
        # catalogue read speed and slip as magnitudes (a negative one made f_effective fall with f: an internal error)
        sigma = (float(np.mean(d.F_io)) + 0.5 * float(np.mean(d.F_eo))) / (math.pi * d.radius**2)  # eq. 19, 21
        self.context = Context(V=max(float(np.mean(d.V)), 0.0), tau_mean=tau, slip=max(float(np.mean(d.slip)), 0.0),
                               sigma_mean=sigma)
        self.base_scales = dict(base_scales or {})
        #: f and nu of the stationary analysis: with the header's modulus, a second start of every extended fit
        self.nominal = dict(nominal or {})
        #: the models whose cut posterior was made (:meth:`resolved`), by label and mode (:func:`_key`)
        self._resolved: dict[tuple, ModelFit] = {}

    def _model(self, variants: tuple[Variant, ...]) -> SimulatorModel:
        extra = [self.modulus] + [p for v in variants for p in v.mechanism.parameters]
        def apply(values: Mapping[str, float], settings: dict[str, Any], readings: dict[str, Reading]) -> None:
            app = settings["apparatus"]
            sample = replace(app.sample, young_modulus=float(values["sample_modulus"]))
            settings["apparatus"] = replace(app, sample=sample)
            for v in variants:
                v.mechanism.apply(values, settings, readings, v.channel)

        return SimulatorModel(self.prep.record.apparatus, self.loading, hoop=self.hoop, extra=tuple(extra),
                              apply=apply, dispersion=self.dispersion, dispersive_loading=self.dispersive_loading)

    def fit(self, variants: tuple[Variant, ...], start: Mapping[str, float], label: str, *,
            cut: bool = True) -> ModelFit:
        """The model's whole-record fit and ELPD; with ``nu_cut``, f from the cut posterior (:meth:`resolved`) unless
        ``cut`` is False: then f is the joint fit's until :meth:`resolved` is asked for it (the names and the evidence
        do not depend on the cut; the cut is seeded by the label, so it gives the same bits whenever it is made)."""
        model = self._model(variants)
        lik = WholeRecordLikelihood(self.prep, model, hoop_calibration=self.hoop_calibration)
        log_prior = self.log_prior(variants)

        st = {"f": start["f"], "nu": start["nu"], "sample_modulus": start.get("sample_modulus", self.E0)}
        for v in variants:
            for p in v.mechanism.parameters:
                st[p.name] = start.get(p.name, v.mechanism.start[p.name])
        # seeded by the model's label: the same draws whichever process fits it, in whatever order
        rng = stream(self.seed, "extended fit", label)
        scales = self._scales(variants)
        # the baseline from several nu (the closed form's, and either side of the prior): see fit.py. An
        # extended model also from the stationary analysis's f and nu with the header's modulus: a reference
        # model that misses the record bends nu and the modulus to fit it (on a record with bare end faces, nu
        # 0.31 and the modulus 1.5 times the header's), and the mechanism that explains the record is found
        # from there only at a poorer mode; not needed (and not made) while the modulus is within its prior's sd
        if not variants:
            extra = tuple({"nu": nu, "sample_modulus": self.E0} for nu in NU_STARTS)
        elif abs(self.modulus.to_unbounded(st["sample_modulus"]) - scales["sample_modulus"][0]) > \
                scales["sample_modulus"][1]:
            extra = ({**{k: self.nominal[k] for k in ("f", "nu") if k in self.nominal}, "sample_modulus": self.E0},)
        else:
            extra = ()
        extra += tuple(dict(s) for v in variants for s in v.mechanism.further_starts(self.context, st["nu"]))
        block_of = lik.blocks(self.block)
        fit = fit_whole_record(lik, log_prior, st, n_draws=self.n_draws, rng=rng, importance=False,
                               prior_scale=scales, extra_starts=extra, score_blocks=block_of)
        unit = lik.unit_strains(fit.mode)
        pred, gain = lik.scaled(unit)
        dens = []
        for c in lik.channels:
            i0, _, _, i3 = lik.bounds[c]
            nz = lik.noise[c]
            logw = np.add.reduceat(np.log(lik.weight[c]), np.arange(0, i3 - i0, self.block))
            dens.append(ar1_block_loo(lik.scaled_residual(c, unit[c])[None], sd=nz.sd, rho=nz.rho_long_run,
                                      block=self.block)[0] + logw)
        elpd = takeuchi_block_loo(np.concatenate(dens), fit.jacobian, fit.whitened, fit.cov_z, block_of)
        elpd = with_calibration(elpd, self._calibration(lik, fit, unit, scales["sample_modulus"]))
        mf = ModelFit(label=label, variants=variants, fit=fit, hoop_gain=gain, elpd=elpd,
                      f_effective=self.f_of(variants, fit.draws), predicted={c: v[None] for c, v in pred.items()},
                      lik=lik)
        return self.resolved(mf) if cut else mf

    def _scales(self, variants: tuple[Variant, ...]) -> dict[str, tuple[float, float]]:
        """The Gaussian stand-ins of a model's priors for the mode searches (the sample's modulus, the mechanisms')."""
        scales = {"sample_modulus": self.modulus.gaussian_stand_in(self.modulus_prior), **self.base_scales}
        for v in variants:
            scales.update(v.mechanism.prior_z())
        return scales

    def resolved(self, mf: ModelFit) -> ModelFit:
        """The model with f from the cut posterior (:mod:`.nu_cut`) when ``nu_cut`` is on, made once per model
        (kept by its label and mode, :func:`_key`); the model as it is otherwise. Its ELPD, mode and predictions are
        the joint fit's; its draws become the cut posterior's (paired with f), the joint fit's kept as
        ``laplace_draws`` for the predictive, as calibrated."""
        if not self.nu_cut or mf.cut is not None:
            return mf
        key = _key(mf)
        if key in self._resolved:
            return self._resolved[key]
        cut = self._cut(mf)
        params = [mf.lik.model.parameters[n] for n in cut.fit.names]
        z = np.column_stack([np.asarray(p.to_unbounded(cut.fit.draws[p.name]), float) for p in params])
        draws = cut.draws(params, z, stream(self.seed, "nu cut draws", mf.label))
        fit = replace(mf.fit, draws=draws, laplace_draws=mf.fit.laplace_draws or mf.fit.draws)
        out = replace(mf, fit=fit, f_effective=self.f_of(mf.variants, draws), cut=cut)
        self._resolved[key] = out
        return out

    def known(self, mf: ModelFit) -> ModelFit:
        """The model as :meth:`resolved` made it, if it was asked for; else as it is (no fit is made here)."""
        return self._resolved.get(_key(mf), mf) if mf.cut is None else mf

    def _cut(self, mf: ModelFit) -> CutFit:
        """The cut posterior's fit (:mod:`.nu_cut`): nu from the stationary windows, every parameter free under its
        prior (the search from the joint fit's mode, the sample's modulus from its header's), then theta at that nu."""
        lik, mode, label = mf.lik, mf.fit.mode, mf.label
        assert lik is not None  # every fit made here carries its likelihood
        log_prior, scales = self.log_prior(mf.variants), self._scales(mf.variants)
        nu_window = window_nu(self.prep, lik.model, log_prior, dict(mode) | {"sample_modulus": self.E0},
                              n_draws=NU_WINDOW_DRAWS, rng=stream(self.seed, "nu window", label), prior_scale=scales,
                              hoop_calibration=self.hoop_calibration, extra_starts=nominal_starts(mf.variants))
        return conditional_fit(lik, log_prior, mode, nu_window, n_draws=self.n_draws,
                               rng=stream(self.seed, "nu cut", label), prior_scale=scales,
                               score_blocks=lik.blocks(self.block))

    def f_of(self, variants: tuple[Variant, ...], draws: Mapping[str, np.ndarray]) -> np.ndarray:
        """f_effective of each draw."""
        S = len(draws["f"])
        return np.array([self._f_effective(variants, {n: float(v[s]) for n, v in draws.items()}) for s in range(S)])

    def log_prior(self, variants: tuple[Variant, ...]) -> Callable[[Mapping[str, float]], float]:
        """The log prior density of a model's parameters (f, nu, the sample's modulus, the mechanisms')."""
        def log_prior(values: Mapping[str, float]) -> float:
            out = self.log_prior_f_nu(values) + float(self.modulus_prior.logpdf(values["sample_modulus"]))
            for v in variants:
                out += v.mechanism.log_prior(values)
            return out

        return log_prior

    def _calibration(self, lik: WholeRecordLikelihood, fit: WholeRecordFit, unit: Mapping[str, np.ndarray],
                     modulus_scale: tuple[float, float]) -> dict[str, tuple[float, float, float]]:
        """The calibration data left out in turn (:func:`~.elpd.calibration_loo`): the hoop gauge's factor
        (its known median +- its prior sd) and the sample's modulus (the header's, its prior's Gaussian stand-in in the
        unbounded coordinate), each from the fit's posterior at the mode."""
        out = {}
        if "tube_hoop" in lik.gain_sd:
            m, v = lik.gain_posterior("tube_hoop", unit["tube_hoop"])
            out["hoop_gain"] = calibration_loo(m, v, 0.0, lik.gain_sd["tube_hoop"])
        i = fit.names.index("sample_modulus")
        v = float(fit.cov_z[i, i]) if fit.cov_z is not None else 0.0
        out["sample_modulus"] = calibration_loo(float(self.modulus.to_unbounded(fit.mode["sample_modulus"])), v,
                                                *modulus_scale)
        return out

    def fit_many(self, jobs: list[tuple[tuple[Variant, ...], Mapping[str, float], str]], *,
                 workers: int = 1, cut: bool = True) -> list[ModelFit]:
        """:meth:`fit` for each (variants, start, label) job, on ``workers`` processes (forked: they share
        this object). A daemon process or one running other threads (a campaign's Dask worker: forking
        a threaded process can deadlock) fits them in turn. Same results as one by one. ``cut``: as
        :meth:`fit`'s (False: the cut is left to :meth:`resolved`, for the models whose f is reported)."""
        def fit_job(job: tuple[tuple[Variant, ...], Mapping[str, float], str]) -> tuple:
            mf = self.fit(*job, cut=cut)  # what of the fit can be pickled back from a forked worker
            return mf.fit, mf.hoop_gain, mf.elpd, mf.f_effective, mf.predicted, mf.cut

        if min(workers, len(jobs)) <= 1 or not can_fork():
            return [self.fit(*job, cut=cut) for job in jobs]
        parts = forked_map(fit_job, jobs, workers=workers)
        out = []
        for (variants, _, label), (fit, gain, elpd, f_eff, predicted, cut_fit) in zip(jobs, parts):
            lik = WholeRecordLikelihood(self.prep, self._model(variants),  # closures do not cross processes
                                        hoop_calibration=self.hoop_calibration)
            mf = ModelFit(label=label, variants=variants, fit=fit, hoop_gain=gain, elpd=elpd,
                          f_effective=f_eff, predicted=predicted, lik=lik, cut=cut_fit)
            if cut_fit is not None:
                self._resolved.setdefault(_key(mf), mf)
            out.append(mf)
        return out

    def predictive(self, mf: ModelFit, n: int = 30) -> dict[str, np.ndarray]:
        """Simulated gauges for the first ``n`` draws of a fitted model (channel -> (n, samples)), the hoop
        gauge's most probable calibration factor applied."""
        draws = mf.fit.laplace_draws or mf.fit.draws  # the likelihood's posterior: the misfit decision's footing
        rows: dict[str, list[np.ndarray]] = {}
        for s in range(min(n, len(draws["f"]))):
            pred, _ = mf.lik.strains({k: float(v[s]) for k, v in draws.items()})
            for c, v in pred.items():
                rows.setdefault(c, []).append(v)
        return {c: np.array(v) for c, v in rows.items()}

    def _f_effective(self, variants: tuple[Variant, ...], values: Mapping[str, float]) -> float:
        f = float(values["f"])
        for v in variants:
            f = v.mechanism.f_effective({**values, "f": f}, self.context)
        return float(f)


def candidates(exclude: tuple[str, ...] = (), gauges: tuple[str, ...] | None = None) -> list[Variant]:
    """Every mechanism of the catalogue as fitted (gauge_gain once per gauge), minus ``exclude`` and
    the other members of an excluded mechanism's group (one friction law at a time). ``gauges``: the gauges
    the record is read by (:attr:`Diagnoser.gauges`): the measurement chain's entries on those only (None: all)."""
    out: list[Variant] = []
    groups = {MECHANISMS[n].group for n in exclude if MECHANISMS[n].group}
    for entry in MECHANISMS.values():
        if entry.name in exclude or (entry.group is not None and entry.group in groups):
            continue
        m = entry if gauges is None else entry.on_gauges(gauges)
        if m is not None:
            out += [Variant(m, ch) for ch in m.channels] if m.channels else [Variant(m)]
    return out
