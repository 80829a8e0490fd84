"""What a run does beside its sampling: the other core's work (the whole-record check and the report's
pages that need no posterior draw, in a forked process: :class:`friction_uq._parallel.Background`).

Nothing runs on a thread beside the sampling: the sampler's steps are small numpy operations that hold
the interpreter's lock most of the time, so imports made on a thread meanwhile (dask's, about 1.5 s of
the lock) slowed the sampling by as much as they saved later (measured: sampling 2.6 s with such a
thread, 1.55 s without; the run 0.4 s shorter without)."""

from __future__ import annotations

import numpy as np

from ..analysis import Identification, Prepared
from ..discrepancy.check import WholeRecordCheck


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
    needs no posterior draw) and its pages of the report (``pages``)."""
    wrc = None
    if check:
        from ..discrepancy import run_stage

        wrc = run_stage.whole_record_check(prep, priors, start, hoop=hoop, seed=seed)
    part = None
    if pages and wrc is not None:
        from ..report.pdf import render_record_part

        part = render_record_part(prep, wrc, hoop=hoop)
    return wrc, part
