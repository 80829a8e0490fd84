"""Low-level checks of the reader: typed attributes, sample sanity, clipping (format version 1).

Every failure is a :class:`~friction_uq.errors.RecordError` naming the file, the path inside it
and the problem.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import RecordError
from ..plausible import MAX_ATTRIBUTE_BYTES, MAX_CHUNKS, MAX_SAMPLES, text_bytes
from .saturation import RUN_ALPHA, flat_run


class Reader:
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
        loc = f"{where}@{name}" if where != "/" else f"/@{name}"
        try:
            stored = obj.attrs.get_id(name).get_storage_size()
        except (KeyError, OSError, RuntimeError) as exc:
            raise self.fail(loc, f"cannot be read ({exc})") from None
        if stored > MAX_ATTRIBUTE_BYTES:
            raise self.fail(loc, f"takes {stored} bytes, more than the {MAX_ATTRIBUTE_BYTES} an attribute may")
        value = obj.attrs[name]
        if isinstance(value, np.ndarray):
            if value.shape not in ((), (1,)):
                raise self.fail(loc, f"must be a scalar, got an array of shape {value.shape}")
            value = value.reshape(())[()]
        if isinstance(value, np.generic):  # messages show plain values, not np.float64(...)
            value = value.item()
        if isinstance(value, bytes):
            value = value.decode("utf-8", "replace")
        if isinstance(value, str) and text_bytes(value) > MAX_ATTRIBUTE_BYTES:
            # a variable-length string is stored apart from its attribute, whose storage size does not count it
            raise self.fail(loc, f"holds {text_bytes(value)} bytes of text, more than the {MAX_ATTRIBUTE_BYTES} an "
                            "attribute may")
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
        import h5py

        if name not in group:
            try:  # a dangling link is not "in" its group
                link = group.get(name, getlink=True)
            except (KeyError, OSError):
                link = None
            if link is None:
                return None
        else:
            link = group.get(name, getlink=True)
        if isinstance(link, h5py.ExternalLink):
            raise self.fail(where, f"is an external link (to {link.filename}:{link.path}); a record must hold its "
                            "data itself, so that its checksum covers every byte it is analysed from (copy the "
                            "linked object in, e.g. with h5copy)")
        try:
            obj = group[name]
        except (KeyError, OSError) as exc:
            raise self.fail(where, f"is a broken link ({exc})") from None
        if isinstance(obj, h5py.Dataset) and (obj.is_virtual or obj.external):
            raise self.fail(where, "keeps its data in other files (a virtual or external dataset); a record must "
                            "hold its data itself, so that its checksum covers every byte it is analysed from")
        return obj

    def positive(self, obj: Any, where: str, name: str) -> float:
        value = self.attr(obj, where, name, "float")
        if value <= 0:
            raise self.fail(f"{where}@{name}", f"must be > 0, got {value!r}")
        return value


def sha256_of(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def plain(value: Any) -> Any:
    """An attribute value of the free-form groups as plain Python (any shape, any encoding)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        return plain(value.reshape(())[()]) if value.size == 1 else [plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return value.item()
    return value


def check_samples(raw: np.ndarray, where: str, r: Reader) -> None:
    bad = ~np.isfinite(raw)
    if bad.any():
        i = int(np.argmax(bad))
        kind = "NaN" if np.isnan(raw[i]) else "inf"
        raise r.fail(where, f"has {int(bad.sum())} non-finite samples ({kind} first at index {i})")
    if raw.size and np.ptp(raw) == 0.0:
        raise r.fail(where, f"is flat (every sample equals {float(raw[0])!r}): the gauge recorded no signal")
    run = flat_run(raw)
    if run is not None and run.saturated:
        raise r.fail(
            where,
            f"is clipped: {run.run} consecutive samples sit at the {run.side} value {run.value!r} "
            "(amplifier or digitiser saturated), a run its pre-trigger noise leaves with a chance below "
            f"{RUN_ALPHA:g}; re-record with a smaller gain",
        )


def check_strain(strain: np.ndarray, where: str, r: Reader) -> None:
    """Refuse a channel whose strain is larger than an elastic bar or tube can carry (a gain or unit slip)."""
    from ..plausible import out_of_range

    peak = float(np.max(np.abs(strain)))
    problem = out_of_range("signals.strain", peak)
    if problem:
        raise r.fail(where, f"reaches a strain of {peak:.3g}: {problem.removeprefix('is ')}; check its units and "
                     "strain_per_volt")


def check_distinct(strain: np.ndarray, earlier: dict[str, Any], where: str, r: Reader) -> None:
    """Refuse a channel that is another channel's data again (equal, or equal up to a factor): two gauges on
    different bars never record proportional noise."""
    for name, ch in earlier.items():
        other = ch.strain
        if np.array_equal(strain, other):
            raise r.fail(where, f"holds the same samples as /signals/{name}: a channel copied twice?")
        a, b = strain - strain.mean(), other - other.mean()
        den = float(np.sqrt(np.dot(a, a) * np.dot(b, b)))
        if den > 0 and abs(float(np.dot(a, b))) / den > 1.0 - 1e-12:
            raise r.fail(where, f"is /signals/{name} multiplied by a constant: a channel copied twice?")


def check_dataset(ds: Any, where: str, r: Reader) -> None:
    """A channel's dataset: 1-D floats, no more samples than a channel may have (checked before it is read)."""
    import h5py

    if not isinstance(ds, h5py.Dataset):
        raise r.fail(where, "must be a dataset")
    if ds.ndim != 1:
        raise r.fail(where, f"must be 1-D, got shape {ds.shape}")
    if ds.dtype.kind != "f" or ds.dtype.itemsize not in (4, 8):
        raise r.fail(where, f"must be float32 or float64, got {ds.dtype}")
    if ds.shape[0] > MAX_SAMPLES:
        raise r.fail(where, f"declares {ds.shape[0]} samples, more than the {MAX_SAMPLES} a channel may have "
                     "(docs/limits.md)")
    _check_storage(ds, where, r)


def _check_storage(ds: Any, where: str, r: Reader) -> None:
    """A channel's storage, before it is read: no more chunks than :data:`MAX_CHUNKS` (a chunk a sample holds
    a 4-channel record of a million samples in 4 GB of HDF5's index), and every filter it was written through
    available here (else HDF5 reports the whole file as damaged)."""
    import h5py

    if ds.chunks is not None:
        n_chunks = -(-ds.shape[0] // ds.chunks[0]) if ds.shape[0] else 0
        if n_chunks > MAX_CHUNKS:
            raise r.fail(where, f"is stored in {n_chunks} chunks of {ds.chunks[0]} samples, more than the "
                         f"{MAX_CHUNKS} a channel may have (docs/limits.md): write it contiguous or in larger chunks "
                         "(h5repack -l CONTI)")
    plist = ds.id.get_create_plist()
    for i in range(plist.get_nfilters()):
        code, _, _, name = plist.get_filter(i)
        if not h5py.h5z.filter_avail(code):
            label = name.decode(errors="replace") if isinstance(name, bytes) else str(name)
            raise r.fail(where, f"is compressed with HDF5 filter {code} ({label or 'unnamed'}), which this "
                         "installation cannot read: write it uncompressed or with gzip")
