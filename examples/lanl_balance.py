"""Force balance of a real two-bar SHPB record (LANL, OFE copper, 2006): which amplifier gain?

The LANL file states the transmitted-bar gain twice: 200 ("Transmitted Bar Gain") and 500
("Transmitted Bar Calibrated Gain"); the input bar's two gain fields agree (200). A gain common to
both channels cancels from the balance, so the balance tests the transmitted gain against the input
gain: the right one makes the input-face force F_1 = A E (eps_i + eps_r) match the output-face force
F_2 = A E eps_t over the loading.

Usage::

    python examples/lanl_balance.py [OUTPUT_DIR] [--record PATH]

Prints the balance error for both gains, with and without the Pochhammer-Chree correction and
with both choices of transport wave speed, and writes ``lanl_balance.png`` (F_1 and F_2 against
time for both gains) into OUTPUT_DIR (default /tmp). The record is read from ``../shared/`` beside
the repository; no copy of it belongs in the repository.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from matplotlib.figure import Figure

from friction_uq.errors import FrictionUQError
from friction_uq.shpb import BALANCE_LEVEL, TwoBarForces, read_lanl_raw, two_bar_forces

RECORD = (
    Path(__file__).resolve().parents[1]
    / ".."
    / "shared"
    / "data"
    / "real"
    / "lanl-hoppybar-cu"
    / "20061201_1148HE_CuOFE_273K.raw"
)
GAINS = (200.0, 500.0)


def draw(results: dict[float, TwoBarForces], title: str) -> Figure:
    """F_1 and F_2 (kN) against time (us) at the specimen faces, one panel per transmitted gain."""
    fig = Figure(figsize=(11.69, 5.5), layout="constrained")
    axes = fig.subplots(1, len(results), sharey=True)
    for ax, (gain, f) in zip(axes, results.items(), strict=True):
        t = f.time * 1e6
        ax.plot(t, f.front_force / 1e3, label="F_1 = A E (eps_i + eps_r), input face")
        ax.plot(t, f.back_force / 1e3, label="F_2 = A E eps_t, output face")
        ax.axvspan(f.window[0] * 1e6, f.window[1] * 1e6, color="0.85", zorder=0,
                   label=f"loading: F_2 >= {BALANCE_LEVEL:.0%} of peak")
        lo, hi = f.window
        ax.set_xlim((lo - 0.8 * (hi - lo)) * 1e6, (hi + 0.8 * (hi - lo)) * 1e6)
        ax.set_title(f"transmitted gain {gain:.0f} (input {f.input_gain:.0f}): "
                     f"balance error {f.balance_error:.1%}")
        ax.set_xlabel("time (us)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("force (kN)")
    axes[0].legend(loc="upper left", fontsize=8)
    fig.suptitle(title)
    return fig


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output_dir", nargs="?", type=Path, default=Path("/tmp"),
                        help="directory for lanl_balance.png (default /tmp)")
    parser.add_argument("--record", type=Path, default=RECORD, help=f"the LANL .raw file (default {RECORD})")
    args = parser.parse_args(argv)
    if not args.record.is_file():
        print(f"error: record not found: {args.record} (the shared data directory is not beside the repository)",
              file=sys.stderr)
        return 2
    try:
        record = read_lanl_raw(args.record)
        print(f"{record.path.name}: input-bar gain fields {dict(record.input_bar.gains)}, "
              f"transmitted-bar gain fields {dict(record.transmitted_bar.gains)}")
        print("balance error = mean|F_1 - F_2| / mean F_2 over the loading; impulse error = "
              "(int F_1 - int F_2) / int F_2 there")
        print(f"{'wave speed':>24} {'dispersion':>10} {'gain':>5} {'balance':>8} {'impulse':>8}")
        for speed in ("timing", "rod"):
            for dispersion in (False, True):
                for gain in GAINS:
                    f = two_bar_forces(record, gain=gain, dispersion=dispersion, wave_speed=speed)
                    label = f"{speed} ({f.wave_speeds[0]:.0f} m/s)"
                    print(f"{label:>24} {dispersion!s:>10} {gain:5.0f} {f.balance_error:8.1%} {f.impulse_error:+8.1%}")
        results = {gain: two_bar_forces(record, gain=gain) for gain in GAINS}
    except FrictionUQError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    best = min(results, key=lambda g: results[g].balance_error)
    print(f"the balance supports a transmitted gain of {best:.0f}")
    f = results[best]
    print("arrivals at the gauges (us): " + ", ".join(f"{k} {v * 1e6:.2f}" for k, v in f.arrivals.items()))
    args.output_dir.mkdir(parents=True, exist_ok=True)
    out = args.output_dir / "lanl_balance.png"
    title = (f"{record.path.name}: forces at the specimen faces\n"
             "(no dispersion correction; travel times from the calibrated reflection time)")
    draw(results, title).savefig(out, dpi=120)
    print(f"figure: {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
