"""The whole-record likelihood's forward runs: the whole record against each gauge's span only.

    python benchmarks/bench_forward_spans.py [RECORD] [--repeat N]

A whole-record fit runs the 1-D simulator a few hundred times per model, and ``diagnose`` fits one model per entry
of the catalogue each round. The likelihood reads each gauge over its span only (the input bar's ends before its
reflected wave's far-end echo, the output bars' before theirs); the cell's history those samples need ends earlier
still, a gauge distance's travel before them. Since the fifty-eighth session the simulation stops there
(``SimulatorModel.predict(..., until=...)``; the samples read are the whole run's to the bit,
``tests/test_forward_spans.py``). Prints, for the baseline and each entry of the catalogue at its start, the
median milliseconds of one forward run each way, measured alternately in the same process, and the ratio.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from friction_uq.analysis import prepare
from friction_uq.discrepancy.extended import candidates
from friction_uq.discrepancy.fit import WholeRecordLikelihood
from friction_uq.models import SimulatorModel, measured_loading
from friction_uq.record import read_record

RECORD = Path(__file__).resolve().parents[1] / "data" / "A" / "A-03.h5"


def model_of(prep, variant) -> SimulatorModel:
    rec = prep.record

    def apply(values, settings, readings):
        if variant is not None:
            variant.mechanism.apply(values, settings, readings, variant.channel)

    extra = variant.mechanism.parameters if variant is not None else ()
    return SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces), extra=extra, apply=apply,
                          dispersive_loading=measured_loading(rec, prep.forces, dispersion=True))


def timed(run, repeat: int) -> tuple[float, float]:
    """Median milliseconds of ``run(None)`` and ``run(True)``, taken in turn ``repeat`` times after a warm-up."""
    run(None), run(True)
    whole, spans = [], []
    for _ in range(repeat):
        for out, arg in ((whole, None), (spans, True)):
            t = time.perf_counter()
            run(arg)
            out.append(1e3 * (time.perf_counter() - t))
    return statistics.median(whole), statistics.median(spans)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("record", nargs="?", default=str(RECORD))
    ap.add_argument("--repeat", type=int, default=15)
    a = ap.parse_args()
    prep = prepare(read_record(a.record))
    lik = WholeRecordLikelihood(prep, model_of(prep, None))
    until = {c: b[3] for c, b in lik.bounds.items()}
    n = prep.record.n_samples
    print(f"{Path(a.record).name}: {n} samples; spans end at " + ", ".join(f"{c} {k}" for c, k in until.items()))
    print(f"{'model':38s} {'whole (ms)':>10s} {'spans (ms)':>10s} {'ratio':>6s}")
    ratios = []
    for variant in (None, *candidates()):
        model = model_of(prep, variant)
        values = {"f": 0.05, "nu": 0.40, "hoop_gain": 1.0}
        if variant is not None:
            values |= dict(variant.mechanism.start)
        whole, spans = timed(lambda s: model.predict(values, until=until if s else None), a.repeat)
        ratios.append(whole / spans)
        label = "baseline" if variant is None else variant.label
        print(f"{label:38s} {whole:10.1f} {spans:10.1f} {whole / spans:6.2f}")
    print(f"median ratio {statistics.median(ratios):.2f} over {len(ratios)} models")


if __name__ == "__main__":
    main()
