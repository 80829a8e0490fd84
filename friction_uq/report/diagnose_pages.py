"""Pages of ``diagnose``: the mechanisms ranked by dELPD, and the named mechanism's fit.

Page A: every round's dELPD with +-2 SE bars for every mechanism of the catalogue against that
round's reference model (the decisive threshold drawn, the named cause in bold, the colours in the
legend), the rule, the causes named, and f under the baseline and the extended model.
Page B: per gauge, the residual of the baseline and of the extended model over the whole record
(standardised by the noise), with the named mechanism's parameters.
"""

from __future__ import annotations

import textwrap
from types import SimpleNamespace

import numpy as np
from matplotlib.figure import Figure

from ..discrepancy.diagnosis import Diagnosis
from ..discrepancy.diagnosis_words import hoop_prior_words
from ..stats import RULE
from ..discrepancy.outcome import kappa_draws
from ..discrepancy.verdict import FORM_SHIFT
from ..discrepancy.whole_record import CHANNEL_LABELS
from .style import figure


#: The ranking page's text column: its margins from the page's right edge and foot, its gap from the ranking and its
#: least width should the ranking reach that far right (fractions of the page), and the spacing of its lines (in font
#: sizes).
RIGHT_MARGIN = 0.02
BOTTOM_MARGIN = 0.03
COLUMN_GAP = 0.02
MIN_COLUMN = 0.25
LINE_SPACING = 1.2
#: Points from the ranking's lower edge to its legend's top: below the tick labels and the two-line axis label.
LEGEND_DROP = 44.0


def _ranking_axes(ax, dg: Diagnosis) -> None:
    """Every round's candidates, each against its round's reference model (the baseline, then the baseline
    with the causes named before), the named cause's label in bold; what the colours mean in the legend."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.transforms import ScaledTranslation

    rows, labels, named, seps, colours = [], [], [], [], []
    for k, rnd in enumerate(dg.rounds):
        cause = dg.causes[k] if k < len(dg.causes) and dg.causes[k] in dg.named_causes else None
        judged = {c.label: c for c in dg.verdicts[k].candidates} if k < len(dg.verdicts) else {}
        for r in rnd:
            c = judged.get(r.fit.label)
            rows.append(r)
            labels.append(f"{k + 1}: {r.fit.variants[-1].label}" + (f" (w {c.weight:.2f})" if c is not None else ""))
            named.append(cause is not None and r.fit.variants[-1] is cause)
            decisive = c.decisive if c is not None else r.decisive
            colours.append("tab:red" if (c.passes if c is not None else decisive) else
                           "tab:orange" if decisive else "0.6")
        tried = dg.pair_tried
        if tried is not None and tried.round == k + 1:  # the round's pair fitted together, against its reference
            d, se, dt, st = tried.evidence.against["reference"]
            rows.append(SimpleNamespace(delpd=d, se=se))
            labels.append(f"{k + 1}: {' + '.join(tried.causes)} together"
                          + ("" if tried.refused is None else " (not named)"))
            named.append(tried.refused is None)
            colours.append("tab:red" if RULE.decisive(dt, st) else "tab:orange" if RULE.decisive(d, se) else "0.6")
        seps.append(len(rows))
    y = np.arange(len(rows))[::-1]
    d = np.array([r.delpd for r in rows])
    se = np.array([r.se for r in rows])
    shown = np.sign(d) * np.log10(1.0 + np.abs(d))
    lo = np.sign(d - 2 * se) * np.log10(1.0 + np.abs(d - 2 * se))
    hi = np.sign(d + 2 * se) * np.log10(1.0 + np.abs(d + 2 * se))
    ax.barh(y, shown, color=colours)
    ax.errorbar(shown, y, xerr=[shown - lo, hi - shown], fmt="none", ecolor="k", lw=0.8)
    ax.axvline(np.log10(1.0 + RULE.min_delpd), color="tab:blue", ls="--", lw=0.8)
    ax.axvline(0.0, color="k", lw=0.6)
    for s in seps[:-1]:
        ax.axhline(len(rows) - s - 0.5, color="0.3", lw=0.6)
    ax.set_yticks(y, labels, fontsize=7 if len(rows) > 16 else 8)
    for t, bold in zip(ax.get_yticklabels(), named):
        t.set_fontweight("bold" if bold else "normal")
    ax.set_xlabel("dELPD over the round's reference model, sign(d) log10(1 + |d|), bars +- 2 SE;\n"
                  "left of 0: predicts the record worse than the reference (its parameters cost more "
                  "than they explain)", fontsize=8)
    ax.legend([Patch(color="tab:red"), Patch(color="tab:orange"), Patch(color="0.6"),
               Line2D([], [], color="tab:blue", ls="--")],
              ["decisive with the 5 % of blocks most in its favour left out: spread over the record, whatever\n"
               "its whole-record bar (bold: the cause named in that round)",
               "decisive, but carried by a few blocks (5 % left out: not decisive)", "not decisive", "dELPD = 4"],
              # below the axes and their two-line label, a fixed distance in points whatever the axes' height:
              # inside, it covered the last round's lowest bars (B-02's fourth round)
              loc="upper left", bbox_to_anchor=(0.0, 0.0), fontsize=7, ncols=2, title_fontsize=7,
              bbox_transform=ax.transAxes + ScaledTranslation(0.0, -LEGEND_DROP / 72.0, ax.figure.dpi_scale_trans),
              title="w: stacking weight, the share of the record's predictions the model carries against the "
                    "round's reference and the other mechanisms", alignment="left")
    ax.set_title("rounds 1, 2, ...: each mechanism added to the model of the round before", fontsize=9)


def page_ranking(dg: Diagnosis, *, f_without: dict[str, float], sentence: str, test: str, hoop: bool) -> Figure:
    """The ranking of the first round and, beside it, the verdict and the posteriors; ``hoop``: the stationary
    analysis used the hoop gauge."""
    fig, axes = figure(f"{test}: what the baseline misses, mechanism by mechanism", nrows=1, ncols=2,
                       gridspec_kw={"width_ratios": [3, 2]})
    _ranking_axes(axes[0], dg)
    ax2 = axes[1]
    ax2.axis("off")
    fx = dg.final.f_summary()
    fb = dg.baseline.f_summary()
    lines = [sentence, "",
             "The posteriors below are given the output bars' header values; the f to quote (the sentence's, and the "
             "first line of page 1) also carries the bars' calibration"
             + (", and holds the stationary f from nu's prior alone for half (the hoop gauge and the prior file "
                "disagree)." if dg.f_prior_nu is not None else "."),
             f"f, stationary phase (eq. 17{' + hoop' if hoop else '; the hoop gauge left out'}): "
             f"{f_without['q50']:.4f} [{f_without['q05']:.4f}, {f_without['q95']:.4f}]",
             f"f, baseline over the whole record: {fb['q50']:.4f} [{fb['q05']:.4f}, {fb['q95']:.4f}] "
             f"(nu {np.median(dg.baseline.fit.draws['nu']):.3f}, kappa {np.median(kappa_draws(dg.baseline)):.4f})",
             f"f, model '{dg.final.label}': {fx['q50']:.4f} [{fx['q05']:.4f}, {fx['q95']:.4f}] "
             f"(nu {np.median(dg.final.fit.draws['nu']):.3f}, kappa {np.median(kappa_draws(dg.final)):.4f})",
             *_nu_source_line(dg),
             *([f"hoop gauge gain (final model, most probable under {hoop_prior_words(dg)}): {dg.final.hoop_gain:.3f}"]
               if "tube_hoop" in dg.final.predicted else []), ""]
    for v in dg.causes:
        turn = "" if v in dg.named_causes else (" (in the model within the check's tolerance, not named)"
                                                if v.label in dg.within_tolerance else
                                                " (a candidate fitted in turn, not named)")
        lines.append(f"{v.mechanism.name}{' (' + v.channel + ')' if v.channel else ''}{turn}: {v.mechanism.meaning}")
        for p in v.mechanism.parameters:
            x = dg.final.fit.draws[p.name]
            q = np.quantile(x, [0.05, 0.5, 0.95])
            lines.append(f"   {p.name} = {q[1]:.4g} [{q[0]:.4g}, {q[2]:.4g}] {p.unit}: {p.meaning}")
    m0 = dg.misfits[0] if dg.misfits else None
    if dg.mixture_f is not None:
        fm = np.quantile(dg.mixture_f, [0.05, 0.5, 0.95])
        lines.insert(7, f"f, stacking mixture ({', '.join(f'{k} {w:.2f}' for k, w in dg.mixture_weights.items())}): "
                        f"{fm[1]:.4f} [{fm[0]:.4f}, {fm[2]:.4f}] (given the headers; the sentence's f to quote adds the bars' calibration"
                        f"{' and the stationary f from the prior nu for half' if dg.f_prior_nu is not None else ''})")
    lines += ["", "Rule: a cause is named only of a misfit the whole-record check found, when its dELPD over the "
                  "round's reference is > 4 and > 2 SE with the 5 % of blocks most in its favour left out (the "
                  "whole record's sum is larger still), and rules out every other mechanism (by the same margin, "
                  "or the other is > 4 behind without "
                  "those blocks and carries < 0.1 of the weight); others not ruled out make candidates, a misfit "
                  "none explains is unexplained (f then from the stacking mixture, "
                  "half of it the stationary analysis' f when nothing is named); "
                  "after a named cause the search goes on with it in the model; a candidate fitted in turn is "
                  "named when, with the later causes in the model, it rules out so each rival of its round left "
                  "open and the model without it, which the whole-record check must then flag (where no rival was "
                  "left open, by the rule alone); else it is superfluous and not named. A later round whose "
                  "reference the check no longer flags names an entry of the measurement chain only if it moves f "
                  f"by more than {100 * FORM_SHIFT:.1f} % (the whole-record models' form); else it stays in the "
                  "model, not named." + (" Two mechanisms neither of which passes alone in an unexplained first "
                                         "round are named together when, fitted together, they pass against the "
                                         "round's reference and each alone, rule out every other mechanism, and the "
                                         "next round names the second on top of the first."
                                         if dg.pair_tried is not None else "")]
    if m0 is not None:
        lines.append(f"Baseline misfit statistic {m0.statistic:.1f} (threshold {m0.threshold:g}): "
                     f"{'detected' if m0.detected else 'not detected'}.")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    column_text(fig, axes[0], lines)
    return fig


def column_text(fig: Figure, beside, lines: list[str], *, size: float = 8.0, smallest: float = 5.5) -> None:
    """``lines`` wrapped into the column from just right of the axes ``beside`` to the page's right margin and from
    their top to the page's foot (or to their label's and legend's top where those reach under it), at ``size`` pt
    or the largest size down to ``smallest`` at which they fit. Measured once the page is laid out: the ranking's
    tick labels decide where the column starts (a fixed count of characters ran past the page's edge)."""
    fig.draw_without_rendering()  # the label and legend where the layout put them, not where they were drawn last
    renderer = fig.canvas.get_renderer()
    pos = beside.get_position()
    left = min(pos.x1 + COLUMN_GAP, 1.0 - RIGHT_MARGIN - MIN_COLUMN)
    width = (1.0 - RIGHT_MARGIN - left) * fig.bbox.width
    foot = BOTTOM_MARGIN * fig.bbox.height
    for art in (beside.xaxis.label, beside.get_legend()):
        box = art.get_window_extent(renderer) if art is not None else None
        if box is not None and box.x1 > left * fig.bbox.width:
            foot = max(foot, box.y1 + COLUMN_GAP * fig.bbox.height)
    height = pos.y1 * fig.bbox.height - foot
    sample = " ".join(" ".join(lines).split())[:600] or "x"
    while True:
        probe = fig.text(0.0, 0.0, sample, fontsize=size)
        per_char = max(probe.get_window_extent(renderer).width / len(sample), 1e-3)
        probe.remove()
        wrap = max(20, int(0.95 * width / per_char))
        text = "\n".join(textwrap.fill(line, wrap) if line else line for line in lines)
        if (text.count("\n") + 1) * LINE_SPACING * size * fig.dpi / 72.0 <= height or size <= smallest:
            break
        size = max(smallest, size - 0.25)
    fig.text(left, pos.y1, text, va="top", fontsize=size, linespacing=LINE_SPACING)


def page_extended_fit(dg: Diagnosis, *, test: str) -> Figure:
    a, b = dg.baseline_comparison, dg.final_comparison
    chans = [c for c in CHANNEL_LABELS if c in a.spans]
    alone = not dg.final.variants  # nothing named: the baseline's residuals, not compared with themselves
    what = ("residuals of the baseline (no cause named: no extended model to compare)" if alone else
            f"residuals of the baseline and of '{dg.final.label}'")
    fig, axes = figure(f"{test}: {what}", nrows=len(chans), ncols=1, sharex=False)
    axes = np.atleast_1d(axes)
    for ax, ch in zip(axes, chans):
        i0, i3 = a.spans[ch]
        _, iw0, iw1, _ = a.phase_bounds[ch]
        t = a.time[i0:i3] * 1e6
        ax.axvspan(a.time[iw0] * 1e6, a.time[max(iw1 - 1, iw0)] * 1e6, color="0.88", zorder=0)
        ax.plot(t, a.standardised(ch)[i0:i3], color="0.5", lw=0.5, label="baseline", rasterized=True)
        if not alone:
            ax.plot(t, b.standardised(ch)[i0:i3], color="tab:red", lw=0.5, label=dg.final.label, rasterized=True)
        ax.axhline(2, color="tab:blue", ls="--", lw=0.6)
        ax.axhline(-2, color="tab:blue", ls="--", lw=0.6)
        rms = dg.rms.get(ch, {})
        txt = "; ".join(f"{ph} {bf:.2f} -> {af:.2f}" for ph, (bf, af) in rms.items())
        ax.set_title(f"{CHANNEL_LABELS[ch]}: RMS of residual / noise sd, {txt}", fontsize=8)
        ax.set_ylabel("residual / sd")
        lim = max(4.0, float(np.nanpercentile(np.abs(a.standardised(ch)[i0:i3]), 99.5)) * 1.1)
        ax.set_ylim(-lim, lim)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time on the record (us)")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return fig


def _nu_source_line(dg) -> list[str]:
    """Where the models' nu comes from, and what the whole record alone reads (friction_uq.discrepancy.nu_cut)."""
    if dg.final.cut is None:
        return []
    return [f"nu from the gauges' levels over the stationary window under this model; the whole record, its dynamics "
            f"included, would read nu {dg.final.fit.mode['nu']:.3f}"]
