"""Pochhammer-Chree frequency equation: first longitudinal mode of a solid elastic cylinder.

``pochhammer_phase_velocity_ratio`` solves the frequency equation for c/c0 by root bracketing
along the first-mode branch; ``phase_velocity_curve`` is the cached table (d/Lambda, c/c0) of
that branch for one Poisson ratio, for interpolation (docs/physics.md section 7).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize, special

from ._checks import check_nu

#: Upper end of the tabulated first-mode curve, d/Lambda (dimensionless).
CURVE_MAX_D_OVER_LAMBDA = 2.5

#: d/Lambda beyond which the first-mode correction is not trusted (docs/physics.md section 7:
#: f a / c0 = 0.2619 at d/Lambda = 0.6 for a solid bar with nu = 0.29).
CUTOFF_D_OVER_LAMBDA = 0.6

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
    Reproduces the table of docs/physics.md section 7 to better than 1e-4.

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
    nu_v = check_nu(nu)
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
    nu_v = check_nu(nu)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 11:
        raise ValueError(f"n must be an integer >= 11, received {n!r}")
    return _cached_curve(round(nu_v, _NU_DECIMALS), int(n))
