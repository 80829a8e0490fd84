"""Likelihood of the friction coefficient f, the sample Poisson ratio nu (and the hoop-gauge factor g).

Data: a :class:`~friction_uq.window.StationaryData` (the stationary phase of one test).

Force term (eq. 17, errors in variables)
----------------------------------------
In the stationary phase eq. 5 and 13 give F_eo = r F_io with r = exp(f beta(nu)) - 1. Both forces
are measured with noise: F_io(t) = x(t) + e_io(t), F_eo(t) = r x(t) + e_eo(t), x(t) the unknown
true internal force. Integrating x(t) out under a flat prior leaves exactly (effective-variance
method; the Jacobian factors cancel)

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
sums precomputed once (no pass over the samples per parameter vector).

Offset errors. Each channel's offset is removed with the mean of the same pre-pulse segment, which
is itself uncertain: the error delta is constant over the window, with sd
sd_offset = sd sqrt((1 + rho) / ((1 - rho) n_baseline)) (AR(1) mean of n_baseline samples). With
n_baseline ~ n_window it is as large as the noise of the window mean, and ignoring it makes the
posterior of kappa overconfident (SBC through whole records: 67 % coverage of 90 % intervals). It
is integrated out exactly: u gets the extra constant delta_eo - r delta_io, a rank-one term
c^2 1 1' with c^2 = sd_offset_eo^2 + r^2 sd_offset_io^2 added to the AR(1) covariance (matrix
determinant lemma and Sherman-Morrison, again from precomputed sums), and the same for the hoop
gauge. The offset sds are read from the data's ``sd_offset_io``, ``sd_offset_eo``,
``sd_offset_hoop`` (0 when the data do not carry them).

Hoop term (physics.md section 6)
--------------------------------
The tube gauge reads (package convention, compression positive, so negative while swelling)

    h(t) = -g [ Lame * integral_{-L/2}^{L/2} p(s, t) K_w(z_g(t) - s) ds + nu_t N(z_g(t), t) / (E_t A_t) ]

with Lame = 2 a^2 / (E_t (b^2 - a^2)); s the position from the sample's middle, positive toward the
output side; z_g(t) = gauge_offset - slip(t) the gauge's position (the sample slides toward the
output side, so the gauge moves toward the input face); K_w the tube kernel K averaged over the gauge's
width (a strain gauge reads the mean strain under its grid; ``gauge_averaging=False`` gives the
point gauge of physics.md section 6, ~0.4 % higher, well inside the kernel's own 2.4 % fit error;
the simulator and the closed-form records average too); p(s, t) the eq. 20 wall
pressure, written as p = nu/(1-nu) sigma(z) (eq. 8) with sigma(z) = F_io(t) e^{f beta (L - z)/L} / (pi R^2) from eq. 11-13 (z = s + L/2), identical to
eq. 20 and regular at f = 0. F_io(t) is the observed internal force smoothed over ``smooth``
(10 us): its noise (~0.2 % per sample, less after smoothing) is negligible beside the hoop noise.

Axial Poisson term, sign choice: the tube rests on the external output bar at its output end, so
friction puts the tube section at s in axial compression N(s) = friction force on the wall between
the input face and s, N = F_io e^{fb (1/2 - s/L)} (e^{fb (s/L + 1/2)} - 1) for |s| < L/2, 0 on the
input side, F_eo on the output side (fb = f beta). Axial compression widens the tube (physical hoop
strain + nu_t N / (E_t A_t), the "+19 microstrain for 5 kN" of physics.md), the same direction as
the pressure term, so in the package's convention both terms enter with the minus sign above. The
local N at the gauge is used (no Saint-Venant spreading), an approximation for a term ~4 % of the
reading. g, the calibration factor, scales the whole reading. Noise: the hoop channel's pre-pulse
sd and AR(1) coefficient, exact AR(1) likelihood.

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

Parameter vectors are rows (f, nu) or (f, nu, hoop_gain); SI units, forces in N, strains in
strain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from .errors import SignalError
from .noise import ar1_noise
from .physics import cell, tube
from .signals import ar1_mean_sd
from .window import StationaryData

#: Parameter names without / with the hoop term.
FORCE_PARAMETERS = ("f", "nu")
HOOP_PARAMETERS = ("f", "nu", "hoop_gain")

_LOG_2PI = math.log(2.0 * math.pi)

#: How the hoop reading enters the likelihood (HoopTerm).
HOOP_MODES = ("level", "series")
#: Relative standard deviation of the hoop model's error on the level: the kernel's fit of the
#: exact tube solution (2.4 % of peak, physics.md section 6) and the local axial-force
#: approximation of the Poisson term.
HOOP_DISCREPANCY = 0.03


# ----------------------------------------------------------------------------------------------
# AR(1) Gaussian noise
# ----------------------------------------------------------------------------------------------


def ar1_pointwise(
    resid: np.ndarray, sd: np.ndarray | float, rho: np.ndarray | float, offset: np.ndarray | float = 0.0,
) -> np.ndarray:
    """Conditional log densities of a stationary AR(1) Gaussian series; they sum to the exact log-likelihood.

    Parameters
    ----------
    resid : array, shape (..., n)
        Residuals, time along the last axis.
    sd : float or array broadcastable to shape (...,)
        Marginal standard deviation of the noise (same unit as ``resid``).
    rho : float or array broadcastable to shape (...,)
        Lag-1 coefficient, |rho| < 1.
    offset : float or array broadcastable to shape (...,)
        Standard deviation of an unknown constant added to the series (integrated out); 0: none.

    Returns
    -------
    array, shape (..., n)
        log p(e_1) = log N(e_1; 0, sd^2) and log p(e_t | e_{t-1}) = log N(e_t; rho e_{t-1}, sd^2 (1 - rho^2))
        (with an offset: the conditionals given all earlier samples).
    """
    resid = np.asarray(resid, float)
    sd = np.asarray(sd, float)
    rho = np.asarray(rho, float)
    offset = np.asarray(offset, float)
    if np.any(offset > 0.0):
        shape = resid.shape[:-1]
        return _offset_pointwise_shift(resid, np.broadcast_to(sd, shape), np.broadcast_to(rho, shape),
                                       np.broadcast_to(np.maximum(offset, 1e-150), shape))
    var = sd**2
    var_c = var * (1.0 - rho**2)  # conditional variance of e_t given e_{t-1}
    out = np.empty(np.broadcast_shapes(resid.shape, sd.shape + (1,), rho.shape + (1,)))
    out[..., 0] = -0.5 * (_LOG_2PI + np.log(var) + resid[..., 0] ** 2 / var)
    innov = resid[..., 1:] - rho[..., None] * resid[..., :-1]
    innov *= innov
    innov /= -2.0 * var_c[..., None]
    innov += (-0.5 * (_LOG_2PI + np.log(var_c)))[..., None]
    out[..., 1:] = innov
    return out


def ar1_loglike(
    resid: np.ndarray, sd: np.ndarray | float, rho: np.ndarray | float, offset: np.ndarray | float = 0.0,
) -> np.ndarray:
    """Exact log-likelihood of a stationary AR(1) Gaussian series along the last axis.

    log L = -n/2 log(2 pi sd^2) - (n-1)/2 log(1 - rho^2)
            - [(1 - rho^2) e_1^2 + sum_{t>=2} (e_t - rho e_{t-1})^2] / (2 sd^2 (1 - rho^2)).

    Shapes and ``offset`` as :func:`ar1_pointwise`; returns shape (...,). With an offset, adds
    :func:`ar1_offset_correction`.
    """
    resid = np.asarray(resid, float)
    sd = np.asarray(sd, float)
    rho = np.asarray(rho, float)
    n = resid.shape[-1]
    one = 1.0 - rho**2
    d = resid[..., 1:] - rho[..., None] * resid[..., :-1]
    q = one * resid[..., 0] ** 2 + np.sum(d * d, axis=-1)
    out = -0.5 * n * (_LOG_2PI + np.log(sd**2)) - 0.5 * (n - 1) * np.log(one) - q / (2.0 * sd**2 * one)
    if np.any(np.asarray(offset) > 0.0):
        out = out + ar1_offset_correction(resid.sum(-1), resid[..., 0] + resid[..., -1], n=n, sd=sd, rho=rho, offset=offset)
    return out


def offset_sd(sd: float, rho: float, n_baseline: int) -> float:
    """Standard deviation of the mean of ``n_baseline`` AR(1) samples: the error of an offset removed
    with the mean of a pre-pulse segment (:func:`friction_uq.signals.ar1_mean_sd`)."""
    return ar1_mean_sd(sd, rho, n_baseline)


def ar1_offset_correction(
    sum_u: np.ndarray, ends_u: np.ndarray, *, n: int, sd: np.ndarray | float, rho: np.ndarray | float,
    offset: np.ndarray | float,
) -> np.ndarray:
    """log N(u; 0, S + c^2 1 1') - log N(u; 0, S) for S the AR(1) covariance (sd, rho) and c = ``offset``.

    Needs only sum(u) and u_1 + u_n: with P = S^-1, 1'Pu = [(1-rho)^2 sum(u) + rho(1-rho)(u_1 + u_n)]
    / (sd^2 (1-rho^2)) and 1'P1 = [(1-rho^2) + (n-1)(1-rho)^2] / (sd^2 (1-rho^2)); the correction is
    c^2 (1'Pu)^2 / (2 (1 + c^2 1'P1)) - log(1 + c^2 1'P1) / 2 (Sherman-Morrison, determinant lemma).
    """
    sd, rho, c2 = np.asarray(sd, float), np.asarray(rho, float), np.asarray(offset, float) ** 2
    var_c = sd**2 * (1.0 - rho**2)
    g = ((1.0 - rho) ** 2 * sum_u + rho * (1.0 - rho) * ends_u) / var_c
    h = ((1.0 - rho**2) + (n - 1) * (1.0 - rho) ** 2) / var_c
    return 0.5 * c2 * g * g / (1.0 + c2 * h) - 0.5 * np.log1p(c2 * h)


def _offset_pointwise_shift(resid: np.ndarray, sd: np.ndarray, rho: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Per-sample conditional log densities of u = delta + AR(1), delta ~ N(0, offset^2) (recursive form).

    Innovations eta_1 = u_1 = delta + e_1 (variance sd^2), eta_t = u_t - rho u_{t-1} = (1-rho) delta + w_t
    (variance sd^2 (1-rho^2)): a regression on delta, whose predictive densities follow from
    cumulative sums.
    """
    n = resid.shape[-1]
    var = sd[..., None] ** 2
    var_t = np.concatenate([np.broadcast_to(var, var.shape), np.broadcast_to(var * (1.0 - rho[..., None] ** 2), var.shape[:-1] + (n - 1,))], axis=-1)
    x = np.concatenate([np.ones(var.shape), np.broadcast_to((1.0 - rho[..., None]), var.shape[:-1] + (n - 1,))], axis=-1)
    eta = np.concatenate([resid[..., :1], resid[..., 1:] - rho[..., None] * resid[..., :-1]], axis=-1)
    a = np.cumsum(x * eta / var_t, axis=-1)
    b = 1.0 / offset[..., None] ** 2 + np.cumsum(x * x / var_t, axis=-1)
    a_prev = np.concatenate([np.zeros(var.shape), a[..., :-1]], axis=-1)
    b_prev = np.concatenate([np.broadcast_to(1.0 / offset[..., None] ** 2, var.shape), b[..., :-1]], axis=-1)
    mean = x * a_prev / b_prev
    v = var_t + x * x / b_prev
    return -0.5 * (_LOG_2PI + np.log(v) + (eta - mean) ** 2 / v)


# ----------------------------------------------------------------------------------------------
# Force term
# ----------------------------------------------------------------------------------------------


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


# ----------------------------------------------------------------------------------------------
# Hoop term
# ----------------------------------------------------------------------------------------------


def gauge_kernel(x: np.ndarray, *, gauge_width: float, beta: float = tube.BETA_EFF_PAPER_TUBE) -> np.ndarray:
    """Tube kernel K averaged over a gauge of width ``gauge_width`` centred at ``x`` (1/m).

    Equal to :func:`friction_uq.physics.tube.hoop_kernel` when the width is 0.
    """
    if gauge_width <= 0.0:
        return tube.hoop_kernel(x, beta=beta)
    return tube.band_response(x, band_length=gauge_width, beta=beta) / gauge_width


class HoopTerm:
    """Hoop-gauge prediction and AR(1) log-likelihood (module docstring).

    The prediction is evaluated on knots every ``knot_step`` seconds and interpolated linearly in
    between. It varies on the scale of the slip past the kernel, ~5 mm, against ~40 um of slip per
    4 us knot step, and with the 10 us smoothing of F_io: on the paper's case the interpolated
    prediction is within 0.12 microstrain of the per-sample one (gauge noise ~2 microstrain). With the interpolated prediction
    pred = Phi c (Phi the (n, m) hat basis, c the knot values) the AR(1) quadratic form is
    |D(h - Phi c)|^2 = |Dh|^2 - 2 c.(D Phi)'Dh + c'(D Phi)'(D Phi)c, D the AR(1) innovation
    operator, so a parameter vector costs O(m^2), not O(n).

    Parameters
    ----------
    data : StationaryData
        Needs ``hoop``, ``sd_hoop``, ``rho_hoop``; uses ``slip``, ``F_io``, ``tube``.
    axial_poisson : bool
        Include the tube's axial Poisson term.
    smooth : float
        Moving-average length applied to F_io for the wall pressure (s).
    knot_step : float
        Spacing of the prediction knots (s); 0 puts a knot on every sample.
    gauge_averaging : bool
        Average the kernel over ``tube.gauge_width`` (default; False: point gauge, physics.md section 6).
    n_nodes : int
        Gauss-Legendre nodes over the sample length.
    kernel_beta : float
        Decay rate of the tube kernel (1/m).
    mode : {"level", "series"}
        "level" (default): the window mean of the reading against the window mean of the model,
        with the model's relative ``discrepancy`` as an extra standard deviation; "series": every
        sample, exact AR(1) (see the module docstring for why "level" is the default).
    discrepancy : float
        Relative standard deviation of the model's error on the level (default 3 %).
    """

    def __init__(
        self, data: StationaryData, *, axial_poisson: bool = True, smooth: float = 10e-6, knot_step: float = 4e-6,
        gauge_averaging: bool = True, n_nodes: int = 16, kernel_beta: float = tube.BETA_EFF_PAPER_TUBE,
        mode: str = "level", discrepancy: float = HOOP_DISCREPANCY,
    ) -> None:
        if mode not in HOOP_MODES:
            raise ValueError(f"hoop mode {mode!r} is not understood, allowed values: {', '.join(HOOP_MODES)}")
        self.mode = mode
        self.discrepancy = float(discrepancy)
        if data.hoop is None or data.sd_hoop is None or data.rho_hoop is None:
            raise SignalError("hoop term requested but the data have no tube_hoop channel (or no noise estimate for it)")
        if not (data.sd_hoop > 0.0 and -1.0 < data.rho_hoop < 1.0):
            raise SignalError(f"hoop noise must have sd > 0 and |rho| < 1, got sd={data.sd_hoop!r}, rho={data.rho_hoop!r}")
        tb = data.tube
        R, L = data.radius, data.length
        n = data.n
        self.observed = np.asarray(data.hoop, float)
        self.sd = float(data.sd_hoop)
        self.rho = float(data.rho_hoop)
        self.radius, self.length = R, L
        self.axial_poisson = axial_poisson
        n_smooth = max(1, int(round(smooth * data.sample_rate)))
        F_io = uniform_filter1d(np.asarray(data.F_io, float), n_smooth, mode="nearest")
        z_g = tb.gauge_offset - np.asarray(data.slip, float)
        self.gauge_position = z_g

        step = max(1, int(round(knot_step * data.sample_rate)))
        knots = np.unique(np.append(np.arange(0, n, step), n - 1))
        self.knots = knots
        # hat basis (n, m): linear interpolation between knots
        self._basis = _hat_basis(knots, n)
        self._left = np.clip(np.searchsorted(knots, np.arange(n), side="right") - 1, 0, len(knots) - 2)
        self._w = (np.arange(n) - knots[self._left]) / (knots[self._left + 1] - knots[self._left])
        F_k, z_k = F_io[knots], z_g[knots]

        x, w = np.polynomial.legendre.leggauss(n_nodes)
        self.nodes = 0.5 * L * x  # s, from the sample's middle (m)
        width = tb.gauge_width if gauge_averaging else 0.0
        kern = gauge_kernel(z_k[:, None] - self.nodes[None, :], gauge_width=width, beta=kernel_beta)
        # (n_nodes, m): weight * K_w * Lame * F_io / (pi R^2); pressure term = lat * exp(fb c) @ this
        self._kmat = (0.5 * L * w[:, None]) * kern.T * (F_k / (math.pi * R**2))[None, :] * tb.lame_hoop_strain_per_pressure
        self._c = 0.5 - self.nodes / L
        u = np.clip(z_k, -0.5 * L, 0.5 * L)
        self._pc_a = 0.5 - u / L  # N = F_io e^{fb a} (e^{fb b} - 1)
        self._pc_b = u / L + 0.5
        self._poisson = tb.poisson_ratio * F_k / (tb.young_modulus * tb.area)

        # AR(1) innovations of the data and of the basis
        dh = _innovations(self.observed, self.rho)
        dphi = _innovations(self._basis.T, self.rho).T  # (n, m)
        self._hh = float(dh @ dh)
        self._hb = dphi.T @ dh  # (m,)
        self._bb = dphi.T @ dphi  # (m, m)
        self._n = n
        self.offset = float(getattr(data, "sd_offset_hoop", 0.0) or 0.0)
        self._h_sum, self._h_ends = float(self.observed.sum()), float(self.observed[0] + self.observed[-1])
        self._b_sum = self._basis.sum(axis=0)
        self._b_ends = self._basis[0] + self._basis[-1]
        one = 1.0 - self.rho**2
        self._scale = 2.0 * self.sd**2 * one
        self._const = -0.5 * n * (_LOG_2PI + math.log(self.sd**2)) - 0.5 * (n - 1) * math.log(one)

    def predict_knots(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Predicted hoop reading at the knots, compression positive, shape (len(f), m) (strain)."""
        f, nu, gain = (np.atleast_1d(np.asarray(v, float)) for v in (f, nu, gain))
        lat = cell.lateral_ratio(nu)
        fb = f * cell.beta(nu, radius=self.radius, length=self.length)
        swell = lat[:, None] * (np.exp(fb[:, None] * self._c[None, :]) @ self._kmat)
        if self.axial_poisson:
            axial = np.exp(fb[:, None] * self._pc_a) * np.expm1(fb[:, None] * self._pc_b)
            swell = swell + self._poisson * axial
        return -gain[:, None] * swell

    def predict(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Predicted hoop reading at every sample, shape (len(f), n) (strain).

        ``f``, ``nu``, ``gain`` are 1-d arrays of equal length (or scalars).
        """
        c = self.predict_knots(f, nu, gain)
        return c[:, self._left] * (1.0 - self._w) + c[:, self._left + 1] * self._w

    def level_sd(self, predicted_mean: np.ndarray) -> np.ndarray:
        """Standard deviation of (observed - predicted) window means: noise, offset, model discrepancy."""
        tau = (1.0 + self.rho) / (1.0 - self.rho)
        return np.sqrt(self.sd**2 * tau / self._n + self.offset**2 + (self.discrepancy * predicted_mean) ** 2)

    def loglike(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Log-likelihood of the hoop reading, shape (len(f),): level or series (class docstring).

        "series": exact AR(1) log-likelihood of the residuals, offset error integrated out.
        """
        c = self.predict_knots(f, nu, gain)
        if self.mode == "level":
            mean_pred = (c @ self._b_sum) / self._n
            sd = self.level_sd(mean_pred)
            z = (self._h_sum / self._n - mean_pred) / sd
            return -0.5 * (_LOG_2PI + z * z) - np.log(sd)
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


def _hat_basis(knots: np.ndarray, n: int) -> np.ndarray:
    """(n, m) matrix of linear interpolation from values at sample indices ``knots`` (increasing, from 0 to n-1)."""
    t = np.arange(n)
    k = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2)
    left, right = knots[k], knots[k + 1]
    w = (t - left) / (right - left)
    basis = np.zeros((n, len(knots)))
    basis[t, k] = 1.0 - w
    basis[t, k + 1] += w
    return basis


def _innovations(x: np.ndarray, rho: float) -> np.ndarray:
    """AR(1) innovations along the last axis: sqrt(1 - rho^2) x_1, x_t - rho x_{t-1}."""
    x = np.asarray(x, float)
    out = np.empty_like(x)
    out[..., 0] = math.sqrt(1.0 - rho**2) * x[..., 0]
    out[..., 1:] = x[..., 1:] - rho * x[..., :-1]
    return out


# ----------------------------------------------------------------------------------------------
# The likelihood
# ----------------------------------------------------------------------------------------------


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
    hoop : bool or None
        Include the hoop-gauge term; None: when the data have a hoop channel.
    axial_poisson : bool
        Include the tube's axial Poisson term in the hoop prediction.

    Attributes
    ----------
    names : tuple of str
        Column names of parameter vectors: ("f", "nu") or ("f", "nu", "hoop_gain").
    """

    def __init__(
        self, data: StationaryData, *, hoop: bool | None = None, axial_poisson: bool = True, hoop_mode: str = "level",
    ) -> None:
        _check_data(data)
        if hoop is None:
            hoop = data.hoop is not None and data.sd_hoop is not None
        self.data = data
        self.force = ForceTerm(data)
        self.hoop = HoopTerm(data, axial_poisson=axial_poisson, mode=hoop_mode) if hoop else None
        self.names = HOOP_PARAMETERS if hoop else FORCE_PARAMETERS

    @property
    def has_hoop(self) -> bool:
        return self.hoop is not None

    def ratio(self, theta: np.ndarray) -> np.ndarray:
        """r = F_eo/F_io = expm1(f beta(nu)) per parameter vector (eq. 5 and 13), shape theta.shape[:-1]."""
        theta = np.asarray(theta, float)
        return cell.force_ratio(theta[..., 0], theta[..., 1], radius=self.data.radius, length=self.data.length)

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
        theta = np.atleast_2d(np.asarray(theta, float))
        with np.errstate(over="ignore", invalid="ignore"):  # far-out proposals (f beta > 700) overflow
            out = self.force.loglike(self.ratio(theta))
            if self.hoop is not None:
                out = out + self.hoop.loglike(theta[:, 0], theta[:, 1], theta[:, 2])
        return np.where(np.isfinite(out), out, -np.inf)

    def pointwise(self, theta: np.ndarray, *, segment: int | None = None) -> dict[str, np.ndarray]:
        """Log-likelihood per sample time (or per segment of ``segment`` consecutive samples).

        Keys "F_eo" (the force term: F_eo given F_io) and "hoop" (with the hoop term). Values have
        shape (ndraw, n) or (ndraw, ceil(n / segment)) (the "level" hoop term: (ndraw, 1), one
        observation); per draw they sum to :meth:`__call__`.
        The AR(1) conditionals make the per-time split exact.
        """
        theta = np.atleast_2d(np.asarray(theta, float))
        out = {"F_eo": self.force.pointwise(self.ratio(theta))}
        if self.hoop is not None:
            out["hoop"] = self.hoop.pointwise(theta[:, 0], theta[:, 1], theta[:, 2])
        if segment is not None:
            idx = np.arange(0, self.data.n, segment)
            out = {k: np.add.reduceat(v, idx, axis=-1) if v.shape[-1] == self.data.n else v for k, v in out.items()}
        return out

    def simulate(self, theta: np.ndarray, *, rng: np.random.Generator) -> dict[str, np.ndarray]:
        """Replicated data (posterior predictive) for parameter vectors, with AR(1) noise.

        True F_io(t) is taken as the latent estimate given r; F_eo = r F_io (eq. 5, 13). Each
        replicate and channel also gets a constant offset error of the data's ``sd_offset_*``.

        Returns
        -------
        dict
            "F_io", "F_eo" (N) and, with the hoop term, "hoop" (strain), each shape (ndraw, n).
        """
        theta = np.atleast_2d(np.asarray(theta, float))
        r = self.ratio(theta)
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
        if self.hoop is not None:
            pred = self.hoop.predict(theta[:, 0], theta[:, 1], theta[:, 2])
            out["hoop"] = pred + ar1_noise(shape, sd=self.hoop.sd, rho=self.hoop.rho, rng=rng) \
                + rng.normal(0.0, self.hoop.offset, (len(x), 1))
        return out
