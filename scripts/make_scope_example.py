"""Write the bundled oscilloscope example, data/scope/A-03_scope.csv, from data/A/A-03.h5.

The record's gauges as a scope exports them: a Keysight-like preamble, a header and a units row,
time and four voltages with 7 significant digits; strain per volt 2e-4 (input and internal output
bars), 1e-4 (external output bar), 5e-5 (tube); the input bar's bridge wired to read compression
positive (its voltages negated), as data/scope/SETUP.toml describes (sign = -1).

    python scripts/make_scope_example.py            # writes data/scope/A-03_scope.csv
    python scripts/make_scope_example.py --check    # compares a fresh export with the bundled file
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "data" / "A" / "A-03.h5"
OUT = ROOT / "data" / "scope" / "A-03_scope.csv"
STRAIN_PER_VOLT = {"input_bar": 2e-4, "internal_output_bar": 2e-4, "external_output_bar": 1e-4, "tube_hoop": 5e-5}
SIGN = {"input_bar": -1}


def write(path: Path) -> Path:
    from friction_uq.acquisition.scope_export import gauge_signals, write_scope_csv

    strains, rate, t0 = gauge_signals(RECORD)
    n = len(strains["input_bar"])
    volts = {f"CH{i + 1}": SIGN.get(g, 1) * eps / STRAIN_PER_VOLT[g] for i, (g, eps) in enumerate(strains.items())}
    return write_scope_csv(path, t0 + np.arange(n) / rate, volts, fmt="%.6e")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    if not ap.parse_args().check:
        print(f"wrote {write(OUT)}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        same = write(Path(tmp) / OUT.name).read_bytes() == OUT.read_bytes()
    print(f"{OUT}: {'identical to a fresh export' if same else 'DIFFERS from a fresh export'}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
