"""Name the bar-level causes of the force-balance misfit of the real LANL copper record.

    python examples/lanl_diagnose.py [--record PATH] [--seed N] [--prepulse-noise]

Starts from the nominal model of the record (the header's transmitted gain, 200 V/V; the stated
rod wave speed c0 = 4975 m/s; no dispersion correction): the transmitted gauge predicted from the
input gauge by force balance (:mod:`friction_uq.shpb.balance`). Prints its misfit, then the
forward selection of :func:`friction_uq.shpb.diagnose_balance` (each step: every mechanism tried
on top of the current model, its parameters' posterior, dELPD +- SE, the misfit before and after),
the named causes, and what the fitted parameters measure (the transmitted gain in V/V, the bar
wave speed and the gauge-to-gauge reflection time against the file's calibrated one). The record
is read from ``../shared/`` beside the repository; no copy of it belongs in the repository.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from friction_uq.errors import FrictionUQError
from friction_uq.shpb import (
    MECHANISMS,
    BalanceFit,
    BalanceObservation,
    combine,
    diagnose_balance,
    fit_balance,
    read_lanl_raw,
)

RECORD = (Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "real" / "lanl-hoppybar-cu"
          / "20061201_1148HE_CuOFE_273K.raw")


def describe(fit: BalanceFit) -> str:
    """Parameters' posterior: mean [5 %, 95 %] (the noise scale last)."""
    parts = []
    for name in fit.draws:
        s = fit.summary(name)
        fmt = ".4f" if name != "noise_scale" else ".1f"
        parts.append(f"{name} {s['mean']:{fmt}} [{s['q05']:{fmt}}, {s['q95']:{fmt}}]")
    return "; ".join(parts) or "-"


def misfit_line(fit: BalanceFit) -> str:
    m = fit.misfit
    return f"chi2/dof {m.chi2_dof:7.1f}  RMS {m.rms_force:6.0f} N ({m.relative_rms:5.1%} of peak F_2)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--record", type=Path, default=RECORD, help="the LANL .raw file")
    parser.add_argument("--seed", type=int, default=0, help="seed of the posterior draws")
    parser.add_argument("--prepulse-noise", action="store_true",
                        help="score with the pre-pulse noise alone (no fitted noise scale): "
                             "shows why it is not the default")
    args = parser.parse_args(argv)
    if not args.record.is_file():
        print(f"error: record not found: {args.record} (the shared data directory is not beside the repository)",
              file=sys.stderr)
        return 2
    try:
        record = read_lanl_raw(args.record)
        obs = BalanceObservation(record)
        result = diagnose_balance(obs, seed=args.seed, scaled_noise=not args.prepulse_noise)
    except FrictionUQError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    ib = record.input_bar
    nz = obs.waves.noise
    print(f"{record.path.name}: transmitted gauge over {obs.time[0] * 1e6:.1f}-{obs.time[-1] * 1e6:.1f} us "
          f"({obs.n} samples) predicted from the input gauge by force balance")
    print(f"noise of the residual (pre-pulse): sd {obs.sd * obs.force_scale:.1f} N, lag-1 {obs.rho:.2f} "
          f"(input gauge sd {nz['input'].sd:.2e}, transmitted {nz['transmitted'].sd:.2e} strain)")
    print(f"nominal model (gain {obs.header_gain:.0f} V/V, c0 {ib.wave_speed:.0f} m/s, no dispersion): "
          f"{misfit_line(result.nominal)}, level {result.nominal.misfit.level:.0f} sd, "
          f"longest same-sign run {result.nominal.misfit.longest_run}")
    for i, step in enumerate(result.steps, 1):
        print(f"\nstep {i}: on top of [{step.base.name}] ({misfit_line(step.base)})")
        print(f"  {'mechanism':<12} {'dELPD +- SE':>17} {'decisive':>8} {'k (IS, LOO)':>12}  misfit after; posterior")
        for c in step.candidates:
            k = f"{c.fit.pareto_k:.2f}, {c.fit.elpd.pareto_k_max:.1f}"
            print(f"  {c.mechanism:<12} {c.delpd:8.1f} +- {c.se:6.1f} {c.decisive!s:>8} {k:>12}  "
                  f"{misfit_line(c.fit)}; {describe(c.fit)}")
        print(f"  -> {'added: ' + step.added if step.added else 'nothing decisive: stop'}"
              + (f" (not separable from it: {', '.join(step.not_separable)})" if step.not_separable else ""))
    d, se = result.gain()
    f = result.final
    print(f"\nnamed causes: {', '.join(result.causes) or 'none'}"
          + (f"; not separable: {', '.join(result.not_separable)}" if result.not_separable else ""))
    print(f"gain over the nominal model: dELPD {d:.0f} +- {se:.0f}; {misfit_line(result.nominal)} -> {misfit_line(f)}")
    speed = f.draws.get("speed_factor")
    if speed is not None:
        s = f.summary("speed_factor")
        c = s["mean"] * ib.wave_speed
        t = 2 * ib.gauge_distance / c
        print(f"bar wave speed {c:.0f} m/s [{s['q05'] * ib.wave_speed:.0f}, {s['q95'] * ib.wave_speed:.0f}] "
              f"(stated c0 {ib.wave_speed:.0f}); reflection time 2 d / c = {t * 1e6:.1f} us "
              f"(file's calibrated value {2 * ib.gauge_distance / ib.timing_wave_speed * 1e6:.1f} us)")
    # the gain measured with every mechanism in (not only the named ones): what the record says of it
    g = fit_balance(obs, combine(MECHANISMS), rng=np.random.default_rng(args.seed),
                    scaled_noise=not args.prepulse_noise)
    s = g.summary("gain_factor")
    print(f"transmitted gain under [{g.name}]: {s['mean'] * obs.header_gain:.1f} V/V "
          f"[{s['q05'] * obs.header_gain:.1f}, {s['q95'] * obs.header_gain:.1f}], "
          f"gamma {s['mean']:.4f} +- {s['sd']:.4f} "
          f"(header: 200 'Transmitted Bar Gain', 500 'Calibrated Gain': {(2.5 - s['mean']) / s['sd']:.0f} sd away); "
          f"{misfit_line(g)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
