"""The tests whose runs warned, and the campaign's pooled f without them.

A run's warning says that its f may be biased (a misfit the model cannot explain, a force ratio that wanders over
the window, gauges out of balance, a hoop gauge that disagrees with nu's prior, ...). Under ``--diagnose`` a test
whose misfit ``diagnose`` explained keeps the misfit's warning (it says which f to quote), so the pooled f without
the warned tests leaves out the tests whose f a named cause corrected too. The campaign pools every
analysed test, since a warning is not a verdict that the test is wrong; but a person quoting the pooled f must know
which tests carried one, and whether the pooled f hangs on them. So the campaign lists the warned tests with their
counts (each run's JSON and report say why; the campaign's JSON lists every warning) and pools f again on the same
basis without them, where at least two tests are left: two population means that differ by more than their
intervals allow say the warned tests move the answer.
"""

from __future__ import annotations

from collections.abc import Sequence

from .draws import RecordPosterior, f_draws
from .pooling import Pooled, pool


def warned(tests: Sequence[RecordPosterior]) -> list[RecordPosterior]:
    """The tests whose runs gave at least one warning."""
    return [t for t in tests if t.warnings]


def pooled_without_warned(tests: Sequence[RecordPosterior], pooled_f: Pooled | None) -> Pooled | None:
    """f pooled on ``pooled_f``'s basis from the tests whose runs did not warn; None when none warned or there is
    no pooled f (a pooling of fewer than two tests comes back refused, with its reason)."""
    if pooled_f is None or not warned(tests):
        return None
    kept = [t for t in tests if not t.warnings]
    return pool(f_draws(kept, pooled_f.basis), "f", basis=pooled_f.basis)


def warned_statement(tests: Sequence[RecordPosterior], without: Pooled | None) -> str | None:
    """'tests whose runs warned (how many warnings): A A-03 (2), B B-02 (1) ...; pooled f without them: ...'; None
    when no run warned."""
    marked = warned(tests)
    if not marked:
        return None
    listed = ", ".join(f"{t.label} ({len(t.warnings)})" for t in marked)
    why = "each run's JSON and report say why; the campaign's JSON lists them"
    if len(marked) == len(tests):
        return (f"every test's run warned (how many warnings: {listed}; {why}): the pooled f rests on warned tests "
                "alone")
    head = f"tests whose runs warned (how many warnings: {listed}; {why}): the pooled f holds them"
    if without is None:
        return head
    if without.refused:
        return f"{head}; without them: {without.refused}"
    mu = without.mu
    basis = "under each test's diagnosed model" if without.basis == "diagnosed" else "of the stationary analysis"
    return (f"{head}; pooled f {basis} without them: population mean {mu['q50']:.4g} [{mu['q05']:.4g}, "
            f"{mu['q95']:.4g}] (90 %; {len(without.tests)} tests)")
