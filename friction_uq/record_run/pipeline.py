"""``friction-uq run``: from one record to the posterior, its propagation and the report.

Outputs (in ``out_dir``): ``<campaign>_<test_id>.nc`` (ArviZ DataTree), ``.json`` (summary) and
``.pdf`` (report). The three are made in memory, written to temporary names, then renamed
together, the JSON (which names the ``.nc``'s and the ``.pdf``'s sha256) last: they always come
from the same run. A run holds ``.<stem>.lock`` in the folder while it works (a second run of the
same record into the same folder is refused), removes temporary files an interrupted run left,
and keeps a checkpoint (``.<stem>.checkpoint.npz``, every few seconds) from which an interrupted
run resumes; a checkpoint of another seed, prior, window or setting is replaced with a notice.
The checkpoint is removed once the outputs are written.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from .._atomic import output_folder, output_lock, remove_orphans, write_together
from .._json_text import json_text
from .._parallel import Background
from ..analysis import Identification, Prepared
from ..diagnostics import Convergence, VariableSummary
from ..discrepancy.check import WholeRecordCheck
from ..errors import check_seed
from ..likelihood import LevelForceTerm
from ..prior_sensitivity import FUnderPrior, PriorDataConflict
from ..sampler import PosteriorSamples
from .alongside import alongside, whole_record_start
from .outputs import netcdf_bytes, summary_table
from .run_document import run_document
from .steps import RunSetup, StationaryPosterior, set_up, stationary_posterior
from .warnings import RunWarning, run_warnings

@dataclass(frozen=True)
class RunResult:
    prepared: Prepared
    samples: PosteriorSamples
    summary: dict[str, VariableSummary]
    convergence: Convergence
    lab: Identification
    outputs: dict[str, Path]
    seconds: float
    conflict: PriorDataConflict | None = None
    notes: tuple[str, ...] = ()
    stages: dict[str, float] = dataclasses.field(default_factory=dict)
    sensitivity: dict[str, FUnderPrior] = dataclasses.field(default_factory=dict)
    whole_record: WholeRecordCheck | None = None
    diagnosis: object | None = None  # friction_uq.discrepancy.diagnose.Diagnosis
    warnings: tuple[str, ...] = ()  # the checks that failed (friction_uq.record_run.warnings); empty when all pass
    warning_kinds: tuple[str, ...] = ()  # each warning's kind (friction_uq.record_run.warnings.WARNING_KINDS)


def run_file(
    path: str | os.PathLike[str],
    *,
    priors_path: str | os.PathLike[str] | None = None,
    out_dir: str | os.PathLike[str] = "reports",
    seed: int = 20161,
    window: tuple[float, float] | None = None,
    dispersion: bool = False,
    hoop: bool = True,
    pdf: bool = True,
    progress: bool = True,
    table: bool = True,
    notes: bool = True,
    whole_record: bool = True,
    diagnose: bool = False,
) -> RunResult:
    """The main job (see the module docstring).

    ``progress`` prints progress lines, ``notes`` one-line notices (hoop gauge left out, checkpoint
    replaced, prior-data conflict) and ``table`` the summary table; with all three False nothing is
    printed (the notices are in ``RunResult.notes``). ``whole_record`` simulates the whole test with
    the posterior against every gauge (:mod:`friction_uq.discrepancy`); ``diagnose`` also fits every
    mechanism of the catalogue and names the cause of a misfit. Every input (seed, record, priors, output
    folder) is checked before sampling.

    Raises
    ------
    FrictionUQError
        Bad input of any kind, or an output that cannot be written (:class:`OutputError`).
    """
    t_start = time.perf_counter()
    seed = check_seed(seed)
    stages: dict[str, float] = {}
    voice = _Voice(progress=progress, notes=notes)
    out = Path(out_dir)
    s = set_up(path, priors_path, out, window=window, dispersion=dispersion, hoop=hoop)
    stages["signals"] = time.perf_counter() - t_start
    check = bool(whole_record or diagnose)
    if pdf:  # imported once, before the fork, for both processes
        import matplotlib.backends.backend_pdf  # noqa: F401
        import matplotlib.figure  # noqa: F401
    # on the other core while this one samples: forked before the output lock is taken (the child holds
    # no lock), stopped on the way out
    with (output_folder(out),  # created here; removed again if the run fails and leaves it empty
          Background(alongside if check else None, s.prepared, s.priors, whole_record_start(s.lab, s.priors),
                     hoop=s.use_hoop, seed=seed, check=check, pages=pdf) as side_job,
          output_lock(out, s.stem)):
        backend = _fresh_backend(out, s)
        _announce(s, voice, check=check, alongside=side_job.forked)
        post = stationary_posterior(s, seed=seed, backend=backend, progress=progress, say=voice.say,
                                    note=voice.note, stages=stages)
        t = time.perf_counter()
        inputs, posterior_part = _posterior_pages(s, post) if pdf else (None, None)  # while the other core finishes
        stages["pdf"] = time.perf_counter() - t
        t = time.perf_counter()  # whole_record: what is left of the check when this process gets to it, and diagnose
        wrc, record_part = side_job.result() if check else (None, None)
        diag = _record_check(s, post, wrc, diagnose=diagnose, seed=seed, say=voice.say) if wrc is not None else None
        stages["whole_record"] = time.perf_counter() - t
        found = _warnings(s, post, wrc, diag)
        warns, kinds = [w.text for w in found], [w.kind for w in found]
        _complete_datatree(post, s, seed)  # the DataTree is complete: nothing below changes it
        if inputs is not None:
            inputs = dataclasses.replace(inputs, whole_record=wrc, diagnosis=diag, warnings=tuple(warns))
        doc, pdf_bytes, seconds = _write_outputs(s, post, inputs, (record_part, posterior_part), wrc=wrc, diag=diag,
                                                 warns=warns, kinds=kinds, notes=voice.said, seed=seed, dispersion=dispersion,
                                                 stages=stages, t_start=t_start)
        backend.unlink(missing_ok=True)
    outputs = {k: p for k, p in s.names.items() if k != "pdf" or pdf_bytes is not None}
    if table:
        _print_summary(s, post, wrc, diag, doc, warns, outputs, seconds, page=pdf_bytes is not None)
    return RunResult(s.prepared, post.samples, post.summary, post.convergence, s.lab, outputs, seconds, post.conflict,
                     tuple(voice.said), stages, post.sensitivity, wrc, diag, tuple(warns), tuple(kinds))


class _Voice:
    """What a run says on stderr: progress lines (``progress``) and one-line notices (``notes``); the notices
    are kept (``said``) for the JSON and ``RunResult.notes`` whether printed or not."""

    def __init__(self, *, progress: bool, notes: bool) -> None:
        self.progress, self.notes, self.said = progress, notes, []

    def say(self, msg: str) -> None:
        if self.progress:
            print(f"friction-uq: {msg}", file=sys.stderr, flush=True)

    def note(self, msg: str) -> None:
        self.said.append(msg)
        if self.notes:
            print(f"friction-uq: note: {msg}", file=sys.stderr, flush=True)


def _fresh_backend(out: Path, s: RunSetup) -> Path:
    """The checkpoint's path, after the temporary files an interrupted run left and an earlier version's emcee
    backend are removed (the lock is held)."""
    backend = out / f".{s.stem}.checkpoint.npz"
    remove_orphans(out, [p.name for p in s.names.values()] + [backend.name])
    (out / f".{s.stem}.chains.h5").unlink(missing_ok=True)  # an earlier version's emcee backend
    return backend


def _announce(s: RunSetup, voice: _Voice, *, check: bool, alongside: bool) -> None:
    """The run's first lines: the record, its window, the hoop term and the priors; what is left out; where the
    whole-record check runs."""
    voice.say(f"{s.record.campaign} {s.record.test_id}: window {s.prepared.window.t0 * 1e6:.1f}-"
              f"{s.prepared.window.t1 * 1e6:.1f} us, hoop term {'on' if s.use_hoop else 'off'}, priors {s.prior_path}")
    if s.hoop_left_out:
        voice.note(f"the hoop gauge is left out of the likelihood: {s.hoop_left_out}")
    sample = s.record.apparatus.sample.material
    if s.priors.material and sample and s.priors.material.casefold() != sample.casefold():  # said, not refused
        voice.note(f"the prior file {s.prior_path} is for material {s.priors.material!r}, the record's sample is "
                   f"{sample!r}: its nu prior is another material's unless you meant it")
    if check:
        voice.say("the whole test simulated and fitted to every gauge " + ("(alongside the sampling)" if alongside
                                                                           else "(after the sampling)"))


def _write_outputs(s: RunSetup, post: StationaryPosterior, inputs: object | None, parts: tuple, *,
                   wrc: WholeRecordCheck | None, diag: object | None, warns: list[str], kinds: list[str],
                   notes: list[str], seed: int,
                   dispersion: bool, stages: dict[str, float], t_start: float) -> tuple[dict, bytes | None, float]:
    """The netCDF (on the other core, its writer loads dask and xarray's backends, ~0.6 s; in line where this
    process may not fork) while this one draws the report's last pages (``inputs`` None: no PDF); then the JSON,
    and the three written together, the JSON last. (The JSON, the PDF's bytes or None, the run's seconds.)"""
    with Background(netcdf_bytes, post.datatree) as nc_job:
        t = time.perf_counter()
        pdf_bytes = None
        if inputs is not None:
            from ..report.pdf import render_report

            record_part, posterior_part = parts
            pdf_bytes = render_report(inputs, record_part=record_part, posterior_part=posterior_part)
        stages["pdf"] += time.perf_counter() - t
        t = time.perf_counter()
        nc_bytes = nc_job.result()
    seconds = time.perf_counter() - t_start
    doc = run_document(s, post, seed=seed, seconds=seconds, warns=warns, kinds=kinds, notes=notes, wrc=wrc, diag=diag,
                       dispersion=dispersion, nc_bytes=nc_bytes, pdf_bytes=pdf_bytes)
    js_bytes = json_text(doc).encode()
    write_together({s.names["netcdf"]: nc_bytes, s.names["pdf"]: pdf_bytes, s.names["json"]: js_bytes},
                   last=s.names["json"])
    stages["outputs"] = time.perf_counter() - t  # the netCDF's wait, the JSON and the writes
    return doc, pdf_bytes, seconds


def _posterior_pages(s: RunSetup, post: StationaryPosterior) -> tuple[object, bytes]:
    """The report's inputs so far and its posterior pages (2-8, 9 with the hoop term)."""
    from ..report.pdf import ReportInputs, render_posterior_part

    inputs = ReportInputs(s.prepared, post.samples, post.datatree, post.summary, post.convergence, post.band,
                          post.sensitivity, post.nu_share, post.ppc, s.lab, post.V, __version__, post.conflict,
                          likelihood=s.likelihood, halves=s.halves, hoop_or_prior=post.hoop_or_prior)
    return inputs, render_posterior_part(inputs)


def _warnings(s: RunSetup, post: StationaryPosterior, wrc: WholeRecordCheck | None,
              diag: object | None) -> list[RunWarning]:
    """The checks that failed, one sentence each with its kind (:mod:`.warnings`)."""
    lik = s.likelihood
    levels = lik.force if isinstance(lik.force, LevelForceTerm) else LevelForceTerm(s.prepared.data)
    return run_warnings(ppc=post.ppc, excess_spread=levels.excess_spread(), dof=levels.dof, f=post.f_read,
                        lab=s.lab, conv=post.convergence, conflict=post.conflict, check=wrc,
                        findings=s.prepared.findings, diagnosis=diag,
                        hoop_silent=s.hoop_left_out if s.hoop_silent else None, hoop_or_prior=post.hoop_or_prior)


def _record_check(s: RunSetup, post: StationaryPosterior, wrc: WholeRecordCheck, *, diagnose: bool, seed: int,
                  say: Callable[[str], None]) -> object | None:
    """The whole-record check written into the DataTree; with ``diagnose``, every mechanism of the catalogue
    fitted to the whole record and the cause named (written there too), else None."""
    from ..discrepancy import outcome, run_stage

    run_stage.add_whole_record(post.datatree, wrc)
    if not diagnose:
        return None
    say("diagnose: fitting each mechanism of the catalogue to the whole record")
    start = {"f": post.summary["f"].q50, "nu": post.summary["nu"].q50}
    diag = run_stage.run_diagnose(s.prepared, s.priors, start, hoop=s.use_hoop, seed=seed, say=say, check=wrc,
                                 stationary_f=post.samples.flat("f"))
    if post.hoop_or_prior is not None:  # its models read nu through the hoop gauge as well: f from both readings
        diag = dataclasses.replace(diag, f_prior_nu=post.hoop_or_prior.f_prior_draws)
    outcome.add_to_datatree(post.datatree, diag, s.priors["f"], s.priors["nu"])
    return diag


def _complete_datatree(post: StationaryPosterior, s: RunSetup, seed: int) -> None:
    """The run's provenance in the DataTree's attributes."""
    post.datatree.attrs.update({
        "friction_uq_version": __version__, "record": str(s.record.path), "record_sha256": s.record.sha256,
        "test_id": s.record.test_id, "campaign": s.record.campaign,
        "window_s": [s.prepared.window.t0, s.prepared.window.t1],
        "dispersion_correction": int(s.settings.dispersion), "hoop_term": int(s.use_hoop),
        "seed": seed if seed < 2**63 else str(seed),  # netCDF attributes hold int64
        "prior_file": str(s.prior_path), "prior_data_conflict": int(bool(post.conflict.flagged)),
    })


def _both(post: StationaryPosterior) -> dict[str, float] | None:
    """The two readings' medians of f when the hoop gauge and nu's prior disagree, else None."""
    return None if post.hoop_or_prior is None else post.hoop_or_prior.medians


def _print_summary(s: RunSetup, post: StationaryPosterior, wrc: WholeRecordCheck | None, diag: object | None,
                   doc: dict[str, object], warns: list[str], outputs: dict[str, Path], seconds: float, *,
                   page: bool) -> None:
    """The terminal's headline, warnings and summary table (``page``: a report was written to point at)."""
    from ..report.pdf import first_whole_record_page
    from ..report.quote import quote_line

    print(quote_line(post.f_quoted, diag, len(warns), hoop=post.samples.hoop, both=_both(post)))
    for w in warns:
        print(f"WARNING: {w}")
    lines = []
    if wrc is not None:
        lines.append(wrc.decision.sentence(page=first_whole_record_page(s.use_hoop) if page else None))
    if diag is not None:
        lines.append(doc["discrepancy"]["sentence"])
    print(summary_table(s.record.campaign, s.record.test_id, dict(post.summary) | {"V": post.V}, post.convergence,
                        outputs, seconds, post.conflict, lines,
                        both=post.hoop_or_prior is not None))
