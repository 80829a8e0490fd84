"""JSON text every parser reads: a non-finite number is written ``null``.

Python's ``json`` writes NaN and infinity as ``NaN`` and ``Infinity``, which RFC 8259 does not allow and strict
parsers (JavaScript's ``JSON.parse``, most other languages') refuse. The package's JSON outputs (a run's, a
campaign's and its records') go through :func:`json_text`, which writes them as ``null`` and refuses any other
non-finite value it meets (``allow_nan=False``); docs/outputs.md says which keys can be null so.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np


def finite_or_null(obj: Any) -> Any:
    """``obj`` with every non-finite float (Python's or numpy's) in its dicts, lists and tuples replaced by None,
    numpy scalars made Python numbers and numpy arrays lists."""
    if isinstance(obj, dict):
        return {k: finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_null(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite_or_null(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


def read_json_file(path: Path, what: str = "result file") -> Any:
    """The JSON document of an input file (a run's result), read as every text input is
    (:func:`~friction_uq.plausible.text_of`: a regular file, its size, UTF-8); else one FrictionUQError naming the
    file: not a ``what``, or not JSON (an integer of more than 4300 digits and a nesting too deep included)."""
    from .errors import FrictionUQError
    from .plausible import MAX_TEXT_BYTES, NotText, text_of

    try:
        text = text_of(path, what, MAX_TEXT_BYTES)
    except NotText as why:
        raise FrictionUQError(f"{path}: {why}") from None
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise FrictionUQError(f"{path}: not a friction-uq {what} (not JSON: {exc})") from None


def json_text(doc: Any, *, indent: int | None = 2) -> str:
    """``doc`` as strict JSON (non-finite numbers null), ending in a newline."""
    return json.dumps(finite_or_null(doc), indent=indent, allow_nan=False, default=float) + "\n"
