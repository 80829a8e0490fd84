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
(``f_effective``): the wall's coefficient at the stationary window's mean sliding speed, wall pressure
(nu / (1 - nu) times the sample's mean axial stress, eq. 19 and 21, at each draw's nu) or slip, so that f
under the extended model compares with the baseline's.

Priors (why these ranges):

* ``velocity_friction``: f_s ~ half-normal(0.3) like f; v_c ~ lognormal(median 5 m/s, sd of log 1):
  the speeds of the test.
* ``pressure_friction``: p0 ~ lognormal(median 200 MPa, sd of log 1.5): where f0 p meets the shear cap
  f0 p0 (at n = 1 f has halved there), the test's pressures are 50-200 MPa.
* ``slip_friction``: f_s ~ half-normal(0.3); d_c ~ lognormal(median 1 mm, sd of log 1): the
  sample slides ~5 mm.
* The friction families' shape, n_p, n_d ~ lognormal(median 1, sd of log 1). A family is a direction of change
  (down with pressure, with slip), not one formula: n = 1 is the simple law (the hyperbola in p, a straight drop
  in slip), and one sd either way bends it by a factor e, from a slow, power-like turn (n ~ 0.4) to a sharp one
  (n ~ 2.7: a shear cap in p, an exponential drop in slip when d_c is long). The velocity law keeps its simple
  exponential: a shape there left f at the window's speed far less determined on two pair records of the study
  (intervals of 0.029-0.24 and 0.013-0.063, docs/trust.md, fifty-sixth session) and named no velocity wall the
  simple law does not. A wall whose law is another monotone shape is then read by the
  direction it changes in, not by which formula happens to lie closest to it.
* ``clearance``: gap ~ half-normal(20 um): the paper quotes ~10 um of radial clearance.
* ``plug_friction``: force ~ half-normal(500 N), coefficient ~ half-normal(0.03) of F_i.
* ``gauge_gain``: gain ~ lognormal(0, 0.1): a bar gauge's calibration is rarely 10 % off.
* ``dispersion``: no parameter (the bars' geometry gives it); no candidate of an analysis with the dispersion
  correction (``--dispersion``), whose every model's bars already disperse.
* ``end_friction``: f_e ~ half-normal(0.25): PTFE on steel is 0.02-0.1, bare faces (a sheet torn or
  missing: explosive on steel) 0.3-0.5.

The measurement chain beside the gain (a zero drifting, a channel's timing, an amplifier's bandwidth, a bar's
modulus): :mod:`.chain_faults`, registered after the entries here. The registry itself (:class:`Mechanism`,
:class:`Context`, :func:`register`, :data:`MECHANISMS`): :mod:`.mechanism_registry`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy import stats

from ..models.measurement_chain import Reading
from ..models.parameters import Parameter
from .chain_faults import chain_faults
from .mechanism_registry import MECHANISMS, Context, Mechanism, lognormal, register

__all__ = ["MECHANISMS", "Context", "Mechanism", "register"]


def _law(settings: dict[str, Any], law: str, **params: float) -> None:
    settings["friction_law"] = law
    settings["friction_params"] = MappingProxyType({k: float(v) for k, v in params.items()})


F_S = Parameter("f_s", "-", 0.0, 2.0, "friction coefficient at rest (zero sliding speed, or before any slip)")


def _shape(name: str, what: str) -> Parameter:
    return Parameter(name, "-", 0.0, math.inf, f"shape of the change with {what} (1: the simple law)")


SHAPE_PRIOR = lognormal(1.0, 1.0)
#: the pressure family's further start, a cap: reached at this share of the window's mean wall pressure (so it binds
#: over the plateau), with a sharp corner (n_p two prior sds above the simple law's 1). A start, not a prior
CAP_START_SHARE = 0.5
CAP_START_SHAPE = 8.0


def power_weight(x: Any, n: Any) -> Any:
    """max(0, 1 - x)^n, x >= 0: the share of the change still to come at a scaled slip x = d / d_c."""
    return np.power(np.maximum(0.0, 1.0 - x), n)


def saturating_f(f0: Any, p: Any, p0: Any, n: Any) -> Any:
    """tau / p of the saturating wall, tau = f0 p / (1 + (p/p0)^n)^(1/n), at the wall pressure p (Pa): f0 at low
    pressure, f0 p0 / p on the cap. (1 + x^n)^(1/n) as exp(log(1 + exp(n log x)) / n), which neither overflows
    nor underflows whatever n.)"""
    with np.errstate(divide="ignore"):
        log_x = np.log(np.maximum(p, 0.0) / p0)
    return f0 * np.exp(-np.logaddexp(0.0, n * log_x) / n)


register(Mechanism(
    name="velocity_friction",
    meaning="the wall's friction coefficient depends on the sliding speed: f(V) = f + (f_s - f) exp(-V / v_c)",
    signature="F_eo/F_io changes with V during the rise (while the sample speeds up) and across tests at "
              "different striker speeds",
    parameters=(F_S, Parameter("v_c", "m/s", 0.0, math.inf, "characteristic sliding speed of the change")),
    priors={"f_s": stats.halfnorm(scale=0.3), "v_c": lognormal(5.0, 1.0)},
    start={"f_s": 0.08, "v_c": 5.0},
    apply=lambda v, s, g, ch: _law(s, "velocity", f_s=v["f_s"], f_d=v["f"], v_c=v["v_c"]),
    f_effective=lambda v, c: v["f"] + (v["f_s"] - v["f"]) * np.exp(-c.V / v["v_c"]),
    group="friction_law",
    companion="f_s",
))

register(Mechanism(
    name="pressure_friction",
    meaning="the interface's shear strength saturates with pressure: tau = f p / (1 + (p / p0)^n_p)^(1/n_p), "
            "from Coulomb at low pressure to a cap f p0",
    signature="the apparent f falls as the load rises: F_eo/F_io depends on the load level (rise vs plateau)",
    parameters=(Parameter("p0", "Pa", 0.0, math.inf, "pressure at which f p meets the shear cap f p0"),
                _shape("n_p", "pressure")),
    priors={"p0": lognormal(2e8, 1.5), "n_p": SHAPE_PRIOR},
    start={"p0": 1e9, "n_p": 1.0},
    apply=lambda v, s, g, ch: _law(s, "pressure_saturating", f0=v["f"], p0=v["p0"], n=v["n_p"]),
    # at the window's mean wall pressure, not at its shear stress: on the cap every pressure carries the same tau,
    # so tau alone leaves f anywhere between 0 and f0 (a capped wall's named model read f = 0 [0, 0] that way)
    f_effective=lambda v, c: saturating_f(v["f"], c.wall_pressure(v["nu"]), v["p0"], v["n_p"]),
    group="friction_law",
    uses_nu=True,
    # a cap reached below the window's pressure: from p0 = 1 GPa and n_p = 1 alone, the search stopped at a mild
    # hyperbola on a capped record, which slip friction then fitted better (docs/trust.md, fifty-fifth session)
    further_starts=lambda c, nu: ({"p0": CAP_START_SHARE * float(c.wall_pressure(nu)), "n_p": CAP_START_SHAPE},),
))

register(Mechanism(
    name="slip_friction",
    meaning="friction changes monotonically with slip: f = f + (f_s - f) max(0, 1 - d / d_c)^n_d, the friction "
            "drop at the start",
    signature="F_eo/F_io high at the first slip, then drifting down to its plateau value",
    parameters=(F_S, Parameter("d_c", "m", 0.0, math.inf, "slip by which the coefficient has reached f"),
                _shape("n_d", "slip")),
    priors={"f_s": stats.halfnorm(scale=0.3), "d_c": lognormal(1e-3, 1.0), "n_d": SHAPE_PRIOR},
    start={"f_s": 0.08, "d_c": 1e-3, "n_d": 1.0},
    apply=lambda v, s, g, ch: _law(s, "slip_power", f_s=v["f_s"], f_d=v["f"], d_c=v["d_c"], n=v["n_d"]),
    f_effective=lambda v, c: v["f"] + (v["f_s"] - v["f"]) * power_weight(c.slip / v["d_c"], v["n_d"]),
    group="friction_law",
    companion="f_s",
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
    priors={"gain": lognormal(1.0, 0.1)},
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


for _fault in chain_faults():  # after the cell's: the catalogue's order is the order diagnose fits in
    register(_fault)
