"""The campaign report: summary, forest plot with the pooled band, f against V and p with the law's
band, the law comparison and the flag table. Draws what the campaign analysis computed."""

from __future__ import annotations

import io
import os
import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import write_bytes
from .style import RC, figure

#: What is drawn is friction_uq.campaign.analysis.CampaignAnalysis, read by its attributes: the report sits below the campaign
#: stage and does not import it.
CampaignAnalysis = Any


def _text_page(title: str, lines: list[str]):
    fig, ax = figure(title)
    ax.axis("off")
    wrapped = []
    for line in lines:
        wrapped.extend(textwrap.wrap(line, 125, subsequent_indent="    ") or [""])
    ax.text(0.0, 1.0, "\n".join(wrapped[:60]), va="top", ha="left", family="monospace", fontsize=8,
            transform=ax.transAxes)
    return fig


def _forest(ca: CampaignAnalysis):
    fig, axes = figure("Per-test posteriors of the stationary analysis (90 % intervals) and the pooled population",
                       nrows=1, ncols=2)
    colors = {s: f"C{k}" for k, s in enumerate(sorted({t.setup for t in ca.tests}))}
    for ax, name in zip(axes, ("f", "kappa")):
        y = np.arange(len(ca.tests))[::-1]
        for yy, t in zip(y, ca.tests):
            d = getattr(t, name)
            q = np.quantile(d, [0.05, 0.5, 0.95])
            ax.plot(q[[0, 2]], [yy, yy], color=colors[t.setup], lw=2)
            ax.plot(q[1], yy, "o", color=colors[t.setup])
        p = ca.pooled.get(name)
        if p is not None and not p.refused:
            ax.axvspan(p.mu["q05"], p.mu["q95"], color="k", alpha=0.15, label="population mean (90 %)")
            ax.axvline(p.mu["q50"] - p.sigma["q50"], color="k", ls=":", lw=1)
            ax.axvline(p.mu["q50"] + p.sigma["q50"], color="k", ls=":", lw=1, label="mean +- scatter")
            ax.set_title(f"{name}: mean {p.mu['q50']:.4g}, scatter {p.sigma['q50']:.2g}", loc="left")
        elif p is not None:
            ax.set_title(f"{name}: pooling refused (see summary)", loc="left")
        ax.set_yticks(y, [t.label for t in ca.tests])
        ax.set_xlabel(name)
        ax.legend(loc="lower right", fontsize=8)
    return fig


def _law_page(ca: CampaignAnalysis):
    d = ca.law_data
    name = ca.chosen or str(ca.ranking[0]["model"])
    nu = ca.nu[0]
    head = f"f at the campaign's nu = {nu:.3f}" if d.basis == "kappa" else d.meaning
    fig, axes = figure(f"{head} against V and p (median, 90 %); band: {name} (90 %)", nrows=1, ncols=2)
    setups = sorted(set(d.setups))
    for k, s in enumerate(setups):
        on = np.array([x == s for x in d.setups])
        # each test's median and 90 % interval from its draws (a normal of mean and sd would misdraw a skewed one)
        q = (np.array([np.quantile(x, [0.05, 0.5, 0.95]) for x, o in zip(d.draws, on) if o]).T if d.draws is not None
             else d.kappa[on] + np.outer([-1.645, 0.0, 1.645], d.kappa_sd[on])) * d.to_f(nu)
        f, ferr = q[1], np.abs(q[[0, 2]] - q[1])
        # the set-up's (V, p) line: p rises with V through the striker speed
        coef = np.polyfit(d.V[on], d.p[on], 1) if on.sum() > 1 else np.array([0.0, d.p[on][0]])
        vv = np.linspace(d.V[on].min() * 0.9, d.V[on].max() * 1.1, 60)
        pp = np.polyval(coef, vv)
        band = np.quantile(ca.f_curve(name, vv, pp, s), [0.05, 0.5, 0.95], axis=0)
        for ax, x, xx, xs in ((axes[0], d.V[on], vv, 1.0), (axes[1], d.p[on], pp, 1e-6)):
            ax.errorbar(x * xs, f, yerr=ferr, fmt="o", color=f"C{k}", capsize=3, label=f"set-up {s}")
            ax.fill_between(xx * xs, band[0], band[2], color=f"C{k}", alpha=0.2)
            ax.plot(xx * xs, band[1], color=f"C{k}", lw=1)
    axes[0].set_xlabel("sliding velocity V (m/s)")
    axes[1].set_xlabel("mean wall pressure p_mean (MPa)")
    for ax in axes:
        ax.set_ylabel("f = kappa (1-nu)/nu" if d.basis == "kappa" else d.meaning)
        ax.legend(fontsize=8)
    return fig


def _comparison_page(ca: CampaignAnalysis):
    fig, ax = figure("Friction laws: leave-one-test-out ELPD (higher is better), +- SE")
    r = ca.ranking
    y = np.arange(len(r))[::-1]
    ax.errorbar([m["elpd"] for m in r], y, xerr=[m["se"] for m in r], fmt="o", color="k", capsize=3,
                label="ELPD +- SE")
    top = r[0]["elpd"]
    ax.errorbar([top - m["d_elpd"] for m in r[1:]], y[1:] - 0.2, xerr=[m["d_se"] for m in r[1:]], fmt="^",
                color="C3", capsize=3, label="difference to the top +- its SE")
    ax.set_yticks(y, [f"{m['model']}  (dELPD {m['d_elpd']:.1f} +- {m['d_se']:.1f})" for m in r])
    ax.set_xlabel("ELPD (leave one test out)")
    ax.legend(fontsize=8)
    fig.subplots_adjust(left=0.35)
    return fig


def write_campaign_report(ca: CampaignAnalysis, doc: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write the campaign PDF atomically; pages after the summary only when there is something to draw."""
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    out = Path(path)
    records = [f"{Path(r['path']).name:<22} {r['campaign']!s:<6} {r['test_id']!s:<8} {r['status']:<8} "
               f"{r['message'] or ''}" for r in doc["records"]]
    with plt.rc_context(RC):
        pages = [_text_page("Campaign summary", doc["statements"] + [""] + records)]
        if ca.tests:
            pages.append(_forest(ca))
        if ca.law_data is not None and ca.ranking:
            pages += [_law_page(ca), _comparison_page(ca)]
            flag_lines = [f"{'what':<12} {'on':<6} {'offset / gap':<28} {'dELPD':>7} {'SE':>5}"]
            for f in ca.flagged:
                if "setup" in f:
                    o = f["offset"]
                    flag_lines.append(f"set-up {f['setup']:<5} {f.get('basis', ca.law_data.basis):<6} "
                                      f"{o['q50'] * 100:+6.1f} % [{o['q05'] * 100:+.1f}, {o['q95'] * 100:+.1f}]"
                                      f"{'':<6} {f['d_elpd']:>7.1f} {f['d_se']:>5.1f}")
                    flag_lines += ["    " + str(f[k]) for k in ("note", "note_diagnosed", "note_causes") if k in f]
                    flag_lines += ["    " + str(c) for c in f["causes"].values()]
                else:
                    flag_lines.append(f"test {f['test']:<7} {f['below_median_by']:>6.1f} below median")
            if not ca.flagged:
                flag_lines.append("nothing flagged: every set-up and test follows the shared law")
            pages.append(_text_page("Flags: set-ups and tests off the shared law", flag_lines))
        buf = io.BytesIO()  # in memory, then written at once (a disk that fills mid-file is one OSError)
        with PdfPages(buf) as pdf:
            for fig in pages:
                pdf.savefig(fig)
                plt.close(fig)
        write_bytes(out, buf.getvalue())
    return out
