"""Campaigns: many records analysed in parallel on Dask, pooled, and the friction law across set-ups.

Modules, one concern each:

* :mod:`.job` - the per-record job and its versioned result (read back with ``read_result``);
* :mod:`.runner` - records and seeds, the Dask cluster or scheduler, the progress bar;
* :mod:`.pooling` - hierarchical pooling of f and kappa from the stored draws;
* :mod:`.laws` - friction laws fitted jointly, leave-one-test-out ELPD;
* :mod:`.kernels` - a test's stored draws as its likelihood (a weighted kernel mixture);
* :mod:`.flags` - set-ups and tests off the shared law, per-record causes tallied;
* :mod:`.analysis` - from the results to the campaign's conclusions;
* :mod:`.outputs` - ``campaign.json``, ``campaign.nc``, the text summary;
* :mod:`.compare` - the older ``compare`` of JSON medians (weighted trend lines).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._atomic import check_unlocked, output_folder, output_lock
from ..errors import FrictionUQError, check_seed
from ..prior_loader import load_priors
from .analysis import CampaignAnalysis, analyse
from .compare import Comparison, TestResult, TrendFit, compare, comparison_table, fit_trend, load_result
from .job import RecordResult, RecordTask, read_result, run_record
from .outputs import campaign_doc, summary_text, write_json, write_netcdf
from .runner import check_headers, find_records, local_workers, make_tasks, read_header, record_seed, run_tasks

RECORDS_SUBDIR = "records"
#: The campaign's lock in its output folder (``.campaign.lock``): one campaign writes into a folder at a time.
CAMPAIGN_LOCK = "campaign"


@dataclass(frozen=True)
class CampaignOutcome:
    results: list[RecordResult]
    analysis: CampaignAnalysis | None
    doc: dict[str, Any]
    outputs: dict[str, Path]


def run_campaign(
    inputs: Sequence[str | os.PathLike[str]],
    out_dir: str | os.PathLike[str],
    *,
    workers: int = 2,
    scheduler: str | None = None,
    seed: int = 20161,
    priors_path: str | os.PathLike[str] | None = None,
    dispersion: bool = False,
    hoop: bool = True,
    pdf: bool = True,
    diagnose: bool = False,
    progress: bool = True,
) -> CampaignOutcome:
    """Analyse every record (skipping those up to date), then pool, fit the laws, flag, write the outputs.

    Per-record outputs go to ``out_dir/records/`` (their PDF reports only with ``pdf``);
    ``campaign.json``, ``campaign.nc`` and ``campaign.pdf`` to ``out_dir``.
    """
    seed = check_seed(seed)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise FrictionUQError(f"{out}: --out must be a directory, and this is a file")
    if not scheduler:
        workers = local_workers(workers)
    busy = (f"{out}: another friction-uq campaign is writing into this folder (lock .{CAMPAIGN_LOCK}.lock); "
            "wait for it to end or choose another --out")
    check_unlocked(out, CAMPAIGN_LOCK, busy=busy)  # said at once; the lock itself is taken below
    if priors_path is not None:  # one prior file for every record: refused at once, not once per record
        load_priors(priors_path)
    headers = [read_header(p) for p in find_records(inputs)]
    check_headers(headers)
    # a refused campaign leaves no empty folder behind (output_folder removes those it made, while empty)
    with output_folder(out), output_lock(out, CAMPAIGN_LOCK, busy=busy):
        return _run_locked(headers, out, workers=workers, scheduler=scheduler, seed=seed,
                           priors_path=priors_path, dispersion=dispersion, hoop=hoop, pdf=pdf, diagnose=diagnose,
                           progress=progress)


def _run_locked(headers, out: Path, *, workers: int, scheduler: str | None, seed: int, priors_path, dispersion: bool,
                hoop: bool, pdf: bool, diagnose: bool, progress: bool) -> CampaignOutcome:
    """:func:`run_campaign` once its inputs are checked and it holds the folder's campaign lock."""
    records_dir = out / RECORDS_SUBDIR
    with output_folder(records_dir):  # removed again while empty if the tasks are refused (no scheduler answers)
        tasks = make_tasks(headers, out_dir=records_dir, seed=seed,
                           priors_path=str(priors_path) if priors_path else None, dispersion=dispersion, hoop=hoop,
                           pdf=pdf, diagnose=diagnose)
        t0 = time.perf_counter()
        results = run_tasks(tasks, workers=workers, scheduler=scheduler, progress=progress)
    t1 = time.perf_counter()
    say = (lambda line: print(f"campaign: {line}", file=sys.stderr, flush=True)) if progress else None
    ca = analyse(results, records_dir, seed=seed, say=say) if any(r.ok for r in results) else None
    settings = {"dispersion": dispersion, "hoop": hoop, "pdf": pdf, "diagnose": diagnose,
                "priors": str(priors_path) if priors_path else None}
    doc = campaign_doc(results, ca, seed=seed, settings=settings)
    # wall time of the records' tasks (their own time is each record's ``seconds``) and of the campaign's analysis
    doc["wall_seconds"] = {"records": t1 - t0, "analysis": time.perf_counter() - t1}
    outputs = {"json": write_json(doc, out / "campaign.json")}
    if ca is not None:
        if say is not None:
            say("writing campaign.nc and campaign.pdf")
        outputs["netcdf"] = write_netcdf(ca, out / "campaign.nc")
        from ..report.campaign_pages import write_campaign_report

        outputs["pdf"] = write_campaign_report(ca, doc, out / "campaign.pdf")
    return CampaignOutcome(results, ca, doc, outputs)


__all__ = [
    "CampaignAnalysis", "CampaignOutcome", "Comparison", "RecordResult", "RecordTask", "TestResult", "TrendFit",
    "analyse", "check_headers", "compare", "comparison_table", "find_records", "fit_trend", "load_result",
    "make_tasks", "read_header", "read_result", "record_seed", "run_campaign", "run_record", "run_tasks",
    "summary_text",
]

