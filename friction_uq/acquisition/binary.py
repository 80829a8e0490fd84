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

npTDMS is a dependency of friction-uq; lecroyparser and RigolWFM come with the ``scopes`` extra
(``pip install 'friction-uq[scopes]'``). Each trace carries its own time base (start and sample
interval), so ``[time]`` may be left out of SETUP.toml for these files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ScopeFileError

TDMS_SUFFIXES = (".tdms",)
LECROY_SUFFIXES = (".trc",)
RIGOLWFM_SUFFIXES = (".wfm", ".isf", ".bin")
BINARY_SUFFIXES = TDMS_SUFFIXES + LECROY_SUFFIXES + RIGOLWFM_SUFFIXES
#: Largest binary file read (bytes).
MAX_BINARY_BYTES = 4_000_000_000


@dataclass(frozen=True)
class Trace:
    """One channel as a file holds it: its values, a label for messages, and its time base if it has one."""

    values: np.ndarray
    label: str
    t0: float | None = None
    dt: float | None = None


def _rate_digits(dt: float, digits: int = 7) -> float:
    """A sample interval stored in single precision, rounded to the rate it stands for (1/dt to 7 digits)."""
    rate = 1.0 / dt
    scale = 10 ** (digits - 1 - math.floor(math.log10(rate)))
    return 1.0 / (round(rate * scale) / scale)


def _need(module: str, path: Path) -> object:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ScopeFileError(f"{path}: reading this format needs the package {module!r}: "
                             "pip install 'friction-uq[scopes]'") from None


def _size(path: Path) -> None:
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise ScopeFileError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if size > MAX_BINARY_BYTES:
        raise ScopeFileError(f"{path}: {size / 1e9:.1f} GB, larger than the {MAX_BINARY_BYTES / 1e9:.0f} GB read")


def read_tdms(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """Channels of an NI TDMS file, scaled as the file says (npTDMS applies its scaling)."""
    _size(path)
    nptdms = _need("nptdms", path)
    try:
        f = nptdms.TdmsFile.read(str(path))  # type: ignore[attr-defined]
    except Exception as exc:  # npTDMS raises ValueError, KeyError, struct.error on damaged files
        raise ScopeFileError(f"{path}: not a readable TDMS file ({type(exc).__name__}: {exc})") from None
    chans = [(g.name, c.name, c) for g in f.groups() for c in g.channels()]
    names = [f"{g}/{c}" for g, c, _ in chans]
    out: dict[str | int, Trace] = {}
    for col in columns:
        if isinstance(col, int):
            if col > len(chans):
                raise ScopeFileError(f"{path}: channel number {col} asked for, the file has {len(chans)}: "
                                     f"{', '.join(names)}")
            g, c, ch = chans[col - 1]
        else:
            hits = [x for x, n in zip(chans, names) if n == col] or [x for x in chans if x[1] == col]
            if len(hits) != 1:
                why = "no channel" if not hits else "several channels"
                raise ScopeFileError(f"{path}: {why} named {col!r}; the file has {', '.join(names) or 'none'} "
                                     "(write 'group/channel')")
            g, c, ch = hits[0]
        props = ch.properties
        dt = props.get("wf_increment")
        t0 = props.get("wf_start_offset", 0.0)
        values = np.asarray(ch[:], dtype=np.float64)
        out[col] = Trace(values, f"'{g}/{c}'", float(t0) if dt else None, float(dt) if dt else None)
    return out


def read_lecroy(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """The single trace of a LeCroy ``.trc`` file, in volts, with its time base."""
    _size(path)
    lecroyparser = _need("lecroyparser", path)
    for col in columns:
        if col not in (1, "1"):
            raise ScopeFileError(f"{path}: a LeCroy .trc file holds one trace: give column = 1, not {col!r}")
    try:
        d = lecroyparser.ScopeData(str(path))  # type: ignore[attr-defined]
    except Exception as exc:
        raise ScopeFileError(f"{path}: not a readable LeCroy trace ({type(exc).__name__}: {exc})") from None
    # the sample interval and start from the descriptor (the parser's x spans n intervals over n - 1 steps)
    dt = _rate_digits(float(d.horizInterval))
    tr = Trace(np.asarray(d.y, dtype=np.float64), f"trace of {d.waveSource}", float(d.horizOffset), dt)
    return {col: tr for col in columns}


def read_rigolwfm(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """Channels of a Tektronix, Rigol, Keysight, Siglent or Yokogawa waveform file (RigolWFM), in volts."""
    _size(path)
    _need("RigolWFM", path)
    import RigolWFM.wfm as wfm  # type: ignore[import-not-found]

    try:
        w = wfm.Wfm.from_file(str(path), "auto")
    except Exception as exc:
        raise ScopeFileError(f"{path}: not a waveform file RigolWFM can read ({type(exc).__name__}: {exc})") from None
    chans = [c for c in w.channels if getattr(c, "volts", None) is not None and len(c.volts)]
    out: dict[str | int, Trace] = {}
    for col in columns:
        key = str(col).upper().replace(" ", "")
        hits = [c for c in chans if key in (str(c.channel_number), c.name.upper().replace(" ", ""))]
        if not hits:
            have = ", ".join(f"{c.channel_number} ({c.name})" for c in chans) or "none"
            raise ScopeFileError(f"{path}: no channel {col!r} with data; the file has {have}")
        c = hits[0]
        t = np.asarray(c.times, dtype=np.float64)
        dt = _rate_digits((t[-1] - t[0]) / (len(t) - 1), 9) if len(t) > 1 else None
        out[col] = Trace(np.asarray(c.volts, dtype=np.float64), c.name, float(t[0]), dt)
    return out


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
        _size(path)
        nptdms = _need("nptdms", path)
        try:
            f = nptdms.TdmsFile.read(str(path))  # type: ignore[attr-defined]
        except Exception as exc:
            raise ScopeFileError(f"{path}: not a readable TDMS file ({type(exc).__name__}: {exc})") from None
        out = [f"{path}: NI TDMS; column = \"group/channel\""]
        for g in f.groups():
            for c in g.channels():
                dt = c.properties.get("wf_increment")
                start = c.properties.get("wf_start_offset", 0.0)
                tb = f", every {dt:.6g} s from {start:.6g} s" if dt else ", no time base"
                out.append(f"  \"{g.name}/{c.name}\"  {len(c)} samples{tb}")
        return out
    traces = read_lecroy(path, [1]) if s in LECROY_SUFFIXES else None
    if traces is not None:
        t = traces[1]
        return [f"{path}: LeCroy trace, column = 1",
                f"  {t.label}: {len(t.values)} samples every {t.dt:.6g} s from {t.t0:.6g} s"]
    _need("RigolWFM", path)
    import RigolWFM.wfm as wfm  # type: ignore[import-not-found]

    try:
        w = wfm.Wfm.from_file(str(path), "auto")
    except Exception as exc:
        raise ScopeFileError(f"{path}: not a waveform file RigolWFM can read ({type(exc).__name__}: {exc})") from None
    out = [f"{path}: {w.header_name} waveform; column = the channel number"]
    for c in w.channels:
        if getattr(c, "volts", None) is not None and len(c.volts):
            out.append(f"  {c.channel_number} ({c.name}): {len(c.volts)} samples")
    return out
