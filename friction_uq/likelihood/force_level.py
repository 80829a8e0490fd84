"""Force term of the likelihood by levels: eq. 17 from the window means of the two output forces.

Why levels. In the stationary phase eq. 5 and 13 say that the *levels* of the forces obey
F_eo = r F_io, r = exp(f beta(nu)) - 1. The sample-by-sample term (:mod:`.force`) also reads r off
how F_eo follows F_io from one sample to the next, with the pre-pulse noise as the only error.
When the record fluctuates in a way the model does not describe (stick-slip on the wall, a
clearance closing, a ringing the 1-D model lacks) that covariation is not r: on a stick-slip
record F_io oscillates and F_eo does not share the oscillation, and the series term followed the
oscillation (ratio 0.040 where the window means give 0.144). Here the data are the window means.

The model. Cut the window into ``B`` contiguous batches (8 by default) and let a_b, x_b be the batch
means of F_eo and F_io. With u_b(r) = a_b - r x_b, the window's level equation is
u_bar(r) = mean(F_eo) - r mean(F_io) = 0 up to errors, and the standard error of u_bar is taken
from the spread of the batch means (non-overlapping batch means, the long-run variance of the
window mean; Schmeiser 1982, fixed-b asymptotics: u_bar / se is Student-t with B - 1 degrees of
freedom whatever the correlation inside the batches, provided the batches are long against it):

    se_batch(r)^2 = sum_b (u_b - u_bar)^2 / (B (B - 1)),

so fluctuations the model does not describe widen the interval instead of moving r. The constant
offset error of each channel's baseline (the pre-pulse mean, the same in every batch, so invisible
to the spread) is added:

    s(r)^2 = se_batch(r)^2 + sd_off_eo^2 + r^2 sd_off_io^2,
    log L(r) = log t_{B-1}(u_bar(r) / s(r)) - log s(r).

No floor. The noise model's own standard error of u_bar (AR(1) pre-pulse noise of both channels,
:func:`friction_uq.stats.ar1.ar1_mean_sd`) is not used as a lower bound on se_batch: the t with B - 1
degrees of freedom already pays for a batch spread that is small by chance, and flooring it made the
90 % interval of the ratio cover 0.97 of records that are the model plus its noise (a scale mixture
over the posterior of the variance truncated at the noise level; simulation-based calibration,
tests/test_sbc.py), where the t covers 0.90 whatever the true variance (docs/trust.md). The noise
model's standard error stays as the yardstick of :meth:`LevelForceTerm.excess_spread`.

Model form. Eq. 17 is a 1-D closed form (uniform stresses over the section, the lateral ratio
nu/(1 - nu) everywhere). A test that has none of these assumptions (the axisymmetric simulation,
docs/axisymmetric.md; a real cell) makes a level ratio a few per cent off the closed form's at the
true kappa, where the window mean's standard error is 0.3-0.5 %: without a term for it kappa's 90 %
interval held the truth on 2 of 16 clean axisymmetric records. The ratio of the world is taken as
r (1 + delta eta), eta standard normal, delta = :data:`RATIO_MODEL_FORM`; in u_bar that is a
standard deviation delta r mean(F_io), added to s(r)^2:

    s(r)^2 = se_batch(r)^2 + sd_off_eo^2 + r^2 sd_off_io^2 + (delta r mean(F_io))^2.

delta is the root mean square of the ratio's error on clean axisymmetric records
(``benchmarks/bench_model_form.py``, docs/trust.md), not on the records that check it. The
likelihood's generative model (:meth:`friction_uq.likelihood.Likelihood.simulate`) draws the same
term, so a simulation-based calibration covers what the analysis assumes.

The 1 / s(r) factor makes L the density of u_bar, so r's interval is the t interval of the mean
ratio (errors in both forces: u_bar(r) carries both). All terms are quadratics in r precomputed from
batch sums, so a parameter vector costs O(1).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaln

from ..stats.ar1 import ar1_mean_sd
from ..window import StationaryData

#: Relative standard deviation of eq. 17's ratio against a test it did not make (module docstring): the root
#: mean square of the level ratio's error on 40 clean records of the axisymmetric simulation, 2.47 %
#: (mean -2.41 %, sd 0.55 %, largest 3.54 %; ``benchmarks/bench_model_form.py``, seed 11; docs/trust.md).
#: Zero-mean: a real cell's error need not have the axisymmetric simulation's sign.
RATIO_MODEL_FORM = 0.025
#: Number of batches of the window (Student-t with BATCHES - 1 degrees of freedom).
BATCHES = 8
#: Fewest samples per batch: shorter windows use fewer batches (at least 3).
MIN_BATCH_SAMPLES = 8


def batch_count(n: int, batches: int = BATCHES) -> int:
    """Batches for a window of ``n`` samples: ``batches``, fewer when a batch would hold < 8 samples."""
    return int(max(3, min(batches, n // MIN_BATCH_SAMPLES)))


def batch_means(x: np.ndarray, batches: int) -> np.ndarray:
    """Means of ``batches`` contiguous batches of equal length (the last samples that do not fill a
    batch are spread by ``np.array_split``, which keeps every sample)."""
    return np.array([float(np.mean(p)) for p in np.array_split(np.asarray(x, float), batches)])


class LevelForceTerm:
    """Log-likelihood of the force ratio r from the window means (module docstring).

    Parameters
    ----------
    data : StationaryData
        F_io, F_eo (N), their noise sd (N), AR(1) coefficients and offset errors.
    batches : int
        Batches of the window (fewer for short windows, :func:`batch_count`).
    model_form : float
        Relative sd of the closed form's ratio against the world (:data:`RATIO_MODEL_FORM`; 0: none).
    """

    mode = "level"

    def __init__(self, data: StationaryData, *, batches: int = BATCHES, model_form: float = RATIO_MODEL_FORM) -> None:
        if not (math.isfinite(model_form) and 0.0 <= model_form < 1.0):
            raise ValueError(f"the ratio's model-form sd must lie in [0, 1), got {model_form!r}")
        self.model_form = float(model_form)
        a = np.asarray(data.F_eo, float)
        b = np.asarray(data.F_io, float)
        self.n = len(a)
        self.F_eo, self.F_io = a, b
        self.batches = batch_count(self.n, batches)
        self.dof = self.batches - 1
        self.var_eo, self.var_io = float(data.sd_eo) ** 2, float(data.sd_io) ** 2
        self.rho_eo, self.rho_io = float(data.rho_eo), float(data.rho_io)
        self.var_offset_eo = float(getattr(data, "sd_offset_eo", 0.0) or 0.0) ** 2
        self.var_offset_io = float(getattr(data, "sd_offset_io", 0.0) or 0.0) ** 2
        self.mean_eo, self.mean_io = float(a.mean()), float(b.mean())
        self.r0 = self.mean_eo / self.mean_io  # the ratio of the levels (eq. 17's reading)
        bm_eo, bm_io = batch_means(a, self.batches), batch_means(b, self.batches)
        da, dx = bm_eo - bm_eo.mean(), bm_io - bm_io.mean()
        k = self.batches * (self.batches - 1)
        self._saa, self._sax, self._sxx = float(da @ da) / k, float(da @ dx) / k, float(dx @ dx) / k
        # noise model: variance of the window mean of each channel (AR(1), exact sum)
        self._mv_eo = ar1_mean_sd(math.sqrt(self.var_eo), self.rho_eo, self.n) ** 2
        self._mv_io = ar1_mean_sd(math.sqrt(self.var_io), self.rho_io, self.n) ** 2
        self._const = float(gammaln((self.dof + 1) / 2) - gammaln(self.dof / 2) - 0.5 * math.log(self.dof * math.pi))

    def se_batch(self, r: np.ndarray) -> np.ndarray:
        """Standard error of the window mean of u = F_eo - r F_io from the batch means (N)."""
        r = np.asarray(r, float)
        return np.sqrt(np.maximum(self._saa - 2.0 * r * self._sax + r * r * self._sxx, 0.0))

    def se_noise(self, r: np.ndarray) -> np.ndarray:
        """Standard error of the window mean of u under the pre-pulse AR(1) noise model (N)."""
        r = np.asarray(r, float)
        return np.sqrt(self._mv_eo + r * r * self._mv_io)

    def offset(self, r: np.ndarray) -> np.ndarray:
        """sd (N) of the constant offset error of u: sqrt(sd_off_eo^2 + r^2 sd_off_io^2)."""
        return np.sqrt(self.var_offset_eo + np.asarray(r, float) ** 2 * self.var_offset_io)

    def model_form_sd(self, r: np.ndarray) -> np.ndarray:
        """sd (N) of u_bar from the closed form's model-form error: delta r mean(F_io)."""
        return self.model_form * np.asarray(r, float) * self.mean_io

    def scale(self, r: np.ndarray) -> np.ndarray:
        """s(r): the standard error of u_bar(r) the likelihood uses (N)."""
        return np.sqrt(self.se_batch(r) ** 2 + self.offset(r) ** 2 + self.model_form_sd(r) ** 2)

    def excess_spread(self) -> float:
        """se_batch / se_noise at the level ratio: how much more the window's level wanders than the
        gauges' noise allows (about 1 when the model describes the window; chi-square with B - 1
        degrees of freedom in its square)."""
        return float(self.se_batch(self.r0) / self.se_noise(self.r0))

    def loglike(self, r: np.ndarray) -> np.ndarray:
        """log t_{B-1}(u_bar / s) - log s for each ratio; shape of ``r``."""
        r = np.asarray(r, float)
        s = self.scale(r)
        z = (self.mean_eo - r * self.mean_io) / s
        return self._const - np.log(s) - 0.5 * (self.dof + 1) * np.log1p(z * z / self.dof)

    def pointwise(self, r: np.ndarray) -> np.ndarray:
        """The one observation (the window level), shape r.shape + (1,)."""
        return self.loglike(r)[..., None]

    def residuals(self, r: np.ndarray) -> np.ndarray:
        """u(t) = F_eo(t) - r F_io(t), shape r.shape + (n,) (N)."""
        return self.F_eo - np.asarray(r, float)[..., None] * self.F_io

    def latent_internal_force(self, r: np.ndarray) -> np.ndarray:
        """Estimate of the true F_io(t) given r (white-noise effective-variance weights), shape r.shape + (n,) (N)."""
        r = np.asarray(r, float)[..., None]
        w_io, w_eo = 1.0 / self.var_io, 1.0 / self.var_eo
        return (w_io * self.F_io + w_eo * r * self.F_eo) / (w_io + w_eo * r * r)
