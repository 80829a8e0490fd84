"""The catalogue of mechanisms: what the paper's model leaves out (docs/physics.md section 5), each an
extension of the baseline simulator with named parameters.

Every entry declares its parameters (:class:`~friction_uq.models.Parameter`: name, unit, physical
support, meaning), their priors (scipy distributions over physical ranges, documented here), a
starting value for the fit, what it is physically and its signature in the record, and how it acts
on the simulator (``apply``: it edits the simulator settings and the gauges' measurement chains,
:mod:`friction_uq.models.measurement_chain`). The baseline's
own parameters (f, nu and the sample's modulus factor) stay free in every fit. Adding a mechanism
is one :func:`register` call below and its tests.

A mechanism that replaces the friction law also says what "the" friction coefficient is under it
(``f_effective``): the wall's coefficient at the stationary window's mean sliding speed, pressure
or slip, so that f under the extended model compares with the baseline's.

Priors (why these ranges):

* ``velocity_friction``: f_s ~ half-normal(0.3) like f; v_c ~ lognormal(median 5 m/s, sd of log 1):
  the speeds of the test.
* ``pressure_friction``: p0 ~ lognormal(median 200 MPa, sd of log 1.5): f halves at p0, the
  test's pressures are 50-200 MPa.
* ``slip_friction``: f_s ~ half-normal(0.3); d_c ~ lognormal(median 1 mm, sd of log 1): the
  sample slides ~5 mm.
* ``clearance``: gap ~ half-normal(20 um): the paper quotes ~10 um of radial clearance.
* ``plug_friction``: force ~ half-normal(500 N), coefficient ~ half-normal(0.03) of F_i.
* ``gauge_gain``: gain ~ lognormal(0, 0.1): a bar gauge's calibration is rarely 10 % off.
* ``dispersion``: no parameter (the bars' geometry gives it).
* ``end_friction``: f_e ~ half-normal(0.25): PTFE on steel is 0.02-0.1, bare faces (a sheet torn or
  missing: explosive on steel) 0.3-0.5.

The measurement chain beside the gain (each fitted once, on every gauge it may act on at once: a
parameter per gauge, the gauges that read right keep theirs near the neutral value):

* ``zero_drift``: a rate per gauge ~ normal(0, 10 microstrain per ms): a bridge warming or an
  amplifier's zero creeping moves a few microstrain over a record of 1-2 ms; the constant part of a
  zero is the likelihood's own offset.
* ``channel_timing``: the output bars' and the hoop gauge's delays against the input bar ~ normal(0,
  2 us): a gauge 1 cm from where the header puts it on a 5000 m/s bar reads 2 us late, two digitisers
  triggered apart by a few samples as much (a delay common to every channel changes nothing).
* ``bandwidth``: an equivalent first-order time constant per output gauge ~ half-normal(1 us): a bridge
  amplifier of 100 kHz (older SHPB chains) has 1.6 us, one of 1 MHz 0.16 us. The input bar is left
  out: its reading, low-pass and all, drives the simulation, so the output gauges' time constants are
  read against the input bar's (exactly so where the cell responds linearly to the wave's shape).
* ``bar_modulus``: each output bar's modulus over its header's ~ lognormal(0, 3 %), its density kept (the
  wave speed moves by half as much): a supplier's modulus is good to 2-3 %, a wave speed timed on the
  bar to 1 %. The bar's force per microstrain and the wave's travel to its gauge both change. The input
  bar is left out: its measured wave drives the simulation, transported to the cell once.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy import stats

from ..models.measurement_chain import Reading
from ..models.parameters import Parameter

Apply = Callable[[Mapping[str, float], dict[str, Any], dict[str, Reading], str | None], None]
"""apply(values, settings, readings, channel): edit the simulator settings and the gauges' measurement chains
(channel -> :class:`~friction_uq.models.measurement_chain.Reading`) in place."""


@dataclass(frozen=True)
class Context:
    """Stationary-window means a mechanism needs to state its effective f: sliding speed V (m/s), wall shear
    stress tau_mean (Pa, eq. 18 from F_eo), slip (m)."""

    V: float
    tau_mean: float
    slip: float


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

    def prior_z(self) -> dict[str, tuple[float, float]]:
        """Gaussian stand-ins of the priors in each parameter's unbounded coordinate (centre, sd), from the
        prior's 16 % and 84 % quantiles: what the mode search uses (the exact prior weighs the draws)."""
        return {p.name: p.gaussian_stand_in(self.priors[p.name]) for p in self.parameters}

    def log_prior(self, values: Mapping[str, float]) -> float:
        return float(sum(self.priors[p.name].logpdf(values[p.name]) for p in self.parameters))

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


def _law(settings: dict[str, Any], law: str, **params: float) -> None:
    settings["friction_law"] = law
    settings["friction_params"] = MappingProxyType({k: float(v) for k, v in params.items()})


def _lognormal(median: float, sd_log: float) -> Any:
    return stats.lognorm(s=sd_log, scale=median)


F_S = Parameter("f_s", "-", 0.0, 2.0, "friction coefficient at rest (zero sliding speed, or before any slip)")

register(Mechanism(
    name="velocity_friction",
    meaning="the wall's friction coefficient depends on the sliding speed: f(V) = f + (f_s - f) exp(-V / v_c)",
    signature="F_eo/F_io changes with V during the rise (while the sample speeds up) and across tests at "
              "different striker speeds",
    parameters=(F_S, Parameter("v_c", "m/s", 0.0, math.inf, "characteristic sliding speed of the change")),
    priors={"f_s": stats.halfnorm(scale=0.3), "v_c": _lognormal(5.0, 1.0)},
    start={"f_s": 0.08, "v_c": 5.0},
    apply=lambda v, s, g, ch: _law(s, "velocity", f_s=v["f_s"], f_d=v["f"], v_c=v["v_c"]),
    f_effective=lambda v, c: v["f"] + (v["f_s"] - v["f"]) * np.exp(-c.V / v["v_c"]),
    group="friction_law",
))

register(Mechanism(
    name="pressure_friction",
    meaning="the interface's shear strength saturates with pressure: tau = f p / (1 + p / p0)",
    signature="the apparent f falls as the load rises: F_eo/F_io depends on the load level (rise vs plateau)",
    parameters=(Parameter("p0", "Pa", 0.0, math.inf, "pressure at which the friction coefficient has halved"),),
    priors={"p0": _lognormal(2e8, 1.5)},
    start={"p0": 1e9},
    apply=lambda v, s, g, ch: _law(s, "hyperbolic", f0=v["f"], p0=v["p0"]),
    # at the window's shear stress: tau = f p / (1 + p/p0) gives tau / p = f - tau / p0
    f_effective=lambda v, c: np.maximum(v["f"] - c.tau_mean / v["p0"], 0.0),
    group="friction_law",
))

register(Mechanism(
    name="slip_friction",
    meaning="friction changes with slip: f = f + (f_s - f) max(0, 1 - d / d_c), the friction drop at the start",
    signature="F_eo/F_io high at the first slip, then drifting down to its plateau value",
    parameters=(F_S, Parameter("d_c", "m", 0.0, math.inf, "slip over which the coefficient changes")),
    priors={"f_s": stats.halfnorm(scale=0.3), "d_c": _lognormal(1e-3, 1.0)},
    start={"f_s": 0.08, "d_c": 1e-3},
    apply=lambda v, s, g, ch: _law(s, "slip_weakening", f_s=v["f_s"], f_d=v["f"], d_c=v["d_c"]),
    f_effective=lambda v, c: v["f"] + (v["f_s"] - v["f"]) * np.maximum(0.0, 1.0 - c.slip / v["d_c"]),
    group="friction_law",
))


def _clearance(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
    s["gap"] = float(v["gap"])
    s["tube_compliance"] = True


register(Mechanism(
    name="clearance",
    meaning="a radial clearance between sample and tube, with the tube bore's compliance: the wall pressure "
            "starts only once the sample has closed the gap, then is less than nu/(1-nu) sigma",
    signature="the hoop gauge starts late and reads low; F_eo/F_io depends on the load level; eq. 17 reads f low",
    parameters=(Parameter("gap", "m", 0.0, 1e-4, "radial clearance sample/tube"),),
    priors={"gap": stats.halfnorm(scale=20e-6)},
    start={"gap": 3e-6},
    apply=_clearance,
))


def _plug(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
    s["plug_friction_force"] = float(v["plug_force"])
    s["plug_friction_coefficient"] = float(v["plug_coefficient"])


register(Mechanism(
    name="plug_friction",
    meaning="parasitic friction of the plug on the tube: a force that reaches the tube and the external bar "
            "without passing through the sample",
    signature="F_eo too high for the sample's friction through the whole loading; the hoop gauge does not follow",
    parameters=(Parameter("plug_force", "N", 0.0, 1e5, "constant part of the plug/tube friction"),
                Parameter("plug_coefficient", "-", 0.0, 1.0, "plug/tube friction per newton of input force")),
    priors={"plug_force": stats.halfnorm(scale=500.0), "plug_coefficient": stats.halfnorm(scale=0.03)},
    start={"plug_force": 50.0, "plug_coefficient": 0.003},
    apply=_plug,
))


def _gain(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
    if ch is None:
        raise ValueError("gauge_gain acts on one gauge: give its channel")
    g[ch].gain = float(v["gain"])


register(Mechanism(
    name="gauge_gain",
    meaning="a calibration error on one bar gauge: its reading is the true strain times a gain",
    signature="the equilibrium F_i = F_eo + F_io broken by a constant factor; one channel off by a constant ratio",
    parameters=(Parameter("gain", "-", 0.0, 10.0, "recorded / true strain of the gauge"),),
    priors={"gain": _lognormal(1.0, 0.1)},
    start={"gain": 1.0},
    apply=_gain,
    channels=("input_bar", "internal_output_bar", "external_output_bar"),
))

register(Mechanism(
    name="dispersion",
    meaning="Pochhammer-Chree dispersion of the waves along the bars, which the 1-D bar model ignores",
    signature="oscillations after each front and smeared fronts, strongest on the reflected wave and the solid "
              "bars' rise",
    parameters=(),
    priors={},
    start={},
    apply=lambda v, s, g, ch: s.__setitem__("dispersion", True),
))

register(Mechanism(
    name="end_friction",
    meaning="friction on the sample's end faces (the PTFE sheets not frictionless) holds back its radial "
            "expansion near the faces",
    signature="a lower F_eo/F_io than eq. 13 gives for the same f (eq. 17 reads f low) and a smaller hoop "
              "signal; the cell's equilibrium unchanged",
    parameters=(Parameter("f_e", "-", 0.0, 1.0, "friction coefficient of the end faces"),),
    priors={"f_e": stats.halfnorm(scale=0.25)},
    start={"f_e": 0.01},
    apply=lambda v, s, g, ch: s.__setitem__("end_friction", float(v["f_e"])),
))


#: The gauges read against the input bar's (its reading drives the simulation), and the outputs' own
OUTPUT_GAUGES = ("internal_output_bar", "external_output_bar", "tube_hoop")
ALL_GAUGES = ("input_bar", *OUTPUT_GAUGES)


def _chain_fault(name: str, field: str, gauges: tuple[str, ...], *, unit: str, low: float, prior: Any, start: float,
                 what: str, meaning: str, signature: str, scale: float = 1.0) -> Mechanism:
    """A measurement-chain fault fitted on every gauge of ``gauges`` at once: one parameter ``<field>_<gauge>`` per
    gauge (the :class:`~friction_uq.models.measurement_chain.Reading` field it sets; ``what``: its meaning, with
    ``{gauge}`` for the gauge), the same prior and start for each."""
    def apply(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
        for gauge in gauges:
            setattr(g[gauge], field, float(v[f"{field}_{gauge}"]))

    return Mechanism(
        name=name, meaning=meaning, signature=signature,
        parameters=tuple(Parameter(f"{field}_{c}", unit, low, math.inf, what.format(gauge=c), scale=scale)
                         for c in gauges),
        priors={f"{field}_{c}": prior for c in gauges}, start={f"{field}_{c}": start for c in gauges},
        apply=apply, per_gauge=gauges)


register(_chain_fault(
    "zero_drift", "drift", ALL_GAUGES, unit="1/s", low=-math.inf, prior=stats.norm(0.0, 0.01), start=0.0,
    scale=1e-2, what="zero drift of {gauge} (strain per second)",
    meaning="a gauge's zero drifting through the record: the channel reads the strain plus rate x time",
    signature="a residual growing steadily with time on one channel, before the waves as after them"))

register(_chain_fault(
    "channel_timing", "delay", OUTPUT_GAUGES, unit="s", low=-math.inf, prior=stats.norm(0.0, 2e-6), start=0.0,
    scale=1e-6, what="delay of {gauge} against the input bar",
    meaning="a channel read late or early against the input bar's: a gauge not where the header puts it, or "
            "digitisers triggered apart",
    signature="residuals shaped like the derivative of the wave at every front of one channel, opposite in sign "
              "at its rise and its fall"))

register(_chain_fault(
    "bandwidth", "time_constant", OUTPUT_GAUGES, unit="s", low=0.0, prior=stats.halfnorm(scale=1e-6), start=0.1e-6,
    what="low-pass time constant of {gauge}",
    meaning="an amplifier too slow for the waves: a gauge's reading through a low-pass (equivalent first-order "
            "time constant)",
    signature="fronts of one channel late and rounded, the plateau right: residuals at every front, none between"))


def _bar_modulus(v: Mapping[str, float], s: dict[str, Any], g: dict[str, Reading], ch: str | None) -> None:
    app = s["apparatus"]
    for name in OUTPUT_BARS:
        k = float(v[f"modulus_factor_{name}"])
        bar = getattr(app, name)
        app = replace(app, **{name: replace(bar, young_modulus=bar.young_modulus * k,
                                            wave_speed=bar.wave_speed * math.sqrt(k))})
    s["apparatus"] = app


OUTPUT_BARS = ("internal_output_bar", "external_output_bar")

register(Mechanism(
    name="bar_modulus",
    meaning="an output bar's modulus (and with it its wave speed) not the header's: its force per microstrain "
            "and the wave's travel time to its gauge both off",
    signature="one output channel scaled by a constant factor and its fronts early or late by a fraction of a "
              "microsecond per per cent",
    parameters=tuple(Parameter(f"modulus_factor_{b}", "-", 0.0, math.inf, f"Young's modulus of the {b} over the "
                               "header's") for b in OUTPUT_BARS),
    priors={f"modulus_factor_{b}": _lognormal(1.0, 0.03) for b in OUTPUT_BARS},
    start={f"modulus_factor_{b}": 1.0 for b in OUTPUT_BARS},
    apply=_bar_modulus,
    per_gauge=OUTPUT_BARS,
    neutral=1.0,
))
