"""The package's JSON is strict (RFC 8259): non-finite numbers are null, every parser reads it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from friction_uq._json_text import finite_or_null, json_text


def strict_loads(text: str):
    """json.loads that refuses NaN and Infinity, as JavaScript's JSON.parse does."""
    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")
    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_are_null_and_numpy_values_plain():
    doc = {"k": math.nan, "ess": np.float64(np.inf), "n": np.int64(3), "ok": np.bool_(True),
           "a": np.array([1.0, np.nan]), "t": (np.float32(0.5), -math.inf), "s": "NaN"}
    text = json_text(doc)
    assert strict_loads(text) == {"k": None, "ess": None, "n": 3, "ok": True, "a": [1.0, None], "t": [0.5, None],
                                  "s": "NaN"}
    assert text.endswith("}\n")


@given(st.recursive(st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=5),
                    lambda kids: st.lists(kids, max_size=4) | st.dictionaries(st.text(max_size=4), kids, max_size=4),
                    max_leaves=20))
def test_any_document_reads_back_strictly_with_finite_numbers_kept(doc):
    back = strict_loads(json_text(doc))
    assert back == finite_or_null(doc)


def test_a_run_document_with_an_unfitted_pareto_k_is_strict_json():
    """A diagnosis without an importance step has pareto_k and importance_ess NaN: written null."""
    text = json_text({"discrepancy": {"pareto_k": float("nan"), "importance_ess": float("nan")}})
    assert strict_loads(text) == {"discrepancy": {"pareto_k": None, "importance_ess": None}}
    with pytest.raises(ValueError):
        strict_loads(json.dumps({"pareto_k": float("nan")}))
