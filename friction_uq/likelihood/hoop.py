"""Hoop term of the likelihood: the tube gauge against the closed form's hoop prediction
(:class:`friction_uq.models.closed_form.HoopPrediction`, docs/physics.md section 6).

Noise: the hoop channel's pre-pulse sd and AR(1) coefficient, exact AR(1) likelihood; the offset
error of the baseline (``sd_offset_hoop`` of the data, 0 when absent) is integrated out.

Caveat: the hoop signal is ~75 noise sds per sample over ~2000 samples, so the term also reads
nu from the *shape* of the reading (the Poisson term scales with g, the pressure term with
g nu/(1-nu)). A shape error of the model that the noise does not describe biases nu: a 0.4 %
position-dependent mismatch (gauge-width averaging on in the model, off in the generator) moved
nu by ~1 posterior sd in a simulation-based calibration. The kernel itself is only good to 2.4 %
of its peak, so on real records a model-discrepancy term (or a wider g prior) is advisable.

Level, not series (default). The hoop reading is ~75 noise standard deviations per sample, so
the per-sample ("series") likelihood reads parameters off the *shape* of the signal as the gauge
slides past the pressure band. That shape carries no information on nu that the forces lack (it
depends on f beta = 2 kappa L / R); only the small axial Poisson term is not scaled by nu/(1-nu),
and a shape error of a few percent in the kernel (fitted to 2.4 %) then drives g and nu far from
the truth (seen on simulated records at 14 m/s: g = 2, nu = 0.24 for a true 1, 0.4). The "level"
mode compares the window mean of the reading with the window mean of the model, with sd^2 =
sd^2 tau / n (AR(1) noise of the mean) + sd_offset^2 + (discrepancy x model mean)^2. It gives g
nu/(1-nu) to the precision of the model (3 %) and the gain prior, which is what the gauge can
honestly say.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SignalError
from ..models.closed_form import HoopPrediction
from ..physics import tube
from ..window import StationaryData
from ..stats.ar1 import LOG_2PI as _LOG_2PI, ar1_innovations, ar1_offset_correction, ar1_pointwise

#: How the hoop reading enters the likelihood (HoopTerm).
HOOP_MODES = ("level", "series")
#: Relative standard deviation of the hoop model's error on the level: the kernel's fit of the
#: exact tube solution (2.4 % of peak, docs/physics.md section 6) and the local axial-force
#: approximation of the Poisson term.
HOOP_DISCREPANCY = 0.03


class HoopTerm:
    """AR(1) log-likelihood of the hoop reading against the closed form's prediction (module docstring).

    With the interpolated prediction pred = Phi c (Phi the (n, m) hat basis of the prediction's
    knots, c the knot values) the AR(1) quadratic form is
    |D(h - Phi c)|^2 = |Dh|^2 - 2 c.(D Phi)'Dh + c'(D Phi)'(D Phi)c, D the AR(1) innovation
    operator, so a parameter vector costs O(m^2), not O(n).

    Parameters
    ----------
    data : StationaryData
        Needs ``hoop``, ``sd_hoop``, ``rho_hoop``; uses ``slip``, ``F_io``, ``tube``.
    prediction : HoopPrediction or None
        The closed form's hoop prediction over ``data``; None: built here from the options below.
    axial_poisson, smooth, knot_step, gauge_averaging, n_nodes, kernel_beta
        Options of :class:`~friction_uq.models.closed_form.HoopPrediction` (when it is built here).
    mode : {"level", "series"}
        "level" (default): the window mean of the reading against the window mean of the model,
        with the model's relative ``discrepancy`` as an extra standard deviation; "series": every
        sample, exact AR(1) (see the module docstring for why "level" is the default).
    discrepancy : float
        Relative standard deviation of the model's error on the level (default 3 %).
    """

    def __init__(
        self, data: StationaryData, *, prediction: HoopPrediction | None = None, axial_poisson: bool = True,
        smooth: float = 10e-6, knot_step: float = 4e-6, gauge_averaging: bool = True, n_nodes: int = 16,
        kernel_beta: float = tube.BETA_EFF_PAPER_TUBE, mode: str = "level", discrepancy: float = HOOP_DISCREPANCY,
    ) -> None:
        if mode not in HOOP_MODES:
            raise ValueError(f"hoop mode {mode!r} is not understood, allowed values: {', '.join(HOOP_MODES)}")
        self.mode = mode
        self.discrepancy = float(discrepancy)
        if data.hoop is None or data.sd_hoop is None or data.rho_hoop is None:
            raise SignalError("hoop term requested but the data have no tube_hoop channel (or no noise estimate for it)")
        if not (data.sd_hoop > 0.0 and -1.0 < data.rho_hoop < 1.0):
            raise SignalError(f"hoop noise must have sd > 0 and |rho| < 1, got sd={data.sd_hoop!r}, rho={data.rho_hoop!r}")
        if prediction is None:
            prediction = HoopPrediction(data, axial_poisson=axial_poisson, smooth=smooth, knot_step=knot_step,
                                        gauge_averaging=gauge_averaging, n_nodes=n_nodes, kernel_beta=kernel_beta)
        self.prediction = prediction
        n = data.n
        self.observed = np.asarray(data.hoop, float)
        self.sd = float(data.sd_hoop)
        self.rho = float(data.rho_hoop)
        self.knots = prediction.knots
        basis = prediction.basis

        # AR(1) innovations of the data and of the basis
        dh = ar1_innovations(self.observed, self.rho)
        dphi = ar1_innovations(basis.T, self.rho).T  # (n, m)
        self._hh = float(dh @ dh)
        self._hb = dphi.T @ dh  # (m,)
        self._bb = dphi.T @ dphi  # (m, m)
        self._n = n
        self.offset = float(getattr(data, "sd_offset_hoop", 0.0) or 0.0)
        self._h_sum, self._h_ends = float(self.observed.sum()), float(self.observed[0] + self.observed[-1])
        self._b_sum = basis.sum(axis=0)
        self._b_ends = basis[0] + basis[-1]
        one = 1.0 - self.rho**2
        self._scale = 2.0 * self.sd**2 * one
        self._const = -0.5 * n * (_LOG_2PI + math.log(self.sd**2)) - 0.5 * (n - 1) * math.log(one)

    def predict_knots(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Predicted hoop reading at the knots, shape (len(f), m) (:meth:`HoopPrediction.predict_knots`)."""
        return self.prediction.predict_knots(f, nu, gain)

    def predict(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Predicted hoop reading at every sample, shape (len(f), n) (:meth:`HoopPrediction.predict`)."""
        return self.prediction.predict(f, nu, gain)

    def level_sd(self, predicted_mean: np.ndarray) -> np.ndarray:
        """Standard deviation of (observed - predicted) window means: noise, offset, model discrepancy."""
        tau = (1.0 + self.rho) / (1.0 - self.rho)
        return np.sqrt(self.sd**2 * tau / self._n + self.offset**2 + (self.discrepancy * predicted_mean) ** 2)

    def loglike(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Log-likelihood of the hoop reading, shape (len(f),): level or series (class docstring).

        "series": exact AR(1) log-likelihood of the residuals, offset error integrated out.
        """
        if self.mode == "level":
            mean_pred = self.prediction.predict_weighted(f, nu, gain, self._b_sum / self._n)
            sd = self.level_sd(mean_pred)
            z = (self._h_sum / self._n - mean_pred) / sd
            return -0.5 * (_LOG_2PI + z * z) - np.log(sd)
        c = self.predict_knots(f, nu, gain)
        q = self._hh - 2.0 * (c @ self._hb) + np.einsum("wi,wi->w", c @ self._bb, c)
        out = self._const - q / self._scale
        if self.offset > 0.0:
            out = out + ar1_offset_correction(self._h_sum - c @ self._b_sum, self._h_ends - c @ self._b_ends,
                                              n=self._n, sd=self.sd, rho=self.rho, offset=self.offset)
        return out

    def pointwise(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Per-sample conditional log densities, shape (len(f), n); in "level" mode the one
        observation (the window mean), shape (len(f), 1)."""
        if self.mode == "level":
            return self.loglike(f, nu, gain)[:, None]
        return ar1_pointwise(self.observed - self.predict(f, nu, gain), self.sd, self.rho, self.offset)
