"""Run many records on Dask distributed: one task per record, seeds from one campaign seed.

A local cluster of processes with one thread each by default (``LocalCluster(n_workers=N,
threads_per_worker=1, processes=True)``), or an existing scheduler by address (``dask scheduler``
and ``dask worker`` processes, or a dask-jobqueue cluster on Slurm). Every worker must see the
records and the output folder at the same paths (a shared file system on a cluster).

Seeds: record k's seed comes from ``SeedSequence(campaign_seed, spawn_key=(key_k,))``, the child
that ``SeedSequence.spawn`` would make, keyed by the record's content (its sha256) rather than its
position: results are bit-identical with 1 or N workers, in any order, and adding a record to a
campaign leaves the seeds (and so the up-to-date results) of the others unchanged.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FrictionUQError
from ..plausible import not_regular
from .job import RecordResult, RecordTask, file_sha256, run_record

RECORD_SUFFIXES = (".h5", ".hdf5")
CONNECT_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class RecordHeader:
    """What the campaign needs before the analysis: checksum, identity and sample material."""

    path: str
    sha256: str
    campaign: str | None
    test_id: str | None
    material: str | None


def find_records(inputs: Sequence[str | os.PathLike[str]]) -> list[Path]:
    """Record files from files and folders (folders searched recursively for ``*.h5``, ``*.hdf5``)."""
    if not inputs:
        raise FrictionUQError("no records given: name record files (.h5) or folders that contain them")
    found: list[Path] = []
    for item in inputs:
        p = Path(item)
        if p.is_dir():
            inside = sorted(q for q in p.rglob("*") if q.suffix.lower() in RECORD_SUFFIXES and q.is_file())
            if not inside:
                raise FrictionUQError(f"{p}: a folder with no records in it (no *.h5 or *.hdf5 file)")
            found.extend(inside)
        elif not p.exists():
            raise FrictionUQError(f"{p}: no such file or folder")
        elif odd := not_regular(p):  # a pipe would block the checksum, a device never end it
            raise FrictionUQError(f"{p}: {odd}, not a record")
        elif not _hdf5_signature(p):  # a file of another type named as a record (a run's JSON, a scope file)
            raise FrictionUQError(f"{p}: not an HDF5 file, so not a test record (`friction-uq import` writes records "
                                  "from scope files)")
        else:
            found.append(p)  # a damaged record is a failed record of the campaign, said in its table
    return found


def _hdf5_signature(path: Path) -> bool:
    """Whether ``path`` holds the HDF5 signature (at byte 0 or after a user block, as h5py finds it; a damaged record
    does too, and its job says what is wrong)."""
    import h5py

    try:
        return bool(h5py.is_hdf5(path))
    except OSError:
        return True  # unreadable: the job's own reading says why, in the campaign's table


def read_header(path: Path) -> RecordHeader:
    """Checksum, campaign, test id and sample material, or None for what cannot be read (the job says why)."""
    import h5py

    from ..plausible import MAX_RECORD_BYTES

    try:
        if path.stat().st_size > MAX_RECORD_BYTES:  # not hashed: the job refuses it in one sentence
            return RecordHeader(str(path), "", None, None, None)
        sha = file_sha256(path)
    except OSError:
        return RecordHeader(str(path), "", None, None, None)
    try:
        with h5py.File(path, "r") as h5:
            camp, tid = h5.attrs.get("campaign"), h5.attrs.get("test_id")
            mat = h5["apparatus/sample"].attrs.get("material") if "apparatus/sample" in h5 else None
    except (OSError, KeyError):
        return RecordHeader(str(path), sha, None, None, None)
    as_str = lambda v: v.decode() if isinstance(v, bytes) else (str(v) if v is not None else None)
    return RecordHeader(str(path), sha, as_str(camp), as_str(tid), as_str(mat))


def check_headers(headers: Sequence[RecordHeader]) -> None:
    """Refuse a campaign that mixes sample materials, names one record (or one test id) twice, or has two
    records whose output names collide (``A_B``/``C`` and ``A``/``B_C`` both write ``A_B_C.*``; names that
    differ only in case collide on some file systems)."""
    from ..record_run import safe_stem

    by_material: dict[str, list[str]] = {}
    for h in headers:
        if h.material is not None:
            by_material.setdefault(h.material, []).append(Path(h.path).name)
    if len(by_material) > 1:
        parts = "; ".join(f"{m} in {', '.join(v[:3])}{' ...' if len(v) > 3 else ''}" for m, v in sorted(by_material.items()))
        raise FrictionUQError(f"records of different sample materials are mixed ({parts}): a campaign pools tests "
                              "of one material pair, run one campaign per material")
    seen: dict[str, str] = {}
    ids: dict[tuple[str, str], str] = {}
    stems: dict[str, RecordHeader] = {}
    for h in headers:
        if h.sha256 and h.sha256 in seen:
            raise FrictionUQError(f"{h.path} and {seen[h.sha256]} are the same record (same sha256): give it once")
        seen[h.sha256] = h.path
        if h.campaign is not None and h.test_id is not None:
            key = (h.campaign, h.test_id)
            if key in ids:
                raise FrictionUQError(f"{h.path} and {ids[key]} have the same campaign and test_id "
                                      f"({h.campaign} {h.test_id}): their outputs would overwrite each other")
            ids[key] = h.path
            stem = safe_stem(h.campaign, h.test_id)
            other = stems.get(stem.casefold())
            if other is not None:
                raise FrictionUQError(
                    f"{h.path} (campaign {h.campaign!r}, test_id {h.test_id!r}) and {other.path} (campaign "
                    f"{other.campaign!r}, test_id {other.test_id!r}) would both write {stem}.*: rename one test_id")
            stems[stem.casefold()] = h


def record_seed(campaign_seed: int, sha256: str, path: str) -> int:
    """The record's seed: the SeedSequence child of the campaign seed keyed by the record's checksum."""
    key = int(sha256[:16], 16) if sha256 else int.from_bytes(path.encode()[-8:].rjust(8, b"\0"), "big")
    child = np.random.SeedSequence(campaign_seed, spawn_key=(key,))
    return int(child.generate_state(1, np.uint32)[0])


def make_tasks(headers: Sequence[RecordHeader], *, out_dir: str | os.PathLike[str], seed: int,
               priors_path: str | None = None, dispersion: bool = False, hoop: bool = True,
               pdf: bool = True, diagnose: bool = False) -> list[RecordTask]:
    return [RecordTask(path=h.path, seed=record_seed(seed, h.sha256, h.path), out_dir=str(out_dir),
                       priors_path=priors_path, dispersion=dispersion, hoop=hoop, pdf=pdf, diagnose=diagnose)
            for h in headers]


class Progress:
    """Records done, failed and left, on stderr (one updating line on a terminal, a line per record otherwise)."""

    def __init__(self, total: int, *, stream=None, enabled: bool = True) -> None:
        self.total, self.done, self.failed, self.skipped = total, 0, 0, 0
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def update(self, r: RecordResult) -> None:
        if r.status == "failed":
            self.failed += 1
        else:
            self.done += 1
            self.skipped += r.status == "skipped"
        if not self.enabled:
            return
        left = self.total - self.done - self.failed
        line = (f"campaign: {self.done} done ({self.skipped} up to date), {self.failed} failed, {left} left"
                f" - {r.label}: {r.status}")
        if self.tty:
            print("\r" + line.ljust(100), end="\n" if left == 0 else "", file=self.stream, flush=True)
        else:
            print(line, file=self.stream, flush=True)


def local_workers(workers: int) -> int:
    """The local cluster's worker processes: ``workers``, at most one per core of this machine (more only
    share the cores, each with its own memory), with a note on stderr when it is capped."""
    if workers < 1:
        raise FrictionUQError(f"--workers must be at least 1, got {workers}")
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if workers > cores:
        print(f"friction-uq: note: --workers {workers} is more than the {cores} core(s) this process may use: "
              f"{cores} worker process(es)", file=sys.stderr, flush=True)
        return cores
    return workers


def open_client(*, workers: int, scheduler: str | None, timeout: float = CONNECT_TIMEOUT_S):
    """A Dask client: on an existing scheduler, or on a new local cluster of one-thread processes."""
    import dask
    from dask.distributed import Client, LocalCluster

    from .._logfile import reroute

    reroute()  # dask.distributed set up its own log handlers when imported: its messages go to the log file

    if scheduler:
        try:
            return Client(scheduler, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).split("\n")[0] or type(exc).__name__
            raise FrictionUQError(f"--scheduler {scheduler}: no Dask scheduler answers at this address within "
                                  f"{timeout:g} s ({reason[:120]})") from None
    if workers < 1:
        raise FrictionUQError(f"--workers must be at least 1, got {workers}")
    # numba's default threading layer is not fork- or thread-safe: one thread per worker process
    with dask.config.set({"distributed.nanny.pre-spawn-environ.NUMBA_NUM_THREADS": 1,
                          "distributed.worker.daemon": True}), _workers_ignore_ctrl_c():
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
    return Client(cluster)


@contextlib.contextmanager
def _workers_ignore_ctrl_c() -> Iterator[None]:
    """Ignore SIGINT while the local cluster starts its worker processes: they inherit it, so Ctrl-C (sent by
    the terminal to the whole process group) reaches only this process, which stops them quietly."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old if old is not None else signal.default_int_handler)


def quiet_cancellations() -> None:
    """In a Dask worker: no warning for each task cut short when an interrupted campaign stops the worker."""
    import logging

    logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)


@contextlib.contextmanager
def _quiet_shutdown() -> Iterator[None]:
    """Dask's loggers silenced while an interrupted campaign stops its cluster (tracebacks of tasks cut short)."""
    import logging

    loggers = [logging.getLogger(n) for n in ("distributed", "tornado", "asyncio")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)


def run_tasks(tasks: Sequence[RecordTask], *, workers: int = 1, scheduler: str | None = None,
              progress: bool = True, job: Callable[[RecordTask], RecordResult] = run_record) -> list[RecordResult]:
    """Run the tasks on Dask and return the results in the order of ``tasks``."""
    from dask.distributed import as_completed

    client = open_client(workers=workers, scheduler=scheduler)
    cluster = None if scheduler else client.cluster
    bar = Progress(len(tasks), enabled=progress)
    interrupted = False
    try:
        client.run(quiet_cancellations)
        futures = client.map(job, list(tasks), pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        results: list[RecordResult | None] = [None] * len(tasks)
        for fut in as_completed(futures):
            i = index[fut.key]
            try:
                res = fut.result()
            except Exception as exc:  # noqa: BLE001 - a lost worker or an unpicklable error: that record failed
                res = RecordResult(path=tasks[i].path, status="failed",
                                   message=f"{tasks[i].path}: the task failed on its worker ({type(exc).__name__}: {exc})")
            results[i] = res
            bar.update(res)
        return [r for r in results if r is not None]
    except KeyboardInterrupt:
        interrupted = True  # each record's checkpoint stays; the next campaign resumes from them
        raise
    finally:
        with _quiet_shutdown() if interrupted else contextlib.nullcontext():
            client.close()
            if cluster is not None:
                cluster.close()
