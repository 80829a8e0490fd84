"""The analysis settings: one frozen object, plain JSON for the provenance."""

import dataclasses
import json

import pytest

from friction_uq.settings import AnalysisSettings


def test_settings_are_frozen_and_written_as_plain_json():
    s = AnalysisSettings(window=(1e-4, 3e-4), dispersion=True)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.hoop = False  # type: ignore[misc]
    doc = s.to_json()
    assert doc == {"window": [1e-4, 3e-4], "dispersion": True, "hoop": True, "hoop_mode": "level",
                   "axial_poisson": True, "hoop_discrepancy": 0.03, "force_mode": "level", "ratio_model_form": 0.025}
    assert json.loads(s.to_attr()) == doc
    assert AnalysisSettings().to_json()["window"] is None


def test_unknown_hoop_mode_is_refused():
    with pytest.raises(ValueError, match="hoop mode 'shape' is not understood, allowed values: level, series"):
        AnalysisSettings(hoop_mode="shape")
