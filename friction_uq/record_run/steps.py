"""The stages of ``friction-uq run`` before its outputs: the inputs checked and the signals prepared
(:func:`set_up`), then the stationary posterior and what is read from it (:func:`stationary_posterior`).
:func:`friction_uq.record_run.pipeline.run_file` calls them in that order, between the output folder's lock and
the writing of the outputs.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..analysis import Identification, Prepared, identify, prepare
from ..diagnostics import (
    Convergence,
    FNuBand,
    RatioPPC,
    VariableSummary,
    build_datatree,
    convergence,
    f_given_nu,
    nu_sensitivity,
    nu_variance_share,
    prior_data_conflict,
    ratio_ppc,
    summarize,
)
from ..errors import OutputError, SamplingError
from ..hoop_or_prior import HOOP_OR_PRIOR_GROUP, HoopOrPrior, TwoReadings, disagree, hoop_or_prior, worth_asking
from ..likelihood import Likelihood
from ..prior_sensitivity import FUnderPrior, PriorDataConflict
from ..priors import Priors
from ..prior_loader import load_priors, record_prior_path
from ..quoted import quoted_summary
from ..record import Record, read_record
from ..sampler import PosteriorSamples, likelihood_priors, sample_posterior, stderr_progress
from ..settings import AnalysisSettings
from ..window_halves import WindowHalves, window_halves
from .._atomic import check_unlocked
from .inputs import alternative_nu_priors, hoop_fault, hoop_silence, sliding_velocity_summary
from .outputs import safe_stem

if TYPE_CHECKING:
    import xarray as xr


@dataclass(frozen=True)
class RunSetup:
    """What a run decided from its inputs before any sampling."""

    record: Record
    prior_path: Path
    priors: Priors
    prepared: Prepared
    settings: AnalysisSettings
    alternatives: dict[str, Priors]  # the nu priors f is also shown under (the one used: "default")
    hoop_left_out: str | None  # why the hoop gauge is left out of the likelihood, or None
    #: left out because it reads nothing a swelling tube makes (:func:`.inputs.hoop_silence`): a dead bridge, or a
    #: sample that hardly swells
    hoop_silent: bool
    use_hoop: bool
    likelihood: Likelihood  # built once, passed to every stage that needs it
    stem: str
    names: dict[str, Path]  # "netcdf", "pdf", "json" -> the output's path
    lab: Identification  # the lab's analysis: eq. 17 at the nominal nu (the prior's median)
    halves: WindowHalves | None  # kappa's change across the window (the JSON's and the report's), or None


def _likelihood(prep: Prepared, settings: AnalysisSettings, *, hoop: bool) -> Likelihood:
    """The run's likelihood over the stationary data, as ``settings`` build it, with or without the hoop term."""
    return Likelihood(prep.data, hoop=hoop, axial_poisson=settings.axial_poisson, hoop_mode=settings.hoop_mode,
                      hoop_discrepancy=settings.hoop_discrepancy, force_mode=settings.force_mode,
                      ratio_model_form=settings.ratio_model_form)


def set_up(path: str | os.PathLike[str], priors_path: str | os.PathLike[str] | None, out_dir: Path, *,
           window: tuple[float, float] | None, dispersion: bool, hoop: bool) -> RunSetup:
    """Every input checked (record, priors, the output folder and names) and the signals prepared."""
    record = read_record(path, hoop=hoop)  # --no-hoop: the hoop channel unread (a dead bridge stops nothing)
    p_path = Path(priors_path) if priors_path else record_prior_path(record.path, record.apparatus.sample.material)
    priors = load_priors(p_path)  # every input is checked before the signals' work, the busy folder too
    stem = safe_stem(record.campaign, record.test_id)
    check_unlocked(out_dir, stem)
    prep = prepare(record, window=window, dispersion=dispersion)
    settings = AnalysisSettings(window=window, dispersion=dispersion, hoop=hoop)
    alternatives = alternative_nu_priors(p_path, priors)
    left_out, silent = None, False
    if settings.hoop and prep.data.hoop is None:
        left_out = "the record has no hoop gauge (/signals/tube_hoop)"
    elif settings.hoop:
        fault = hoop_fault(prep)
        silence = None if fault else hoop_silence(prep)
        left_out, silent = fault or silence, silence is not None
    use_hoop = bool(settings.hoop and prep.data.hoop is not None and left_out is None)
    likelihood = _likelihood(prep, settings, hoop=use_hoop)
    likelihood_priors(likelihood, priors)  # the prior file holds every parameter the likelihood needs
    names = {"netcdf": out_dir / f"{stem}.nc", "pdf": out_dir / f"{stem}.pdf", "json": out_dir / f"{stem}.json"}
    for p in names.values():
        if p.is_dir():
            raise OutputError(f"{p}: cannot write the output, a directory has that name")
    lab = identify(prep, nu=round(float(priors["nu"].ppf(0.5)), 3))
    return RunSetup(record, p_path, priors, prep, settings, alternatives, left_out, silent, use_hoop, likelihood, stem,
                    names, lab, window_halves(prep.data))


@dataclass(frozen=True)
class StationaryPosterior:
    """The stationary posterior of f and nu and what is read from it."""

    samples: PosteriorSamples
    datatree: xr.DataTree
    convergence: Convergence
    summary: dict[str, VariableSummary]
    sensitivity: dict[str, FUnderPrior]  # f under each nu prior of ``RunSetup.alternatives``
    conflict: PriorDataConflict
    band: FNuBand  # f given nu
    nu_share: float  # the share of f's variance that comes from nu
    ppc: RatioPPC
    V: VariableSummary  # the sliding velocity over the window (measured)
    f_quoted: dict[str, float]  # the stationary f to quote, with the output bars' calibration: mean, sd, q05, q50, q95
    #: f with the hoop gauge and from the prior's nu alone, when the prior-data check flags the hoop term's posterior
    #: (then ``f_quoted`` is the two in equal parts: :mod:`friction_uq.hoop_or_prior`), else None
    hoop_or_prior: HoopOrPrior | None = None

    @property
    def f_read(self) -> VariableSummary:
        """f's posterior summary the warnings and the JSON's ``f.given_bar_headers`` read: the run's, or where the hoop
        gauge and nu's prior disagree, the two readings in equal parts (as ``f_quoted``)."""
        f = self.summary["f"]
        if self.hoop_or_prior is None:
            return f
        return TwoReadings(**(dataclasses.asdict(f) | self.hoop_or_prior.f_given_headers))


def stationary_posterior(s: RunSetup, *, seed: int, backend: Path, progress: bool, say: Callable[[str], None],
                         note: Callable[[str], None], stages: dict[str, float]) -> StationaryPosterior:
    """Sample the stationary posterior (resuming from ``backend``), build its DataTree and read it: the
    sensitivity to the nu prior, the prior-data check, f given nu, the predictive check; ``stages`` takes
    the seconds of each step."""
    t = time.perf_counter()
    try:
        samples = sample_posterior(s.prepared.data, s.priors, seed=seed, hoop=s.use_hoop, backend_path=backend,
                                   progress=stderr_progress if progress else None, notify=note,
                                   likelihood=s.likelihood)
    except SamplingError as exc:  # the sampler knows the priors, not the record: name it
        raise SamplingError(f"{s.record.path}: {exc}") from None
    stages["sampling"] = time.perf_counter() - t
    t = time.perf_counter()
    dt = build_datatree(samples, s.prepared.data, s.priors, seed=seed, likelihood=s.likelihood)
    dt.attrs["analysis_settings"] = s.settings.to_attr()  # provenance: how the likelihood was built
    conv = convergence(dt, samples)
    summary = summarize(dt)
    stages["datatree"] = time.perf_counter() - t
    t = time.perf_counter()
    sens = nu_sensitivity(s.prepared.data, s.alternatives, seed=seed, hoop=s.use_hoop, done={"default": samples},
                          likelihood=s.likelihood)
    n_rerun = sum(x.method == "sampled" for k, x in sens.items() if k != "default")
    say(f"sensitivity to the nu prior: {len(s.alternatives) - 1} alternatives, {len(s.alternatives) - 1 - n_rerun} "
        f"by importance reweighting, {n_rerun} sampled afresh")
    conflict = prior_data_conflict(dt, samples, s.priors)
    if conflict.flagged:
        note(conflict.sentence())
    both = _hoop_or_prior(s, samples, conflict, seed=seed, say=say)
    if both is not None:
        dt[HOOP_OR_PRIOR_GROUP] = both.datatree_group()
    stages["sensitivity"] = time.perf_counter() - t
    t = time.perf_counter()
    band = f_given_nu(samples, np.linspace(0.15, 0.49, 69))
    share = nu_variance_share(samples)
    ppc = ratio_ppc(samples, s.prepared.data, seed=seed, likelihood=s.likelihood)
    V = sliding_velocity_summary(s.prepared)
    f_quoted = quoted_summary(samples.flat("f")) if both is None else both.f_quoted
    stages["analysis"] = time.perf_counter() - t
    return StationaryPosterior(samples, dt, conv, summary, sens, conflict, band, share, ppc, V, f_quoted, both)


def _hoop_or_prior(s: RunSetup, samples: PosteriorSamples, conflict: PriorDataConflict, *, seed: int,
                   say: Callable[[str], None]) -> HoopOrPrior | None:
    """When the prior-data check flags the hoop term's posterior: the posterior again with the hoop gauge left out,
    and the two readings (:mod:`friction_uq.hoop_or_prior`); else None."""
    if not worth_asking(conflict, s.use_hoop):
        return None
    say("the prior-data check flags the posterior with the hoop gauge: sampling again with nu from the prior alone")
    alone = sample_posterior(s.prepared.data, s.priors, seed=seed, hoop=False,
                             likelihood=_likelihood(s.prepared, s.settings, hoop=False))
    if not disagree(conflict, samples.flat("f"), alone.flat("f")):
        return None
    return hoop_or_prior(samples, alone, s.priors, conflict, s.likelihood.hoop, s.prepared.data)
