"""Likelihood of the friction coefficient f, the sample Poisson ratio nu (and the hoop-gauge factor g)
over a forward model and the observations of one stationary phase.

The model is the closed form (:class:`friction_uq.models.ClosedFormModel`: the force ratio of
eq. 13/17 and the tube-kernel hoop prediction); the observations a
:class:`~friction_uq.window.StationaryData`. The likelihood is the sum of

* the force term (:mod:`.force`): eq. 17 with errors in variables, AR(1) noise and offset errors,
  evaluated from precomputed sums (fast path for a constant ratio);
* the hoop term (:mod:`.hoop`): the tube gauge against the model, by its window level (default)
  or sample by sample;

with the AR(1) algebra in :mod:`friction_uq.stats.ar1`. Parameter vectors are rows in the order of the model's
:class:`~friction_uq.models.ParameterSet` (``Likelihood.parameters``) and are read by name through it;
SI units, forces in N, strains in strain.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SignalError
from ..models.closed_form import ClosedFormModel, gauge_kernel
from ..noise import ar1_noise
from ..stats.ar1 import ar1_loglike, ar1_offset_correction, ar1_pointwise, offset_sd
from ..window import StationaryData
from .force import ForceTerm
from .force_level import RATIO_MODEL_FORM, LevelForceTerm
from .hoop import HOOP_DISCREPANCY, HOOP_MODES, HoopTerm

#: How the force ratio enters the likelihood: by the window levels (default) or sample by sample.
FORCE_MODES = ("level", "series")

__all__ = [
    "FORCE_MODES", "HOOP_DISCREPANCY", "RATIO_MODEL_FORM", "HOOP_MODES", "ForceTerm", "HoopTerm", "LevelForceTerm", "Likelihood",
    "ar1_loglike", "ar1_noise", "ar1_offset_correction", "ar1_pointwise", "gauge_kernel", "offset_sd",
]


def _check_data(data: StationaryData) -> None:
    if data.n < 8:
        raise SignalError(f"stationary data of {data.test_id or 'record'}: {data.n} samples, at least 8 are needed")
    for name in ("F_io", "F_eo", "slip"):
        if not np.all(np.isfinite(getattr(data, name))):
            raise SignalError(f"stationary data of {data.test_id or 'record'}: {name} has non-finite values")
    for name in ("sd_io", "sd_eo"):
        v = getattr(data, name)
        if not (v > 0.0 and math.isfinite(v)):
            raise SignalError(f"stationary data: noise {name} must be a positive number, got {v!r}")
    for name in ("rho_io", "rho_eo"):
        v = getattr(data, name)
        if not -1.0 < v < 1.0:
            raise SignalError(f"stationary data: AR(1) coefficient {name} must lie in (-1, 1), got {v!r}")


class Likelihood:
    """Log-likelihood of parameter vectors (f, nu[, hoop_gain]) for one stationary phase.

    Parameters
    ----------
    data : StationaryData
        The observations.
    hoop : bool or None
        Include the hoop-gauge term; None: when the data have a hoop channel (or, with ``model``,
        when the model predicts the hoop gauge).
    axial_poisson : bool
        Include the tube's axial Poisson term in the hoop prediction (when the model is built here).
    hoop_mode : {"level", "series"}
        How the hoop reading enters (:class:`~.hoop.HoopTerm`).
    hoop_discrepancy : float
        Relative sd of the hoop model's error on the level ("level" mode).
    force_mode : {"level", "series"}
        How the force ratio enters: "level" (default), the window means with a standard error from
        batch means (:mod:`.force_level`), which holds when the record fluctuates in ways the model
        does not describe; "series", every sample with the pre-pulse AR(1) noise as the only error
        (:mod:`.force`), exact only when the window is the model plus that noise.
    model : ClosedFormModel or None
        The forward model over ``data``; None: ``ClosedFormModel(data, hoop=hoop,
        axial_poisson=axial_poisson)``.
    ratio_model_form : float
        Relative sd of the closed form's force ratio against the world ("level" force mode:
        :data:`~.force_level.RATIO_MODEL_FORM`; the "series" mode has no such term).

    Attributes
    ----------
    model : ClosedFormModel
    parameters : ParameterSet
        The model's parameters: (f, nu) or (f, nu, hoop_gain); columns of parameter vectors.
    names : tuple of str
        Their names.
    """

    def __init__(
        self, data: StationaryData, *, hoop: bool | None = None, axial_poisson: bool = True, hoop_mode: str = "level",
        model: ClosedFormModel | None = None, hoop_discrepancy: float = HOOP_DISCREPANCY, force_mode: str = "level",
        ratio_model_form: float = RATIO_MODEL_FORM,
    ) -> None:
        if force_mode not in FORCE_MODES:
            raise ValueError(f"force mode {force_mode!r} is not understood, allowed values: {', '.join(FORCE_MODES)}")
        _check_data(data)
        if model is not None:
            if hoop is not None and bool(hoop) != (model.hoop is not None):
                does = "predicts" if model.hoop else "does not predict"
                raise ValueError(f"hoop={hoop} but the model {does} the hoop gauge")
            hoop = model.hoop is not None
        elif hoop is None:
            hoop = data.hoop is not None and data.sd_hoop is not None
        if model is None:
            model = ClosedFormModel(data, hoop=bool(hoop), axial_poisson=axial_poisson)
        self.data = data
        self.model = model
        self.force = (LevelForceTerm(data, model_form=ratio_model_form) if force_mode == "level"
                      else ForceTerm(data))
        self.force_mode = force_mode
        self.hoop = (HoopTerm(data, prediction=model.hoop, mode=hoop_mode, discrepancy=hoop_discrepancy)
                     if hoop else None)
        self.parameters = model.parameters
        self.hoop_mode = hoop_mode

    @property
    def names(self) -> tuple[str, ...]:
        return self.parameters.names

    def _values(self, theta: np.ndarray) -> dict[str, np.ndarray]:
        return self.parameters.as_dict(np.atleast_2d(np.asarray(theta, float)))

    @property
    def has_hoop(self) -> bool:
        return self.hoop is not None

    def ratio(self, theta: np.ndarray) -> np.ndarray:
        """r = F_eo/F_io = expm1(f beta(nu)) per parameter vector (eq. 5 and 13), shape theta.shape[:-1]."""
        return self.model.ratio(self.parameters.as_dict(np.asarray(theta, float)))

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        """Total log-likelihood.

        Parameters
        ----------
        theta : array, shape (nwalkers, ndim)
            Rows (f, nu[, hoop_gain]) inside 0 <= f, 0 < nu < 0.5, g > 0 (not checked: the prior's job).

        Returns
        -------
        array, shape (nwalkers,); -inf where the model overflows (f beta beyond ~700).
        """
        v = self._values(theta)
        with np.errstate(over="ignore", invalid="ignore"):  # far-out proposals (f beta > 700) overflow
            out = self.force.loglike(self.model.ratio(v))
            if self.hoop is not None:
                out = out + self.hoop.loglike(v["f"], v["nu"], v["hoop_gain"])
        return np.where(np.isfinite(out), out, -np.inf)

    def pointwise(self, theta: np.ndarray, *, segment: int | None = None) -> dict[str, np.ndarray]:
        """Log-likelihood per sample time (or per segment of ``segment`` consecutive samples).

        Keys "F_eo" (the force term: F_eo given F_io) and "hoop" (with the hoop term). Values have
        shape (ndraw, n) or (ndraw, ceil(n / segment)) (the "level" hoop term: (ndraw, 1), one
        observation); per draw they sum to :meth:`__call__`.
        The AR(1) conditionals make the per-time split exact.
        """
        v = self._values(theta)
        out = {"F_eo": self.force.pointwise(self.model.ratio(v))}
        if self.hoop is not None:
            out["hoop"] = self.hoop.pointwise(v["f"], v["nu"], v["hoop_gain"])
        if segment is not None:
            idx = np.arange(0, self.data.n, segment)
            out = {k: np.add.reduceat(v, idx, axis=-1) if v.shape[-1] == self.data.n else v for k, v in out.items()}
        return out

    def simulate(self, theta: np.ndarray, *, rng: np.random.Generator, hoop: bool = True) -> dict[str, np.ndarray]:
        """Replicated data (posterior predictive) for parameter vectors, with AR(1) noise.

        True F_io(t) is taken as the latent estimate given r; F_eo = r F_io (eq. 5, 13). Each
        replicate and channel also gets a constant offset error of the data's ``sd_offset_*``. In the
        "level" force mode each replicate's ratio is also r (1 + delta eta), eta standard normal and
        delta the term's model-form sd (:mod:`.force_level`), drawn after every other number so that
        the noise is the same draw with or without it.
        ``hoop=False``: the forces only (the same draws as a likelihood without the hoop term).

        Returns
        -------
        dict
            "F_io", "F_eo" (N) and, with the hoop term, "hoop" (strain), each shape (ndraw, n).
        """
        v = self._values(theta)
        r = self.model.ratio(v)
        x = self.force.latent_internal_force(r)
        d = self.data
        shape = x.shape
        fo = self.force
        out = {
            "F_io": x + ar1_noise(shape, sd=d.sd_io, rho=d.rho_io, rng=rng)
            + rng.normal(0.0, math.sqrt(fo.var_offset_io), (len(x), 1)),
            "F_eo": r[:, None] * x + ar1_noise(shape, sd=d.sd_eo, rho=d.rho_eo, rng=rng)
            + rng.normal(0.0, math.sqrt(fo.var_offset_eo), (len(x), 1)),
        }
        if self.hoop is not None and hoop:
            pred = self.hoop.predict(v["f"], v["nu"], v["hoop_gain"])
            out["hoop"] = pred + ar1_noise(shape, sd=self.hoop.sd, rho=self.hoop.rho, rng=rng) \
                + rng.normal(0.0, self.hoop.offset, (len(x), 1))
        delta = getattr(fo, "model_form", 0.0)
        if delta > 0.0:
            out["F_eo"] = out["F_eo"] + (delta * r * rng.standard_normal(len(x)))[:, None] * x
        return out
