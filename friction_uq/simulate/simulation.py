"""One synthetic test: the noise-free model, the measurement chain, the record file.

Randomness: one ``numpy.random.default_rng(seed)`` per call, passed down explicitly; the seed
comes from the ``seed`` argument, else the configuration's ``record.seed``, else fresh entropy
(then recorded, so every file can be regenerated). The same seed gives bit-identical signals.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from ..physics.cell import beta as janssen_beta
from ..errors import check_seed
from ..record import write_record
from .config import SimulationConfig
from .measurement import measure
from .model_1d import ModelOutput, run_model

#: Version of the simulator's model, written to ``/provenance`` and ``/truth``.
MODEL_VERSION = "1"


@dataclass(frozen=True)
class Simulation:
    """A simulated test.

    ``clean``: true gauge strains (no gain, offset, noise); ``noisy``: as recorded (gain, offset,
    white + AR(1) noise, quantisation). Both compression positive, channel name -> array on
    ``model.time``. ``model`` holds the internal fields (interface forces, velocities, sliding,
    wall pressure history, momenta; see :class:`~.model.ModelOutput`).
    """

    config: SimulationConfig
    seed: int
    model: ModelOutput
    clean: dict[str, np.ndarray]
    noisy: dict[str, np.ndarray]
    truth: dict[str, Any]

    @property
    def time(self) -> np.ndarray:
        """Record time base (s): 0 at the incident wave's foot on the input gauge."""
        return self.model.time

    def __getattr__(self, name: str) -> Any:
        # internal fields straight from the model: sim.force_internal, sim.wall_pressure, ...
        if name != "model" and name in {f.name for f in fields(ModelOutput)}:
            return getattr(self.model, name)
        raise AttributeError(name)


def resolve_seed(seed: int | None, config: SimulationConfig) -> int:
    """The seed to use: the argument, else the configuration's, else fresh entropy (a 63-bit int)."""
    if seed is not None:
        return check_seed(seed, what="seed")  # one sentence (SeedError), the range numpy's SeedSequence takes
    if config.seed is not None:
        return config.seed
    return int(np.random.SeedSequence().entropy % (2**63))


def simulate(config: SimulationConfig, *, seed: int | None = None) -> Simulation:
    """Simulate one test: model, then measurement noise drawn from ``default_rng(seed)``."""
    seed = resolve_seed(seed, config)
    model = run_any(config)
    rng = np.random.default_rng(seed)
    noisy = measure(model.strains, config.channels, rng)
    return Simulation(config=config, seed=seed, model=model, clean=dict(model.strains), noisy=noisy,
                      truth=truth_attributes(config, seed=seed, model=model))


def run_any(config: SimulationConfig) -> ModelOutput:
    """The noise-free model the configuration asks for: 1-D (default) or axisymmetric (``[model] fidelity``)."""
    if config.model.axisymmetric:
        from .axisymmetric import run_axisymmetric

        return run_axisymmetric(config)
    return run_model(config)


def truth_attributes(config: SimulationConfig, *, seed: int, model: ModelOutput) -> dict[str, Any]:
    """The generating parameters, for the record's ``/truth`` group (scalars: float, int or str)."""
    t: dict[str, Any] = {
        "generator": "friction_uq.simulate",
        "model_version": MODEL_VERSION,
        "seed": int(seed),
        "poisson_ratio": config.poisson_ratio,
        "nu": config.poisson_ratio,
        "friction_law": config.friction_law,
        "striker_velocity": config.striker_velocity,
        "rise_time": config.rise_time,
        "incident_strain": model.incident_strain,
        "gap": config.gap,
        "tube_compliance": int(config.tube_compliance),
        "plug_friction_force": config.plug_friction_force,
        "plug_friction_coefficient": config.plug_friction_coefficient,
        "dispersion": int(config.dispersion),
        "hoop_beta": config.hoop_beta,
        "hoop_axial_term": int(config.hoop_axial_term),
        "tube_density": config.tube_density,
        "elements": config.elements,
        "time_step": model.time_step,
        "plateau_start": model.plateau[0],
        "plateau_end": model.plateau[1],
        "config_source": Path(config.source).name,
    }
    if config.model.axisymmetric:  # written only then, so 1-D records regenerate bit for bit
        t["fidelity"] = "axisymmetric"
        t["element_size"] = config.model.element_size
        t["plug_insertion"] = config.model.plug_insertion
        t["plug_clearance"] = config.model.plug_clearance
        t["plug_friction"] = config.model.plug_friction
        t["sample_plasticity"] = config.model.sample_plasticity
    if config.end_friction > 0.0:  # written only when present, so older records regenerate bit for bit
        t["end_friction"] = config.end_friction
    for k, v in config.friction_params.items():
        t[f"friction_{k}"] = float(v)
    if config.friction_law == "coulomb":
        t["f"] = float(config.friction_params["f"])
        sample = config.apparatus.sample
        t["janssen_beta"] = float(janssen_beta(config.poisson_ratio, radius=sample.radius, length=sample.length))
    for name, spec in config.channels.items():
        if name == "tube_hoop" and not spec.enabled:
            continue
        t[f"gain_{name}"] = spec.gain
        t[f"offset_{name}"] = spec.offset
        t[f"noise_white_sd_{name}"] = spec.white
        t[f"noise_ar1_sd_{name}"] = spec.ar1
        t[f"noise_sd_{name}"] = float(np.hypot(spec.white, spec.ar1))
        t[f"ar1_coef_{name}"] = spec.ar1_coef
        t[f"quantum_{name}"] = spec.quantum
    return t


def simulate_to_file(config: SimulationConfig, path: str | os.PathLike[str], *, seed: int | None = None) -> Path:
    """Simulate one test and write it with :func:`friction_uq.record.write_record`; returns the path."""
    sim = simulate(config, seed=seed)
    units = {name: spec.units for name, spec in config.channels.items() if name in sim.noisy}
    spv = {name: float(spec.strain_per_volt) for name, spec in config.channels.items()
           if name in sim.noisy and spec.units == "V" and spec.strain_per_volt is not None}
    return write_record(
        path,
        test_id=config.test_id,
        campaign=config.campaign,
        sample_rate=config.sample_rate,
        strains=sim.noisy,
        apparatus=config.apparatus,
        t0=float(sim.time[0]),
        units=units,
        strain_per_volt=spv,
        dtype=np.dtype(config.dtype).type,
        date=config.date,
        description=config.description,
        striker_velocity=config.striker_velocity,
        truth=sim.truth,
        provenance={"simulator_model_version": MODEL_VERSION, "seed": int(sim.seed)},
    )
