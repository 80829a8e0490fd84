"""The whole-record check's cells on clean records of three families and on records with a hidden effect.

For each record the statistic of every channel and phase of ``run``'s whole-record check is computed over
the tolerance grid of ``bench_check_tolerance.py`` and stored, so that the check's tolerances and thresholds
can be set and judged without fitting again. Groups (f, nu, striker speed, rise time and noise drawn as in
``bench_misfit.py``, both bundled set-ups; the makers of ``verdict_records.py``):

* ``clean``: the 1-D simulation, the likelihood's own family;
* ``clean_axisymmetric``: the axisymmetric simulation (plug, sample and tube in r-z);
* ``clean_perturbed``: the 1-D simulation perturbed in a way no mechanism describes (mesh, hoop kernel,
  incident pulse, coloured noise, one channel's timing within +-0.5 us);
* any group of ``verdict_records.groups()`` (a hidden mechanism in either simulation, a measurement-chain
  fault).

    python benchmarks/bench_check_cells.py --save FILE [--groups clean,clean_axisymmetric,...] [--n 40]
        [--seed 41]
    python benchmarks/bench_check_cells.py --load FILE [FILE ...]

``--load`` prints, per group, the records flagged before (the channels' own tolerances, one threshold for
every cell) and as the package applies the check (``CHECK_TOLERANCE``, ``CELL_THRESHOLD``), the cells over,
and the largest statistic of the cells with a threshold of their own and of the three other largest cells, as
applied.
"""

from __future__ import annotations

import argparse
import os
import pickle
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_check_tolerance import GRID, own, record_statistics  # noqa: E402
from verdict_records import make, write  # noqa: E402

from friction_uq.discrepancy.misfit import CELL_THRESHOLD, CHECK_TOLERANCE, THRESHOLD, cell_threshold  # noqa: E402


def collect(group: str, n: int, seed: int) -> list[dict]:
    """The cells' statistics of ``n`` records of ``group`` (a record refused is reported and left out)."""
    rng = np.random.default_rng([seed, sum(map(ord, group))])
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(n):
            t = time.perf_counter()
            cfg, edit, note, header = make(group, k, rng)
            path = os.path.join(tmp, f"{group}-{k}.h5")
            write(cfg, path, int(rng.integers(2**31)), edit, header)
            if (stats := record_statistics(path, seed, f"{group} {k} ({note})", t)) is not None:
                rows.append({"group": group, "k": k, "note": note, "cells": stats})
    return rows


def applied(cells: dict, table: dict) -> dict[tuple[str, str], float]:
    """Each cell's statistic under the tolerance ``table`` (the channel's own where it has none)."""
    return {c: float(v[GRID.index(table.get(c, own(c)))]) for c, v in cells.items()}


def flagged(cells: dict, table: dict, *, own_thresholds: bool = True) -> list[tuple[str, str]]:
    """The cells over their threshold under the tolerance ``table``: each cell's own threshold
    (:func:`cell_threshold`), or with ``own_thresholds`` False the record threshold for all."""
    return [c for c, s in applied(cells, table).items() if s > (cell_threshold(*c) if own_thresholds else THRESHOLD)]


def summary(rows: list[dict]) -> str:
    lines = [f"{'group':<32} {'n':>3} {'before':>7} {'applied':>8}  cells over (applied)  largest per cell (applied)"]
    for g in dict.fromkeys(r["group"] for r in rows):
        rs = [r for r in rows if r["group"] == g]
        n_own = sum(bool(flagged(r["cells"], {}, own_thresholds=False)) for r in rs)
        n_app = sum(bool(flagged(r["cells"], CHECK_TOLERANCE)) for r in rs)
        over: dict[str, int] = {}
        for r in rs:
            for c in flagged(r["cells"], CHECK_TOLERANCE):
                over[f"{c[0]}/{c[1]}"] = over.get(f"{c[0]}/{c[1]}", 0) + 1
        top: dict[tuple[str, str], float] = {}
        for r in rs:
            for c, s in applied(r["cells"], CHECK_TOLERANCE).items():
                top[c] = max(top.get(c, -np.inf), s)
        big = [(c, top[c]) for c in CELL_THRESHOLD if c in top]  # the cells of their own threshold, then the largest
        big += [kv for kv in sorted(top.items(), key=lambda kv: -kv[1]) if kv[0] not in CELL_THRESHOLD][:3]
        lines.append(f"{g:<32} {len(rs):>3} {n_own:>7} {n_app:>8}  "
                     f"{', '.join(f'{k} {v}' for k, v in over.items()) or '-'}  "
                     f"{', '.join(f'{c[0]}/{c[1]} {s:.1f}' for c, s in big)}")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--groups", default="clean,clean_axisymmetric,clean_perturbed")
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--seed", type=int, default=41)
    ap.add_argument("--save")
    ap.add_argument("--load", nargs="+")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    if a.load:
        for f in a.load:
            with open(f, "rb") as fh:
                rows += pickle.load(fh)
    else:
        for g in a.groups.split(","):
            rows += collect(g, a.n, a.seed)
        if a.save:
            with open(a.save, "wb") as fh:
                pickle.dump(rows, fh)
    print(f"threshold {THRESHOLD:g} (cells of their own: "
          f"{', '.join(f'{c[0]}/{c[1]} {t:g}' for c, t in CELL_THRESHOLD.items()) or 'none'}); "
          f"CHECK_TOLERANCE {CHECK_TOLERANCE!r}")
    print(summary(rows))
    print(f"{len(rows)} records, {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
