"""Report pages about the posterior: corner plot against the priors, nu -> f, convergence, PPC.

Pages only draw what :mod:`friction_uq.diagnostics` computed.
"""

from __future__ import annotations

import textwrap

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..diagnostics import Convergence, FNuBand, FUnderPrior, RatioPPC
from ..sampler import PosteriorSamples
from .style import RC, figure

US = 1e6
LABELS = {"f": "f (-)", "nu": "nu (-)", "hoop_gain": "hoop gain g (-)", "kappa": "kappa = f nu/(1-nu) (-)"}


def _prior_lines(description: str) -> list[str]:
    """One short line per parameter from a :meth:`Priors.describe` text (notes dropped)."""
    out = []
    for line in description.splitlines():
        line = line.strip()
        if "~" in line:
            out.append(line.split("  --")[0].split(" -- ")[0])
    return out


def page_corner(samples: PosteriorSamples, dt: xr.DataTree, *, number: int = 5) -> Figure:
    """Corner plot of the sampled parameters, prior densities on the diagonal."""
    import corner
    import matplotlib.pyplot as plt

    names = list(samples.names)
    data = np.column_stack([samples.flat(n) for n in names])
    with plt.rc_context(RC):
        fig = plt.figure(figsize=(8.27, 8.27))
        corner.corner(
            data, fig=fig, labels=[LABELS.get(n, n) for n in names], quantiles=[0.05, 0.5, 0.95],
            show_titles=True, title_fmt=".4f", title_kwargs={"fontsize": 9}, label_kwargs={"fontsize": 10},
            hist_kwargs={"density": True}, plot_datapoints=False, fill_contours=True, levels=(0.5, 0.9),
            quiet=True,  # a posterior piled at a bound (nu at 0.5) gave "WARNING:root:Too few points ..." on stderr
        )
        axes = np.array(fig.axes).reshape(len(names), len(names))
        prior = dt["prior"] if "prior" in dt.children else None
        for i, n in enumerate(names):
            ax = axes[i, i]
            if prior is not None and n in prior.data_vars:
                x = np.asarray(prior[n].values).reshape(-1)
                lo, hi = ax.get_xlim()
                xs = x[(x >= lo) & (x <= hi)]
                if xs.size > 10:
                    frac = xs.size / x.size
                    h, edges = np.histogram(xs, bins=30, range=(lo, hi), density=True)
                    ax.stairs(h * frac, edges, color="C1", lw=1.2, label="prior")
            if i == 0:
                from matplotlib.lines import Line2D

                handles = [Line2D([], [], color="k", lw=1.2), Line2D([], [], color="k", ls="--", lw=1.0),
                           Line2D([], [], color="C1", lw=1.2)]
                # in the empty corner of the grid, above the priors' text: on the diagonal it hid the histogram
                fig.legend(handles, ["posterior (black: histograms, 50 % and 90 % regions)",
                                     "posterior 5, 50, 95 % quantiles", "prior (orange)"],
                           fontsize=8, loc="upper left", bbox_to_anchor=(0.52, 0.93))
        fig.suptitle(f"{number}. Joint posterior of f and nu (90 % and 50 % regions) against the priors", y=0.995)
        fig.text(0.52, 0.83, "priors (orange):\n" + "\n".join(_prior_lines(samples.prior_description)),
                 fontsize=8, va="top")
    return fig


def page_propagation(
    samples: PosteriorSamples, band: FNuBand, sensitivity: dict[str, FUnderPrior], share: float,
    *, nu_assumed: float = 0.4, number: int = 6,
) -> Figure:
    """nu -> f: f against nu with its band, f under three nu priors, the variance share due to nu."""
    fig, axes = figure(f"{number}. How the uncertainty of nu becomes the uncertainty of f", nrows=1, ncols=2)
    ax = axes[0]
    ax.fill_between(band.nu, band.q05, band.q95, color="C0", alpha=0.25, label="90 % band of f given nu")
    ax.plot(band.nu, band.q50, color="C0", label="median of f given nu (eq. 17)")
    f, nu = samples.flat("f"), samples.flat("nu")
    step = max(1, len(f) // 2000)
    ax.plot(nu[::step], f[::step], ".", ms=1.5, color="k", alpha=0.3, label="posterior draws (f, nu)", rasterized=True)
    ax.axvline(nu_assumed, color="0.5", ls=":", lw=1)
    ax.set_xlabel("Poisson ratio of the sample nu (-)")
    ax.set_ylabel("friction coefficient f (-)")
    ax.set_title(f"share of Var(f) due to nu (law of total variance): {100 * share:.0f} %", loc="left")
    ax.legend(loc="lower left")
    ax.set_ylim(0, max(float(np.max(band.q95[band.nu >= 0.2])) * 1.1, float(np.quantile(f, 0.999)) * 1.1))
    _band_zoom(ax, band, nu, f, step)
    ax = axes[1]
    for k, (label, s) in enumerate(sensitivity.items()):
        hist, edges = np.histogram(s.draws, bins=60, density=True)
        nu_line = next((ln for ln in _prior_lines(s.prior_description) if ln.startswith("nu")), "")
        ax.stairs(hist, edges, color=f"C{k}", lw=1.5,
                  label=f"{label}: {s.q50:.4f} [{s.q05:.4f}, {s.q95:.4f}]\n  {nu_line}")
    ax.set_xlabel("friction coefficient f (-)")
    ax.set_ylabel("posterior density (1/-)")
    ax.set_title("f under three priors for nu: median [90 % interval]", loc="left")
    ax.set_ylim(0, ax.get_ylim()[1] * 1.45)  # room for the legend above the highest peak
    ax.legend(loc="upper right", fontsize=8)
    return fig


def _band_zoom(ax, band: FNuBand, nu: np.ndarray, f: np.ndarray, step: int) -> None:
    """An inset over the posterior's nu range, where the 90 % band of f given nu (the forces' share of f's
    uncertainty, a few % wide) can be seen beside the draws."""
    lo, hi = np.quantile(nu, [0.005, 0.995])
    keep = (band.nu >= lo - 0.01) & (band.nu <= hi + 0.01)
    if keep.sum() < 2:
        return
    ins = ax.inset_axes([0.55, 0.55, 0.42, 0.32])
    ins.fill_between(band.nu[keep], band.q05[keep], band.q95[keep], color="C0", alpha=0.35)
    ins.plot(band.nu[keep], band.q50[keep], color="C0", lw=1)
    ins.plot(nu[::step], f[::step], ".", ms=1, color="k", alpha=0.2, rasterized=True)
    ins.set_title("zoom: the band, where the draws are", fontsize=7)
    ins.tick_params(labelsize=6)


def page_convergence(samples: PosteriorSamples, conv: Convergence, *, number: int = 7) -> Figure:
    """Traces per chain (independent ensembles), R-hat, ESS, autocorrelation times."""
    names = list(samples.names)
    fig, axes = figure(f"{number}. Convergence: {'OK' if conv.ok else 'NOT CONVERGED - read with care'}",
                       nrows=len(names), ncols=1, sharex=True)
    axes = np.atleast_1d(axes)
    for ax, n in zip(axes, names):
        d = samples.draws[n]
        for c in range(d.shape[0]):
            ax.plot(d[c], lw=0.4, alpha=0.8, label=f"ensemble {c + 1}")
        ax.set_ylabel(LABELS.get(n, n))
    axes[0].legend(loc="upper right", ncols=4, fontsize=8)
    axes[-1].set_xlabel(f"draw (after {samples.burn} burn-in steps, thinned by {samples.thin}; "
                        f"walkers pooled within each ensemble)")
    text = (
        f"R-hat max {conv.r_hat_max:.4f} (across {samples.n_chains} independent ensembles; < 1.01 wanted)   "
        f"ESS bulk min {conv.ess_bulk_min:.0f}, tail min {conv.ess_tail_min:.0f} (>= 400 wanted)   "
        f"steps {conv.n_steps} per walker, {samples.nwalkers} walkers x {samples.n_chains} ensembles   "
        f"tau max {conv.tau_max:.1f} steps (chain > 50 tau: {'yes' if conv.converged else 'no'})   "
        f"acceptance {conv.acceptance:.2f}   {conv.seconds:.1f} s, {conv.ess_per_second:.0f} ESS/s"
    )
    fig.text(0.01, 0.01, "\n".join(textwrap.wrap(text, 190)), fontsize=8)
    fig.subplots_adjust(bottom=0.12)
    return fig


def page_ppc(ppc: RatioPPC, *, number: int = 8) -> Figure:
    """Posterior predictive check of F_eo/F_io over the window."""
    fig, ax = figure(f"{number}. Posterior predictive check: F_eo / F_io over the stationary window")
    t = ppc.time * US
    for k in range(min(30, len(ppc.replicated))):
        ax.plot(t, ppc.replicated[k], color="C0", lw=0.3, alpha=0.3)
    ax.fill_between(t, ppc.q05, ppc.q95, color="C0", alpha=0.25, label="90 % band of replicated data")
    ax.plot(t, ppc.q50, color="C0", lw=1, label="median of replicated data")
    ax.plot(t, ppc.observed, color="k", lw=1.2, label="observed")
    ax.axhspan(ppc.model_q05, ppc.model_q95, color="C3", alpha=0.15, label="90 % interval of the model ratio")
    ax.set_xlabel("time (us)")
    ax.set_ylabel(f"F_eo / F_io, {ppc.smooth * US:.0f} us smoothing (-)")
    ax.set_title(f"observed inside the 90 % band {100 * ppc.coverage:.0f} % of the time "
                 "(about 90 % if the constant-ratio model and the noise model hold)", loc="left")
    ax.legend(loc="upper right")
    return fig


def page_hoop(samples: PosteriorSamples, data, forces, *, number: int = 9, n_draws: int = 200, seed: int = 0,
              likelihood=None) -> Figure:
    """The hoop gauge against the model: whole record, window prediction band, residual shape.

    The likelihood uses the window level only (3 % model discrepancy); this page shows what the
    level hides: the shape of the reading as the sample slides past the gauge, against the
    shape the Janssen pressure and the tube kernel predict. ``likelihood``: the analysis' (with
    the hoop term), whose model predicts the reading; None: one is built.
    """
    from ..likelihood import Likelihood

    fig, axes = figure(f"{number}. Tube hoop gauge against the model (posterior draws)", nrows=1, ncols=2)
    lk = likelihood if likelihood is not None and likelihood.has_hoop else Likelihood(data, hoop=True)
    rng = np.random.default_rng(seed)
    flat = samples.array().reshape(-1, len(samples.names))
    pick = lk.parameters.as_dict(flat[rng.choice(len(flat), size=min(n_draws, len(flat)), replace=False)])
    pred = lk.hoop.predict(pick["f"], pick["nu"], pick["hoop_gain"])
    q = np.quantile(pred, [0.05, 0.5, 0.95], axis=0)
    t = np.asarray(data.time) * US
    ax = axes[0]
    ax.plot(forces.time * US, forces.hoop * US, color="k", lw=0.6, label="hoop gauge (compression positive)")
    ax.fill_between(t, q[0] * US, q[2] * US, color="C1", alpha=0.4, label="model, 90 % band (window)")
    ax.plot(t, q[1] * US, color="C1", lw=1.2)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("hoop strain (ue); the swelling tube reads negative")
    ax.set_title("whole record; model over the window", loc="left")
    ax.legend(loc="lower right")
    ax = axes[1]
    resid = (np.asarray(data.hoop) - q[1]) * US
    sd = float(data.sd_hoop) * US
    ax.plot(t, resid, color="k", lw=0.6, label="observed - model median")
    ax.axhspan(-2 * sd, 2 * sd, color="0.8", alpha=0.6, label="+- 2 sd of the gauge noise")
    level = 0.03 * float(np.mean(np.abs(q[1]))) * US
    ax.axhline(level, color="C3", ls="--", lw=1, label="+- 3 % of the level (model discrepancy)")
    ax.axhline(-level, color="C3", ls="--", lw=1)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("residual (ue)")
    ax.set_title(f"residual: mean {np.mean(resid):+.2f} ue,\ntrend {np.polyfit(t, resid, 1)[0] * 100:+.2f} ue "
                 "per 100 us", loc="left")
    ax.legend(loc="upper right")
    return fig
