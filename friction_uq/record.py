"""Read and write a confined friction test record (``test.h5``, format version 1).

The contract is ``shared/spec/test-h5.md``. This module is the reading boundary of the package:

* every rule of the contract is checked here, and a file that breaks one is refused with a
  :class:`~friction_uq.errors.RecordError` naming the file, the path inside it and the problem;
* gauge signals are converted to strain and **their sign is flipped here, once**: inside the
  package strains are positive in compression (a compressive bar wave reads positive, a swelling
  tube reads negative on the hoop channel);
* the result is one immutable :class:`Record` (frozen dataclasses, read-only arrays).

The writer :func:`write_record` is the single way the package writes records (closed-form builders
and the simulator both use it); it flips the sign back and writes atomically.
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from datetime import datetime
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from ._atomic import atomic_path
from .apparatus import (  # noqa: F401  (re-exported: the record's apparatus types)
    DEFAULT_BAR_POISSON_RATIO,
    Apparatus,
    Bar,
    Plug,
    Sample,
    Tube,
    paper_apparatus,
)
from .errors import RecordError

FORMAT = "friction-uq/test"
FORMAT_VERSION = 1

REQUIRED_CHANNELS = ("input_bar", "internal_output_bar", "external_output_bar")
OPTIONAL_CHANNELS = ("tube_hoop",)
CHANNELS = REQUIRED_CHANNELS + OPTIONAL_CHANNELS

UNITS = {"strain": 1.0, "microstrain": 1e-6, "V": None}

#: Minimum run of identical samples at a channel's extreme value that marks it as clipped.
#: The test applies only to channels whose pre-trigger head (first 2 %, at least 32 samples)
#: shows resolved noise: in a noise-free (synthetic) record or one whose noise is below one
#: digitiser step, a run of equal values is a plateau, not a saturated amplifier.
CLIP_RUN = 8

#: Minimum number of samples in a channel.
MIN_SAMPLES = 64


# ----------------------------------------------------------------------------------------------
# Record
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Channel:
    """One gauge channel, converted to strain, **positive in compression**.

    ``units`` and ``strain_per_volt`` are as stored in the file (for display).
    """

    name: str
    strain: np.ndarray
    units: str
    strain_per_volt: float | None = None


@dataclass(frozen=True)
class Record:
    """One confined friction test, read and checked. Immutable."""

    path: str
    test_id: str
    campaign: str
    sample_rate: float
    t0: float
    channels: Mapping[str, Channel]
    apparatus: Apparatus
    date: str | None = None
    description: str | None = None
    striker_velocity: float | None = None
    provenance: Mapping[str, Any] = field(default_factory=dict)
    sha256: str = ""

    @property
    def n_samples(self) -> int:
        return len(next(iter(self.channels.values())).strain)

    @property
    def sample_interval(self) -> float:
        return 1.0 / self.sample_rate

    @property
    def duration(self) -> float:
        return self.n_samples / self.sample_rate

    @property
    def time(self) -> np.ndarray:
        """Time of each sample on the record's time base (s)."""
        return self.t0 + np.arange(self.n_samples) / self.sample_rate

    @property
    def has_hoop(self) -> bool:
        return "tube_hoop" in self.channels

    def strain(self, name: str) -> np.ndarray:
        """Strain of channel ``name``, compression positive."""
        return self.channels[name].strain


# ----------------------------------------------------------------------------------------------
# Reading
# ----------------------------------------------------------------------------------------------

_BAR_ATTRS = ("young_modulus", "wave_speed", "diameter", "length")
_APPARATUS_SCHEMA: dict[str, tuple[str, ...]] = {
    "striker": _BAR_ATTRS,
    "input_bar": _BAR_ATTRS + ("gauge_distance",),
    "internal_output_bar": _BAR_ATTRS + ("gauge_distance",),
    "external_output_bar": (
        "young_modulus", "wave_speed", "outer_diameter", "inner_diameter", "length", "gauge_distance",
    ),
    "tube": (
        "young_modulus", "poisson_ratio", "inner_diameter", "outer_diameter", "length",
        "gauge_offset", "gauge_width",
    ),
    "sample": ("material", "diameter", "length", "young_modulus", "density"),
}
_PLUG_ATTRS = ("length", "young_modulus", "density")
# attributes that may be zero or negative
_SIGNED = {"gauge_offset"}


class _Reader:
    """Helpers that raise RecordError with the file name filled in."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, problem: str) -> RecordError:
        return RecordError(self.path, where, problem)

    def attr(self, obj: Any, where: str, name: str, kind: str, *, required: bool = True) -> Any:
        if name not in obj.attrs:
            if required:
                raise self.fail(where, f"required attribute '{name}' is missing")
            return None
        value = obj.attrs[name]
        loc = f"{where}@{name}" if where != "/" else f"/@{name}"
        if isinstance(value, np.ndarray):
            if value.shape not in ((), (1,)):
                raise self.fail(loc, f"must be a scalar, got an array of shape {value.shape}")
            value = value.reshape(())[()]
        if isinstance(value, np.generic):  # messages show plain values, not np.float64(...)
            value = value.item()
        if isinstance(value, bytes):
            value = value.decode("utf-8", "replace")
        if kind == "str":
            if not isinstance(value, str):
                raise self.fail(loc, f"must be a string, got {type(value).__name__} {value!r}")
            return value
        if kind == "int":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                if isinstance(value, (float, np.floating)) and float(value).is_integer():
                    return int(value)
                raise self.fail(loc, f"must be an integer, got {value!r}")
            return int(value)
        # float
        if isinstance(value, (str, bool, np.bool_)):
            raise self.fail(loc, f"must be a number, got {value!r}")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise self.fail(loc, f"must be a number, got {value!r}") from None
        if not math.isfinite(value):
            raise self.fail(loc, f"must be finite, got {value!r}")
        return value

    def member(self, group: Any, name: str, where: str) -> Any:
        """``group[name]``, or None if absent; a dangling soft or external link is refused at ``where``."""
        if name not in group:
            return None
        try:
            return group[name]
        except (KeyError, OSError) as exc:
            raise self.fail(where, f"is a broken link ({exc})") from None

    def positive(self, obj: Any, where: str, name: str) -> float:
        value = self.attr(obj, where, name, "float")
        if value <= 0:
            raise self.fail(f"{where}@{name}", f"must be > 0, got {value!r}")
        return value


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_record(path: str | os.PathLike[str]) -> Record:
    """Read, check and convert a ``test.h5`` record.

    Parameters
    ----------
    path
        The record file.

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
    r = _Reader(p)
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
    try:
        fh = h5py.File(p, "r")
    except OSError as exc:
        raise r.fail("/", f"is a damaged or truncated HDF5 file ({exc})") from None
    try:
        with fh:
            return _read_open(fh, p, r)
    except RecordError:
        raise
    except (OSError, KeyError, RuntimeError) as exc:
        raise r.fail("/", f"is a damaged or truncated HDF5 file ({exc})") from None


def _read_open(fh: Any, p: Path, r: _Reader) -> Record:
    import h5py

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
    if not test_id.strip():
        raise r.fail("/@test_id", "is empty")
    campaign = r.attr(fh, "/", "campaign", "str")
    if not campaign.strip():
        raise r.fail("/@campaign", "is empty")
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

    # ---- apparatus ----
    app = r.member(fh, "apparatus", "/apparatus")
    if app is None:
        raise r.fail("/apparatus", "required group is missing")
    if not isinstance(app, h5py.Group):
        raise r.fail("/apparatus", "must be a group")
    apparatus = _read_apparatus(app, r)

    # ---- signals ----
    sig = r.member(fh, "signals", "/signals")
    if sig is None:
        raise r.fail("/signals", "required group is missing")
    if not isinstance(sig, h5py.Group):
        raise r.fail("/signals", "must be a group")
    sample_rate = r.attr(sig, "/signals", "sample_rate", "float")
    if sample_rate <= 0:
        raise r.fail("/signals@sample_rate", f"must be > 0 Hz, got {sample_rate!r}")
    t0 = r.attr(sig, "/signals", "t0", "float", required=False)
    t0 = 0.0 if t0 is None else t0

    channels: dict[str, Channel] = {}
    length: int | None = None
    first: str | None = None
    for name in CHANNELS:
        where = f"/signals/{name}"
        ds = r.member(sig, name, where)
        if ds is None:
            if name in REQUIRED_CHANNELS:
                raise r.fail(where, "required channel is missing")
            continue
        if not isinstance(ds, h5py.Dataset):
            raise r.fail(where, "must be a dataset")
        if ds.ndim != 1:
            raise r.fail(where, f"must be 1-D, got shape {ds.shape}")
        if ds.dtype.kind != "f" or ds.dtype.itemsize not in (4, 8):
            raise r.fail(where, f"must be float32 or float64, got {ds.dtype}")
        if length is None:
            length, first = ds.shape[0], name
            if length < MIN_SAMPLES:
                raise r.fail(where, f"has {length} samples, at least {MIN_SAMPLES} are needed")
        elif ds.shape[0] != length:
            raise r.fail(
                where, f"has {ds.shape[0]} samples but /signals/{first} has {length}; channels must have equal length"
            )
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
            scale = spv
        else:
            scale = UNITS[units]
        raw = np.asarray(ds[()], dtype=np.float64)
        _check_samples(raw, where, r)
        strain = -scale * raw  # the one sign flip of the package: compression positive from here on
        strain.setflags(write=False)
        channels[name] = Channel(name, strain, units, spv)
    assert length is not None  # REQUIRED_CHANNELS is not empty

    # a record must be long enough for the reflected wave to pass the input-bar gauge
    duration = length / sample_rate
    ib = apparatus.input_bar
    needed = 2.0 * ib.gauge_delay + apparatus.pulse_duration
    if duration < needed:
        raise r.fail(
            "/signals",
            f"lasts {duration * 1e6:.0f} us, too short to hold the reflected wave: the input-bar gauge "
            f"needs at least 2 x gauge_distance / wave_speed + 2 x striker length / striker wave speed "
            f"= {needed * 1e6:.0f} us",
        )

    provenance: dict[str, Any] = {}
    prov = r.member(fh, "provenance", "/provenance")
    if prov is not None:
        provenance = {k: _plain(v) for k, v in prov.attrs.items()}

    return Record(
        path=str(p),
        test_id=test_id,
        campaign=campaign,
        sample_rate=sample_rate,
        t0=t0,
        channels=MappingProxyType(channels),
        apparatus=apparatus,
        date=date,
        description=description,
        striker_velocity=striker_velocity,
        provenance=MappingProxyType(provenance),
        sha256=_sha256(p),
    )


def _plain(value: Any) -> Any:
    """An attribute value of the free-form groups as plain Python (any shape, any encoding)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        return _plain(value.reshape(())[()]) if value.size == 1 else [_plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _check_samples(raw: np.ndarray, where: str, r: _Reader) -> None:
    bad = ~np.isfinite(raw)
    if bad.any():
        i = int(np.argmax(bad))
        kind = "NaN" if np.isnan(raw[i]) else "inf"
        raise r.fail(where, f"has {int(bad.sum())} non-finite samples ({kind} first at index {i})")
    if raw.size and np.ptp(raw) == 0.0:
        raise r.fail(where, f"is flat (every sample equals {float(raw[0])!r}): the gauge recorded no signal")
    head = raw[: max(32, raw.size // 50)]
    if np.ptp(head) == 0.0:
        return
    median = float(np.median(raw))
    swing = float(np.max(np.abs(raw - median)))
    for extreme, label in ((raw.max(), "maximum"), (raw.min(), "minimum")):
        if abs(float(extreme) - median) < 0.5 * swing:
            continue  # the extreme of the side the pulse does not reach: baseline noise
        run = _longest_run(raw == extreme)
        if run >= CLIP_RUN:
            raise r.fail(
                where,
                f"is clipped: {run} consecutive samples sit at the {label} value {float(extreme)!r} "
                "(amplifier or digitiser saturated); re-record with a smaller gain",
            )


def _longest_run(mask: np.ndarray) -> int:
    if not mask.any():
        return 0
    padded = np.concatenate(([0], mask.astype(np.int8), [0]))
    edges = np.flatnonzero(np.diff(padded))
    return int((edges[1::2] - edges[0::2]).max())


def _read_apparatus(app: Any, r: _Reader) -> Apparatus:
    import h5py

    parts: dict[str, dict[str, Any]] = {}
    for part, names in _APPARATUS_SCHEMA.items():
        where = f"/apparatus/{part}"
        g = r.member(app, part, where)
        if g is None:
            raise r.fail(where, "required group is missing")
        if not isinstance(g, h5py.Group):
            raise r.fail(where, "must be a group")
        vals: dict[str, Any] = {}
        for name in names:
            if name == "material":
                vals[name] = r.attr(g, where, name, "str")
            elif name in _SIGNED:
                vals[name] = r.attr(g, where, name, "float")
            else:
                vals[name] = r.positive(g, where, name)
        if part in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
            nu = r.attr(g, where, "poisson_ratio", "float", required=False)
            if nu is not None and not -1.0 < nu < 0.5:
                raise r.fail(f"{where}@poisson_ratio", f"must lie in (-1, 0.5), got {nu!r}")
            vals["poisson_ratio"] = DEFAULT_BAR_POISSON_RATIO if nu is None else nu
        parts[part] = vals

    plug = None
    g = r.member(app, "plug", "/apparatus/plug")
    if g is not None:
        plug = Plug(**{n: r.positive(g, "/apparatus/plug", n) for n in _PLUG_ATTRS})

    # cross-checks
    for part in ("input_bar", "internal_output_bar", "external_output_bar"):
        v = parts[part]
        if v["gauge_distance"] >= v["length"]:
            raise r.fail(
                f"/apparatus/{part}@gauge_distance",
                f"is {v['gauge_distance']!r} m, beyond the bar's length {v['length']!r} m",
            )
    eob = parts["external_output_bar"]
    if eob["inner_diameter"] >= eob["outer_diameter"]:
        raise r.fail(
            "/apparatus/external_output_bar@inner_diameter",
            f"is {eob['inner_diameter']!r} m, not smaller than outer_diameter {eob['outer_diameter']!r} m",
        )
    tube = parts["tube"]
    if tube["inner_diameter"] >= tube["outer_diameter"]:
        raise r.fail(
            "/apparatus/tube@inner_diameter",
            f"is {tube['inner_diameter']!r} m, not smaller than outer_diameter {tube['outer_diameter']!r} m",
        )
    if not -1.0 < tube["poisson_ratio"] < 0.5:
        raise r.fail("/apparatus/tube@poisson_ratio", f"must lie in (-1, 0.5), got {tube['poisson_ratio']!r}")
    sample = parts["sample"]
    if sample["diameter"] > tube["inner_diameter"] * (1 + 1e-9):
        raise r.fail(
            "/apparatus/sample@diameter",
            f"is {sample['diameter']!r} m, larger than the tube's inner_diameter {tube['inner_diameter']!r} m",
        )
    if sample["length"] >= tube["length"]:
        raise r.fail(
            "/apparatus/sample@length",
            f"is {sample['length']!r} m, not shorter than the tube's length {tube['length']!r} m",
        )
    if parts["internal_output_bar"]["diameter"] > tube["inner_diameter"] * (1 + 1e-9):
        raise r.fail(
            "/apparatus/internal_output_bar@diameter",
            f"is {parts['internal_output_bar']['diameter']!r} m, too large to slide in the tube "
            f"(inner_diameter {tube['inner_diameter']!r} m)",
        )
    if eob["inner_diameter"] <= parts["internal_output_bar"]["diameter"]:
        raise r.fail(
            "/apparatus/external_output_bar@inner_diameter",
            f"is {eob['inner_diameter']!r} m, not larger than the internal output bar's diameter "
            f"{parts['internal_output_bar']['diameter']!r} m (the bars are coaxial)",
        )
    if abs(tube["gauge_offset"]) >= tube["length"] / 2:
        raise r.fail(
            "/apparatus/tube@gauge_offset",
            f"is {tube['gauge_offset']!r} m, outside the tube (half length {tube['length'] / 2!r} m)",
        )

    def bar(name: str) -> Bar:
        v = parts[name]
        return Bar(
            name=name,
            young_modulus=v["young_modulus"],
            wave_speed=v["wave_speed"],
            outer_diameter=v.get("outer_diameter", v.get("diameter")),
            inner_diameter=v.get("inner_diameter", 0.0),
            length=v["length"],
            gauge_distance=v.get("gauge_distance"),
            poisson_ratio=v["poisson_ratio"],
        )

    return Apparatus(
        striker=bar("striker"),
        input_bar=bar("input_bar"),
        internal_output_bar=bar("internal_output_bar"),
        external_output_bar=bar("external_output_bar"),
        tube=Tube(**tube),
        sample=Sample(**sample),
        plug=plug,
    )


# ----------------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------------


def _apparatus_attrs(app: Apparatus) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
        b: Bar = getattr(app, name)
        d: dict[str, Any] = {"young_modulus": b.young_modulus, "wave_speed": b.wave_speed, "length": b.length}
        if name == "external_output_bar":
            d["outer_diameter"] = b.outer_diameter
            d["inner_diameter"] = b.inner_diameter
        else:
            d["diameter"] = b.outer_diameter
        if b.gauge_distance is not None:
            d["gauge_distance"] = b.gauge_distance
        d["poisson_ratio"] = b.poisson_ratio
        out[name] = d
    out["tube"] = asdict(app.tube)
    out["sample"] = asdict(app.sample)
    if app.plug is not None:
        out["plug"] = asdict(app.plug)
    return out


def write_record(
    path: str | os.PathLike[str],
    *,
    test_id: str,
    campaign: str,
    sample_rate: float,
    strains: Mapping[str, np.ndarray],
    apparatus: Apparatus,
    t0: float = 0.0,
    units: Mapping[str, str] | None = None,
    strain_per_volt: Mapping[str, float] | None = None,
    dtype: Any = np.float64,
    date: str | None = None,
    description: str | None = None,
    striker_velocity: float | None = None,
    truth: Mapping[str, Any] | None = None,
    provenance: Mapping[str, Any] | None = None,
) -> Path:
    """Write a record that follows the contract, atomically.

    Parameters
    ----------
    strains
        Channel name -> strain, **compression positive** (the package's convention); the gauge
        sign (elongation positive) is restored here.
    units
        Channel name -> ``"strain"``, ``"microstrain"`` or ``"V"`` (default ``"strain"``).
    strain_per_volt
        Channel name -> conversion factor, required for channels stored in ``"V"``.
    truth
        Parameters that generated a synthetic record (written to ``/truth``).
    """
    import h5py

    from . import __version__

    units = dict(units or {})
    strain_per_volt = dict(strain_per_volt or {})
    p = Path(path)
    with atomic_path(p) as tmp:
        with h5py.File(tmp, "w") as fh:
            fh.attrs["format"] = FORMAT
            fh.attrs["format_version"] = FORMAT_VERSION
            fh.attrs["test_id"] = test_id
            fh.attrs["campaign"] = campaign
            for k, v in (("date", date), ("description", description), ("striker_velocity", striker_velocity)):
                if v is not None:
                    fh.attrs[k] = v
            sig = fh.create_group("signals")
            sig.attrs["sample_rate"] = float(sample_rate)
            sig.attrs["t0"] = float(t0)
            for name, eps in strains.items():
                if name not in CHANNELS:
                    raise ValueError(f"unknown channel {name!r}, allowed: {CHANNELS}")
                u = units.get(name, "strain")
                if u == "V":
                    scale = strain_per_volt[name]
                elif u in UNITS:
                    scale = UNITS[u]
                else:
                    raise ValueError(f"unknown units {u!r} for {name!r}, allowed: {tuple(UNITS)}")
                raw = -np.asarray(eps, dtype=np.float64) / scale
                ds = sig.create_dataset(name, data=raw.astype(dtype))
                ds.attrs["units"] = u
                if u == "V":
                    ds.attrs["strain_per_volt"] = float(scale)
            app = fh.create_group("apparatus")
            for part, attrs in _apparatus_attrs(apparatus).items():
                g = app.create_group(part)
                for k, v in attrs.items():
                    g.attrs[k] = v
            prov = fh.create_group("provenance")
            prov.attrs["generator"] = "friction-uq"
            prov.attrs["generator_version"] = __version__
            for k, v in (provenance or {}).items():
                prov.attrs[k] = v
            if truth is not None:
                tg = fh.create_group("truth")
                for k, v in truth.items():
                    tg.attrs[k] = v
    return p


def read_truth(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The ``/truth`` attributes of a synthetic record (validation only; the analysis never reads them)."""
    import h5py

    with h5py.File(path, "r") as fh:
        if "truth" not in fh:
            return {}
        return {k: _plain(v) for k, v in fh["truth"].attrs.items()}
