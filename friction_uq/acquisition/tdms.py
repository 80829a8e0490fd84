"""NI TDMS files (npTDMS): channels by ``"group/channel"``, by a name unique in the file, or by number.

What a channel declares is checked from the file's metadata before any sample is read
(:meth:`nptdms.TdmsFile.open` reads the metadata and leaves the data on disk): its length against
the sample limit of a record (docs/limits.md), its data type (real numbers; not text, booleans,
complex numbers or timestamps), and its time base, the properties ``wf_increment`` (the sample
interval, a positive number of seconds) and ``wf_start_offset`` (the time of the first sample).
Only then are the channels asked for read, one at a time, scaled as the file says.
"""

from __future__ import annotations

import logging
import math
import numbers
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ScopeFileError
from ..plausible import MAX_SAMPLES
from .trace import Trace, check_size, need

#: What a channel of another data type holds, in words (by numpy's dtype kind).
_KINDS = {"b": "booleans", "c": "complex numbers", "M": "timestamps", "m": "time intervals", "O": "text",
          "U": "text", "S": "text"}


class _Said(logging.Handler):
    """npTDMS's log records about a file (a damaged segment, undecodable text), kept to be said in one sentence."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.said: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.said.append(record.getMessage())


@contextmanager
def _captured(nptdms: Any) -> Iterator[list[str]]:
    """npTDMS's warnings while the block runs, kept (the list yielded) and not printed: its console handler, which it
    puts on each of its loggers, is silenced and restored after."""
    log, said = logging.getLogger("nptdms"), _Said()  # npTDMS's module loggers propagate to it
    console = getattr(getattr(getattr(nptdms, "log", None), "log_manager", None), "console_handler", None)
    level = console.level if console is not None else None
    if console is not None:
        console.setLevel(logging.CRITICAL + 1)
    log.addHandler(said)
    try:
        yield said.said
    finally:
        log.removeHandler(said)
        if console is not None:
            console.setLevel(level)


@contextmanager
def _open(path: Path, describing: list[str] | None = None) -> Iterator[Any]:
    """The TDMS file with its metadata read and its data left on disk. npTDMS's warnings (a damaged segment, an unknown
    scaling) are not printed (:func:`_captured`): a refusal while the file is open names the first of them, and a
    read that succeeds with one is refused; ``describing`` (a listing's lines, ``--show``) gets it as a line
    instead."""
    check_size(path)
    nptdms = need("nptdms", path)
    with _captured(nptdms) as said:
        try:
            with np.errstate(all="ignore"):
                f = nptdms.TdmsFile.open(str(path))  # type: ignore[attr-defined]
        except Exception as exc:  # npTDMS raises ValueError, KeyError, struct.error on damaged files
            raise ScopeFileError(f"{path}: not a readable TDMS file ({type(exc).__name__}: {exc})") from None
        try:
            yield f
        except ScopeFileError as exc:
            if said:
                raise ScopeFileError(f"{exc}; npTDMS warned: {_short(said[0])}") from None
            raise
        finally:
            f.close()
        if said and describing is None:  # the samples read may not be those recorded (cut short, scaling unknown)
            raise ScopeFileError(f"{path}: npTDMS warned while reading it: {_short(said[0])}; the samples read "
                                 "may not be those recorded (a truncated file, a scaling npTDMS does not know)")
        if said:
            describing.append(f"  npTDMS warned: {_short(said[0])} (an import would refuse this file)")


def _short(text: str, limit: int = 120) -> str:
    """``text`` on one line, at most ``limit`` characters, its control characters escaped (npTDMS quotes raw bytes)."""
    from ..plausible import escaped

    one = escaped(" ".join(text.split()))
    return one if len(one) <= limit else one[:limit - 3] + "..."


def _channels(f: Any) -> list[tuple[str, Any]]:
    """("group/channel", channel) of every channel, in file order."""
    return [(f"{g.name}/{c.name}", c) for g in f.groups() for c in g.channels()]


def _pick(path: Path, chans: list[tuple[str, Any]], col: str | int) -> tuple[str, Any]:
    names = [n for n, _ in chans]
    if isinstance(col, int):
        if col > len(chans):
            raise ScopeFileError(f"{path}: channel number {col} asked for, the file has {len(chans)}: "
                                 f"{', '.join(names)}")
        return chans[col - 1]
    hits = [x for x in chans if x[0] == col] or [x for x in chans if x[1].name == col]
    if len(hits) != 1:
        why = "no channel" if not hits else "several channels"
        raise ScopeFileError(f"{path}: {why} named {col!r}; the file has {', '.join(names) or 'none'} "
                             "(write 'group/channel')")
    return hits[0]


def _property(path: Path, name: str, ch: Any, key: str, *, positive: bool = False) -> float | None:
    """The number a channel's time-base property holds (None when it has none), else one sentence naming it."""
    value = ch.properties.get(key)
    if value is None:
        return None
    where = f"{path}: channel '{name}' property {key}"
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ScopeFileError(f"{where}: must be a number (seconds), got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise ScopeFileError(f"{where}: must be a finite number (seconds), got {x!r}")
    if positive and x <= 0:
        raise ScopeFileError(f"{where}: must be positive (the time between two samples, s), got {x!r}")
    return x


def _time_base(path: Path, name: str, ch: Any) -> tuple[float | None, float | None]:
    """(t0, dt) from ``wf_start_offset`` and ``wf_increment``; (None, None) for a channel without a time base."""
    dt = _property(path, name, ch, "wf_increment", positive=True)
    t0 = _property(path, name, ch, "wf_start_offset")
    if dt is None:
        return None, None
    return (0.0 if t0 is None else t0), dt


def _not_numeric(ch: Any) -> str | None:
    """What a channel holds in words when that is not real numbers (from its declared type), else None."""
    try:
        kind = np.dtype(ch.dtype).kind
    except Exception:  # no data type declared, or one numpy has no name for
        return f"data of type {getattr(ch.data_type, '__name__', ch.data_type)}"
    return None if kind in "iuf" else _KINDS.get(kind, f"data of type {ch.dtype}")


def _check_declared(path: Path, name: str, ch: Any) -> None:
    """The channel's length and data type as the metadata declares them, before a sample is read."""
    n = len(ch)
    if n > MAX_SAMPLES:
        raise ScopeFileError(f"{path}: channel '{name}' declares {n} samples, more than the {MAX_SAMPLES} a record "
                             "may hold (docs/limits.md); export a shorter or decimated record")
    if n == 0:
        raise ScopeFileError(f"{path}: channel '{name}' holds no samples")
    what = _not_numeric(ch)
    if what is not None:
        raise ScopeFileError(f"{path}: channel '{name}' holds {what}, not numeric samples (a gauge's samples are "
                             "real numbers, in volts or strain)")


def _read(path: Path, name: str, ch: Any) -> np.ndarray:
    try:
        values = np.asarray(ch[:])
    except Exception as exc:  # a damaged data section, a scaling npTDMS cannot apply
        raise ScopeFileError(f"{path}: channel '{name}': its samples cannot be read ({type(exc).__name__}: "
                             f"{exc})") from None
    if values.dtype.kind not in "iuf":  # a scaling that turned numbers into something else
        what = _KINDS.get(values.dtype.kind, f"data of type {values.dtype}")
        raise ScopeFileError(f"{path}: channel '{name}' holds {what}, not numeric samples (a gauge's samples are "
                             "real numbers, in volts or strain)")
    return np.asarray(values, dtype=np.float64)


def read_tdms(path: Path, columns: list[str | int]) -> dict[str | int, Trace]:
    """Channels of an NI TDMS file, scaled as the file says (npTDMS applies its scaling).

    Every channel asked for is checked from the metadata (length, data type, time base) before any
    of them is read.
    """
    with _open(path) as f:
        chans = _channels(f)
        picked = {col: _pick(path, chans, col) for col in columns}
        bases = {}
        for col, (name, ch) in picked.items():
            _check_declared(path, name, ch)
            bases[col] = _time_base(path, name, ch)
        out: dict[str | int, Trace] = {}
        for col, (name, ch) in picked.items():
            t0, dt = bases[col]
            names = (f"channel '{name}' property wf_increment", f"channel '{name}' property wf_start_offset")
            out[col] = Trace(_read(path, name, ch), f"'{name}'", t0, dt, names)
        return out


def describe_tdms(path: Path) -> list[str]:
    """A TDMS file's channels with their lengths and time bases, from its metadata alone (no sample is read)."""
    warned: list[str] = []
    with _open(path, warned) as f:
        out = [f"{path}: NI TDMS; column = \"group/channel\""]
        for name, c in _channels(f):
            t0, dt = _time_base(path, name, c)
            tb = f", every {dt:.6g} s from {t0:.6g} s" if dt is not None else ", no time base"
            what = _not_numeric(c)
            kind = f" of {what} (not numeric: cannot be imported)" if what else ""
            out.append(f"  \"{name}\"  {len(c)} samples{kind}{tb}")
    return out + warned
