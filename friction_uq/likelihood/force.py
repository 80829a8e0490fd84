"""Force term of the likelihood: eq. 17 with errors in variables and AR(1) noise.

In the stationary phase eq. 5 and 13 give F_eo = r F_io with r = exp(f beta(nu)) - 1 (the closed
form's ratio, :meth:`friction_uq.models.ClosedFormModel.ratio`). Both forces are measured with
noise: F_io(t) = x(t) + e_io(t), F_eo(t) = r x(t) + e_eo(t), x(t) the unknown true internal force.
Integrating x(t) out under a flat prior leaves exactly (effective-variance method; the Jacobian
factors cancel)

    u(t) = F_eo(t) - r F_io(t) = e_eo(t) - r e_io(t),   Var u = sd_eo^2 + r^2 sd_io^2,

so neither force is treated as exact. The noise of each force is measured on its bar's pre-pulse
segment, the only part of the record where the true signal is known to be zero; inside the window
the true signal is unknown, so residual scatter there would mix noise with model misfit. Each
channel's noise is AR(1) (coefficients rho_io, rho_eo from the same segment). u is a sum of two
AR(1) processes, which is AR(1) only when rho_io = rho_eo; we use the exact AR(1) likelihood with
the variance-weighted coefficient

    rho_u(r) = (rho_eo sd_eo^2 + r^2 rho_io sd_io^2) / (sd_eo^2 + r^2 sd_io^2),

which reproduces u's variance and lag-1 autocorrelation exactly (exact when rho_io = rho_eo).
The AR(1) log-likelihood of u is a quadratic form in r, so it is evaluated from lag-0 and lag-1
sums precomputed once (no pass over the samples per parameter vector): the fast path for a
constant ratio.

Offset errors. Each channel's offset is removed with the mean of the same pre-pulse segment, which
is itself uncertain: the error delta is constant over the window, with sd
sd_offset = sd sqrt((1 + rho) / ((1 - rho) n_baseline)) (AR(1) mean of n_baseline samples). With
n_baseline ~ n_window it is as large as the noise of the window mean, and ignoring it makes the
posterior of kappa overconfident (SBC through whole records: 67 % coverage of 90 % intervals). It
is integrated out exactly: u gets the extra constant delta_eo - r delta_io, a rank-one term
c^2 1 1' with c^2 = sd_offset_eo^2 + r^2 sd_offset_io^2 added to the AR(1) covariance (matrix
determinant lemma and Sherman-Morrison, again from precomputed sums). The offset sds are read from
the data's ``sd_offset_io``, ``sd_offset_eo`` (0 when the data do not carry them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..window import StationaryData
from ..stats.ar1 import LOG_2PI as _LOG_2PI, ar1_offset_correction, ar1_pointwise


@dataclass(frozen=True)
class _Quadratic:
    """Coefficients of c0 - 2 c1 d + c2 d^2 (a sum over t of products of u = a - d b)."""

    c0: float
    c1: float
    c2: float

    def __call__(self, d: np.ndarray) -> np.ndarray:
        return self.c0 - 2.0 * self.c1 * d + self.c2 * d * d


class ForceTerm:
    """Effective-variance AR(1) log-likelihood of the force ratio r = F_eo / F_io (module docstring).

    Parameters
    ----------
    data : StationaryData
        F_io, F_eo (N), their noise sd (N) and AR(1) coefficients.
    """

    mode = "series"

    def __init__(self, data: StationaryData) -> None:
        a = np.asarray(data.F_eo, float)
        b = np.asarray(data.F_io, float)
        self.n = len(a)
        self.var_eo = float(data.sd_eo) ** 2
        self.var_io = float(data.sd_io) ** 2
        self.rho_eo = float(data.rho_eo)
        self.rho_io = float(data.rho_io)
        self.F_eo, self.F_io = a, b
        # centre on the least-squares ratio so the sums are of residual size (no cancellation)
        self.r0 = float(np.dot(a, b) / np.dot(b, b))
        a0 = a - self.r0 * b
        self._s0 = _Quadratic(float(a0 @ a0), float(a0 @ b), float(b @ b))
        self._s1 = _Quadratic(float(a0[1:] @ a0[:-1]), 0.5 * float(a0[1:] @ b[:-1] + b[1:] @ a0[:-1]), float(b[1:] @ b[:-1]))
        self._e1 = _Quadratic(float(a0[0] ** 2 + a0[-1] ** 2), float(a0[0] * b[0] + a0[-1] * b[-1]), float(b[0] ** 2 + b[-1] ** 2))
        # offset errors (module docstring): u's sum and end values, linear in d = r - r0
        self.var_offset_eo = float(getattr(data, "sd_offset_eo", 0.0) or 0.0) ** 2
        self.var_offset_io = float(getattr(data, "sd_offset_io", 0.0) or 0.0) ** 2
        self._sum = (float(a0.sum()), float(b.sum()))
        self._ends = (float(a0[0] + a0[-1]), float(b[0] + b[-1]))

    def noise(self, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """sd (N) and AR(1) coefficient of u = F_eo - r F_io for ratios ``r`` (any shape)."""
        r2 = np.asarray(r, float) ** 2
        var = self.var_eo + r2 * self.var_io
        rho = (self.rho_eo * self.var_eo + r2 * self.rho_io * self.var_io) / var
        return np.sqrt(var), rho

    def loglike(self, r: np.ndarray) -> np.ndarray:
        """Exact AR(1) log-likelihood of u for each ratio, from the precomputed sums. Shape of ``r``."""
        r = np.asarray(r, float)
        sd, rho = self.noise(r)
        var = sd**2
        d = r - self.r0
        one = 1.0 - rho**2
        # (1-rho^2) u_1^2 + sum_{t>=2}(u_t - rho u_{t-1})^2 = (1+rho^2) S0 - rho^2 (u_1^2 + u_n^2) - 2 rho S1
        q = (1.0 + rho**2) * self._s0(d) - rho**2 * self._e1(d) - 2.0 * rho * self._s1(d)
        n = self.n
        out = -0.5 * n * (_LOG_2PI + np.log(var)) - 0.5 * (n - 1) * np.log(one) - q / (2.0 * var * one)
        if self.var_offset_eo or self.var_offset_io:
            out = out + ar1_offset_correction(
                self._sum[0] - d * self._sum[1], self._ends[0] - d * self._ends[1], n=n, sd=sd, rho=rho,
                offset=self.offset(r),
            )
        return out

    def offset(self, r: np.ndarray) -> np.ndarray:
        """sd (N) of the constant offset error of u = F_eo - r F_io: sqrt(sd_off_eo^2 + r^2 sd_off_io^2)."""
        return np.sqrt(self.var_offset_eo + np.asarray(r, float) ** 2 * self.var_offset_io)

    def residuals(self, r: np.ndarray) -> np.ndarray:
        """u(t) = F_eo(t) - r F_io(t), shape r.shape + (n,) (N)."""
        return self.F_eo - np.asarray(r, float)[..., None] * self.F_io

    def pointwise(self, r: np.ndarray) -> np.ndarray:
        """Per-sample conditional log densities, shape r.shape + (n,); they sum to :meth:`loglike`."""
        sd, rho = self.noise(r)
        return ar1_pointwise(self.residuals(r), sd, rho, self.offset(r))

    def latent_internal_force(self, r: np.ndarray) -> np.ndarray:
        """Estimate of the true F_io(t) given r (white-noise effective-variance weights), shape r.shape + (n,) (N).

        x_hat = (F_io / sd_io^2 + r F_eo / sd_eo^2) / (1 / sd_io^2 + r^2 / sd_eo^2).
        """
        r = np.asarray(r, float)[..., None]
        w_io, w_eo = 1.0 / self.var_io, 1.0 / self.var_eo
        return (w_io * self.F_io + w_eo * r * self.F_eo) / (w_io + w_eo * r * r)
