"""What the 1-D model gets wrong, measured against the axisymmetric simulator; its convergence and speed.

    python benchmarks/bench_axisymmetric.py [--quick]

Prints five tables (docs/axisymmetric.md quotes them):

1. per set-up (the paper's, the bundled campaigns' A-03 and B-03 configurations), 1-D against
   axisymmetric on the same configuration and loading: F_io, F_eo, hoop strain and reflected wave
   per phase (rise, stationary, unloading); 1b: the RMS difference of each gauge per phase;
2. the paper's figure 15 in numbers: F_io (exp(f beta) - 1) against the axisymmetric F_eo in the
   stationary phase (how much the analytical model over- or underestimates F_eo);
3. eq. 17's f from the axisymmetric forces against the f put in, f 0.02-0.2, nu 0.3-0.45 (Coulomb);
4. mesh convergence: stationary forces and hoop strain at element sizes 1, 0.5 and 0.25 mm;
5. speed: wall time of a 1.1 ms record of the paper's test (after one warm-up run for numba).

``--quick`` uses 1 mm elements for tables 1-3 and skips the 0.25 mm mesh.
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace
from pathlib import Path
from types import MappingProxyType

import numpy as np

from friction_uq.physics.cell import beta
from friction_uq.simulate import SimulationConfig, load_config, run_model
from friction_uq.simulate.axisymmetric.side_by_side import (
    PHASES,
    QUANTITIES,
    UNITS,
    compare,
    eq17_friction,
    gauge_discrepancy,
    phase_windows,
)
from friction_uq.simulate.axisymmetric.model_axisymmetric import run_axisymmetric
from friction_uq.simulate.axisymmetric.settings import ModelSettings

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = {"paper": ROOT / "data/configs/paper-axisymmetric.toml", "A-03": ROOT / "data/configs/A-03.toml",
           "B-03": ROOT / "data/configs/B-03.toml"}


def paper(f: float = 0.05, nu: float = 0.4, h: float = 0.5e-3) -> SimulationConfig:
    return SimulationConfig(duration=1.1e-3, pretrigger=20e-6, poisson_ratio=nu,
                            friction_params=MappingProxyType({"f": f}),
                            model=ModelSettings(fidelity="axisymmetric", element_size=h))


def stationary(cfg: SimulationConfig, out, series: np.ndarray) -> float:
    a, b = phase_windows(cfg)["stationary"]
    m = (out.time >= a) & (out.time < b)
    return float(np.mean(series[m]))


def table_setups(h: float) -> None:
    print(f"\n1. 1-D against axisymmetric, per phase (element size {h * 1e3:g} mm); diff = (axi - 1-D) / |1-D|")
    print(f"{'set-up':<7} {'phase':<11} " + " ".join(f"{q + ' (' + UNITS[q][:5] + ')':>28}" for q in QUANTITIES))
    print(f"{'':<19} " + " ".join(f"{'1-D':>9} {'axi':>9} {'diff%':>8}" for _ in QUANTITIES))
    gauges = {}
    for name, path in CONFIGS.items():
        cfg = load_config(path)
        comp = compare(cfg, element_size=h)
        gauges[name] = gauge_discrepancy(comp)
        for phase in PHASES:
            cells = []
            for q in QUANTITIES:
                a, b = comp.table[phase][q]
                cells.append(f"{a:9.1f} {b:9.1f} {100 * comp.relative_difference(phase, q):+8.2f}")
            print(f"{name:<7} {phase:<11} " + " ".join(cells))
    print("\n1b. Gauge by gauge: RMS of (axisymmetric - 1-D) strain per phase, % of the 1-D channel's peak "
          "(what a whole-record check's model tolerance must absorb)")
    channels = ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop")
    print(f"{'set-up':<7} {'phase':<11} " + " ".join(f"{c:>20}" for c in channels))
    for name, table in gauges.items():
        for phase in PHASES:
            print(f"{name:<7} {phase:<11} " + " ".join(f"{100 * table[c][phase]:20.2f}" for c in channels))


def table_figure15(h: float) -> None:
    print(f"\n2. Figure 15 in numbers: eq. 13's F_io (exp(f beta) - 1) against the axisymmetric F_eo, stationary phase "
          f"(paper's set-up, nu = 0.4, {h * 1e3:g} mm)")
    print(f"{'f':>6} {'F_eo axi N':>11} {'F_io(e^fb-1) N':>15} {'over %':>7} {'F_eo 1-D N':>11}")
    for f in (0.02, 0.05, 0.1, 0.2):
        cfg = paper(f, h=h)
        two, one = run_axisymmetric(cfg), run_model(replace(cfg, model=ModelSettings()))
        fb = f * float(beta(0.4, radius=5e-3, length=10e-3))
        feo = stationary(cfg, two, two.force_external)
        pred = stationary(cfg, two, two.force_internal) * np.expm1(fb)
        print(f"{f:6.2f} {feo:11.1f} {pred:15.1f} {100 * (pred / feo - 1):+7.2f} "
              f"{stationary(cfg, one, one.force_external):11.1f}")


def table_eq17(h: float) -> None:
    print(f"\n3. Eq. 17 f from the axisymmetric forces against the f put in (Coulomb, paper's set-up, {h * 1e3:g} mm);"
          " 1-D: the same read from the 1-D simulator (rigid tube)")
    nus = (0.3, 0.4, 0.45)
    print(f"{'f in':>6} " + " ".join(f"{'nu=' + str(nu) + ' axi':>13} {'err%':>6} {'1-D':>7}" for nu in nus))
    for f in (0.02, 0.05, 0.1, 0.2):
        cells = []
        for nu in nus:
            cfg = paper(f, nu, h)
            f_axi = eq17_friction(cfg, run_axisymmetric(cfg))
            f_one = eq17_friction(cfg, run_model(replace(cfg, model=ModelSettings())))
            cells.append(f"{f_axi:13.4f} {100 * (f_axi / f - 1):+6.2f} {f_one:7.4f}")
        print(f"{f:6.2f} " + " ".join(cells))


def table_convergence(sizes: tuple[float, ...]) -> None:
    print("\n4. Mesh convergence (paper's set-up, f = 0.05, nu = 0.4): stationary phase; change against the next "
          "coarser mesh")
    print(f"{'h mm':>5} {'elements':>8} {'dt ns':>6} {'F_io N':>9} {'d%':>6} {'F_eo N':>8} {'d%':>6} "
          f"{'hoop ue':>8} {'d%':>6} {'wall s':>7}")
    prev = None
    for h in sizes:
        cfg = paper(h=h)
        run_axisymmetric(cfg) if prev is None else None  # numba warm-up on the first
        t0 = time.perf_counter()
        out = run_axisymmetric(cfg)
        wall = time.perf_counter() - t0
        vals = (stationary(cfg, out, out.force_internal), stationary(cfg, out, out.force_external),
                -1e6 * stationary(cfg, out, out.strains["tube_hoop"]))
        d = ["" if prev is None else f"{100 * (v / p - 1):+6.3f}" for v, p in zip(vals, prev or vals, strict=True)]
        print(f"{h * 1e3:5.2f} {out.elements:8d} {out.time_step * 1e9:6.1f} {vals[0]:9.1f} {d[0]:>6} {vals[1]:8.1f} "
              f"{d[1]:>6} {vals[2]:8.2f} {d[2]:>6} {wall:7.1f}")
        prev = vals


def table_speed(sizes: tuple[float, ...]) -> None:
    print(f"\n5. Speed: one 1.1 ms record of the paper's test (5 MHz), numba, {os.cpu_count()} cores visible")
    print(f"{'h mm':>5} {'elements':>8} {'dt ns':>6} {'steps':>7} {'wall s':>7}")
    for h in sizes:
        cfg = paper(h=h)  # numba compiled by the convergence table's warm-up
        t0 = time.perf_counter()
        out = run_axisymmetric(cfg)
        wall = time.perf_counter() - t0
        print(f"{h * 1e3:5.2f} {out.elements:8d} {out.time_step * 1e9:6.1f} {out.time.size * out.substeps:7d} "
              f"{wall:7.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1 mm elements for tables 1-3; no 0.25 mm mesh")
    args = parser.parse_args()
    h = 1e-3 if args.quick else 0.5e-3
    sizes = (1e-3, 0.5e-3) if args.quick else (1e-3, 0.5e-3, 0.25e-3)
    table_setups(h)
    table_figure15(h)
    table_eq17(h)
    table_convergence(sizes)
    table_speed(sizes[1:])


if __name__ == "__main__":
    main()
