"""A standard two-bar SHPB record in the LANL text format: reading, forces on the specimen faces.

This module is how the generic signal code (:mod:`friction_uq.signals`) is exercised on a record
that no one on this project made (``shared/data/real/lanl-hoppybar-cu/``): a compression test with
one input bar (incident and reflected waves on one gauge) and one transmitted bar. It has nothing
to do with the confined friction cell.

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

Strain from volts (quarter bridge): strain = V (2 / GF) / (gain Vexc).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Literal

import numpy as np

from .errors import RecordError, SignalError
from .physics import bars as eq
from .signals import (
    ARRIVAL_FRACTION,
    ARRIVAL_SIGMAS,
    MIN_BASELINE_SAMPLES,
    NoiseEstimate,
    noise_estimate,
    prepulse_noise,
    pulse_arrival,
    transport,
    window_mask,
)

#: Fraction of the peak transmitted force above which the balance is assessed (the loading).
BALANCE_LEVEL = 0.5
#: Fraction of its peak below which a wave has ended (after its peak): where its window stops.
PULSE_END_FRACTION = 0.1
#: Rows before the samples (channel names, t0, sampling interval).
HEADER_ROWS = 3

#: Which wave speeds set the gauge-to-face travel times (see :func:`transport_speeds`).
WaveSpeed = Literal["timing", "rod"]

_LOADING_SIGN = {"compression": +1, "tension": -1}


@dataclass(frozen=True)
class BarProperties:
    """One elastic bar as the file describes it. SI units.

    Attributes
    ----------
    name : str
        "input" or "transmitted".
    young_modulus : float
        E (Pa).
    wave_speed : float
        Rod (one-dimensional) wave speed c0 (m/s), as stated ("Rod Sound Speed").
    poisson_ratio : float
        nu (dimensionless).
    density : float
        rho (kg/m^3).
    diameter : float
        Bar diameter (m).
    gauge_distance : float
        Distance from the gauge to the bar end touching the specimen (m).
    gauge_factor : float
        Calibrated gauge factor GF (dimensionless).
    excitation : float
        Bridge excitation Vexc (V).
    gains : Mapping[str, float]
        Every amplifier-gain field of the file that concerns this bar, by its key (V/V).
    timing_wave_speed : float or None
        Wave speed from the calibrated reflection time ("Reflected Time Sound Speed", m/s), when
        the file gives one.
    """

    name: str
    young_modulus: float
    wave_speed: float
    poisson_ratio: float
    density: float
    diameter: float
    gauge_distance: float
    gauge_factor: float
    excitation: float
    gains: Mapping[str, float]
    timing_wave_speed: float | None = None

    @property
    def area(self) -> float:
        """Cross-section area pi d^2 / 4 (m^2)."""
        return math.pi / 4.0 * self.diameter**2

    @property
    def gauge_delay(self) -> float:
        """Travel time from the gauge to the specimen face, d / c0 (s)."""
        return self.gauge_distance / self.wave_speed

    def strain(self, volts: np.ndarray, *, gain: float) -> np.ndarray:
        """Quarter-bridge strain V (2 / GF) / (gain Vexc) (dimensionless) from volts."""
        return np.asarray(volts, dtype=float) * (2.0 / self.gauge_factor) / (gain * self.excitation)


@dataclass(frozen=True)
class SpecimenProperties:
    """The specimen as the file describes it (m, K)."""

    material: str
    description: str
    diameter: float
    length: float
    temperature: float


@dataclass(frozen=True)
class TwoBarRecord:
    """A two-bar SHPB record read by :func:`read_lanl_raw`. Arrays are read-only.

    Attributes
    ----------
    path : Path
        The file read.
    time : numpy.ndarray
        Time of each sample (s), shape (n,).
    input_volts, transmitted_volts : numpy.ndarray
        Gauge signals (V), shape (n,), sign-corrected so that compression is positive.
    polarity : tuple[int, int]
        The sign applied to the (input, transmitted) columns of the file (+1 or -1).
    sample_interval : float
        Sampling interval (s).
    metadata : Mapping[str, str]
        Every key/value pair of columns 1-2, verbatim (keys with their units).
    input_bar, transmitted_bar : BarProperties
    specimen : SpecimenProperties
    """

    path: Path
    time: np.ndarray
    input_volts: np.ndarray
    transmitted_volts: np.ndarray
    polarity: tuple[int, int]
    sample_interval: float
    metadata: Mapping[str, str]
    input_bar: BarProperties
    transmitted_bar: BarProperties
    specimen: SpecimenProperties

    @property
    def n_samples(self) -> int:
        return int(self.time.size)


# ----------------------------------------------------------------------------------------------
# reading
# ----------------------------------------------------------------------------------------------


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


# ----------------------------------------------------------------------------------------------
# forces
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TwoBarForces:
    """Waves at the specimen faces, forces and their balance, on the record's time base.

    Attributes
    ----------
    time : numpy.ndarray
        Time (s), shape (n,).
    eps_incident, eps_reflected, eps_transmitted : numpy.ndarray
        Baseline-free waves transported to the specimen faces (strain, compression positive).
    front_force, back_force : numpy.ndarray
        F_1 = A E (eps_i + eps_r) on the input face (eq. 2) and F_2 = A E eps_t on the output
        face (eq. 3), in N.
    input_gain, transmitted_gain : float
        Amplifier gains used (V/V).
    wave_speeds : tuple[float, float]
        Speeds (input, transmitted) that set the gauge-to-face travel times (m/s).
    noise : Mapping[str, NoiseEstimate]
        Pre-pulse baseline of the "input" and "transmitted" channels (strain).
    arrivals : Mapping[str, float]
        Arrival (foot, :func:`friction_uq.signals.pulse_arrival`) of the "incident" and
        "reflected" waves on the input gauge and of the "transmitted" wave on its gauge (s).
    window : tuple[float, float]
        Loading window [start, stop) (s): the contiguous run of samples around the peak of F_2
        where F_2 >= ``BALANCE_LEVEL`` times its peak.
    balance_error : float
        mean |F_1 - F_2| / mean F_2 over the loading window (dimensionless).
    impulse_error : float
        (integral F_1 - integral F_2) / integral F_2 over the loading window (signed).
    dispersion : bool
        Whether the Pochhammer-Chree correction was applied in the transport.
    """

    time: np.ndarray
    eps_incident: np.ndarray
    eps_reflected: np.ndarray
    eps_transmitted: np.ndarray
    front_force: np.ndarray
    back_force: np.ndarray
    input_gain: float
    transmitted_gain: float
    wave_speeds: tuple[float, float]
    noise: Mapping[str, NoiseEstimate]
    arrivals: Mapping[str, float]
    window: tuple[float, float]
    balance_error: float
    impulse_error: float
    dispersion: bool

    @property
    def loading(self) -> np.ndarray:
        """Boolean mask of the loading window."""
        return (self.time >= self.window[0]) & (self.time < self.window[1])


def _stated_gain(bar: BarProperties) -> float:
    values = set(bar.gains.values())
    if len(values) != 1:
        raise SignalError(
            f"the {bar.name} bar's gain fields disagree ({dict(bar.gains)}): pass the gain explicitly"
        )
    return values.pop()


def _pulse_end(y: np.ndarray, *, start: float) -> float:
    """First index after the peak of ``y[start:]`` where ``y`` falls below PULSE_END_FRACTION of it."""
    i0 = int(np.floor(start))
    k = i0 + int(np.argmax(y[i0:]))
    below = np.flatnonzero(y[k:] < PULSE_END_FRACTION * y[k])
    return float(k + below[0]) if below.size else float(y.size)


def _loading_window(force: np.ndarray) -> tuple[int, int]:
    """[start, stop) of the contiguous run around the peak where force >= BALANCE_LEVEL * peak."""
    k = int(np.argmax(force))
    above = force >= BALANCE_LEVEL * force[k]
    start = k
    while start > 0 and above[start - 1]:
        start -= 1
    stop = k + 1
    while stop < force.size and above[stop]:
        stop += 1
    return start, stop


def transport_speeds(record: TwoBarRecord, *, wave_speed: WaveSpeed = "timing") -> tuple[float, float]:
    """Wave speeds (input, transmitted) that set the gauge-to-face travel times d / c (m/s).

    ``"rod"``: the stated rod speeds c0. ``"timing"``: the speed from the input bar's calibrated
    reflection time, 2 d / t_reflected (a direct measurement of the travel time over 2 d); the
    transmitted bar, for which the file gives none, takes its c0 times the same ratio (the same
    speed for identical bars). Falls back to c0 when the file has no calibrated reflection time.
    """
    ib, tb = record.input_bar, record.transmitted_bar
    if wave_speed == "rod" or (wave_speed == "timing" and ib.timing_wave_speed is None):
        return ib.wave_speed, tb.wave_speed
    if wave_speed == "timing":
        ratio = ib.timing_wave_speed / ib.wave_speed
        return ib.timing_wave_speed, tb.wave_speed * ratio
    raise ValueError(f"wave_speed {wave_speed!r} is not understood, allowed values: 'timing', 'rod'")


def two_bar_forces(
    record: TwoBarRecord,
    *,
    gain: float,
    input_gain: float | None = None,
    dispersion: bool = False,
    wave_speed: WaveSpeed = "timing",
) -> TwoBarForces:
    """Forces on both faces of the specimen and their balance.

    Steps:

    1. volts to strain (:meth:`BarProperties.strain`); each channel's baseline offset and noise
       from its pre-pulse segment (:func:`~friction_uq.signals.prepulse_noise`), offset removed;
    2. on the input gauge, the incident wave is what comes before the reflected front (2 d / c
       after the incident's foot, less a margin of 1 % of that time, at least 8 samples); the
       reflected wave is what comes after. Each wave (and the transmitted one) is kept until it has
       fallen below 10 % of its peak, plus the margin, and set to zero elsewhere (this cuts the
       far-end echoes, whose timing the file does not give);
    3. the incident wave is transported forward by d, the reflected and transmitted waves back by
       their d (:func:`~friction_uq.signals.transport`, speeds from :func:`transport_speeds`);
    4. F_1 = A E (eps_i + eps_r) (eq. 2), F_2 = A E eps_t (eq. 3; Durand et al. 2016);
    5. loading window: the contiguous samples around the peak of F_2 where F_2 >= 50 % of it.
       Balance error: mean |F_1 - F_2| / mean F_2 over it; impulse error: (sum F_1 - sum F_2) /
       sum F_2 over it.

    Parameters
    ----------
    record
        A record read by :func:`read_lanl_raw`.
    gain
        Amplifier gain of the transmitted-bar channel (V/V). This is the disputed one: the LANL
        file says 200 ("Transmitted Bar Gain") and 500 ("Transmitted Bar Calibrated Gain"). A
        gain common to both channels cancels from the balance error, so only the ratio of the two
        gains can be tested by the balance. (LANL's own analysis code, HopPyBar.py, reads the
        "... Bar Gain" fields, 200 and 200, and keeps the "Calibrated Gain" ones as information.)
    input_gain
        Amplifier gain of the input-bar channel (V/V); by default the file's value, when all its
        fields for that bar agree (200 in both for the LANL copper record).
    dispersion
        Transport with the Pochhammer-Chree first-mode correction (which also low-passes at the
        first-mode cut-off, about 270 kHz for these 9.47 mm bars) instead of a pure delay; the
        phase velocity curve is scaled by the transport speed of ``wave_speed``.
    wave_speed
        ``"timing"`` (default) or ``"rod"``: which speeds set the travel times d / c, see
        :func:`transport_speeds`.

    Returns
    -------
    TwoBarForces

    Raises
    ------
    SignalError
        If a pulse cannot be found, or the input bar's gain fields disagree and ``input_gain`` is
        not given.
    ValueError
        If a gain is not a positive finite number or ``wave_speed`` is not understood.
    """
    for name, g in (("gain", gain), ("input_gain", input_gain)):
        valid = isinstance(g, numbers.Real) and not isinstance(g, bool) and math.isfinite(g) and g > 0
        if g is not None and not valid:
            raise ValueError(f"{name} must be a positive finite number (V/V), received {g!r}")
    ib, tb = record.input_bar, record.transmitted_bar
    c_in, c_tr = transport_speeds(record, wave_speed=wave_speed)
    g_in = _stated_gain(ib) if input_gain is None else float(input_gain)
    n, dt = record.n_samples, record.sample_interval

    # a pulse must end before its reflection comes back to the input gauge: search peaks within that
    span = int(2.0 * ib.gauge_distance / c_in / dt)
    x_in = ib.strain(record.input_volts, gain=g_in)
    noise_in, arr_inc = prepulse_noise(x_in, polarity=+1, span=span)
    y_in = x_in - noise_in.offset
    x_tr = tb.strain(record.transmitted_volts, gain=float(gain))
    noise_tr, arr_tr = prepulse_noise(x_tr, polarity=+1, span=span)
    y_tr = x_tr - noise_tr.offset

    sep = arr_inc + 2.0 * ib.gauge_distance / c_in / dt  # the reflected front reaches the input gauge
    margin = max(8.0, 0.01 * (sep - arr_inc))
    arr_ref = pulse_arrival(
        x_in, offset=noise_in.offset, sd=noise_in.sd, start=int(sep - margin), span=span, polarity=-1
    )
    end_inc = _pulse_end(np.where(window_mask(n, 0, sep - margin), y_in, 0.0), start=arr_inc)
    end_ref = _pulse_end(-y_in, start=arr_ref)
    end_tra = _pulse_end(y_tr, start=arr_tr)
    inc = np.where(window_mask(n, 0, min(end_inc + margin, sep - margin)), y_in, 0.0)
    ref = np.where(window_mask(n, sep - margin, end_ref + margin), y_in, 0.0)
    tra = np.where(window_mask(n, 0, end_tra + margin), y_tr, 0.0)

    def moved(wave: np.ndarray, bar: BarProperties, speed: float, distance: float) -> np.ndarray:
        return transport(
            wave,
            sample_interval=dt,
            distance=distance,
            wave_speed=speed,
            diameter=bar.diameter,
            poisson_ratio=bar.poisson_ratio,
            dispersion=dispersion,
        )

    eps_i = moved(inc, ib, c_in, +ib.gauge_distance)
    eps_r = moved(ref, ib, c_in, -ib.gauge_distance)
    eps_t = moved(tra, tb, c_tr, -tb.gauge_distance)
    f1 = eq.input_force(eps_i, eps_r, area=ib.area, young_modulus=ib.young_modulus)
    f2 = eq.transmitted_force(eps_t, area=tb.area, young_modulus=tb.young_modulus)

    start, stop = _loading_window(f2)
    w = slice(start, stop)
    balance = float(np.mean(np.abs(f1[w] - f2[w])) / np.mean(f2[w]))
    impulse = float((np.sum(f1[w]) - np.sum(f2[w])) / np.sum(f2[w]))
    t0 = float(record.time[0])
    arrivals = {"incident": arr_inc, "reflected": arr_ref, "transmitted": arr_tr}
    for a in (eps_i, eps_r, eps_t, f1, f2):
        a.setflags(write=False)
    return TwoBarForces(
        time=record.time,
        eps_incident=eps_i,
        eps_reflected=eps_r,
        eps_transmitted=eps_t,
        front_force=f1,
        back_force=f2,
        input_gain=g_in,
        transmitted_gain=float(gain),
        wave_speeds=(c_in, c_tr),
        noise=MappingProxyType({"input": noise_in, "transmitted": noise_tr}),
        arrivals=MappingProxyType({k: t0 + v * dt for k, v in arrivals.items()}),
        window=(t0 + start * dt, t0 + stop * dt),
        balance_error=balance,
        impulse_error=impulse,
        dispersion=dispersion,
    )
