"""A record written out as an oscilloscope would: metadata lines, a header, volts, a lab's wiring.

For the round-trip tests, the bundled scope example and the import benchmark: the gauge signals
of a record (elongation positive, as stored) become voltages ``strain / strain_per_volt``, times
``sign`` (-1 for a bridge wired to read compression positive), in one delimited file with every
channel or one file per channel.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..record.contract import CHANNELS, UNITS

#: Metadata lines a scope writes before its header (a Keysight-like preamble).
PREAMBLE = ("Model,DSOX3024T", "Serial,MY00000000", "Date,2016-03-01 10:42:00", "Averaging,off", "")


def gauge_signals(path: str | os.PathLike[str]) -> tuple[dict[str, np.ndarray], float, float]:
    """(channel -> strain as stored, elongation positive; sample_rate; t0) of a record file."""
    import h5py

    out: dict[str, np.ndarray] = {}
    with h5py.File(path, "r") as fh:
        sig = fh["signals"]
        rate, t0 = float(sig.attrs["sample_rate"]), float(sig.attrs.get("t0", 0.0))
        for name in CHANNELS:
            if name in sig:
                ds = sig[name]
                units = ds.attrs["units"]
                units = units.decode() if isinstance(units, bytes) else str(units)
                scale = float(ds.attrs["strain_per_volt"]) if units == "V" else UNITS[units]
                out[name] = np.asarray(ds[()], dtype=np.float64) * scale
    return out, rate, t0


def _lines(columns: list[np.ndarray], fmt: str, delimiter: str, decimal: str) -> str:
    rows = np.column_stack(columns)
    text = "\n".join(delimiter.join(fmt % v for v in row) for row in rows)
    return text.replace(".", decimal) if decimal != "." else text


def write_scope_csv(path: str | os.PathLike[str], time: np.ndarray | None, volts: Mapping[str, np.ndarray], *,
                    delimiter: str = ",", decimal: str = ".", preamble: tuple[str, ...] = PREAMBLE,
                    time_name: str = "Time", units_row: bool = True, fmt: str = "%.9e",
                    units: Sequence[str] | None = None) -> Path:
    """One delimited file: preamble lines, a header (``time_name`` then the keys of ``volts``), an
    optional units row (seconds, then ``units``: volts unless given), then the samples."""
    names = ([time_name] if time is not None else []) + list(volts)
    cols = ([time] if time is not None else []) + [np.asarray(v, float) for v in volts.values()]
    head = list(preamble) + [delimiter.join(names)]
    if units_row:
        head.append(delimiter.join((["s"] if time is not None else []) + list(units or ["V"] * len(volts))))
    p = Path(path)
    p.write_text("\n".join(head) + "\n" + _lines(cols, fmt, delimiter, decimal) + "\n", encoding="utf-8")
    return p


def export_record(record_path: str | os.PathLike[str], folder: str | os.PathLike[str], *,
                  strain_per_volt: Mapping[str, float], signs: Mapping[str, int] | None = None,
                  names: Mapping[str, str] | None = None, per_channel: bool = False,
                  delimiter: str = ",", decimal: str = ".") -> list[Path]:
    """Write ``record_path``'s gauges as scope CSV files in ``folder``; returns the files written.

    ``names`` maps a gauge to its scope column (default CH1..CH4 in contract order); one file
    ``scope.csv`` holds every channel, or with ``per_channel`` one ``<column>.csv`` each, each
    with its own time column.
    """
    strains, rate, t0 = gauge_signals(record_path)
    signs = dict(signs or {})
    names = dict(names or {g: f"CH{i + 1}" for i, g in enumerate(strains)})
    n = len(next(iter(strains.values())))
    time = t0 + np.arange(n) / rate
    volts = {names[g]: signs.get(g, 1) * eps / strain_per_volt[g] for g, eps in strains.items()}
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    if not per_channel:
        return [write_scope_csv(out / "scope.csv", time, volts, delimiter=delimiter, decimal=decimal)]
    return [write_scope_csv(out / f"{col}.csv", time, {col: v}, delimiter=delimiter, decimal=decimal)
            for col, v in volts.items()]
