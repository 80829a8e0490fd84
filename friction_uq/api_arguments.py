"""The Python interface's arguments checked before any work, each refusal one sentence naming the argument
(:class:`~friction_uq.errors.FrictionUQError`), as the command line's are: a path is text or an
``os.PathLike``, a switch is a bool (the string "no" is true), a window two finite numbers, a number of workers a
whole number of at least 1."""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .errors import FrictionUQError


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def path_argument(name: str, value: Any, *, optional: bool = False) -> Path | None:
    """``value`` as a Path (None where ``optional`` and None); text or os.PathLike, not empty."""
    if value is None and optional:
        return None
    if isinstance(value, bytes) or not isinstance(value, (str, os.PathLike)):
        raise FrictionUQError(f"{name}: must be a path (text or os.PathLike), got {type(value).__name__} "
                              f"{_shown(value)}")
    path = os.fspath(value)
    if isinstance(path, bytes) or not path.strip():
        raise FrictionUQError(f"{name}: must be a path, got {_shown(value)}" + ("; write '.' for the current folder"
                                                                            if path == "" else ""))
    return Path(path)


def paths_argument(name: str, value: Any) -> list[Path]:
    """One path, or a list or tuple of paths, as a list (a single path is not read character by character)."""
    if isinstance(value, (str, os.PathLike)):
        return [path_argument(name, value)]
    if isinstance(value, (bytes, bytearray)) or not isinstance(value, Sequence):
        raise FrictionUQError(f"{name}: must be a path or a list of paths, got {type(value).__name__} "
                              f"{_shown(value)}")
    return [path_argument(f"{name}[{k}]", v) for k, v in enumerate(value)]


def flag_argument(name: str, value: Any) -> bool:
    """A switch: True or False (numpy's bools too); anything else is refused, not read as true or false."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise FrictionUQError(f"{name}: must be True or False, got {type(value).__name__} {_shown(value)}")


def window_argument(value: Any) -> tuple[float, float] | None:
    """None (found) or (t0, t1): two finite numbers of seconds."""
    if value is None:
        return None
    ok = (isinstance(value, Sequence) and not isinstance(value, (str, bytes)) and len(value) == 2
          and all(isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v) for v in value))
    if not ok:
        raise FrictionUQError(f"window: must be (t0, t1), two finite numbers of seconds on the record's time base, "
                              f"got {_shown(value)}")
    return float(value[0]), float(value[1])


def workers_argument(value: Any) -> int:
    """A number of local worker processes: a whole number, at least 1."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise FrictionUQError(f"workers: must be a whole number of at least 1, got {type(value).__name__} "
                              f"{_shown(value)}")
    return int(value)


def scheduler_argument(value: Any) -> str | None:
    """None (a local cluster) or a Dask scheduler's address as text."""
    if value is None or (isinstance(value, str) and value.strip()):
        return value
    raise FrictionUQError(f"scheduler: must be a Dask scheduler's address (text) or None, got {_shown(value)}")
