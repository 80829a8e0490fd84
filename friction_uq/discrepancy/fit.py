"""Fit a forward model of the whole test to the whole record: Laplace approximation and draws.

The whole-record likelihood compares every gauge over its span (:mod:`.whole_record`: from its
wave's arrival to the first far-end echo) with the simulator's prediction, each residual scored by
the exact AR(1) Gaussian log-likelihood of that gauge's pre-pulse noise (the reflected wave with
twice the variance: its prediction carries the measured incident's noise). The hoop gauge's
calibration factor enters linearly and is profiled out (its generalised least-squares value for
each parameter vector).

The posterior is approximated by a normal distribution in the unbounded coordinates of the
parameters (:meth:`~friction_uq.models.Parameter.to_unbounded`) around the maximum a posteriori
(Nelder-Mead), with the finite-difference Hessian as precision, and the draws are corrected by
Pareto-smoothed importance sampling against the exact posterior (the k diagnostic is returned;
k > 0.7 says the normal approximation is poor). A simulator run costs ~10 ms, so a fit of two or
three parameters costs about 1 s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..analysis import Prepared
from ..likelihood import ar1_loglike
from ..models.simulator import SimulatorModel
from .whole_record import CHANNEL_LABELS, channel_noise, channel_spans, whiten

LogPrior = Callable[[Mapping[str, float]], float]


@dataclass(frozen=True)
class WholeRecordFit:
    """Laplace fit of a model to the whole record."""

    names: tuple[str, ...]
    mode: dict[str, float]
    draws: dict[str, np.ndarray]
    log_weights: np.ndarray
    pareto_k: float
    loglike_mode: float
    n_calls: int

    def summary(self, name: str) -> dict[str, float]:
        v = self.draws[name]
        q = np.quantile(v, [0.05, 0.5, 0.95])
        return {"mean": float(v.mean()), "sd": float(v.std(ddof=1)), "q05": float(q[0]), "q50": float(q[1]),
                "q95": float(q[2])}


class WholeRecordLikelihood:
    """log p(record | parameters) over every gauge's span (module docstring)."""

    def __init__(self, prep: Prepared, model: SimulatorModel) -> None:
        rec = prep.record
        self.model = model
        self.channels = tuple(c for c in CHANNEL_LABELS if c in rec.channels and (c != "tube_hoop" or model.hoop))
        self.bounds = channel_spans(prep, self.channels)
        self.noise = {c: channel_noise(prep, c) for c in self.channels}
        self.measured = {c: rec.strain(c) - prep.forces.channels[c].noise.offset for c in self.channels}

    def _span(self, c: str) -> slice:
        i0, _, _, i3 = self.bounds[c]
        return slice(i0, i3)

    def hoop_gain(self, predicted_unit: np.ndarray) -> float:
        """Generalised least-squares gain of the hoop gauge for a prediction at gain 1."""
        s, nz = self._span("tube_hoop"), self.noise["tube_hoop"]
        wp = whiten(predicted_unit[s], sd=nz.sd, rho=nz.rho)
        wm = whiten(self.measured["tube_hoop"][s], sd=nz.sd, rho=nz.rho)
        den = float(wp @ wp)
        return float(wm @ wp) / den if den > 0 else 1.0

    def strains(self, values: Mapping[str, float]) -> tuple[dict[str, np.ndarray], float]:
        """Predicted strains with the hoop gain profiled; returns (strains, hoop gain)."""
        vals = dict(values)
        vals["hoop_gain"] = 1.0
        pred = self.model.predict(vals).strains
        g = 1.0
        if "tube_hoop" in self.channels:
            g = self.hoop_gain(pred["tube_hoop"])
            pred = dict(pred)
            pred["tube_hoop"] = g * pred["tube_hoop"]
        return pred, g

    def loglike(self, values: Mapping[str, float]) -> float:
        pred, _ = self.strains(values)
        out = 0.0
        for c in self.channels:
            s, nz = self._span(c), self.noise[c]
            out += float(ar1_loglike(self.measured[c][s] - pred[c][s], nz.sd, nz.rho))
        return out


def fit_whole_record(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], *,
                     n_draws: int = 30, rng: np.random.Generator) -> WholeRecordFit:
    """MAP, Laplace approximation and importance-corrected draws (module docstring).

    ``start`` gives a value for every free parameter (``hoop_gain``, profiled, is not one).
    """
    params = [lik.model.parameters[n] for n in start if n != "hoop_gain"]
    names = tuple(p.name for p in params)
    calls = 0

    def values_of(z: np.ndarray) -> dict[str, float]:
        return {p.name: float(p.from_unbounded(zi)) for p, zi in zip(params, z)}

    def neg_log_post(z: np.ndarray) -> float:
        nonlocal calls
        calls += 1
        vals = values_of(z)
        lp = log_prior(vals)
        if not np.isfinite(lp):
            return 1e300
        jac = sum(float(p.log_jacobian(zi)) for p, zi in zip(params, z))
        ll = lik.loglike(vals)
        return -(ll + lp + jac) if np.isfinite(ll) else 1e300

    z0 = np.array([float(p.to_unbounded(start[p.name])) for p in params])
    simplex = np.vstack([z0] + [z0 + 0.03 * np.eye(len(z0))[i] for i in range(len(z0))])
    res = optimize.minimize(neg_log_post, z0, method="Nelder-Mead",
                            options={"xatol": 1e-4, "fatol": 0.01, "initial_simplex": simplex, "maxfev": 400})
    zm = res.x
    H = _hessian(neg_log_post, zm)
    try:
        cov = np.linalg.inv(H)
        chol = np.linalg.cholesky(0.5 * (cov + cov.T))
    except np.linalg.LinAlgError:
        chol = np.diag(np.full(len(zm), 1e-3))
    eps = rng.standard_normal((n_draws, len(zm)))
    z = zm + eps @ chol.T
    log_q = -0.5 * np.sum(eps * eps, axis=1)
    log_p = np.array([-neg_log_post(zi) for zi in z]) + float(res.fun)
    log_w = log_p - log_q
    k = _pareto_k(log_w)
    draws = {p.name: np.asarray(p.from_unbounded(z[:, i]), float) for i, p in enumerate(params)}
    mode = values_of(zm)
    return WholeRecordFit(names=names, mode=mode, draws=draws, log_weights=log_w - np.logaddexp.reduce(log_w),
                          pareto_k=k, loglike_mode=lik.loglike(mode), n_calls=calls)


def _hessian(fun: Callable[[np.ndarray], float], z: np.ndarray, h: float = 2e-3) -> np.ndarray:
    k = len(z)
    H = np.empty((k, k))
    f0 = fun(z)
    e = np.eye(k) * h
    for i in range(k):
        H[i, i] = (fun(z + e[i]) - 2.0 * f0 + fun(z - e[i])) / (h * h)
        for j in range(i + 1, k):
            H[i, j] = H[j, i] = (fun(z + e[i] + e[j]) - fun(z + e[i] - e[j]) - fun(z - e[i] + e[j])
                                 + fun(z - e[i] - e[j])) / (4.0 * h * h)
    return H


def _pareto_k(log_w: np.ndarray) -> float:
    """Pareto k of importance weights (arviz-stats PSIS); nan when it cannot be computed."""
    try:
        from arviz_stats.base import array_stats

        _, k = array_stats.psislw(np.asarray(log_w, float))
        return float(np.asarray(k).ravel()[0])
    except Exception:  # noqa: BLE001 - the diagnostic is optional, the draws stand without it
        return math.nan
