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
    table: bool = True,
) -> RunResult:
    """The main job (see the module docstring); prints a summary table at the end unless ``table=False``."""
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

        inputs = ReportInputs(prep, samples, dt, summary, conv, band, sens, share, ppc, lab, V, __version__)
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
    js = out / f"{stem}.json"
    _atomic_write_bytes(js, lambda tmp: Path(tmp).write_text(json.dumps(doc, indent=2) + "\n"))
    outputs["json"] = js
    if backend.exists():
        backend.unlink()
    if table:
        print(summary_table(record.campaign, record.test_id, allv, conv, outputs, seconds))
    return RunResult(prep, samples, summary, conv, lab, outputs, seconds)


def summary_table(campaign: str, test_id: str, allv: dict[str, VariableSummary], conv: Convergence,
                  outputs: dict[str, Path], seconds: float) -> str:
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
    for k, pth in outputs.items():
        lines.append(f"wrote {pth}")
    return "\n".join(lines)
