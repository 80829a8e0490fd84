"""Set-ups and tests that do not follow the shared law, and the per-record causes tallied beside them.

A set-up is flagged when the best law with a multiplicative offset on that set-up beats the law
without it decisively (leave-one-test-out dELPD > 4 and > t(0.975, tests - 1) SE). With two set-ups and a
named law with a pressure term, a set-up is also flagged when, among every law with and without its offset,
those with it carry the stacking weight (``friction_uq.campaigns.analysis``: one set-up's bars put all its
tests at other pressures, and a pressure term can stand for its offset). With exactly two set-ups an
offset on one is the same model as an offset on the other: the campaign then says that the two
disagree, by how much, and lets the per-record causes (when a diagnosis named them) say which: the
set-up where a cause was named that the other set-up never shows.

A test is flagged when its own leave-one-out predictive density under the chosen model is an
outlier: a pointwise ELPD more than 4 below the median of the others (a test the law and the
between-test scatter do not explain).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

import numpy as np

from .job import RecordResult
from ..stats import RULE, paired_difference
from .laws import Elpd

TEST_OUTLIER_ELPD = 4.0


def tally_causes(results: Sequence[RecordResult]) -> dict[str, dict[str, object]]:
    """Per set-up: tests analysed, tests diagnosed, and how many tests named each cause.

    ``causes`` is None on a result no diagnosis was made for; such tests count in ``tests`` but
    not in ``diagnosed``. A cause named twice in one test counts once.
    """
    out: dict[str, dict[str, object]] = {}
    for r in results:
        if not r.ok:
            continue
        entry = out.setdefault(str(r.campaign), {"tests": 0, "diagnosed": 0, "causes": Counter()})
        entry["tests"] += 1
        if r.causes is not None:
            entry["diagnosed"] += 1
            entry["causes"].update(set(r.causes))
    return {k: {"tests": v["tests"], "diagnosed": v["diagnosed"], "causes": dict(sorted(v["causes"].items()))}
            for k, v in sorted(out.items())}


def causes_sentence(setup: str, tally: dict[str, object]) -> str:
    """E.g. 'set-up B: 5 tests, 5 diagnosed; plug friction named in 5, gauge gain in 1'."""
    causes = tally.get("causes") or {}
    head = f"set-up {setup}: {tally['tests']} tests, {tally['diagnosed']} diagnosed"
    if not tally["diagnosed"]:
        return head + " (no per-record diagnosis in these results: campaign --diagnose names the causes)"
    if not causes:
        return head + "; no cause named"
    return head + "; " + ", ".join(f"{c} named in {n}" for c, n in sorted(causes.items(), key=lambda kv: -kv[1]))


def setup_flags(base: Elpd, with_offset: dict[str, tuple[Elpd, dict[str, float]]], setups: Sequence[str],
                tallies: dict[str, dict[str, object]], *, quantity: str = "kappa") -> list[dict[str, object]]:
    """One entry per set-up whose offset model beats the shared law decisively (``quantity``: what the law
    was fitted to, kappa or f)."""
    flags = []
    for s, (e, delta) in with_offset.items():
        d, se = paired_difference(e.pointwise, base.pointwise)
        if RULE.decisive(d, se, n=e.pointwise.size):
            flags.append(setup_entry(s, delta, d, se, setups, tallies, quantity=quantity))
    return flags


def setup_entry(s: str, delta: dict[str, float], d: float, se: float, setups: Sequence[str],
                tallies: dict[str, dict[str, object]], *, quantity: str) -> dict[str, object]:
    """The flag of set-up ``s``: its offset ``delta`` (a summary), the evidence (dELPD ``d`` +- ``se``), and with
    two set-ups which of them the per-record causes point at."""
    other = [x for x in setups if x != s]
    pair = len(setups) == 2
    entry: dict[str, object] = {
        "setup": s, "basis": quantity, "offset": delta, "d_elpd": d, "d_se": se,
        "tests": int(tallies.get(s, {}).get("tests", 0)),
    }
    if pair:
        entry["relative_to"] = other[0]
        entry["note"] = (f"with two set-ups an offset on {s} is an offset on {other[0]}: they disagree by "
                         f"{delta['q50'] * 100:+.0f} % on {quantity}; which one is off needs a third set-up or "
                         "the per-record causes")
        own = {x: set(tallies.get(x, {}).get("causes") or {}) for x in setups}
        only = {x: sorted(own[x] - own[y]) for x, y in ((s, other[0]), (other[0], s))}
        named = s if only[s] and not only[other[0]] else other[0] if only[other[0]] and not only[s] else None
        if named is not None:
            entry["named_by_causes"], entry["causes_only_here"] = named, only[named]
            entry["note_causes"] = f"named only in set-up {named}: " + ", ".join(only[named])
    entry["causes"] = {x: causes_sentence(x, tallies[x]) for x in ([s] + (other if pair else [])) if x in tallies}
    return entry


def outlier_tests(chosen: Elpd, labels: Sequence[str]) -> list[dict[str, object]]:
    """Tests whose leave-one-out density is far below the others' under the chosen model."""
    pw = chosen.pointwise
    out = []
    for i, lab in enumerate(labels):
        rest = np.delete(pw, i)
        gap = float(np.median(rest) - pw[i])
        if gap > TEST_OUTLIER_ELPD:
            out.append({"test": lab, "elpd_loo": float(pw[i]), "below_median_by": gap})
    return out
