"""Benchmark of the main job: ``friction-uq run`` on bundled records, end to end with the PDF.

Target (issue 4): <= 30 s per record on a 2-core machine. Prints a table: wall time, sampler time,
steps, ESS (bulk, min over variables), ESS per second of f, R-hat max.

    python benchmarks/bench_run.py [RECORD ...]
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import arviz_stats

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = [ROOT / "data" / "A" / "A-03.h5", ROOT / "data" / "B" / "B-03.h5"]


def main(argv: list[str]) -> int:
    from friction_uq.run import run_file
    from friction_uq.sampler import PosteriorSamples  # noqa: F401  (import cost outside the timing)
    import friction_uq.report.pdf  # noqa: F401

    records = [Path(a) for a in argv] or DEFAULT
    rows = []
    for rec in records:
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            res = run_file(rec, out_dir=out, seed=1, progress=False)
            wall = time.perf_counter() - t0
            import xarray as xr

            dt = xr.open_datatree(res.outputs["netcdf"], engine="h5netcdf")
            ess_f = float(arviz_stats.ess(dt, var_names=["f"], method="bulk")["f"].values)
            rows.append((rec.name, wall, res.samples.seconds, res.samples.n_steps, res.convergence.ess_bulk_min,
                         ess_f / res.samples.seconds, res.convergence.r_hat_max))
    print()
    print(f"{'record':<10} {'wall s':>7} {'sampler s':>9} {'steps':>6} {'ESS min':>8} {'ESS/s f':>8} {'R-hat':>7}")
    for r in rows:
        print(f"{r[0]:<10} {r[1]:>7.1f} {r[2]:>9.1f} {r[3]:>6d} {r[4]:>8.0f} {r[5]:>8.0f} {r[6]:>7.4f}")
    print("target: wall <= 30 s per record (issue 4)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
