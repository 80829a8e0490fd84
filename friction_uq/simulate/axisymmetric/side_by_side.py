"""The 1-D and the axisymmetric simulations of one configuration, side by side, per phase of the test.

Phases on the cell's time base (t_c: the incident wave's foot at the plug, T: pulse length, t_r:
rise time; the 1-D simulator's definitions):

* rise: [t_c, t_c + T/4) — loading and the cell's transient;
* stationary: the last quarter of the incident plateau, [t_c + t_r + 3 (T - t_r)/4, t_c + T];
* unloading: [t_c + T, t_c + 5 T/4).

Quantities per phase (means): F_io and F_eo at the cell (N), the hoop gauge (physical strain,
swelling positive) and the reflected wave at the input gauge (strain, tensile negative; read d_i /
c_i after the phase as it leaves the cell). :func:`figure15` gives the paper's figure 15 from the
axisymmetric forces (F_eo against F_io (exp(f beta) - 1), eq. 13); :func:`eq17_friction` reads f
back from the axisymmetric forces by eq. 17.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...physics.cell import beta, friction_from_ratio
from .. import bars
from ..config import SimulationConfig
from ..model_1d import ModelOutput, run_model
from .model_axisymmetric import AxisymmetricOutput, run_axisymmetric
from .settings import ModelSettings

PHASES = ("rise", "stationary", "unloading")
QUANTITIES = ("F_io", "F_eo", "hoop", "reflected")
UNITS = {"F_io": "N", "F_eo": "N", "hoop": "microstrain", "reflected": "microstrain"}


@dataclass(frozen=True)
class Comparison:
    """Both models' outputs on one configuration and their per-phase means.

    ``table``: phase -> quantity -> (1-D value, axisymmetric value) in the units of :data:`UNITS`.
    ``reflected``: model name ("1d", "axisymmetric") -> reflected wave at the input gauge (strain).
    """

    config: SimulationConfig
    one_d: ModelOutput
    axisymmetric: AxisymmetricOutput
    windows: dict[str, tuple[float, float]]
    table: dict[str, dict[str, tuple[float, float]]]
    reflected: dict[str, np.ndarray]

    def relative_difference(self, phase: str, quantity: str) -> float:
        """(axisymmetric - 1-D) / |1-D| of a phase's mean."""
        a, b = self.table[phase][quantity]
        return (b - a) / abs(a) if a != 0.0 else float("nan")


def phase_windows(config: SimulationConfig) -> dict[str, tuple[float, float]]:
    """Start and end (s, record time base) of each phase at the cell (module docstring)."""
    app = config.apparatus
    t_c = app.input_bar.gauge_distance / app.input_bar.wave_speed
    pulse, tr = app.pulse_duration, config.rise_time
    return {"rise": (t_c, t_c + pulse / 4), "stationary": (t_c + tr + 0.75 * (pulse - tr), t_c + pulse),
            "unloading": (t_c + pulse, t_c + 1.25 * pulse)}


def reflected_at_gauge(config: SimulationConfig, out: ModelOutput) -> np.ndarray:
    """Input gauge minus the incident wave (as the gauge reads it): the reflected wave (strain)."""
    app = config.apparatus
    dt = out.time[1] - out.time[0]
    eps_i = bars.incident_amplitude(config.striker_velocity, striker=app.striker, input_bar=app.input_bar)
    _, inc_gauge = bars.incident_waves(amplitude=eps_i, pulse_duration=app.pulse_duration,
                                       rise_time=config.rise_time, input_bar=app.input_bar,
                                       t_start=float(out.time[0]), dt=dt, n=out.time.size,
                                       dispersive=config.dispersion)
    return out.strains["input_bar"] - inc_gauge


def _mean(t: np.ndarray, x: np.ndarray, window: tuple[float, float]) -> float:
    m = (t >= window[0]) & (t < window[1])
    return float(x[m].mean())


def compare(config: SimulationConfig, *, element_size: float | None = None) -> Comparison:
    """Run the configuration with both simulators (the axisymmetric settings of its ``[model]`` table)."""
    ms = config.model
    if element_size is not None:
        ms = replace(ms, element_size=element_size)
    axi_cfg = replace(config, model=replace(ms, fidelity="axisymmetric"))
    one_cfg = replace(config, model=ModelSettings())
    one, two = run_model(one_cfg), run_axisymmetric(axi_cfg)
    windows = phase_windows(config)
    delay = config.apparatus.input_bar.gauge_delay
    refl = {"1d": reflected_at_gauge(config, one), "axisymmetric": reflected_at_gauge(config, two)}
    table: dict[str, dict[str, tuple[float, float]]] = {}
    for phase, w in windows.items():
        row = {}
        for name, get in (("F_io", lambda o: o.force_internal), ("F_eo", lambda o: o.force_external),
                          ("hoop", lambda o: -1e6 * o.strains.get("tube_hoop", np.zeros_like(o.time)))):
            row[name] = (_mean(one.time, get(one), w), _mean(two.time, get(two), w))
        shifted = (w[0] + delay, w[1] + delay)
        row["reflected"] = (1e6 * _mean(one.time, refl["1d"], shifted), 1e6 * _mean(two.time, refl["axisymmetric"],
                                                                                    shifted))
        table[phase] = row
    return Comparison(config=config, one_d=one, axisymmetric=two, windows=windows, table=table, reflected=refl)


def gauge_discrepancy(comp: Comparison) -> dict[str, dict[str, float]]:
    """RMS of (axisymmetric - 1-D) gauge strain per phase, as a fraction of the 1-D channel's peak.

    channel -> phase -> fraction. Each phase is read at the gauge: shifted by the gauge's delay from
    the cell (the hoop gauge sits on the tube: no shift). What a model tolerance of a whole-record
    check has to absorb when the 1-D model describes a test that the axisymmetric one made.
    """
    app = comp.config.apparatus
    delay = {name: bar.gauge_delay for name, bar in app.bars.items()}
    delay["tube_hoop"] = 0.0
    one, two = comp.one_d, comp.axisymmetric
    out: dict[str, dict[str, float]] = {}
    for name in ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"):
        if name not in one.strains or name not in two.strains:
            continue
        a, b = one.strains[name], two.strains[name]
        peak = float(np.max(np.abs(a)))
        out[name] = {}
        for phase, (t0, t1) in comp.windows.items():
            m = (one.time >= t0 + delay[name]) & (one.time < t1 + delay[name])
            out[name][phase] = float(np.sqrt(np.mean((b[m] - a[m]) ** 2)) / peak)
    return out


def stationary_profiles(comp: Comparison) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Stationary-phase profiles along the sample (z from the input face, m; Pa): name -> (z, value).

    ``axial axi``: the axisymmetric section-mean axial stress; ``wall axi`` and ``wall 1d``: the wall
    pressure of each model; ``wall eq20``: eq. 20 with p_mean = F_eo / (2 pi R L f) of the axisymmetric
    forces (Coulomb only); ``axial eq11``: sigma(L) exp(f beta (L - z) / L), sigma(L) = F_io / (pi R^2).
    """
    cfg, one, two = comp.config, comp.one_d, comp.axisymmetric
    sample = cfg.apparatus.sample
    length, radius = sample.length, sample.radius
    w = comp.windows["stationary"]

    def mean(out, series):
        m = (out.time >= w[0]) & (out.time < w[1])
        return series[m].mean(axis=0)

    p2 = mean(two, two.wall_pressure_nodes)
    p1 = mean(one, one.wall_pressure)
    out = {"axial axi": (two.row_z, mean(two, two.axial_stress)),
           "wall axi": (np.linspace(0.0, length, p2.size), p2),
           "wall 1d": ((np.arange(p1.size) + 0.5) * length / p1.size, p1)}
    if cfg.friction_law == "coulomb":
        f = float(cfg.friction_params["f"])
        fb = f * float(beta(cfg.poisson_ratio, radius=radius, length=length))
        z = np.linspace(0.0, length, 101)
        if f > 0.0:
            p_mean = mean(two, two.force_external) / (2 * np.pi * radius * length * f)
            out["wall eq20"] = (z, p_mean * fb * np.exp(fb * (length - z) / length) / np.expm1(fb))
        sigma_out = mean(two, two.force_internal) / (np.pi * radius**2)
        out["axial eq11"] = (z, sigma_out * np.exp(fb * (length - z) / length))
    return out


def figure15(config: SimulationConfig, out: ModelOutput, *, f: float) -> tuple[np.ndarray, np.ndarray]:
    """(F_eo, F_io (exp(f beta) - 1)) over time (N): the paper's figure 15 (eq. 13 with the model's F_io)."""
    sample = config.apparatus.sample
    fb = f * float(beta(config.poisson_ratio, radius=sample.radius, length=sample.length))
    return out.force_external, out.force_internal * np.expm1(fb)


def eq17_friction(config: SimulationConfig, out: ModelOutput) -> float:
    """f read back by eq. 17 from a model's stationary F_eo / F_io, with the configuration's nu."""
    w = phase_windows(config)["stationary"]
    ratio = _mean(out.time, out.force_external, w) / _mean(out.time, out.force_internal, w)
    sample = config.apparatus.sample
    return float(friction_from_ratio(ratio, config.poisson_ratio, radius=sample.radius, length=sample.length))
