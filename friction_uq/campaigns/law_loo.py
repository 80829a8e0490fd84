"""Leave-one-test-out ELPD of a friction-law fit (:class:`~.laws.Fit`): Pareto-smoothed importance sampling
(PSIS-LOO, Vehtari et al. 2017, through ArviZ), with an exact refit without the test wherever its Pareto k
exceeds :data:`PARETO_K_MAX`. The parts are separate so that a campaign can spread the refits of several
models over its processes (``law_comparison.fits_with_loo``)."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.special import logsumexp

from .laws import Elpd, Fit, LawData

PARETO_K_MAX = 0.7
#: an exact leave-one-out refit's chain: it starts from the full fit's walkers, so it burns in less, and it is not
#: run on (the full fit's was: law_chain.TAU_MULTIPLE); one test's predictive density is all it gives
REFIT = {"nwalkers": 32, "nsteps": 700, "burn": 200, "max_steps": 700}


def psis_loo(fit: Fit) -> tuple[np.ndarray, np.ndarray]:
    """Leave-one-test-out by Pareto-smoothed importance sampling: each test's ELPD and Pareto k."""
    import arviz as az

    ll = fit.pointwise(fit.draws)
    dt = az.from_dict({"posterior": {"r": fit.draws[None, :, -1]}, "log_likelihood": {"y": ll[None]},
                       "observed_data": {"y": fit.data.kappa}}, dims={"y": ["test"]})
    with warnings.catch_warnings():  # high Pareto k is handled by exact refits (refit_elpd)
        warnings.filterwarnings("ignore", message="Estimated shape parameter of Pareto")
        res = az.loo(dt, pointwise=True)
    return np.asarray(res.elpd_i, float).copy(), np.asarray(res.pareto_k, float)


def refit_elpd(fit: Fit, i: int, *, seed: int) -> float:
    """Test ``i``'s leave-one-out ELPD from an exact refit without it (where its Pareto k > 0.7), with the seed
    ``seed + 1 + i``."""
    sub = fit.data.drop(i)
    # started from the full fit's last walkers, which are near the leave-one-out posterior: a shorter burn-in
    start = fit.draws[-REFIT["nwalkers"]:]
    refit = Fit(fit.model, sub, kbar=fit.kbar, p_ref=fit.p_ref, seed=seed + 1 + i, start=start, **REFIT)
    lli = refit.pointwise(refit.draws, _one(fit.data, i))[:, 0]
    return float(logsumexp(lli) - np.log(lli.size))


def to_refit(k: np.ndarray) -> list[int]:
    """The tests whose PSIS estimate is not trusted (Pareto k > :data:`PARETO_K_MAX`): refitted exactly."""
    return [int(i) for i in np.flatnonzero(k > PARETO_K_MAX)]


def loo_elpd(fit: Fit, elpd_i: np.ndarray, k: np.ndarray, refits: dict[int, float]) -> Elpd:
    """The model's ELPD (sum and SE over tests) from the PSIS values with the refitted tests' values in place."""
    elpd_i = elpd_i.copy()
    for i, v in refits.items():
        elpd_i[i] = v
    n = elpd_i.size
    return Elpd(fit.model.name, float(elpd_i.sum()), float(np.sqrt(n * np.var(elpd_i, ddof=1))), elpd_i, k,
                len(refits))


def _one(d: LawData, i: int) -> LawData:
    return d.select(np.arange(d.n) == i)
