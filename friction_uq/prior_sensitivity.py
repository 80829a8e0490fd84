"""How the answer depends on the priors: f under other nu priors, and prior-data conflict.

* :func:`nu_sensitivity`: f's posterior under each alternative prior, by Pareto-smoothed
  importance reweighting (PSIS, Vehtari et al. 2024) of the draws of the run under the prior used:
  the weight of a draw theta is p_alt(theta) / p_used(theta) (the likelihood cancels). The Pareto
  k of the weights says whether this is reliable; where k exceeds ``min(1 - 1/log10 S, 0.7)``
  (S draws) the alternative is sampled afresh instead.
* :func:`prior_data_conflict`: power-scaling sensitivity (Kallioinen et al. 2024,
  ``arviz_stats.psense``) of each parameter to its own prior and to the likelihood.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from .models.parameters import effective_sample_size
from .priors import Priors
from .sampler import PosteriorSamples, sample_posterior
from .stats import khat_threshold, psis
from .window import StationaryData

#: Probabilities of the quantiles reported.
QUANTILES = (0.05, 0.5, 0.95)


@dataclass(frozen=True)
class FUnderPrior:
    """f's posterior under one nu prior.

    ``method`` is "sampled" (the run itself or a fresh run) or "reweighted" (PSIS from the run under
    the prior used); ``pareto_k`` is the Pareto k of the importance weights (nan when sampled
    without reweighting being tried) and ``ess`` the effective sample size of the weights.
    """

    label: str
    prior_description: str
    mean: float
    sd: float
    q05: float
    q50: float
    q95: float
    draws: np.ndarray  # f draws (at most 4000), equally weighted, for histograms
    method: str = "sampled"
    pareto_k: float = math.nan
    ess: float = math.nan

    def to_json(self) -> dict[str, float | str]:
        keys = ("label", "prior_description", "mean", "sd", "q05", "q50", "q95", "method", "pareto_k", "ess")
        return {k: (None if isinstance(getattr(self, k), float) and not math.isfinite(getattr(self, k))
                    else getattr(self, k)) for k in keys}


def weighted_quantiles(x: np.ndarray, w: np.ndarray, q: tuple[float, ...]) -> np.ndarray:
    """Quantiles of ``x`` under normalised weights ``w`` (inverse of the midpoint weighted CDF)."""
    order = np.argsort(x, kind="stable")
    xs, ws = x[order], w[order]
    cdf = np.cumsum(ws) - 0.5 * ws
    return np.interp(q, cdf, xs)


def _thin(f: np.ndarray) -> np.ndarray:
    keep = np.unique(np.linspace(0, len(f) - 1, min(len(f), 4000)).astype(int))
    return f[keep]


def _f_under(label: str, samples: PosteriorSamples) -> FUnderPrior:
    f = samples.flat("f")
    q = np.quantile(f, QUANTILES)
    return FUnderPrior(label, samples.prior_description, float(f.mean()), float(f.std(ddof=1)),
                       float(q[0]), float(q[1]), float(q[2]), _thin(f))


def reweight(samples: PosteriorSamples, used: Priors, other: Priors, *, label: str, seed: int) -> FUnderPrior:
    """f under ``other`` from the draws of ``samples`` (sampled under ``used``) by PSIS."""

    theta = samples.array().reshape(-1, len(samples.names))
    with np.errstate(divide="ignore", invalid="ignore"):
        log_w = other.subset(samples.names).logpdf(theta) - used.subset(samples.names).logpdf(theta)
    f = samples.flat("f")
    if not np.any(np.isfinite(log_w)):
        return FUnderPrior(label, other.subset(samples.names).describe(), *([math.nan] * 5), np.array([]),
                           "reweighted", math.inf, 0.0)
    smoothed = psis(np.where(np.isfinite(log_w), log_w, -np.inf))
    k = float(smoothed.pareto_k)
    w = np.exp(smoothed.log_weights)
    mean = float(w @ f)
    sd = float(math.sqrt(max(float(w @ (f - mean) ** 2), 0.0)))
    q = weighted_quantiles(f, w, QUANTILES)
    rng = np.random.default_rng(seed)
    n = min(len(f), 4000)
    pick = np.searchsorted(np.cumsum(w), (rng.random() + np.arange(n)) / n)  # systematic resampling
    return FUnderPrior(label, other.subset(samples.names).describe(), mean, sd, float(q[0]), float(q[1]),
                       float(q[2]), f[np.minimum(pick, len(f) - 1)], "reweighted", float(k), effective_sample_size(w))


def nu_sensitivity(
    data: StationaryData,
    priors: Mapping[str, Priors],
    *,
    seed: int,
    hoop: bool | None = None,
    done: Mapping[str, PosteriorSamples] | None = None,
    reference: str = "default",
    **sampler_kwargs: object,
) -> dict[str, FUnderPrior]:
    """f's posterior under each prior of ``priors`` (label -> Priors).

    Runs already done are passed in ``done`` under their label and reused. The others are
    reweighted from ``done[reference]`` (PSIS, see the module docstring) and sampled afresh
    (``sample_posterior`` with ``sampler_kwargs``) only where the Pareto k says the reweighting
    is unreliable, or when there is no reference run.
    """
    done = dict(done or {})
    out = {}
    ref = done.get(reference)
    for label, pri in priors.items():
        if label in done:
            out[label] = _f_under(label, done[label])
            continue
        if ref is not None:
            rw = reweight(ref, priors[reference], pri, label=label, seed=seed)
            if rw.pareto_k <= khat_threshold(ref.n_chains * ref.n_draws):
                out[label] = rw
                continue
        s = sample_posterior(data, pri, seed=seed, hoop=hoop, **sampler_kwargs)
        res = _f_under(label, s)
        out[label] = res if ref is None else replace(res, pareto_k=rw.pareto_k)
    return out


@dataclass(frozen=True)
class PriorDataConflict:
    """Power-scaling sensitivity of each sampled parameter (``arviz_stats.psense``).

    Attributes
    ----------
    prior, likelihood : dict of str to float
        Sensitivity (cumulative Jensen-Shannon distance per unit of log power) of each parameter's
        posterior to power-scaling its own prior, and to power-scaling the likelihood.
    diagnosis : dict of str to str
        "prior-data conflict" (both above ``threshold``), "prior dominates the data" (the prior
        only), or "" (neither).
    flagged : tuple of str
        Parameters whose diagnosis is a problem: any diagnosis for f; for nu and hoop_gain only a
        conflict (the forces cannot inform nu, so a dominant nu prior is the design, not a fault).
    """

    prior: dict[str, float]
    likelihood: dict[str, float]
    diagnosis: dict[str, str]
    flagged: tuple[str, ...]
    threshold: float

    def sentence(self) -> str:
        """One sentence for the terminal and the summary page."""
        if not self.flagged:
            return (f"Prior-data check (power-scaling, threshold {self.threshold:g}): no conflict; the data, "
                    "not the priors, determine f.")
        parts = [f"{n}: {self.diagnosis[n]} (prior sensitivity {self.prior[n]:.2f}, likelihood "
                 f"{self.likelihood[n]:.2f})" for n in self.flagged]
        # a conflict is the data pulling against the prior, not a prior that leaves the data nothing to say
        head = ("the prior file and the data disagree" if any(self.diagnosis[n] == "prior-data conflict"
                                                              for n in self.flagged)
                else "the priors, not the data, drive the result")
        return (f"WARNING: {head} - " + "; ".join(parts)
                + ". Check the prior file against the data before using these numbers.")

    def to_json(self) -> dict[str, object]:
        return {"conflict": bool(self.flagged), "flagged": list(self.flagged), "diagnosis": self.diagnosis,
                "prior_sensitivity": self.prior, "likelihood_sensitivity": self.likelihood,
                "threshold": self.threshold, "method": "power-scaling sensitivity (arviz_stats.psense)"}


def prior_data_conflict(dt, samples: PosteriorSamples, priors: Priors, *, threshold: float = 0.05) -> PriorDataConflict:
    """Power-scaling diagnosis of each sampled parameter against its own prior and the likelihood.

    ``dt`` is the run's DataTree (:func:`friction_uq.diagnostics.build_datatree`, with its
    ``log_likelihood`` group); the per-parameter log prior densities are added as a
    ``log_prior`` group of a shallow copy.
    """
    import arviz_stats
    import xarray as xr

    pri = priors.subset(samples.names)
    lp = {p.name: (("chain", "draw"), p.logpdf(samples.draws[p.name])) for p in pri.parameters}
    tree = dt.copy()
    tree["log_prior"] = xr.DataTree(xr.Dataset(lp, coords={"chain": dt["posterior"]["chain"], "draw": dt["posterior"]["draw"]}))
    ll_vars = list(dt["log_likelihood"].data_vars)
    prior_s, like_s, diag = {}, {}, {}
    for n in samples.names:
        ls = arviz_stats.psense(tree, var_names=[n], group="likelihood", group_var_names=ll_vars)
        like_s[n] = float(ls[n].values)
        if np.ptp(lp[n][1]) == 0.0:  # a flat prior over the draws (uniform): a power of it is the same prior,
            prior_s[n] = 0.0         # so the posterior does not move (and PSIS has no tail to fit)
        else:
            ps = arviz_stats.psense(tree, var_names=[n], group="prior", group_var_names=[n])
            prior_s[n] = float(ps[n].values)
        if prior_s[n] >= threshold and like_s[n] >= threshold:
            diag[n] = "prior-data conflict"
        elif prior_s[n] >= threshold:
            diag[n] = "prior dominates the data"
        else:
            diag[n] = ""
    flagged = tuple(n for n in samples.names if diag[n] and (n == "f" or diag[n] == "prior-data conflict"))
    return PriorDataConflict(prior_s, like_s, diag, flagged, threshold)
