"""Frequency-domain wave transport along elastic bars (physics.md sections 2 and 7).

Everything that moves a strain wave along a bar goes through this module: the transport of the
gauge signals to the bar ends that touch the cell (section 2), the dispersion correction of those
signals (section 7, Tyas and Pope 2005) and the dispersive bar legs of the simulator.

Contents
--------
``pochhammer_phase_velocity_ratio``
    c/c0 of the first longitudinal mode of a solid elastic cylinder, from the Pochhammer-Chree
    frequency equation solved by root bracketing along the first-mode branch.
``phase_velocity_curve``
    Cached table (d/Lambda, c/c0) of that branch for one Poisson ratio, for interpolation.
``phase_velocity``
    Phase velocity (m/s) against frequency (Hz) for a solid bar (exact first mode) or a hollow bar
    (Love estimate, an approximation valid well below the tube's ring frequency).
``first_mode_cutoff``
    Frequency (Hz) above which the first-mode correction is not trusted (d/Lambda = 0.6; for a
    hollow bar also at most 0.6 of its ring frequency).
``delay``
    Exact fractional (sub-sample) delay by a phase ramp on the zero-padded FFT.
``propagate``
    The wave as it reads a signed distance further along its direction of travel, with or without
    dispersion.

Conventions
-----------
SI units throughout: seconds, metres, hertz, m/s. c0 = sqrt(E / rho) is the one-dimensional bar
velocity. A wave travelling in +z with phase velocity c_p(f) is transported over a distance z by
multiplying each bin of ``numpy.fft.rfft`` by exp(-i 2 pi f z / c_p(f)), so that a non-dispersive
bar gives out(t) = in(t - z / c0). Negative z brings a wave back towards where it came from (the
correction of a gauge signal to the bar end it travelled from).

Not implemented
---------------
The amplitude factor M1 of Tyas and Wilson (2001), which converts the surface strain of a gauge to
the mean stress over the section at each frequency, is **not** implemented: only the phase of each
bin is corrected (and bins beyond the first-mode cut-off are removed). M1 tends to 1 at low
frequency; the error of leaving it out grows towards the cut-off.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike
from scipy import optimize, special

__all__ = [
    "CURVE_MAX_D_OVER_LAMBDA",
    "CUTOFF_D_OVER_LAMBDA",
    "CUTOFF_TAPER_FRACTION",
    "RING_FREQUENCY_FRACTION",
    "delay",
    "first_mode_cutoff",
    "phase_velocity",
    "phase_velocity_curve",
    "pochhammer_phase_velocity_ratio",
    "propagate",
]

#: Upper end of the tabulated first-mode curve, d/Lambda (dimensionless).
CURVE_MAX_D_OVER_LAMBDA = 2.5

#: d/Lambda beyond which the first-mode correction is not trusted (physics.md section 7:
#: f a / c0 = 0.2619 at d/Lambda = 0.6 for a solid bar with nu = 0.29).
CUTOFF_D_OVER_LAMBDA = 0.6

#: Width of the raised-cosine taper that removes the bins near the cut-off, as a fraction of the
#: cut-off frequency: the weight is 1 up to (1 - fraction) f_c and falls smoothly to 0 at f_c.
CUTOFF_TAPER_FRACTION = 0.1

#: Fraction of a hollow bar's ring frequency c0 / (2 pi r_m) above which its Love estimate is not
#: trusted (see ``first_mode_cutoff``).
RING_FREQUENCY_FRACTION = 0.6

#: Largest d/Lambda for which the Pochhammer root finder is run (the first mode is close to its
#: high-frequency limit, the Rayleigh wave velocity, well before that).
_MAX_D_OVER_LAMBDA = 10.0

#: Step of the continuation in d/Lambda, step and block size of the upward root-bracketing scan in
#: c/c0, and how far below the previous root the scan starts.
_MARCH_STEP = 0.005
_SCAN_STEP = 5e-4
_SCAN_BLOCK = 32
_SCAN_WINDOW = 0.05

#: Decimals of nu used as the cache key of ``phase_velocity_curve``.
_NU_DECIMALS = 6


# --------------------------------------------------------------------------------------------
# validation helpers
# --------------------------------------------------------------------------------------------


def _check_positive(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive finite number, received {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a positive finite number, received {value!r}")
    return v


def _check_finite(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, received {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number, received {value!r}")
    return v


def _check_nu(nu: float) -> float:
    try:
        v = float(nu)
    except (TypeError, ValueError):
        raise ValueError(f"nu (Poisson ratio) must be a number in [0, 0.5), received {nu!r}") from None
    if not (0.0 <= v < 0.5):
        raise ValueError(f"nu (Poisson ratio) must be in [0, 0.5), received {nu!r}")
    return v


def _check_geometry(diameter: float, inner_diameter: float) -> tuple[float, float]:
    d = _check_positive("diameter", diameter)
    try:
        di = float(inner_diameter)
    except (TypeError, ValueError):
        raise ValueError(
            f"inner_diameter must be a number in [0, diameter={d!r}) m, received {inner_diameter!r}"
        ) from None
    if not math.isfinite(di) or not (0.0 <= di < d):
        raise ValueError(f"inner_diameter must be in [0, diameter={d!r}) m, received {inner_diameter!r}")
    return d, di


# --------------------------------------------------------------------------------------------
# Pochhammer-Chree frequency equation, first longitudinal mode of a solid cylinder
# --------------------------------------------------------------------------------------------


def _frequency_function(ratio: np.ndarray | float, xi: float, nu: float) -> np.ndarray:
    """Pochhammer frequency function, zero on the longitudinal modes of a solid cylinder.

    With a the radius, k the wavenumber, c the phase velocity, c1 and c2 the dilatational and
    shear velocities, p^2 = k^2 (c^2/c1^2 - 1) and q^2 = k^2 (c^2/c2^2 - 1), the frequency equation
    (Pochhammer 1876, Chree 1889; see Graff, *Wave Motion in Elastic Solids*, chapter 8) reads

        (2p/a)(q^2 + k^2) J1(pa) J1(qa) - (q^2 - k^2)^2 J0(pa) J1(qa) - 4 k^2 p q J1(pa) J0(qa) = 0.

    Multiplied by a^5 / q it becomes, with P = (pa)^2, Q = (qa)^2, xi = ka, X = pa, Y = qa,

        2 (Q + xi^2) [X J1(X)] [J1(Y)/Y] - (Q - xi^2)^2 J0(X) [J1(Y)/Y] - 4 xi^2 [X J1(X)] J0(Y) = 0,

    where every bracket is a real entire function of P or Q (so the equation is real on both sides
    of c = c1 and c = c2), and the spurious root Q = 0 (c = c2) of the original form is removed.
    Since c2 < c0 < c1, the first mode starts with X imaginary and Y real (c2 < c < c0) and ends
    with both imaginary (c < c2); for an imaginary argument J0(iy) = I0(y), iy J1(iy) = -y I1(y)
    and J1(iy)/(iy) = I1(y)/y. The P-factors and Q-factors with imaginary argument are scaled by
    exp(-|X|) and exp(-|Y|) (``i0e``, ``i1e``), which keeps the sign and avoids overflow.

    Parameters
    ----------
    ratio : array_like
        Trial phase velocity ratio c/c0 (dimensionless), c0 = sqrt(E / rho).
    xi : float
        k a = pi d / Lambda (dimensionless).
    nu : float
        Poisson ratio.

    Returns
    -------
    numpy.ndarray
        Value of the scaled frequency function (dimensionless, only its sign and zeros matter).
    """
    s = np.asarray(ratio, dtype=float)
    c0_over_c1_sq = (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu)
    c0_over_c2_sq = 2.0 * (1.0 + nu)
    xi2 = xi * xi
    big_p = xi2 * (s * s * c0_over_c1_sq - 1.0)
    big_q = xi2 * (s * s * c0_over_c2_sq - 1.0)

    x = np.sqrt(np.abs(big_p))
    p_real = big_p >= 0.0
    x_j1 = np.where(p_real, x * special.j1(x), -x * special.i1e(x))  # X J1(X)
    j0_x = np.where(p_real, special.j0(x), special.i0e(x))  # J0(X)

    y = np.sqrt(np.abs(big_q))
    q_real = big_q >= 0.0
    y_safe = np.where(y == 0.0, 1.0, y)
    j1_over_y = np.where(
        y == 0.0, 0.5, np.where(q_real, special.j1(y_safe) / y_safe, special.i1e(y_safe) / y_safe)
    )  # J1(Y)/Y
    j0_y = np.where(q_real, special.j0(y), special.i0e(y))  # J0(Y)

    return (
        2.0 * (big_q + xi2) * x_j1 * j1_over_y
        - (big_q - xi2) ** 2 * j0_x * j1_over_y
        - 4.0 * xi2 * x_j1 * j0_y
    )


def _bracket_lowest(s_from: float, xi: float, nu: float) -> tuple[float, float]:
    """Lowest sign change of the frequency function above ``s_from`` (scan upwards in blocks).

    The scan stops at c/c0 = 1: by the Rayleigh quotient of the uniaxial-stress trial field, the
    first mode is slower than c0 for every k a > 0.
    """
    bottom = s_from
    ceiling = 1.0 + 1e-9
    while bottom < ceiling:
        trial = np.minimum(bottom + _SCAN_STEP * np.arange(_SCAN_BLOCK + 1), ceiling)
        signs = np.sign(_frequency_function(trial, xi, nu))
        change = np.nonzero(signs[:-1] * signs[1:] <= 0.0)[0]
        if change.size:
            j = int(change[0])
            return float(trial[j]), float(trial[j + 1])
        bottom = float(trial[-1])
    raise RuntimeError(  # pragma: no cover - the first mode always has a root below c0
        f"no first-mode root of the Pochhammer equation found in [{s_from}, 1] at k a={xi}, nu={nu}"
    )


def _march_first_mode(grid: np.ndarray, nu: float) -> np.ndarray:
    """c/c0 of the first mode on an increasing grid of d/Lambda starting at 0 (continuation).

    At fixed wavenumber the longitudinal modes are the eigenfrequencies of a self-adjoint problem,
    so the first mode is the lowest positive phase velocity root of the frequency equation. The
    continuation looks for that lowest root upwards from a window ``_SCAN_WINDOW`` below the
    previous step's root (the first mode moves by less than 0.01 in c/c0 per step of 0.005 in
    d/Lambda for any nu). It may move up as well as down: for small Poisson ratios the first mode's phase
    velocity has a minimum below the Rayleigh velocity and rises back towards it.
    """
    ratio = np.empty_like(grid)
    ratio[0] = 1.0  # d/Lambda = 0: c = c0 exactly
    s_prev = 1.0
    for i in range(1, grid.size):
        xi = math.pi * float(grid[i])
        lo, hi = _bracket_lowest(s_prev - _SCAN_WINDOW, xi, nu)
        root = optimize.brentq(
            lambda s: float(_frequency_function(s, xi, nu)), lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps
        )
        ratio[i] = root
        s_prev = root
    return ratio


def pochhammer_phase_velocity_ratio(d_over_lambda: ArrayLike, nu: float) -> np.ndarray:
    """Phase velocity ratio c/c0 of the first longitudinal mode of a solid elastic cylinder.

    Solves the Pochhammer-Chree frequency equation (written with J0, J1; see
    ``_frequency_function``) by root bracketing and ``scipy.optimize.brentq``, following the first
    mode continuously from c/c0 = 1 at d/Lambda = 0 in steps of at most 0.005 in d/Lambda: at
    each step the root is the lowest sign change above a window just below the previous root (the
    first mode is the slowest longitudinal mode at each wavenumber; see ``_march_first_mode``).
    Reproduces the table of physics.md section 7 to better than 1e-4.

    Parameters
    ----------
    d_over_lambda : array_like
        Diameter over wavelength d/Lambda (dimensionless), each in [0, 10].
    nu : float
        Poisson ratio of the bar, in [0, 0.5).

    Returns
    -------
    numpy.ndarray
        c/c0 (dimensionless), same shape as ``d_over_lambda``; c0 = sqrt(E / rho) is the bar velocity.

    Raises
    ------
    ValueError
        If ``nu`` is outside [0, 0.5) or a d/Lambda is not finite or outside [0, 10].

    Examples
    --------
    >>> round(float(pochhammer_phase_velocity_ratio(0.6, 0.29)), 4)
    0.873
    """
    nu_v = _check_nu(nu)
    dl = np.asarray(d_over_lambda, dtype=float)
    if dl.size == 0:
        return np.empty(dl.shape)
    finite = np.isfinite(dl)
    if not np.all(finite) or np.any(dl < 0.0) or np.any(dl > _MAX_D_OVER_LAMBDA):
        shown = f"[{dl[finite].min()!r}, {dl[finite].max()!r}]" if np.any(finite) else "none"
        raise ValueError(
            f"d_over_lambda must be finite and in [0, {_MAX_D_OVER_LAMBDA}], received finite values in "
            f"{shown} and {int(np.sum(~finite))} non-finite value(s)"
        )
    return _first_mode_at(dl, nu_v)


def _first_mode_at(d_over_lambda: np.ndarray, nu: float) -> np.ndarray:
    """First-mode c/c0 at given d/Lambda values (>= 0), marching through steps of at most 0.005."""
    top = float(d_over_lambda.max())
    march = np.arange(0.0, top + _MARCH_STEP, _MARCH_STEP)
    grid = np.union1d(np.union1d([0.0], march[march <= top]), d_over_lambda.ravel())
    ratio = _march_first_mode(grid, nu)
    return ratio[np.searchsorted(grid, d_over_lambda)]


@functools.lru_cache(maxsize=64)
def _cached_curve(nu_rounded: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    grid = np.linspace(0.0, CURVE_MAX_D_OVER_LAMBDA, n)
    ratio = _first_mode_at(grid, nu_rounded)
    grid.setflags(write=False)
    ratio.setflags(write=False)
    return grid, ratio


def phase_velocity_curve(nu: float, *, n: int = 1001) -> tuple[np.ndarray, np.ndarray]:
    """Tabulated first-mode curve (d/Lambda, c/c0) of a solid bar, cached per Poisson ratio.

    The root finding of ``pochhammer_phase_velocity_ratio`` runs once per (nu rounded to 6
    decimals, n); later calls return the same read-only arrays.

    Parameters
    ----------
    nu : float
        Poisson ratio, in [0, 0.5). Rounded to 6 decimals for the cache key (the effect on c/c0 is
        below 1e-6).
    n : int, optional
        Number of grid points, uniform in d/Lambda from 0 to ``CURVE_MAX_D_OVER_LAMBDA`` = 2.5
        (at least 11). With the default (step 0.0025) the linear interpolation of
        ``phase_velocity`` is accurate to 3e-6 in c/c0.

    Returns
    -------
    d_over_lambda : numpy.ndarray
        Grid of d/Lambda (dimensionless), read-only.
    ratio : numpy.ndarray
        c/c0 of the first mode on that grid (dimensionless), read-only, decreasing from 1.

    Raises
    ------
    ValueError
        If ``nu`` is outside [0, 0.5) or ``n`` is not an integer >= 11.
    """
    nu_v = _check_nu(nu)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 11:
        raise ValueError(f"n must be an integer >= 11, received {n!r}")
    return _cached_curve(round(nu_v, _NU_DECIMALS), int(n))


# --------------------------------------------------------------------------------------------
# phase velocity against frequency
# --------------------------------------------------------------------------------------------


def _love_hollow_ratio(frequency: np.ndarray, *, c0: float, mean_square_radius: float, nu: float) -> np.ndarray:
    """Self-consistent Love estimate s = c/c0 with s = 1 - nu^2 pi^2 (r_i^2 + r_o^2) f^2 / (s c0)^2.

    s solves s^3 - s^2 + B = 0 with B = nu^2 pi^2 (r_i^2 + r_o^2) f^2 / c0^2. A root in (2/3, 1]
    exists for B <= 4/27; Newton from s = 1 converges monotonically to it (the cubic is convex and
    increasing there). The callers clip the frequency well before that (s >= 0.77 at the clip).
    """
    b = (nu * math.pi) ** 2 * mean_square_radius * (np.asarray(frequency, dtype=float) / c0) ** 2
    if np.any(b > 4.0 / 27.0):  # pragma: no cover - guarded by the callers' clip
        raise ValueError(f"Love estimate has no real phase velocity for B = {float(np.max(b))!r} > 4/27")
    s = np.ones_like(b)
    for _ in range(60):
        step = (s**3 - s**2 + b) / (3.0 * s**2 - 2.0 * s)
        s = s - step
        if np.all(np.abs(step) <= 1e-15):
            break
    return s


def _hollow_cutoff(*, c0: float, outer_radius: float, inner_radius: float, nu: float) -> float:
    """Cut-off of the hollow bar's Love estimate (Hz): the lower of the d/Lambda rule and the ring bound."""
    mean_square_radius = inner_radius**2 + outer_radius**2
    ratio_cut = 1.0 - (nu * math.pi * CUTOFF_D_OVER_LAMBDA / 2.0) ** 2
    f_love = CUTOFF_D_OVER_LAMBDA * ratio_cut * c0 / (2.0 * math.sqrt(mean_square_radius))
    f_ring = c0 / (2.0 * math.pi * 0.5 * (inner_radius + outer_radius))
    return min(f_love, RING_FREQUENCY_FRACTION * f_ring)


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
    physics.md section 7),

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
    c0_v = _check_positive("c0", c0)
    d, di = _check_geometry(diameter, inner_diameter)
    nu_v = _check_nu(nu)
    f = np.asarray(frequency, dtype=float)
    if not np.all(np.isfinite(f)) or np.any(f < 0.0):
        raise ValueError(
            "frequency must be finite and >= 0 Hz, received "
            f"{int(np.sum(~np.isfinite(f)))} non-finite and {int(np.sum(f < 0.0))} negative value(s)"
        )
    if di == 0.0:
        ratio = _solid_ratio_at(f * d / c0_v, nu_v)
    else:
        cutoff = _hollow_cutoff(c0=c0_v, outer_radius=d / 2.0, inner_radius=di / 2.0, nu=nu_v)
        mean_square_radius = (di / 2.0) ** 2 + (d / 2.0) ** 2
        ratio = _love_hollow_ratio(np.minimum(f, cutoff), c0=c0_v, mean_square_radius=mean_square_radius, nu=nu_v)
    return c0_v * ratio


def first_mode_cutoff(*, c0: float, diameter: float, nu: float, inner_diameter: float = 0.0) -> float:
    """Frequency above which the first-mode dispersion correction is not trusted (Hz).

    Solid bar: d/Lambda = 0.6 (``CUTOFF_D_OVER_LAMBDA``) converted to frequency with the exact
    first-mode curve, f_c = 0.6 (c_p / c0) c0 / d; for nu = 0.29 this is f a / c0 = 0.2619
    (physics.md section 7).

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
    c0_v = _check_positive("c0", c0)
    d, di = _check_geometry(diameter, inner_diameter)
    nu_v = _check_nu(nu)
    if di == 0.0:
        dl, ratio = phase_velocity_curve(nu_v)
        ratio_cut = float(np.interp(CUTOFF_D_OVER_LAMBDA, dl, ratio))
        return CUTOFF_D_OVER_LAMBDA * ratio_cut * c0_v / d
    return _hollow_cutoff(c0=c0_v, outer_radius=d / 2.0, inner_radius=di / 2.0, nu=nu_v)


# --------------------------------------------------------------------------------------------
# transport of signals
# --------------------------------------------------------------------------------------------


def _padded_length(n: int, pad_factor: float) -> int:
    """Odd fast FFT length >= pad_factor * n.

    Odd so that there is no Nyquist bin: every phase factor then acts on a conjugate pair of bins,
    and delays compose exactly (d1 then d2 equals d1 + d2 on the padded circle).
    """
    target = max(int(math.ceil(pad_factor * n)), n, 1)
    m = scipy.fft.next_fast_len(target, real=False)
    while m % 2 == 0:
        m = scipy.fft.next_fast_len(m + 1, real=False)
    return int(m)


def _prepare_signal(signal: ArrayLike, sample_interval: float, pad_factor: float) -> tuple[np.ndarray, float, int]:
    x = np.asarray(signal, dtype=np.float64)
    if x.ndim == 0 or x.shape[-1] == 0:
        raise ValueError(f"signal must be an array with at least one sample along its last axis, received shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"signal must be finite, received {int(np.sum(~np.isfinite(x)))} non-finite sample(s)")
    dt = _check_positive("sample_interval", sample_interval)
    try:
        pf = float(pad_factor)
    except (TypeError, ValueError):
        raise ValueError(f"pad_factor must be a finite number >= 1, received {pad_factor!r}") from None
    if not math.isfinite(pf) or pf < 1.0:
        raise ValueError(f"pad_factor must be a finite number >= 1, received {pad_factor!r}")
    return x, dt, _padded_length(x.shape[-1], pf)


def _apply_transfer(x: np.ndarray, length: int, transfer: np.ndarray) -> np.ndarray:
    spectrum = np.fft.rfft(x, n=length, axis=-1)
    out = np.fft.irfft(spectrum * transfer, n=length, axis=-1)
    return np.ascontiguousarray(out[..., : x.shape[-1]], dtype=np.float64)


def _delay_padded(x: np.ndarray, dt: float, length: int, delay_s: float) -> np.ndarray:
    k = np.arange(length // 2 + 1, dtype=float)
    # phase in cycles, reduced modulo 1 before exp for precision at large k
    cycles = np.mod(k * (delay_s / (dt * length)), 1.0)
    return _apply_transfer(x, length, np.exp(-2j * np.pi * cycles))


def delay(signal: ArrayLike, *, sample_interval: float, delay: float) -> np.ndarray:
    """Exact fractional delay: out(t) = in(t - delay).

    The signal is zero-padded to an odd fast FFT length of at least twice its length
    (``scipy.fft.next_fast_len``), each bin of its ``numpy.fft.rfft`` is multiplied by
    exp(-i 2 pi f delay) and the inverse transform is cut back to the original length. No bin is
    dropped and the odd length leaves no Nyquist bin, so delays compose exactly and a delay followed
    by its opposite is the identity, for every signal that stays inside the record.

    The signal is assumed to be zero (baseline removed) at both ends; the mean is not removed.
    The zero padding avoids wrap-around as long as the signal does not move by more than the
    padding (at least the record length); what moves past either end of the record is lost.
    ``propagate`` with ``dispersive=False`` is this delay with delay = distance / c0 and a
    selectable padding. Non-integer delays act as band-limited (sinc) interpolation, so a signal with
    a step at an end of the record rings there.

    Parameters
    ----------
    signal : array_like
        Samples, time along the last axis.
    sample_interval : float
        Time between samples (s), > 0.
    delay : float
        Delay (s), any sign; negative values advance the signal.

    Returns
    -------
    numpy.ndarray
        Delayed signal, float64, same shape as ``signal``.

    Raises
    ------
    ValueError
        If the signal is empty or not finite, or a parameter is out of range.

    Examples
    --------
    >>> (delay([0.0, 1.0, 0.0, 0.0], sample_interval=1e-6, delay=1e-6).round(12) + 0.0).tolist()
    [0.0, 0.0, 1.0, 0.0]
    """
    x, dt, length = _prepare_signal(signal, sample_interval, 2)
    delay_s = _check_finite("delay", delay)
    return _delay_padded(x, dt, length, delay_s)


def _cutoff_weight(frequency: np.ndarray, cutoff: float) -> np.ndarray:
    """Raised-cosine weight: 1 below (1 - CUTOFF_TAPER_FRACTION) f_c, 0 at and above f_c."""
    start = (1.0 - CUTOFF_TAPER_FRACTION) * cutoff
    u = np.clip((frequency - start) / (cutoff - start), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(np.pi * u))


def propagate(
    signal: ArrayLike,
    *,
    sample_interval: float,
    distance: float,
    c0: float,
    diameter: float | None = None,
    nu: float | None = None,
    inner_diameter: float = 0.0,
    dispersive: bool = False,
    pad_factor: float = 2,
) -> np.ndarray:
    """The wave as it reads ``distance`` metres further along its direction of travel.

    Non-dispersive bar (``dispersive=False``): out(t) = in(t - distance / c0), the exact
    sub-sample delay of ``delay`` (no bin dropped); ``diameter``, ``nu`` and ``inner_diameter``
    are ignored.

    Dispersive bar (``dispersive=True``, Tyas and Pope 2005): each bin of the zero-padded
    ``numpy.fft.rfft`` is multiplied by exp(-i 2 pi f distance / c_p(f)) with c_p from
    ``phase_velocity`` (first longitudinal mode; Love estimate for a hollow bar), and the bins near
    and beyond ``first_mode_cutoff`` are removed: their weight falls from 1 at
    0.9 f_c to 0 at f_c along a raised cosine (``CUTOFF_TAPER_FRACTION``), which avoids the ringing
    of a brick-wall cut. The output is therefore low-pass filtered at f_c; a forward transport
    followed by the backward one returns the original's content below the cut-off. The amplitude
    factor M1 (Tyas and Wilson 2001) is not applied.

    The signal is assumed to be zero (baseline removed) at both ends; its mean is not removed.
    Zero padding to an odd fast FFT length of at least ``pad_factor`` times the record length
    avoids wrap-around as long as the wave (including its dispersive tail) moves by less than the
    padding; what leaves the record is lost. With ``pad_factor=1`` there is (almost) no padding and
    the transport is circular.

    Parameters
    ----------
    signal : array_like
        Samples (any unit, typically strain), time along the last axis.
    sample_interval : float
        Time between samples (s), > 0.
    distance : float
        Signed distance along the direction of travel (m); negative brings a wave back to where
        it came from.
    c0 : float
        Bar velocity sqrt(E / rho) (m/s), > 0.
    diameter : float, optional
        Outer diameter of the bar (m); required when ``dispersive`` is True.
    nu : float, optional
        Poisson ratio of the bar; required when ``dispersive`` is True.
    inner_diameter : float, optional
        Bore diameter (m) of a hollow bar, 0 (default) for a solid bar.
    dispersive : bool, optional
        Apply first-mode dispersion (True) or a pure delay (False, default).
    pad_factor : float, optional
        Minimum padded length as a multiple of the record length, >= 1 (default 2).

    Returns
    -------
    numpy.ndarray
        Transported signal, float64, same shape as ``signal``.

    Raises
    ------
    ValueError
        If the signal is empty or not finite, a parameter is out of range, or ``dispersive`` is
        True without ``diameter`` and ``nu``.
    """
    x, dt, length = _prepare_signal(signal, sample_interval, pad_factor)
    z = _check_finite("distance", distance)
    c0_v = _check_positive("c0", c0)
    if not dispersive:
        return _delay_padded(x, dt, length, z / c0_v)
    if diameter is None or nu is None:
        raise ValueError(
            f"dispersive=True needs the bar's diameter (m) and nu, received diameter={diameter!r}, nu={nu!r}"
        )
    f = np.fft.rfftfreq(length, d=dt)
    cp = phase_velocity(f, c0=c0_v, diameter=diameter, nu=nu, inner_diameter=inner_diameter)
    cutoff = first_mode_cutoff(c0=c0_v, diameter=diameter, nu=nu, inner_diameter=inner_diameter)
    weight = _cutoff_weight(f, cutoff)
    cycles = np.mod(f * (z / cp), 1.0)
    return _apply_transfer(x, length, weight * np.exp(-2j * np.pi * cycles))
