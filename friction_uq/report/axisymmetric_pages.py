"""Pages of ``friction-uq simulate CONFIG --compare PDF``: the 1-D and the axisymmetric simulations side by side.

Page 1: the per-phase table (rise, stationary, unloading) of F_io, F_eo, hoop strain and reflected
wave, each model's value and the difference. Page 2: the interface forces over time. Page 3: the
hoop gauge and the reflected wave. Page 4: the axial stress and the wall pressure along the sample
in the stationary phase, against eq. 11 and eq. 20. Page 5: the paper's figure 15 (F_eo against F_io (exp(f beta) - 1))
from the axisymmetric forces, with eq. 17's f read back from them (Coulomb friction only).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from ..simulate.axisymmetric.side_by_side import (
    PHASES,
    QUANTITIES,
    UNITS,
    Comparison,
    compare,
    eq17_friction,
    figure15,
    stationary_profiles,
)
from ..simulate.config import SimulationConfig
from .style import A4_LANDSCAPE, CORE_FONTS, RC, plt


def table_text(comp: Comparison) -> str:
    """The per-phase table as monospaced text (also printed by the CLI)."""
    lines = [f"{'phase':<11} {'quantity':<10} {'unit':<11} {'1-D':>11} {'axisym.':>11} {'diff %':>8}"]
    for phase in PHASES:
        for q in QUANTITIES:
            a, b = comp.table[phase][q]
            lines.append(f"{phase:<11} {q:<10} {UNITS[q]:<11} {a:11.2f} {b:11.2f} "
                         f"{100 * comp.relative_difference(phase, q):+8.2f}")
    return "\n".join(lines)


def _page_table(comp: Comparison):
    fig = plt.figure(figsize=A4_LANDSCAPE)
    cfg, two = comp.config, comp.axisymmetric
    fig.suptitle(f"{cfg.test_id}: 1-D against axisymmetric simulation, same configuration and loading")
    head = (f"configuration {Path(cfg.source).name}; friction law {cfg.friction_law} "
            f"{dict(cfg.friction_params)}; nu = {cfg.poisson_ratio}; V_s = {cfg.striker_velocity} m/s\n"
            f"axisymmetric mesh: element size {two.element_size * 1e3:g} mm, {two.elements} elements, "
            f"time step {two.time_step * 1e9:.1f} ns (stability limit {two.critical_time_step * 1e9:.1f} ns)\n"
            "phases at the cell: " + "; ".join(f"{p} {w[0] * 1e6:.0f}-{w[1] * 1e6:.0f} us"
                                              for p, w in comp.windows.items())
            + "\nhoop: physical strain (swelling positive); reflected: at the input gauge, tensile negative")
    fig.text(0.05, 0.88, head, fontsize=9, va="top", family="monospace")
    fig.text(0.05, 0.70, table_text(comp), fontsize=10, va="top", family="monospace")
    return fig


def _page_forces(comp: Comparison):
    fig, axes = plt.subplots(2, 1, figsize=A4_LANDSCAPE, sharex=True)
    one, two = comp.one_d, comp.axisymmetric
    for ax, name, label in ((axes[0], "force_internal", "F_io (N)"), (axes[1], "force_external", "F_eo (N)")):
        ax.plot(one.time * 1e6, getattr(one, name), label="1-D")
        ax.plot(two.time * 1e6, getattr(two, name), label="axisymmetric", ls="--")
        ax.set_ylabel(label)
        _shade(ax, comp)
        ax.legend(loc="upper right")
    axes[1].set_xlabel("time (us)")
    fig.suptitle("Interface forces at the cell")
    return fig


def _page_gauges(comp: Comparison):
    fig, axes = plt.subplots(2, 1, figsize=A4_LANDSCAPE)
    one, two = comp.one_d, comp.axisymmetric
    for out, label, ls in ((one, "1-D", "-"), (two, "axisymmetric", "--")):
        if "tube_hoop" in out.strains:
            axes[0].plot(out.time * 1e6, -1e6 * out.strains["tube_hoop"], label=label, ls=ls)
    axes[0].set_ylabel("hoop strain (microstrain)")
    _shade(axes[0], comp)
    for key, label, ls in (("1d", "1-D", "-"), ("axisymmetric", "axisymmetric", "--")):
        axes[1].plot(one.time * 1e6, 1e6 * comp.reflected[key], label=label, ls=ls)
    axes[1].set_ylabel("reflected wave at the input gauge (microstrain)")
    axes[1].set_xlabel("time (us)")
    for ax in axes:
        ax.legend(loc="upper right")
    fig.suptitle("Tube hoop gauge and reflected wave")
    return fig


def _page_figure15(comp: Comparison):
    cfg, two = comp.config, comp.axisymmetric
    f = float(cfg.friction_params["f"])
    f_eo, predicted = figure15(cfg, two, f=f)
    fig, ax = plt.subplots(figsize=A4_LANDSCAPE)
    ax.plot(two.time * 1e6, f_eo, label="F_eo, axisymmetric model")
    ax.plot(two.time * 1e6, predicted, ls="--", label=f"F_io (exp(2 f nu L / ((1 - nu) R)) - 1), f = {f:g}")
    ax.plot(comp.one_d.time * 1e6, comp.one_d.force_external, ls=":", label="F_eo, 1-D model")
    _shade(ax, comp)
    w = comp.windows["stationary"]
    m = (two.time >= w[0]) & (two.time < w[1])
    over = float(np.mean(predicted[m]) / np.mean(f_eo[m]) - 1.0)
    ax.set_title(f"Paper's figure 15 from the axisymmetric model: the analytical model is {100 * over:+.1f} % "
                 f"on F_eo in the stationary phase; eq. 17 reads f = {eq17_friction(cfg, two):.4f} (put in {f:g})")
    ax.set_xlabel("time (us)")
    ax.set_ylabel("force (N)")
    ax.legend(loc="upper right")
    return fig


def _page_profiles(comp: Comparison):
    prof = stationary_profiles(comp)
    fig, axes = plt.subplots(1, 2, figsize=A4_LANDSCAPE)
    styles = {"axial axi": ("axisymmetric, section mean", "-"), "axial eq11": ("eq. 11 from F_io", "--"),
              "wall axi": ("axisymmetric", "-"), "wall 1d": ("1-D", ":"),
              "wall eq20": ("eq. 20 from F_eo", "--")}
    for key, (z, val) in prof.items():
        ax = axes[0] if key.startswith("axial") else axes[1]
        label, ls = styles[key]
        ax.plot(z * 1e3, val / 1e6, ls=ls, label=label)
    axes[0].set_ylabel("axial stress (MPa, compression positive)")
    axes[1].set_ylabel("wall pressure (MPa)")
    for ax in axes:
        ax.set_xlabel("z from the sample's input face at the start (mm)")
        ax.legend()
    fig.suptitle("Stationary phase along the sample: axial stress and wall pressure")
    return fig


def _shade(ax, comp: Comparison) -> None:
    for (_, (a, b)), colour in zip(comp.windows.items(), ("0.9", "0.8", "0.9"), strict=True):
        ax.axvspan(a * 1e6, b * 1e6, color=colour, alpha=0.5, lw=0)


def comparison_pages(comp: Comparison, path: str | Path) -> Path:
    """Write the comparison pages to ``path`` (PDF; atomic)."""
    from matplotlib.backends.backend_pdf import PdfPages

    builders = [_page_table, _page_forces, _page_gauges, _page_profiles]
    if comp.config.friction_law == "coulomb":
        builders.append(_page_figure15)
    out = Path(path)
    with plt.rc_context({**RC, **CORE_FONTS}), atomic_path(out) as tmp, PdfPages(tmp) as pdf:
        for build in builders:
            fig = build(comp)
            pdf.savefig(fig)
            plt.close(fig)
    return out


def compare_to_pdf(config: SimulationConfig, path: str | Path) -> str:
    """Run both models on ``config``, write the pages to ``path``; returns the table and the file's line."""
    comp = compare(config)
    out = comparison_pages(comp, path)
    return f"{table_text(comp)}\nwrote {out}"
