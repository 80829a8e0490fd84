"""The import set-up file (``SETUP.toml``): what the oscilloscope files hold and the apparatus they came from.

Tables (docs/import.md has the full description, ``friction-uq import --template`` prints an example)::

    [record]            test_id, campaign, optional date, description, striker_velocity (m/s)
    [time]              column (the time column, seconds unless ``units``) or sample_rate (Hz) and t0 (s);
                        may be left out for files that carry their time base (TDMS, LeCroy, Tektronix, Rigol)
    [apparatus.<part>]  the record contract's parts and attributes, SI units
    [channels.<gauge>]  column, optional file, units, strain_per_volt (or gauge_factor, bridge,
                        excitation, amplifier_gain), sign

Every problem is a :class:`~friction_uq.errors.SetupError` naming the file, the table and key, and
what is allowed.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

from ..errors import SetupError
from ..plausible import MAX_TEXT_BYTES, NotText, text_of, toml_shape_problem
from ..record.contract import CHANNELS, REQUIRED_CHANNELS

#: Largest set-up file read (bytes): every text input's (docs/limits.md)
MAX_SETUP_BYTES = MAX_TEXT_BYTES
#: Units a channel may be recorded in, and the factor to the unit stored in the record.
CHANNEL_UNITS = {"V": ("V", 1.0), "mV": ("V", 1e-3), "strain": ("strain", 1.0), "microstrain": ("microstrain", 1.0)}
#: Time column units and their factor to seconds.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "\u00b5s": 1e-6, "ns": 1e-9}
#: Bridge arrangement -> bridge factor k in V_out / V_excitation = k * gauge_factor * strain / 4.
BRIDGES = {"quarter": 1.0, "half": 2.0, "full": 4.0}

BAR_ATTRS = ("young_modulus", "wave_speed", "diameter", "length")
APPARATUS: dict[str, tuple[str, ...]] = {
    "striker": BAR_ATTRS,
    "input_bar": BAR_ATTRS + ("gauge_distance",),
    "internal_output_bar": BAR_ATTRS + ("gauge_distance",),
    "external_output_bar": ("young_modulus", "wave_speed", "outer_diameter", "inner_diameter", "length",
                            "gauge_distance"),
    "tube": ("young_modulus", "poisson_ratio", "inner_diameter", "outer_diameter", "length", "gauge_offset",
             "gauge_width"),
    "sample": ("material", "diameter", "length", "young_modulus", "density"),
}
OPTIONAL_PARTS = {"plug": ("length", "young_modulus", "density")}
#: Optional attributes of a part (an addition of this project to the contract).
OPTIONAL_ATTRS = {p: ("poisson_ratio",) for p in ("striker", "input_bar", "internal_output_bar", "external_output_bar")}

_RECORD_KEYS = ("test_id", "campaign", "date", "description", "striker_velocity")
_CHANNEL_KEYS = ("column", "file", "units", "sign", "strain_per_volt", "gauge_factor", "bridge", "excitation",
                 "amplifier_gain")


@dataclass(frozen=True)
class TimeSetup:
    """Where the time base comes from: a column (``column``, in ``units``) or a rate and a start."""

    column: str | int | None = None
    units: str = "s"
    sample_rate: float | None = None
    t0: float = 0.0


@dataclass(frozen=True)
class ChannelSetup:
    """One gauge: where its samples are, their unit and sign, and the volts-to-strain factor."""

    gauge: str
    column: str | int
    units: str
    sign: int
    file: str | None = None
    strain_per_volt: float | None = None
    conversion: dict[str, Any] = field(default_factory=dict)

    @property
    def stored_units(self) -> str:
        """The unit written to the record (millivolts are stored as volts)."""
        return CHANNEL_UNITS[self.units][0]

    @property
    def scale(self) -> float:
        """Factor from the file's numbers to :attr:`stored_units`."""
        return CHANNEL_UNITS[self.units][1]


@dataclass(frozen=True)
class Setup:
    """A checked ``SETUP.toml``."""

    path: Path
    record: dict[str, Any]
    time: TimeSetup | None
    apparatus: dict[str, dict[str, Any]]
    channels: dict[str, ChannelSetup]


def _fail(path: Path, key: str, problem: str) -> SetupError:
    return SetupError(f"{path}: {key}: {problem}")


def _table(path: Path, doc: dict, name: str, *, required: bool = True) -> dict | None:
    t = doc.get(name)
    if t is None:
        if required:
            raise _fail(path, f"[{name}]", "required table is missing (friction-uq import --template prints one)")
        return None
    if not isinstance(t, dict):
        raise _fail(path, name, f"must be a table [{name}], got {t!r}")
    return t


def _unknown(path: Path, where: str, table: dict, allowed: tuple[str, ...]) -> None:
    for key in table:
        if key not in allowed:
            raise _fail(path, f"{where} {key}", f"unknown key; allowed: {', '.join(allowed)}")


def _number(path: Path, key: str, value: object, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _fail(path, key, f"must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(path, key, f"must be finite, got {value!r}")
    if positive and x <= 0:
        raise _fail(path, key, f"must be > 0, got {value!r}")
    return x


def _string(path: Path, key: str, value: object) -> str:
    if not isinstance(value, str) or not value.strip():
        raise _fail(path, key, f"must be a non-empty string, got {value!r}")
    return value


def _record(path: Path, doc: dict) -> dict[str, Any]:
    t = _table(path, doc, "record")
    _unknown(path, "[record]", t, _RECORD_KEYS)
    out: dict[str, Any] = {}
    for key in ("test_id", "campaign"):
        if key not in t:
            raise _fail(path, f"[record] {key}", "missing (the test's name and its series, e.g. 'A-07' and 'A')")
        out[key] = _string(path, f"[record] {key}", t[key])
    if "date" in t:
        d = t["date"]
        text = d.isoformat() if hasattr(d, "isoformat") else d
        try:
            datetime.fromisoformat(str(text))
        except ValueError:
            raise _fail(path, "[record] date", f"is {d!r}, not an ISO 8601 date such as 2016-03-01") from None
        out["date"] = str(text)
    if "description" in t:
        if not isinstance(t["description"], str):
            raise _fail(path, "[record] description", f"must be a string, got {t['description']!r}")
        out["description"] = t["description"]
    if "striker_velocity" in t:
        out["striker_velocity"] = _number(path, "[record] striker_velocity", t["striker_velocity"], positive=True)
    return out


def _column(path: Path, key: str, value: object) -> str | int:
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise _fail(path, key, f"must be a column name (a string) or a 1-based column number, got {value!r}")
    if isinstance(value, int) and value < 1:
        raise _fail(path, key, f"column numbers start at 1, got {value}")
    if isinstance(value, str) and not value.strip():
        raise _fail(path, key, "must not be empty")
    return value


def _time(path: Path, doc: dict) -> TimeSetup | None:
    t = _table(path, doc, "time", required=False)
    if t is None:
        return None
    _unknown(path, "[time]", t, ("column", "units", "sample_rate", "t0"))
    if ("column" in t) == ("sample_rate" in t):
        raise _fail(path, "[time]", "give either column (the time column's name or number) or sample_rate (Hz) "
                    "with t0 (s), not both or neither")
    units = t.get("units", "s")
    if units not in TIME_UNITS:
        raise _fail(path, "[time] units", f"unknown unit {units!r}; allowed: {', '.join(TIME_UNITS)}")
    if "column" in t:
        if "t0" in t:
            raise _fail(path, "[time] t0", "comes from the time column; give t0 only with sample_rate")
        return TimeSetup(column=_column(path, "[time] column", t["column"]), units=units)
    if "units" in t:
        raise _fail(path, "[time] units", "is the time column's unit; sample_rate is in Hz and t0 in s")
    rate = _number(path, "[time] sample_rate", t["sample_rate"], positive=True)
    t0 = _number(path, "[time] t0", t.get("t0", 0.0))
    return TimeSetup(sample_rate=rate, t0=t0)


def _apparatus(path: Path, doc: dict) -> dict[str, dict[str, Any]]:
    t = _table(path, doc, "apparatus")
    allowed_parts = tuple(APPARATUS) + tuple(OPTIONAL_PARTS)
    _unknown(path, "[apparatus]", t, allowed_parts)
    out: dict[str, dict[str, Any]] = {}
    for part in allowed_parts:
        where = f"[apparatus.{part}]"
        if part not in t:
            if part in APPARATUS:
                raise _fail(path, where, f"required table is missing; it holds {', '.join(APPARATUS[part])}")
            continue
        g = t[part]
        if not isinstance(g, dict):
            raise _fail(path, where, f"must be a table, got {g!r}")
        names = APPARATUS.get(part) or OPTIONAL_PARTS[part]
        _unknown(path, where, g, names + OPTIONAL_ATTRS.get(part, ()))
        vals: dict[str, Any] = {}
        for name in names:
            if name not in g:
                raise _fail(path, f"{where} {name}", "missing (SI units: Pa, m/s, m, kg/m^3)")
            if name == "material":
                vals[name] = _string(path, f"{where} {name}", g[name])
            else:
                vals[name] = _number(path, f"{where} {name}", g[name], positive=name != "gauge_offset")
        for name in OPTIONAL_ATTRS.get(part, ()):
            if name in g:
                vals[name] = _number(path, f"{where} {name}", g[name])
        out[part] = vals
    return out


def _conversion(path: Path, where: str, c: dict, units: str) -> tuple[float | None, dict[str, Any]]:
    """strain_per_volt of a voltage channel: given, or from gauge factor, bridge, excitation and gain."""
    bridge_keys = ("gauge_factor", "bridge", "excitation", "amplifier_gain")
    given = [k for k in bridge_keys if k in c]
    if units not in ("V", "mV"):
        for k in ("strain_per_volt", *given):
            if k in c:
                raise _fail(path, f"{where} {k}", f"applies to channels in V or mV; this channel is in {units}")
        return None, {}
    if "strain_per_volt" in c:
        if given:
            raise _fail(path, f"{where} {given[0]}", "give strain_per_volt or the gauge factor and bridge, not both")
        spv = _number(path, f"{where} strain_per_volt", c["strain_per_volt"], positive=True)
        return spv, {}
    missing = [k for k in ("gauge_factor", "bridge", "excitation") if k not in c]
    if missing:
        raise _fail(path, where, "a channel in volts needs strain_per_volt (strain per volt at the scope), or "
                    f"gauge_factor, bridge and excitation (and amplifier_gain); missing {', '.join(missing)}")
    gf = _number(path, f"{where} gauge_factor", c["gauge_factor"], positive=True)
    b = c["bridge"]
    if isinstance(b, str):
        if b not in BRIDGES:
            raise _fail(path, f"{where} bridge", f"unknown bridge {b!r}; allowed: {', '.join(BRIDGES)} or the bridge "
                        "factor as a number (active arms, e.g. 2.6 for a full Poisson bridge with nu = 0.3)")
        k = BRIDGES[b]
    else:
        k = _number(path, f"{where} bridge", b, positive=True)
    vex = _number(path, f"{where} excitation", c["excitation"], positive=True)
    gain = _number(path, f"{where} amplifier_gain", c.get("amplifier_gain", 1.0), positive=True)
    spv = 4.0 / (k * gf * vex * gain)  # V_out = gain * excitation * k * gauge_factor * strain / 4
    return spv, {"gauge_factor": gf, "bridge": b, "bridge_factor": k, "excitation": vex, "amplifier_gain": gain}


def _channels(path: Path, doc: dict) -> dict[str, ChannelSetup]:
    t = _table(path, doc, "channels")
    _unknown(path, "[channels]", t, CHANNELS)
    out: dict[str, ChannelSetup] = {}
    for gauge in CHANNELS:
        where = f"[channels.{gauge}]"
        if gauge not in t:
            if gauge in REQUIRED_CHANNELS:
                raise _fail(path, where, "required table is missing (the three bar gauges are required, the tube's "
                            "hoop gauge is optional)")
            continue
        c = t[gauge]
        if not isinstance(c, dict):
            raise _fail(path, where, f"must be a table, got {c!r}")
        _unknown(path, where, c, _CHANNEL_KEYS)
        if "column" not in c:
            raise _fail(path, f"{where} column", "missing: the column's header name, its 1-based number, or a TDMS "
                        "'group/channel'")
        column = _column(path, f"{where} column", c["column"])
        units = c.get("units")
        if units not in CHANNEL_UNITS:
            raise _fail(path, f"{where} units", f"is {units!r}; allowed: {', '.join(CHANNEL_UNITS)}")
        if "sign" not in c:
            raise _fail(path, f"{where} sign", "missing: +1 when the file's positive is elongation (a compressive "
                        "wave reads negative, as the record contract), -1 when the bridge reads compression positive")
        sign = c["sign"]
        if isinstance(sign, bool) or sign not in (1, -1):
            raise _fail(path, f"{where} sign", f"must be +1 or -1, got {sign!r}")
        file = c.get("file")
        if file is not None:
            file = _string(path, f"{where} file", file)
        spv, conv = _conversion(path, where, c, units)
        out[gauge] = ChannelSetup(gauge, column, units, int(sign), file, spv, conv)
    return out


def parse_setup(doc: dict, *, path: str | Path = "<setup>") -> Setup:
    """Check a parsed SETUP.toml document into a :class:`Setup`."""
    p = Path(path)
    allowed = ("record", "time", "apparatus", "channels")
    _unknown(p, "", doc, allowed)
    return Setup(p, _record(p, doc), _time(p, doc), _apparatus(p, doc), _channels(p, doc))


def load_setup(path: str | Path) -> Setup:
    """Read and check a SETUP.toml; :class:`SetupError` names the file, the key and the problem."""
    p = Path(path)
    try:
        text = text_of(p, "set-up file", MAX_SETUP_BYTES, encoding="utf-8-sig")  # a BOM: Windows' editors
    except NotText as why:
        raise _fail(p, "file", str(why)) from None
    shape = toml_shape_problem(text)  # before the parser, whose time and memory grow with the depth
    if shape:
        raise _fail(p, "file", f"{shape}, too deep for a set-up file")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _fail(p, "file", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise _fail(p, "file", "is nested too deeply to be a set-up file") from None
    return parse_setup(doc, path=p)
