"""The closed form as a forward model: the force ratio (eq. 13, 17) and the tube hoop gauge (eq. 20
through the tube kernel, docs/physics.md section 6), for named parameter values.

It is driven by what the stationary phase measured (a :class:`~friction_uq.window.StationaryData`):
the internal output force F_io(t) and the slip of the sample; it predicts the external force
ratio and the hoop reading over the window. The likelihood (:mod:`friction_uq.likelihood`) takes
this model and the observations.

Force ratio
-----------
In the stationary phase eq. 5 and 13 give F_eo = r F_io with r = exp(f beta(nu)) - 1 (eq. 17
inverted), beta(nu) = 2 nu L / ((1 - nu) R).

Hoop gauge
----------
The tube gauge reads (package convention, compression positive, so negative while swelling)

    h(t) = -g [ Lame * integral_{-L/2}^{L/2} p(s, t) K_w(z_g(t) - s) ds + nu_t N(z_g(t), t) / (E_t A_t) ]

with Lame = 2 a^2 / (E_t (b^2 - a^2)); s the position from the sample's middle, positive toward the
output side; z_g(t) = gauge_offset - slip(t) the gauge's position (the sample slides toward the
output side, so the gauge moves toward the input face); K_w the tube kernel K averaged over the
gauge's width (a strain gauge reads the mean strain under its grid; ``gauge_averaging=False`` gives
the point gauge of docs/physics.md section 6, ~0.4 % higher, well inside the kernel's own 2.4 % fit
error; the simulator and the closed-form records average too); p(s, t) the eq. 20 wall pressure,
written as p = nu/(1-nu) sigma(z) (eq. 8) with sigma(z) = F_io(t) e^{f beta (L - z)/L} / (pi R^2)
from eq. 11-13 (z = s + L/2), identical to eq. 20 and regular at f = 0. F_io(t) is the observed
internal force smoothed over ``smooth`` (10 us): its noise (~0.2 % per sample, less after
smoothing) is negligible beside the hoop noise.

Axial Poisson term, sign choice: the tube rests on the external output bar at its output end, so
friction puts the tube section at s in axial compression N(s) = friction force on the wall between
the input face and s, N = F_io e^{fb (1/2 - s/L)} (e^{fb (s/L + 1/2)} - 1) for |s| < L/2, 0 on the
input side, F_eo on the output side (fb = f beta). Axial compression widens the tube (physical hoop
strain + nu_t N / (E_t A_t), the "+19 microstrain for 5 kN" of docs/physics.md), the same direction as
the pressure term, so in the package's convention both terms enter with the minus sign above. The
local N at the gauge is used (no Saint-Venant spreading), an approximation for a term ~4 % of the
reading. g, the calibration factor, scales the whole reading.

:func:`friction_uq.synthetic.closed_form_strains` reuses :class:`HoopPrediction` on the true force
and slip histories; the tests hold it against an independent quadrature (a trapezoid rule over the
profile of :func:`friction_uq.physics.cell.pressure_profile`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from scipy.ndimage import uniform_filter1d

from ..physics import cell, tube
from ..window import StationaryData
from .parameters import F, HOOP_GAIN, NU, ParameterSet


def force_ratio(f: np.ndarray | float, nu: np.ndarray | float, *, radius: float, length: float) -> np.ndarray:
    """r = F_eo / F_io = exp(f beta(nu)) - 1 in the stationary phase (eq. 5, 13; eq. 17 inverted)."""
    return cell.force_ratio(f, nu, radius=radius, length=length)


def gauge_kernel(x: np.ndarray, *, gauge_width: float, beta: float = tube.BETA_EFF_PAPER_TUBE) -> np.ndarray:
    """Tube kernel K averaged over a gauge of width ``gauge_width`` centred at ``x`` (1/m).

    Equal to :func:`friction_uq.physics.tube.hoop_kernel` when the width is 0.
    """
    if gauge_width <= 0.0:
        return tube.hoop_kernel(x, beta=beta)
    return tube.band_response(x, band_length=gauge_width, beta=beta) / gauge_width


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


class HoopPrediction:
    """The hoop reading of the closed form over one stationary phase (module docstring).

    The prediction is evaluated on knots every ``knot_step`` seconds and interpolated linearly in
    between (``basis``, the (n, m) hat matrix). It varies on the scale of the slip past the kernel,
    ~5 mm, against ~40 um of slip per 4 us knot step, and with the 10 us smoothing of F_io: on the
    paper's case the interpolated prediction is within 0.12 microstrain of the per-sample one
    (gauge noise ~2 microstrain).

    Parameters
    ----------
    data : StationaryData
        Uses ``slip``, ``F_io``, ``tube``, ``radius``, ``length``, ``sample_rate``.
    axial_poisson : bool
        Include the tube's axial Poisson term.
    smooth : float
        Moving-average length applied to F_io for the wall pressure (s).
    knot_step : float
        Spacing of the prediction knots (s); 0 puts a knot on every sample.
    gauge_averaging : bool
        Average the kernel over ``tube.gauge_width`` (default; False: point gauge).
    n_nodes : int
        Gauss-Legendre nodes over the sample length.
    kernel_beta : float
        Decay rate of the tube kernel (1/m).
    """

    def __init__(
        self, data: StationaryData, *, axial_poisson: bool = True, smooth: float = 10e-6, knot_step: float = 4e-6,
        gauge_averaging: bool = True, n_nodes: int = 16, kernel_beta: float = tube.BETA_EFF_PAPER_TUBE,
    ) -> None:
        tb = data.tube
        R, L = data.radius, data.length
        n = data.n
        self.n = n
        self.radius, self.length = R, L
        self.axial_poisson = axial_poisson
        n_smooth = max(1, int(round(smooth * data.sample_rate)))
        F_io = uniform_filter1d(np.asarray(data.F_io, float), n_smooth, mode="nearest")
        z_g = tb.gauge_offset - np.asarray(data.slip, float)
        self.gauge_position = z_g

        step = max(1, int(round(knot_step * data.sample_rate)))
        knots = np.unique(np.append(np.arange(0, n, step), n - 1))
        self.knots = knots
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

    @functools.cached_property
    def basis(self) -> np.ndarray:
        """(n, m) hat matrix of the linear interpolation from the knots (built when first asked for: with a
        knot on every sample it is n x n)."""
        return _hat_basis(self.knots, self.n)

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

    def predict_weighted(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """``predict_knots(f, nu, gain) @ weights``, shape (len(f),), without the (len(f), m) knot values: the
        pressure term's quadrature is contracted with the weights first, and the axial Poisson term uses
        e^{fb a} (e^{fb b} - 1) = e^{fb} - e^{fb a} (a + b = 1). A weighted mean of the reading (the level
        likelihood's window mean) then costs one exponential per knot instead of two and a product."""
        f, nu, gain = (np.atleast_1d(np.asarray(v, float)) for v in (f, nu, gain))
        w = np.asarray(weights, float)
        lat = cell.lateral_ratio(nu)
        fb = f * cell.beta(nu, radius=self.radius, length=self.length)
        swell = lat * (np.exp(fb[:, None] * self._c[None, :]) @ (self._kmat @ w))
        if self.axial_poisson:
            pw = self._poisson * w
            swell = swell + np.exp(fb) * pw.sum() - np.exp(fb[:, None] * self._pc_a) @ pw
        return -gain * swell

    def interpolate(self, c: np.ndarray) -> np.ndarray:
        """Knot values (..., m) -> every sample (..., n), linear interpolation."""
        return c[:, self._left] * (1.0 - self._w) + c[:, self._left + 1] * self._w

    def predict(self, f: np.ndarray, nu: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Predicted hoop reading at every sample, shape (len(f), n) (strain).

        ``f``, ``nu``, ``gain`` are 1-d arrays of equal length (or scalars).
        """
        return self.interpolate(self.predict_knots(f, nu, gain))


class ClosedFormModel:
    """The closed form (eq. 13-21, the tube kernel) over one stationary phase, parameters by name.

    Parameters
    ----------
    data : StationaryData
        The stationary phase whose measured F_io and slip drive the model.
    hoop : bool
        Predict the tube hoop gauge (adds ``hoop_gain`` to the parameters).
    **hoop_options
        Options of :class:`HoopPrediction` (``axial_poisson``, ``smooth``, ``knot_step``, ...).

    Attributes
    ----------
    parameters : ParameterSet
        (f, nu) or (f, nu, hoop_gain).
    hoop : HoopPrediction or None
    """

    name = "closed form"
    #: The closed form's coordinates: eq. 17 fixes log f + log(nu / (1 - nu)) = log kappa, a straight
    #: ridge in (log f, log-odds nu); the gauge factor on a log scale.
    PARAMETERS = (replace(F, transform="log"), replace(NU, transform="logodds"), replace(HOOP_GAIN, transform="log"))

    def __init__(self, data: StationaryData, *, hoop: bool = True, **hoop_options: object) -> None:
        self.radius, self.length = data.radius, data.length
        self.hoop = HoopPrediction(data, **hoop_options) if hoop else None  # type: ignore[arg-type]
        self.parameters = ParameterSet(self.PARAMETERS if hoop else self.PARAMETERS[:2])

    def ratio(self, values: Mapping[str, np.ndarray | float]) -> np.ndarray:
        """F_eo / F_io in the stationary phase for named values (eq. 5, 13)."""
        return force_ratio(values["f"], values["nu"], radius=self.radius, length=self.length)

    def hoop_reading(self, values: Mapping[str, np.ndarray | float]) -> np.ndarray:
        """Hoop reading over the window (strain, compression positive), shape (ndraw, n)."""
        if self.hoop is None:
            raise ValueError("this closed-form model was built without the hoop gauge (hoop=False)")
        return self.hoop.predict(values["f"], values["nu"], values.get("hoop_gain", 1.0))

    def predict(self, values: Mapping[str, np.ndarray | float]) -> dict[str, np.ndarray]:
        """``ratio`` and, with the hoop gauge, ``tube_hoop`` for named values."""
        out = {"ratio": self.ratio(values)}
        if self.hoop is not None:
            out["tube_hoop"] = self.hoop_reading(values)
        return out
