"""Optional compilation with numba.

The time loop of the cell (:mod:`.simulate.cell`), the hoop gauge (:mod:`.simulate.hoop`) and the AR(1)
conditional densities with an offset (:mod:`.stats.ar1`) are written as plain
Python loops over scalars and compiled with ``numba.njit`` when numba is installed (about 1 ms
per record instead of seconds). Without numba the same functions run as ordinary Python: results
are identical, only slower. Compiled code is cached on disk (``cache=True``) next to the modules.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

try:  # pragma: no cover - depends on the environment
    import numba

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False


def njit(func: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit(cache=True)`` when numba is available, else the function unchanged."""
    if HAVE_NUMBA:
        return numba.njit(cache=True)(func)
    return func  # pragma: no cover
