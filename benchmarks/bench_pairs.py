"""Two hidden effects at once: does ``diagnose`` name both, and does f's interval hold the truth?

Records (f, nu, striker speed, rise time and noise drawn as in ``bench_misfit.py``, both bundled set-ups):
eight pairs of effects on the 1-D simulation and eight on the axisymmetric one (:data:`PAIRS_1D`,
:data:`PAIRS_AXISYMMETRIC`), each effect at the strength of its single-effect study group
(``bench_diagnose.HIDDEN`` for the mechanisms of the cell, ``verdict_records.CHAIN_FAULTS`` for the faults
of the measurement chain). Each record goes through ``diagnose`` with all its rounds (up to
``MAX_CAUSES``), as ``friction-uq diagnose`` does.

Per record it prints the pair, each round's verdict, the causes named, the quoted f (the headline's: the
named model's, or the stacking mixture's; the baseline's when nothing needed explaining) against the truth
(the wall's coefficient at the window's mean sliding speed, pressure and slip), and the time. The table:
per simulator, how often both effects were named (as the JSON's ``causes`` says: a candidate fitted in turn
whose rivals no later round named is not named), one, a wrong cause named, both among the named causes and the
candidates listed, f covered by the 90 % interval of the f to quote (the output bars' calibration and the
whole-record models' form included), by the same without the form, and by the posterior's own (given the bars'
header values), and the first round's verdicts. Each record's line says how the exact posterior of the model
with the causes was obtained and its effective sample size.

    python benchmarks/bench_pairs.py [--seed 29] [--only 1d,axisymmetric] [--first 0] [--count 8] [--alone]

``--alone`` also makes each effect of a pair alone on the same record (the same draws of f, nu, speed and of the
other effect, the same noise; the other effect left out) and runs diagnose's first round on it: is the effect named
by itself at this strength? Issue 24 asks both causes of a pair named "when both are at detectable strength"; the
last lines count the pairs whose two effects are each named alone, and how many of those the pair names both of.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections import Counter

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_diagnose import HIDDEN, analyse, true_f  # noqa: E402
from bench_misfit import clean_config  # noqa: E402
from verdict_records import CHAIN_FAULTS, _axisymmetric, write  # noqa: E402

from friction_uq.discrepancy.diagnose import MAX_CAUSES  # noqa: E402
from friction_uq.discrepancy.diagnosed_f import quoted_of  # noqa: E402
from friction_uq.discrepancy.diagnosis_words import sentence  # noqa: E402
from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.prior_loader import default_prior_path, load_priors  # noqa: E402

#: Pairs on the 1-D simulation: the issue's two (a clearance with a velocity law; plug friction with a gauge's
#: gain), others of the cell with each other, and faults of the chain with effects of the cell.
PAIRS_1D = (("clearance", "velocity_friction"), ("plug_friction", "gauge_gain"), ("end_friction", "gauge_gain"),
            ("clearance", "pressure_friction"), ("plug_friction", "slip_friction"), ("dispersion", "clearance"),
            ("velocity_friction", "channel_timing"), ("plug_friction", "bar_modulus"))
#: Pairs on the axisymmetric simulation: only effects it has (plug friction, clearance, the friction laws) and
#: faults of the chain (made on its recorded strains).
PAIRS_AXISYMMETRIC = (("clearance", "velocity_friction"), ("plug_friction", "channel_timing"),
                      ("clearance", "pressure_friction"), ("plug_friction", "slip_friction"),
                      ("clearance", "bar_modulus"), ("velocity_friction", "channel_timing"),
                      ("plug_friction", "clearance"), ("pressure_friction", "bar_modulus"))


def make_pair(pair: tuple[str, str], axisymmetric: bool, k: int, r: np.random.Generator, keep: int | None = None):
    """The configuration simulated, the edit of its recorded strains (or None), the header's apparatus (or
    None: the configuration's) and a note, for record ``k`` with the two effects of ``pair``; with ``keep`` (0 or
    1), the same record with that effect alone: the other is drawn (the same draws follow) but not applied."""
    cfg = clean_config(r, "A" if k % 2 == 0 else "B")
    clean_header = cfg.apparatus
    edit, header, notes = None, None, []
    for j, effect in enumerate(pair):
        applied = keep is None or keep == j
        if effect in CHAIN_FAULTS:
            c, e, note = CHAIN_FAULTS[effect](cfg, r)
            if applied:
                cfg, edit = c, (e if e is not None else edit)
                header = clean_header if effect == "bar_modulus" else header
                notes.append(note)
        else:
            c = HIDDEN[effect](cfg, r)
            if applied:
                cfg = c
                notes.append(effect)
    if axisymmetric:
        cfg = _axisymmetric(cfg)
    return cfg, edit, header, " + ".join(notes)


def named_causes(dg) -> list[str]:
    """The causes the record is said to have, as the JSON's ``causes`` says (``Diagnosis.named_causes``: each
    round's named cause, and a round's candidate fitted in turn whose rivals later rounds named)."""
    return [v.mechanism.name for v in dg.named_causes]


def candidates_of(dg) -> list[str]:
    """The mechanisms a round listed as candidates: under "candidates" the best and its rivals, under
    "unexplained" or "unconfirmed" the models that carry the stacking weight."""
    out = []
    for verdict in dg.verdicts:
        by = {c.label: c.mechanism for c in verdict.candidates}
        if verdict.kind == "candidates":
            out += [by[label] for label in (verdict.named, *verdict.rivals)]
        elif verdict.kind in ("unexplained", "unconfirmed"):
            out += [by[label] for label in verdict.supported if label in by]
    return list(dict.fromkeys(out))


def score(pair: tuple[str, str], dg, cfg, prep) -> dict:
    named = named_causes(dg)
    # the diagnosed f with the output bars' calibration (friction_uq.quoted): the JSON's f when a cause or candidates
    # were found (when nothing needed explaining the JSON quotes the stationary f; this is the whole-record baseline's)
    fx = quoted_of(dg)
    f_calibration_only = quoted_of(dg, model_form=0.0)  # before the whole-record models' form was folded in
    draws = dg.mixture_f if dg.mixture_f is not None else dg.final.f_effective
    given = np.quantile(draws, [0.05, 0.95])  # the posterior's own interval, given the bars' header values
    truth = true_f(cfg, prep)
    among = set(named) | set(candidates_of(dg))
    return {"both": set(pair) <= set(named), "one": len(set(pair) & set(named)) == 1,
            "wrong": bool(set(named) - set(pair)), "kind": dg.verdicts[0].kind if dg.verdicts else "none",
            "both_among": set(pair) <= among, "candidates": candidates_of(dg),
            "covered": fx["q05"] <= truth <= fx["q95"], "covered_given_headers": bool(given[0] <= truth <= given[1]),
            "covered_calibration_only": f_calibration_only["q05"] <= truth <= f_calibration_only["q95"],
            "route": (f"{dg.posterior_method}, ESS {dg.importance_ess:.0f}"
                      f"{'' if dg.posterior_converged else ', short of its floor'}") if dg.causes else "-",
            "named": named, "f": fx, "truth": truth,
            "rounds": [v.kind for v in dg.verdicts]}


def named_alone(pair: tuple[str, str], j: int, axisymmetric: bool, k: int, state: dict, sim_seed: int, path: str,
                priors) -> tuple[bool, str]:
    """Effect ``j`` of the pair alone on record ``k`` (the pair's draws from ``state``, its noise from ``sim_seed``):
    whether diagnose's first round names it as the cause, and what that round said."""
    r = np.random.default_rng()
    r.bit_generator.state = state
    cfg, edit, header, _ = make_pair(pair, axisymmetric, k, r, keep=j)
    try:
        write(cfg, path, sim_seed, edit, header)
        _, dg = analyse(path, priors, seed=k, max_causes=1)
    except FrictionUQError as exc:  # refused alone as a pair may be: not named
        return False, f"refused: {exc}"
    finally:
        if os.path.exists(path):
            os.remove(path)
    v = dg.verdicts[0]
    said = v.kind + (f" {v.named}" if v.named else "")
    return bool(dg.cause is not None and dg.cause.mechanism.name == pair[j]), said


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=29)
    ap.add_argument("--only", default="1d,axisymmetric", help="simulators: 1d, axisymmetric or both")
    ap.add_argument("--first", type=int, default=0, help="first pair of each list to analyse")
    ap.add_argument("--count", type=int, default=8, help="pairs of each list to analyse")
    ap.add_argument("--sentences", action="store_true", help="print each record's diagnosis sentence")
    ap.add_argument("--alone", action="store_true", help="also each effect of a pair alone on the same record (the "
                    "same draws and noise, the other effect left out), through diagnose's first round: is it named "
                    "alone at this strength?")
    a = ap.parse_args()
    priors = load_priors(default_prior_path("I1"))
    rng = np.random.default_rng(a.seed)
    tmp = tempfile.mkdtemp()
    tally: dict[str, Counter] = {}
    secs = []
    for sim, pairs in (("1d", PAIRS_1D), ("axisymmetric", PAIRS_AXISYMMETRIC)):
        for k, pair in enumerate(pairs):
            state = rng.bit_generator.state  # the pair's draws, for its effects alone (--alone)
            cfg, edit, header, note = make_pair(pair, sim == "axisymmetric", k, rng)
            sim_seed = int(rng.integers(2**31))  # drawn for every record: the others do not move with --only
            if sim not in a.only.split(",") or not a.first <= k < a.first + a.count:
                continue
            c = tally.setdefault(sim, Counter())
            c["n"] += 1
            path = os.path.join(tmp, f"{sim}-{k}.h5")
            t = time.perf_counter()
            try:
                write(cfg, path, sim_seed, edit, header)
                prep, dg = analyse(path, priors, seed=k, max_causes=MAX_CAUSES)
            except FrictionUQError as exc:
                c["refused"] += 1
                print(f"{sim}-{k} ({note}): refused: {exc}", flush=True)
                continue
            secs.append(time.perf_counter() - t)
            s = score(pair, dg, cfg, prep)
            for key in ("both", "one", "wrong", "covered", "covered_given_headers", "covered_calibration_only",
                        "both_among"):
                c[key] += s[key]
            c[f"first:{s['kind']}"] += 1
            fx = s["f"]
            print(f"{sim}-{k} ({note}): rounds {s['rounds']}, named {s['named']}, candidates {s['candidates']}; "
                  f"f {fx['q50']:.4f} "
                  f"[{fx['q05']:.4f}, {fx['q95']:.4f}] truth {s['truth']:.4f}; exact posterior: {s['route']}; "
                  f"{secs[-1]:.0f} s", flush=True)
            if a.sentences:
                print("    " + sentence(dg, dg.baseline.f_summary()), flush=True)
            os.remove(path)
            if a.alone:
                alone = [named_alone(pair, j, sim == "axisymmetric", k, state, sim_seed, path, priors) for j in (0, 1)]
                print("    alone: " + ", ".join(f"{e} {'named' if ok else 'not named'} ({said})"
                                              for e, (ok, said) in zip(pair, alone)), flush=True)
                if all(ok for ok, _ in alone):
                    c["detectable"] += 1
                    c["both_detectable"] += s["both"]
    print(f"\n{'simulator':<13} {'n':>3} {'both':>5} {'one':>4} {'wrong':>6} {'both among':>10} {'f covered':>9} "
          f"{'calibration only':>16} {'given headers':>13} {'refused':>7}  first round's verdict")
    for sim, c in tally.items():
        kinds = ", ".join(f"{k.split(':', 1)[1]} {v}" for k, v in sorted(c.items()) if k.startswith("first:"))
        print(f"{sim:<13} {c['n']:>3} {c['both']:>5} {c['one']:>4} {c['wrong']:>6} {c['both_among']:>10} "
              f"{c['covered']:>9} {c['covered_calibration_only']:>16} {c['covered_given_headers']:>13} "
              f"{c['refused']:>7}  {kinds}")
    print("f covered: the f to quote (the JSON's: the output bars' calibration and the whole-record models' form "
          "included); calibration only: without the form; given headers: the posterior's own 90 % interval")
    if a.alone:
        for sim, c in tally.items():
            print(f"{sim}: both effects named alone on {c['detectable']} of {c['n']} pairs; both named in the pair on "
                  f"{c['both_detectable']} of those")
    if secs:
        print(f"time per record: median {np.median(secs):.0f} s, range {min(secs):.0f}-{max(secs):.0f} s")


if __name__ == "__main__":
    main()
