"""The f to quote when ``diagnose`` names no cause, on records the 1-D likelihood did not make: the stationary
analysis' f, the candidates' stacking mixture and their equal mixture (what ``diagnose`` quotes since the
eighteenth session, :mod:`friction_uq.discrepancy.candidates_mixture`), each against the truth.

Records as ``verdict_records.py`` makes them (its groups: clean axisymmetric and perturbed 1-D records, the
measurement-chain faults in the axisymmetric simulation, hidden mechanisms in either), each through
``friction_uq.run(..., diagnose=True)``. Prints per group: records, verdicts, and for each of the three f's the
90 % interval holding the truth (the output bars' calibration folded in, as the JSON's f) and its median width
over the truth; then the width of the equal mixture over the candidates' alone where a mixture was quoted.

    python benchmarks/bench_no_cause_quote.py [--per 6] [--seed 43] [--groups clean_axisymmetric,...]

About 40-60 s a record on 2 cores.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections import Counter, defaultdict

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_diagnose import true_f  # noqa: E402
from verdict_records import make, write  # noqa: E402

import friction_uq as fu  # noqa: E402
from friction_uq.discrepancy.candidates_mixture import STATIONARY  # noqa: E402
from friction_uq.discrepancy.diagnosed_f import _folded, f_draws_to_quote  # noqa: E402
from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.quoted import folded_sd, quoted_summary  # noqa: E402

GROUPS = ("clean_axisymmetric,clean_perturbed,axisymmetric_zero_drift,axisymmetric_bandwidth,"
          "axisymmetric_bar_modulus,axisymmetric_channel_timing,axisymmetric_plug_friction")


def interval(draws: np.ndarray, sd) -> tuple[float, float]:
    s = quoted_summary(draws, sd)
    return s["q05"], s["q95"]


def three(res) -> tuple[str, dict[str, tuple[float, float]]]:
    """The record's verdict and the three intervals (module docstring)."""
    d = res.details
    dg = d.diagnosis
    st = interval(d.samples.flat("f"), folded_sd())
    quoted = (res.f["q05"], res.f["q95"])
    kind = ("named" if dg.named_causes else dg.verdict.kind) if dg is not None and dg.verdict else "none"
    if dg is None or dg.named_causes or STATIONARY not in dg.mixture_weights:
        return kind, {"stationary": st, "candidates": quoted, "equal mixture": quoted}
    src = np.asarray(dg.mixture_source, int)
    cand = src != list(dg.mixture_weights).index(STATIONARY)
    sds = np.broadcast_to(_folded(dg), src.shape)
    return kind, {"stationary": st, "candidates": interval(f_draws_to_quote(dg)[cand], sds[cand]),
                  "equal mixture": quoted}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per", type=int, default=6)
    ap.add_argument("--seed", type=int, default=43)
    ap.add_argument("--groups", default=GROUPS)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    tmp = tempfile.mkdtemp()
    rows: dict[str, list] = defaultdict(list)
    for g in a.groups.split(","):
        for k in range(a.per):
            cfg, edit, note, header = make(g, k, rng)
            path = os.path.join(tmp, f"{g}-{k}.h5")
            try:
                write(cfg, path, int(rng.integers(2**31)), edit, header)
                res = fu.run(path, out_dir=os.path.join(tmp, "out"), seed=k + 1, pdf=False, diagnose=True)
            except FrictionUQError as exc:
                print(f"{g}-{k}: refused: {exc}", flush=True)
                continue
            truth = true_f(cfg, res.details.prepared)
            kind, iv = three(res)
            rows[g].append((truth, kind, iv))
            print(f"{g}-{k} ({note}): truth {truth:.4f}, {kind}, "
                  + ", ".join(f"{n} [{lo:.4f}, {hi:.4f}]" for n, (lo, hi) in iv.items()), flush=True)
    names = ("stationary", "candidates", "equal mixture")
    print("\n| group | n | verdicts | " + " | ".join(f"{n}: covered (width)" for n in names)
          + " | equal / candidates width, where mixed |")
    print("|---" * (len(names) + 4) + "|")
    for g, rs in rows.items():
        cells = []
        for n in names:
            cov = sum(lo <= t <= hi for t, _, iv in rs for lo, hi in [iv[n]])
            width = np.median([(iv[n][1] - iv[n][0]) / t for t, _, iv in rs])
            cells.append(f"{cov}/{len(rs)} ({width:.2f})")
        ratio = [(iv[names[2]][1] - iv[names[2]][0]) / (iv[names[1]][1] - iv[names[1]][0])
                 for _, _, iv in rs if iv[names[2]] != iv[names[1]]]
        verdicts = ", ".join(f"{k} {c}" for k, c in Counter(kind for _, kind, _ in rs).most_common())
        r = f"{np.median(ratio):.2f} ({min(ratio):.2f}-{max(ratio):.2f})" if ratio else "-"
        print(f"| {g} | {len(rs)} | {verdicts} | " + " | ".join(cells) + f" | {r} |")


if __name__ == "__main__":
    main()
