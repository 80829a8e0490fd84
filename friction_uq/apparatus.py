"""The apparatus of a confined friction test: bars, tube, sample, plug (SI units).

Frozen dataclasses with the derived quantities the analysis needs (areas, densities from
rho = E / c^2, impedances Z = A E / c, the Lame hoop factor), and :func:`paper_apparatus`, the
set-up of Durand et al. 2016 (docs/physics.md section 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Poisson ratio assumed for a bar when the record does not give one (optional attribute
#: ``poisson_ratio`` on a bar's group, an addition of this project); only the dispersion
#: correction uses it.
DEFAULT_BAR_POISSON_RATIO = 0.30

# ----------------------------------------------------------------------------------------------
# Apparatus
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Bar:
    """An elastic bar (solid when ``inner_diameter`` is 0, hollow otherwise). SI units.

    ``gauge_distance`` is measured from the end that touches the cell (None for the striker).
    """

    name: str
    young_modulus: float
    wave_speed: float
    outer_diameter: float
    length: float
    inner_diameter: float = 0.0
    gauge_distance: float | None = None
    poisson_ratio: float = DEFAULT_BAR_POISSON_RATIO

    @property
    def area(self) -> float:
        """Cross-section area (m^2)."""
        return math.pi / 4.0 * (self.outer_diameter**2 - self.inner_diameter**2)

    @property
    def density(self) -> float:
        """Density rho = E / c^2 (kg/m^3)."""
        return self.young_modulus / self.wave_speed**2

    @property
    def impedance(self) -> float:
        """Mechanical impedance Z = A E / c (N s/m)."""
        return self.area * self.young_modulus / self.wave_speed

    @property
    def gauge_delay(self) -> float:
        """Travel time from the gauge to the cell end, gauge_distance / c (s)."""
        if self.gauge_distance is None:
            raise ValueError(f"bar {self.name!r} has no gauge")
        return self.gauge_distance / self.wave_speed


@dataclass(frozen=True)
class Tube:
    """The confinement tube and its hoop gauge. SI units."""

    young_modulus: float
    poisson_ratio: float
    inner_diameter: float
    outer_diameter: float
    length: float
    gauge_offset: float
    gauge_width: float

    @property
    def lame_hoop_strain_per_pressure(self) -> float:
        """Outer-surface hoop strain per unit bore pressure, 2 a^2 / (E (b^2 - a^2)) (1/Pa).

        Lame, long open tube (docs/physics.md section 6): 2.10 microstrain per MPa for the paper's tube.
        """
        a = self.inner_diameter / 2.0
        b = self.outer_diameter / 2.0
        return 2.0 * a**2 / (self.young_modulus * (b**2 - a**2))

    @property
    def area(self) -> float:
        """Wall cross-section area (m^2)."""
        return math.pi / 4.0 * (self.outer_diameter**2 - self.inner_diameter**2)


@dataclass(frozen=True)
class Sample:
    """The confined sample (its Poisson ratio is an unknown of the analysis, not stored)."""

    material: str
    diameter: float
    length: float
    young_modulus: float
    density: float

    @property
    def radius(self) -> float:
        return self.diameter / 2.0

    @property
    def area(self) -> float:
        return math.pi * self.radius**2

    @property
    def wave_speed(self) -> float:
        """Bar wave speed sqrt(E / rho) of the sample (m/s)."""
        return math.sqrt(self.young_modulus / self.density)


@dataclass(frozen=True)
class Plug:
    """The steel plug between input bar and sample (optional in the contract)."""

    length: float
    young_modulus: float
    density: float


@dataclass(frozen=True)
class Apparatus:
    striker: Bar
    input_bar: Bar
    internal_output_bar: Bar
    external_output_bar: Bar
    tube: Tube
    sample: Sample
    plug: Plug | None = None

    @property
    def bars(self) -> dict[str, Bar]:
        """The three gauged bars by channel name."""
        return {
            "input_bar": self.input_bar,
            "internal_output_bar": self.internal_output_bar,
            "external_output_bar": self.external_output_bar,
        }

    @property
    def pulse_duration(self) -> float:
        """Incident pulse length 2 L_striker / c_striker (s)."""
        return 2.0 * self.striker.length / self.striker.wave_speed


def paper_apparatus() -> Apparatus:
    """The set-up of Durand et al. 2016 (docs/physics.md section 1 table, spec example)."""
    return Apparatus(
        striker=Bar("striker", 166e9, 4555.0, 0.02, 1.05, poisson_ratio=0.29),
        input_bar=Bar("input_bar", 166e9, 4555.0, 0.02, 2.5, gauge_distance=1.22, poisson_ratio=0.29),
        internal_output_bar=Bar(
            "internal_output_bar", 72.8e9, 5092.0, 0.01, 1.46, gauge_distance=0.33, poisson_ratio=0.33
        ),
        external_output_bar=Bar(
            "external_output_bar", 205e9, 5162.0, 0.04, 1.5, inner_diameter=0.03,
            gauge_distance=0.295, poisson_ratio=0.29,
        ),
        tube=Tube(200e9, 0.29, 0.01, 0.024, 0.04, 0.0025, 0.002),
        sample=Sample("I1", 0.01, 0.01, 2e9, 1850.0),
        plug=None,
    )
