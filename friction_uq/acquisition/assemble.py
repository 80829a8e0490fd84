"""From oscilloscope files and a SETUP.toml to one checked record (``test.h5``).

Each gauge is read from its file and column, converted to the unit the record stores (millivolts
to volts; strain and microstrain as they are), and multiplied by its ``sign`` so that positive is
elongation, as the record contract says. The channels must share one time base: equal lengths,
equal sample intervals, starts within half a sample. The record is written to a temporary file,
read back by :func:`friction_uq.record.read_record` (so it follows the contract), checked for a
gauge that disagrees with the others (:mod:`friction_uq.gauge_check`), and only then renamed into
place: a refused import leaves nothing behind.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from ..record.writer import write_apparatus
from .._atomic import atomic_path
from ..errors import RecordError, ScopeFileError, SetupError
from ..plausible import not_regular
from ..record.contract import FORMAT, FORMAT_VERSION
from .binary import BINARY_SUFFIXES, Trace, read_binary
from .delimited import TextTable, read_delimited
from .file_units import channel_unit_conflict, time_unit_conflict
from .setup_file import ChannelSetup, Setup, load_setup
from .timebase import time_base

#: Largest relative difference of two channels' sample intervals.
RATE_TOL = 1e-6


@dataclass(frozen=True)
class Channel:
    """A gauge's samples as read, with where they came from and their time base."""

    setup: ChannelSetup
    file: Path
    label: str
    values: np.ndarray
    t0: float
    dt: float


@dataclass(frozen=True)
class ImportOutcome:
    """What an import wrote and what its checks found."""

    path: Path
    n_samples: int
    sample_rate: float
    t0: float
    warnings: tuple[str, ...]
    sources: dict[str, str]


def _file_of(setup: Setup, ch: ChannelSetup, files: Sequence[Path]) -> Path:
    where = f"{setup.path}: [channels.{ch.gauge}]"
    if ch.file is None:
        if len(files) == 1:
            return files[0]
        raise SetupError(f"{where}: several files were given; say which holds this gauge with file = \"NAME\" "
                         f"(one of {', '.join(f.name for f in files)})")
    hits = [f for f in files if str(f) == ch.file] or [f for f in files if f.name == ch.file]
    if not hits:
        raise SetupError(f"{where} file: {ch.file!r} is not among the files given ({', '.join(str(f) for f in files)})")
    if len({f.resolve() for f in hits}) > 1:  # one name in two folders: which one holds the gauge cannot be guessed
        raise SetupError(f"{where} file: {ch.file!r} names {len(hits)} of the files given "
                         f"({', '.join(str(f) for f in hits)}); write the file's path as given instead")
    return hits[0]


def _read_file(setup: Setup, file: Path, chans: list[ChannelSetup]) -> list[Channel]:
    cols: list[str | int] = list(dict.fromkeys(c.column for c in chans))
    ts = setup.time
    time_col = ts.column if ts is not None else None
    if file.suffix.lower() in BINARY_SUFFIXES:
        wanted = cols + ([time_col] if time_col is not None and time_col not in cols else [])
        traces = read_binary(file, wanted)
        time = traces[time_col].values if time_col is not None else None
        first = None  # a binary file's time channel is named by sample, not by line
    else:
        if time_col is None and (ts is None or ts.sample_rate is None):
            raise SetupError(f"{setup.path}: [time]: a text export has no time base of its own; give [time] column "
                             "= the time column's name or number, or sample_rate (Hz) and t0 (s)")
        wanted = cols + ([time_col] if time_col is not None and time_col not in cols else [])
        table = read_delimited(file, wanted)
        _check_units(setup, file, table, chans)
        traces = {k: Trace(v, table.labels[k]) for k, v in table.columns.items()}
        time = table.columns[time_col] if time_col is not None else None
        first = table.first_data_line
    out = []
    for c in chans:
        tr = traces[c.column]
        t0, dt = time_base(setup, file, time, tr, first)
        out.append(Channel(c, file, tr.label, tr.values, t0, dt))
    return out


def _check_units(setup: Setup, file: Path, table: TextTable, chans: list[ChannelSetup]) -> None:
    """Refuse a channel or time column whose unit in the file (a units row, or its name's bracketed end) is not the
    one SETUP.toml declares: the file's numbers would be read a thousand or a million times off."""
    for c in chans:
        problem = channel_unit_conflict(table.units.get(c.column), c.units)
        if problem:
            raise SetupError(f"{setup.path}: [channels.{c.gauge}] units: is {c.units!r}, but {file} gives column "
                             f"{table.labels[c.column]} in {table.units[c.column]} by {table.units_from[c.column]}; {problem}")
    ts = setup.time
    if ts is not None and ts.column is not None:
        problem = time_unit_conflict(table.units.get(ts.column), ts.units)
        if problem:
            raise SetupError(f"{setup.path}: [time] units: is {ts.units!r}, but {file} gives the time column "
                             f"{table.labels[ts.column]} in {table.units[ts.column]} by {table.units_from[ts.column]}; {problem}")


def _common_time_base(chans: list[Channel]) -> tuple[float, float, int]:
    ref = chans[0]
    for c in chans[1:]:
        if len(c.values) != len(ref.values):
            raise ScopeFileError(f"{c.file}: column {c.label} ({c.setup.gauge}) has {len(c.values)} samples but "
                                 f"{ref.file} column {ref.label} ({ref.setup.gauge}) has {len(ref.values)}; the "
                                 "channels of a record must have equal lengths (export the same time span)")
        if abs(c.dt - ref.dt) > RATE_TOL * ref.dt:
            raise ScopeFileError(f"{c.file}: {c.setup.gauge} is sampled every {c.dt:.6g} s but {ref.setup.gauge} in "
                                 f"{ref.file} every {ref.dt:.6g} s; the channels must share one sample rate")
        if abs(c.t0 - ref.t0) > 0.5 * ref.dt:
            raise ScopeFileError(f"{c.file}: {c.setup.gauge} starts at {c.t0:.9g} s but {ref.setup.gauge} in "
                                 f"{ref.file} at {ref.t0:.9g} s; the channels must share one time base (one trigger)")
    return ref.t0, ref.dt, len(ref.values)


def _write(tmp: str, setup: Setup, chans: list[Channel], t0: float, dt: float) -> None:
    import h5py

    from .. import __version__

    with h5py.File(tmp, "w") as fh:
        fh.attrs["format"] = FORMAT
        fh.attrs["format_version"] = FORMAT_VERSION
        for k, v in setup.record.items():
            fh.attrs[k] = v
        sig = fh.create_group("signals")
        sig.attrs["sample_rate"] = 1.0 / dt
        sig.attrs["t0"] = t0
        for c in chans:
            s = c.setup
            ds = sig.create_dataset(s.gauge, data=c.values * (s.scale * s.sign))
            ds.attrs["units"] = s.stored_units
            if s.strain_per_volt is not None:
                ds.attrs["strain_per_volt"] = s.strain_per_volt
            ds.attrs["source_file"] = c.file.name
            ds.attrs["source_column"] = str(c.label)
            ds.attrs["source_units"] = s.units
            ds.attrs["sign_applied"] = s.sign
            for k, v in s.conversion.items():
                ds.attrs[k] = v
        write_apparatus(fh, setup.apparatus)
        prov = fh.create_group("provenance")
        prov.attrs["generator"] = "friction-uq import"
        prov.attrs["generator_version"] = __version__
        prov.attrs["created"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
        prov.attrs["setup_file"] = setup.path.name
        prov.attrs["source_files"] = ", ".join(dict.fromkeys(c.file.name for c in chans))


def _translate(exc: RecordError, setup: Setup, chans: list[Channel]) -> Exception:
    """A contract refusal of the written record, said in terms of SETUP.toml or the scope file."""
    where, problem = exc.where, exc.problem
    if where.startswith("/apparatus/"):
        part, _, attr = where.removeprefix("/apparatus/").partition("@")
        return SetupError(f"{setup.path}: [apparatus.{part}]{' ' + attr if attr else ''}: {problem}")
    if where.startswith("/@"):
        return SetupError(f"{setup.path}: [record] {where[2:]}: {problem}")
    for c in chans:
        if where.startswith(f"/signals/{c.setup.gauge}"):
            return ScopeFileError(f"{c.file}: column {c.label} ([channels.{c.setup.gauge}]): {problem}")
    files = ", ".join(dict.fromkeys(str(c.file) for c in chans))
    return ScopeFileError(f"{files}: {problem}")


def import_scope_files(files: Sequence[str | os.PathLike[str]], setup: Setup | str | os.PathLike[str],
                       output: str | os.PathLike[str], *, check: bool = True) -> ImportOutcome:
    """Read oscilloscope files as ``setup`` describes them and write a checked record to ``output``.

    Parameters
    ----------
    files
        One file with every channel, or one file per channel (then each channel's ``file`` names its own).
    setup
        A :class:`~friction_uq.acquisition.setup_file.Setup` or the path of a SETUP.toml.
    output
        The record to write (``.h5``); written only when every check passes.
    check
        Refuse a record whose gauges contradict each other (reversed, swapped, a scale off); with
        ``False`` the findings are returned as warnings and the record is written all the same.

    Raises
    ------
    SetupError, ScopeFileError
        One sentence naming the file, the line, column or key, and the problem.
    """
    st = setup if isinstance(setup, Setup) else load_setup(setup)
    paths = [Path(f) for f in files]
    if not paths:
        raise ScopeFileError("no oscilloscope file given")
    for p in paths:
        if not p.is_file():
            raise ScopeFileError(f"{p}: {not_regular(p) or 'file not found'}")
    by_file: dict[Path, list[ChannelSetup]] = {}
    for ch in st.channels.values():
        by_file.setdefault(_file_of(st, ch, paths), []).append(ch)
    chans = [c for f, cs in by_file.items() for c in _read_file(st, f, cs)]
    t0, dt, n = _common_time_base(chans)
    out = Path(output)
    with atomic_path(out) as tmp:
        _write(tmp, st, chans, t0, dt)
        warnings = _read_back_and_check(tmp, st, chans, check)
    sources = {c.setup.gauge: f"{c.file.name} column {c.label}" for c in chans}
    return ImportOutcome(out, n, 1.0 / dt, t0, warnings, sources)


def _read_back_and_check(tmp: str, setup: Setup, chans: list[Channel], check: bool) -> tuple[str, ...]:
    from ..record import read_record
    from .sanity import import_findings

    try:
        rec = read_record(tmp)
    except RecordError as exc:
        raise _translate(exc, setup, chans) from None
    refusals, warnings = import_findings(rec, setup)
    said = []
    for channel, text in refusals:
        c = next((c for c in chans if c.setup.gauge == channel), None)
        said.append(f"{c.file}: column {c.label} ([channels.{channel}]): {text}" if c else f"{setup.path}: {text}")
    if said and check:
        raise ScopeFileError(f"{said[0]} (friction-uq import --no-check writes the record anyway)")
    return tuple(said + warnings)


def describe(outcome: ImportOutcome) -> list[str]:
    """Lines ``friction-uq import`` prints."""
    lines = [f"wrote {outcome.path}: {outcome.n_samples} samples at {outcome.sample_rate / 1e6:g} MHz, "
             f"t0 = {outcome.t0 * 1e6:.2f} us"]
    lines += [f"  {g:<20} <- {src}" for g, src in outcome.sources.items()]
    lines += [f"WARNING: {w}" for w in outcome.warnings]
    return lines

