"""Wall friction laws of the simulator: one registry, one entry per named law.

A law gives the shear strength tau_max (Pa) of the sample/tube interface from the local wall
pressure p (Pa), the local sliding speed V (m/s) and the slip distance already travelled d (m).
The cell kernel (:mod:`.cell`) applies it at every node as a Coulomb-type set-valued law: the
interface sticks while the force needed to stick stays below tau_max times the node's wall area,
and slides with tau = tau_max against the sliding direction otherwise (docs/physics.md eq. 10 for the
``coulomb`` law).

Laws (docs/physics.md section 5):

``coulomb``         tau = f p                                       (eq. 10)
``velocity``        tau = [f_d + (f_s - f_d) exp(-V / v_c)] p       (velocity weakening or strengthening)
``pressure``        tau = min(f p, tau_max)                         (shear-strength limited)
``hyperbolic``      tau = f0 p / (1 + p / p0)                       (pressure dependent, smooth)
``slip_weakening``  tau = [f_d + (f_s - f_d) max(0, 1 - d / d_c)] p (linear weakening over d_c)

and three families that hold a law above as their shape n = 1 and bend it either way: walls of other shapes for the
studies of ``diagnose`` (whose friction mechanisms are the simple laws; fitting the families instead was measured and
not applied, docs/trust.md, "Fifty-fifth session"):

``velocity_stretched``   tau = [f_d + (f_s - f_d) exp(-(V / v_c)^n)] p    (n = 1: ``velocity``; n = 2 a sharper
                         turn; n < 1 a slow, power-like tail)
``pressure_saturating``  tau = f0 p / (1 + (p / p0)^n)^(1/n)             (n = 1: ``hyperbolic``; n large: the
                         cap of ``pressure`` at tau_max = f0 p0)
``slip_power``           tau = [f_d + (f_s - f_d) max(0, 1 - d / d_c)^n] p (n = 1: ``slip_weakening``; n large
                         with d_c = n d_e: an exponential drop over d_e)

Adding a law touches this module only: one :class:`FrictionLaw` entry in :data:`LAWS` (name,
code, parameters with units and bounds) and one branch of :func:`shear_strength`. The
configuration reader, the ``/truth`` group and the documentation read the registry.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._jit import njit


@dataclass(frozen=True)
class Param:
    """One parameter of a friction law: name, unit, allowed interval [low, high] and meaning."""

    name: str
    unit: str
    low: float
    high: float
    doc: str
    low_open: bool = False  # True: the value must be > low

    def allows(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        return above and value <= self.high

    def describe_range(self) -> str:
        lo = "(" if self.low_open else "["
        return f"{lo}{self.low:g}, {self.high:g}]"


@dataclass(frozen=True)
class FrictionLaw:
    """A named friction law: integer ``code`` used by the compiled kernel and its parameters."""

    name: str
    code: int
    params: tuple[Param, ...]
    doc: str

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    def pack(self, values: Mapping[str, float]) -> np.ndarray:
        """Parameter vector in the order of :attr:`params` (what :func:`shear_strength` reads)."""
        return np.array([float(values[p.name]) for p in self.params], dtype=np.float64)


_F = 5.0  # largest friction coefficient accepted (far beyond any lubricated interface)
COULOMB, VELOCITY, PRESSURE, HYPERBOLIC, SLIP_WEAKENING = 0, 1, 2, 3, 4
VELOCITY_STRETCHED, PRESSURE_SATURATING, SLIP_POWER = 5, 6, 7
_N = Param("n", "-", 0.0, 1e3, "shape of the change (n = 1: the family's simple law)", low_open=True)

#: the parameters a velocity and a slip law share with their families (which add the shape n)
_VELOCITY_PARAMS = (
    Param("f_s", "-", 0.0, _F, "coefficient at zero sliding speed"),
    Param("f_d", "-", 0.0, _F, "coefficient at high sliding speed"),
    Param("v_c", "m/s", 0.0, 1e3, "characteristic speed", low_open=True),
)
_SLIP_PARAMS = (
    Param("f_s", "-", 0.0, _F, "static (initial) coefficient"),
    Param("f_d", "-", 0.0, _F, "dynamic coefficient after the slip d_c"),
    Param("d_c", "m", 0.0, 1.0, "critical slip distance: where the coefficient reaches f_d", low_open=True),
)

LAWS: dict[str, FrictionLaw] = {
    "coulomb": FrictionLaw("coulomb", COULOMB, (
        Param("f", "-", 0.0, _F, "friction coefficient"),
    ), "tau = f p (eq. 10)"),
    "velocity": FrictionLaw("velocity", VELOCITY, _VELOCITY_PARAMS,
        "tau = [f_d + (f_s - f_d) exp(-V/v_c)] p"),
    "pressure": FrictionLaw("pressure", PRESSURE, (
        Param("f", "-", 0.0, _F, "friction coefficient below the shear limit"),
        Param("tau_max", "Pa", 0.0, 1e10, "shear strength of the interface", low_open=True),
    ), "tau = min(f p, tau_max)"),
    "hyperbolic": FrictionLaw("hyperbolic", HYPERBOLIC, (
        Param("f0", "-", 0.0, _F, "coefficient at zero pressure"),
        Param("p0", "Pa", 0.0, 1e11, "pressure at which f has halved", low_open=True),
    ), "tau = f0 p / (1 + p/p0)"),
    "slip_weakening": FrictionLaw("slip_weakening", SLIP_WEAKENING, _SLIP_PARAMS,
        "tau = [f_d + (f_s - f_d) max(0, 1 - d/d_c)] p"),
    "velocity_stretched": FrictionLaw("velocity_stretched", VELOCITY_STRETCHED, _VELOCITY_PARAMS + (_N,),
        "tau = [f_d + (f_s - f_d) exp(-(V/v_c)^n)] p"),
    "pressure_saturating": FrictionLaw("pressure_saturating", PRESSURE_SATURATING, (
        Param("f0", "-", 0.0, _F, "coefficient at zero pressure"),
        Param("p0", "Pa", 0.0, 1e11, "pressure at which f0 p meets the shear cap f0 p0", low_open=True),
        _N,
    ), "tau = f0 p / (1 + (p/p0)^n)^(1/n)"),
    "slip_power": FrictionLaw("slip_power", SLIP_POWER, _SLIP_PARAMS + (_N,),
        "tau = [f_d + (f_s - f_d) max(0, 1 - d/d_c)^n] p"),
}


@njit
def saturation(x: float, n: float) -> float:
    """(1 + x^n)^(1/n) for x >= 0, n > 0, written so that neither power overflows (x^n for x > 1 and large n):
    1 at x = 0, x for x >> 1, their smooth join at x = 1 (2^(1/n)).

    >>> round(saturation(3.0, 1.0), 12), round(saturation(3.0, 1e3), 6), round(saturation(0.5, 1e3), 6)
    (4.0, 3.0, 1.0)
    """
    if x <= 1.0:
        return (1.0 + x ** n) ** (1.0 / n)
    return x * (1.0 + x ** (-n)) ** (1.0 / n)


@njit
def shear_strength(code: int, par: np.ndarray, p: float, v: float, d: float) -> float:
    """Shear strength tau_max (Pa) of the wall at pressure ``p`` (Pa), speed ``v`` (m/s), slip ``d`` (m).

    ``code`` and ``par`` come from a :class:`FrictionLaw` (:data:`LAWS`); ``v`` and ``d`` are >= 0.

    >>> round(shear_strength(COULOMB, np.array([0.05]), 1e8, 0.0, 0.0) / 1e6, 6)
    5.0
    """
    if p <= 0.0:
        return 0.0
    if code == COULOMB:
        return par[0] * p
    if code == VELOCITY or code == VELOCITY_STRETCHED:  # the simple law: its family at n = 1 (x ** 1.0 is x)
        n = par[3] if code == VELOCITY_STRETCHED else 1.0
        return (par[1] + (par[0] - par[1]) * math.exp(-((v / par[2]) ** n))) * p
    if code == PRESSURE:
        return min(par[0] * p, par[1])
    if code == HYPERBOLIC:
        return par[0] * p / (1.0 + p / par[1])
    if code == SLIP_WEAKENING or code == SLIP_POWER:  # the simple law: its family at n = 1
        n = par[3] if code == SLIP_POWER else 1.0
        w = 1.0 - d / par[2]
        return (par[1] + (par[0] - par[1]) * (w ** n if w > 0.0 else 0.0)) * p
    if code == PRESSURE_SATURATING:
        return par[0] * p / saturation(p / par[1], par[2])
    return math.nan  # unknown code: poisons the run instead of failing silently
