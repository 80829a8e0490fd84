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
out (its generalised least-squares value for each parameter vector). Each channel's offset error
(the pre-pulse mean is uncertain) and each output bar gauge's gain error (its calibration, 1 %:
an error correlated over the whole record, which the per-sample tolerance alone would treat as
averaging out) enter linearly with Gaussian priors and are marginalised: least squares on the
whitened residuals with one pseudo-residual per nuisance gives the marginal quadratic form exactly.

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
#: Calibration errors of the output bar gauges marginalised in the whole-record likelihood (relative sd):
#: a bar gauge's calibration and the bar's E and c are known to about 1 % (the level part of
#: :data:`~.whole_record.TOLERANCE`, correlated over the record as a calibration error is).
GAIN_SD = {"internal_output_bar": 0.01, "external_output_bar": 0.01}
#: Step (unbounded coordinate) of the central differences giving the Laplace precision.
JACOBIAN_STEP = 1e-3
#: Blocks apart whose scores are taken as correlated in :func:`robust_covariance` (Bartlett weights).
ROBUST_LAGS = 4


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
    laplace_draws: dict[str, np.ndarray] | None = None  # the normal approximation's, when ``draws`` are robust

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
        # the Gaussian constants (the nuisances' log determinant depends on the prediction: per call)
        self._const = 0.0
        for c in self.channels:
            nz, n = self.noise[c], len(self.weight[c])
            self._const += -0.5 * n * math.log(2.0 * math.pi * nz.sd**2) - 0.5 * (n - 1) * math.log(1.0 - nz.rho_long_run**2)

    def _raw_scaled(self, c: str, pred: np.ndarray) -> np.ndarray:
        sl = self._span(c)
        return (self.measured[c][sl] - pred[sl]) * self.weight[c]

    def _nuisance_basis(self, c: str, pred: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The channel's calibration nuisances: raw (scaled) directions, their whitened columns and prior sds.

        A constant offset error (the pre-pulse mean is uncertain: sd ``offset_sd``) and, on the output bar
        gauges, a gain error (their calibration: sd :data:`GAIN_SD`), whose direction is the prediction."""
        nz, sl, w = self.noise[c], self._span(c), self.weight[c]
        raw, sds = [], []
        if nz.offset_sd > 0.0:
            raw.append(w)
            sds.append(nz.offset_sd)
        if c in GAIN_SD:
            raw.append(pred[sl] * w)
            sds.append(GAIN_SD[c])
        if not raw:
            return np.zeros((len(w), 0)), np.zeros((len(w), 0)), np.zeros(0)
        R = np.stack(raw, axis=1)
        return R, whiten(R, sd=nz.sd, rho=nz.rho_long_run), np.array(sds)  # whitened along time, per column

    def _nuisances(self, c: str, pred: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                           np.ndarray, float]:
        """Most probable nuisance values (prior N(0, sd^2)) given whitened residuals w: (values, raw
        directions, whitened directions, prior sds, log det(I + Sd V^T V Sd) of their marginalisation).
        Least squares on the whitened residual with the pseudo-residuals value / sd gives the marginal
        likelihood's quadratic form exactly (the nuisances enter linearly)."""
        R, V, sds = self._nuisance_basis(c, pred)
        if not len(sds):
            return np.zeros(0), R, V, sds, 0.0
        A = V.T @ V + np.diag(1.0 / sds**2)
        d = np.linalg.solve(A, V.T @ w)
        logdet = float(np.linalg.slogdet(A)[1] + 2.0 * np.sum(np.log(sds)))
        return d, R, V, sds, logdet

    def scaled_residual(self, c: str, pred: np.ndarray) -> np.ndarray:
        """(measured - predicted - nuisances) sd / s_t over the channel's span: AR(1) with the gauge's sd
        and effective coefficient. The offset error (the pre-pulse mean is uncertain) and an output bar
        gauge's gain error are profiled."""
        nz = self.noise[c]
        u = self._raw_scaled(c, pred)
        d, R, _, _, _ = self._nuisances(c, pred, whiten(u, sd=nz.sd, rho=nz.rho_long_run))
        return u - R @ d

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
        w, logdet = self._whitened_logdet(pred)
        return self._log_weight + self._const - 0.5 * logdet - 0.5 * float(w @ w)

    @property
    def n_pseudo(self) -> int:
        """Pseudo-residuals (nuisance / its prior sd) at the end of :meth:`whitened`: one per nuisance."""
        return sum(int(self.noise[c].offset_sd > 0.0) + int(c in GAIN_SD) for c in self.channels)

    def whitened_from(self, pred: Mapping[str, np.ndarray]) -> np.ndarray:
        return self._whitened_logdet(pred)[0]

    def _whitened_logdet(self, pred: Mapping[str, np.ndarray]) -> tuple[np.ndarray, float]:
        out, pseudo, logdet = [], [], 0.0
        for c in self.channels:
            nz = self.noise[c]
            w = whiten(self._raw_scaled(c, pred[c]), sd=nz.sd, rho=nz.rho_long_run)
            d, _, V, sds, ld = self._nuisances(c, pred[c], w)
            out.append(w - V @ d)
            pseudo.append(d / sds)
            logdet += ld
        return np.concatenate(out + pseudo), logdet


def robust_covariance(jacobian: np.ndarray, whitened: np.ndarray, cov: np.ndarray, blocks: np.ndarray, *,
                      lags: int = ROBUST_LAGS) -> np.ndarray:
    """Posterior covariance widened for a model that misses the record: the Laplace covariance ``cov``
    plus the positive part of (sandwich - cov).

    The sandwich H^-1 B H^-1 (H^-1 = ``cov``) is the spread of the best-fitting parameters when the
    model is wrong (Huber; White 1982); B is the covariance of the score summed per block of the
    record (``blocks``: the block of each whitened residual), with the products of blocks up to
    ``lags`` apart weighted by Bartlett's kernel (Newey-West), since a model's error is correlated
    over longer than one block. When the model is right, B ~ H and nothing changes; where it
    misses, the residual's structure that the parameters had to absorb widens their posterior
    (Muller 2013, "Risk of Bayesian inference in misspecified models").
    """
    g = jacobian * whitened[:, None]
    G = np.zeros((int(blocks.max()) + 1, jacobian.shape[1]))
    np.add.at(G, blocks, g)
    B = G.T @ G
    for lag in range(1, lags + 1):
        C = G[:-lag].T @ G[lag:]
        B += (1.0 - lag / (lags + 1.0)) * (C + C.T)
    D = cov @ B @ cov - cov
    w, V = np.linalg.eigh(0.5 * (D + D.T))
    return cov + (V * np.clip(w, 0.0, None)) @ V.T


def fit_whole_record(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], *,
                     n_draws: int = 30, rng: np.random.Generator,
                     prior_scale: Mapping[str, tuple[float, float]] | None = None,
                     importance: bool = True, extra_starts: tuple[Mapping[str, float], ...] = (),
                     score_blocks: np.ndarray | None = None) -> WholeRecordFit:
    """Posterior mode, Laplace approximation and importance-weighted draws (module docstring).

    ``start`` gives a value for every free parameter (``hoop_gain``, profiled, is not one).
    ``prior_scale`` (name -> (centre, sd) in the parameter's unbounded coordinate) gives the
    Gaussian stand-ins of the priors used while searching the mode (Levenberg-Marquardt on the
    whitened residuals); the exact ``log_prior`` weights the draws. Without ``importance`` the
    draws are the normal approximation's, unweighted (no simulator run per draw). ``extra_starts``
    (partial value sets overriding ``start``) are further starting points of the mode search; the
    best mode is kept (the rise of the record pins the sample's confined modulus, which a low nu with
    a stiff sample matches as well as the right nu: two modes). ``score_blocks`` (the block of each
    whitened residual, :meth:`WholeRecordLikelihood.whitened`): the draws are taken from
    :func:`robust_covariance` (the normal approximation's are kept in ``laplace_draws``).
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
    # the precision from central differences over JACOBIAN_STEP: the explicit stick-slip integration makes
    # the prediction jump by a time step's worth where a slip starts one step earlier or later, and a
    # derivative over the optimiser's 1e-6 step can read such a jump as information
    J = np.stack([(residuals(zm + JACOBIAN_STEP * e) - residuals(zm - JACOBIAN_STEP * e)) / (2.0 * JACOBIAN_STEP)
                  for e in np.eye(len(zm))], axis=1)
    H = J.T @ J  # Gauss-Newton precision in z (data and the Gaussian stand-ins of the priors)
    try:
        cov = np.linalg.inv(H)
        chol = np.linalg.cholesky(0.5 * (cov + cov.T))
    except np.linalg.LinAlgError:
        cov, chol = None, np.diag(np.full(len(zm), 1e-3))

    def log_post(z: np.ndarray) -> float:
        vals = values_of(z)
        lp = log_prior(vals)
        if not np.isfinite(lp):
            return -np.inf
        jac = sum(float(p.log_jacobian(zi)) for p, zi in zip(params, z))
        return lik.loglike(vals) + lp + jac

    eps = rng.standard_normal((n_draws, len(zm)))
    n_data = len(res.fun) - len(zm)
    laplace = None
    if score_blocks is not None and cov is not None:
        laplace = {p.name: np.asarray(p.from_unbounded(zm[i] + eps @ chol[i]), float) for i, p in enumerate(params)}
        try:
            chol = np.linalg.cholesky(robust_covariance(J[:n_data], res.fun[:n_data], cov, score_blocks))
        except np.linalg.LinAlgError:
            pass
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
    return WholeRecordFit(names=names, mode=mode, draws=draws, log_weights=log_w, pareto_k=k,
                          loglike_mode=lik.loglike(mode), n_calls=calls + (n_draws if importance else 0),
                          cov_z=cov, jacobian=J[:n_data], whitened=res.fun[:n_data], laplace_draws=laplace)


def _pareto_k(log_w: np.ndarray) -> float:
    """Pareto k of importance weights (arviz-stats PSIS); nan when it cannot be computed."""
    try:
        from arviz_stats.base import array_stats

        _, k = array_stats.psislw(np.asarray(log_w, float))
        return float(np.asarray(k).ravel()[0])
    except Exception:  # noqa: BLE001 - the diagnostic is optional, the draws stand without it
        return math.nan
