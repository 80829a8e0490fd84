"""Simulation-based calibration study: coverage of the 90 % intervals of kappa and f.

Usage::

    .venv/bin/python benchmarks/bench_sbc.py [N] [--seed S] [--no-hoop | --hoop-only] [--ensembles K] [--records]

Prints, for the force-only likelihood and for the force + hoop likelihood, the coverage rates with
the binomial 95 % band around 90 %, the share of converged runs and the time. Replicas, the data
builder and the band are those of ``tests/test_sbc.py`` (same seeds give the same numbers).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_sbc import binomial_band, coverage, run_sbc  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=200, help="replicas per likelihood (default 200)")
    ap.add_argument("--seed", type=int, default=10_000)
    ap.add_argument("--ensembles", type=int, default=1, help="independent ensembles per replica (default 1)")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--records", action="store_true",
                    help="whole closed-form records through friction_uq.analysis.prepare instead of stationary data")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--no-hoop", action="store_true", help="force term only")
    g.add_argument("--hoop-only", action="store_true", help="force + hoop term only")
    a = ap.parse_args(argv)
    cases = [False] if a.no_hoop else [True] if a.hoop_only else [False, True]
    lo, hi = binomial_band(a.n, 0.9, 0.95)
    source = "records" if a.records else "closed-form"
    print(f"SBC ({source}): {a.n} replicas per likelihood, truth from the packaged I1.toml, seed {a.seed}; "
          f"binomial 95 % band around 0.90: [{lo:.3f}, {hi:.3f}]")
    ok = True
    for hoop in cases:
        t0 = time.perf_counter()
        reps = run_sbc(a.n, seed=a.seed + (10_000 if hoop else 0), hoop=hoop, n_ensembles=a.ensembles,
                       workers=a.workers, source=source)
        ck, cf = coverage(reps)
        conv = sum(r.converged for r in reps)
        inside = lo <= ck <= hi and lo <= cf <= hi
        ok &= inside
        print(f"  {'force + hoop' if hoop else 'force only  '}: coverage kappa {ck:.3f}, f {cf:.3f} "
              f"({'inside' if inside else 'OUTSIDE'} the band); converged {conv}/{a.n}; "
              f"{time.perf_counter() - t0:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
