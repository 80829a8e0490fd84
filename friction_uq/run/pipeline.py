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
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from .._atomic import check_unlocked, output_folder, output_lock, remove_orphans, write_together
from .._parallel import Background
from ..analysis import Identification, Prepared, identify, prepare
from ..discrepancy.check import WholeRecordCheck
from ..diagnostics import (
    Convergence,
    VariableSummary,
    build_datatree,
    convergence,
    f_given_nu,
    nu_sensitivity,
    nu_variance_share,
    prior_data_conflict,
    ratio_ppc,
    summarize,
)
from ..errors import OutputError, PriorError, SamplingError, check_seed
from ..likelihood import Likelihood, LevelForceTerm
from ..prior_sensitivity import FUnderPrior, PriorDataConflict
from ..priors import default_prior_path, load_priors
from ..quoted import quoted_summary
from ..record import read_record
from ..sampler import PosteriorSamples, likelihood_priors, sample_posterior, stderr_progress
from ..settings import AnalysisSettings
from .alongside import alongside, whole_record_start
from .inputs import alternative_nu_priors, hoop_unusable, sliding_velocity_summary
from .outputs import RUN_SCHEMA, RUN_SCHEMA_VERSION, netcdf_bytes, quoted_f, safe_stem, sha256_hex, summary_table
from .warnings import run_warnings

JSON_VARIABLES = ("f", "nu", "kappa", "p_mean", "tau_mean", "V", "ratio")


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
    warnings: tuple[str, ...] = ()  # the checks that failed (friction_uq.run.warnings); empty when all pass


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
    said: list[str] = []
    say = (lambda msg: print(f"friction-uq: {msg}", file=sys.stderr, flush=True)) if progress else (lambda msg: None)

    def note(msg: str) -> None:
        said.append(msg)
        if notes:
            print(f"friction-uq: note: {msg}", file=sys.stderr, flush=True)

    record = read_record(path)
    try:
        p_path = Path(priors_path) if priors_path else default_prior_path(record.apparatus.sample.material)
    except PriorError as exc:  # the record's material names no prior file: say which record and field
        raise PriorError(f"{record.path}: /apparatus/sample@material: {exc}") from None
    priors = load_priors(p_path)  # every input is checked before the signals' work, the busy folder too
    check_unlocked(Path(out_dir), safe_stem(record.campaign, record.test_id))
    prep = prepare(record, window=window, dispersion=dispersion)
    settings = AnalysisSettings(window=window, dispersion=dispersion, hoop=hoop)
    alternatives = alternative_nu_priors(p_path, priors)
    left_out = hoop_unusable(prep) if settings.hoop and prep.data.hoop is not None else None
    use_hoop = bool(settings.hoop and prep.data.hoop is not None and left_out is None)
    # the likelihood of this analysis, built once and passed to every stage that needs it
    likelihood = Likelihood(prep.data, hoop=use_hoop, axial_poisson=settings.axial_poisson,
                            hoop_mode=settings.hoop_mode, hoop_discrepancy=settings.hoop_discrepancy,
                            force_mode=settings.force_mode, ratio_model_form=settings.ratio_model_form)
    likelihood_priors(likelihood, priors)  # the prior file holds every parameter the likelihood needs
    out = Path(out_dir)
    stem = safe_stem(record.campaign, record.test_id)
    names = {"netcdf": out / f"{stem}.nc", "pdf": out / f"{stem}.pdf", "json": out / f"{stem}.json"}
    for p in names.values():
        if p.is_dir():
            raise OutputError(f"{p}: cannot write the output, a directory has that name")
    stages["signals"] = time.perf_counter() - t_start
    # the lab's analysis: eq. 17 at the nominal nu (the prior's median, 0.4 for I1)
    lab = identify(prep, nu=round(float(priors["nu"].ppf(0.5)), 3))
    check = bool(whole_record or diagnose)
    if pdf:  # imported once, before the fork, for both processes
        import matplotlib.backends.backend_pdf  # noqa: F401
        import matplotlib.figure  # noqa: F401
    # on the other core while this one samples: forked before the output lock is taken (the child holds
    # no lock), stopped on the way out
    with (output_folder(out),  # created here; removed again if the run fails and leaves it empty
          Background(alongside if check else None, prep, priors, whole_record_start(lab, priors),
                     hoop=use_hoop, seed=seed, check=check, pages=pdf) as side_job,
          output_lock(out, stem)):
        backend = out / f".{stem}.checkpoint.npz"
        remove_orphans(out, [p.name for p in names.values()] + [backend.name])
        old_backend = out / f".{stem}.chains.h5"  # an earlier version's emcee backend
        if old_backend.exists():
            old_backend.unlink()
        say(f"{record.campaign} {record.test_id}: window {prep.window.t0 * 1e6:.1f}-"
            f"{prep.window.t1 * 1e6:.1f} us, hoop term {'on' if use_hoop else 'off'}, priors {p_path}")
        if left_out:
            note(f"the hoop gauge is left out of the likelihood: {left_out}")
        if check:
            say("the whole test simulated and fitted to every gauge " + ("(alongside the sampling)" if side_job.forked
                                                                         else "(after the sampling)"))

        t = time.perf_counter()
        try:
            samples = sample_posterior(prep.data, priors, seed=seed, hoop=use_hoop, backend_path=backend,
                                       progress=stderr_progress if progress else None, notify=note,
                                       likelihood=likelihood)
        except SamplingError as exc:  # the sampler knows the priors, not the record: name it
            raise SamplingError(f"{record.path}: {exc}") from None
        stages["sampling"] = time.perf_counter() - t
        t = time.perf_counter()
        dt = build_datatree(samples, prep.data, priors, seed=seed, likelihood=likelihood)
        dt.attrs["analysis_settings"] = settings.to_attr()  # provenance: how the likelihood was built
        conv = convergence(dt, samples)
        summary = summarize(dt)
        stages["datatree"] = time.perf_counter() - t
        t = time.perf_counter()
        sens = nu_sensitivity(prep.data, alternatives, seed=seed, hoop=use_hoop, done={"default": samples},
                              likelihood=likelihood)
        n_rerun = sum(s.method == "sampled" for k, s in sens.items() if k != "default")
        say(f"sensitivity to the nu prior: {len(alternatives) - 1} alternatives, {len(alternatives) - 1 - n_rerun} "
            f"by importance reweighting, {n_rerun} sampled afresh")
        conflict = prior_data_conflict(dt, samples, priors)
        if conflict.flagged:
            note(conflict.sentence())
        stages["sensitivity"] = time.perf_counter() - t
        t = time.perf_counter()
        band = f_given_nu(samples, np.linspace(0.15, 0.49, 69))
        share = nu_variance_share(samples)
        ppc = ratio_ppc(samples, prep.data, seed=seed, likelihood=likelihood)
        V = sliding_velocity_summary(prep)
        f_quoted = quoted_summary(samples.flat("f"))  # the stationary f to quote: with the bars' calibration
        stages["analysis"] = time.perf_counter() - t
        t = time.perf_counter()
        posterior_part = None
        if pdf:  # the posterior's pages, while the other core finishes
            from ..report.pdf import ReportInputs, render_posterior_part, render_report

            inputs = ReportInputs(prep, samples, dt, summary, conv, band, sens, share, ppc, lab, V, __version__,
                                  conflict, likelihood=likelihood)
            posterior_part = render_posterior_part(inputs)
        stages["pdf"] = time.perf_counter() - t
        t = time.perf_counter()  # whole_record: what is left of the check when this process gets to it, and diagnose
        wrc, record_part = side_job.result() if check else (None, None)
        diag = None
        if wrc is not None:
            from ..discrepancy import pipeline

            pipeline.add_whole_record(dt, wrc)
            if diagnose:
                from ..discrepancy import outcome

                say("diagnose: fitting each mechanism of the catalogue to the whole record")
                start = {"f": summary["f"].q50, "nu": summary["nu"].q50}
                diag = pipeline.run_diagnose(prep, priors, start, hoop=use_hoop, seed=seed, say=say, check=wrc,
                                             stationary_f=samples.flat("f"))
                outcome.add_to_datatree(dt, diag, priors["f"])
        stages["whole_record"] = time.perf_counter() - t
        levels = likelihood.force if isinstance(likelihood.force, LevelForceTerm) else LevelForceTerm(prep.data)
        warns = run_warnings(ppc=ppc, excess_spread=levels.excess_spread(), dof=levels.dof, f=summary["f"], lab=lab,
                             conv=conv, conflict=conflict, check=wrc, gauge_notes=prep.gauge_notes,
                             diagnosis=diag)
        dt.attrs.update({
            "friction_uq_version": __version__, "record": str(record.path), "record_sha256": record.sha256,
            "test_id": record.test_id, "campaign": record.campaign, "window_s": [prep.window.t0, prep.window.t1],
            "dispersion_correction": int(dispersion), "hoop_term": int(use_hoop),
            "seed": seed if seed < 2**63 else str(seed),  # netCDF attributes hold int64
            "prior_file": str(p_path), "prior_data_conflict": int(bool(conflict.flagged)),
        })  # the DataTree is complete: nothing below changes it
        # the netCDF on the other core (its writer loads dask and xarray's backends, ~0.6 s) while this one
        # draws the report's last pages; in line where this process may not fork
        with Background(netcdf_bytes, dt) as nc_job:
            t = time.perf_counter()
            pdf_bytes = None
            if pdf:
                inputs = dataclasses.replace(inputs, whole_record=wrc, diagnosis=diag, warnings=tuple(warns))
                pdf_bytes = render_report(inputs, record_part=record_part, posterior_part=posterior_part)
            stages["pdf"] += time.perf_counter() - t
            t = time.perf_counter()
            nc_bytes = nc_job.result()

        seconds = time.perf_counter() - t_start
        doc: dict[str, object] = {"schema": RUN_SCHEMA, "schema_version": RUN_SCHEMA_VERSION, "warnings": warns,
                                  "f": quoted_f(f_quoted, summary["f"].to_json(), diag, hoop=samples.hoop)}
        allv = dict(summary) | {"V": V}
        for name in JSON_VARIABLES:
            v = allv[name]
            doc["f_stationary" if name == "f" else name] = {"mean": v.mean, "sd": v.sd, "q05": v.q05, "q50": v.q50,
                                                            "q95": v.q95}
        if "hoop_gain" in summary:
            v = summary["hoop_gain"]
            doc["hoop_gain"] = {"mean": v.mean, "sd": v.sd, "q05": v.q05, "q50": v.q50, "q95": v.q95}
        doc |= {
            "window": [prep.window.t0, prep.window.t1],
            "rhat_max": conv.r_hat_max,
            "ess_min": min(conv.ess_bulk_min, conv.ess_tail_min),
            "seed": seed,
            "seconds": seconds,
            "converged": conv.ok,
            "test_id": record.test_id,
            "campaign": record.campaign,
            "record_sha256": record.sha256,
            "prior_file": str(p_path),
            "hoop_term": use_hoop,
            "hoop_left_out": left_out,
            "dispersion_correction": dispersion,
            "analysis_settings": settings.to_json(),
            "nu_variance_share_of_f": share,
            "f_under_nu_priors": {k: s.to_json() for k, s in sens.items()},
            "prior_data_conflict": conflict.to_json(),
            "ppc_ratio_coverage_90": ppc.coverage,
            "lab_point_estimate_nominal_nu": {"nu": lab.nu, "f": lab.f, "ratio": lab.ratio},
            "ess_per_second": conv.ess_per_second,
            "notes": said,
            "outputs": {"netcdf": {"file": names["netcdf"].name, "sha256": sha256_hex(nc_bytes)},
                        "pdf": None if pdf_bytes is None else {"file": names["pdf"].name, "sha256": sha256_hex(pdf_bytes)}},
            "friction_uq_version": __version__,
        }
        if wrc is not None:
            doc["misfit"] = wrc.to_json()
        if diag is not None:
            doc["discrepancy"] = outcome.to_json(diag, summary["f"].to_json(), f_quoted)
        js_bytes = (json.dumps(doc, indent=2) + "\n").encode()
        write_together({names["netcdf"]: nc_bytes, names["pdf"]: pdf_bytes, names["json"]: js_bytes},
                       last=names["json"])
        backend.unlink(missing_ok=True)
        stages["outputs"] = time.perf_counter() - t  # the netCDF's wait, the JSON and the writes
    outputs = {k: p for k, p in names.items() if k != "pdf" or pdf_bytes is not None}
    if table:
        from ..report.quote import quote_line

        print(quote_line(f_quoted, diag, len(warns), hoop=samples.hoop))
        for w in warns:
            print(f"WARNING: {w}")
        lines = []
        if wrc is not None:
            lines.append(wrc.decision.sentence(page=(10 if use_hoop else 9) if pdf_bytes is not None else None))
        if diag is not None:
            lines.append(doc["discrepancy"]["sentence"])
        print(summary_table(record.campaign, record.test_id, allv, conv, outputs, seconds, conflict, lines))
    return RunResult(prep, samples, summary, conv, lab, outputs, seconds, conflict, tuple(said), stages, sens,
                     wrc, diag, tuple(warns))

