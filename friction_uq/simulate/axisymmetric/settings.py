"""The ``[model]`` table of a simulation configuration: which simulator, and the axisymmetric one's settings.

.. code-block:: toml

    [model]
    fidelity = "1d"               # "1d" (default: the 1-D simulator) | "axisymmetric" (plug, sample, tube in (r, z))
    # the keys below are read by the axisymmetric model only
    element_size = 0.5e-3         # m, target edge of the 4-node rings of every body, (0, 2e-3]
    cfl = 0.8                     # time step as a fraction of the mesh's stability limit, (0, 1]
    time_step = 0.0               # s; 0: cfl x the limit; else this step, refused when above the limit
    hourglass = 0.05              # hourglass stiffness coefficient c_hg, [0, 0.5]
    damping = 0.3                 # stiffness-proportional damping: ratio of the mesh's highest mode, [0, 1]
    tube = true                   # false: no tube (verification: a free sample between two bars)
    plug_insertion = 5e-3         # m, length of the plug inside the tube at the start, [0, plug length)
    plug_clearance = 1e-5         # m, radial clearance plug/tube, [0, 1e-4]
    plug_friction = 0.0           # Coulomb coefficient of the plug on the bore (on its own wall pressure), [0, 1]
    sample_plasticity = "elastic" # "elastic" | "drucker_prager" (sigma_mises - alpha P < C, eq. 1)
    cohesion = 25e6               # Pa, C of Drucker-Prager (the paper's I1)
    dp_alpha = 0.64               # alpha of Drucker-Prager (the paper's I1)

Every other table means the same for both simulators: friction law (sample/tube wall), ``[cell]``
gap (sample/tube clearance), plug_friction_force / plug_friction_coefficient (a strength of the
plug/tube contact independent of its pressure, spread over the plug's length inside the tube),
end_friction (both end faces of the sample), tube_density; bars, loading, measurement and channels.
Keys of the 1-D approximations that the axisymmetric model computes instead (``tube_compliance``,
``hoop_beta``, ``hoop_axial_term``, ``[numerics]``) are read and ignored by it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ...record import Apparatus

from ...errors import ConfigError
from .._checks import Section

FIDELITIES = ("1d", "axisymmetric")
PLASTICITY = ("elastic", "drucker_prager")
KEYS = ("fidelity", "element_size", "cfl", "time_step", "hourglass", "damping", "tube", "plug_insertion",
        "plug_clearance", "plug_friction", "sample_plasticity", "cohesion", "dp_alpha")


@dataclass(frozen=True)
class ModelSettings:
    """The ``[model]`` table (module docstring)."""

    fidelity: str = "1d"
    element_size: float = 0.5e-3
    cfl: float = 0.8
    time_step: float = 0.0
    hourglass: float = 0.05
    damping: float = 0.3
    tube: bool = True
    plug_insertion: float = 5e-3
    plug_clearance: float = 1e-5
    plug_friction: float = 0.0
    sample_plasticity: str = "elastic"
    cohesion: float = 25e6
    dp_alpha: float = 0.64

    @property
    def axisymmetric(self) -> bool:
        return self.fidelity == "axisymmetric"


def parse_model(source: str, table: Any) -> ModelSettings:
    """Read the ``[model]`` table (ConfigError naming the key when a value is refused)."""
    d = ModelSettings()
    s = Section(source, "model", table if isinstance(table, Mapping) else table, KEYS)
    return ModelSettings(
        fidelity=s.string("fidelity", d.fidelity, choices=FIDELITIES),
        element_size=s.number("element_size", d.element_size, low=0.0, high=2e-3, low_open=True),
        cfl=s.number("cfl", d.cfl, low=0.0, high=1.0, low_open=True),
        time_step=s.number("time_step", d.time_step, low=0.0, high=1e-5),
        hourglass=s.number("hourglass", d.hourglass, low=0.0, high=0.5),
        damping=s.number("damping", d.damping, low=0.0, high=1.0),
        tube=s.boolean("tube", d.tube),
        plug_insertion=s.number("plug_insertion", d.plug_insertion, low=0.0, high=1.0),
        plug_clearance=s.number("plug_clearance", d.plug_clearance, low=0.0, high=1e-4),
        plug_friction=s.number("plug_friction", d.plug_friction, low=0.0, high=1.0),
        sample_plasticity=s.string("sample_plasticity", d.sample_plasticity, choices=PLASTICITY),
        cohesion=s.number("cohesion", d.cohesion, low=0.0, high=1e10, low_open=True),
        dp_alpha=s.number("dp_alpha", d.dp_alpha, low=0.0, high=3.0),
    )


#: Fewest elements across the sample's radius and along its length.
MIN_SAMPLE_ELEMENTS = 4


def _fail(source: str, key: str, problem: str) -> ConfigError:
    return ConfigError(f"{source}: key '{key}' {problem}.")


def check_sizes(ms: ModelSettings, app: Apparatus, *, source: str) -> None:
    """Refuse, naming the key, a mesh too coarse for the sample (fewer than 4 elements across its radius
    or along its length) and sizes that do not fit together (the plug inside the tube at least as long
    as the plug, plug and sample longer than the tube, the hoop gauge off the tube, a plug clearance
    as large as the bore). Geometry only: no mesh is built."""
    sample, tube, plug = app.sample, app.tube, app.plug
    h = ms.element_size
    radius, length = sample.radius, sample.length
    if radius / h < MIN_SAMPLE_ELEMENTS - 1e-9 or length / h < MIN_SAMPLE_ELEMENTS - 1e-9:
        raise _fail(source, "model.element_size", f"is {h * 1e3:g} mm, too coarse for the sample (radius "
                    f"{radius * 1e3:g} mm, length {length * 1e3:g} mm): it needs at least {MIN_SAMPLE_ELEMENTS} "
                    f"elements across its radius and along its length, an element size <= "
                    f"{min(radius, length) / MIN_SAMPLE_ELEMENTS * 1e3:g} mm")
    a = tube.inner_diameter / 2.0
    has_plug = plug is not None and plug.length > 0.0
    lp = plug.length if has_plug else 0.0
    if has_plug and ms.tube and ms.plug_insertion >= lp:
        raise _fail(source, "model.plug_insertion", f"is {ms.plug_insertion * 1e3:g} mm, not shorter than the plug "
                    f"({lp * 1e3:g} mm): the input bar pushes the plug's end outside the tube")
    z_t = -ms.plug_insertion if has_plug else 0.0
    if ms.tube and z_t + tube.length <= length:
        raise _fail(source, "apparatus.tube.length", f"is {tube.length * 1e3:g} mm, shorter than the plug inside it "
                    f"and the sample ({(length - z_t) * 1e3:g} mm)")
    z_gauge = 0.5 * length + tube.gauge_offset
    if ms.tube and not (z_t + 0.5 * tube.gauge_width <= z_gauge <= z_t + tube.length - 0.5 * tube.gauge_width):
        raise _fail(source, "apparatus.tube.gauge_offset", f"is {tube.gauge_offset * 1e3:g} mm, which puts the hoop "
                    f"gauge off the tube (plug inside the tube {ms.plug_insertion * 1e3:g} mm, tube "
                    f"{tube.length * 1e3:g} mm)")
    if has_plug and ms.plug_clearance >= a:
        raise _fail(source, "model.plug_clearance", f"is {ms.plug_clearance!r} m, not below the bore's radius {a!r} m")
