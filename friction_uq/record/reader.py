"""Read and check a confined friction test record (``test.h5``, format version 1).

This module is the reading boundary of the package:

* every rule of the contract is checked here, and a file that breaks one is refused with a
  :class:`~friction_uq.errors.RecordError` naming the file, the path inside it and the problem;
* gauge signals are converted to strain and **their sign is flipped here, once**: inside the
  package strains are positive in compression (a compressive bar wave reads positive, a swelling
  tube reads negative on the hoop channel);
* the result is one immutable :class:`~friction_uq.record.Record` (frozen dataclasses, read-only
  arrays).
"""

from __future__ import annotations

import os
from datetime import datetime
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from ..apparatus import Apparatus
from ..errors import RecordError
from ._apparatus_reader import read_apparatus
from ..plausible import (
    MAX_ATTRIBUTE_BYTES,
    MAX_ID_CHARS,
    MAX_RECORD_BYTES,
    apparatus_problem,
    escaped,
    out_of_range,
    text_bytes,
    unprintable,
)
from ._checks import Reader, check_dataset, check_distinct, check_samples, check_strain, plain, sha256_of
from .contract import (
    CHANNELS,
    FORMAT,
    FORMAT_VERSION,
    MIN_SAMPLES,
    REQUIRED_CHANNELS,
    UNITS,
    Channel,
    Record,
)


def read_record(path: str | os.PathLike[str], *, hoop: bool = True) -> Record:
    """Read, check and convert a ``test.h5`` record.

    Parameters
    ----------
    path
        The record file.
    hoop
        Read the hoop gauge (``/signals/tube_hoop``, optional) if the record has one; False leaves it
        unread and unchecked (``--no-hoop``: a dead hoop bridge does not stop the analysis).

    Returns
    -------
    Record
        Channels in strain, compression positive; apparatus with derived quantities.

    Raises
    ------
    RecordError
        If the file breaks the contract; the message names the file, the path inside it and what
        is wrong.
    """
    import h5py

    p = Path(path)
    r = Reader(p)
    if not p.exists():
        raise r.fail("/", "file not found")
    if p.is_dir():
        raise r.fail("/", "is a directory, not an HDF5 file")
    try:
        is_hdf5 = h5py.is_hdf5(p)
    except OSError as exc:  # unreadable
        raise r.fail("/", f"cannot be read ({exc.strerror or exc})") from None
    if not is_hdf5:
        raise r.fail("/", "is not an HDF5 file (no HDF5 signature); a test record must be HDF5")
    size = p.stat().st_size
    if size > MAX_RECORD_BYTES:
        raise r.fail("/", f"is {size / 2**20:.0f} MiB, more than the {MAX_RECORD_BYTES // 2**20} MiB a record may be "
                     "(docs/limits.md)")
    try:
        fh = h5py.File(p, "r")
    except OSError as exc:
        raise r.fail("/", f"is a damaged or truncated HDF5 file ({exc})") from None
    try:
        with fh:
            return _read_open(fh, p, r, hoop)
    except RecordError:
        raise
    except (OSError, KeyError, RuntimeError) as exc:
        raise r.fail("/", f"is a damaged or truncated HDF5 file ({exc})") from None


def _read_open(fh: Any, p: Path, r: Reader, hoop: bool = True) -> Record:
    """The record of an open file, checked part by part in the order of the contract: the root's attributes, the
    apparatus, the signals, the provenance; the first problem raises ``r.fail`` (file, field, problem)."""
    header = _read_header(fh, r)
    apparatus = _read_apparatus(fh, r)
    sample_rate, t0, channels = _read_signals(fh, r, apparatus, hoop)
    return Record(
        path=str(p),
        sample_rate=sample_rate,
        t0=t0,
        channels=MappingProxyType(channels),
        apparatus=apparatus,
        provenance=MappingProxyType(_read_provenance(fh, r)),
        sha256=sha256_of(p),
        **header,
    )


def _read_header(fh: Any, r: Reader) -> dict[str, Any]:
    """The root's attributes: the format and its version, the ids, the date, the description and the striker's
    speed (the :class:`Record` fields they fill)."""
    fmt = r.attr(fh, "/", "format", "str")
    if fmt != FORMAT:
        raise r.fail("/@format", f"is {fmt!r}, expected {FORMAT!r}")
    version = r.attr(fh, "/", "format_version", "int")
    if version > FORMAT_VERSION:
        raise r.fail(
            "/@format_version",
            f"is {version}, newer than the {FORMAT_VERSION} this friction-uq reads; upgrade friction-uq",
        )
    if version < 1:
        raise r.fail("/@format_version", f"is {version}, expected {FORMAT_VERSION}")
    test_id = r.attr(fh, "/", "test_id", "str")
    campaign = r.attr(fh, "/", "campaign", "str")
    for key, value in (("test_id", test_id), ("campaign", campaign)):
        if not value.strip():
            raise r.fail(f"/@{key}", "is empty")
        if len(value) > MAX_ID_CHARS:
            raise r.fail(f"/@{key}", f"is {len(value)} characters long, more than the {MAX_ID_CHARS} an id may be "
                         "(it names the output files)")
        bad = unprintable(value)
        if bad:
            raise r.fail(f"/@{key}", f"{bad} ('{escaped(value)}'): an id is printed on terminals and names files")
        try:  # bytes that are not UTF-8: h5py reads a string's as lone surrogates, a fixed-length one's as U+FFFD
            value.encode("utf-8")
            utf8 = "\ufffd" not in value
        except UnicodeEncodeError:
            utf8 = False
        if not utf8:  # the id would name the output files A___
            raise r.fail(f"/@{key}", f"is not UTF-8 text ({value.encode('utf-8', 'backslashreplace')!r} as read); an "
                         "id names the output files")
    date = r.attr(fh, "/", "date", "str", required=False)
    if date is not None:
        try:
            datetime.fromisoformat(date)
        except ValueError:
            raise r.fail(
                "/@date", f"is {date!r}, not an ISO 8601 date such as '2016-03-01' or '2016-03-01T10:42:00'"
            ) from None
    description = r.attr(fh, "/", "description", "str", required=False)
    striker_velocity = r.attr(fh, "/", "striker_velocity", "float", required=False)
    if striker_velocity is not None and striker_velocity <= 0:
        raise r.fail("/@striker_velocity", f"must be > 0 m/s, got {striker_velocity!r}")
    if striker_velocity is not None and out_of_range("striker_velocity", striker_velocity):
        raise r.fail("/@striker_velocity", out_of_range("striker_velocity", striker_velocity))
    return dict(test_id=test_id, campaign=campaign, date=date, description=description,
                striker_velocity=striker_velocity)


def _group(parent: Any, name: str, r: Reader) -> Any:
    """A required group under ``parent`` (the root)."""
    import h5py

    g = r.member(parent, name, f"/{name}")
    if g is None:
        raise r.fail(f"/{name}", "required group is missing")
    if not isinstance(g, h5py.Group):
        raise r.fail(f"/{name}", "must be a group")
    return g


def _read_apparatus(fh: Any, r: Reader) -> Apparatus:
    """/apparatus: its parts, checked together (:func:`apparatus_problem`), and the sample's material printable."""
    apparatus = read_apparatus(_group(fh, "apparatus", r), r)
    implausible = apparatus_problem(apparatus)
    if implausible:
        part, attr, problem = implausible
        raise r.fail(f"/apparatus/{part}@{attr}", problem)
    bad = unprintable(apparatus.sample.material)
    if bad:
        raise r.fail("/apparatus/sample@material", f"{bad} ('{escaped(apparatus.sample.material)}')")
    return apparatus


def _read_signals(fh: Any, r: Reader, apparatus: Apparatus,
                  hoop: bool = True) -> tuple[float, float, dict[str, Channel]]:
    """/signals: the sample rate, t0 and every channel (the required ones present, all of one length; the hoop
    gauge's only with ``hoop``), the record long enough for the reflected wave to pass the input-bar gauge."""
    sig = _group(fh, "signals", r)
    sample_rate = r.attr(sig, "/signals", "sample_rate", "float")
    if sample_rate <= 0:
        raise r.fail("/signals@sample_rate", f"must be > 0 Hz, got {sample_rate!r}")
    t0 = r.attr(sig, "/signals", "t0", "float", required=False)
    t0 = 0.0 if t0 is None else t0
    for key, value in (("sample_rate", sample_rate), ("t0", t0)):
        if out_of_range(f"signals.{key}", value):
            raise r.fail(f"/signals@{key}", out_of_range(f"signals.{key}", value))
    channels: dict[str, Channel] = {}
    length: int | None = None
    first: str | None = None
    for name in CHANNELS if hoop else REQUIRED_CHANNELS:
        where = f"/signals/{name}"
        try:
            ds = r.member(sig, name, where)
            if ds is None:
                if name in REQUIRED_CHANNELS:
                    raise r.fail(where, "required channel is missing")
                continue
            check_dataset(ds, where, r)
            if length is None:
                length, first = ds.shape[0], name
                if length < MIN_SAMPLES:
                    raise r.fail(where, f"has {length} samples, at least {MIN_SAMPLES} are needed")
            elif ds.shape[0] != length:
                raise r.fail(where, f"has {ds.shape[0]} samples but /signals/{first} has {length}; channels must "
                             "have equal length")
            channels[name] = _read_channel(ds, name, where, r, channels)
        except RecordError as exc:
            if name in REQUIRED_CHANNELS:
                raise
            raise RecordError(exc.file, exc.where, f"{exc.problem} (the hoop gauge is optional: `run`, `diagnose` "
                              "and `campaign` analyse the record without it with --no-hoop)") from None
    assert length is not None  # REQUIRED_CHANNELS is not empty
    duration = length / sample_rate
    needed = 2.0 * apparatus.input_bar.gauge_delay + apparatus.pulse_duration
    if duration < needed:
        raise r.fail(
            "/signals",
            f"lasts {duration * 1e6:.0f} us, too short to hold the reflected wave: the input-bar gauge "
            f"needs at least 2 x gauge_distance / wave_speed + 2 x striker length / striker wave speed "
            f"= {needed * 1e6:.0f} us",
        )
    return sample_rate, t0, channels


def _read_channel(ds: Any, name: str, where: str, r: Reader, read: dict[str, Channel]) -> Channel:
    """One channel as strain, compression positive (the package's one sign flip), its units and, for volts, the
    strain per volt; checked sample by sample, as strain, and against the channels ``read`` before it."""
    units = r.attr(ds, where, "units", "str")
    if units not in UNITS:
        raise r.fail(f"{where}@units", f"is {units!r}, allowed: {', '.join(UNITS)}")
    spv = None
    if units == "V":
        spv = r.attr(ds, where, "strain_per_volt", "float", required=False)
        if spv is None:
            raise r.fail(where, "units are 'V' but attribute 'strain_per_volt' is missing")
        if spv == 0:
            raise r.fail(f"{where}@strain_per_volt", "must not be zero")
        if out_of_range("signals.strain_per_volt", abs(spv)):
            raise r.fail(f"{where}@strain_per_volt", out_of_range("signals.strain_per_volt", abs(spv)))
        scale = spv
    else:
        scale = UNITS[units]
    try:  # a chunk HDF5 cannot decompress or read: the dataset named, not the file's root
        raw = np.asarray(ds[()], dtype=np.float64)
    except OSError as exc:
        raise r.fail(where, f"cannot be read: its stored data are damaged ({exc})") from None
    check_samples(raw, where, r)
    strain = -scale * raw  # the one sign flip of the package: compression positive from here on
    strain.setflags(write=False)
    check_strain(strain, where, r)
    check_distinct(strain, read, where, r)
    return Channel(name, strain, units, spv)


def _read_provenance(fh: Any, r: Reader) -> dict[str, Any]:
    """/provenance's attributes (optional, free-form), each bounded like every attribute."""
    import h5py

    prov = r.member(fh, "provenance", "/provenance")
    if prov is None:
        return {}
    if not isinstance(prov, h5py.Group):
        raise r.fail("/provenance", "must be a group")
    provenance = {}
    for k in prov.attrs:
        try:  # an attribute HDF5 cannot size or read (a null dataspace, a type it lacks): named, not "damaged"
            if prov.attrs.get_id(k).get_storage_size() > MAX_ATTRIBUTE_BYTES:
                raise r.fail(f"/provenance@{k}", f"is larger than the {MAX_ATTRIBUTE_BYTES} bytes an attribute may be")
            provenance[k] = plain(prov.attrs[k])
        except (KeyError, OSError, RuntimeError, TypeError, ValueError) as exc:
            raise r.fail(f"/provenance@{k}", f"cannot be read ({exc})") from None
    for k, v in provenance.items():  # a variable-length string is stored apart: its storage size does not count it
        if isinstance(v, str) and text_bytes(v) > MAX_ATTRIBUTE_BYTES:
            raise r.fail(f"/provenance@{k}", f"is larger than the {MAX_ATTRIBUTE_BYTES} bytes an attribute may be")
    return provenance


def read_truth(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The ``/truth`` attributes of a synthetic record (validation only; the analysis never reads them)."""
    import h5py

    with h5py.File(path, "r") as fh:
        if "truth" not in fh:
            return {}
        return {k: plain(v) for k, v in fh["truth"].attrs.items()}
