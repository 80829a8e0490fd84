"""Time-domain simulator of the confined friction test (striker, bars, plug, sample, tube, gauges).

Writes synthetic ``test.h5`` records with the physics that the paper's closed-form model leaves
out (docs/physics.md section 5): friction laws, radial clearance and tube compliance, parasitic plug
friction, gauge gain errors, bar dispersion, measurement noise.

Modules: :mod:`.config` (TOML format and checks), :mod:`.friction` (registry of friction laws),
:mod:`.cell` (time integration of plug, sample column and tube), :mod:`.bars` (bar legs and
gauges), :mod:`.hoop` (tube hoop gauge), :mod:`.model_1d` (the noise-free model),
:mod:`.measurement` (gains, offsets, noise, quantisation), :mod:`.simulation` (the public calls).

>>> from friction_uq.simulate import load_config, simulate, simulate_to_file   # doctest: +SKIP
>>> sim = simulate(load_config("data/configs/A-01.toml"), seed=1)              # doctest: +SKIP
>>> sim.noisy["internal_output_bar"], sim.force_external, sim.wall_pressure     # doctest: +SKIP
"""

from __future__ import annotations

from .config import ChannelSpec, SimulationConfig, load_config, parse_config
from .friction import LAWS
from .model_1d import ModelOutput, run_model
from .simulation import Simulation, simulate, simulate_to_file

__all__ = [
    "LAWS",
    "ChannelSpec",
    "ModelOutput",
    "Simulation",
    "SimulationConfig",
    "load_config",
    "parse_config",
    "run_model",
    "simulate",
    "simulate_to_file",
]
