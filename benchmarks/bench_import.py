"""Benchmark of ``friction-uq import``: a 1 M-sample x 4-channel scope CSV to a checked record.

Target (issue 21): <= 5 s for 1 M samples x 4 channels. The CSV is the bundled record A-03
resampled onto 1 M samples (769 MHz over its 1.3 ms), written as a scope writes it (metadata lines,
a header, a units row, time and four voltages with 9 digits, ~80 MB). Prints

1. the command's wall and CPU time for each of ``--repeat`` runs as a user starts it (a new
   process each time, imports included) and their median;
2. the breakdown of one in-process import: reading the CSV (dialect, header, parse), the time
   base, writing the HDF5 record, reading it back against the contract, the gauge check.

    python benchmarks/bench_import.py [--samples 1000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "data" / "A" / "A-03.h5"
SPV = {"input_bar": 2e-4, "internal_output_bar": 2e-4, "external_output_bar": 1e-4, "tube_hoop": 5e-5}


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def make_inputs(folder: Path, n: int) -> tuple[Path, Path]:
    from friction_uq.acquisition.scope_export import gauge_signals, write_scope_csv
    from friction_uq.acquisition.template import TEMPLATE

    strains, rate, t0 = gauge_signals(RECORD)
    m = len(next(iter(strains.values())))
    t_old = t0 + np.arange(m) / rate
    t_new = t0 + np.arange(n) * ((m - 1) / rate / (n - 1))
    volts = {f"CH{i + 1}": np.interp(t_new, t_old, eps) / SPV[g] for i, (g, eps) in enumerate(strains.items())}
    csv = write_scope_csv(folder / "big.csv", t_new, volts)
    setup = TEMPLATE.replace('test_id = "A-07"', 'test_id = "A-03"').replace("striker_velocity = 10.0",
                                                                            "striker_velocity = 9.9")
    setup = setup.replace("gauge_factor = 2.1\nunits", "units")
    for line in ("gauge_factor = 2.1", 'bridge = "half"                  # two axial gauges on opposite sides '
                 "(bending cancels)", "excitation = 10.0                # V", "amplifier_gain = 100.0"):
        setup = setup.replace(line + "\n", "")
    setup = setup.replace('column = "CH1"\nunits = "V"\n', 'column = "CH1"\nunits = "V"\nstrain_per_volt = 2e-4\n')
    setup = setup.replace('column = "CH3"\nunits = "V"\nstrain_per_volt = 2.0e-4',
                          'column = "CH3"\nunits = "V"\nstrain_per_volt = 1.0e-4')
    (folder / "SETUP.toml").write_text(setup)
    return csv, folder / "SETUP.toml"


def breakdown(csv: Path, setup_path: Path, out: Path) -> list[tuple[str, float]]:
    from friction_uq.acquisition import assemble, load_setup
    from friction_uq.acquisition.sanity import import_findings
    from friction_uq.record import read_record

    rows = []
    t = time.perf_counter()
    setup = load_setup(setup_path)
    chans = assemble._read_file(setup, csv, list(setup.channels.values()))
    rows.append(("read CSV + time base", time.perf_counter() - t))
    t = time.perf_counter()
    t0, dt, _ = assemble._common_time_base(chans)
    assemble._write(str(out), setup, chans, t0, dt)
    rows.append(("write record", time.perf_counter() - t))
    t = time.perf_counter()
    rec = read_record(out)
    rows.append(("read back (contract)", time.perf_counter() - t))
    t = time.perf_counter()
    refusals, _ = import_findings(rec, setup)
    rows.append(("gauge check", time.perf_counter() - t))
    if refusals:
        raise SystemExit(f"the benchmark record was refused: {refusals}")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        t = time.perf_counter()
        csv, setup = make_inputs(folder, args.samples)
        print(f"input: {csv.stat().st_size / 1e6:.0f} MB CSV, {args.samples} samples x 4 channels + time "
              f"(made in {time.perf_counter() - t:.1f} s)\n")
        exe = Path(sys.executable).with_name("friction-uq")
        walls, cpus = [], []
        print(f"{'run':>4}  {'wall s':>7}  {'cpu s':>6}")
        for i in range(args.repeat):
            c0, w0 = _cpu_children(), time.perf_counter()
            r = subprocess.run([str(exe), "import", str(csv), "--setup", str(setup), "-o", str(folder / "r.h5")],
                               capture_output=True, text=True)
            walls.append(time.perf_counter() - w0)
            cpus.append(_cpu_children() - c0)
            if r.returncode:
                raise SystemExit(r.stderr)
            print(f"{i + 1:>4}  {walls[-1]:7.2f}  {cpus[-1]:6.2f}")
        print(f"{'med':>4}  {statistics.median(walls):7.2f}  {statistics.median(cpus):6.2f}   (target <= 5 s)\n")
        rows = breakdown(csv, setup, folder / "b.h5")
        print(f"{'stage (in process)':<24}  {'s':>6}")
        for name, s in rows:
            print(f"{name:<24}  {s:6.2f}")
        print(f"{'total':<24}  {sum(s for _, s in rows):6.2f}")


if __name__ == "__main__":
    main()
