"""f under a whole-record model with nu from the record's stationary window: the cut posterior.

A whole-record model reads nu from the record's dynamics as well as from the hoop gauge's level: the
rises, the hoop's course around the window and its unloading all move with nu at a fixed confined modulus.
Those shapes are where a 1-D model and the real cell (or an axisymmetric simulation of it) differ most
(docs/trust.md, "The 1-D plug friction's f in the axisymmetric cell"): there the fit bends nu low by
0.04-0.14, the hoop gauge's factor goes 20-80 % over its calibration to keep the level, and f = kappa
(1 - nu) / nu comes out a quarter to twice too high, with an interval that does not hold the truth. The
stationary analysis reads nu from the quasi-static relation of the hoop's level over the window to the
axial stress alone, which two simulators of the test agree on.

So the f a whole-record model gives is taken from a *cut* posterior (modular inference: the feedback of
the misspecified part of a model on a shared parameter is cut; Plummer 2015, Jacob et al. 2017), in two modules:

* nu from the quasi-static part of the record under the model: the same model's likelihood over every gauge's
  stationary window alone, its slow bends there marginalised (:func:`window_nu`), with every parameter of the model
  free under its prior: f, nu, the sample's modulus (the output forces fix kappa, the hoop's level with its 5 %
  calibration fixes nu; the modulus is what the dynamics bend with nu) and the mechanism's (a clearance's gap, a
  plug's friction: what changes the window's relation of the wall pressure to the axial stress). The stationary
  analysis reads nu from the window too, but without the mechanism: a gap or end-face friction the stationary model
  does not have puts its nu 0.03-0.14 off, which this module does not inherit. The mechanism's parameters are not
  taken from the joint fit: held at its mode they would carry the whole record's dynamics, the cut part, into nu
  (on B-02's four-cause model nu's sd fell to 0.002, a fifth of what the hoop gauge's calibration allows; free, it
  is 0.008, docs/trust.md);
* theta, the model's other parameters (f, the sample's modulus, the mechanism's), from the whole record given nu
  (:func:`conditional_fit`: the fit at nu fixed at that posterior's median nu_0 and its Laplace approximation); its
  dependence on nu is the conditional mode's linear response, d theta / d nu = -(J^T J)^-1 J^T J_nu (Gauss-Newton
  at the conditional mode, J_nu by a central difference; :func:`conditional_slope`).

A draw is nu from the first module's draws and theta from the conditional normal at nu_0, moved along the slope by
nu - nu_0 (:func:`cut_draws`). What this changes is f's draws alone (and nu's, paired with them): the models'
evidence (ELPD), the ranking, the names and the misfit decisions are the joint fit's, as they were calibrated
(:mod:`.extended`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..analysis import Prepared
from ..models.parameters import Parameter
from ..models.simulator import SimulatorModel
from .fit import LogPrior, WholeRecordFit, fit_whole_record
from .record_likelihood import HOOP_GAIN_SD, WholeRecordLikelihood
from .whole_record import CHANNEL_LABELS

#: Central-difference step of d(residual)/d nu (nu itself, not its unbounded coordinate).
NU_STEP = 1e-3
#: Prior sd (relative to the window's level) of the smooth bends of each gauge's course over its window that the
#: first module marginalises (Legendre degrees 1 and 2): wide, so that the windows' levels alone inform nu and f.
WINDOW_SHAPE_SD = 0.5


@dataclass(frozen=True)
class NuCut:
    """Draws of nu from the first module (:func:`window_nu`), which a whole-record model's f is conditioned on."""

    draws: np.ndarray

    def __post_init__(self) -> None:
        d = np.asarray(self.draws, float).ravel()
        if d.size < 2 or not np.all(np.isfinite(d)) or np.any((d <= 0.0) | (d >= 0.5)):
            raise ValueError("the draws of nu for the cut must be at least two, finite, in (0, 0.5)")
        object.__setattr__(self, "draws", d)

    @property
    def centre(self) -> float:
        """nu_0: the draws' median, where the conditional fit is made."""
        return float(np.median(self.draws))

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n draws of nu (with replacement)."""
        return rng.choice(self.draws, size=n, replace=True)


class Fixed:
    """A whole-record likelihood with some parameters held at values: what :func:`fit_whole_record` and the exact
    posterior need of a likelihood (its model's parameters, whitened residuals, log-likelihood, size)."""

    def __init__(self, lik: WholeRecordLikelihood, values: Mapping[str, float]) -> None:
        self.lik, self.values = lik, dict(values)
        self.model = lik.model

    def whitened(self, values: Mapping[str, float]) -> np.ndarray:
        return self.lik.whitened(self.values | dict(values))

    def loglike(self, values: Mapping[str, float]) -> float:
        return self.lik.loglike(self.values | dict(values))

    @property
    def n_samples(self) -> int:
        return self.lik.n_samples


@dataclass(frozen=True)
class CutFit:
    """A model's fit at nu = nu_0 (theta's Laplace approximation) and the conditional mode's slope in nu."""

    fit: WholeRecordFit
    nu0: float
    slope: np.ndarray  # d z_theta / d nu, in the order of fit.names
    nu: NuCut  # the first module's draws of nu

    def draws(self, params: list[Parameter], z: np.ndarray, rng: np.random.Generator) -> dict[str, np.ndarray]:
        """:func:`cut_draws` of theta's conditional draws ``z`` with as many draws of nu, taken from ``rng``."""
        return cut_draws(params, z, self, self.nu.sample(len(z), rng))


def window_nu(prep: Prepared, model: SimulatorModel, log_prior: LogPrior, start: Mapping[str, float], *,
              n_draws: int, rng: np.random.Generator, prior_scale: Mapping[str, tuple[float, float]],
              hoop_calibration: tuple[float, float] = (1.0, HOOP_GAIN_SD),
              extra_starts: tuple[Mapping[str, float], ...] = ()) -> NuCut:
    """nu's posterior from every gauge's stationary window under the model (module docstring): every parameter of
    the model free under its prior (``prior_scale``: their Gaussian stand-ins), the search from ``start`` (the joint
    fit's mode) and from each of ``extra_starts`` (``start`` with those values; the lowest cost kept), the gauges'
    calibrations and slow bends marginalised; its normal approximation's draws.

    The windows' surface is flat along nu and rough on a scale far below its width (the explicit stick-slip
    integration): from one start the search can stop in a dip 0.01 in log density from a lower one, 0.13 sd of nu
    away (tests/test_nu_cut.py), so the mechanisms' own nominal start is searched from too."""
    lik = WholeRecordLikelihood(prep, model, window_only=True, hoop_calibration=hoop_calibration,
                                shape_sd={(c, "stationary"): WINDOW_SHAPE_SD for c in CHANNEL_LABELS})
    free = {k: v for k, v in start.items() if k != "hoop_gain"}
    fit = fit_whole_record(lik, log_prior, free, n_draws=n_draws, rng=rng, importance=False,
                           prior_scale={k: v for k, v in prior_scale.items() if k in free},
                           extra_starts=tuple({k: v for k, v in alt.items() if k in free} for alt in extra_starts))
    return NuCut(fit.draws["nu"])


def conditional_fit(lik: WholeRecordLikelihood, log_prior: LogPrior, start: Mapping[str, float], cut: NuCut, *,
                    n_draws: int, rng: np.random.Generator, prior_scale: Mapping[str, tuple[float, float]],
                    score_blocks: np.ndarray) -> CutFit:
    """The whole-record fit of theta at nu = nu_0 (``cut``'s median) from ``start`` (the joint fit's mode) and its
    slope in nu."""
    nu0 = cut.centre
    fixed = Fixed(lik, {"nu": nu0})
    st = {k: v for k, v in start.items() if k not in ("nu", "hoop_gain")}
    scales = {k: v for k, v in prior_scale.items() if k != "nu"}
    fit = fit_whole_record(fixed, lambda v: log_prior(dict(v) | {"nu": nu0}), st, n_draws=n_draws, rng=rng,
                           importance=False, prior_scale=scales, score_blocks=score_blocks)
    return CutFit(fit=fit, nu0=nu0, slope=conditional_slope(lik, fit, nu0), nu=cut)


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
    the slope by nu - nu_0, beside the first module's draws ``nu`` (one per row of ``z``)."""
    zs = z + np.outer(nu - cf.nu0, cf.slope)
    out = {p.name: np.asarray(p.from_unbounded(zs[:, i]), float) for i, p in enumerate(params)}
    out["nu"] = np.asarray(nu, float)
    return out
