"""JSON text every parser reads: a non-finite number is written ``null``.

Python's ``json`` writes NaN and infinity as ``NaN`` and ``Infinity``, which RFC 8259 does not allow and strict
parsers (JavaScript's ``JSON.parse``, most other languages') refuse. The package's JSON outputs (a run's, a
campaign's and its records') go through :func:`json_text`, which writes them as ``null`` and refuses any other
non-finite value it meets (``allow_nan=False``); docs/outputs.md says which keys can be null so.
"""

from __future__ import annotations

import json
import math
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


def json_text(doc: Any, *, indent: int | None = 2) -> str:
    """``doc`` as strict JSON (non-finite numbers null), ending in a newline."""
    return json.dumps(finite_or_null(doc), indent=indent, allow_nan=False, default=float) + "\n"
