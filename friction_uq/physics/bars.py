"""Hopkinson bar formulae (Durand et al. 2016, eq. 2-7 and 14). SI units, compression positive.

All strains are the waves *transported* to the bar end that touches the cell.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def input_force(eps_incident: ArrayLike, eps_reflected: ArrayLike, *, area: float, young_modulus: float) -> np.ndarray:
    """Force on the plug, F_i = A_i E_i (eps_i + eps_r) (N). Eq. 2, Durand et al. 2016.

    >>> round(float(input_force(1e-3, -0.9e-3, area=1e-4, young_modulus=2e11)), 6)
    2000.0
    """
    return area * young_modulus * (np.asarray(eps_incident, float) + np.asarray(eps_reflected, float))


def input_velocity(eps_incident: ArrayLike, eps_reflected: ArrayLike, *, wave_speed: float) -> np.ndarray:
    """Velocity of the input bar's end, V_i = C_i (eps_i - eps_r) (m/s). Eq. 2."""
    return wave_speed * (np.asarray(eps_incident, float) - np.asarray(eps_reflected, float))


def transmitted_force(eps_transmitted: ArrayLike, *, area: float, young_modulus: float) -> np.ndarray:
    """Force carried by an output bar, F = A E eps_t (N). Eq. 3 (internal) and eq. 4 (external)."""
    return area * young_modulus * np.asarray(eps_transmitted, float)


def transmitted_velocity(eps_transmitted: ArrayLike, *, wave_speed: float) -> np.ndarray:
    """Velocity of an output bar's end, V = C eps_t (m/s). Eq. 3 and eq. 4."""
    return wave_speed * np.asarray(eps_transmitted, float)


def equilibrium_error(force_input: ArrayLike, force_internal: ArrayLike, force_external: ArrayLike) -> np.ndarray:
    """Relative imbalance of the cell, (F_i - F_io - F_eo) / F_i. Eq. 5 holds when it is 0."""
    fi = np.asarray(force_input, float)
    return (fi - np.asarray(force_internal, float) - np.asarray(force_external, float)) / fi


def stationarity_error(velocity_input: ArrayLike, velocity_internal: ArrayLike) -> np.ndarray:
    """Relative velocity mismatch (V_i - V_io) / V_i across the sample. Eq. 6 holds when it is 0."""
    vi = np.asarray(velocity_input, float)
    return (vi - np.asarray(velocity_internal, float)) / vi


def sliding_velocity(velocity_internal: ArrayLike, velocity_external: ArrayLike) -> np.ndarray:
    """Sliding velocity of the sample on the tube, V = V_io - V_eo (m/s). Eq. 7."""
    return np.asarray(velocity_internal, float) - np.asarray(velocity_external, float)


def incident_strain(striker_velocity: float, *, wave_speed: float) -> float:
    """Incident strain from the striker speed, eps_i = V_s / (2 C_i). Eq. 14.

    Same material and section for striker and input bar.

    >>> round(incident_strain(10.0, wave_speed=4555.0), 9)
    0.001097695
    """
    return striker_velocity / (2.0 * wave_speed)


def trapezoid_pulse(t: ArrayLike, *, rise_time: float, end: float, amplitude: float = 1.0) -> np.ndarray:
    """Trapezoidal pulse, the closed-form incident wave of eq. 14 with finite rise and fall.

    Foot at t = 0, linear rise over ``rise_time`` to ``amplitude``, plateau, linear fall over
    ``rise_time`` that ends at ``end`` (s). A striker of length L_s and wave speed c_s gives a
    pulse 2 L_s / c_s long between its half-amplitude points: ``end`` = 2 L_s / c_s + ``rise_time``
    (the simulator); the closed-form records take ``end`` = 2 L_s / c_s.

    >>> trapezoid_pulse(np.array([-1.0, 0.5, 2.0, 4.5, 6.0]), rise_time=1.0, end=5.0, amplitude=2.0).tolist()
    [0.0, 1.0, 2.0, 1.0, 0.0]
    """
    t = np.asarray(t, float)
    up = np.clip(t / rise_time, 0.0, 1.0)
    down = np.clip((end - t) / rise_time, 0.0, 1.0)
    return amplitude * np.minimum(up, down)


#: Relative standard deviation of one output bar's force E A eps from its calibration: the modulus (~1 %), the
#: section (~1 %, 0.5 % on a diameter) and the gauge's factor with its amplifier (~1 %), independent.
BAR_FORCE_CALIBRATION_SD = float(np.sqrt(3.0)) * 0.01
#: Relative standard deviation of eq. 17's ratio F_eo / F_io from the two output bars' calibrations, which the
#: stationary phase cannot tell from f (the equilibrium with the input bar checks the forces' sum, within that bar's
#: own calibration): sqrt(2) x :data:`BAR_FORCE_CALIBRATION_SD`,
#: 2.45 %. f = ln(1 + r) / beta(nu) (eq. 17) moves by r / ((1 + r) ln(1 + r)) of the ratio's relative error (0.93
#: at r = 0.15, below 1 for every r > 0): taken as 1, a slightly wider interval of f.
FORCE_RATIO_CALIBRATION_SD = float(np.sqrt(2.0)) * BAR_FORCE_CALIBRATION_SD

