"""``friction-uq run``: from one record to the posterior, its propagation and the report.

Outputs (in ``out_dir``): ``<campaign>_<test_id>.nc`` (ArviZ DataTree), ``.json`` (summary) and
``.pdf`` (report). Each file is written to a temporary name and renamed: it appears whole or not
at all. The sampler's HDF5 backend (``.<stem>.chains.h5``) lets an interrupted run resume; it is
removed once the outputs are written.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats

from . import __version__
from ._atomic import atomic_path
from .analysis import Identification, Prepared, identify, prepare
from .discrepancy.check import WholeRecordCheck, check_whole_record
from .diagnostics import (
    Convergence,
    VariableSummary,
    build_datatree,
    convergence,
    f_given_nu,
    nu_sensitivity,
    nu_variance_share,
    ratio_ppc,
    summarize,
)
from .errors import FrictionUQError
from .priors import PRIORS_DIR, Priors, default_prior_path, load_priors
from .record import read_record
from .sampler import PosteriorSamples, sample_posterior, stderr_progress

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
    whole_record: WholeRecordCheck | None = None


def safe_stem(campaign: str, test_id: str) -> str:
    """``<campaign>_<test_id>`` with anything but letters, digits, '.', '-' and '_' replaced by '_'."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", f"{campaign}_{test_id}").lstrip(".")


def sliding_velocity_summary(p: Prepared) -> VariableSummary:
    """V over the window: mean and its standard error, normal quantiles.

    V = V_io - V_eo (eq. 7) is measured, not a model parameter; its uncertainty is the noise of
    the two output gauges averaged over the window (effective AR(1) sample size) plus the error
    of the offsets removed from them (pre-pulse estimates).
    """
    app = p.record.apparatus
    ch = p.forces.channels
    io, eo = app.internal_output_bar, app.external_output_bar
    n_io, n_eo = ch["internal_output_bar"].noise, ch["external_output_bar"].noise
    v = np.asarray(p.data.V, float)
    sd = math.hypot(n_io.window_mean_sd(len(v), scale=io.wave_speed), n_eo.window_mean_sd(len(v), scale=eo.wave_speed))
    m = float(np.mean(v))
    q = stats.norm.ppf([0.05, 0.5, 0.95], loc=m, scale=sd)
    return VariableSummary(m, sd, float(q[0]), float(q[1]), float(q[2]), float("nan"), float("nan"))


def alternative_nu_priors(default_path: Path, priors: Priors) -> dict[str, Priors]:
    """The priors used and the nu alternatives shipped in ``priors/`` (``<material>-nu-*.toml``).

    Each alternative keeps the used f (and hoop gain) prior and swaps nu only, so the posteriors
    of f differ by the nu prior alone. A material without alternatives gets none (the report then
    shows f under the one prior used).
    """
    out: dict[str, Priors] = {"default": priors}
    material = priors.material or default_path.stem
    for alt in sorted(PRIORS_DIR.glob(f"{material}-nu-*.toml")):
        if alt.resolve() == Path(default_path).resolve():
            continue
        other = load_priors(alt)
        label = alt.stem.removeprefix(f"{material}-")
        out[label] = dataclasses.replace(priors.replace(other["nu"]), path=str(alt), description=other.description)
    return out


def _atomic_write_bytes(path: Path, write) -> None:
    with atomic_path(path) as tmp:
        write(tmp)


def hoop_unusable(p: Prepared) -> str | None:
    """Why the hoop gauge cannot enter the likelihood for this record, or None if it can.

    * the channel shows no pulse above its noise (a dead or disconnected gauge);
    * its window mean is not a swelling beyond 3 standard errors (noise of the mean and offset);
    * the tube differs from the one the influence function was fitted to (bore 10 mm, outer
      24 mm, nu_t 0.29; physics.md section 6): the kernel would be wrong.
    """
    t = p.record.apparatus.tube
    if not (abs(t.inner_diameter - 0.010) < 1e-6 and abs(t.outer_diameter - 0.024) < 1e-6
            and abs(t.poisson_ratio - 0.29) < 1e-3):
        return (f"the tube influence function is fitted to a 10/24 mm tube with nu_t = 0.29, this record's tube is "
                f"{t.inner_diameter * 1e3:g}/{t.outer_diameter * 1e3:g} mm with nu_t = {t.poisson_ratio:g}")
    info = p.forces.channels["tube_hoop"]
    if not info.detected:
        return "tube_hoop shows no pulse above its noise (a dead or disconnected gauge?)"
    se = info.noise.window_mean_sd(p.data.n)
    mean = float(np.mean(p.data.hoop))
    if not mean < -3.0 * se:  # compression positive: a swelling tube reads negative
        return (f"tube_hoop shows no swelling over the window (mean {mean * 1e6:+.2f} microstrain, standard "
                f"error {se * 1e6:.2f})")
    return None


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
    whole_record: bool = True,
    diagnose: bool = False,
) -> RunResult:
    """The main job (see the module docstring); prints a summary table at the end."""
    t_start = time.perf_counter()
    record = read_record(path)
    prep = prepare(record, window=window, dispersion=dispersion)
    p_path = Path(priors_path) if priors_path else default_prior_path(record.apparatus.sample.material)
    priors = load_priors(p_path)
    alternatives = alternative_nu_priors(p_path, priors)
    left_out = hoop_unusable(prep) if hoop and prep.data.hoop is not None else None
    use_hoop = bool(hoop and prep.data.hoop is not None and left_out is None)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise FrictionUQError(f"{out}: --out must be a directory, and this is a file")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FrictionUQError(f"{out}: cannot create the output directory ({exc.strerror or exc})") from None
    stem = safe_stem(record.campaign, record.test_id)
    backend = out / f".{stem}.chains.h5"
    say = (lambda msg: print(msg, file=sys.stderr)) if progress else (lambda msg: None)
    say(f"friction-uq: {record.campaign} {record.test_id}: window {prep.window.t0 * 1e6:.1f}-"
        f"{prep.window.t1 * 1e6:.1f} us, hoop term {'on' if use_hoop else 'off'}, priors {p_path}")
    if left_out:
        print(f"friction-uq: note: the hoop gauge is left out of the likelihood: {left_out}", file=sys.stderr)

    samples = sample_posterior(prep.data, priors, seed=seed, hoop=use_hoop, backend_path=backend,
                               progress=stderr_progress if progress else None)
    dt = build_datatree(samples, prep.data, priors, seed=seed)
    conv = convergence(dt, samples)
    summary = summarize(dt)
    say(f"friction-uq: sensitivity to the nu prior ({len(alternatives) - 1} more runs)")
    sens = nu_sensitivity(prep.data, alternatives, seed=seed, hoop=use_hoop, done={"default": samples})
    band = f_given_nu(samples, np.linspace(0.15, 0.49, 69))
    share = nu_variance_share(samples)
    ppc = ratio_ppc(samples, prep.data, seed=seed)
    # the lab's analysis: eq. 17 at the nominal nu (the prior's median, 0.4 for I1)
    lab = identify(prep, nu=round(float(priors["nu"].ppf(0.5)), 3))
    V = sliding_velocity_summary(prep)
    wrc = None
    if whole_record:
        say("friction-uq: the whole test simulated with the posterior, against every gauge")
        wrc = whole_record_check(prep, priors, summary, hoop=use_hoop, seed=seed)
        add_whole_record(dt, wrc)
    diag = None
    if diagnose:
        from .discrepancy import outcome

        say("friction-uq: diagnose: fitting each mechanism of the catalogue to the whole record")
        diag = run_diagnose(prep, priors, summary, hoop=use_hoop, seed=seed, say=say)
        outcome.add_to_datatree(dt, diag)

    dt.attrs.update({
        "friction_uq_version": __version__, "record": str(record.path), "record_sha256": record.sha256,
        "test_id": record.test_id, "campaign": record.campaign, "window_s": [prep.window.t0, prep.window.t1],
        "dispersion_correction": int(dispersion), "hoop_term": int(use_hoop), "seed": seed,
        "prior_file": str(p_path),
    })
    outputs: dict[str, Path] = {}
    nc = out / f"{stem}.nc"
    _atomic_write_bytes(nc, lambda tmp: dt.to_netcdf(tmp, engine="h5netcdf"))
    outputs["netcdf"] = nc

    if pdf:
        from .report.pdf import ReportInputs, write_report

        inputs = ReportInputs(prep, samples, dt, summary, conv, band, sens, share, ppc, lab, V, __version__,
                              whole_record=wrc, diagnosis=diag)
        outputs["pdf"] = write_report(inputs, out / f"{stem}.pdf")

    seconds = time.perf_counter() - t_start
    doc: dict[str, object] = {}
    allv = dict(summary) | {"V": V}
    for name in JSON_VARIABLES:
        v = allv[name]
        doc[name] = {"mean": v.mean, "sd": v.sd, "q05": v.q05, "q50": v.q50, "q95": v.q95}
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
        "nu_variance_share_of_f": share,
        "f_under_nu_priors": {k: s.to_json() for k, s in sens.items()},
        "ppc_ratio_coverage_90": ppc.coverage,
        "lab_point_estimate_nominal_nu": {"nu": lab.nu, "f": lab.f, "ratio": lab.ratio},
        "ess_per_second": conv.ess_per_second,
        "friction_uq_version": __version__,
    }
    if wrc is not None:
        doc["misfit"] = wrc.to_json()
    if diag is not None:
        doc["discrepancy"] = outcome.to_json(diag, summary["f"].to_json())
        fx = diag.final.f_summary() if diag.causes else summary["f"].to_json()
        doc["f_headline"] = {"model": diag.final.label if diag.causes else "baseline (stationary phase, eq. 17 + hoop)"}
        doc["f_headline"].update({k: fx[k] for k in ("mean", "sd", "q05", "q50", "q95")})
    js = out / f"{stem}.json"
    _atomic_write_bytes(js, lambda tmp: Path(tmp).write_text(json.dumps(doc, indent=2) + "\n"))
    outputs["json"] = js
    if backend.exists():
        backend.unlink()
    print(summary_table(record.campaign, record.test_id, allv, conv, outputs, seconds, wrc,
                        page=(9 if use_hoop else 8) if pdf else None,
                        diagnosis=doc["discrepancy"]["sentence"] if diag is not None else None))
    return RunResult(prep, samples, summary, conv, lab, outputs, seconds, wrc)


def whole_record_check(prep: Prepared, priors: Priors, summary: dict[str, VariableSummary], *, hoop: bool,
                       seed: int) -> WholeRecordCheck:
    """The whole-record check (:mod:`friction_uq.discrepancy.check`) with this run's f and nu priors,
    started from the stationary posterior's medians."""

    def log_prior(v) -> float:
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    return check_whole_record(prep, log_prior, {"f": summary["f"].q50, "nu": summary["nu"].q50},
                              hoop=hoop or prep.record.has_hoop, seed=seed)


def run_diagnose(prep: Prepared, priors: Priors, summary: dict[str, VariableSummary], *, hoop: bool, seed: int,
                 say=lambda msg: None):
    """Fit every mechanism of the catalogue (:mod:`friction_uq.discrepancy.diagnose`), started from the
    stationary posterior's medians, with this run's f and nu priors."""
    from .discrepancy.diagnose import diagnose

    def log_prior(v) -> float:
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    from .models.parameters import F, NU

    scales = {}
    for par in (F, NU):
        lo, mid, hi = (float(par.to_unbounded(priors[par.name].ppf(q))) for q in (0.16, 0.5, 0.84))
        scales[par.name] = (mid, max(0.5 * (hi - lo), 1e-3))
    return diagnose(prep, log_prior, {"f": summary["f"].q50, "nu": summary["nu"].q50}, hoop=hoop or prep.record.has_hoop,
                    seed=seed, progress=lambda m: say(f"friction-uq: diagnose: {m}"), base_scales=scales)


def add_whole_record(dt, wrc: WholeRecordCheck) -> None:
    """Simulated gauges of the posterior draws over the whole record (``posterior_predictive``) and
    the measured ones (``whole_record_observed``), on the record's time base."""
    import xarray as xr

    comp = wrc.comparison
    pp = {ch: (("chain", "draw", "time_record"), v[None]) for ch, v in comp.predicted.items()}
    obs = {ch: (("time_record",), v) for ch, v in comp.measured.items()}
    coords = {"time_record": comp.time}
    dt["posterior_predictive"] = xr.DataTree(xr.Dataset(pp, coords=coords | {"chain": [0], "draw": np.arange(
        len(next(iter(comp.predicted.values()))))}, attrs={
        "description": "gauge strains (compression positive) simulated for draws of the whole-record fit of the "
                       "simulator driven by the measured incident wave", "misfit_statistic": wrc.decision.statistic,
        "misfit_threshold": wrc.decision.threshold, "misfit_detected": int(wrc.decision.detected)}))
    dt["whole_record_observed"] = xr.DataTree(xr.Dataset(obs, coords=coords, attrs={
        "description": "measured gauge strains, offset removed, compression positive"}))


def summary_table(campaign: str, test_id: str, allv: dict[str, VariableSummary], conv: Convergence,
                  outputs: dict[str, Path], seconds: float, wrc: WholeRecordCheck | None = None, *,
                  page: int | None = None, diagnosis: str | None = None) -> str:
    """The table the terminal ends with."""
    units = {"p_mean": ("MPa", 1e-6), "tau_mean": ("MPa", 1e-6), "V": ("m/s", 1.0)}
    lines = [f"{campaign} {test_id}: posterior (90 % credible intervals)",
             f"{'quantity':<10} {'unit':<5} {'q50':>10} {'q05':>10} {'q95':>10} {'mean':>10} {'sd':>10}"]
    for name in ("f", "nu", "kappa", "hoop_gain", "ratio", "p_mean", "tau_mean", "V"):
        if name not in allv:
            continue
        v = allv[name]
        u, s = units.get(name, ("-", 1.0))
        lines.append(f"{name:<10} {u:<5} {v.q50 * s:>10.4g} {v.q05 * s:>10.4g} {v.q95 * s:>10.4g} "
                     f"{v.mean * s:>10.4g} {v.sd * s:>10.4g}")
    lines.append(f"convergence {'OK' if conv.ok else 'NOT REACHED'}: R-hat max {conv.r_hat_max:.4f}, "
                 f"ESS min {min(conv.ess_bulk_min, conv.ess_tail_min):.0f}, {conv.ess_per_second:.0f} ESS/s; "
                 f"{seconds:.1f} s in all")
    if wrc is not None:
        lines.append(wrc.decision.sentence(page=page))
    if diagnosis is not None:
        lines.append(diagnosis)
    for k, pth in outputs.items():
        lines.append(f"wrote {pth}")
    return "\n".join(lines)
