"""Convergence (R-hat across independent ensembles, ESS) and the per-variable summaries."""

from __future__ import annotations

import math
from dataclasses import dataclass

import arviz_stats
import numpy as np
import xarray as xr

from ..sampler import PosteriorSamples


#: Variables summarised, in report order (hoop_gain only when sampled).
SUMMARY_VARIABLES = ("f", "nu", "kappa", "hoop_gain", "ratio", "p_mean", "tau_mean")
#: Probabilities of the quantiles reported everywhere.
QUANTILES = (0.05, 0.5, 0.95)

@dataclass(frozen=True)
class Convergence:
    """R-hat across independent ensembles and effective sample sizes (arviz_stats, rank-normalised)."""

    r_hat_max: float
    ess_bulk_min: float
    ess_tail_min: float
    ess_per_second: float
    seconds: float
    converged: bool
    n_steps: int
    tau_max: float
    acceptance: float

    @property
    def ok(self) -> bool:
        """R-hat < 1.01, bulk and tail ESS >= 400 and the sampler's own criterion met."""
        return self.converged and self.r_hat_max < 1.01 and min(self.ess_bulk_min, self.ess_tail_min) >= 400.0

    def to_json(self) -> dict[str, float | int | bool]:
        return {k: getattr(self, k) for k in self.__dataclass_fields__} | {"ok": self.ok}


def _posterior_vars(dt: xr.DataTree) -> list[str]:
    return [v for v in SUMMARY_VARIABLES if v in dt["posterior"].data_vars]


def convergence(dt: xr.DataTree, samples: PosteriorSamples) -> Convergence:
    """R-hat max, bulk/tail ESS min over the posterior variables, ESS min per sampling second."""
    var_names = _posterior_vars(dt)
    rhat = arviz_stats.rhat(dt, var_names=var_names)
    bulk = arviz_stats.ess(dt, var_names=var_names, method="bulk")
    tail = arviz_stats.ess(dt, var_names=var_names, method="tail")
    r_max = max(float(rhat[v].values) for v in var_names)
    b_min = min(float(bulk[v].values) for v in var_names)
    t_min = min(float(tail[v].values) for v in var_names)
    return Convergence(
        r_hat_max=r_max, ess_bulk_min=b_min, ess_tail_min=t_min,
        ess_per_second=b_min / samples.seconds if samples.seconds > 0 else math.inf,
        seconds=samples.seconds, converged=samples.converged, n_steps=samples.n_steps,
        tau_max=float(samples.tau.max()), acceptance=float(samples.acceptance.mean()),
    )


@dataclass(frozen=True)
class VariableSummary:
    """Posterior summary of one variable (its SI unit; plain floats)."""

    mean: float
    sd: float
    q05: float
    q50: float
    q95: float
    r_hat: float
    ess_bulk: float

    def to_json(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def summarize(dt: xr.DataTree) -> dict[str, VariableSummary]:
    """Mean, sd, 5/50/95 % quantiles, R-hat and bulk ESS of each posterior variable."""
    var_names = _posterior_vars(dt)
    rhat = arviz_stats.rhat(dt, var_names=var_names)
    bulk = arviz_stats.ess(dt, var_names=var_names, method="bulk")
    out = {}
    for v in var_names:
        x = np.asarray(dt["posterior"][v].values, float).reshape(-1)
        x = x[np.isfinite(x)]
        q = np.quantile(x, QUANTILES)
        out[v] = VariableSummary(
            float(np.mean(x)), float(np.std(x, ddof=1)), float(q[0]), float(q[1]), float(q[2]),
            float(rhat[v].values), float(bulk[v].values),
        )
    return out
