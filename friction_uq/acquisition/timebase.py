"""A channel's time base (start and sample interval), and where it came from when it is not plausible.

Three sources, in this order: ``[time] sample_rate`` and ``t0`` of SETUP.toml; a time column of
the file (in ``[time] units``), which must hold finite, evenly spaced, increasing times; the time
base the file itself carries (TDMS ``wf_increment`` and ``wf_start_offset``, a LeCroy or Tektronix
header). A sample rate or start outside the plausible range of a record (docs/limits.md) is
refused naming that source: the SETUP key, or the file and the property it was read from.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ScopeFileError, SetupError
from ..plausible import out_of_range
from .setup_file import TIME_UNITS, Setup
from .trace import Trace

#: Largest departure of a time column from even spacing, in sample intervals.
TIME_JITTER = 0.25


def _place(first_line: int | None, i: int) -> str:
    """Where the ``i``-th value of a time column is: a line of a text export, else a sample of a channel."""
    return f"line {first_line + i}" if first_line is not None else f"sample {i + 1}"


def _from_column(setup: Setup, file: Path, table_time: np.ndarray, first_line: int | None) -> tuple[float, float]:
    """(t0, dt) of a time column: finite, increasing, evenly spaced (within :data:`TIME_JITTER` of a step)."""
    ts = setup.time
    assert ts is not None
    n = len(table_time)
    if n < 2:
        raise ScopeFileError(f"{file}: the time column has {n} value(s); a record needs many samples")
    bad = np.flatnonzero(~np.isfinite(table_time))
    if bad.size:
        i = int(bad[0])
        raise ScopeFileError(f"{file}: {_place(first_line, i)}: the time column {ts.column!r} holds "
                             f"{float(table_time[i])!r}, not a finite time")
    t = table_time * TIME_UNITS[ts.units]
    step = np.diff(t)
    dt = float(np.median(step))
    if not dt > 0:
        raise ScopeFileError(f"{file}: the time column {ts.column!r} does not increase "
                             f"(from {t[0]:g} to {t[-1]:g} s)")
    bad = np.flatnonzero(np.abs(step - dt) > TIME_JITTER * dt)  # a jump between two rows
    if bad.size:
        i = int(bad[0]) + 1
        raise ScopeFileError(f"{file}: {_place(first_line, i)}: the time column {ts.column!r} is not evenly spaced "
                             f"(it reads {t[i]:.9g} s where a step of {dt:.6g} s from the row before gives "
                             f"{t[i - 1] + dt:.9g} s): a gap, a second segment or a time column in another unit "
                             "(see [time] units)")
    dt = (t[-1] - t[0]) / (n - 1)  # the mean step: the printed times' rounding averages out
    bad = np.flatnonzero(np.abs(t - (t[0] + np.arange(n) * dt)) > TIME_JITTER * dt)  # or a slow drift
    if bad.size:
        i = int(bad[0])
        raise ScopeFileError(f"{file}: {_place(first_line, i)}: the time column {ts.column!r} drifts from an even "
                             f"step of {dt:.6g} s (it reads {t[i]:.9g} s, the step gives {t[0] + i * dt:.9g} s)")
    rate = float(f"{1.0 / dt:.9g}")  # the rate to 9 digits: the printed times' rounding is not a rate
    return float(t[0]), 1.0 / rate


def _implausible(t0: float, dt: float) -> tuple[str, str] | None:
    """("sample_rate" or "t0", the problem) when the time base lies outside a record's plausible ranges."""
    for key, value in (("sample_rate", 1.0 / dt), ("t0", t0)):
        problem = out_of_range(f"signals.{key}", value)
        if problem:
            return key, problem
    return None


def time_base(setup: Setup, file: Path, table_time: np.ndarray | None, trace: Trace,
              first_line: int | None) -> tuple[float, float]:
    """(t0, dt) of a channel: from [time] sample_rate, from the time column, or from the file's own time base.

    ``first_line`` is the line of a text export's first data row (None for a binary file, whose time
    column's values are named by sample).
    """
    ts = setup.time
    if ts is not None and ts.sample_rate is not None:
        for key, value in (("sample_rate", ts.sample_rate), ("t0", ts.t0)):
            problem = out_of_range(f"signals.{key}", value)
            if problem:
                raise SetupError(f"{setup.path}: [time] {key}: {problem}")
        return ts.t0, 1.0 / ts.sample_rate
    if table_time is not None:
        assert ts is not None
        t0, dt = _from_column(setup, file, table_time, first_line)
        odd = _implausible(t0, dt)
        if odd:
            what = "sample rate" if odd[0] == "sample_rate" else "time of the first sample"
            raise SetupError(f"{setup.path}: [time] units: the {what} from the time column {ts.column!r} of {file} "
                             f"read in {ts.units!r} {odd[1]}")
        return t0, dt
    if trace.dt is None:
        raise SetupError(f"{setup.path}: [time]: {file} holds no time base; give [time] column = the time column's "
                         "name or number, or sample_rate (Hz) and t0 (s)")
    t0 = float(trace.t0 or 0.0)
    odd = _implausible(t0, trace.dt)
    if odd:
        names = trace.time_names or (f"{trace.label} sample interval", f"{trace.label} start time")
        what = f"{trace.dt!r} s between samples is a sample rate that" if odd[0] == "sample_rate" else "the start"
        raise ScopeFileError(f"{file}: {names[odd[0] == 't0']}: {what} {odd[1]} (or give [time] sample_rate and "
                             f"t0 in {setup.path.name})")
    return t0, trace.dt
