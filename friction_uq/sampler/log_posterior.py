"""The density emcee samples, log posterior and start ball.

emcee walks in the unbounded coordinates z of the likelihood's named parameters (each by its own
transform: :meth:`friction_uq.models.ParameterSet.from_unbounded`, logit on a bounded support); the
density in z carries the transform's log Jacobian.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy import optimize

from ..errors import SamplingError
from ..likelihood import Likelihood
from ..physics import cell
from ..priors import Priors


class LogPosterior:
    """Vectorised log posterior density in z (emcee's ``log_prob_fn`` with ``vectorize=True``)."""

    def __init__(self, likelihood: Likelihood, priors: Priors) -> None:
        if tuple(priors.names) != likelihood.names:
            raise ValueError(f"priors over {', '.join(priors.names)}, the likelihood's parameters are "
                             f"{', '.join(likelihood.names)}")
        self.likelihood = likelihood
        self.priors = priors
        self.parameters = likelihood.parameters

    def to_theta(self, z: np.ndarray) -> np.ndarray:
        """Unbounded coordinates -> parameter vectors."""
        return self.parameters.from_unbounded(z)

    def to_z(self, theta: np.ndarray) -> np.ndarray:
        """Parameter vectors -> unbounded coordinates."""
        return self.parameters.to_unbounded(theta)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """z: shape (nwalkers, ndim) -> shape (nwalkers,); -inf outside the prior support."""
        z = np.atleast_2d(np.asarray(z, float))
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            theta = self.to_theta(z)
            lp = self.priors.logpdf(theta) + self.parameters.log_jacobian(z)
        inside = np.all([p.contains(theta[..., i]) for i, p in enumerate(self.parameters)], axis=0)
        ok = np.isfinite(lp) & inside
        out = np.full(len(z), -np.inf)
        if ok.any():
            ll = self.likelihood(theta[ok])
            out[ok] = np.where(np.isfinite(ll), lp[ok] + ll, -np.inf)
        return out


# ----------------------------------------------------------------------------------------------
# Start
# ----------------------------------------------------------------------------------------------


def _initial_guess(likelihood: Likelihood, priors: Priors) -> np.ndarray:
    """Parameter vector from the least-squares force ratio and the prior medians (the other parameters)."""
    d = likelihood.data
    nu = float(priors["nu"].ppf(0.5))
    r0 = likelihood.force.r0
    sd_r = math.hypot(d.sd_eo, r0 * d.sd_io) / (abs(float(np.mean(d.F_io))) * math.sqrt(d.n))
    r = max(r0, 3.0 * sd_r, 1e-6)
    f = float(math.log1p(r) / cell.beta(nu, radius=d.radius, length=d.length))
    if not np.isfinite(priors["f"].logpdf(np.array([f]))[0]):  # the data's f outside a prior's support (uniform on
        lo, _ = priors["f"].support                             # [0.1, 1], say): start at its nearest end, inside
        f = float(priors["f"].ppf(1e-6 if f < lo else 1.0 - 1e-6))
    values = {n: float(priors[n].ppf(0.5)) for n in likelihood.names}
    values.update(f=f, nu=nu)
    return likelihood.parameters.vector(values)


def _hessian(fun: Callable[[np.ndarray], np.ndarray], z: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """Central-difference Hessian of a vectorised function at z (all stencil points in one call)."""
    k = len(z)
    eye = np.eye(k) * h
    pts = [z]
    for i in range(k):
        for j in range(i, k):
            pts += [z + eye[i] + eye[j], z + eye[i] - eye[j], z - eye[i] + eye[j], z - eye[i] - eye[j]]
    vals = fun(np.array(pts))
    H = np.full((k, k), np.nan)
    if not np.all(np.isfinite(vals)):  # optimum on a prior bound: no Hessian
        return H
    m = 1
    for i in range(k):
        for j in range(i, k):
            pp, pm, mp, mm = vals[m:m + 4]
            H[i, j] = H[j, i] = (pp - pm - mp + mm) / (4.0 * h * h)
            m += 4
    return H


def start_ball(
    log_post: LogPosterior, priors: Priors, *, nwalkers: int, n_ensembles: int, rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Maximum a posteriori in z and starting positions, shape (n_ensembles, nwalkers, ndim).

    The ball's sd is a tenth of the Laplace approximation's (inverse Hessian at the optimum);
    walkers falling outside the prior support are redrawn.
    """
    z0 = log_post.to_z(_initial_guess(log_post.likelihood, priors))
    source = f"prior file {priors.path}" if priors.path else "the priors"
    if not np.isfinite(log_post(z0)[0]):
        raise SamplingError(f"the starting point {_point(priors.names, log_post.to_theta(z0))} has zero density under "
                            f"{source} or the likelihood; check the sections {_sections(priors.names)} against the data")
    res = optimize.minimize(lambda z: -float(log_post(z)[0]), z0, method="Nelder-Mead",
                            options={"xatol": 1e-7, "fatol": 1e-7, "maxiter": 4000})
    z_map = res.x if np.isfinite(res.fun) and res.fun <= -float(log_post(z0)[0]) else z0
    H = _hessian(log_post, z_map)
    try:
        cov = np.linalg.inv(-H)
        chol = np.linalg.cholesky(0.5 * (cov + cov.T))
    except np.linalg.LinAlgError:
        chol = np.eye(len(z_map)) * 1e-3
    if not np.all(np.isfinite(chol)):
        chol = np.eye(len(z_map)) * 1e-3
    out = np.empty((n_ensembles, nwalkers, len(z_map)))
    for k in range(n_ensembles):
        todo = np.ones(nwalkers, bool)
        for _ in range(100):
            out[k, todo] = z_map + 0.1 * rng.standard_normal((int(todo.sum()), len(z_map))) @ chol.T
            todo = ~np.isfinite(log_post(out[k]))
            if not todo.any():
                break
        else:
            raise SamplingError(f"could not place the walkers around the most probable point "
                                f"{_point(priors.names, log_post.to_theta(z_map))} inside the support of {source}: "
                                f"the data put the parameters at the edge of it; widen {_sections(priors.names)}")
    return z_map, out


def _point(names, theta) -> str:
    """``f = 0.0512, nu = 0.401``: a parameter vector in words (plain numbers, not numpy reprs)."""
    return ", ".join(f"{n} = {float(v):.4g}" for n, v in zip(names, np.ravel(theta)))


def _sections(names) -> str:
    return ", ".join(f"[{n}]" for n in names)
