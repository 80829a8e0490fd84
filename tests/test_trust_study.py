"""The study of issue 22 on records the likelihood did not make (``benchmarks/bench_trust.py``), slow.

At least 60 records from the project's simulator with settings the stationary model does not share
(stick-slip, strongly coloured noise, a drifting zero, gains 0.9-1.1, a sign flipped, the hidden
mechanisms of the catalogue) and clean ones, each through ``run``'s path. Required: no silent miss
(f more than 3 posterior sd from the truth with ``warnings`` empty), and warnings on at most 10 %
of the clean records.

A plug friction of 200-400 N + 1-2 % of the input force biases the stationary f by 15-40 % and the
stationary phase cannot tell it from wall friction; ``run`` warns through the whole-record check, which
tests the first half of the external output bar's rise, where the plug's force leads the wall friction, at
its own threshold (docs/trust.md). Its records are held to the same "no silent miss" as every other group.
"""

from __future__ import annotations

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
from bench_trust import silent_miss, study, table  # noqa: E402


@pytest.mark.slow
def test_no_confident_wrong_f_and_few_warnings_on_clean_records():
    rows = study(per=4, clean=12, seed=5, say=lambda line: None)
    print(table(rows))
    assert len(rows) >= 60
    misses = [r for r in rows if silent_miss(r)]
    assert not misses, misses
    clean = [r for r in rows if r["group"] == "clean"]
    assert all("truth" in r for r in clean)
    assert sum(bool(r["warnings"]) for r in clean) <= 0.1 * len(clean)
    # a flipped sign is refused naming the gauge as reversed, or analysed (the hoop gauge, then left out); every
    # other group reaches the analysis at least once (a study that refuses all is no study)
    assert all("truth" in r or "reversed" in r["refused"] for r in rows if r["group"] == "sign_flipped")
    groups = {r["group"] for r in rows} - {"sign_flipped"}
    assert all(any("truth" in r for r in rows if r["group"] == g) for g in groups)
    assert all(".h5: " in r["refused"] for r in rows if "refused" in r)  # every refusal names the file
