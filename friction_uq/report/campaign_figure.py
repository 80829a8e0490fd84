"""Figure comparing tests across campaigns: kappa and f against sliding velocity and wall pressure."""

from __future__ import annotations

import os
from pathlib import Path

from typing import Any

import numpy as np

from .style import RC, figure, save_figure


#: What is drawn is friction_uq.campaigns.compare.Comparison, read by its attributes: the report sits below the campaign
#: stage and does not import it.
Comparison = Any


def campaign_figure(c: Comparison, path: str | os.PathLike[str]) -> Path:
    """Three panels (kappa vs V, kappa vs p_mean, f vs V), 90 % intervals, one colour per campaign."""
    import matplotlib.pyplot as plt

    with plt.rc_context(RC):
        fig, axes = figure(f"Tests across campaigns ({', '.join(c.campaigns)}): 90 % credible intervals",
                           nrows=1, ncols=3)
        panels = [
            (axes[0], "V", 1.0, "sliding velocity V (m/s)", "kappa", "kappa = f nu/(1-nu) (-)"),
            (axes[1], "p_mean", 1e-6, "mean wall pressure p_mean (MPa)", "kappa", "kappa = f nu/(1-nu) (-)"),
            (axes[2], "V", 1.0, "sliding velocity V (m/s)", "f", "friction coefficient f (-)"),
        ]
        for k, camp in enumerate(c.campaigns):
            rs = [r for r in c.results if r.campaign == camp]
            for ax, xname, xs, xlabel, yname, ylabel in panels:
                x = np.array([getattr(r, xname)["q50"] for r in rs]) * xs
                y = np.array([getattr(r, yname)["q50"] for r in rs])
                lo = y - np.array([getattr(r, yname)["q05"] for r in rs])
                hi = np.array([getattr(r, yname)["q95"] for r in rs]) - y
                ax.errorbar(x, y, yerr=[lo, hi], fmt="o", color=f"C{k}", capsize=3, label=f"campaign {camp}")
                ax.set_xlabel(xlabel)
                ax.set_ylabel(ylabel)
        for name, ax, xs in (("V", axes[0], 1.0), ("p_mean", axes[1], 1e-6)):
            fit = c.fits.get(name)
            if fit is None:
                continue
            lo, hi = ax.get_xlim()
            xx = np.linspace(lo, hi, 50)
            ax.plot(xx, fit.coef[0] + fit.coef[1] * xx / xs, "k--", lw=1, label="weighted fit")
            ax.set_title(f"slope {fit.slope_z(name):+.1f} se, chi2/dof {fit.chi2_dof:.1f}", loc="left", fontsize=9)
        for ax in axes:
            ax.legend(loc="upper right", fontsize=8)
        fig.subplots_adjust(wspace=0.4)
    return save_figure(fig, path)
