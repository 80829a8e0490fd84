"""The unit a text export writes beside a column, held against the unit SETUP.toml declares for it.

Scope software writes units in one of two places: a row under the header (PicoScope ``(us) (mV)``,
Keysight ``second Volt``, this package's own exports ``s V``), or in the column's name (``Time (s)``,
``CH2 [mV]``). A SETUP.toml that says ``units = "V"`` for a column the file says is in millivolts puts a
factor of a thousand into every force read from that gauge, and only some such factors show in the
record's checks; the file's own word is cheaper to read than the damage. A cell that names no unit this
module knows (a channel's name, a probe's label) says nothing, and nothing is checked against it.
"""

from __future__ import annotations

import re

#: A unit's spellings (case-folded, brackets and spaces stripped) -> its name in SETUP.toml's terms.
VOLTAGE = {"v": "V", "volt": "V", "volts": "V", "mv": "mV", "millivolt": "mV", "millivolts": "mV",
           "uv": "uV", "\u00b5v": "uV", "\u03bcv": "uV", "microvolt": "uV", "microvolts": "uV", "kv": "kV"}
STRAIN = {"strain": "strain", "m/m": "strain", "\u03b5": "strain", "microstrain": "microstrain",
          "\u00b5\u03b5": "microstrain", "\u03bc\u03b5": "microstrain", "ue": "microstrain", "\u00b5strain": "microstrain",
          "\u03bcstrain": "microstrain", "ustrain": "microstrain"}
TIME = {"s": "s", "sec": "s", "second": "s", "seconds": "s", "ms": "ms", "msec": "ms", "us": "us",
        "\u00b5s": "us", "\u03bcs": "us", "usec": "us", "ns": "ns", "nsec": "ns"}
#: Units a scope writes for what no gauge channel holds (a current probe, a percentage, a power, a frequency).
OTHER = {"a": "A", "ma": "mA", "amp": "A", "amps": "A", "ampere": "A", "%": "%", "db": "dB", "dbm": "dBm",
         "w": "W", "hz": "Hz", "pa": "Pa", "n": "N", "\u00b0c": "degC", "degc": "degC"}

_SUFFIX = re.compile(r"[(\[]\s*([^()\[\]]{1,16}?)\s*[)\]]\s*$")


def unit_name(cell: str) -> str | None:
    """The unit a cell names (``"(mV)"``, ``"Volt"``, ``"[µs]"``: "mV", "V", "us"), or None for any other text."""
    s = cell.strip().strip('"').strip()
    m = re.fullmatch(r"[(\[]\s*(.*?)\s*[)\]]", s)
    key = (m.group(1) if m else s).replace(" ", "").casefold()
    return VOLTAGE.get(key) or STRAIN.get(key) or TIME.get(key) or OTHER.get(key)


def suffix_unit(name: str) -> str | None:
    """The unit in brackets at the end of a column's name (``"Time (s)"``, ``"CH2 [mV]"``), else None."""
    m = _SUFFIX.search(name)
    return unit_name(m.group(1)) if m and m.start() > 0 else None


def units_row(cells: list[str], ncols: int) -> list[str | None] | None:
    """Each column's unit when the line ``cells`` is a units row (at most one cell per column, the missing ones at
    its end empty, every cell that is not empty naming a unit, at least one of them), else None."""
    if len(cells) > ncols:
        return None
    cells = list(cells) + [""] * (ncols - len(cells))
    units = [unit_name(c) if c.strip().strip('"') else None for c in cells]
    named = [u for u, c in zip(units, cells) if c.strip().strip('"')]
    return units if named and all(named) else None


def channel_unit_conflict(file_unit: str | None, declared: str) -> str | None:
    """Why a channel the file says is in ``file_unit`` cannot be read in the ``declared`` unit (SETUP.toml's
    channel ``units``: V, mV, strain or microstrain), or None when they agree or the file says nothing."""
    if file_unit is None or file_unit == declared:
        return None
    if file_unit in TIME.values():
        return f"the file gives its unit as {file_unit}, a time: is it the time column?"
    if file_unit in ("uV", "kV"):
        return f"write the channel's numbers in V or mV (SETUP.toml has no {file_unit})"
    if file_unit in OTHER.values():
        return f"a gauge's channel holds volts or strain: is it the right column (SETUP.toml has no {file_unit})?"
    return f'write units = "{file_unit}"'


def time_unit_conflict(file_unit: str | None, declared: str) -> str | None:
    """Why a time column the file says is in ``file_unit`` cannot be read in ``declared`` ([time] units), or None."""
    if file_unit is None or file_unit not in TIME.values() or file_unit == TIME.get(declared.casefold(), declared):
        return None
    return f'write [time] units = "{file_unit}"'
