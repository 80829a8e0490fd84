"""Simulation configuration: one TOML file describes one synthetic test.

Every section and key is optional; what is left out takes the default shown (the paper's
set-up, Coulomb friction f = 0.05, nu = 0.4, V_s = 10 m/s, no noise). Units are SI. A key or
section that is not listed here (a typo), a value of the wrong type or out of range, or an
unknown friction law is refused with a :class:`~friction_uq.errors.ConfigError` that names the
file and the key.

.. code-block:: toml

    [record]
    test_id = "A-01"           # written to the record
    campaign = "A"
    description = "..."         # optional
    date = "2024-05-02"         # optional, ISO 8601
    dtype = "float32"           # float32 | float64 (default float64)
    seed = 101                  # optional integer >= 0; simulate(..., seed=N) overrides it

    [loading]
    striker_velocity = 10.0     # m/s, [0.1, 100]
    rise_time = 20e-6           # s, rise (and fall) of the trapezoidal incident wave, (0, 1e-4]

    [sample]
    poisson_ratio = 0.4         # [0.01, 0.49]; E, density, size go under [apparatus.sample]

    [friction]                  # sample/tube wall; the parameters depend on the law
    law = "coulomb"             # coulomb: f | velocity: f_s f_d v_c | pressure: f tau_max
    f = 0.05                    # hyperbolic: f0 p0 | slip_weakening: f_s f_d d_c | velocity_stretched: f_s f_d
                                # v_c n | pressure_saturating: f0 p0 n | slip_power: f_s f_d d_c n (friction.py)

    [cell]
    gap = 0.0                   # radial clearance sample/tube, m, [0, 1e-4]
    tube_compliance = false     # bore compliance C_t in the wall pressure (docs/physics.md section 6)
    tube_density = 7850.0       # kg/m^3 (tube mass for its axial motion)
    hoop_beta = 192.0           # 1/m, decay rate of the hoop influence function (fitted for the paper's tube:
                                # a = 5 mm, b = 12 mm, nu_t = 0.29; set it for another tube)
    hoop_axial_term = true      # add nu_t x (axial tube force) / (E_t A_t) to the hoop strain (docs/physics.md section 6)
    plug_friction_force = 0.0   # N, constant part of the plug/tube friction strength
    plug_friction_coefficient = 0.0   # plug/tube friction strength per newton of F_i, [0, 1]
    end_friction = 0.0          # friction coefficient of the sample's end faces (PTFE sheets), [0, 1]

    [bars]
    dispersion = false          # Pochhammer-Chree dispersion on every bar leg

    [measurement]
    sample_rate = 5e6           # Hz, [1e5, 1e9]
    duration = 1.3e-3           # s, record length
    pretrigger = 80e-6          # s, from the record start to the incident wave's foot at the input gauge

    [channels.input_bar]        # also internal_output_bar, external_output_bar, tube_hoop
    enabled = true              # false drops the channel (only tube_hoop may be dropped)
    units = "strain"            # strain | microstrain | V
    strain_per_volt = 2e-4      # required with units = "V"
    gain = 1.0                  # gauge factor error: recorded = gain x true strain, (0, 10]
    offset = 0.0                # baseline offset, strain
    white = 0.0                 # white noise standard deviation, strain
    ar1 = 0.0                   # AR(1) noise standard deviation (stationary), strain
    ar1_coef = 0.0              # AR(1) coefficient, [0, 0.999]
    quantum = 0.0               # digitiser step, strain per count (0: none)

    [numerics]
    elements = 20               # sample elements, [4, 400]
    cfl = 0.8                   # time step as a fraction of the column's stability limit, (0, 1]
    damping = 0.2               # artificial viscosity: damping ratio of the column's highest mode, [0, 1]

    [model]                     # which simulator: fidelity = "1d" (default) | "axisymmetric", and the
    fidelity = "1d"             # axisymmetric model's mesh and contacts (friction_uq/simulate/axisymmetric/settings.py)

    [apparatus.input_bar]       # overrides of record.paper_apparatus(), per part and attribute:
    length = 2.5                # striker, input_bar, internal_output_bar (diameter, young_modulus,
                                # wave_speed, length, gauge_distance, poisson_ratio),
                                # external_output_bar (outer_diameter, inner_diameter, ...),
                                # tube, sample, plug (the record contract's attribute names)

The plug is optional in the record contract; the simulator always has one (default 10 mm of
steel, E = 200 GPa, rho = 7800 kg/m^3, the tube's bore diameter) and writes it to the record.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from datetime import datetime as _datetime
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ..errors import ConfigError
from ..physics.tube import BETA_EFF_PAPER_TUBE
from ..plausible import MAX_ATTRIBUTE_BYTES, MAX_ID_CHARS, MAX_SIMULATED_SAMPLES, RANGES, apparatus_problem
from ..record import CHANNELS, UNITS, Apparatus, Plug, paper_apparatus
from ._checks import Section
from .apparatus import check_consistency, parse_apparatus
from .axisymmetric.settings import ModelSettings, check_sizes, parse_model
from .friction import LAWS

DEFAULT_PLUG = Plug(length=0.01, young_modulus=200e9, density=7800.0)
SECTIONS = ("record", "loading", "sample", "friction", "cell", "bars", "measurement", "channels",
            "numerics", "apparatus", "model")


@dataclass(frozen=True)
class ChannelSpec:
    """Measurement chain of one gauge (strains and noise levels in strain, compression positive)."""

    enabled: bool = True
    units: str = "strain"
    strain_per_volt: float | None = None
    gain: float = 1.0
    offset: float = 0.0
    white: float = 0.0
    ar1: float = 0.0
    ar1_coef: float = 0.0
    quantum: float = 0.0


def _default_channels() -> Mapping[str, ChannelSpec]:
    return MappingProxyType({name: ChannelSpec() for name in CHANNELS})


def default_apparatus() -> Apparatus:
    """:func:`record.paper_apparatus` with the simulator's default plug."""
    return replace(paper_apparatus(), plug=DEFAULT_PLUG)


@dataclass(frozen=True)
class SimulationConfig:
    """Everything one simulated test needs (see the module docstring for the TOML names)."""

    test_id: str = "SIM-01"
    campaign: str = "SIM"
    description: str | None = None
    date: str | None = None
    dtype: str = "float64"
    seed: int | None = None
    striker_velocity: float = 10.0
    rise_time: float = 20e-6
    poisson_ratio: float = 0.4
    friction_law: str = "coulomb"
    friction_params: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({"f": 0.05}))
    gap: float = 0.0
    tube_compliance: bool = False
    tube_density: float = 7850.0
    hoop_beta: float = BETA_EFF_PAPER_TUBE
    hoop_axial_term: bool = True
    plug_friction_force: float = 0.0
    plug_friction_coefficient: float = 0.0
    end_friction: float = 0.0
    dispersion: bool = False
    sample_rate: float = 5e6
    duration: float = 1.3e-3
    pretrigger: float = 80e-6
    channels: Mapping[str, ChannelSpec] = field(default_factory=_default_channels)
    elements: int = 20
    cfl: float = 0.8
    damping: float = 0.2
    min_substeps: int = 1  # not a TOML key: fits fix the time step so the output is smooth in the parameters
    apparatus: Apparatus = field(default_factory=default_apparatus)
    model: ModelSettings = field(default_factory=ModelSettings)
    source: str = "<config>"


def load_config(path: str | Path) -> SimulationConfig:
    """Read and check a TOML simulation configuration (format: this module's docstring).

    Raises
    ------
    ConfigError
        One sentence naming the file, the key and the problem.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{p}: configuration file not found.") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{p}: cannot be read ({exc}).") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: is not valid TOML ({exc}).") from None
    return parse_config(data, source=str(p))


def parse_config(data: Mapping[str, Any], *, source: str = "<config>") -> SimulationConfig:
    """Build a :class:`SimulationConfig` from the parsed TOML tables (checks as :func:`load_config`)."""
    if not isinstance(data, Mapping):
        raise ConfigError(f"{source}: a simulation configuration is a table of sections, got {type(data).__name__}")
    for name in data:
        if name not in SECTIONS:
            raise ConfigError(f"{source}: unknown section [{name}]; allowed sections: {', '.join(SECTIONS)}.")
    d = SimulationConfig()
    kw: dict[str, Any] = {"source": source}

    s = Section(source, "record", data.get("record", {}),
                ("test_id", "campaign", "description", "date", "dtype", "seed"))
    kw["test_id"] = s.string("test_id", d.test_id, max_chars=MAX_ID_CHARS)  # what the reader takes back
    kw["campaign"] = s.string("campaign", d.campaign, max_chars=MAX_ID_CHARS)
    kw["description"] = s.string("description", None, max_bytes=MAX_ATTRIBUTE_BYTES, free_text=True)
    kw["date"] = s.string("date", None)
    if kw["date"] is not None:
        try:
            _datetime.fromisoformat(kw["date"])  # as the record reader reads it back
        except ValueError:
            raise s.fail("date", f"is {kw['date']!r}, not an ISO 8601 date such as '2024-05-02'") from None
    kw["dtype"] = s.string("dtype", d.dtype, choices=("float32", "float64"))
    kw["seed"] = s.integer("seed", None, low=0, high=2**63 - 1)

    s = Section(source, "loading", data.get("loading", {}), ("striker_velocity", "rise_time"))
    # the lower bounds are the record reader's (friction_uq.plausible): what is simulated can be read back
    kw["striker_velocity"] = s.number("striker_velocity", d.striker_velocity, low=RANGES["striker_velocity"][0],
                                      high=100.0)
    kw["rise_time"] = s.number("rise_time", d.rise_time, low=0.0, high=1e-4, low_open=True)

    s = Section(source, "sample", data.get("sample", {}), ("poisson_ratio",))
    kw["poisson_ratio"] = s.number("poisson_ratio", d.poisson_ratio, low=0.01, high=0.49)

    kw["friction_law"], kw["friction_params"] = _friction(source, data.get("friction", {}))

    s = Section(source, "cell", data.get("cell", {}), (
        "gap", "tube_compliance", "tube_density", "hoop_beta", "hoop_axial_term",
        "plug_friction_force", "plug_friction_coefficient", "end_friction"))
    kw["gap"] = s.number("gap", d.gap, low=0.0, high=1e-4)
    kw["tube_compliance"] = s.boolean("tube_compliance", d.tube_compliance)
    kw["tube_density"] = s.number("tube_density", d.tube_density, low=0.0, high=3e4, low_open=True)
    kw["hoop_beta"] = s.number("hoop_beta", d.hoop_beta, low=0.0, high=1e5, low_open=True)
    kw["hoop_axial_term"] = s.boolean("hoop_axial_term", d.hoop_axial_term)
    kw["plug_friction_force"] = s.number("plug_friction_force", d.plug_friction_force, low=0.0, high=1e6)
    kw["plug_friction_coefficient"] = s.number("plug_friction_coefficient", d.plug_friction_coefficient,
                                               low=0.0, high=1.0)
    kw["end_friction"] = s.number("end_friction", d.end_friction, low=0.0, high=1.0)

    s = Section(source, "bars", data.get("bars", {}), ("dispersion",))
    kw["dispersion"] = s.boolean("dispersion", d.dispersion)

    s = Section(source, "measurement", data.get("measurement", {}), ("sample_rate", "duration", "pretrigger"))
    kw["sample_rate"] = s.number("sample_rate", d.sample_rate, low=RANGES["signals.sample_rate"][0], high=1e9)
    kw["duration"] = s.number("duration", d.duration, low=0.0, high=0.1, low_open=True)
    kw["pretrigger"] = s.number("pretrigger", d.pretrigger, low=0.0, high=0.1)

    kw["channels"] = _channels(source, data.get("channels", {}))

    s = Section(source, "numerics", data.get("numerics", {}), ("elements", "cfl", "damping"))
    kw["elements"] = s.integer("elements", d.elements, low=4, high=400)
    kw["cfl"] = s.number("cfl", d.cfl, low=0.0, high=1.0, low_open=True)
    kw["damping"] = s.number("damping", d.damping, low=0.0, high=1.0)

    kw["apparatus"] = parse_apparatus(source, data.get("apparatus", {}), default_apparatus())
    kw["model"] = parse_model(source, data.get("model", {}))
    cfg = SimulationConfig(**kw)
    n_samples = cfg.sample_rate * cfg.duration
    if n_samples > MAX_SIMULATED_SAMPLES:
        raise ConfigError(f"{source}: key 'measurement.duration' x 'measurement.sample_rate' = {n_samples:.3g} samples "
                          f"per channel, more than the {MAX_SIMULATED_SAMPLES} a record may have (docs/limits.md).")
    implausible = apparatus_problem(cfg.apparatus)
    if implausible:
        part, attr, problem = implausible
        raise ConfigError(f"{source}: key 'apparatus.{part}.{attr}' {problem}.")
    check_consistency(cfg.apparatus, source=cfg.source, rise_time=cfg.rise_time,
                      pretrigger=cfg.pretrigger, duration=cfg.duration)
    if cfg.model.axisymmetric:
        check_sizes(cfg.model, cfg.apparatus, source=cfg.source)
    return cfg


def _friction(source: str, table: Any) -> tuple[str, Mapping[str, float]]:
    if not isinstance(table, Mapping):
        raise ConfigError(f"{source}: [friction] must be a table, got {table!r}.")
    law_name = table.get("law", "coulomb")
    if not isinstance(law_name, str):  # a list or a table is not a name (and not hashable)
        raise ConfigError(f"{source}: key 'friction.law' must be a string, got {law_name!r}.")
    if law_name not in LAWS:
        raise ConfigError(f"{source}: key 'friction.law' is {law_name!r}, allowed values: {', '.join(LAWS)}.")
    law = LAWS[law_name]
    s = Section(source, "friction", table, ("law",) + law.param_names)
    if law_name == "coulomb" and "f" not in table:
        return law_name, MappingProxyType({"f": 0.05})
    params = {}
    for p in law.params:
        if p.name not in table:
            raise s.fail(p.name, f"is missing; law {law_name!r} needs {', '.join(law.param_names)}")
        params[p.name] = s.number(p.name, None, low=p.low, high=p.high, low_open=p.low_open)
    return law_name, MappingProxyType(params)


def _channels(source: str, table: Any) -> Mapping[str, ChannelSpec]:
    if not isinstance(table, Mapping):
        raise ConfigError(f"{source}: [channels] must be a table of [channels.NAME] tables.")
    out = dict(_default_channels())
    names = [f.name for f in fields(ChannelSpec)]
    for name, sub in table.items():
        if name not in CHANNELS:
            raise ConfigError(f"{source}: unknown section [channels.{name}]; allowed channels: {', '.join(CHANNELS)}.")
        s = Section(source, f"channels.{name}", sub, names)
        spec = ChannelSpec(
            enabled=s.boolean("enabled", True),
            units=s.string("units", "strain", choices=tuple(UNITS)),
            strain_per_volt=s.number("strain_per_volt", math.nan, low=RANGES["signals.strain_per_volt"][0],
                                     high=RANGES["signals.strain_per_volt"][1])  # the reader's range
            if "strain_per_volt" in s else None,
            gain=s.number("gain", 1.0, low=0.0, high=10.0, low_open=True),
            offset=s.number("offset", 0.0, low=-1e-2, high=1e-2),
            white=s.number("white", 0.0, low=0.0, high=1e-2),
            ar1=s.number("ar1", 0.0, low=0.0, high=1e-2),
            ar1_coef=s.number("ar1_coef", 0.0, low=0.0, high=0.999),
            quantum=s.number("quantum", 0.0, low=0.0, high=1e-3),
        )
        if spec.units == "V" and spec.strain_per_volt is None:
            raise s.fail("strain_per_volt", "is missing; units 'V' need it")
        if not spec.enabled and name != "tube_hoop":
            raise s.fail("enabled", "must be true: only tube_hoop is optional in the record contract")
        out[name] = spec
    return MappingProxyType(out)
