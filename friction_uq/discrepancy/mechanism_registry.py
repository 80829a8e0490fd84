"""The registry of mechanisms: what an entry of the catalogue declares (:class:`Mechanism`), the stationary
window's means it states its effective f at (:class:`Context`), and :func:`register`, which adds one to
:data:`MECHANISMS` (its order is the order in which ``diagnose`` fits them). The entries themselves:
:mod:`.mechanisms` (the cell and the bar gauges' gain) and :mod:`.chain_faults` (the measurement chain).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from scipy import stats

from ..models.measurement_chain import Reading
from ..models.parameters import Parameter
from ..physics.cell import lateral_ratio

Apply = Callable[[Mapping[str, float], dict[str, Any], dict[str, Reading], str | None], None]
"""apply(values, settings, readings, channel): edit the simulator settings and the gauges' measurement chains
(channel -> :class:`~friction_uq.models.measurement_chain.Reading`) in place."""


@dataclass(frozen=True)
class Context:
    """Stationary-window means a mechanism needs to state its effective f: sliding speed V (m/s), wall shear
    stress tau_mean (Pa, eq. 18 from F_eo), slip (m), and the sample's mean axial stress sigma_mean (Pa, eq. 19 and
    21: (F_io + F_eo / 2) / (pi R^2)), whose nu / (1 - nu) is the mean wall pressure."""

    V: float
    tau_mean: float
    slip: float
    sigma_mean: float

    def wall_pressure(self, nu: Any) -> Any:
        """The window's mean wall pressure (Pa) under a Poisson ratio nu: nu / (1 - nu) sigma_mean (eq. 19, 21)."""
        return lateral_ratio(nu) * self.sigma_mean


@dataclass(frozen=True)
class Mechanism:
    """One entry of the catalogue (module docstring)."""

    name: str
    meaning: str
    signature: str
    parameters: tuple[Parameter, ...]
    priors: Mapping[str, Any]
    start: Mapping[str, float]
    apply: Apply
    #: f_effective(values, context): numpy expressions, so that arrays of values give arrays (the implied prior of
    #: f_effective, :mod:`.effective_prior`, evaluates it over many parameter draws at once)
    f_effective: Callable[[Mapping[str, Any], Context], Any] = field(default=lambda v, c: v["f"])
    channels: tuple[str, ...] = ()  # gauge_gain: the gauges it may act on (one fit each)
    group: str | None = None  # mechanisms of one group replace the same thing (the friction law): one at a time
    per_gauge: tuple[str, ...] = ()  # a measurement-chain fault fitted on every gauge at once: parameter i is gauge i's
    neutral: float = 0.0  # per_gauge: the parameter's value where its gauge reads right
    #: a friction law whose f_effective mixes f with another coefficient of its own, (1 - w) f + w f_s: that
    #: coefficient's name (its prior is pushed through f_effective where it carries the larger share, :mod:`.effective_prior`)
    companion: str | None = None
    #: f_effective reads the sample's nu (the pressure family, at the window's wall pressure): its prior's
    #: push-forward draws nu too
    uses_nu: bool = False
    #: further_starts(context, nu): starts of the entry's own parameters besides ``start``, placed from the window's
    #: means (a law's search from its simple form alone can stop short of a sharp one the record holds)
    further_starts: Callable[[Context, float], tuple[Mapping[str, float], ...]] = field(default=lambda c, nu: ())

    @property
    def measurement_chain(self) -> bool:
        """An entry of the measurement chain: it changes how one gauge reads the test (a gain, a zero, a delay, a
        low-pass, a bar's modulus), not the test itself, so it can take up any departure of that gauge's waveform
        from the 1-D model's, where the cell's mechanisms act through the physics on every gauge at once."""
        return bool(self.channels or self.per_gauge)

    def prior_z(self) -> dict[str, tuple[float, float]]:
        """Gaussian stand-ins of the priors in each parameter's unbounded coordinate (centre, sd), from the
        prior's 16 % and 84 % quantiles: what the mode search uses (the exact prior weighs the draws)."""
        return {p.name: p.gaussian_stand_in(self.priors[p.name]) for p in self.parameters}

    def log_prior(self, values: Mapping[str, float]) -> float:
        return float(sum(self.priors[p.name].logpdf(values[p.name]) for p in self.parameters))

    def on_gauges(self, gauges: tuple[str, ...]) -> Mechanism | None:
        """This entry as fitted on a record read by ``gauges`` only (a record without a hoop gauge, or analysed
        without it): a chain fault keeps the parameters of the gauges there (with none left, None), a gain the
        channels there; an entry of the cell is itself. A parameter of a gauge that is not read has no data: its
        posterior would be its prior, reported as if the gauge had been fitted."""
        if not (self.per_gauge or self.channels):
            return self
        channels = tuple(c for c in self.channels if c in gauges)
        kept = tuple((g, p) for g, p in zip(self.per_gauge, self.parameters) if g in gauges)
        if not (channels or kept):
            return None
        if not self.per_gauge:
            return replace(self, channels=channels)
        names = {p.name for _, p in kept}
        return replace(self, per_gauge=tuple(g for g, _ in kept), parameters=tuple(p for _, p in kept),
                       priors={k: v for k, v in self.priors.items() if k in names},
                       start={k: v for k, v in self.start.items() if k in names})

    def departing_gauge(self, values: Mapping[str, float]) -> tuple[str, Parameter] | None:
        """For a fault fitted on every gauge at once (``per_gauge``): the gauge whose parameter lies furthest
        from the neutral value (``neutral``: the gauge reads right), in its prior's sds, and that parameter
        (None for any other mechanism)."""
        if not self.per_gauge:
            return None

        def away(p: Parameter) -> float:
            return abs(float(values[p.name]) - self.neutral) / float(self.priors[p.name].std())

        i = max(range(len(self.per_gauge)), key=lambda k: away(self.parameters[k]))
        return self.per_gauge[i], self.parameters[i]


MECHANISMS: dict[str, Mechanism] = {}


def register(mech: Mechanism) -> Mechanism:
    """Add a mechanism to the catalogue (names are unique)."""
    if mech.name in MECHANISMS:
        raise ValueError(f"mechanism {mech.name!r} is registered twice")
    missing = [p.name for p in mech.parameters if p.name not in mech.priors or p.name not in mech.start]
    if missing:
        raise ValueError(f"mechanism {mech.name!r}: no prior or start for {', '.join(missing)}")
    MECHANISMS[mech.name] = mech
    return mech



def lognormal(median: float, sd_log: float) -> Any:
    """A lognormal prior by its median and the sd of its log."""
    return stats.lognorm(s=sd_log, scale=median)
