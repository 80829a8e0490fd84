"""The tests whose runs warned, and the campaign's pooled f without them.

A run's warning says that its f may be biased (a misfit the model cannot explain, a force ratio that wanders over
the window, gauges out of balance, a hoop gauge that disagrees with nu's prior, ...). The campaign pools every
analysed test, since a warning is not a verdict that the test is wrong; but a person quoting the pooled f must know
which tests carried one, and whether the pooled f hangs on them. So the campaign lists the warned tests with their
counts (each run's JSON and report say why; the campaign's JSON lists every warning and its kind) and pools f again
on the same basis without them, where at least two tests are left: two population means that differ by more than
their intervals allow say the warned tests move the answer.

A misfit whose causes ``diagnose`` named (the run JSON's kind ``misfit_diagnosed``) keeps its warning, which says to
quote f under those causes. Where the campaign pools each test's diagnosed f, that f is the answer the warning asks
for, so such a warning does not count here (the statement says how many tests it spared); it does where the test's
pooled f is the stationary one (a campaign without ``--diagnose``, or a test whose hoop gauge and nu's prior disagree,
whose stationary readings are pooled in place of the diagnosed f).
"""

from __future__ import annotations

from collections.abc import Sequence

from .draws import RecordPosterior, f_draws
from .pooling import Pooled, pool

#: A warning's kind that a campaign pooling each test's diagnosed f answers (:mod:`friction_uq.record_run.warnings`).
ANSWERED_WHEN_DIAGNOSED = "misfit_diagnosed"


def open_warnings(t: RecordPosterior, basis: str) -> list[str]:
    """The test's warnings that f pooled on ``basis`` does not answer (module docstring)."""
    answered = basis == "diagnosed" and not t.hoop_disagrees and t.f_model is not None
    kinds = t.warning_kinds if len(t.warning_kinds) == len(t.warnings) else ("",) * len(t.warnings)
    return [w for w, kind in zip(t.warnings, kinds) if not (answered and kind == ANSWERED_WHEN_DIAGNOSED)]


def warned(tests: Sequence[RecordPosterior], basis: str = "stationary") -> list[RecordPosterior]:
    """The tests whose runs gave at least one warning that f pooled on ``basis`` does not answer."""
    return [t for t in tests if open_warnings(t, basis)]


def pooled_without_warned(tests: Sequence[RecordPosterior], pooled_f: Pooled | None) -> Pooled | None:
    """f pooled on ``pooled_f``'s basis from the tests whose runs did not warn (of anything that basis leaves open);
    None when none warned or there is no pooled f (a pooling of fewer than two tests comes back refused, with its
    reason)."""
    if pooled_f is None or not (marked := warned(tests, pooled_f.basis)):
        return None
    left_out = {id(t) for t in marked}
    kept = [t for t in tests if id(t) not in left_out]
    return pool(f_draws(kept, pooled_f.basis), "f", basis=pooled_f.basis)


def _spared(tests: Sequence[RecordPosterior], basis: str) -> str:
    """'N tests (...) warned only of a misfit whose causes diagnose named ...', or ''."""
    spared = [t for t in tests if t.warnings and not open_warnings(t, basis)]
    if not spared:
        return ""
    many = len(spared) > 1
    return (f"{len(spared)} {'tests' if many else 'test'} ({', '.join(t.label for t in spared)}) warned only of a "
            f"misfit whose causes diagnose named, and {'their' if many else 'its'} f under them is what is pooled")


def _count(t: RecordPosterior, basis: str) -> str:
    """A warned test as the statement lists it: its open warnings' count, 'of' all its warnings where some are
    answered."""
    n, total = len(open_warnings(t, basis)), len(t.warnings)
    return f"{t.label} ({n})" if n == total else f"{t.label} ({n} of {total})"


def warned_statement(tests: Sequence[RecordPosterior], pooled_f: Pooled | None, without: Pooled | None) -> str | None:
    """'tests whose runs warned (how many warnings): A A-03 (2), B B-02 (1 of 2) ...; pooled f without them: ...'
    (where a test's misfit is answered by the diagnosed f pooled, its count is of the others, 'of' all its warnings);
    the tests spared alone where only those warned; None when no run warned."""
    basis = pooled_f.basis if pooled_f is not None else "stationary"
    marked = warned(tests, basis)
    spared = _spared(tests, basis)
    if not marked:
        return f"{spared}; no other test's run warned" if spared else None
    listed = ", ".join(_count(t, basis) for t in marked)
    why = "each run's JSON and report say why; the campaign's JSON lists them" + (f"; {spared}" if spared else "")
    if len(marked) == len(tests):
        return (f"every test's run warned (how many warnings: {listed}; {why}): the pooled f rests on warned tests "
                "alone")
    head = f"tests whose runs warned (how many warnings: {listed}; {why}): the pooled f holds them"
    if without is None:
        return head
    if without.refused:
        return f"{head}; without them: {without.refused}"
    mu = without.mu
    said = "under each test's diagnosed model" if without.basis == "diagnosed" else "of the stationary analysis"
    return (f"{head}; pooled f {said} without them: population mean {mu['q50']:.4g} [{mu['q05']:.4g}, "
            f"{mu['q95']:.4g}] (90 %; {len(without.tests)} tests)")
