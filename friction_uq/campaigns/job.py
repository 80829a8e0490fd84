"""The per-record job of a campaign and its result, with a versioned JSON schema.

:func:`run_record` is what a Dask worker runs for one record: it calls
:func:`friction_uq.record_run.run_file` (no progress, no table), reads back the JSON it wrote and returns
a :class:`RecordResult`. It prints nothing: whatever the analysis would say on the terminal
(notes such as a hoop gauge left out) is captured into ``notes``. A record the analysis refuses
gives a result with ``status = "failed"`` and the one-sentence refusal as ``message``; the job
never raises for a bad record, so the campaign goes on.

The result is written beside the run outputs as ``<stem>.result.json`` and read back with
:func:`read_result` (the one function that knows the schema). A record whose stored result is
up to date (same record sha256, same settings, same prior file checksum, same package version,
outputs present and holding the bytes the run JSON names) is not analysed again: the job returns
the stored result with ``status = "skipped"``; one that cannot be read is analysed again.

Schema version 4 (``schema = "friction-uq/campaign-record"``): ``path``, ``status``
(``done`` | ``skipped`` | ``failed``), ``message``, ``campaign`` (the set-up), ``test_id``,
``material``, ``record_sha256``, ``prior_file``, ``prior_sha256``, ``friction_uq_version``,
``settings`` (seed, dispersion, hoop, pdf), ``outputs`` (file names in the same folder),
``summary`` (f, kappa, nu, V, p_mean: mean, sd, q05, q50, q95), ``converged``, ``notes``,
``seconds`` (wall), ``cpu_seconds`` (the worker process's user + system time for this record),
``peak_rss_mb`` (the worker process's peak resident memory so far) and ``causes``: the causes a per-record diagnosis names (a list of strings, or null
when no diagnosis was made); the campaign tallies them per set-up; ``window_halves``: kappa's change across the
stationary window as the run JSON gives it (:mod:`friction_uq.window_halves`; null where it could not be read),
which the campaign's slip law reads; ``warnings``: the run's warnings, as its JSON gives them (the campaign lists
the tests that have any and pools f without them beside the pooled f); ``warning_kinds``: each warning's kind, as
the run JSON gives them (schema 4). Versions 1 to 3 had no ``window_halves``, no ``warnings`` or no
``warning_kinds``: such a stored result is not read back, so its record is analysed again.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import io
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import __version__
from .._atomic import atomic_path
from .._json_text import json_text
from ..errors import FrictionUQError, LockedError
from ..window_halves import WindowHalves

SCHEMA = "friction-uq/campaign-record"
SCHEMA_VERSION = 4
SUMMARY_VARIABLES = ("f", "kappa", "nu", "V", "p_mean")
STATUSES = ("done", "skipped", "failed")
#: Seconds a record waits for its lock in the campaign's folder: only a killed campaign's worker can hold it
#: (the campaign holds the folder's lock), and Dask stops such a worker within a few seconds.
LOCK_WAIT_S = 30


@dataclass(frozen=True)
class RecordTask:
    """One record to analyse: the file, its seed and the campaign's settings."""

    path: str
    seed: int
    out_dir: str
    priors_path: str | None = None
    dispersion: bool = False
    hoop: bool = True
    pdf: bool = True
    diagnose: bool = False

    @property
    def settings(self) -> dict[str, Any]:
        out = {"seed": int(self.seed), "dispersion": bool(self.dispersion), "hoop": bool(self.hoop),
               "pdf": bool(self.pdf)}
        if self.diagnose:  # only when set: results written without it stay up to date
            out["diagnose"] = True
        return out


@dataclass(frozen=True)
class RecordResult:
    """What the job returns for one record (see the module docstring for the schema)."""

    path: str
    status: str
    message: str | None = None
    campaign: str | None = None
    test_id: str | None = None
    material: str | None = None
    record_sha256: str | None = None
    prior_file: str | None = None
    prior_sha256: str | None = None
    friction_uq_version: str = __version__
    settings: dict[str, Any] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)
    summary: dict[str, dict[str, float]] = field(default_factory=dict)
    converged: bool | None = None
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    cpu_seconds: float = 0.0
    peak_rss_mb: float = 0.0
    causes: list[str] | None = None
    window_halves: dict[str, Any] | None = None
    warnings: list[str] = field(default_factory=list)
    warning_kinds: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status in ("done", "skipped")

    @property
    def label(self) -> str:
        return f"{self.campaign} {self.test_id}" if self.test_id else Path(self.path).name

    def to_json(self) -> dict[str, Any]:
        return {"schema": SCHEMA, "schema_version": SCHEMA_VERSION} | dataclasses.asdict(self)


def file_sha256(path: str | os.PathLike[str]) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_result(path: str | os.PathLike[str]) -> RecordResult:
    """Read a ``<stem>.result.json`` back; refuse a file of another schema or version with one sentence."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except (OSError, ValueError, RecursionError) as exc:  # unreadable, not JSON, nested too deep, a huge integer
        raise FrictionUQError(f"{p}: not a campaign record result ({exc})") from None
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise FrictionUQError(f"{p}: not a campaign record result (key 'schema' is not {SCHEMA!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise FrictionUQError(f"{p}: key 'schema_version' is {doc.get('schema_version')!r}, this friction-uq reads "
                              f"version {SCHEMA_VERSION}")
    names = {f.name for f in dataclasses.fields(RecordResult)}
    unknown = sorted(set(doc) - names - {"schema", "schema_version"})
    if unknown:
        raise FrictionUQError(f"{p}: unknown key(s) {', '.join(unknown)} in a schema version {SCHEMA_VERSION} result")
    if doc.get("status") not in STATUSES:
        raise FrictionUQError(f"{p}: key 'status' is {doc.get('status')!r}, allowed values: {', '.join(STATUSES)}")
    if "path" not in doc:
        raise FrictionUQError(f"{p}: key 'path' missing")
    if doc.get("window_halves") is not None:
        try:
            WindowHalves.from_json(doc["window_halves"])
        except ValueError as exc:
            raise FrictionUQError(f"{p}: key 'window_halves': {exc}") from None
    return RecordResult(**{k: v for k, v in doc.items() if k in names})


def result_path(out_dir: str | os.PathLike[str], stem: str) -> Path:
    return Path(out_dir) / f"{stem}.result.json"


def write_result(result: RecordResult, path: str | os.PathLike[str]) -> Path:
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json_text(result.to_json()))
    return Path(path)


def _up_to_date(old: RecordResult, new: RecordResult, out_dir: Path, stem: str) -> dict[str, Any] | None:
    """The stored run's JSON document when the stored result is of this record (its bytes, campaign and test id),
    its analysis settings, prior and friction-uq version, and its outputs are this record's and intact
    (:func:`_outputs_intact`); else None (the record is analysed again)."""
    # a run with the PDF report also serves a campaign without one (not the other way round)
    analysis = {k: v for k, v in old.settings.items() if k != "pdf"} == {k: v for k, v in new.settings.items()
                                                                        if k != "pdf"}
    pdf_ok = old.settings.get("pdf", False) or not new.settings.get("pdf", False)
    same = (old.ok and old.record_sha256 == new.record_sha256 and analysis and pdf_ok
            and old.prior_sha256 == new.prior_sha256 and old.friction_uq_version == new.friction_uq_version
            and (old.campaign, old.test_id) == (new.campaign, new.test_id))
    named = {"json": f"{stem}.json", "netcdf": f"{stem}.nc", "pdf": f"{stem}.pdf"}
    if not same or any(name != named.get(kind) for kind, name in old.outputs.items()):
        return None  # another record's outputs named in an edited result, or a stale one
    doc = _outputs_intact(old, out_dir)
    if doc is None or (doc.get("record_sha256"), doc.get("campaign"), doc.get("test_id")) != (
            new.record_sha256, new.campaign, new.test_id):
        return None
    return doc


def _outputs_intact(old: RecordResult, out_dir: Path) -> dict[str, Any] | None:
    """The stored run's JSON document when the stored outputs are there, are the bytes their run wrote (the run
    JSON names the sha256 of the ``.nc`` and the ``.pdf``) and the run JSON is of this package's schema version.
    Anything missing, unreadable, changed or older: None."""
    try:
        if not all((out_dir / name).is_file() for name in old.outputs.values()):
            return None
        doc = json.loads((out_dir / old.outputs["json"]).read_text())
        from ..record_run.outputs import RUN_SCHEMA_VERSION

        if doc.get("schema_version") != RUN_SCHEMA_VERSION:  # written by an older run: its keys meant other things
            return None
        for kind in ("netcdf", "pdf"):
            if kind not in old.outputs:
                continue
            named = doc["outputs"][kind]
            if named is None or named["file"] != old.outputs[kind] or \
                    file_sha256(out_dir / named["file"]) != named["sha256"]:
                return None
        return doc if "netcdf" in old.outputs else None
    except (OSError, KeyError, TypeError, ValueError):
        return None


def _from_run_json(doc: dict[str, Any]) -> dict[str, Any]:
    """What a record result takes from its run's JSON: the summaries, convergence, causes, window halves and
    warnings (a stored result is read back from the run it names, not from its own copy, which an edit could
    change)."""
    return {"summary": _summary(doc), "converged": bool(doc.get("converged")),
            "causes": [c["name"] for c in doc["discrepancy"]["causes"]] if "discrepancy" in doc else None,
            "window_halves": doc.get("window_halves"), "warnings": [str(w) for w in doc["warnings"]],
            "warning_kinds": [str(k) for k in doc["warning_kinds"]]}


def _summary(doc: dict[str, Any]) -> dict[str, dict[str, float]]:
    """The stationary analysis' summaries (its f is ``f_stationary`` in a run JSON of schema version 2 or later)."""
    key = {"f": "f_stationary"} if "f_stationary" in doc else {}
    return {k: {s: float(doc[key.get(k, k)][s]) for s in ("mean", "sd", "q05", "q50", "q95")}
            for k in SUMMARY_VARIABLES}


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def run_record(task: RecordTask) -> RecordResult:
    """Analyse one record (or find it up to date); never prints, never raises for a bad record."""
    from ..prior_loader import record_prior_path
    from ..record import read_record
    from ..record_run import run_file, safe_stem

    import logging

    # a Dask worker's state machine warns of each task cut short when an interrupted campaign stops it (also
    # set by the runner on the workers it starts with; here for a worker started later)
    logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)
    t0, c0 = time.perf_counter(), time.process_time()
    out = Path(task.out_dir)
    base = RecordResult(path=str(task.path), status="failed", settings=task.settings)
    try:
        record = read_record(task.path, hoop=task.hoop)
        material = record.apparatus.sample.material
        prior = Path(task.priors_path) if task.priors_path else record_prior_path(record.path, material)
        stem = safe_stem(record.campaign, record.test_id)
        base = dataclasses.replace(
            base, campaign=record.campaign, test_id=record.test_id, material=material,
            record_sha256=record.sha256, prior_file=str(prior),
            prior_sha256=file_sha256(prior) if prior.is_file() else None)
        stored = result_path(out, stem)
        if stored.exists():
            try:  # a stored result that cannot be read, or holds values of the wrong kind, is redone
                old = read_result(stored)
                run_doc = _up_to_date(old, base, out, stem)
                if run_doc is not None:
                    kept = dataclasses.replace(old, **_from_run_json(run_doc))
                    if kept != old:  # the stored copy was edited: restored from its run
                        write_result(kept, stored)
                    return dataclasses.replace(kept, status="skipped", path=str(task.path))
            except (FrictionUQError, TypeError, ValueError, AttributeError, KeyError):
                pass
        buf_out, buf_err = io.StringIO(), io.StringIO()
        for attempt in range(LOCK_WAIT_S + 1):
            try:
                with contextlib.redirect_stdout(buf_out), contextlib.redirect_stderr(buf_err):
                    run = run_file(task.path, priors_path=task.priors_path, out_dir=out, seed=task.seed,
                                   dispersion=task.dispersion, hoop=task.hoop, pdf=task.pdf, progress=False,
                                   table=False, diagnose=task.diagnose)
                break
            except LockedError:  # the campaign holds the folder: the holder is a killed campaign's dying worker
                if attempt == LOCK_WAIT_S:
                    raise
                time.sleep(1.0)
        doc = json.loads(run.outputs["json"].read_text())
        notes = [line.removeprefix("friction-uq: note: ") for line in buf_err.getvalue().splitlines() if line.strip()]
        result = dataclasses.replace(
            base, status="done", outputs={k: p.name for k, p in run.outputs.items()}, notes=notes,
            seconds=time.perf_counter() - t0, cpu_seconds=time.process_time() - c0, peak_rss_mb=_peak_rss_mb(),
            **_from_run_json(doc))
        write_result(result, stored)
        return result
    except FrictionUQError as exc:
        return dataclasses.replace(base, message=str(exc), seconds=time.perf_counter() - t0)
    except Exception as exc:  # noqa: BLE001 - one record's crash must not stop a campaign of a hundred
        return dataclasses.replace(base, message=f"{task.path}: unexpected {type(exc).__name__}: {exc}",
                                   seconds=time.perf_counter() - t0)
