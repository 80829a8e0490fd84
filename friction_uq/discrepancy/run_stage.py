"""The discrepancy stage as ``run`` calls it: with the run's priors and its stationary posterior."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace

import numpy as np

from ..analysis import Prepared
from ..models.parameters import F
from ..models.simulator import NU
from ..priors import Priors
from .check import WholeRecordCheck, check_whole_record
from .diagnose import Diagnosis, diagnose
from .record_likelihood import HOOP_GAIN_SD, hoop_calibration


def f_nu_log_prior(priors: Priors) -> Callable[[Mapping[str, float]], float]:
    """log prior of f and nu from the run's prior file."""

    def log_prior(v: Mapping[str, float]) -> float:
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    return log_prior


def _hoop_calibration(priors: Priors) -> tuple[float, float]:
    """The hoop gauge's factor as the run's prior file states it (a prior file without ``hoop_gain``: 1 +- 5 %)."""
    return hoop_calibration(priors["hoop_gain"]) if "hoop_gain" in priors else (1.0, HOOP_GAIN_SD)


def whole_record_check(prep: Prepared, priors: Priors, start: Mapping[str, float], *, hoop: bool,
                       seed: int) -> WholeRecordCheck:
    """:func:`.check.check_whole_record` with the run's f and nu priors, started from ``start`` (run: the
    lab's eq. 17 estimate)."""
    return check_whole_record(prep, f_nu_log_prior(priors), start, hoop=hoop and prep.record.has_hoop, seed=seed,
                              hoop_calibration=_hoop_calibration(priors))


def run_diagnose(prep: Prepared, priors: Priors, start: Mapping[str, float], *, hoop: bool, seed: int,
                 say: Callable[[str], None] = lambda msg: None, check: WholeRecordCheck | None = None,
                 stationary_f: np.ndarray | None = None) -> Diagnosis:
    """:func:`.diagnose.diagnose` with the run's f and nu priors (and their Gaussian stand-ins for the
    mode search), started from the stationary posterior's medians; ``check``: the run's whole-record
    check, whose hoop reading the calibration finding compares with the final model's; ``stationary_f``: the
    stationary posterior's draws of f (half of the f to quote when no cause is named). Every whole-record model's f
    is the cut posterior's (:mod:`.nu_cut`)."""
    scales = {par.name: par.gaussian_stand_in(priors[par.name]) for par in (F, NU)}
    dg = diagnose(prep, f_nu_log_prior(priors), start, hoop=hoop and prep.record.has_hoop, seed=seed,
                  progress=lambda m: say(f"diagnose: {m}"), base_scales=scales, stationary_f=stationary_f,
                  nu_cut=True, hoop_calibration=_hoop_calibration(priors))
    return dg if check is None else replace(dg, check_hoop_gain=check.hoop_gain)


def add_whole_record(dt, wrc: WholeRecordCheck) -> None:
    """Simulated gauges of the posterior draws over the whole record (``posterior_predictive``) and
    the measured ones (``whole_record_observed``), on the record's time base."""
    import xarray as xr

    comp = wrc.comparison
    n_draw = len(next(iter(comp.predicted.values())))
    pp = {ch: (("chain", "draw", "time_record"), v[None]) for ch, v in comp.predicted.items()}
    obs = {ch: (("time_record",), v) for ch, v in comp.measured.items()}
    coords = {"time_record": comp.time}
    dt["posterior_predictive"] = xr.DataTree(xr.Dataset(
        pp, coords=coords | {"chain": [0], "draw": np.arange(n_draw)},
        attrs={"description": "gauge strains (compression positive) simulated for draws of the whole-record fit "
                              "of the simulator driven by the measured incident wave",
               "misfit_statistic": wrc.decision.statistic, "misfit_threshold": wrc.decision.threshold,
               "misfit_detected": int(wrc.decision.detected)}))
    dt["whole_record_observed"] = xr.DataTree(xr.Dataset(obs, coords=coords, attrs={
        "description": "measured gauge strains, offset removed, compression positive"}))
