"""Campaign scale: the bundled records on 1 and 2 local workers, and many simulated records.

    python benchmarks/bench_campaign.py bundled [--workers 1 2] [--pdf] [--keep DIR]
    python benchmarks/bench_campaign.py simulated [--n 100] [--workers 2]
    python benchmarks/bench_campaign.py analysis DIR [DIR ...] [--repeat 3]

``bundled`` runs the 10 records of data/A and data/B in a fresh folder for each worker count
(nothing up to date) and prints wall time, the CPU time the workers spent on the records (user +
system, summed over records), the speed-up against the first worker count, and the peak memory
of a worker process, and the wall time of the campaign's own analysis (pooling, laws, flags) after the
records. ``simulated`` draws N test configurations (the bundled A-01 and B-01 set-ups
with striker speeds uniform in 6-14 m/s and fresh noise seeds), simulates them (not timed) and
runs them as one campaign without PDF reports; it prints the time per record and the campaign's
conclusions. ``analysis`` times the campaign's own analysis alone (pooling, law fits on the package's
forked processes, flags, next-test advice; no record is run again) on the stored records of campaign
output folders (``campaign --out DIR``, with or without ``--diagnose``), ``--repeat`` times each, and
prints each time and their median (target, issue 20: <= 15 s for 10 tests on 2 cores). The machine may
be shared: quote CPU time beside wall time.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):  # as the friction-uq command: before numpy loads
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def campaign(records: list[Path], out: Path, *, workers: int, pdf: bool) -> tuple[float, list, dict]:
    from friction_uq.campaigns import run_campaign

    t0 = time.perf_counter()
    outcome = run_campaign(records, out, workers=workers, pdf=pdf, progress=True)
    return time.perf_counter() - t0, outcome.results, outcome.doc


def row(label: str, workers: int, wall: float, results: list, base: float | None, doc: dict) -> str:
    cpu = sum(r.cpu_seconds for r in results)
    rss = max((r.peak_rss_mb for r in results), default=float("nan"))
    n = len(results)
    speed = f"{base / wall:8.2f}" if base else f"{'-':>8}"
    failed = sum(r.status == "failed" for r in results)
    return (f"{label:<10} {workers:>7} {n:>7} {failed:>6} {wall:>9.1f} {cpu:>10.1f} {wall / n:>10.1f} "
            f"{cpu / n:>9.1f} {speed} {rss:>12.0f} {doc.get('wall_seconds', {}).get('analysis', float('nan')):>10.1f}")


HEADER = (f"{'case':<10} {'workers':>7} {'records':>7} {'failed':>6} {'wall s':>9} {'CPU s':>10} {'wall/rec':>10} "
          f"{'CPU/rec':>9} {'speed-up':>8} {'worker MB':>12} {'analysis s':>10}")


def bundled(args: argparse.Namespace) -> None:
    records = sorted((ROOT / "data").glob("[AB]/*.h5"))
    lines, base = [], None
    for w in args.workers:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(args.keep) / f"workers{w}" if args.keep else Path(tmp)
            wall, results, doc = campaign(records, out, workers=w, pdf=args.pdf)
        lines.append(row("bundled", w, wall, results, base, doc))
        base = base or wall
        print("\n".join(doc["statements"]))
    print(HEADER)
    print("\n".join(lines))


def simulated(args: argparse.Namespace) -> None:
    from friction_uq.simulate import load_config, simulate_to_file

    rng = np.random.default_rng(args.seed)
    bases = [load_config(ROOT / "data" / "configs" / "A-01.toml"), load_config(ROOT / "data" / "configs" / "B-01.toml")]
    tmp = Path(tempfile.mkdtemp(prefix="bench_campaign_"))
    # kept when something fails: a re-run of the campaign in that folder skips what is done
    records = []
    t0 = time.perf_counter()
    for k in range(args.n):
        base = bases[k % 2]
        cfg = dataclasses.replace(base, test_id=f"{base.campaign}-{k:03d}", striker_velocity=float(rng.uniform(6, 14)),
                                  seed=int(rng.integers(2**31)))
        records.append(simulate_to_file(cfg, tmp / "records" / f"{cfg.campaign}-{k:03d}.h5"))
    print(f"simulated {args.n} records in {time.perf_counter() - t0:.1f} s (not counted below)")
    wall, results, doc = campaign(records, tmp / "out", workers=args.workers[0], pdf=False)
    print("\n".join(doc["statements"]))
    print(HEADER)
    print(row("simulated", args.workers[0], wall, results, None, doc))
    shutil.rmtree(tmp, ignore_errors=True)


def analysis(args: argparse.Namespace) -> None:
    from friction_uq.campaigns.analysis import analyse
    from friction_uq.campaigns.job import read_result

    print(f"{'campaign':<40} {'tests':>5} {'diagnosed':>9} {'analysis s (each run)':>24} {'median s':>9}")
    for folder in args.dirs:
        results = [read_result(p) for p in sorted(Path(folder, "records").glob("*.result.json"))]
        ok = [r for r in results if r.ok]
        diagnosed = sum(bool(r.settings.get("diagnose")) for r in ok)
        doc = Path(folder, "campaign.json")
        seed = json.loads(doc.read_text()).get("seed", 20161) if doc.exists() else 20161  # the campaign's own
        walls = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            analyse(results, Path(folder, "records"), seed=seed)
            walls.append(time.perf_counter() - t0)
        each = " ".join(f"{w:.1f}" for w in walls)
        print(f"{str(folder):<40} {len(ok):>5} {diagnosed:>9} {each:>24} {float(np.median(walls)):>9.1f}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", choices=("bundled", "simulated", "analysis"))
    p.add_argument("dirs", nargs="*", help="analysis: campaign output folders")
    p.add_argument("--repeat", type=int, default=3, help="analysis: runs of the analysis per folder (default 3)")
    p.add_argument("--workers", type=int, nargs="+", default=None)
    p.add_argument("--n", type=int, default=100, help="simulated records (default 100)")
    p.add_argument("--seed", type=int, default=2026)
    p.add_argument("--pdf", action="store_true", help="bundled: write the PDF reports too")
    p.add_argument("--keep", help="bundled: keep the campaign outputs in KEEP/workers<N> (fresh folders)")
    args = p.parse_args()
    args.workers = args.workers or ([1, 2] if args.case == "bundled" else [2])
    if args.case == "analysis" and not args.dirs:
        p.error("analysis needs campaign output folders")
    {"bundled": bundled, "simulated": simulated, "analysis": analysis}[args.case](args)


if __name__ == "__main__":
    main()
