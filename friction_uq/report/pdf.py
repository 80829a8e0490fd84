"""The multi-page PDF report of one run, written atomically."""

from __future__ import annotations

import io
import os
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from .._atomic import write_bytes
from ..analysis import Identification, Prepared
from ..discrepancy.candidates_mixture import STATIONARY
from ..discrepancy.check import WholeRecordCheck
from ..discrepancy.diagnosed_f import headline as outcome_headline
from .quote import quote_line
from ..diagnostics import Convergence, FNuBand, FUnderPrior, PriorDataConflict, RatioPPC, VariableSummary
from ..quoted import quoted_summary
from ..sampler import PosteriorSamples
from ..hoop_or_prior import HoopOrPrior
from ..window_halves import WindowHalves
from .posterior_pages import page_convergence, page_corner, page_hoop, page_ppc, page_propagation
from .signal_pages import page_forces, page_raw, page_window
from .style import CORE_FONTS, figure
from .whole_record_pages import page_count

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
    warnings: tuple[str, ...] = ()  # the run's checks that failed (friction_uq.record_run.warnings), shown first
    halves: WindowHalves | None = None  # kappa's change across the window (the run JSON's window_halves)
    hoop_or_prior: HoopOrPrior | None = None  # f with the hoop gauge and from nu's prior alone, when they disagree


#: Top of the summary page's table (axes fraction) for up to ten rows: the sentences above stay clear of it.
SUMMARY_TABLE_TOP = 0.37
#: A text line's height over its font size (matplotlib's line spacing 1.2, with the glyphs' own height).
LINE_SPACING = 1.3
#: The summary lines' font never shrinks below this factor on 10 pt (5 pt): below it they may overflow.
MIN_FONT_FACTOR = 0.5


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def stationary_quoted(r: ReportInputs) -> dict[str, float]:
    """The stationary analysis' f to quote: its posterior with the output bars' calibration (as the JSON's); where
    the hoop gauge and nu's prior disagree, that with the hoop gauge and that from the prior alone in equal parts."""
    return quoted_summary(r.samples.flat("f")) if r.hoop_or_prior is None else r.hoop_or_prior.f_quoted


def _shrink_to_fit(lines: list[str], room: float, line: float, width: int = 135) -> tuple[list[str], float]:
    """The lines wrapped, and the largest factor k (<= 1) on their 10 pt font that fits them in ``room`` (axes
    fraction; ``line``: the height of a 10 pt line, the same unit): a smaller font takes more characters on a line
    of the page's width, so the lines are wrapped at ``width / k`` (the block keeps the page's width instead of
    narrowing with its font)."""
    def wrapped(k: float) -> tuple[list[str], float]:
        texts = ["\n".join(textwrap.wrap(line_, int(width / k))) for line_ in lines]
        return texts, k * sum(line * (t.count("\n") + 1.5) for t in texts)

    texts, height = wrapped(1.0)
    if height <= room:
        return texts, 1.0
    lo, hi = MIN_FONT_FACTOR, 1.0  # bisection on k: the height at k shrinks with k; below the floor, overflow
    for _ in range(14):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if wrapped(mid)[1] <= room else (lo, mid)
    return wrapped(lo)[0], lo


def page_summary(r: ReportInputs) -> Figure:
    """Page: the answer first, in words and one table."""
    rec = r.prepared.record
    fig, ax = figure(f"friction-uq report: {rec.campaign} {rec.test_id} (sample {rec.apparatus.sample.material})")
    ax.axis("off")
    # wrapped here, not by matplotlib (whose wrap=True measures the text word by word); the lines shrink
    # together where they would run into the table below them
    first = "\n".join(textwrap.wrap(quote_line(stationary_quoted(r), r.diagnosis, len(r.warnings), hoop=r.samples.hoop,
                                              both=None if r.hoop_or_prior is None else r.hoop_or_prior.medians), 100))
    ax.text(0.0, 1.0, first, fontsize=13, va="top", transform=ax.transAxes, weight="bold",
            color="firebrick" if r.warnings else "black")
    _draw_lines(fig, ax, _summary_lines(r), below=first.count("\n") + 1)
    # one monospace text block: a matplotlib table draws every cell as its own text and frame
    ax.text(0.0, 0.05, _summary_table(r), fontsize=10, family="monospace", va="bottom", transform=ax.transAxes,
            bbox={"facecolor": "white", "edgecolor": "0.6", "pad": 6})
    prov = (f"record {rec.path} (sha256 {rec.sha256[:12]}), priors {r.samples.prior_path}, "
            f"seed {r.samples.seed}, friction-uq {r.version}")
    ax.text(0.0, 0.0, prov, fontsize=8, transform=ax.transAxes)
    ax.text(0.875, SUMMARY_TABLE_TOP - 0.02, _contents(r), fontsize=8, va="top", transform=ax.transAxes,
            family="monospace")
    return fig


def _summary_lines(r: ReportInputs) -> list[str]:
    """The summary page's sentences under the headline: warnings first, then the stationary analysis, nu and
    kappa, the window, the lab's estimate, convergence, the checks and the diagnosis."""
    s = r.summary
    f, nu = s["f"], s["nu"]
    named = None if r.diagnosis is None else outcome_headline(r.diagnosis)  # the JSON's f (the f to quote)
    stationary = "The stationary analysis: "
    if named is None and r.hoop_or_prior is not None:  # the first line holds this reading and the prior's nu's
        stationary = "The stationary analysis with the hoop gauge (one of the two readings the first line holds): "
    hoop = "" if r.hoop_or_prior is None else " with the hoop gauge"  # the first line also holds the prior's nu's
    if named is not None and r.diagnosis.named_causes:
        stationary = (f"The stationary analysis{hoop} without the named causes (page {whole_record_page(r) + 2} for "
                      "them): ")
    elif named is not None:  # nothing named: a mixture of the candidates (and, from run, of this analysis)
        share = "half" if r.diagnosis.f_prior_nu is None else "a quarter"
        half = f"{share} the draws of the f to quote; " if STATIONARY in r.diagnosis.mixture_weights else ""
        stationary = (f"The stationary analysis{hoop} ({half}page {whole_record_page(r) + 2} for the candidates "
                      "that diagnose could not tell apart): ")
    lines = [f"WARNING: {w}" for w in r.warnings] + [
        stationary + f"f = {f.q50:.4f}, 90 % credible interval [{f.q05:.4f}, {f.q95:.4f}] "
        f"(posterior mean {f.mean:.4f}, sd {f.sd:.4f}; given the output bars' header values, whose calibration "
        "the first line includes).",
        f"Poisson ratio nu = {nu.q50:.3f} [{nu.q05:.3f}, {nu.q95:.3f}]; the forces fix only "
        f"kappa = f nu/(1-nu) = {s['kappa'].q50:.4f} [{s['kappa'].q05:.4f}, {s['kappa'].q95:.4f}] (eq. 17).",
        f"{100 * r.nu_share:.0f} % of the variance of f comes from the uncertainty of nu (law of total variance).",
        f"Stationary phase {r.prepared.window.t0 * 1e6:.1f} - {r.prepared.window.t1 * 1e6:.1f} us "
        f"({'automatic' if r.prepared.window.automatic else 'given by hand'}); sliding velocity "
        f"V = {r.V.q50:.2f} m/s, mean wall pressure p_mean = {s['p_mean'].q50 / 1e6:.1f} MPa." + _halves_text(r),
        f"The lab's point estimate (eq. 17 with nu = {r.lab.nu:g}): f = {r.lab.f:.4f}, "
        f"F_eo/F_io = {r.lab.ratio:.4f}, equilibrium error {100 * r.lab.equilibrium_error:+.1f} % (the gauges' noise, "
        f"1 sd: {100 * r.lab.equilibrium_sd:.1f} %).",
        f"Hoop gauge term: {'used' if r.samples.hoop else 'not used'}; the bars' dispersion "
        f"{'corrected' if r.prepared.forces.dispersion else 'not corrected'}. Convergence: "
        f"{'OK' if r.convergence.ok else 'NOT REACHED'} (R-hat max {r.convergence.r_hat_max:.3f}, "
        f"ESS min {min(r.convergence.ess_bulk_min, r.convergence.ess_tail_min):.0f}).",
        f"Posterior predictive check: the observed ratio lies in the 90 % band {100 * r.ppc.coverage:.0f} % of "
        "the window" + (" - the constant-ratio model misses something here (page 8)." if r.ppc.coverage < 0.7 else "."),
    ]
    if r.conflict is not None:
        lines.append(r.conflict.sentence())
    if r.whole_record is not None:
        lines.append("Whole record: " + r.whole_record.decision.sentence(page=whole_record_page(r)))
    if r.diagnosis is not None:
        from ..discrepancy.diagnosis_words import sentence

        lines.append(f"Diagnosis (page {whole_record_page(r) + 2}): " + sentence(r.diagnosis, stationary_quoted(r)))
    return lines


def _draw_lines(fig: Figure, ax, lines: list[str], *, below: int) -> None:
    """The sentences under a headline of ``below`` 13 pt lines, shrunk together to end above the table; warnings
    in red."""
    point = 1.0 / (ax.get_position().height * fig.get_figheight() * 72.0)  # one point, in axes fraction
    line = 10.0 * LINE_SPACING * point  # a 10 pt line
    top = 1.0 - 13.0 * LINE_SPACING * point * below - line
    texts, k = _shrink_to_fit(lines, top - SUMMARY_TABLE_TOP, line)
    y = top
    for line_, text in zip(lines, texts):
        color = "firebrick" if line_.startswith("WARNING") else "black"
        # one text per wrapped line, baselines a fixed step apart: matplotlib spaces a block's lines (and places a
        # text's "top") by the glyphs each line holds, so a line without tall ones ran into the one above it
        for j, row in enumerate(text.split("\n")):
            ax.text(0.0, y - k * (10.0 * point + j * line), row, fontsize=10 * k, va="baseline",
                    transform=ax.transAxes, color=color)
        y -= k * line * (text.count("\n") + 1.5)


def _summary_table(r: ReportInputs) -> str:
    """The posterior summary of every variable, one monospace row each."""
    rows = []
    for name, v in list(r.summary.items()) + [("V", r.V)]:
        unit, scale = UNITS.get(name, ("", 1.0))
        rows.append([name, unit, _fmt(v.mean * scale), _fmt(v.sd * scale), _fmt(v.q05 * scale), _fmt(v.q50 * scale),
                     _fmt(v.q95 * scale), f"{v.r_hat:.4f}" if np.isfinite(v.r_hat) else "-",
                     f"{v.ess_bulk:.0f}" if np.isfinite(v.ess_bulk) else "-"])
    head = ["quantity", "unit", "mean", "sd", "q05", "q50", "q95", "R-hat", "ESS"]
    return "\n".join(f"{c[0]:<10}{c[1]:<5}" + "".join(f"{x:>11}" for x in c[2:]) for c in [head] + rows)


def _contents(r: ReportInputs) -> str:
    """The report's pages, as they are in this one."""
    return ("Pages\n 2 raw gauges\n 3 waves, forces, equilibrium\n 4 window and noise\n"
            " 5 posterior vs prior\n 6 nu -> f\n 7 convergence\n 8 predictive check"
            + ("\n 9 hoop gauge vs model" if r.samples.hoop else "")
            + (f"\n{_span(whole_record_page(r), page_count(r.whole_record))} whole test vs gauges"
               if r.whole_record is not None else "")
            + (f"\n{whole_record_page(r) + 2:2d} mechanisms ranked\n{whole_record_page(r) + 3:2d} extended fit"
               if r.diagnosis is not None else ""))


def _render(builders: list[Callable[[], Figure]]) -> bytes:
    """One PDF of the figures the builders make, one page each, in memory."""
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    buf = io.BytesIO()
    with plt.rc_context(CORE_FONTS), PdfPages(buf) as pdf:
        for build in builders:
            fig = build()
            pdf.savefig(fig)
            plt.close(fig)
    return buf.getvalue()


def render_record_part(prepared: Prepared, whole_record: WholeRecordCheck, *, hoop: bool = True) -> bytes:
    """The whole-record check's pages (from page 10, or 9 without the hoop page: ``hoop``): a run renders them
    on its other core, after the check, while it samples (:func:`render_report` merges them). The record's
    own pages (2-4) are drawn with the posterior's: the check is the longer share of the work, and the two
    cores then finish at about the same time (``benchmarks/bench_run.py``)."""
    from .whole_record_pages import pages_whole_record

    p = prepared
    return _render([lambda fig=fig: fig for fig in pages_whole_record(
        whole_record, test=f"{p.record.campaign} {p.record.test_id}", first_page=first_whole_record_page(hoop))])


def render_posterior_part(r: ReportInputs) -> bytes:
    """Pages 2-4 (the raw gauges, the forces, the window) and 5-8 (and 9, the hoop gauge's, when its term was
    used): everything but the summary, the whole-record check's and the diagnosis's pages (a run renders them
    while it waits for those)."""
    p = r.prepared
    builders: list[Callable[[], Figure]] = [
        lambda: page_raw(p.record),
        lambda: page_forces(p.record, p.forces, p.window),
        lambda: page_window(p.record, p.forces, p.window),
        lambda: page_corner(r.samples, r.datatree),
        lambda: page_propagation(r.samples, r.band, r.sensitivity, r.nu_share, nu_assumed=r.lab.nu),
        lambda: page_convergence(r.samples, r.convergence),
        lambda: page_ppc(r.ppc),
    ]
    if r.samples.hoop:
        builders.append(lambda: page_hoop(r.samples, p.data, p.forces, seed=r.samples.seed, likelihood=r.likelihood))
    return _render(builders)


def render_report(r: ReportInputs, record_part: bytes | None = None, posterior_part: bytes | None = None) -> bytes:
    """The PDF, in memory: summary page (1), pages 2-8, page 9 when the hoop term was used, the
    whole-record pages and, with a diagnosis, its two pages. ``record_part`` and ``posterior_part``: the
    pages of :func:`render_record_part` and :func:`render_posterior_part` for ``r``, rendered already
    (None: rendered here); the summary and the diagnosis pages are rendered here, and all are merged."""
    from pypdf import PdfReader, PdfWriter

    p = r.prepared
    if record_part is None and r.whole_record is not None:
        record_part = render_record_part(p, r.whole_record, hoop=r.samples.hoop)
    if posterior_part is None:
        posterior_part = render_posterior_part(r)
    own = [lambda: page_summary(r)] + [lambda fig=fig: fig for fig in diagnosis_pages(r)]
    summary, *diagnosis = PdfReader(io.BytesIO(_render(own))).pages
    check = PdfReader(io.BytesIO(record_part)).pages if record_part is not None else []
    out = PdfWriter()
    for page in [summary, *PdfReader(io.BytesIO(posterior_part)).pages, *check, *diagnosis]:
        out.add_page(page)
    out.add_metadata({"/Title": f"friction-uq {p.record.campaign} {p.record.test_id}",
                      "/Creator": f"friction-uq {r.version}"})
    buf = io.BytesIO()
    out.write(buf)
    return buf.getvalue()


def _span(first: int, n: int) -> str:
    """' 9', '10', or '10-11': the pages a part of the report takes, for the page list."""
    return f"{first:2d}" if n <= 1 else f"{first}-{first + n - 1}"


def first_whole_record_page(hoop: bool) -> int:
    """PDF page number of the first whole-record page (after page 8, or 9 with the hoop page; the summary is
    page 1)."""
    return 10 if hoop else 9


def whole_record_page(r: ReportInputs) -> int:
    """:func:`first_whole_record_page` of a report's inputs."""
    return first_whole_record_page(r.samples.hoop)


def diagnosis_pages(r: ReportInputs) -> list[Figure]:
    """With a diagnosis, its two pages: the ranking and the extended fit."""
    if r.diagnosis is None:
        return []
    from ..discrepancy.diagnosis_words import sentence
    from .diagnose_pages import page_extended_fit, page_ranking

    test = f"{r.prepared.record.campaign} {r.prepared.record.test_id}"
    n = whole_record_page(r) + 2
    return [page_ranking(r.diagnosis, f_without=r.summary["f"].to_json(),
                         sentence=sentence(r.diagnosis, stationary_quoted(r)), test=f"{n}. {test}", hoop=r.samples.hoop),
            page_extended_fit(r.diagnosis, test=f"{n + 1}. {test}")]


def _halves_text(r: ReportInputs) -> str:
    """kappa's change across the window (the run JSON's ``window_halves``), in words; empty when there is none."""
    h = r.halves
    if h is None:
        return ""
    return (f" From the window's first half to its second the sample slides {h.slip[0] * 1e3:.2f} to "
            f"{h.slip[1] * 1e3:.2f} mm and kappa changes by {100 * np.expm1(h.log_kappa_change):+.1f} % "
            f"(sd {100 * h.sd:.1f} %), which a campaign reads to tell a slip law from a speed law.")


def write_report(r: ReportInputs, path: str | os.PathLike[str]) -> Path:
    """Write the PDF of :func:`render_report` atomically."""
    return write_bytes(path, render_report(r))
