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
from .contract import CLIP_RUN


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
    head = raw[: max(32, raw.size // 50)]
    if np.ptp(head) == 0.0:
        return
    median = float(np.median(raw))
    swing = float(np.max(np.abs(raw - median)))
    for extreme, label in ((raw.max(), "maximum"), (raw.min(), "minimum")):
        if abs(float(extreme) - median) < 0.5 * swing:
            continue  # the extreme of the side the pulse does not reach: baseline noise
        run = longest_run(raw == extreme)
        if run >= CLIP_RUN:
            raise r.fail(
                where,
                f"is clipped: {run} consecutive samples sit at the {label} value {float(extreme)!r} "
                "(amplifier or digitiser saturated); re-record with a smaller gain",
            )


def longest_run(mask: np.ndarray) -> int:
    if not mask.any():
        return 0
    padded = np.concatenate(([0], mask.astype(np.int8), [0]))
    edges = np.flatnonzero(np.diff(padded))
    return int((edges[1::2] - edges[0::2]).max())
