"""Derived variables per draw and the ArviZ DataTree of a run (groups posterior, log_likelihood,
observed_data, sample_stats, prior)."""

from __future__ import annotations

from collections.abc import Mapping

import arviz_base
import numpy as np
import xarray as xr

from ..likelihood import Likelihood
from ..physics import cell
from ..priors import Priors
from ..sampler import PosteriorSamples
from ..window import StationaryData


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
