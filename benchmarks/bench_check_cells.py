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
    python benchmarks/bench_check_cells.py --load FILE [FILE ...] [--by-load]

``--load`` prints, per group, the records flagged before (the channels' own tolerances, one threshold for
every cell) and as the package applies the check (``CHECK_TOLERANCE``, ``CELL_THRESHOLD``), the cells over,
and the largest statistic of the cells with a threshold of their own and of the three other largest cells, as
applied. ``--by-load`` adds, per set-up, the statistic of the input bar's unloading against f V and of the external
bar's early rise against nu (where the clean axisymmetric records it flags sit; docs/trust.md).
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
                rows.append({"group": group, "k": k, "note": note, "cells": stats} | drawn(cfg, k))
    return rows


def drawn(cfg, k: int) -> dict:
    """What the record's test was drawn at: its set-up (A for even k, as ``make`` draws it), wall friction
    coefficient (None for a law other than Coulomb's), Poisson ratio and striker speed."""
    return {"setup": "AB"[k % 2], "f": cfg.friction_params.get("f"), "nu": cfg.poisson_ratio,
            "V": cfg.striker_velocity}


#: ``--by-load``: the cells whose statistic is shown against the test's load, the quantity it is binned by, the
#: bins' edges
BY_LOAD = ((("input_bar", "unloading"), "f V (m/s)", lambda r: r["f"] * r["V"], (0.0, 0.6, 0.9, 1.2, 9.0)),
           (("external_output_bar", "early rise"), "nu", lambda r: r["nu"], (0.0, 0.40, 0.44, 0.45, 1.0)))


def by_load(rows: list[dict]) -> str:
    """Each :data:`BY_LOAD` cell's statistic as applied, per set-up and bin of the test's load: where in the tested
    ranges the records flagged sit (rows saved without what they were drawn at, or of a law other than Coulomb's,
    are left out)."""
    rows = [r for r in rows if r.get("f") is not None]
    lines = [f"{'set-up':<6} {'cell':<32} {'bin':<18} {'n':>4} {'median':>7} {'90 %':>6} {'largest':>8} {'over':>5}"]
    for cell, label, key, edges in BY_LOAD:
        for setup in ("A", "B"):
            rs = [r for r in rows if r["setup"] == setup and cell in r["cells"]]
            v = np.array([key(r) for r in rs])
            st = np.array([applied(r["cells"], CHECK_TOLERANCE)[cell] for r in rs])
            for lo, hi in zip(edges[:-1], edges[1:]):
                on = (v >= lo) & (v < hi)
                if on.any():
                    lines.append(f"{setup:<6} {cell[0] + '/' + cell[1]:<32} {f'{label} {lo:g}-{hi:g}':<18} "
                                 f"{int(on.sum()):>4} {np.median(st[on]):>7.1f} {np.quantile(st[on], 0.9):>6.1f} "
                                 f"{st[on].max():>8.1f} {int(np.sum(st[on] > cell_threshold(*cell))):>5}")
    return "\n".join(lines)


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
    ap.add_argument("--by-load", action="store_true", help="also each BY_LOAD cell's statistic by the test's load")
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
    if a.by_load:
        print(by_load(rows))
    print(f"{len(rows)} records, {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
