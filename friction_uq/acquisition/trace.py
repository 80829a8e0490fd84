"""What the binary readers share: one channel as a file holds it, the file-size check, the optional readers.

:mod:`.tdms` reads NI TDMS files, :mod:`.binary` LeCroy, Tektronix and Rigol waveforms and
dispatches on the extension; both hand back :class:`Trace` objects.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ScopeFileError

#: Largest binary file read (bytes).
MAX_BINARY_BYTES = 4_000_000_000


@dataclass(frozen=True)
class Trace:
    """One channel as a file holds it: its values, a label for messages, and its time base if it has one.

    ``time_names`` says where the file keeps the sample interval and the start (for messages), when
    the format has names for them.
    """

    values: np.ndarray
    label: str
    t0: float | None = None
    dt: float | None = None
    time_names: tuple[str, str] | None = None


def need(module: str, path: Path) -> object:
    """``module`` imported, or one sentence saying which package reading ``path`` needs."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ScopeFileError(f"{path}: reading this format needs the package {module!r}: "
                             "pip install 'friction-uq[scopes]'") from None


def check_size(path: Path) -> None:
    """Refuse a file larger than :data:`MAX_BINARY_BYTES` from its size, before it is opened."""
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise ScopeFileError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if size > MAX_BINARY_BYTES:
        raise ScopeFileError(f"{path}: is {size / 1e9:.1f} GB, more than the {MAX_BINARY_BYTES / 1e9:.0f} GB a binary "
                             "scope file is read up to; export fewer channels or samples")
