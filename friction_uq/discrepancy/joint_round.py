"""Two causes named together where neither alone explains the misfit.

With two effects in a record, each one's model still misses what the other makes, and its evidence can sit at the
other's fronts: no mechanism passes the naming rule alone and the first round is *unexplained*, though each effect
alone would be named (a bars' dispersion with a clearance of the sample in its tube). On such a round the two
candidates with the most evidence (each decisive against the reference over the record, two different mechanisms)
are fitted together. The pair is admitted (:func:`admitted`) when the joint model

* passes the naming rule against the round's reference: decisive, and decisive with the blocks that favour it most
  left out (spread over the record);
* passes it against each of the two alone (each is needed, and not at a few blocks);
* rules out every other candidate of the round by dELPD (:meth:`.verdict.NamingRule.ruling`'s "elpd": over the
  record, or without the blocks most in its favour against that candidate).

The first of the two (by its evidence alone) then joins the model as the round's cause (:attr:`.verdict.Verdict.joint`),
and the next round must name the second by the ordinary rule, every other mechanism fitted on top of the first as in
any round; if it does not, the round is read as it was (unexplained, f the candidates' mixture) and the search stops
(``diagnose._search``). Only a first round is read so: the rule is measured there (``benchmarks/bench_joint_round.py``,
docs/trust.md). A pair tried and not named leaves its evidence and the reason (:class:`PairTrial`): a reader of an
unexplained verdict is told that the two fitted together did not explain it either, and why.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from ..stats import RULE
from ..stats.trimmed import points_to_drop
from .block_loo import elpd_difference


@dataclass(frozen=True)
class JointEvidence:
    """The joint model of a round's two leading candidates against the round's reference and each of the two alone:
    label ("reference", or a candidate's variant label) -> (dELPD, SE over the record, dELPD, SE without the blocks
    most in the joint model's favour); ``partner`` the second candidate's variant label, named by the next round."""

    partner: str
    against: Mapping[str, tuple[float, float, float, float]]


@dataclass(frozen=True)
class PairTrial:
    """A first round's two leading candidates fitted together: their variant labels (the first, then its partner), the
    joint model's evidence, why the two were not named together (None: they were), and whether the pair passed its
    own tests (:func:`admitted`; then only the next round's confirmation can have refused it)."""

    round: int
    causes: tuple[str, str]
    evidence: JointEvidence
    refused: str | None = None
    admitted: bool = False


def leads(verdict, ranked: Sequence) -> tuple | None:
    """The two candidates (:class:`~.diagnosis.Ranked`) with the most evidence against the reference of an unexplained
    round, each decisive over the record by the package's rule, of two different mechanisms that one model can hold
    (not two of one group: one friction law at a time); None when fewer than two are."""
    if verdict.kind != "unexplained":
        return None
    out: list = []
    for r in ranked:  # by dELPD
        m = r.fit.variants[-1].mechanism
        if r.decisive and all(_together(x.fit.variants[-1].mechanism, m) for x in out):
            out.append(r)
        if len(out) == 2:
            return tuple(out)
    return None


def _together(m, n) -> bool:
    """Whether one model holds mechanisms ``m`` and ``n``: two different ones, not of one group."""
    return m.name != n.name and (m.group is None or m.group != n.group)


def joint_job(a, b) -> tuple[tuple, dict[str, float], str]:
    """The fit job (variants, start, label) of the two leading candidates together: from the first's mode, the
    second's own parameters from its mode."""
    fa, fb = a.fit, b.fit
    start = dict(fa.fit.mode) | {k: x for k, x in fb.fit.mode.items() if k not in fa.fit.mode}
    return (fa.variants[-1], fb.variants[-1]), start, f"{fa.label}+{fb.label}"


def joint_evidence(joint, reference, a, b, rule) -> JointEvidence:
    """The joint model against the round's ``reference`` and each of ``a``, ``b`` (:func:`leads`) alone: dELPD and SE
    over the record and without the blocks most in its favour (the naming rule's ``drop_fraction``)."""
    drop = points_to_drop(len(reference.elpd.pointwise), rule.drop_fraction)
    against = {label: (*elpd_difference(joint.elpd, other.elpd), *elpd_difference(joint.elpd, other.elpd, drop=drop))
               for label, other in (("reference", reference), (a.fit.variants[-1].label, a.fit),
                                    (b.fit.variants[-1].label, b.fit))}
    return JointEvidence(b.fit.variants[-1].label, against)


def admitted(joint, reference, a, b, ranked: Sequence, rule) -> tuple[JointEvidence, str | None]:
    """The joint model's evidence (:func:`joint_evidence`) and why it does not admit the pair (module docstring; None
    when it does). ``reference``: the round's; ``a``, ``b``: :func:`leads`; ``ranked``: the round's candidates;
    ``rule``: the :class:`~.verdict.NamingRule`."""
    evidence = joint_evidence(joint, reference, a, b, rule)
    failed = []  # every comparison the pair fails, in the order reference, a, b
    for label, (d, se, dt, st) in evidence.against.items():
        other = "the round's reference model" if label == "reference" else f"{label} alone"
        if not RULE.decisive(d, se):
            failed.append(f"not decisive against {other} ({_whole(d)} +- {_whole(se)} nats)")
        elif not RULE.decisive(dt, st):
            failed.append(f"their gain over {other} is carried by a few blocks ({_whole(d)} +- {_whole(se)} nats; "
                          f"{_whole(dt)} +- {_whole(st)} without the {100 * rule.drop_fraction:.0f} % most in its "
                          "favour)")
    if failed:
        return evidence, "; ".join(failed)
    drop = points_to_drop(len(reference.elpd.pointwise), rule.drop_fraction)
    pair = {a.fit.label, b.fit.label}
    for r in ranked:
        if r.fit.label not in pair and rule.ruling(joint.elpd, r.fit.elpd, weight=1.0, drop=drop,
                                                   carried=True) != "elpd":
            return evidence, f"does not rule out {r.fit.variants[-1].label}"
    return evidence, None


def _whole(x: float) -> str:
    """``x`` to the nat, a negative zero written 0."""
    out = f"{x:.0f}"
    return "0" if out == "-0" else out


def confirms(verdict, ranked: Sequence, partner: str) -> bool:
    """Whether the round after a pair's first cause names its partner (variant label ``partner``) by the ordinary
    rule, with no rival left open and not merely kept within the check's tolerance."""
    if verdict.kind != "named" or verdict.within_tolerance:
        return False
    best = next(r for r in ranked if r.fit.label == verdict.named)
    return best.fit.variants[-1].label == partner


def not_confirmed(verdict, ranked: Sequence, partner: str, first: str, k: int) -> str:
    """Why round ``k`` (1-based; ``ranked``: its candidates), the one after a pair's first cause ``first``, did not
    confirm its ``partner`` (:func:`confirms`): what that round found instead. Round ``k`` is judged as a later round:
    with no misfit flagged it names nothing ("none")."""
    best = next((r.fit.variants[-1].label for r in ranked if r.fit.label == verdict.named), verdict.named)
    found = {"named": f"it named {best}", "candidates": f"{best} and its rivals stayed candidates",
             "unexplained": "its misfit stayed unexplained"}
    said = (f"{best} stayed in the model within the check's tolerance, not named"
            if verdict.within_tolerance else found.get(verdict.kind, "no mechanism passed the naming rule"))
    return f"round {k} did not name {partner} on top of {first} ({said})"
