"""Bar-level mechanisms that make a two-bar record miss its force balance: a small registry.

Each mechanism extends the nominal model of :mod:`.balance` (header gain, stated rod wave speed,
no dispersion correction) with named parameters (:class:`~friction_uq.models.Parameter`), a
documented prior on a physical range, its meaning and its signature in F_1 - F_2. Mechanisms
combine: their parameters merge by name and each sets its own field of
:class:`~.balance.BarSettings`. Adding one touches this registry and its tests only.

Priors (independent, on the parameters' natural scale):

* ``gauge_gain``: gamma = true gain / header gain of the transmitted channel, log-normal with
  median 1 and log-sd ``GAIN_LOG_SD`` = ln(2.5) / 2 = 0.46: the header's other statement (500
  against 200, gamma = 2.5) sits at two prior standard deviations, so the prior admits either
  statement and the data decide. Support (0.05, 20).
* ``wave_speed``: s = c / c0, log-normal with median 1 and log-sd ``SPEED_LOG_SD`` = 0.03: the
  scatter of a titanium alloy's rod speed between heats and heat treatments (E within +-5 %,
  density +-1 %, so c within ~3 %), which also covers a few-microsecond error of the gauge-to-face
  distance over 381 mm. Support (0.8, 1.2).
* ``dispersion``: no parameter; the Pochhammer-Chree first-mode transport replaces the pure delay.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

from ..models.parameters import Parameter
from .balance import BarSettings

#: Prior log-sd of the transmitted gain factor (module docstring).
GAIN_LOG_SD = math.log(2.5) / 2.0
#: Prior log-sd of the wave-speed factor (module docstring).
SPEED_LOG_SD = 0.03

GAIN_FACTOR = Parameter("gain_factor", "-", 0.05, 20.0,
                        "true amplifier gain of the transmitted channel over the header's (200 V/V)")
SPEED_FACTOR = Parameter("speed_factor", "-", 0.8, 1.2,
                         "bar wave speed that sets the gauge-to-face travel times over the stated c0")


@dataclass(frozen=True)
class BarMechanism:
    """One bar-level mechanism.

    Attributes
    ----------
    name : str
        Registry key.
    parameters : tuple[Parameter, ...]
        Its named parameters (may be empty).
    meaning, signature : str
        What it is physically, and how it shows in F_1 - F_2.
    log_prior : Callable[[Mapping[str, float]], float]
        Log prior density of its parameters (natural scale).
    apply : Callable[[BarSettings, Mapping[str, float]], BarSettings]
        The settings with this mechanism switched on at the given parameter values.
    prior_log_sd : Mapping[str, float]
        Prior log-sd of each parameter around 1: where the fit searches for the mode (+-3 of it).
    """

    name: str
    parameters: tuple[Parameter, ...]
    meaning: str
    signature: str
    log_prior: Callable[[Mapping[str, float]], float]
    apply: Callable[[BarSettings, Mapping[str, float]], BarSettings]
    prior_log_sd: Mapping[str, float] = dataclasses.field(default_factory=dict)


MECHANISMS: dict[str, BarMechanism] = {}


def register(mechanism: BarMechanism) -> BarMechanism:
    if mechanism.name in MECHANISMS:
        raise ValueError(f"bar mechanism {mechanism.name!r} is already registered")
    MECHANISMS[mechanism.name] = mechanism
    return mechanism


def lognormal_logpdf(x: float, *, log_sd: float) -> float:
    """Log density of a log-normal with median 1 and log-sd ``log_sd`` at ``x`` > 0.

    >>> round(lognormal_logpdf(1.0, log_sd=1.0), 6)
    -0.918939
    """
    z = math.log(x) / log_sd
    return -0.5 * z * z - math.log(x * log_sd) - 0.5 * math.log(2.0 * math.pi)


register(BarMechanism(
    name="gauge_gain",
    parameters=(GAIN_FACTOR,),
    meaning="a calibration (amplifier gain) error on the transmitted gauge: F_2 scaled by 1 / gamma",
    signature="F_2 a constant fraction off F_1 through the whole pulse: rise, plateau and unloading scale together",
    log_prior=lambda v: lognormal_logpdf(v["gain_factor"], log_sd=GAIN_LOG_SD),
    apply=lambda s, v: dataclasses.replace(s, gain_factor=float(v["gain_factor"])),
    prior_log_sd={"gain_factor": GAIN_LOG_SD},
))

register(BarMechanism(
    name="wave_speed",
    parameters=(SPEED_FACTOR,),
    meaning="bar wave speed (gauge-to-face transit time) off the stated rod speed c0",
    signature="F_1 - F_2 shaped like the derivative of the pulse: of opposite signs on the rise and the unloading",
    log_prior=lambda v: lognormal_logpdf(v["speed_factor"], log_sd=SPEED_LOG_SD),
    apply=lambda s, v: dataclasses.replace(s, speed_factor=float(v["speed_factor"])),
    prior_log_sd={"speed_factor": SPEED_LOG_SD},
))

register(BarMechanism(
    name="dispersion",
    parameters=(),
    meaning="uncorrected Pochhammer-Chree dispersion over the gauge-to-face distances",
    signature="ringing on the plateau and fronts sharper in the prediction than in F_2 (or the reverse)",
    log_prior=lambda v: 0.0,
    apply=lambda s, v: dataclasses.replace(s, dispersion=True),
))


@dataclass(frozen=True)
class CombinedModel:
    """The nominal model extended by a set of mechanisms (parameters merged by name)."""

    mechanisms: tuple[BarMechanism, ...]

    @property
    def name(self) -> str:
        return " + ".join(m.name for m in self.mechanisms) or "nominal"

    @property
    def parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for m in self.mechanisms for p in m.parameters)

    def log_prior(self, values: Mapping[str, float]) -> float:
        return sum(m.log_prior(values) for m in self.mechanisms)

    def prior_log_sd(self, name: str) -> float:
        """Prior log-sd of a parameter (0.1 when its mechanism does not say)."""
        return next((m.prior_log_sd[name] for m in self.mechanisms if name in m.prior_log_sd), 0.1)

    def settings(self, values: Mapping[str, float]) -> BarSettings:
        s = BarSettings()
        for m in self.mechanisms:
            s = m.apply(s, values)
        return s


def combine(names: Iterable[str]) -> CombinedModel:
    """The nominal model with the named mechanisms, in registry order."""
    names = list(names)
    unknown = [n for n in names if n not in MECHANISMS]
    if unknown:
        raise ValueError(f"bar mechanism(s) {', '.join(map(repr, unknown))} not understood, "
                         f"allowed values: {', '.join(MECHANISMS)}")
    return CombinedModel(tuple(m for k, m in MECHANISMS.items() if k in names))
