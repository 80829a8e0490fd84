"""Pages: the whole test simulated with the posterior against every gauge (the paper's figures 11-14).

Per channel: the measured gauge and the simulated one (median and 90 % band of the posterior
draws) over the compared span, and below it the residual over the residual noise's standard
deviation with the +-2 band; the stationary window (carried to the gauge) is shaded.
"""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure

from ..discrepancy.check import WholeRecordCheck
from ..discrepancy.misfit import THRESHOLD
from ..discrepancy.whole_record import CHANNEL_LABELS
from .style import figure


def _channel(ax_sig, ax_res, chk: WholeRecordCheck, ch: str) -> None:
    wr = chk.comparison
    i0, i3 = wr.spans[ch]
    _, iw0, iw1, _ = wr.phase_bounds[ch]
    t = wr.time[i0:i3] * 1e6
    meas = wr.measured[ch][i0:i3] * 1e6
    draws = wr.predicted[ch][:, i0:i3] * 1e6
    lo, med, hi = np.quantile(draws, [0.05, 0.5, 0.95], axis=0)
    tw0, tw1 = wr.time[iw0] * 1e6, wr.time[max(iw1 - 1, iw0)] * 1e6
    for ax in (ax_sig, ax_res):
        ax.axvspan(tw0, tw1, color="0.85", zorder=0)
    ax_sig.plot(t, meas, color="k", lw=0.6, label="measured")
    ax_sig.fill_between(t, lo, hi, color="tab:orange", alpha=0.4, lw=0, label="simulated, 90 % band")
    ax_sig.plot(t, med, color="tab:red", lw=0.9, label="simulated, median")
    ax_sig.set_ylabel("strain (microstrain,\ncompression +)")
    ax_sig.set_title(CHANNEL_LABELS[ch])
    z = wr.standardised(ch)[i0:i3]
    ax_res.plot(t, z, color="k", lw=0.4, rasterized=True)
    ax_res.axhline(2, color="tab:blue", lw=0.8, ls="--")
    ax_res.axhline(-2, color="tab:blue", lw=0.8, ls="--")
    worst = [c for c in chk.decision.cells if c.channel == ch]
    text = ", ".join(f"{c.phase} {c.statistic:.1f}" + ("" if c.threshold == THRESHOLD else f" (threshold {c.threshold:g})")
                     for c in worst)
    ax_res.set_title(f"residual / noise sd; misfit statistic, threshold {THRESHOLD:g}: {text}", fontsize=8)
    ax_res.set_ylabel("standardised")
    ax_res.set_xlabel("time on the record (us)")
    lim = max(4.0, float(np.nanpercentile(np.abs(z), 99.5)) * 1.1)
    ax_res.set_ylim(-lim, lim)


def _drawn(chk: WholeRecordCheck) -> list[str]:
    """The channels the pages draw, in order, two a page."""
    return [c for c in CHANNEL_LABELS if c in chk.comparison.spans]


def page_count(chk: WholeRecordCheck) -> int:
    """How many pages :func:`pages_whole_record` draws."""
    return (len(_drawn(chk)) + 1) // 2


def pages_whole_record(chk: WholeRecordCheck, *, test: str, first_page: int | None = None) -> list[Figure]:
    """Two pages, two channels each (reflected and internal; external and hoop); ``first_page``: the PDF page
    number of the first, written before the titles."""
    chans = _drawn(chk)
    out = []
    for k in range(0, len(chans), 2):
        pair = chans[k:k + 2]
        number = "" if first_page is None else f"{first_page + k // 2}. "
        fig, axes = figure(f"{number}{test}: the whole test simulated with the posterior, against the gauges "
                           f"({k // 2 + 1}/{(len(chans) + 1) // 2})", nrows=2, ncols=2,
                           gridspec_kw={"height_ratios": [2, 1]})
        for j in range(2):
            if j < len(pair):
                _channel(axes[0, j], axes[1, j], chk, pair[j])
            else:
                axes[0, j].axis("off")
                axes[1, j].axis("off")
        axes[0, 0].legend(loc="best")
        fig.text(0.01, 0.01, textwrap.fill(chk.decision.sentence(), 170), fontsize=9)
        # fixed margins: tight_layout draws the page once more to measure it (half the page's time)
        fig.subplots_adjust(left=0.08, right=0.98, bottom=0.1, top=0.9, wspace=0.22, hspace=0.3)
        out.append(fig)
    return out
