"""Janssen-type model of the confined sample (Durand et al. 2016, eq. 8-13 and 17-21).

Assumptions: rigid tube, elastic sample, stresses uniform over the radius, Coulomb friction.
Only the product f nu / (1 - nu) is fixed by the two output forces (eq. 17).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike


def lateral_ratio(nu: ArrayLike) -> np.ndarray:
    """Radial-to-axial stress ratio of a laterally constrained sample, nu / (1 - nu). Eq. 8."""
    nu = np.asarray(nu, float)
    return nu / (1.0 - nu)


def beta(nu: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """Geometric factor beta = 2 nu L / ((1 - nu) R). Eq. 13.

    >>> round(float(beta(0.4, radius=0.005, length=0.01)), 6)
    2.666667
    """
    return 2.0 * lateral_ratio(nu) * length / radius


def kappa(f: ArrayLike, nu: ArrayLike) -> np.ndarray:
    """The identifiable combination kappa = f nu / (1 - nu) (dimensionless)."""
    return np.asarray(f, float) * lateral_ratio(nu)


def force_ratio(f: ArrayLike, nu: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """F_eo / F_io = exp(f beta) - 1, from eq. 5 and 13.

    >>> round(float(force_ratio(0.05, 0.4, radius=0.005, length=0.01)), 4)
    0.1426
    """
    return np.expm1(np.asarray(f, float) * beta(nu, radius=radius, length=length))


def friction_from_ratio(ratio: ArrayLike, nu: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """Friction coefficient f = (1 - nu) R / (2 nu L) ln(1 + F_eo / F_io). Eq. 17, Durand et al. 2016.

    >>> round(float(friction_from_ratio(0.14, 0.4, radius=0.005, length=0.01)), 4)
    0.0491
    >>> round(float(friction_from_ratio(0.14, 0.2, radius=0.005, length=0.01)), 3)
    0.131
    """
    nu = np.asarray(nu, float)
    return (1.0 - nu) * radius / (2.0 * nu * length) * np.log1p(np.asarray(ratio, float))


def kappa_from_ratio(ratio: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """kappa = f nu/(1-nu) = R / (2 L) ln(1 + F_eo/F_io): eq. 17 without the unknown nu."""
    return radius / (2.0 * length) * np.log1p(np.asarray(ratio, float))


def mean_friction_stress(force_external: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """Mean shear stress on the wall, tau_mean = F_eo / (2 pi R L) (Pa). Eq. 18."""
    return np.asarray(force_external, float) / (2.0 * math.pi * radius * length)


def pressure_min(force_internal: ArrayLike, nu: ArrayLike, *, radius: float) -> np.ndarray:
    """Wall pressure at the output face, p_min = nu/(1-nu) F_io / (pi R^2) (Pa). Eq. 19."""
    return lateral_ratio(nu) * np.asarray(force_internal, float) / (math.pi * radius**2)


def pressure_max(force_internal: ArrayLike, force_external: ArrayLike, nu: ArrayLike, *, radius: float) -> np.ndarray:
    """Wall pressure at the input face, p_max = nu/(1-nu) (F_eo + F_io) / (pi R^2) (Pa). Eq. 19."""
    total = np.asarray(force_internal, float) + np.asarray(force_external, float)
    return lateral_ratio(nu) * total / (math.pi * radius**2)


def pressure_mean(force_external: ArrayLike, f: ArrayLike, *, radius: float, length: float) -> np.ndarray:
    """Mean wall pressure p_mean = tau_mean / f (Pa). Eq. 18 and 20."""
    return mean_friction_stress(force_external, radius=radius, length=length) / np.asarray(f, float)


def pressure_profile(z: ArrayLike, *, p_mean: float, f: float, nu: float, radius: float, length: float) -> np.ndarray:
    """Wall pressure along the sample, p(z) = p_mean fb exp(fb (L - z)/L) / (exp(fb) - 1). Eq. 20.

    z from the input face (m); exact for the Janssen model.
    """
    fb = f * float(beta(nu, radius=radius, length=length))
    z = np.asarray(z, float)
    if fb == 0.0:
        return np.full_like(z, p_mean)
    return p_mean * fb * np.exp(fb * (length - z) / length) / np.expm1(fb)


def axial_stress_profile(z: ArrayLike, *, sigma_input: float, f: float, nu: float, radius: float) -> np.ndarray:
    """Axial stress sigma(z) = sigma(0) exp(-2 f nu z / ((1 - nu) R)) (Pa). Solution of eq. 11."""
    k = 2.0 * f * nu / ((1.0 - nu) * radius)
    return sigma_input * np.exp(-k * np.asarray(z, float))
