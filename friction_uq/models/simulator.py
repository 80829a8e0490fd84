"""The simulator of the whole test as a forward model with named parameters.

:class:`SimulatorModel` wraps :func:`friction_uq.simulate.model_1d.run_model`: given a record's
apparatus and a loading (the measured incident wave, :func:`.loading.measured_loading`, or a
trapezoid), it predicts what each gauge reads over the whole record for given parameter values:
the input-bar gauge (incident as given plus the simulated reflected wave), both output-bar gauges
and the tube hoop gauge, compression positive, on the record's time grid.

Parameters are addressed by name. The baseline (the paper's model: Coulomb friction, elastic
sample, rigid tube, frictionless plug, exact gauges, non-dispersive bars) has ``f``, ``nu`` and
``hoop_gain``. An extension adds parameters through ``extra`` and ``apply``: a function that
turns the parameter values into simulator settings (a friction law, a gap, a plug friction) and
into each gauge's measurement chain (:mod:`.measurement_chain`: a gain, a drift, a delay, a bandwidth)
— see :mod:`friction_uq.discrepancy.mechanisms`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from ..record import Apparatus
from ..simulate.config import DEFAULT_PLUG, ChannelSpec, SimulationConfig
from ..simulate.loading import Loading
from ..simulate.model_1d import run_model
from .measurement_chain import Reading, delayed
from .parameters import F, HOOP_GAIN, Parameter, ParameterSet

#: nu as the simulator takes it: below 0.49, where the confined modulus (and with it the column's
#: wave speed and the number of time steps) stays finite.
NU = Parameter("nu", "-", 0.0, 0.49, "Poisson ratio of the sample")

#: Gauge channels the simulator predicts.
GAUGES = ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop")

#: Time steps of the cell per record sample, at least: the stable step shrinks as nu approaches 0.5,
#: and a count that jumped from 1 to 2 inside a fit (near nu = 0.44 for I1) would make the
#: prediction jump too; 3 covers nu up to about 0.48 at the nominal modulus.
MIN_SUBSTEPS = 3

#: Settings -> (config, readings) hook of an extension.
Apply = Callable[[Mapping[str, float], dict[str, Any], dict[str, Reading]], None]


@dataclass(frozen=True)
class Prediction:
    """Simulated gauge strains (compression positive, channel -> array on the record grid) and the
    cell's interface forces (N) and sliding velocity (m/s) behind them."""

    strains: dict[str, np.ndarray]
    force_internal: np.ndarray
    force_external: np.ndarray
    force_input: np.ndarray
    sliding_velocity: np.ndarray


class SimulatorModel:
    """Forward model of the whole test (module docstring).

    Parameters
    ----------
    apparatus : Apparatus
        The record's apparatus (a plug of 10 mm of steel is assumed when the record has none).
    loading : Loading
        The incident wave driving the test.
    dispersive_loading : Loading, optional
        The same wave carried to the cell with Pochhammer-Chree dispersion (a measured wave: read at the
        gauge, it disperses on its way to the cell as every other leg does): it drives the configurations
        whose bars disperse (``dispersion``, here or set by ``apply``). Without it, ``loading`` drives them.
    hoop : bool
        Predict the tube hoop gauge.
    dispersion : bool
        Pochhammer-Chree dispersion on every bar leg.
    elements : int
        Sample elements of the simulator.
    extra : sequence of Parameter
        Parameters of an extension, after f, nu, hoop_gain.
    apply : callable
        ``apply(values, settings, readings)`` edits the simulator settings (a dict of
        :class:`~friction_uq.simulate.config.SimulationConfig` fields) and each gauge's measurement
        chain (channel -> :class:`~.measurement_chain.Reading`) for the values of the extension's
        parameters.
    """

    name = "simulator"

    def __init__(self, apparatus: Apparatus, loading: Loading, *, hoop: bool = True, dispersion: bool = False,
                 elements: int = 20, extra: tuple[Parameter, ...] = (), apply: Apply | None = None,
                 dispersive_loading: Loading | None = None) -> None:
        self.loading = loading
        self.dispersive_loading = dispersive_loading
        self.hoop = hoop
        self.parameters = ParameterSet((F, NU, HOOP_GAIN, *extra))
        self._apply = apply
        app = apparatus if apparatus.plug is not None else replace(apparatus, plug=DEFAULT_PLUG)
        channels = {name: ChannelSpec(enabled=(name != "tube_hoop" or hoop)) for name in GAUGES}
        dt = loading.sample_interval
        self._base = dict(
            apparatus=app, channels=MappingProxyType(channels), dispersion=dispersion, elements=elements,
            sample_rate=1.0 / dt, duration=len(loading.time) * dt, pretrigger=-float(loading.time[0]),
            min_substeps=MIN_SUBSTEPS,
        )

    def config(self, values: Mapping[str, float]) -> tuple[SimulationConfig, dict[str, Reading]]:
        """Simulator configuration and each gauge's measurement chain for one set of parameter values."""
        settings: dict[str, Any] = dict(self._base)
        settings["poisson_ratio"] = float(values["nu"])
        settings["friction_law"] = "coulomb"
        settings["friction_params"] = MappingProxyType({"f": float(values["f"])})
        readings = {name: Reading() for name in GAUGES}
        readings["tube_hoop"].gain = float(values.get("hoop_gain", 1.0))
        if self._apply is not None:
            self._apply(values, settings, readings)
        return SimulationConfig(**settings), readings

    def predict(self, values: Mapping[str, float], *, until: Mapping[str, int] | None = None) -> Prediction:
        """Gauge strains over the whole record for one set of parameter values.

        ``until`` (gauge -> samples): only each named gauge's first samples are asked for (a likelihood's spans);
        the simulation stops where they need it, a few samples' margin later, and the rest of every series, the
        forces and the sliding velocity too, is NaN (:func:`~friction_uq.simulate.model_1d.run_model`; the samples
        asked for are the whole run's to the bit). A dispersive configuration runs over the whole record."""
        cfg, readings = self.config(values)
        loading = self.dispersive_loading if cfg.dispersion and self.dispersive_loading is not None else self.loading
        dt = loading.sample_interval
        # a channel read early (a negative delay) shows at t what its gauge saw at t + |delay| (at most the record)
        span = len(loading.time) * dt
        asked = None if until is None or cfg.dispersion else \
            {c: k + math.ceil(min(max(0.0, -readings[c].delay), span) / dt) + 2 for c, k in until.items()}
        out = run_model(cfg, loading=true_incident(loading, readings["input_bar"]), until=asked)
        t = loading.time
        strains = {k: v if readings[k].exact else readings[k].applied(t, v) for k, v in out.strains.items()}
        return Prediction(strains, out.force_internal, out.force_external, out.force_input, out.sliding_velocity)

    def predict_draws(self, draws: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Gauge strains for each draw: channel -> array (ndraw, n)."""
        n_draw = len(next(iter(draws.values())))
        rows: dict[str, list[np.ndarray]] = {}
        for k in range(n_draw):
            pred = self.predict({name: float(v[k]) for name, v in draws.items()})
            for ch, s in pred.strains.items():
                rows.setdefault(ch, []).append(s)
        return {ch: np.array(v) for ch, v in rows.items()}


def true_incident(loading: Loading, reading: Reading) -> Loading:
    """The incident wave the input bar carried, from the wave its gauge read through ``reading``: the
    measured wave is ``gain`` times the true one, ``delay`` late. The chain's drift over the incident
    pulse (a few microstrain at most) and its bandwidth are left in the wave: the simulation is driven by
    the wave as the input gauge's amplifier passed it, and the other gauges' bandwidths are read against
    it (exactly so where the cell responds linearly to the wave's shape)."""
    if reading.gain == 1.0 and reading.delay == 0.0:
        return loading
    t = loading.time

    def back(x: np.ndarray) -> np.ndarray:
        return delayed(t, x, -reading.delay) / reading.gain

    return Loading(t, back(loading.at_gauge), back(loading.at_cell), loading.source)
