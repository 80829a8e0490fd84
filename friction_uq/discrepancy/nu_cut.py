"""f under a whole-record model with nu from the stationary analysis: the cut posterior.

A whole-record model reads nu from the record's dynamics as well as from the hoop gauge's level: the
rises, the hoop's course around the window and its unloading all move with nu at a fixed confined modulus.
Those shapes are where a 1-D model and the real cell (or an axisymmetric simulation of it) differ most
(docs/trust.md, "The 1-D plug friction's f in the axisymmetric cell"): there the fit bends nu low by
0.04-0.14, the hoop gauge's factor goes 20-80 % over its calibration to keep the level, and f = kappa
(1 - nu) / nu comes out a quarter to twice too high, with an interval that does not hold the truth. The
stationary analysis reads nu from the quasi-static relation of the hoop's level over the window to the
axial stress alone, which two simulators of the test agree on.

So the f a whole-record model gives is taken from the *cut* posterior (modular inference: the feedback of
the misspecified module on a shared parameter is cut; Plummer 2015, Jacob et al. 2017):

    p_cut(theta, nu) = p_stationary(nu | window) p(theta | nu, whole record),

theta being the model's other parameters (f, the sample's modulus, the mechanism's). The second factor is
the whole-record fit at nu fixed (:func:`conditional_fit`: its mode at the stationary median nu_0 and its
Laplace approximation); its dependence on nu is the conditional mode's linear response,
d theta / d nu = -(J_theta^T J_theta)^-1 J_theta^T J_nu (Gauss-Newton at the conditional mode, J_nu by a central
difference; :func:`conditional_slope`). A draw is then nu from the stationary posterior's draws and theta
from the conditional normal at nu_0, moved along the slope by nu - nu_0 (:func:`cut_draws`).

What this changes is f's draws alone: the models' evidence (ELPD), the ranking, the names and the misfit
decisions are the joint fit's, as they were calibrated (:mod:`.extended`). On records of the 1-D simulation
with a hidden plug friction the stationary nu is itself 0.01-0.02 low (the stationary model has no plug);
the cut then reads f a few % high with an interval widened by nu's own uncertainty (measured: docs/trust.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..models.parameters import Parameter
from .fit import LogPrior, WholeRecordFit, fit_whole_record
from .record_likelihood import WholeRecordLikelihood

#: Central-difference step of d(residual)/d nu (nu itself, not its unbounded coordinate).
NU_STEP = 1e-3


@dataclass(frozen=True)
class NuCut:
    """The stationary analysis' draws of nu, which a whole-record model's f is conditioned on."""

    draws: np.ndarray

    def __post_init__(self) -> None:
        d = np.asarray(self.draws, float).ravel()
        if d.size < 2 or not np.all(np.isfinite(d)) or np.any((d <= 0.0) | (d >= 0.5)):
            raise ValueError("the stationary draws of nu for the cut must be at least two, finite, in (0, 0.5)")
        object.__setattr__(self, "draws", d)

    @property
    def centre(self) -> float:
        """nu_0: the stationary posterior's median, where the conditional fit is made."""
        return float(np.median(self.draws))

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n draws of nu (with replacement: the stationary chain's draws are many more than a fit's)."""
        return rng.choice(self.draws, size=n, replace=True)


class FixedNu:
    """A whole-record likelihood with nu held at a value: what :func:`fit_whole_record` and the exact
    posterior need of a likelihood (its model's parameters, whitened residuals, log-likelihood, size)."""

    def __init__(self, lik: WholeRecordLikelihood, nu: float) -> None:
        self.lik, self.nu = lik, float(nu)
        self.model = lik.model

    def whitened(self, values: Mapping[str, float]) -> np.ndarray:
        return self.lik.whitened(dict(values) | {"nu": self.nu})

    def loglike(self, values: Mapping[str, float]) -> float:
        return self.lik.loglike(dict(values) | {"nu": self.nu})

    @property
    def n_samples(self) -> int:
        return self.lik.n_samples


@dataclass(frozen=True)
class CutFit:
    """A model's fit at nu = nu_0 (theta's Laplace approximation) and the conditional mode's slope in nu."""

    fit: WholeRecordFit
    nu0: float
    slope: np.ndarray  # d z_theta / d nu, in the order of fit.names


def conditional_fit(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], cut: NuCut, *,
                    n_draws: int, rng: np.random.Generator, prior_scale: Mapping[str, tuple[float, float]],
                    score_blocks: np.ndarray) -> CutFit:
    """The whole-record fit of theta at nu = nu_0 from ``start`` (the joint fit's mode) and its slope in nu."""
    nu0 = cut.centre
    fixed = FixedNu(lik, nu0)
    st = {k: v for k, v in start.items() if k not in ("nu", "hoop_gain")}
    scales = {k: v for k, v in prior_scale.items() if k != "nu"}
    fit = fit_whole_record(fixed, lambda v: log_prior(dict(v) | {"nu": nu0}), st, n_draws=n_draws, rng=rng,
                           importance=False, prior_scale=scales, score_blocks=score_blocks)
    return CutFit(fit=fit, nu0=nu0, slope=conditional_slope(lik, fit, nu0))


def conditional_slope(lik: WholeRecordLikelihood, fit: WholeRecordFit, nu0: float) -> np.ndarray:
    """d z_theta / d nu of the conditional mode (module docstring): zero where the fit has no precision."""
    if fit.cov_z is None or fit.jacobian is None:
        return np.zeros(len(fit.names))
    try:
        up = lik.whitened(dict(fit.mode) | {"nu": nu0 + NU_STEP})
        down = lik.whitened(dict(fit.mode) | {"nu": nu0 - NU_STEP})
    except ValueError:  # the simulator cannot run a step away: no response known
        return np.zeros(len(fit.names))
    j_nu = (up - down) / (2.0 * NU_STEP)
    return -fit.cov_z @ (fit.jacobian.T @ j_nu)


def cut_draws(params: list[Parameter], z: np.ndarray, cf: CutFit, nu: np.ndarray) -> dict[str, np.ndarray]:
    """Draws of every parameter under the cut: theta's conditional draws ``z`` (unbounded, at nu_0) moved along
    the slope by nu - nu_0, beside the stationary draws ``nu`` (one per row of ``z``)."""
    zs = z + np.outer(nu - cf.nu0, cf.slope)
    out = {p.name: np.asarray(p.from_unbounded(zs[:, i]), float) for i, p in enumerate(params)}
    out["nu"] = np.asarray(nu, float)
    return out
