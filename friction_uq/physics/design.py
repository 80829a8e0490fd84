"""Stationary-state design relations (Durand et al. 2016, eq. 15-16, from eq. 2-6, 13, 14).

e = exp(f beta); Z_i, Z_io, Z_eo the impedances of the input, internal and external output bars.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .cell import beta


def _e(f: ArrayLike, nu: ArrayLike, radius: float, length: float) -> np.ndarray:
    return np.exp(np.asarray(f, float) * beta(nu, radius=radius, length=length))


def stationary_internal_force(
    f: ArrayLike, nu: ArrayLike, *, striker_velocity: float, z_input: float, z_internal: float,
    radius: float, length: float,
) -> np.ndarray:
    """F_io = Z_i V_s / (e + Z_i / Z_io) (N). Eq. 15-16 (docs/physics.md section 4).

    >>> round(float(stationary_internal_force(0.05, 0.4, striker_velocity=10.0, z_input=11449.1,
    ...     z_internal=1122.88, radius=0.005, length=0.01)))
    10097
    """
    e = _e(f, nu, radius, length)
    return z_input * striker_velocity / (e + z_input / z_internal)


def stationary_external_force(
    f: ArrayLike, nu: ArrayLike, *, striker_velocity: float, z_input: float, z_internal: float,
    radius: float, length: float,
) -> np.ndarray:
    """F_eo = (e - 1) F_io (N). Eq. 5 and 13."""
    e = _e(f, nu, radius, length)
    return (e - 1.0) * z_input * striker_velocity / (e + z_input / z_internal)


def stationary_mean_pressure(
    f: ArrayLike, nu: ArrayLike, *, striker_velocity: float, z_input: float, z_internal: float,
    radius: float, length: float,
) -> np.ndarray:
    """p_mean = Z_i V_s (e - 1) / (2 pi R L f (e + Z_i / Z_io)) (Pa). Eq. 15, Durand et al. 2016.

    >>> round(float(stationary_mean_pressure(0.05, 0.4, striker_velocity=10.0, z_input=11449.1,
    ...     z_internal=1122.88, radius=0.005, length=0.01)) / 1e6, 2)
    91.68
    """
    e = _e(f, nu, radius, length)
    f = np.asarray(f, float)
    return z_input * striker_velocity * (e - 1.0) / (2.0 * math.pi * radius * length * f * (e + z_input / z_internal))


def stationary_sliding_velocity(
    f: ArrayLike, nu: ArrayLike, *, striker_velocity: float, z_input: float, z_internal: float,
    z_external: float, radius: float, length: float,
) -> np.ndarray:
    """V = V_s Z_i (1/Z_io - (e - 1)/Z_eo) / (e + Z_i / Z_io) (m/s). Eq. 16, Durand et al. 2016.

    >>> round(float(stationary_sliding_velocity(0.05, 0.4, striker_velocity=10.0, z_input=11449.1,
    ...     z_internal=1122.88, z_external=21833.5, radius=0.005, length=0.01)), 3)
    8.926
    """
    e = _e(f, nu, radius, length)
    return striker_velocity * z_input * (1.0 / z_internal - (e - 1.0) / z_external) / (e + z_input / z_internal)
