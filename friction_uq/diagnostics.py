"""Posterior diagnostics and summaries: plain data for the report (which only draws them).

* :func:`build_datatree`: ArviZ 1.x ``xarray.DataTree`` with groups posterior (sampled and
  derived variables), log_likelihood (per time segment), observed_data, sample_stats, prior;
  dims ("chain", "draw") where chain = an independent emcee ensemble (see
  :mod:`friction_uq.sampler`).
* :func:`convergence`: R-hat max and ESS min (arviz_stats), ESS per second.
* :func:`summarize`: mean, sd, q05, q50, q95 (+ R-hat, ESS) per variable as floats.
* :func:`f_given_nu`, :func:`nu_variance_share`: how the uncertainty of nu propagates into f;
  :func:`nu_sensitivity` and :func:`prior_data_conflict` live in
  :mod:`friction_uq.prior_sensitivity` (re-exported here).
* :func:`ratio_ppc`: posterior predictive of F_eo/F_io over the window.

Derived variables per draw (SI units): ratio r = expm1(f beta(nu)) (eq. 5, 13); kappa = f nu/(1-nu);
tau_mean = r <x> / (2 pi R L) (eq. 18, with <x> the window mean of the latent true F_io given r,
:meth:`~friction_uq.likelihood.ForceTerm.latent_internal_force`); p_mean = tau_mean / f (eq. 20).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import arviz_base
import arviz_stats
import numpy as np
import xarray as xr
from scipy.ndimage import uniform_filter1d

from .likelihood import Likelihood
from .physics import cell
from .priors import Priors
from .prior_sensitivity import FUnderPrior, PriorDataConflict, nu_sensitivity, prior_data_conflict
from .sampler import PosteriorSamples
from .window import StationaryData

__all__ = [
    "Convergence", "FNuBand", "FUnderPrior", "PriorDataConflict", "RatioPPC", "VariableSummary", "build_datatree",
    "convergence", "derived_draws", "f_given_nu", "nu_sensitivity", "nu_variance_share", "pointwise_log_likelihood",
    "prior_data_conflict", "ratio_ppc", "summarize",
]

#: Variables summarised, in report order (hoop_gain only when sampled).
SUMMARY_VARIABLES = ("f", "nu", "kappa", "hoop_gain", "ratio", "p_mean", "tau_mean")
#: Probabilities of the quantiles reported everywhere.
QUANTILES = (0.05, 0.5, 0.95)


# ----------------------------------------------------------------------------------------------
# Derived variables and the DataTree
# ----------------------------------------------------------------------------------------------


def derived_draws(values: Mapping[str, np.ndarray], data: StationaryData) -> dict[str, np.ndarray]:
    """kappa, ratio, tau_mean (Pa), p_mean (Pa) for named draws.

    Parameters
    ----------
    values : mapping
        Draws by parameter name (``f``, ``nu`` are used), arrays of one shape.
    data : StationaryData

    Returns
    -------
    dict of arrays of the draws' shape
    """
    f, nu = np.asarray(values["f"], float), np.asarray(values["nu"], float)
    R, L = data.radius, data.length
    r = cell.force_ratio(f, nu, radius=R, length=L)
    var_io, var_eo = data.sd_io**2, data.sd_eo**2
    x_mean = (float(np.mean(data.F_io)) / var_io + r * float(np.mean(data.F_eo)) / var_eo) / (1.0 / var_io + r * r / var_eo)
    tau = cell.mean_friction_stress(r * x_mean, radius=R, length=L)
    with np.errstate(divide="ignore", invalid="ignore"):
        p_mean = np.where(f > 0.0, tau / f, np.nan)
    return {"kappa": cell.kappa(f, nu), "ratio": r, "tau_mean": tau, "p_mean": p_mean}


def _segments(data: StationaryData, segment_duration: float) -> tuple[int, np.ndarray]:
    seg = max(1, int(round(segment_duration * data.sample_rate)))
    starts = np.arange(0, data.n, seg)
    return seg, np.asarray(data.time)[starts]


def pointwise_log_likelihood(
    samples: PosteriorSamples, data: StationaryData, *, segment_duration: float = 10e-6, batch: int = 1024,
    axial_poisson: bool = True, likelihood: Likelihood | None = None,
) -> dict[str, np.ndarray]:
    """Log-likelihood per draw and time segment, shape (chain, draw, n_segments) per term.

    Segments of ``segment_duration`` (10 us) are used rather than single samples because the
    noise is autocorrelated (leave-one-segment-out, libraries.md). Per draw the segments sum to
    the total log-likelihood. Keys "F_eo" (force term) and "hoop" (with the hoop term).
    ``likelihood``: the one the samples were drawn with (None: built from ``axial_poisson``).
    """
    lk = likelihood if likelihood is not None else Likelihood(data, hoop=samples.hoop, axial_poisson=axial_poisson)
    seg, _ = _segments(data, segment_duration)
    flat = samples.array().reshape(-1, len(samples.names))
    parts: dict[str, list[np.ndarray]] = {}
    for i in range(0, len(flat), batch):
        for k, v in lk.pointwise(flat[i:i + batch], segment=seg).items():
            parts.setdefault(k, []).append(v)
    shape = samples.log_likelihood.shape
    return {k: np.concatenate(v).reshape(shape + (-1,)) for k, v in parts.items()}


def build_datatree(
    samples: PosteriorSamples, data: StationaryData, priors: Priors, *, seed: int, n_prior: int = 4000,
    segment_duration: float = 10e-6, axial_poisson: bool = True, likelihood: Likelihood | None = None,
) -> xr.DataTree:
    """ArviZ DataTree of a posterior run (dims ("chain", "draw") in every sampled group).

    Groups: posterior (sampled parameters + :func:`derived_draws`), log_likelihood (per time
    segment, :func:`pointwise_log_likelihood`; coordinate ``segment`` = segment start time, s),
    observed_data (F_io, F_eo in N and hoop strain over ``time``), sample_stats (lp, the log
    posterior density of each draw, and log_likelihood), prior (``n_prior`` draws from ``priors``
    with the same derived variables, chain of length 1, generator seeded with ``seed``).
    Provenance (seed, prior file, steps, tau, acceptance, convergence) goes into the root attrs.
    """
    names = samples.names
    post = {n: samples.draws[n] for n in names}
    post |= derived_draws(post, data)

    rng = np.random.default_rng(seed)
    prior_sub = priors.subset(names)
    prior = dict(zip(prior_sub.names, np.moveaxis(prior_sub.rvs(rng, n_prior)[None], -1, 0)))
    prior |= derived_draws(prior, data)

    pw = pointwise_log_likelihood(samples, data, segment_duration=segment_duration, axial_poisson=axial_poisson,
                                  likelihood=likelihood)
    _, seg_t = _segments(data, segment_duration)
    observed = {"F_io": np.asarray(data.F_io), "F_eo": np.asarray(data.F_eo)}
    if samples.hoop and data.hoop is not None:
        observed["hoop"] = np.asarray(data.hoop)
    dims = {k: (["segment"] if v.shape[-1] == len(seg_t) else [f"{k}_observation"]) for k, v in pw.items()}
    coords = {"segment": seg_t, "time": np.asarray(data.time)}
    dt = arviz_base.from_dict(
        {
            "posterior": post,
            "log_likelihood": pw,
            "sample_stats": {"lp": samples.log_likelihood + samples.log_prior, "log_likelihood": samples.log_likelihood},
            "prior": prior,
        },
        coords={"segment": seg_t} | {d[0]: np.arange(pw[k].shape[-1]) for k, d in dims.items() if d[0] != "segment"},
        dims=dims,
    )
    dt["observed_data"] = xr.DataTree(xr.Dataset({k: ("time", v) for k, v in observed.items()}, coords={"time": coords["time"]}))
    dt.attrs.update(
        {
            "test_id": data.test_id,
            "seed": samples.seed if samples.seed < 2**63 else str(samples.seed),  # netCDF attributes: int64
            "prior_path": samples.prior_path,
            "prior_description": samples.prior_description,
            "hoop_term": int(samples.hoop),
            "n_steps": samples.n_steps,
            "burn": samples.burn,
            "thin": samples.thin,
            "nwalkers": samples.nwalkers,
            "converged": int(samples.converged),
            "sampling_seconds": samples.seconds,
            "acceptance": samples.acceptance.tolist(),
            "tau_max": float(samples.tau.max()),
            "window": list(data.window),
        }
    )
    return dt


# ----------------------------------------------------------------------------------------------
# Convergence and summaries
# ----------------------------------------------------------------------------------------------


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


# ----------------------------------------------------------------------------------------------
# nu -> f propagation
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FNuBand:
    """f against an assumed nu: quantiles of f given nu on a grid (dimensionless).

    Attributes
    ----------
    nu : array, shape (m,)
    q05, q50, q95 : array, shape (m,)
    """

    nu: np.ndarray
    q05: np.ndarray
    q50: np.ndarray
    q95: np.ndarray


def f_given_nu(samples: PosteriorSamples, nu_grid: Sequence[float] | np.ndarray) -> FNuBand:
    """Credible band of f given nu: f = kappa (1 - nu)/nu with kappa from its posterior draws.

    The forces fix kappa = f nu/(1-nu) (eq. 17); given nu, f|nu,data is kappa|data scaled by
    (1-nu)/nu. This uses kappa's marginal posterior for every nu, which is exact up to the
    variation of the f prior across kappa's posterior width (kappa is fixed to ~1 % by the forces,
    the half-normal f prior varies by < 1 % over that) and, with the hoop term, up to the
    posterior correlation of kappa with nu (small: the hoop term constrains g nu/(1-nu), while
    kappa is fixed by the forces).
    """
    nu = np.asarray(nu_grid, float)
    kappa = samples.flat("f") * cell.lateral_ratio(samples.flat("nu"))
    qk = np.quantile(kappa, QUANTILES)
    scale = (1.0 - nu) / nu
    return FNuBand(nu, qk[0] * scale, qk[1] * scale, qk[2] * scale)


def nu_variance_share(samples: PosteriorSamples, *, n_bins: int = 20) -> float:
    """Share of f's posterior variance due to nu, Var(E[f|nu]) / Var(f) (law of total variance).

    E[f|nu] is estimated by piecewise-linear least squares: a straight line of f against nu in
    each of ``n_bins`` equal-count bins of nu, evaluated at each draw. Lines, not bin means,
    because E[f|nu] = E[kappa|nu] (1-nu)/nu varies strongly across the wide tail bins (bin means
    lose ~2 % of the share on the paper's case, lines < 0.1 %). The fit's noise adds about
    2 n_bins / n_draws of Var(f|nu), negligible with thousands of draws.
    """
    f = samples.flat("f")
    nu = samples.flat("nu")
    order = np.argsort(nu, kind="stable")
    fitted = np.empty_like(f)
    for idx in np.array_split(order, n_bins):
        x, y = nu[idx], f[idx]
        xc = x - x.mean()
        sxx = float(xc @ xc)
        slope = float(xc @ (y - y.mean())) / sxx if sxx > 0 else 0.0
        fitted[idx] = y.mean() + slope * xc
    return float(np.var(fitted) / np.var(f))


# ----------------------------------------------------------------------------------------------
# Posterior predictive of the force ratio
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RatioPPC:
    """Posterior predictive of F_eo/F_io over the window, both smoothed over ``smooth`` seconds.

    Attributes
    ----------
    time : array, shape (n,)  (s)
    observed : array, shape (n,)
        Smoothed observed ratio.
    replicated : array, shape (n_draws, n)
        Smoothed ratio of replicated data (model ratio + AR(1) noise on both forces).
    q05, q50, q95 : array, shape (n,)
        Pointwise quantiles of ``replicated``.
    model_q05, model_q95 : float
        90 % interval of the noise-free model ratio r.
    coverage : float
        Fraction of times where ``observed`` lies inside [q05, q95].
    """

    time: np.ndarray
    observed: np.ndarray
    replicated: np.ndarray
    q05: np.ndarray
    q50: np.ndarray
    q95: np.ndarray
    model_q05: float
    model_q95: float
    coverage: float
    smooth: float


def _smooth_ratio(F_eo: np.ndarray, F_io: np.ndarray, width: int) -> np.ndarray:
    num = uniform_filter1d(F_eo, width, axis=-1, mode="nearest")
    den = uniform_filter1d(F_io, width, axis=-1, mode="nearest")
    return num / den


def ratio_ppc(
    samples: PosteriorSamples, data: StationaryData, *, seed: int, n_draws: int = 200, smooth: float = 10e-6,
    likelihood: Likelihood | None = None,
) -> RatioPPC:
    """Posterior predictive check of the force ratio (see :class:`RatioPPC`); ``likelihood``: the
    analysis' (its forces are replicated; None: a force-only one is built)."""
    rng = np.random.default_rng(seed)
    lk = likelihood if likelihood is not None else Likelihood(data, hoop=False)
    n_all = samples.n_chains * samples.n_draws
    idx = rng.choice(n_all, size=min(n_draws, n_all), replace=False)
    pick = lk.parameters.vector({n: samples.flat(n)[idx] for n in lk.names})
    rep = lk.simulate(pick, rng=rng, hoop=False)
    width = max(1, int(round(smooth * data.sample_rate)))
    replicated = _smooth_ratio(rep["F_eo"], rep["F_io"], width)
    observed = _smooth_ratio(np.asarray(data.F_eo, float), np.asarray(data.F_io, float), width)
    q = np.quantile(replicated, QUANTILES, axis=0)
    r = lk.model.ratio(samples.draws)
    mq = np.quantile(r, [0.05, 0.95])
    inside = (observed >= q[0]) & (observed <= q[2])
    return RatioPPC(np.asarray(data.time), observed, replicated, q[0], q[1], q[2], float(mq[0]), float(mq[1]),
                    float(inside.mean()), smooth)
