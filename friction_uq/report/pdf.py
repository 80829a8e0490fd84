"""The multi-page PDF report of one run, written atomically."""

from __future__ import annotations

import os
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from .._atomic import write_bytes
from ..analysis import Identification, Prepared
from ..discrepancy.check import WholeRecordCheck
from ..diagnostics import Convergence, FNuBand, FUnderPrior, PriorDataConflict, RatioPPC, VariableSummary
from ..sampler import PosteriorSamples
from .posterior_pages import page_convergence, page_corner, page_hoop, page_ppc, page_propagation
from .signal_pages import page_forces, page_raw, page_window
from .style import CORE_FONTS, figure

UNITS = {"f": ("-", 1.0), "nu": ("-", 1.0), "kappa": ("-", 1.0), "hoop_gain": ("-", 1.0), "ratio": ("-", 1.0),
         "p_mean": ("MPa", 1e-6), "tau_mean": ("MPa", 1e-6), "V": ("m/s", 1.0)}


@dataclass(frozen=True)
class ReportInputs:
    """Everything the report draws, computed upstream."""

    prepared: Prepared
    samples: PosteriorSamples
    datatree: xr.DataTree
    summary: dict[str, VariableSummary]
    convergence: Convergence
    band: FNuBand
    sensitivity: dict[str, FUnderPrior]
    nu_share: float
    ppc: RatioPPC
    lab: Identification
    V: VariableSummary
    version: str
    conflict: PriorDataConflict | None = None
    whole_record: WholeRecordCheck | None = None
    diagnosis: object | None = None  # friction_uq.discrepancy.diagnose.Diagnosis
    likelihood: object | None = None  # friction_uq.likelihood.Likelihood, built once by run


#: Top of the summary page's table (axes fraction) for up to ten rows: the sentences above stay clear of it.
SUMMARY_TABLE_TOP = 0.37


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def page_summary(r: ReportInputs) -> Figure:
    """Page: the answer first, in words and one table."""
    rec = r.prepared.record
    fig, ax = figure(f"friction-uq report: {rec.campaign} {rec.test_id} (sample {rec.apparatus.sample.material})")
    ax.axis("off")
    s = r.summary
    f, nu = s["f"], s["nu"]
    share = r.nu_share
    lines = [
        f"Friction coefficient f = {f.q50:.3f}, 90 % credible interval [{f.q05:.3f}, {f.q95:.3f}] "
        f"(posterior mean {f.mean:.3f}, sd {f.sd:.3f}).",
        f"Poisson ratio nu = {nu.q50:.3f} [{nu.q05:.3f}, {nu.q95:.3f}]; the forces fix only "
        f"kappa = f nu/(1-nu) = {s['kappa'].q50:.4f} [{s['kappa'].q05:.4f}, {s['kappa'].q95:.4f}] (eq. 17).",
        f"{100 * share:.0f} % of the variance of f comes from the uncertainty of nu (law of total variance).",
        f"Stationary phase {r.prepared.window.t0 * 1e6:.1f} - {r.prepared.window.t1 * 1e6:.1f} us "
        f"({'automatic' if r.prepared.window.automatic else 'given by hand'}); sliding velocity "
        f"V = {r.V.q50:.2f} m/s, mean wall pressure p_mean = {s['p_mean'].q50 / 1e6:.1f} MPa.",
        f"The lab's point estimate (eq. 17 with nu = {r.lab.nu:g}): f = {r.lab.f:.4f}, "
        f"F_eo/F_io = {r.lab.ratio:.4f}, equilibrium error {100 * r.lab.equilibrium_error:+.1f} %.",
        f"Hoop gauge term: {'used' if r.samples.hoop else 'not used'}. Convergence: "
        f"{'OK' if r.convergence.ok else 'NOT REACHED'} (R-hat max {r.convergence.r_hat_max:.3f}, "
        f"ESS min {min(r.convergence.ess_bulk_min, r.convergence.ess_tail_min):.0f}).",
        f"Posterior predictive check: the observed ratio lies in the 90 % band {100 * r.ppc.coverage:.0f} % of "
        "the window" + (" - the constant-ratio model misses something here (page 7)." if r.ppc.coverage < 0.7 else "."),
    ]
    if r.conflict is not None:
        lines.append(r.conflict.sentence())
    if r.whole_record is not None:
        lines.append("Whole record: " + r.whole_record.decision.sentence(page=whole_record_page(r)))
    if r.diagnosis is not None:
        from ..discrepancy.outcome import sentence

        lines.append(f"Diagnosis (page {whole_record_page(r) + 2}): " + sentence(r.diagnosis, s["f"].to_json()))
    # wrapped here, not by matplotlib (whose wrap=True measures the text word by word); the lines shrink
    # together where they would run into the table below them
    texts = ["\n".join(textwrap.wrap(line, 110)) for line in lines]
    need = sum(0.034 * (t.count("\n") + 1) + 0.016 for t in texts)
    k = min(1.0, (0.97 - SUMMARY_TABLE_TOP) / need)
    y = 0.97
    for line, text in zip(lines, texts):
        color = "firebrick" if line.startswith("WARNING") else "black"
        ax.text(0.0, y, text, fontsize=10 * k, va="top", transform=ax.transAxes, color=color)
        y -= k * (0.034 * (text.count("\n") + 1) + 0.016)
    rows = []
    for name, v in list(s.items()) + [("V", r.V)]:
        unit, scale = UNITS.get(name, ("", 1.0))
        rows.append([name, unit, _fmt(v.mean * scale), _fmt(v.sd * scale), _fmt(v.q05 * scale), _fmt(v.q50 * scale),
                     _fmt(v.q95 * scale), f"{v.r_hat:.4f}" if np.isfinite(v.r_hat) else "-",
                     f"{v.ess_bulk:.0f}" if np.isfinite(v.ess_bulk) else "-"])
    head = ["quantity", "unit", "mean", "sd", "q05", "q50", "q95", "R-hat", "ESS"]
    table = "\n".join(f"{c[0]:<10}{c[1]:<5}" + "".join(f"{x:>11}" for x in c[2:]) for c in [head] + rows)
    # one monospace text block: a matplotlib table draws every cell as its own text and frame
    ax.text(0.0, 0.05, table, fontsize=10, family="monospace", va="bottom", transform=ax.transAxes,
            bbox={"facecolor": "white", "edgecolor": "0.6", "pad": 6})
    prov = (f"record {rec.path} (sha256 {rec.sha256[:12]}), priors {r.samples.prior_path}, "
            f"seed {r.samples.seed}, friction-uq {r.version}")
    ax.text(0.0, 0.0, prov, fontsize=8, transform=ax.transAxes)
    ax.text(0.84, 0.97, "Pages\n 1 raw gauges\n 2 waves, forces, equilibrium\n 3 window and noise\n"
            " 4 posterior vs prior\n 5 nu -> f\n 6 convergence\n 7 predictive check"
            + ("\n 8 hoop gauge vs model" if r.samples.hoop else "")
            + (f"\n{whole_record_page(r):2d} whole test vs gauges" if r.whole_record is not None else "")
            + (f"\n{whole_record_page(r) + 2:2d} mechanisms ranked\n{whole_record_page(r) + 3:2d} extended fit"
               if r.diagnosis is not None else ""),
            fontsize=8, va="top", transform=ax.transAxes, family="monospace")
    return fig


def render_report(r: ReportInputs) -> bytes:
    """The PDF (summary page, pages 1-7, and page 8 when the hoop term was used), in memory."""
    import io

    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    p = r.prepared
    meta = {"Title": f"friction-uq {p.record.campaign} {p.record.test_id}", "Creator": f"friction-uq {r.version}"}
    buf = io.BytesIO()
    with plt.rc_context(CORE_FONTS), PdfPages(buf, metadata=meta) as pdf:
        builders = [
            lambda: page_summary(r),
            lambda: page_raw(p.record),
            lambda: page_forces(p.record, p.forces, p.window),
            lambda: page_window(p.record, p.forces, p.window),
            lambda: page_corner(r.samples, r.datatree),
            lambda: page_propagation(r.samples, r.band, r.sensitivity, r.nu_share, nu_assumed=r.lab.nu),
            lambda: page_convergence(r.samples, r.convergence),
            lambda: page_ppc(r.ppc),
        ]
        if r.samples.hoop:
            builders.append(lambda: page_hoop(r.samples, p.data, p.forces, seed=r.samples.seed,
                                              likelihood=r.likelihood))
        for build in builders:
            fig = build()
            pdf.savefig(fig)
            plt.close(fig)
        for fig in discrepancy_pages(r):
            pdf.savefig(fig)
            plt.close(fig)
    return buf.getvalue()


def whole_record_page(r: ReportInputs) -> int:
    """Number of the first whole-record page (after page 7, or 8 with the hoop page)."""
    return 9 if r.samples.hoop else 8


def discrepancy_pages(r: ReportInputs) -> list[Figure]:
    """The whole-record pages and, with a diagnosis, the ranking and the extended fit."""
    p = r.prepared
    test = f"{p.record.campaign} {p.record.test_id}"
    figs: list[Figure] = []
    if r.whole_record is not None:
        from .whole_record_pages import pages_whole_record

        figs += pages_whole_record(r.whole_record, test=test)
    if r.diagnosis is not None:
        from ..discrepancy.outcome import sentence
        from .diagnose_pages import page_extended_fit, page_ranking

        fw = r.summary["f"].to_json()
        figs += [page_ranking(r.diagnosis, f_without=fw, sentence=sentence(r.diagnosis, fw), test=test),
                 page_extended_fit(r.diagnosis, test=test)]
    return figs


def write_report(r: ReportInputs, path: str | os.PathLike[str]) -> Path:
    """Write the PDF of :func:`render_report` atomically."""
    return write_bytes(path, render_report(r))
