"""Thick confinement tube and its hoop gauge (docs/physics.md section 6).

Strains here are physical hoop strains (positive when the tube swells). The record's
``tube_hoop`` channel is compression positive like every channel inside the package, so it reads
``-hoop_strain``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

#: Effective decay rate of the shell-on-elastic-foundation kernel fitted to the exact axisymmetric
#: solution for a = 5 mm, b = 12 mm, nu_t = 0.29 (docs/physics.md section 6), 1/m.
BETA_EFF_PAPER_TUBE = 192.0


def lame_hoop_strain(pressure: ArrayLike, *, inner_radius: float, outer_radius: float, young_modulus: float) -> np.ndarray:
    """Outer-surface hoop strain of a long open tube, 2 p a^2 / (E (b^2 - a^2)). Lame (docs/physics.md section 6).

    >>> round(float(lame_hoop_strain(1e6, inner_radius=0.005, outer_radius=0.012, young_modulus=200e9)) * 1e6, 2)
    2.1
    """
    a, b = inner_radius, outer_radius
    return 2.0 * np.asarray(pressure, float) * a**2 / (young_modulus * (b**2 - a**2))


def bore_compliance_factor(*, inner_radius: float, outer_radius: float, poisson_ratio: float) -> float:
    """C_t = (b^2 + a^2)/(b^2 - a^2) + nu_t: bore displacement u(a) = p a C_t / E_t (docs/physics.md section 6)."""
    a, b = inner_radius, outer_radius
    return (b**2 + a**2) / (b**2 - a**2) + poisson_ratio


def hoop_kernel(x: ArrayLike, *, beta: float = BETA_EFF_PAPER_TUBE) -> np.ndarray:
    """Influence function K(x) = (beta/2) exp(-beta|x|)(cos(beta|x|) + sin(beta|x|)) (1/m), integral 1.

    Hoop strain at axial distance x from a unit line load, normalised to the Lame strain
    (docs/physics.md section 6).
    """
    ax = np.abs(np.asarray(x, float)) * beta
    return 0.5 * beta * np.exp(-ax) * (np.cos(ax) + np.sin(ax))


def band_response(distance: ArrayLike, *, band_length: float, beta: float = BETA_EFF_PAPER_TUBE) -> np.ndarray:
    """Gauge reading / Lame strain for a uniform pressure band of ``band_length`` centred ``distance`` away.

    Closed-form integral of :func:`hoop_kernel` over the band. docs/physics.md: 0.77, 0.52, 0.14 and ~0
    at 0, 5, 10, 15 mm from a 10 mm band's centre.
    """
    d = np.asarray(distance, float)
    return _kernel_cdf(d + band_length / 2.0, beta) - _kernel_cdf(d - band_length / 2.0, beta)


def _kernel_cdf(x: np.ndarray, beta: float) -> np.ndarray:
    """Integral of K from -inf to x."""
    ax = beta * np.abs(x)
    # integral_0^u of (1/2) e^{-s}(cos s + sin s) ds = (1/2)(1 - e^{-u} cos u)
    half = 0.5 * (1.0 - np.exp(-ax) * np.cos(ax))
    return 0.5 + np.sign(x) * half
