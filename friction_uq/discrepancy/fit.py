"""Fit a forward model of the whole test to the whole record: Laplace approximation and draws.

The whole-record likelihood compares every gauge over its span (:mod:`.whole_record`: from its
wave's arrival to the first far-end echo) with the simulator's prediction, each residual scored by
the exact AR(1) Gaussian log-likelihood of that gauge's pre-pulse noise, with the effective
coefficient that reproduces the noise's long-run variance (white plus AR(1) noise whitened with its
lag-1 coefficient would overstate what the record says about a level: a gain, f), (the reflected wave with
twice the variance: its prediction carries the measured incident's noise), widened by the model's
tolerance: sample t has standard deviation s_t = sqrt(sd^2 + tol_t^2), tol_t the channel's
tolerated model error (:func:`~.whole_record.tolerance_sd`: 1-2 % of the signal on a bar gauge,
3 % on the hoop gauge, and a timing tolerance of 0.2 us times the local slope), and the residual
scaled by sd / s_t is AR(1) with the gauge's coefficient. Without it the 0.1 %-level differences
between any two simulators of the test (time step, mesh, a rounded constant) would read as physics
on the high-signal channels. The hoop gauge's calibration factor enters linearly and is profiled
out (its generalised least-squares value for each parameter vector).

The posterior is approximated by a normal distribution in the unbounded coordinates of the
parameters (:meth:`~friction_uq.models.Parameter.to_unbounded`) around its mode, found by
Levenberg-Marquardt on the whitened residuals (with Gaussian stand-ins of the priors), with the
Gauss-Newton matrix J^T J as precision (no finite-difference Hessian, which fails when the
posterior is narrower than its step), and the draws are corrected by
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
from ..models.parameters import summarize_draws
from ..models.simulator import SimulatorModel
from .whole_record import CHANNEL_LABELS, channel_noise, channel_spans, tolerance_sd, whiten

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
    cov_z: np.ndarray | None = None
    jacobian: np.ndarray | None = None  # d(whitened data residual)/dz at the mode, (n_data, n_par)
    whitened: np.ndarray | None = None  # whitened data residual at the mode

    def summary(self, name: str) -> dict[str, float]:
        return summarize_draws(self.draws[name])


class WholeRecordLikelihood:
    """log p(record | parameters) over every gauge's span (module docstring)."""

    def __init__(self, prep: Prepared, model: SimulatorModel) -> None:
        rec = prep.record
        self.model = model
        self.channels = tuple(c for c in CHANNEL_LABELS if c in rec.channels and (c != "tube_hoop" or model.hoop))
        self.bounds = channel_spans(prep, self.channels)
        self.noise = {c: channel_noise(prep, c) for c in self.channels}
        self.measured = {c: rec.strain(c) - prep.forces.channels[c].noise.offset for c in self.channels}
        self.weight: dict[str, np.ndarray] = {}  # sd / s_t over each span (module docstring)
        for c in self.channels:
            sl, nz = self._span(c), self.noise[c]
            tol = tolerance_sd(self.measured[c], c, sample_rate=rec.sample_rate)[sl]
            self.weight[c] = nz.sd / np.hypot(nz.sd, tol)
        self._log_weight = sum(float(np.sum(np.log(w))) for w in self.weight.values())
        # offset errors: the whitened direction of a constant offset, and the Gaussian constants
        self._wv = {c: whiten(self.weight[c], sd=self.noise[c].sd, rho=self.noise[c].rho_long_run)
                    for c in self.channels}
        self._const = 0.0
        for c in self.channels:
            nz, n = self.noise[c], len(self.weight[c])
            self._const += (-0.5 * n * math.log(2.0 * math.pi * nz.sd**2) - 0.5 * (n - 1) * math.log(1.0 - nz.rho_long_run**2)
                            - 0.5 * math.log1p(nz.offset_sd**2 * float(self._wv[c] @ self._wv[c])))

    def _raw_scaled(self, c: str, pred: np.ndarray) -> np.ndarray:
        sl = self._span(c)
        return (self.measured[c][sl] - pred[sl]) * self.weight[c]

    def _offset(self, c: str, w: np.ndarray) -> float:
        """Most probable offset error of the channel (prior N(0, offset sd^2)) given whitened residuals w."""
        nz = self.noise[c]
        if nz.offset_sd <= 0.0:
            return 0.0
        wv = self._wv[c]
        return float(wv @ w) / (float(wv @ wv) + 1.0 / nz.offset_sd**2)

    def scaled_residual(self, c: str, pred: np.ndarray) -> np.ndarray:
        """(measured - predicted - offset error) sd / s_t over the channel's span: AR(1) with the gauge's sd
        and effective coefficient. The offset error (the pre-pulse mean is uncertain) is profiled."""
        nz = self.noise[c]
        u = self._raw_scaled(c, pred)
        d = self._offset(c, whiten(u, sd=nz.sd, rho=nz.rho_long_run))
        return u - d * self.weight[c]

    def _span(self, c: str) -> slice:
        i0, _, _, i3 = self.bounds[c]
        return slice(i0, i3)

    def hoop_gain(self, predicted_unit: np.ndarray) -> float:
        """Generalised least-squares gain of the hoop gauge for a prediction at gain 1."""
        s, nz, w = self._span("tube_hoop"), self.noise["tube_hoop"], self.weight["tube_hoop"]
        wp = whiten(predicted_unit[s] * w, sd=nz.sd, rho=nz.rho_long_run)
        wm = whiten(self.measured["tube_hoop"][s] * w, sd=nz.sd, rho=nz.rho_long_run)
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

    def whitened(self, values: Mapping[str, float]) -> np.ndarray:
        """AR(1)-whitened residuals of every channel with its profiled offset error, concatenated, then one
        pseudo-residual per channel (offset / its sd): log-likelihood = const - |w|^2 / 2."""
        pred, _ = self.strains(values)
        return self.whitened_from(pred)

    @property
    def n_samples(self) -> int:
        return sum(self.bounds[c][3] - self.bounds[c][0] for c in self.channels)

    def loglike(self, values: Mapping[str, float]) -> float:
        try:
            pred, _ = self.strains(values)
        except ValueError:
            return -np.inf
        w = self.whitened_from(pred)
        return self._log_weight + self._const - 0.5 * float(w @ w)

    def whitened_from(self, pred: Mapping[str, np.ndarray]) -> np.ndarray:
        out, pseudo = [], []
        for c in self.channels:
            nz = self.noise[c]
            w = whiten(self._raw_scaled(c, pred[c]), sd=nz.sd, rho=nz.rho_long_run)
            d = self._offset(c, w)
            out.append(w - d * self._wv[c])
            pseudo.append(d / nz.offset_sd if nz.offset_sd > 0 else 0.0)
        return np.concatenate(out + [np.array(pseudo)])


def fit_whole_record(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], *,
                     n_draws: int = 30, rng: np.random.Generator,
                     prior_scale: Mapping[str, tuple[float, float]] | None = None,
                     importance: bool = True, extra_starts: tuple[Mapping[str, float], ...] = ()) -> WholeRecordFit:
    """Posterior mode, Laplace approximation and importance-weighted draws (module docstring).

    ``start`` gives a value for every free parameter (``hoop_gain``, profiled, is not one).
    ``prior_scale`` (name -> (centre, sd) in the parameter's unbounded coordinate) gives the
    Gaussian stand-ins of the priors used while searching the mode (Levenberg-Marquardt on the
    whitened residuals); the exact ``log_prior`` weights the draws. Without ``importance`` the
    draws are the normal approximation's, unweighted (no simulator run per draw). ``extra_starts``
    (partial value sets overriding ``start``) are further starting points of the mode search; the
    best mode is kept (the rise of the record pins the sample's confined modulus, which a low nu with
    a stiff sample matches as well as the right nu: two modes).
    """
    params = [lik.model.parameters[n] for n in start if n != "hoop_gain"]
    names = tuple(p.name for p in params)
    calls = 0

    def values_of(z: np.ndarray) -> dict[str, float]:
        return {p.name: float(p.from_unbounded(zi)) for p, zi in zip(params, z)}

    z0 = np.array([float(p.to_unbounded(start[p.name])) for p in params])
    scale = {n: (float(z0[i]), 3.0) for i, n in enumerate(names)}
    scale.update(prior_scale or {})
    centre = np.array([scale[n][0] for n in names])
    width = np.array([scale[n][1] for n in names])

    n_data: list[int] = []

    def residuals(z: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        try:
            r = lik.whitened(values_of(z))
            n_data[:] = [len(r)]
        except ValueError:  # parameters the simulator cannot run (a column too stiff to integrate)
            r = np.full(n_data[0] if n_data else lik.n_samples, 1e3)
        return np.concatenate([r, (z - centre) / width])

    res = None
    for alt in ({}, *extra_starts):
        za = np.array([float(p.to_unbounded(alt.get(p.name, start[p.name]))) for p in params])
        r = optimize.least_squares(residuals, za, method="trf", x_scale=width, diff_step=1e-6, xtol=1e-12, ftol=1e-10,
                                   max_nfev=60 * (len(z0) + 1))
        if res is None or r.cost < res.cost:
            res = r
    zm = res.x
    J = res.jac
    H = J.T @ J  # Gauss-Newton precision in z (data and the Gaussian stand-ins of the priors)
    try:
        cov = np.linalg.inv(H)
        chol = np.linalg.cholesky(0.5 * (cov + cov.T))
    except np.linalg.LinAlgError:
        chol = np.diag(np.full(len(zm), 1e-3))

    def log_post(z: np.ndarray) -> float:
        vals = values_of(z)
        lp = log_prior(vals)
        if not np.isfinite(lp):
            return -np.inf
        jac = sum(float(p.log_jacobian(zi)) for p, zi in zip(params, z))
        return lik.loglike(vals) + lp + jac

    eps = rng.standard_normal((n_draws, len(zm)))
    z = zm + eps @ chol.T
    if importance:
        log_q = -0.5 * np.sum(eps * eps, axis=1)
        log_p = np.array([log_post(zi) for zi in z])
        log_w = log_p - log_q
        log_w = np.where(np.isfinite(log_w), log_w, -np.inf)
        k = _pareto_k(log_w[np.isfinite(log_w)])
        log_w = log_w - np.logaddexp.reduce(log_w)
    else:
        log_w, k = np.full(n_draws, -math.log(n_draws)), math.nan
    draws = {p.name: np.asarray(p.from_unbounded(z[:, i]), float) for i, p in enumerate(params)}
    mode = values_of(zm)
    n_data = len(res.fun) - len(zm)
    return WholeRecordFit(names=names, mode=mode, draws=draws, log_weights=log_w, pareto_k=k,
                          loglike_mode=lik.loglike(mode), n_calls=calls + (n_draws if importance else 0),
                          cov_z=cov, jacobian=J[:n_data], whitened=res.fun[:n_data])


def _pareto_k(log_w: np.ndarray) -> float:
    """Pareto k of importance weights (arviz-stats PSIS); nan when it cannot be computed."""
    try:
        from arviz_stats.base import array_stats

        _, k = array_stats.psislw(np.asarray(log_w, float))
        return float(np.asarray(k).ravel()[0])
    except Exception:  # noqa: BLE001 - the diagnostic is optional, the draws stand without it
        return math.nan
