"""The exact posterior of a fitted extended model (the one whose f is quoted), robust to a model that still misses.

A model of :mod:`.extended` is fitted by a Laplace approximation. For the model with the named causes, the f
``diagnose`` quotes comes from its exact posterior instead (:mod:`friction_uq.stats.exact`): the normal
approximation with its robust covariance is weighted by the exact posterior density (the whole-record likelihood,
the priors, the transforms' Jacobians); Pareto k says how far the normal was from it, and beyond the limit a second
proposal or emcee samples it. The exact draws are then given the robust covariance by the open-faced sandwich
adjustment, which keeps their shape.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .._parallel import ForkedPool
from ..stats.exact import ExactDraws, exact_draws
from ..stats.laplace import robust_covariance
from ..stats.streams import stream
from .extended import Diagnoser, ModelFit
from .nu_cut import Fixed

#: Draws of the importance stage of a named model's exact posterior.
IMPORTANCE_DRAWS = 200
#: Equal-weight draws of the exact (sandwich-adjusted) posterior kept for the named model.
EXACT_DRAWS = 1000


def exact_posterior(dg: Diagnoser, mf: ModelFit, *, n: int = IMPORTANCE_DRAWS,
                    workers: int = 1) -> tuple[ModelFit, ExactDraws]:
    """The model ``mf`` of ``dg`` with its exact posterior (module docstring).

    The returned model's draws and f_effective are the exact ones; its mode, ELPD and predictions are unchanged.
    Under the cut (:mod:`.nu_cut`) it is theta's posterior at the windows' nu that is made exact, then moved with
    nu. ``workers``: processes sharing the density's evaluations (forked once; the draws do not depend on it).
    """
    fit = mf.fit if mf.cut is None else mf.cut.fit  # under the cut: theta's posterior at the windows' nu
    lik = mf.lik if mf.cut is None else Fixed(mf.lik, {"nu": mf.cut.nu0})
    params = [mf.lik.model.parameters[name] for name in fit.names]
    mode = np.array([float(p.to_unbounded(fit.mode[p.name])) for p in params])
    cov = fit.cov_z if fit.cov_z is not None else np.eye(len(params)) * 1e-6
    robust = robust_covariance(fit.jacobian, fit.whitened, cov, mf.lik.blocks(dg.block))
    model_prior = dg.log_prior(mf.variants)
    log_prior = model_prior if mf.cut is None else (lambda v: model_prior(dict(v) | {"nu": mf.cut.nu0}))

    def log_post(z: np.ndarray) -> float:
        vals = {p.name: float(p.from_unbounded(v)) for p, v in zip(params, z)}
        lp = log_prior(vals)
        if not np.isfinite(lp):
            return -np.inf
        try:
            return lik.loglike(vals) + lp + sum(float(p.log_jacobian(v)) for p, v in zip(params, z))
        except ValueError:  # parameters the simulator cannot run
            return -np.inf

    rng = stream(dg.seed, "exact posterior", mf.label)
    with ForkedPool(log_post, workers=workers) as pool:
        ex = exact_draws(log_post, mode, cov, robust, rng=rng, n_importance=n, n_out=EXACT_DRAWS, map_rows=pool.map)
    if mf.cut is None:
        draws = {p.name: np.asarray(p.from_unbounded(ex.z_adjusted[:, i]), float) for i, p in enumerate(params)}
    else:
        draws = mf.cut.draws(params, ex.z_adjusted, stream(dg.seed, "nu cut exact", mf.label))
    new_fit = replace(mf.fit, draws=draws, log_weights=np.full(EXACT_DRAWS, -math.log(EXACT_DRAWS)),
                      pareto_k=ex.pareto_k, laplace_draws=mf.fit.laplace_draws or mf.fit.draws)
    return replace(mf, fit=new_fit, f_effective=dg.f_of(mf.variants, draws)), ex
