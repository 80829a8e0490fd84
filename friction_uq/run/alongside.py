"""What a run does beside its sampling: the other core's work (the whole-record check and the report's
pages that need no posterior draw, in a forked process: :class:`friction_uq._parallel.Background`) and
a thread that loads what the stages after the sampling would otherwise wait for."""

from __future__ import annotations

import importlib
import threading

import numpy as np

from ..analysis import Identification, Prepared
from ..discrepancy.check import WholeRecordCheck
from ..likelihood import ar1_pointwise


def whole_record_start(lab: Identification, priors) -> dict[str, float]:
    """Where the whole-record fit starts its mode search (it also starts from nu either side of the prior):
    the lab's eq. 17 estimate at the nominal nu, kept within the f prior's 1-99 % range (its median where
    eq. 17 gives no f)."""
    lo, hi = (float(priors["f"].ppf(q)) for q in (0.01, 0.99))
    f = float(np.clip(lab.f, lo, hi)) if np.isfinite(lab.f) else float(priors["f"].ppf(0.5))
    return {"f": f, "nu": float(lab.nu)}


def alongside(prep: Prepared, priors, start: dict[str, float], *, hoop: bool, seed: int, check: bool,
              pages: bool) -> tuple[WholeRecordCheck | None, bytes | None]:
    """What a run computes on its other core while it samples: the whole-record check (``check``; it
    needs no posterior draw) and the report's pages that need none either (``pages``: the record's and
    the check's)."""
    wrc = None
    if check:
        from ..discrepancy import pipeline

        wrc = pipeline.whole_record_check(prep, priors, start, hoop=hoop, seed=seed)
    part = None
    if pages:
        from ..report.pdf import render_record_part

        part = render_record_part(prep, wrc, hoop=hoop)
    return wrc, part


#: What later stages import on first use: xarray imports dask.array at its first array and dask.distributed
#: when it writes a netCDF file (where dask is installed, as it is for campaigns); pypdf merges the report.
LATER_IMPORTS = ("dask.array", "dask.distributed", "pypdf")


def prepare_soon() -> threading.Thread:
    """On a thread, while this one samples, what the stages after the sampling would otherwise wait for:
    the :data:`LATER_IMPORTS` (three quarters of a second) and the compiled AR(1) densities of the
    pointwise log-likelihood, loaded from numba's cache (a quarter of a second, the first time in a
    process)."""
    def load() -> None:
        for module in LATER_IMPORTS:
            try:
                importlib.import_module(module)
            except ImportError:
                pass
        ar1_pointwise(np.zeros((1, 3)), 1.0, 0.5, 1.0)

    thread = threading.Thread(target=load, name="prepare", daemon=True)
    thread.start()
    return thread
