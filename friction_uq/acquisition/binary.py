"""Oscilloscope and acquisition files in binary formats, each through its maintained reader.

===========================  ==================  ==============================================
format (extension)           reader              channels (``column`` in SETUP.toml)
===========================  ==================  ==============================================
NI TDMS (``.tdms``)          npTDMS              ``"group/channel"``, a channel name unique in
                                                 the file, or its 1-based number in file order
LeCroy trace (``.trc``)      lecroyparser        one trace per file: ``column = 1``
Tektronix (``.wfm``,         RigolWFM            channel number (1-4) or name (``"CH1"``)
``.isf``), Rigol (``.wfm``,
``.bin``), Keysight,
Siglent, Yokogawa
===========================  ==================  ==============================================

npTDMS is a dependency of friction-uq (:mod:`.tdms` reads TDMS files); lecroyparser and RigolWFM come
with the ``scopes`` extra (``pip install 'friction-uq[scopes]'``). Each trace carries its own time
base (start and sample interval), so ``[time]`` may be left out of SETUP.toml for these files.

The number of samples is checked against the sample limit of a record (docs/limits.md) before the
samples are decoded, from what the file's header declares (:mod:`.declared`): a LeCroy trace's
WAVEDESC descriptor, a Tektronix ISF header and curve block, a Tektronix WFM header. The other
formats RigolWFM reads are checked as soon as RigolWFM has parsed them, before their samples are
copied.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ScopeFileError
from ..plausible import MAX_SAMPLES
from .declared import lecroy_declared, over_limit, rigolwfm_declared
from .tdms import describe_tdms, read_tdms
from .trace import MAX_BINARY_BYTES, Trace, check_size, need

__all__ = ["BINARY_SUFFIXES", "MAX_BINARY_BYTES", "Trace", "describe_binary", "read_binary", "read_tdms"]

TDMS_SUFFIXES = (".tdms",)
LECROY_SUFFIXES = (".trc",)
RIGOLWFM_SUFFIXES = (".wfm", ".isf", ".bin")
BINARY_SUFFIXES = TDMS_SUFFIXES + LECROY_SUFFIXES + RIGOLWFM_SUFFIXES


def _sample_interval(path: Path, dt: float, where: str) -> float:
    """``dt`` if it is a positive finite interval, else :class:`ScopeFileError` naming the file and ``where`` the file
    keeps it (a damaged header's 0, NaN or negative step is no time base)."""
    if not (math.isfinite(dt) and dt > 0.0):
        raise ScopeFileError(f"{path}: {where}: the sample interval is {dt!r} s; it must be a positive number (a "
                             "damaged header?)")
    return dt


def _rate_digits(dt: float, digits: int = 7) -> float:
    """A sample interval stored in single precision, rounded to the rate it stands for (1/dt to 7 digits)."""
    rate = 1.0 / dt
    scale = 10 ** (digits - 1 - math.floor(math.log10(rate)))
    return 1.0 / (round(rate * scale) / scale)


def read_lecroy(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """The single trace of a LeCroy ``.trc`` file, in volts, with its time base."""
    check_size(path)
    lecroyparser = need("lecroyparser", path)
    for col in columns:
        if col not in (1, "1"):
            raise ScopeFileError(f"{path}: a LeCroy .trc file holds one trace: give column = 1, not {col!r}")
    lecroy_declared(path)  # the descriptor's counts, before lecroyparser decodes the samples
    try:
        with np.errstate(all="ignore"):  # a damaged descriptor's inf or NaN is said below, not as numpy's warning
            d = lecroyparser.ScopeData(str(path))  # type: ignore[attr-defined]
    except Exception as exc:
        raise ScopeFileError(f"{path}: not a readable LeCroy trace ({type(exc).__name__}: {exc})") from None
    # the sample interval and start from the descriptor (the parser's x spans n intervals over n - 1 steps)
    dt = _rate_digits(_sample_interval(path, float(d.horizInterval), "the descriptor's HORIZ_INTERVAL"))
    tr = Trace(np.asarray(d.y, dtype=np.float64), f"trace of {d.waveSource}", float(d.horizOffset), dt)
    return {col: tr for col in columns}


def _open_rigolwfm(path: Path) -> Any:
    """The waveform file as RigolWFM parses it, once the counts its header declares are checked."""
    check_size(path)
    need("RigolWFM", path)
    import RigolWFM.wfm as wfm  # type: ignore[import-not-found]

    rigolwfm_declared(path)
    try:
        return wfm.Wfm.from_file(str(path), "auto")
    except Exception as exc:
        raise ScopeFileError(f"{path}: not a waveform file RigolWFM can read ({type(exc).__name__}: {exc})") from None


def _pick_channel(path: Path, chans: list[Any], col: str | int) -> Any:
    """The channel ``col`` names (its number or name), its length checked against the sample limit."""
    key = str(col).upper().replace(" ", "")
    hits = [c for c in chans if key in (str(c.channel_number), c.name.upper().replace(" ", ""))]
    if not hits:
        have = ", ".join(f"{c.channel_number} ({c.name})" for c in chans) or "none"
        raise ScopeFileError(f"{path}: no channel {col!r} with data; the file has {have}")
    c = hits[0]
    if len(c.volts) > MAX_SAMPLES:
        raise over_limit(path, f"channel {c.channel_number} ({c.name}), as RigolWFM decoded it,",
                         len(c.volts), "holds", MAX_SAMPLES)
    return c


def read_rigolwfm(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """Channels of a Tektronix, Rigol, Keysight, Siglent or Yokogawa waveform file (RigolWFM), in volts.

    Every channel asked for is picked and its length checked before any of them is copied.
    """
    w = _open_rigolwfm(path)
    chans = [c for c in w.channels if getattr(c, "volts", None) is not None and len(c.volts)]
    picked = {col: _pick_channel(path, chans, col) for col in columns}
    out: dict[str | int, Trace] = {}
    for col, c in picked.items():
        t0, step = _channel_time_base(path, c)
        dt = _rate_digits(step, 9) if step is not None else None
        out[col] = Trace(np.asarray(c.volts, dtype=np.float64), c.name, t0, dt)
    return out


def _channel_time_base(path: Path, channel: Any) -> tuple[float, float | None]:
    """A RigolWFM channel's start and sample interval from its times (None for a single sample), checked positive."""
    t = np.asarray(channel.times, dtype=np.float64)
    if len(t) < 2:
        return float(t[0]), None
    return float(t[0]), _sample_interval(path, float((t[-1] - t[0]) / (len(t) - 1)),
                                         f"channel {channel.name}'s time base (its header's sample interval)")


def read_binary(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """Dispatch on the file's extension (:data:`BINARY_SUFFIXES`)."""
    s = path.suffix.lower()
    if s in TDMS_SUFFIXES:
        return read_tdms(path, columns)
    if s in LECROY_SUFFIXES:
        return read_lecroy(path, columns)
    return read_rigolwfm(path, columns)


def describe_binary(path: Path) -> list[str]:
    """What a binary scope file holds, for writing SETUP.toml: its channels, lengths and time bases."""
    s = path.suffix.lower()
    if s in TDMS_SUFFIXES:
        return describe_tdms(path)
    traces = read_lecroy(path, [1]) if s in LECROY_SUFFIXES else None
    if traces is not None:
        t = traces[1]
        return [f"{path}: LeCroy trace, column = 1",
                f"  {t.label}: {len(t.values)} samples every {t.dt:.6g} s from {t.t0:.6g} s"]
    w = _open_rigolwfm(path)
    out = [f"{path}: {w.header_name} waveform; column = the channel number"]
    for c in w.channels:
        if getattr(c, "volts", None) is not None and len(c.volts):
            t0, dt = _channel_time_base(path, c)
            base = f" every {dt:.6g} s from {t0:.6g} s" if dt is not None else ""
            out.append(f"  {c.channel_number} ({c.name}): {len(c.volts)} samples{base}")
    return out
