"""A two-bar SHPB record as read from its file: the bars, the specimen and the gauge signals.

SI units; the gauge signals are in volts, sign-corrected so that compression is positive (the
reader, :mod:`.lanl`, decides the sign once, from the data).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class BarProperties:
    """One elastic bar as the file describes it. SI units.

    Attributes
    ----------
    name : str
        "input" or "transmitted".
    young_modulus : float
        E (Pa).
    wave_speed : float
        Rod (one-dimensional) wave speed c0 (m/s), as stated ("Rod Sound Speed").
    poisson_ratio : float
        nu (dimensionless).
    density : float
        rho (kg/m^3).
    diameter : float
        Bar diameter (m).
    gauge_distance : float
        Distance from the gauge to the bar end touching the specimen (m).
    gauge_factor : float
        Calibrated gauge factor GF (dimensionless).
    excitation : float
        Bridge excitation Vexc (V).
    gains : Mapping[str, float]
        Every amplifier-gain field of the file that concerns this bar, by its key (V/V).
    timing_wave_speed : float or None
        Wave speed from the calibrated reflection time ("Reflected Time Sound Speed", m/s), when
        the file gives one.
    """

    name: str
    young_modulus: float
    wave_speed: float
    poisson_ratio: float
    density: float
    diameter: float
    gauge_distance: float
    gauge_factor: float
    excitation: float
    gains: Mapping[str, float]
    timing_wave_speed: float | None = None

    @property
    def area(self) -> float:
        """Cross-section area pi d^2 / 4 (m^2)."""
        return math.pi / 4.0 * self.diameter**2

    @property
    def gauge_delay(self) -> float:
        """Travel time from the gauge to the specimen face, d / c0 (s)."""
        return self.gauge_distance / self.wave_speed

    def strain(self, volts: np.ndarray, *, gain: float) -> np.ndarray:
        """Quarter-bridge strain V (2 / GF) / (gain Vexc) (dimensionless) from volts."""
        return np.asarray(volts, dtype=float) * (2.0 / self.gauge_factor) / (gain * self.excitation)


@dataclass(frozen=True)
class SpecimenProperties:
    """The specimen as the file describes it (m, K)."""

    material: str
    description: str
    diameter: float
    length: float
    temperature: float


@dataclass(frozen=True)
class TwoBarRecord:
    """A two-bar SHPB record read by :func:`read_lanl_raw`. Arrays are read-only.

    Attributes
    ----------
    path : Path
        The file read.
    time : numpy.ndarray
        Time of each sample (s), shape (n,).
    input_volts, transmitted_volts : numpy.ndarray
        Gauge signals (V), shape (n,), sign-corrected so that compression is positive.
    polarity : tuple[int, int]
        The sign applied to the (input, transmitted) columns of the file (+1 or -1).
    sample_interval : float
        Sampling interval (s).
    metadata : Mapping[str, str]
        Every key/value pair of columns 1-2, verbatim (keys with their units).
    input_bar, transmitted_bar : BarProperties
    specimen : SpecimenProperties
    """

    path: Path
    time: np.ndarray
    input_volts: np.ndarray
    transmitted_volts: np.ndarray
    polarity: tuple[int, int]
    sample_interval: float
    metadata: Mapping[str, str]
    input_bar: BarProperties
    transmitted_bar: BarProperties
    specimen: SpecimenProperties

    @property
    def n_samples(self) -> int:
        return int(self.time.size)
