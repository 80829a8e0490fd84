"""The naming rule of ``diagnose`` (:mod:`friction_uq.discrepancy.verdict`) on records the 1-D likelihood did
not make: how often it names a cause on clean records, the right cause on records with one, and whether f's
interval then holds the truth.

Reads the first rounds stored by ``benchmarks/verdict_records.py`` (each model's pointwise block ELPD, its
draws of f and the whole-record check's decision) and applies the package's rule, and variants of it for
comparison, without fitting again:

    python benchmarks/verdict_records.py RECORDS [--clean 16 --per 3 --seed 17]   # about 1 min a record
    python benchmarks/bench_verdict.py RECORDS

Prints per group: records, verdicts (named / candidates / unexplained / none), the exact cause named, f's
90 % interval holding the truth (named: the named model's f; candidates or unexplained: the stacking
mixture's; none: the baseline's), the same with the output bars' calibration folded in ("+calib.") and with the
whole-record models' form beside it ("+form": the f to quote's fold, :mod:`friction_uq.quoted`), and the confusion
of first named causes; then the single effects split by whether the whole-record check saw a misfit (the effects
it does not see are not named by design), with the candidates that agree on one gauge's delay
(:mod:`friction_uq.discrepancy.front_delay`). f here is the normal approximation's (``diagnose`` then takes the named model's exact
posterior); the stationary analysis' half of a mixture (``diagnose``'s, when nothing is named) is not stored.
"""

from __future__ import annotations

import argparse
import dataclasses
import glob
import json
import os
import sys
from collections import Counter, defaultdict
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_diagnose import SHAPES  # noqa: E402
from bench_misfit import SETUPS  # noqa: E402

from friction_uq.discrepancy.candidates_mixture import mixture
from friction_uq.discrepancy.diagnose import Ranked
from friction_uq.discrepancy.diagnosed_f import folded_sd_of
from friction_uq.discrepancy.block_loo import Elpd, elpd_difference
from friction_uq.discrepancy.extended import Variant
from friction_uq.discrepancy.mechanisms import MECHANISMS
from friction_uq.discrepancy.front_delay import shared_delay
from friction_uq.discrepancy.verdict import NamingRule
from friction_uq.quoted import WHOLE_RECORD_MODEL_FORM, quoted_summary


def _elpd(a: dict, key: str, names) -> Elpd:
    return Elpd(a[f"{key}_pointwise"], float("nan"), a[f"{key}_calibration"], a[f"{key}_calibration_mean"],
                a[f"{key}_calibration_var"], tuple(names))


def load(folder: str) -> list[dict]:
    """The stored records: meta, the reference fit and the ranked candidates as the rule reads them."""
    out = []
    for path in sorted(glob.glob(os.path.join(folder, "*.npz"))):
        with np.load(path) as d:
            a = {k: d[k] for k in d.files}
        meta = json.loads(str(a.pop("meta")))
        ref = SimpleNamespace(label="reference", elpd=_elpd(a, "base", meta["base_calibration_names"]),
                              f_effective=a["base_f"], variants=())
        fits = [SimpleNamespace(label=m["label"], elpd=_elpd(a, f"m{i}", m["calibration_names"]),
                                f_effective=a[f"m{i}_f"], variants=(Variant(MECHANISMS[m["mechanism"]], m["channel"]),))
                for i, m in enumerate(meta["models"])]
        ranked = tuple(sorted((Ranked(f, *elpd_difference(f.elpd, ref.elpd)) for f in fits), key=lambda r: -r.delpd))
        out.append(meta | {"name": os.path.basename(path)[:-4], "reference": ref, "ranked": ranked})
    return out


def outcome(rec: dict, rule: NamingRule) -> dict:
    """The rule's verdict on one stored record, the f it would quote and whether that holds the truth."""
    v = rule.judge(rec["reference"], rec["ranked"], misfit=rec["misfit"], seed=0)
    fits = {"reference": rec["reference"]} | {r.fit.label: r.fit for r in rec["ranked"]}
    if v.kind in ("named", "none"):
        model = fits[v.named] if v.kind == "named" else rec["reference"]
        f, members, src = model.f_effective, [model], np.zeros(len(model.f_effective), int)
    else:
        f, w, src = mixture(rec["reference"], rec["ranked"], v, 0)
        members = [fits[k] for k in w]
    q05, q95 = np.quantile(f, [0.05, 0.95])
    named = None if v.named is None or v.kind != "named" else v.named.split("[")[0]
    truth = rec["truth_f"]

    def quoted_covers(model_form: float) -> bool:  # the f to quote's interval: each draw with its model's fold
        sd = np.array([folded_sd_of(m.variants, model_form) for m in members])[np.asarray(src, int)]
        q = quoted_summary(f, sd)
        return bool(q["q05"] <= truth <= q["q95"])

    return {"kind": v.kind, "named": named, "covered": bool(q05 <= truth <= q95),
            "quoted_calibration": quoted_covers(0.0), "quoted": quoted_covers(WHOLE_RECORD_MODEL_FORM),
            "candidates": [v.named, *v.rivals] if v.kind == "candidates" else [],
            "shared_delay": _shared_delay(rec, v) if v.kind == "candidates" else None}


def _shared_delay(rec: dict, v) -> object:
    """The delay the candidates agree on (:mod:`friction_uq.discrepancy.front_delay`), from the stored modes (the
    record's set-up from its index: A for even, B for odd, as ``verdict_records.make`` draws them)."""
    models = {m["label"]: m for m in rec["models"]}
    setup = "A" if int(rec["name"].rsplit("-", 1)[1]) % 2 == 0 else "B"
    fits = [(models[label]["mechanism"], models[label]["mode"]) for label in (v.named, *v.rivals)]
    return shared_delay(fits, SETUPS[setup].apparatus)  # None unless two or more delay-like mechanisms agree


def hidden(group: str) -> str | None:
    """The cause a group's records hold (a friction law at another shape: its family)."""
    if group.startswith("clean"):
        return None
    name = group.removeprefix("axisymmetric_")
    return SHAPES[name][0] if name in SHAPES else name


def table(records: list[dict], rule: NamingRule) -> str:
    rows = defaultdict(Counter)
    confusion = defaultdict(Counter)
    for rec in records:
        o = outcome(rec, rule)
        c = rows[rec["group"]]
        c["n"] += 1
        c[o["kind"]] += 1
        c["exact"] += o["named"] is not None and o["named"] == hidden(rec["group"])
        c["in_candidates"] += hidden(rec["group"]) in [x.split("[")[0] for x in o["candidates"] if x]
        c["covered"] += o["covered"]
        c["quoted_calibration"] += o["quoted_calibration"]
        c["quoted"] += o["quoted"]
        if hidden(rec["group"]) is not None:  # the effect records by what the whole-record check saw
            seen = "seen" if rec["misfit"] else "unseen"
            c[seen] += 1
            c[f"{seen}_exact"] += o["named"] is not None and o["named"] == hidden(rec["group"])
            c[f"{seen}_{o['kind']}"] += 1
            c["seen_delay"] += rec["misfit"] and o["shared_delay"] is not None
        confusion[rec["group"]][o["named"] or f"({o['kind']})"] += 1
    head = (f"{'group':<32} {'n':>3} {'named':>5} {'cand.':>5} {'unexpl.':>7} {'unconf.':>7} {'none':>4} {'exact':>5} "
            f"{'in cand.':>8} {'f cov.':>6} {'+calib.':>7} {'+form':>5}  first named cause (or verdict)")
    lines = [head]
    for g in sorted(rows):
        c = rows[g]
        conf = ", ".join(f"{k} {v}" for k, v in confusion[g].most_common())
        lines.append(f"{g:<32} {c['n']:>3} {c['named']:>5} {c['candidates']:>5} {c['unexplained']:>7} "
                     f"{c['unconfirmed']:>7} {c['none']:>4} "
                     f"{c['exact']:>5} {c['in_candidates']:>8} {c['covered']:>6} {c['quoted_calibration']:>7} "
                     f"{c['quoted']:>5}  {conf}")
    clean = [g for g in rows if g.startswith("clean")]
    effect = [g for g in rows if not g.startswith("clean")]

    def share(groups, key):
        return share_of(rows, groups, key, "n")

    lines.append(f"clean records with a cause named: {share(clean, 'named')}; single effects with the exact cause: "
                 f"{share(effect, 'exact')}; f covered on effect records: {share(effect, 'covered')} (with the bars' "
                 f"calibration {share(effect, 'quoted_calibration')}, and the whole-record form {share(effect, 'quoted')})"
                 f", on clean: {share(clean, 'covered')} ({share(clean, 'quoted_calibration')}, {share(clean, 'quoted')})")
    lines.append(f"of the single effects the whole-record check sees (a misfit), {share(effect, 'seen')}: exact cause "
                 f"{share_of(rows, effect, 'seen_exact', 'seen')}, candidates {share_of(rows, effect, 'seen_candidates', 'seen')} "
                 f"({sum(rows[g]['seen_delay'] for g in effect)} of them agreeing on one gauge's delay), unexplained "
                 f"{share_of(rows, effect, 'seen_unexplained', 'seen')}, a wrong cause named "
                 f"{sum(rows[g]['seen_named'] - rows[g]['seen_exact'] for g in effect)}; the check sees no misfit on "
                 f"{share(effect, 'unseen')} (exact {sum(rows[g]['unseen_exact'] for g in effect)})")
    return "\n".join(lines)


def share_of(rows, groups, key: str, of: str) -> str:
    """'k/n': the count ``key`` over the count ``of``, summed over ``groups``."""
    return f"{sum(rows[g][key] for g in groups)}/{sum(rows[g][of] for g in groups)}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("records")
    a = ap.parse_args()
    records = load(a.records)
    rule = NamingRule()
    variants = {
        "the package's rule": rule,
        "without the weight route (rivals ruled out by 2 SE of dELPD only)": dataclasses.replace(rule, by_weight=False),
        "without the misfit gate": dataclasses.replace(rule, require_misfit=False),
        "against passing rivals only": dataclasses.replace(rule, against_all=False),
        "no spread test": dataclasses.replace(rule, drop_fraction=0.0),
        "spread test 10 %": dataclasses.replace(rule, drop_fraction=0.10),
    }
    for name, r in variants.items():
        print(f"\n== {name}: {r}")
        print(table(records, r))


if __name__ == "__main__":
    sys.exit(main())
