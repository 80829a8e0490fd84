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

#: What is drawn is friction_uq.campaigns.analysis.CampaignAnalysis, read by its attributes: the report sits below the campaign
#: stage and does not import it.
CampaignAnalysis = Any


def _wrapped(lines: list[str], width: int = 150) -> str:
    return "\n".join(textwrap.fill(line, width) for line in lines)


def _summary_page(ca: CampaignAnalysis, doc: dict[str, Any]):
    """The verdict in sentences, then every test in a table: set-up, test, V, p, f with its interval, the count of
    its run's warnings, causes."""
    fig, ax = figure(f"Campaign: {doc['counts']['done'] + doc['counts']['skipped']} tests analysed, "
                     f"{doc['counts']['failed']} refused")
    ax.axis("off")
    ax.text(0.0, 1.0, _wrapped(doc["statements"][:12]), va="top", ha="left", fontsize=9, transform=ax.transAxes)
    causes = {(r["campaign"], r["test_id"]): r.get("causes") for r in doc["records"]}
    rows = []
    for t in ca.tests:
        f = t.f_model if t.f_model is not None else t.f
        q = np.quantile(f, [0.05, 0.5, 0.95])
        named = causes.get((t.setup, t.label.split(" ")[-1]))
        rows.append([t.setup, t.label.split(" ")[-1], f"{t.V['mean']:.2f}", f"{np.median(t.p_mean) * 1e-6:.0f}",
                     f"{q[1]:.4f} [{q[0]:.4f}, {q[2]:.4f}]", str(len(t.warnings)), "not diagnosed" if named is None
                     else (", ".join(named) or "none")])
    for r in doc["records"]:
        if r["status"] == "failed":
            rows.append([str(r["campaign"] or "-"), str(r["test_id"] or "-"), "", "", "refused", "",
                         textwrap.shorten(str(r["message"] or ""), 60)])
    if rows:
        head = ["set-up", "test", "V (m/s)", "p_mean (MPa)", "f, median [90 %]", "warnings", "causes named (diagnose)"]
        tab = ax.table(cellText=rows[:28], colLabels=head, loc="lower center", cellLoc="left",
                       colWidths=[0.07, 0.1, 0.08, 0.1, 0.2, 0.08, 0.37],
                       bbox=[0.0, 0.0, 1.0, min(0.55, 0.03 * (len(rows) + 1))])
        tab.auto_set_font_size(False)
        tab.set_fontsize(8)
    fig.text(0.01, 0.01, _wrapped(["f: under each test's diagnosed model where diagnose ran, else the stationary "
                                   "analysis (eq. 17, with the hoop gauge where it was used), given the bars' header "
                                   "values (the laws carry each set-up's calibration offset); each test's f to "
                                   "quote, with its bars' calibration, is in its own JSON."], width=170),
             fontsize=8, va="bottom")
    return fig


def _forest(ca: CampaignAnalysis):
    """Each test's 90 % interval and the pooled population, f and kappa. With a diagnosed pooled f (``basis``
    "diagnosed") the f panel draws f under each test's diagnosed model, and the stationary f's medians and
    pooled mean beside it in grey, each labelled."""
    pf = ca.pooled.get("f")
    diagnosed = pf is not None and pf.basis == "diagnosed"
    what = "f under the diagnosed models" if diagnosed else "the stationary analysis"
    fig, axes = figure(f"Per-test 90 % intervals and the pooled population: {what}", nrows=1, ncols=2)
    colors = {s: f"C{k}" for k, s in enumerate(sorted({t.setup for t in ca.tests}))}
    for ax, name in zip(axes, ("f", "kappa")):
        y = np.arange(len(ca.tests))[::-1]
        use_model = diagnosed and name == "f"
        for yy, t in zip(y, ca.tests):
            d = t.f_model if use_model else getattr(t, name)
            q = np.quantile(d, [0.05, 0.5, 0.95])
            ax.plot(q[[0, 2]], [yy, yy], color=colors[t.setup], lw=2)
            ax.plot(q[1], yy, "o", color=colors[t.setup])
            if use_model:
                ax.plot(np.median(t.f), yy - 0.25, "x", color="0.5",
                        label="stationary analysis, median" if yy == y[0] else None)
        p = ca.pooled.get(name)
        basis = "diagnosed models" if p is not None and p.basis == "diagnosed" else "stationary analysis"
        if p is not None and not p.refused:
            ax.axvspan(p.mu["q05"], p.mu["q95"], color="k", alpha=0.15, label=f"population mean (90 %), {basis}")
            ax.axvline(p.mu["q50"] - p.sigma["q50"], color="k", ls=":", lw=1)
            ax.axvline(p.mu["q50"] + p.sigma["q50"], color="k", ls=":", lw=1, label="mean +- scatter")
            ax.set_title(f"{name} ({basis}): mean {p.mu['q50']:.4g}, scatter {p.sigma['q50']:.2g}", loc="left")
        elif p is not None:
            ax.set_title(f"{name} ({basis}): pooling refused (see summary)", loc="left")
        ps = ca.pooled_stationary.get(name) if use_model else None
        if ps is not None and not ps.refused:
            ax.axvline(ps.mu["q50"], color="0.5", ls="--", lw=1,
                       label=f"population mean, stationary analysis ({ps.mu['q50']:.4g})")
        ax.set_yticks(y, [t.label for t in ca.tests])
        ax.set_xlabel("f under the diagnosed model" if use_model else name)
        ax.legend(loc="best", fontsize=8)
    return fig


def _law_page(ca: CampaignAnalysis):
    d = ca.law_data
    name = ca.chosen or ca.law_models[max(ca.weights, key=ca.weights.get)]
    nu = ca.nu[0]
    in_slip = ca.fits[name].model.law == "slip" and d.slip is not None  # the band along the slip, not along V
    head = f"f at the campaign's nu = {nu:.3f}" if d.basis == "kappa" else d.meaning
    fig, axes = figure(f"{head} against {'the slip S' if in_slip else 'V'} and p (median, 90 %); band: {name} (90 %)",
                       nrows=1, ncols=2)
    setups = sorted(set(d.setups))
    for k, s in enumerate(setups):
        on = np.array([x == s for x in d.setups])
        # each test's median and 90 % interval from its draws (a normal of mean and sd would misdraw a skewed one)
        q = (np.array([np.quantile(x, [0.05, 0.5, 0.95]) for x, o in zip(d.draws, on) if o]).T if d.draws is not None
             else d.kappa[on] + np.outer([-1.645, 0.0, 1.645], d.kappa_sd[on])) * d.to_f(nu)
        f, ferr = q[1], np.abs(q[[0, 2]] - q[1])
        # the set-up's (V, p) line: p rises with V through the striker speed
        coef = np.polyfit(d.V[on], d.p[on], 1) if on.sum() > 1 else np.array([0.0, d.p[on][0]])
        if in_slip:  # the slip law is in S alone: its band along the tested slips, on the first panel only
            ss = np.linspace(d.slip[on].min() * 0.9, d.slip[on].max() * 1.1, 60)
            band = np.quantile(ca.f_curve(name, ss, ss, s, slip=ss), [0.05, 0.5, 0.95], axis=0)
            lines = ((axes[0], d.slip[on], ss, 1e3, band), (axes[1], d.p[on], None, 1e-6, None))
        else:
            vv = np.linspace(d.V[on].min() * 0.9, d.V[on].max() * 1.1, 60)
            pp = np.polyval(coef, vv)
            band = np.quantile(ca.f_curve(name, vv, pp, s), [0.05, 0.5, 0.95], axis=0)
            lines = ((axes[0], d.V[on], vv, 1.0, band), (axes[1], d.p[on], pp, 1e-6, band))
        for ax, x, xx, xs, b in lines:
            ax.errorbar(x * xs, f, yerr=ferr, fmt="o", color=f"C{k}", capsize=3, label=f"set-up {s}")
            if b is not None:
                ax.fill_between(xx * xs, b[0], b[2], color=f"C{k}", alpha=0.2)
                ax.plot(xx * xs, b[1], color=f"C{k}", lw=1)
    axes[0].set_xlabel("mean slip over the window S (mm)" if in_slip else "sliding velocity V (m/s)")
    axes[1].set_xlabel("mean wall pressure p_mean (MPa)" + (" (the slip law has no pressure term)" if in_slip else ""))
    for ax in axes:
        ax.set_ylabel("f = kappa (1-nu)/nu" if d.basis == "kappa" else d.meaning)
        ax.legend(fontsize=8)
    return fig


def _comparison_page(ca: CampaignAnalysis, named: list[str]):
    """The laws' stacking weights as bars, each with its dELPD +- SE behind the best, the laws the verdict names
    (``named``: campaign.json's ``friction_law.supported``) in colour; the next-test advice."""
    fig, axes = figure("Friction laws: which the data support (stacking weights) and which test would tell them apart",
                       nrows=1, ncols=2)
    ax = axes[0]
    r = sorted(ca.ranking, key=lambda m: -float(m["weight"]))
    y = np.arange(len(r))[::-1]
    law = [str(m.get("law", m["model"])) for m in r]
    ax.barh(y, [float(m["weight"]) for m in r], color=["C0" if x in named else "0.7" for x in law])
    for yy, x, m in zip(y, law, r):
        if x in named:
            w = float(m["weight"])
            inside = w > 0.85  # the word on the bar, in white, where the bar reaches the axis' end
            ax.text(w - 0.01 if inside else w + 0.01, yy, "named", va="center", ha="right" if inside else "left",
                    fontsize=8, color="white" if inside else "C0")
    ax.set_yticks(y, [f"{x}\n(dELPD {float(m['d_elpd']):.1f} +- {float(m['d_se']):.1f})" for x, m in zip(law, r)])
    ax.set_xlim(0, 1)
    ax.set_xlabel("stacking weight (0-1): the share of the campaign's predictions each law carries")
    ax.set_title("blue: named by the verdict (carries the weight, or is not ruled out: docs/campaigns.md);\n"
                 "grey: ruled out, or a richer law the tests do not ask for", loc="left", fontsize=9)
    ax = axes[1]
    if ca.next_tests:
        for k, setup in enumerate(sorted({c.setup for c in ca.next_tests})):
            pts = sorted((c.V, c.information) for c in ca.next_tests if c.setup == setup)
            ax.plot([v for v, _ in pts], [i for _, i in pts], "o-", color=f"C{k}", label=f"set-up {setup}")
        best = ca.next_tests[0]
        ax.annotate(f"next: set-up {best.setup} at {best.V:.1f} m/s", (best.V, best.information),
                    textcoords="offset points", xytext=(5, 8), fontsize=9)
        ax.set_xlabel("sliding speed V of the new test (m/s)")
        ax.set_ylabel("expected information on which law holds (nats)")
        ax.legend(fontsize=8)
    else:
        ax.axis("off")
        ax.text(0.0, 0.9, "One law carries the weight: no further test is needed to choose it.", fontsize=10,
                transform=ax.transAxes)
    fig.subplots_adjust(left=0.17)
    return fig


def _flag_page(ca: CampaignAnalysis):
    """Set-ups and tests off the shared law, in a table, with the notes below."""
    fig, ax = figure("Flags: set-ups and tests that do not follow the shared law")
    ax.axis("off")
    rows, notes = [], []
    for f in ca.flagged:
        if "setup" in f:
            o = f["offset"]
            rows.append([f"set-up {f['setup']}", "kappa (stationary)" if f.get("basis") == "kappa" else "f (diagnosed)",
                         f"{o['q50'] * 100:+.1f} % [{o['q05'] * 100:+.1f}, {o['q95'] * 100:+.1f}]",
                         f"{f['d_elpd']:.1f} +- {f['d_se']:.1f}"])
            notes += [str(f[k]) for k in ("note", "note_diagnosed", "note_causes") if k in f]
            notes += [str(c) for c in f["causes"].values()]
        else:
            rows.append([f"test {f['test']}", "under the law", f"{f['below_median_by']:.1f} below the median", ""])
    if rows:
        tab = ax.table(cellText=rows, colLabels=["what", "measured on", "offset from the law, median [90 %]",
                                                  "evidence (dELPD +- SE)"], loc="upper left", cellLoc="left",
                       bbox=[0.0, max(0.45, 1.0 - 0.06 * (len(rows) + 1)), 1.0, min(0.5, 0.06 * (len(rows) + 1))])
        tab.auto_set_font_size(False)
        tab.set_fontsize(9)
        ax.text(0.0, 0.42, _wrapped(notes[:14]), va="top", fontsize=9, transform=ax.transAxes)
    else:
        ax.text(0.0, 0.9, "Nothing flagged: every set-up and test follows the shared law within its calibration "
                "(3 %).", fontsize=10, transform=ax.transAxes)
    return fig


def write_campaign_report(ca: CampaignAnalysis, doc: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write the campaign PDF atomically; pages after the summary only when there is something to draw."""
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    out = Path(path)
    with plt.rc_context(RC):
        pages = [_summary_page(ca, doc)]
        if ca.tests:
            pages.append(_forest(ca))
        if ca.law_data is not None and ca.ranking:
            pages += [_law_page(ca), _comparison_page(ca, list(doc["friction_law"].get("supported") or [])),
                      _flag_page(ca)]
        buf = io.BytesIO()  # in memory, then written at once (a disk that fills mid-file is one OSError)
        with PdfPages(buf) as pdf:
            for fig in pages:
                pdf.savefig(fig)
                plt.close(fig)
        write_bytes(out, buf.getvalue())
    return out
