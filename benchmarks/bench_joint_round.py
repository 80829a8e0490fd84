"""Two causes named together: when no single mechanism explains a first round's misfit, do the round's two leading
candidates, fitted together, explain it? The rule ``diagnose`` applies, measured on records it was not set on.

Issue 24 asks both causes of a pair named when both are at detectable strength. ``diagnose`` names one mechanism
per round, and a round names one only when its evidence against the reference is decisive and spread over the
record (the spread test leaves out the blocks that favour it most). With two effects in the record, each one's
model still misses what the other makes, and its evidence can sit at the other's fronts: the round is then
*unexplained* though each effect alone is named (``bench_pairs.py --alone``: seed 31's 1d-5, a dispersion with a
clearance). The rule (:mod:`friction_uq.discrepancy.joint_round`): on a first round that is *unexplained*, fit the
two candidates with the most evidence (decisive over the record, two different mechanisms one model can hold)
together; admit the pair when the joint model passes the naming rule against the reference (decisive and spread)
and against each of the two alone, and rules out every other candidate by dELPD. ``diagnose`` then asks the next
round to name the second on top of the first by the ordinary rule; that step is not made here, so a pair this
benchmark does not admit is named by neither, and one it admits is at most named.

On clean records of the axisymmetric simulation and of the perturbed 1-D one such a joint model must not pass (a
pair named where nothing is); on single effects it must not add a second, wrong, name; on pairs it should name both.
For each record the line gives the first round's verdict, and, where the rule applies, the joint model's evidence
(dELPD +- SE over the record, and without the blocks that favour it most) against the reference and each
candidate alone, whether the whole-record check still flags it, its f against the truth and the rule's answer.

    python benchmarks/bench_joint_round.py [--clean 20] [--per 1] [--pairs 29,31] [--seed 433] [--only GROUPS]
        [--names NAME,...] [--jsonl FILE]

Groups: ``clean_axisymmetric``, ``clean_perturbed`` and the single-effect groups of ``verdict_records.py``
(``--clean`` and ``--per`` records each, drawn with ``--seed``), and the pairs of ``bench_pairs.py`` drawn with
each seed of ``--pairs`` (``pair_1d``, ``pair_axisymmetric``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_diagnose import true_f  # noqa: E402
from bench_pairs import PAIRS_1D, PAIRS_AXISYMMETRIC, make_pair  # noqa: E402
from verdict_records import groups, make, write  # noqa: E402

from friction_uq.analysis import prepare  # noqa: E402
from friction_uq.discrepancy.diagnose import NAMING, diagnose  # noqa: E402
from friction_uq.discrepancy.joint_round import admitted, joint_job, leads  # noqa: E402
from friction_uq.discrepancy.extended import Diagnoser  # noqa: E402
from friction_uq.discrepancy.misfit import misfit_detected  # noqa: E402
from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.likelihood import Likelihood  # noqa: E402
from friction_uq.prior_loader import default_prior_path, load_priors  # noqa: E402
from friction_uq.record import read_record  # noqa: E402
from friction_uq.sampler import LogPosterior, start_ball  # noqa: E402


def first_round(path: str, priors, seed: int):
    """The record prepared, its first round of ``diagnose`` (as ``bench_diagnose.analyse``) and a Diagnoser built
    with the same inputs, for the joint fit."""
    prep = prepare(read_record(path))
    lp = LogPosterior(Likelihood(prep.data, hoop=True), priors)
    z_map, _ = start_ball(lp, priors, nwalkers=8, n_ensembles=1, rng=np.random.default_rng(seed))
    th = lp.to_theta(z_map)

    def log_prior(v):
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    start = {"f": th[0], "nu": th[1]}
    dg = diagnose(prep, log_prior, start, hoop=True, seed=seed, n_draws=1000, max_causes=1, nu_cut=True)
    maker = Diagnoser(prep, log_prior, hoop=True, seed=seed, n_draws=1000, nominal=start, nu_cut=True,
                      hoop_calibration=dg.hoop_calibration)
    return prep, dg, maker


def joint_test(prep, dg, maker) -> dict | None:
    """The rule on an unexplained first round, as ``diagnose`` admits a pair (:mod:`friction_uq.discrepancy.joint_round`:
    ``leads``, ``joint_job``, ``admitted``); None where it does not apply. The next round's confirmation, which
    ``diagnose`` then asks, is not made here: a pair not admitted is named by neither."""
    v = dg.verdicts[0]
    if v.kind != "unexplained":
        return None
    pair = leads(v, dg.rounds[0])
    if pair is None:
        return {"applies": False, "why": "fewer than two decisive candidates one model can hold"}
    a, b = pair
    joint = maker.fit_many([joint_job(a, b)], workers=2, cut=False)[0]
    evidence, refused = admitted(joint, dg.baseline, a, b, dg.rounds[0], NAMING)
    against = {k: dict(zip(("d", "se", "d_rest", "se_rest"), e)) for k, e in evidence.against.items()}
    resolved = maker.resolved(joint)
    fq = np.quantile(resolved.f_effective, [0.05, 0.5, 0.95])
    return {"applies": True, "pair": [a.fit.variants[-1].label, b.fit.variants[-1].label], "against": against,
            "passes": refused is None, "refused": refused,
            "still_flagged": bool(misfit_detected(prep, maker.predictive(joint))),
            "f": [float(x) for x in fq]}


def records(a, rng_seed: int):
    """(name, group, truth's mechanisms, configuration, edit, header, simulation seed) of every record asked for."""
    only = set(a.only.split(",")) if a.only else None
    r = np.random.default_rng(rng_seed)
    for g in groups():
        n = a.clean if g.startswith("clean") else a.per
        for k in range(n):
            cfg, edit, note, header = make(g, k, r)
            sim_seed = int(r.integers(2**31))
            if only is None or g in only:
                yield f"{g}-{k}", g, note, cfg, edit, header, sim_seed
    for seed in [int(s) for s in a.pairs.split(",") if s]:
        r = np.random.default_rng(seed)
        for sim, pairs in (("1d", PAIRS_1D), ("axisymmetric", PAIRS_AXISYMMETRIC)):
            for k, pair in enumerate(pairs):
                cfg, edit, header, note = make_pair(pair, sim == "axisymmetric", k, r)
                sim_seed = int(r.integers(2**31))
                g = f"pair_{sim}"
                if only is None or g in only:
                    yield f"{g}-{seed}-{k}", g, note, cfg, edit, header, sim_seed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clean", type=int, default=20)
    ap.add_argument("--per", type=int, default=1)
    ap.add_argument("--pairs", default="29,31")
    ap.add_argument("--seed", type=int, default=433)
    ap.add_argument("--only", help="comma-separated groups (clean_axisymmetric, pair_1d, ...)")
    ap.add_argument("--names", help="comma-separated record names (pair_1d-31-5, clean_axisymmetric-3, ...): these only")
    ap.add_argument("--jsonl", help="append each record's result to this file")
    a = ap.parse_args()
    priors = load_priors(default_prior_path("I1"))
    tmp = tempfile.mkdtemp()
    names = set(a.names.split(",")) if a.names else None
    for name, g, note, cfg, edit, header, sim_seed in records(a, a.seed):
        if names is not None and name not in names:
            continue
        path = os.path.join(tmp, f"{name}.h5")
        t = time.perf_counter()
        try:
            write(cfg, path, sim_seed, edit, header)
            prep, dg, maker = first_round(path, priors, seed=zlib.crc32(name.encode()) % 10_000)  # the name's
            out = joint_test(prep, dg, maker)
        except FrictionUQError as exc:
            print(f"{name}: refused: {exc}", flush=True)
            continue
        finally:
            if os.path.exists(path):
                os.remove(path)
        v = dg.verdicts[0]
        row = {"name": name, "group": g, "note": note, "truth_f": true_f(cfg, prep), "first": v.kind,
               "named": v.named, "candidates": [c.label for c in v.candidates if c.passes or c.decisive][:4],
               "joint": out, "seconds": time.perf_counter() - t}
        said = "-" if out is None else (out.get("why") or (
            f"{'+'.join(out['pair'])}: " + "; ".join(f"vs {k} {e['d']:.0f}+-{e['se']:.0f} (rest {e['d_rest']:.0f}"
                                                     f"+-{e['se_rest']:.0f})" for k, e in out["against"].items())
            + f"; flagged {out['still_flagged']}; f {out['f'][1]:.4f} [{out['f'][0]:.4f}, {out['f'][2]:.4f}]"
            + f"; {'ADMITTED' if out['passes'] else 'not admitted: ' + out['refused']}"))
        print(f"{name} ({note}): first round {v.kind}{' ' + v.named if v.named else ''}; truth f "
              f"{row['truth_f']:.4f}; joint: {said}; {row['seconds']:.0f} s", flush=True)
        if a.jsonl:
            with open(a.jsonl, "a") as fh:
                fh.write(json.dumps(row, default=float) + "\n")


if __name__ == "__main__":
    main()
