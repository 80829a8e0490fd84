"""Do ``diagnose``'s verdicts hold when only the random seed changes?

Each record goes through ``friction-uq diagnose RECORD --seed S --no-pdf`` (the command a user runs: the
stationary sampler, the whole-record check and every round of the search) with several seeds; the seed moves
the sampler's draws, the mode search's start, the Laplace draws, the stacking weights' bootstrap and the
mixture's draws. Per record it prints each seed's verdict (the JSON's ``discrepancy.verdict``), its causes
(with the gauge of a gain) and the headline f with its 90 % interval, and whether the verdict and the causes
are the same for every seed. Issue 24 point 6 asks the same named causes with 5 seeds on every bundled record
and every study group.

    python benchmarks/bench_stability.py [RECORD ...] [--seeds 1,2,3,4,5]
    python benchmarks/bench_stability.py --groups all|GROUP,... [--per 1] [--seed 23] [--seeds 1,2,3,4,5]

Without records: the bundled ones (data/A, data/B). With ``--groups``: ``--per`` records of each study group of
``verdict_records.py`` (a clean record of the axisymmetric simulation or of the 1-D one perturbed, a hidden
mechanism in either simulation, a fault of the measurement chain), simulated with ``--seed`` and written to a
temporary folder first; the record's seed is not one of the sampler's.
"""

from __future__ import annotations

import argparse
import contextlib
import glob
import io
import json
import os
import statistics
import sys
import tempfile
import time

import numpy as np

from friction_uq import cli
from friction_uq.errors import FrictionUQError

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def diagnose_once(path: str, seed: int, out: str) -> dict:
    """The JSON of ``friction-uq diagnose path --seed seed --no-pdf`` (written in ``out``)."""
    with contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(["diagnose", path, "--seed", str(seed), "--no-pdf", "--quiet", "--out", out])
    if code != 0:
        return {"error": f"exit {code}"}
    (name,) = [f for f in os.listdir(out) if f.endswith(".json")]
    with open(os.path.join(out, name)) as fh:
        return json.load(fh)


def verdict_of(doc: dict) -> tuple[str, tuple[str, ...]]:
    """(verdict, causes) of a run's JSON: a gain's cause with its gauge."""
    if "error" in doc:
        return doc["error"], ()
    d = doc.get("discrepancy") or {}
    causes = tuple(c["name"] + (f"[{c['channel']}]" if c.get("channel") else "") for c in d.get("causes", []))
    return str(d.get("verdict")), causes


def study_records(names: str, per: int, seed: int, folder: str) -> list[str]:
    """``per`` records of each group in ``names`` (comma-separated, or "all") written in ``folder``."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from verdict_records import groups, make, write

    chosen = groups() if names == "all" else [g for g in names.split(",") if g]
    unknown = sorted(set(chosen) - set(groups()) - {"clean"})
    if unknown:
        raise SystemExit(f"unknown group(s) {', '.join(unknown)}; known: clean, {', '.join(groups())}")
    paths = []
    for group in chosen:
        rng = np.random.default_rng([seed, sum(map(ord, group))])
        for k in range(per):
            cfg, edit, note, header = make(group, k, rng)
            path = os.path.join(folder, f"{group}-{k}.h5")
            try:
                write(cfg, path, int(rng.integers(2**31)), edit, header)
            except FrictionUQError as exc:  # a record the simulator refuses: said, and the study goes on
                print(f"{os.path.basename(path)} ({note}) refused: {exc}", flush=True)
                continue
            print(f"{os.path.basename(path)}: {note}", flush=True)
            paths.append(path)
    return paths


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("records", nargs="*")
    ap.add_argument("--seeds", default="1,2,3,4,5")
    ap.add_argument("--groups", help='study groups of verdict_records.py (comma-separated, or "all")')
    ap.add_argument("--per", type=int, default=1, help="records of each group")
    ap.add_argument("--seed", type=int, default=23, help="the seed the groups' records are simulated with")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        if a.groups:
            records = a.records + study_records(a.groups, a.per, a.seed, folder)
        else:
            records = a.records or sorted(glob.glob(os.path.join(ROOT, "data", "[AB]", "*.h5")))
        check(records, [int(s) for s in a.seeds.split(",")], a.seeds)


def check(records: list[str], seeds: list[int], label: str) -> None:
    """Each record diagnosed with every seed: its verdicts and causes, and whether they agree."""
    stable = 0
    secs = []
    for path in records:
        rows = []
        for seed in seeds:
            t = time.perf_counter()
            with tempfile.TemporaryDirectory() as out:
                doc = diagnose_once(path, seed, out)
            secs.append(time.perf_counter() - t)
            kind, causes = verdict_of(doc)
            f = doc.get("f", {})
            rows.append((seed, kind, causes, f))
            print(f"{os.path.basename(path)} seed {seed}: {kind} {list(causes)}; f {f.get('q50', float('nan')):.4f} "
                  f"[{f.get('q05', float('nan')):.4f}, {f.get('q95', float('nan')):.4f}]; {secs[-1]:.0f} s",
                  flush=True)
        same = len({(k, c) for _, k, c, _ in rows}) == 1
        stable += same
        print(f"{os.path.basename(path)}: {'the same verdict and causes' if same else 'NOT the same'} with "
              f"{len(seeds)} seeds", flush=True)
    if secs:
        print(f"\n{stable} of {len(records)} records give the same verdict and causes with seeds {label}; "
              f"diagnose's time per run: median {statistics.median(secs):.0f} s")


if __name__ == "__main__":
    main()
