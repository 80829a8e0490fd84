"""Phase velocity of a bar's first longitudinal mode against frequency, and its cut-off.

Solid bar: the exact first mode of :mod:`.pochhammer`; hollow bar: Love's estimate of
:mod:`.hollow` (docs/physics.md section 7).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._checks import check_geometry, check_nu, check_positive
from .hollow import hollow_cutoff, love_hollow_ratio
from .pochhammer import CUTOFF_D_OVER_LAMBDA, phase_velocity_curve


def _solid_ratio_at(fd_over_c0: np.ndarray, nu: float) -> np.ndarray:
    """c/c0 of the solid bar's first mode at given f d / c0 (held at the curve's end beyond it)."""
    dl, ratio = phase_velocity_curve(nu)
    x = dl * ratio  # f d / c0 = (d / Lambda)(c / c0): increases along the first mode (group velocity > 0)
    return np.interp(fd_over_c0, x, ratio)


def phase_velocity(
    frequency: ArrayLike, *, c0: float, diameter: float, nu: float, inner_diameter: float = 0.0
) -> np.ndarray:
    """Phase velocity of the first longitudinal mode of a bar against frequency.

    Solid bar (``inner_diameter == 0``): exact first mode, interpolated (linearly) in the cached
    Pochhammer curve of ``phase_velocity_curve``. Since Lambda = c_p / f, d/Lambda = (f d / c0) /
    (c_p / c0), so the curve is re-parametrised by f d / c0 = (d/Lambda)(c/c0), which increases
    along the first mode. Interpolation error < 3e-6 in c/c0. Beyond the curve's end
    (d/Lambda = 2.5, f d / c0 ~ 1.45, far above the first-mode cut-off) the last value is held:
    it is within 2.1 % of the Rayleigh velocity (the first mode's high-frequency limit) for every
    nu in [0, 0.5), 0.4 % for nu = 0.29.

    Hollow bar (``inner_diameter > 0``): **approximation**, Love's estimate with the square of the
    radius replaced by r_i^2 + r_o^2 (lateral inertia with the section's polar radius of gyration;
    docs/physics.md section 7),

        c/c0 = 1 - nu^2 pi^2 (r_i^2 + r_o^2) / Lambda^2,   Lambda = c / f,

    solved self-consistently for Lambda, and clipped at its validity: beyond
    ``first_mode_cutoff`` the value at the cut-off is held. The exact first mode of a hollow
    cylinder (Gazis 1959) is not implemented. It collapses near the ring (breathing) frequency
    f_ring = c0 / (2 pi r_m), r_m = (r_i + r_o)/2, which Love's theory does not see: for the
    40/30 mm steel bar (f_ring = 47 kHz, nu = 0.29) an exact computation made while writing this
    module gives c/c0 = 0.9907, 0.9720, 0.9058, 0.745 at 20, 30, 40, 45 kHz where Love gives
    0.9921, 0.9818, 0.9667, 0.957 (errors 0.14 %, 1.0 %, 6.7 %, 29 %); hence the ring bound of the
    cut-off. For a solid bar the Love formula is within 0.06 % of the exact value at
    d/Lambda = 0.2 but 6 % too high at 0.6 (nu = 0.29).

    Parameters
    ----------
    frequency : array_like
        Frequencies (Hz), finite and >= 0. Frequency 0 gives exactly c0.
    c0 : float
        Bar velocity sqrt(E / rho) (m/s), > 0.
    diameter : float
        Outer diameter of the bar (m), > 0.
    nu : float
        Poisson ratio of the bar, in [0, 0.5).
    inner_diameter : float, optional
        Bore diameter (m), in [0, diameter); 0 (default) for a solid bar.

    Returns
    -------
    numpy.ndarray
        Phase velocity c_p (m/s), same shape as ``frequency``.

    Raises
    ------
    ValueError
        If a frequency is negative or not finite, or a bar parameter is out of range.
    """
    c0_v = check_positive("c0", c0)
    d, di = check_geometry(diameter, inner_diameter)
    nu_v = check_nu(nu)
    f = np.asarray(frequency, dtype=float)
    if not np.all(np.isfinite(f)) or np.any(f < 0.0):
        raise ValueError(
            "frequency must be finite and >= 0 Hz, received "
            f"{int(np.sum(~np.isfinite(f)))} non-finite and {int(np.sum(f < 0.0))} negative value(s)"
        )
    if di == 0.0:
        ratio = _solid_ratio_at(f * d / c0_v, nu_v)
    else:
        cutoff = hollow_cutoff(c0=c0_v, outer_radius=d / 2.0, inner_radius=di / 2.0, nu=nu_v)
        mean_square_radius = (di / 2.0) ** 2 + (d / 2.0) ** 2
        ratio = love_hollow_ratio(np.minimum(f, cutoff), c0=c0_v, mean_square_radius=mean_square_radius, nu=nu_v)
    return c0_v * ratio


def first_mode_cutoff(*, c0: float, diameter: float, nu: float, inner_diameter: float = 0.0) -> float:
    """Frequency above which the first-mode dispersion correction is not trusted (Hz).

    Solid bar: d/Lambda = 0.6 (``CUTOFF_D_OVER_LAMBDA``) converted to frequency with the exact
    first-mode curve, f_c = 0.6 (c_p / c0) c0 / d; for nu = 0.29 this is f a / c0 = 0.2619
    (docs/physics.md section 7).

    Hollow bar: the lower of two limits. (1) The same rule with the Love estimate of
    ``phase_velocity``: d_eq/Lambda = 0.6 with the equivalent diameter d_eq = 2 sqrt(r_i^2 + r_o^2)
    and c_p/c0 = 1 - nu^2 pi^2 0.3^2. (2) ``RING_FREQUENCY_FRACTION`` = 0.6 of the ring
    frequency c0 / (2 pi r_m), r_m = (r_i + r_o)/2, where the exact first mode of a tube departs
    from Love's estimate (see ``phase_velocity``; for the 40/30 mm bar the error of the estimate
    at this bound, 28 kHz, is about 0.8 %). Limit (2) governs thin walls; for thick walls it is
    conservative.

    Parameters
    ----------
    c0 : float
        Bar velocity sqrt(E / rho) (m/s), > 0.
    diameter : float
        Outer diameter (m), > 0.
    nu : float
        Poisson ratio, in [0, 0.5).
    inner_diameter : float, optional
        Bore diameter (m), in [0, diameter); 0 (default) for a solid bar.

    Returns
    -------
    float
        Cut-off frequency (Hz).

    Raises
    ------
    ValueError
        If a bar parameter is out of range.

    Examples
    --------
    >>> round(first_mode_cutoff(c0=4555.0, diameter=0.02, nu=0.29) * 0.01 / 4555.0, 4)
    0.2619
    """
    c0_v = check_positive("c0", c0)
    d, di = check_geometry(diameter, inner_diameter)
    nu_v = check_nu(nu)
    if di == 0.0:
        dl, ratio = phase_velocity_curve(nu_v)
        ratio_cut = float(np.interp(CUTOFF_D_OVER_LAMBDA, dl, ratio))
        return CUTOFF_D_OVER_LAMBDA * ratio_cut * c0_v / d
    return hollow_cutoff(c0=c0_v, outer_radius=d / 2.0, inner_radius=di / 2.0, nu=nu_v)
