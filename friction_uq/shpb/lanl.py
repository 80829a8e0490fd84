"""Read a standard two-bar SHPB record in the LANL text format.

File format (LANL "raw" text, as written by the HopPyBar acquisition): tab-separated, CRLF.
Columns 1-2 are metadata key/value pairs (test conditions, then an "Incident Bar" and a
"Transmitted Bar" block; keys carry their unit in parentheses). Column 3 is the input-bar gauge
and column 4 the transmitted-bar gauge, in volts: row 1 holds the channel names, row 2 the time of
the first sample t0 (s), row 3 the sampling interval (s), and the samples start on row 4.

Sign convention: inside the package strains are positive in compression. The sign of each channel
is decided once, here at reading, from the data: in a test whose "Test Loading" is compression the
first pulse on each gauge (the incident wave on the input bar, the transmitted wave on the output
bar) is compressive, so each channel is multiplied by the sign that makes its first pulse positive
(:attr:`TwoBarRecord.polarity`).
"""

from __future__ import annotations

import math
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ..errors import RecordError, SignalError
from ..signals import ARRIVAL_FRACTION, ARRIVAL_SIGMAS, MIN_BASELINE_SAMPLES, noise_estimate
from .record import BarProperties, SpecimenProperties, TwoBarRecord

#: Rows before the samples (channel names, t0, sampling interval).
HEADER_ROWS = 3

_LOADING_SIGN = {"compression": +1, "tension": -1}


class _Fields:
    """Metadata lookup by key without its unit, with errors that name the file and the key."""

    def __init__(self, path: Path, pairs: dict[str, str]) -> None:
        self.path = path
        self.pairs = pairs
        self.by_base = {k.split("(")[0].strip().lower(): k for k in pairs}

    def key(self, base: str) -> str:
        k = self.by_base.get(base.lower())
        if k is None:
            raise RecordError(self.path, f"metadata key {base!r}", "missing (columns 1-2)")
        return k

    def text(self, base: str) -> str:
        return self.pairs[self.key(base)].strip()

    def number(self, base: str, *, scale: float = 1.0, positive: bool = True) -> float:
        k = self.key(base)
        try:
            v = float(self.pairs[k])
        except ValueError:
            raise RecordError(self.path, f"metadata {k!r}", f"{self.pairs[k]!r} is not a number") from None
        if not math.isfinite(v) or (positive and v <= 0):
            raise RecordError(self.path, f"metadata {k!r}", f"{v!r} must be a positive finite number")
        return v * scale


def _bar(fields: _Fields, prefix: str, name: str) -> BarProperties:
    density = fields.number(f"{prefix} Density")
    # The file labels this field kg/m^3 but writes g/cm^3 (4.416 for Ti-6Al-4V): no solid bar
    # is lighter than 100 kg/m^3, so a smaller value is read as g/cm^3.
    if density < 100.0:
        density *= 1000.0
    gains = {
        k: fields.number(k.split("(")[0])
        for k in fields.pairs
        if k.lower().startswith(prefix.split()[0].lower()) and "gain" in k.lower()
    }
    timing = fields.by_base.get(f"{prefix} reflected time sound speed".lower())
    return BarProperties(
        name=name,
        young_modulus=fields.number(f"{prefix} Young's Modulus", scale=1e9),
        wave_speed=fields.number(f"{prefix} Rod Sound Speed"),
        poisson_ratio=fields.number(f"{prefix} Poisson Ratio"),
        density=density,
        diameter=fields.number(f"{prefix} Diameter", scale=1e-3),
        gauge_distance=fields.number(f"{prefix} Strain Gage Location", scale=1e-3),
        gauge_factor=fields.number(f"{prefix} Calibrated Gage Factor"),
        excitation=fields.number(f"{prefix} Excitation Voltage"),
        gains=MappingProxyType(gains),
        timing_wave_speed=None if timing is None else fields.number(timing.split("(")[0]),
    )


def _first_pulse_sign(x: np.ndarray, *, head: float = 0.02) -> int:
    """Sign (+1/-1) of the first excursion of a channel beyond 8 noise sd and 5 % of its largest.

    The noise is that of the first ``head`` fraction of the record (at least 32 samples), which
    must precede the first pulse.
    """
    noise = noise_estimate(x, stop=max(MIN_BASELINE_SAMPLES, int(head * x.size)))
    y = x - noise.offset
    level = max(ARRIVAL_SIGMAS * noise.sd, ARRIVAL_FRACTION * float(np.abs(y).max()))
    beyond = np.flatnonzero(np.abs(y) >= level)
    if beyond.size == 0 or float(np.abs(y).max()) <= ARRIVAL_SIGMAS * noise.sd:
        raise SignalError("no pulse rises above the noise")
    return 1 if y[beyond[0]] > 0 else -1


def read_lanl_raw(path: str | Path) -> TwoBarRecord:
    """Read a LANL two-bar SHPB text record (module docstring: format, sign convention).

    Parameters
    ----------
    path
        The ``.raw`` text file.

    Returns
    -------
    TwoBarRecord
        Time base (s), both channels (V, compression positive), metadata, bar and specimen data.

    Raises
    ------
    RecordError
        If the file cannot be read, a required field is missing or not a positive number, the time
        bases of the two channels differ, a sample is not a number, or the loading is neither
        compression nor tension.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise RecordError(path, "file", f"cannot be read ({exc.strerror})") from None
    rows = [line.split("\t") for line in lines]
    if len(rows) <= HEADER_ROWS or any(len(r) < 4 for r in rows):
        raise RecordError(path, "layout", "expected tab-separated rows of 4 columns and samples from row 4")
    names = (rows[0][2].lower(), rows[0][3].lower())
    if "incident" not in names[0] or "transmitted" not in names[1]:
        raise RecordError(
            path, "row 1, columns 3-4", f"channel names {rows[0][2:4]!r}: expected the incident, then the transmitted"
        )
    pairs: dict[str, str] = {}
    for number, r in enumerate(rows, start=1):
        key, value = r[0].strip(), r[1].strip()
        if key and pairs.setdefault(key, value) != value:
            raise RecordError(path, f"row {number}, metadata {key!r}", f"given twice: {pairs[key]!r} and {value!r}")
    fields = _Fields(path, pairs)

    columns = [np.empty(len(rows) - 1), np.empty(len(rows) - 1)]
    for number, r in enumerate(rows[1:], start=2):
        for j, column in enumerate(columns):
            try:
                column[number - 2] = float(r[2 + j])
            except ValueError:
                raise RecordError(path, f"row {number}, column {3 + j}", f"{r[2 + j]!r} is not a number") from None
    (t0_in, dt_in), (t0_tr, dt_tr) = columns[0][:2], columns[1][:2]
    if t0_in != t0_tr or dt_in != dt_tr:
        raise RecordError(
            path, "rows 2-3, columns 3-4", f"the channels' t0/dt differ: {t0_in}/{dt_in} vs {t0_tr}/{dt_tr} s"
        )
    if not dt_in > 0:
        raise RecordError(path, "row 3, column 3", f"sampling interval {dt_in!r} s must be > 0")

    loading = fields.text("Test Loading")
    if loading.lower() not in _LOADING_SIGN:
        raise RecordError(path, "metadata 'Test Loading'", f"{loading!r} not understood, allowed: Compression, Tension")
    raw = [c[HEADER_ROWS - 1 :] for c in columns]
    try:
        polarity = tuple(_LOADING_SIGN[loading.lower()] * _first_pulse_sign(v) for v in raw)
    except SignalError as exc:
        raise RecordError(path, "columns 3-4", f"cannot find the first pulse ({exc})") from None
    volts = [p * v for p, v in zip(polarity, raw, strict=True)]
    time = t0_in + dt_in * np.arange(volts[0].size)
    for a in (time, *volts):
        a.setflags(write=False)

    # The unit of this key is a mangled degree sign, "(\ufffdC)": degrees Celsius (0 for this
    # record, whose file name says 273K).
    temperature = fields.number("Test Temperature", positive=False)
    specimen = SpecimenProperties(
        material=fields.text("Sample Material"),
        description=fields.text("Sample Description"),
        diameter=fields.number("Initial Sample Diameter", scale=1e-3),
        length=fields.number("Initial Sample Length", scale=1e-3),
        temperature=temperature + 273.15,
    )
    return TwoBarRecord(
        path=path,
        time=time,
        input_volts=volts[0],
        transmitted_volts=volts[1],
        polarity=(int(polarity[0]), int(polarity[1])),
        sample_interval=float(dt_in),
        metadata=MappingProxyType(pairs),
        input_bar=_bar(fields, "Incident Bar", "input"),
        transmitted_bar=_bar(fields, "Transmitted Bar", "transmitted"),
        specimen=specimen,
    )
