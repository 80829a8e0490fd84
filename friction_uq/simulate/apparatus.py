"""The [apparatus.PART] tables of a simulation configuration and the cross-checks between keys.

Overrides use the record contract's attribute names (docs/record-format.md) plus the bars'
optional ``poisson_ratio``; a part's other attributes keep :func:`.config.default_apparatus`'s
values.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields, replace
from typing import Any

from ..errors import ConfigError
from ..record import Apparatus, Bar, Plug, Sample, Tube
from ._checks import Section

#: Parts that are bars: their contract attribute ``diameter`` is :class:`~friction_uq.record.Bar`'s outer_diameter.
_BARS = ("striker", "input_bar", "internal_output_bar")
_BAR_KEYS = ("young_modulus", "wave_speed", "diameter", "length", "gauge_distance", "poisson_ratio")
_PARTS: dict[str, tuple[str, ...]] = {
    "striker": ("young_modulus", "wave_speed", "diameter", "length", "poisson_ratio"),
    "input_bar": _BAR_KEYS,
    "internal_output_bar": _BAR_KEYS,
    "external_output_bar": ("young_modulus", "wave_speed", "outer_diameter", "inner_diameter", "length",
                            "gauge_distance", "poisson_ratio"),
    "tube": tuple(f.name for f in fields(Tube)),
    "sample": tuple(f.name for f in fields(Sample)),
    "plug": tuple(f.name for f in fields(Plug)),
}


def parse_apparatus(source: str, table: Any, app: Apparatus) -> Apparatus:
    """``app`` with the overrides of the [apparatus.PART] tables (contract attribute names)."""
    if not isinstance(table, Mapping):
        raise ConfigError(f"{source}: [apparatus] must be a table of [apparatus.PART] tables.")
    for part, sub in table.items():
        if part not in _PARTS:
            raise ConfigError(f"{source}: unknown section [apparatus.{part}]; allowed parts: {', '.join(_PARTS)}.")
        s = Section(source, f"apparatus.{part}", sub, _PARTS[part])
        new: dict[str, Any] = {}
        for key in sub:
            if key == "material":
                new[key] = s.string(key, None)  # printable, as the reader wants it (a name finds a prior file)
            elif key == "poisson_ratio":
                new[key] = s.number(key, None, low=-1.0, high=0.499)
            elif key == "gauge_offset":
                new[key] = s.number(key, None, low=-1.0, high=1.0)
            else:
                new[key] = s.number(key, None, low=0.0, high=1e12, low_open=True)
        if "diameter" in new and part in _BARS:  # a bar's diameter is the contract's; its class has outer_diameter
            new["outer_diameter"] = new.pop("diameter")
        app = replace(app, **{part: replace(getattr(app, part), **new)})
    return app


def check_consistency(
    app: Apparatus, *, source: str, rise_time: float, pretrigger: float, duration: float
) -> None:
    """Cross-checks between keys (geometry, record length); ConfigError naming the key at fault.

    ``rise_time``, ``pretrigger`` and ``duration`` (s) are the configuration's loading and
    measurement keys; ``source`` names the configuration in the messages.
    """
    src = source

    def fail(key: str, problem: str) -> ConfigError:
        return ConfigError(f"{src}: key '{key}' {problem}.")

    for name in ("input_bar", "internal_output_bar", "external_output_bar"):
        bar: Bar = getattr(app, name)
        if bar.gauge_distance is None or bar.gauge_distance >= bar.length:
            raise fail(f"apparatus.{name}.gauge_distance", f"is {bar.gauge_distance!r} m, not inside the bar "
                       f"(length {bar.length!r} m)")
    eob = app.external_output_bar
    if eob.inner_diameter >= eob.outer_diameter or eob.inner_diameter <= app.internal_output_bar.outer_diameter:
        raise fail("apparatus.external_output_bar.inner_diameter", f"is {eob.inner_diameter!r} m, it must lie "
                   "between the internal output bar's diameter and the outer diameter")
    if app.tube.inner_diameter >= app.tube.outer_diameter:
        raise fail("apparatus.tube.inner_diameter", f"is {app.tube.inner_diameter!r} m, not below outer_diameter")
    if app.sample.diameter > app.tube.inner_diameter * (1 + 1e-9):
        raise fail("apparatus.sample.diameter", f"is {app.sample.diameter!r} m, larger than the tube's bore")
    if app.sample.length >= app.tube.length:
        raise fail("apparatus.sample.length", f"is {app.sample.length!r} m, not shorter than the tube")
    if abs(app.tube.gauge_offset) >= app.tube.length / 2:
        raise fail("apparatus.tube.gauge_offset", f"is {app.tube.gauge_offset!r} m, outside the tube")
    ib, st = app.input_bar, app.striker
    pulse = 2.0 * st.length / st.wave_speed
    if 2.0 * ib.length / ib.wave_speed <= pulse:
        raise fail("apparatus.striker.length", "makes the incident pulse longer than the input bar's "
                   "round trip; the model's free impact end needs a striker shorter than the input bar")
    if rise_time >= pulse / 2:
        raise fail("loading.rise_time", f"is {rise_time!r} s, not below half the pulse length {pulse:.3g} s")
    needed = pretrigger + 2.0 * ib.gauge_delay + pulse
    if duration < needed:
        raise fail("measurement.duration", f"is {duration * 1e6:.0f} us, too short: the reflected wave leaves "
                   f"the input gauge at pretrigger + 2 x gauge_distance / c + 2 x striker length / c_striker "
                   f"= {needed * 1e6:.0f} us")
