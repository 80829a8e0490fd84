"""The closed form as a forward model (friction_uq.models.closed_form): ratio against eq. 17 and
Table 1 of physics.md; the likelihood over the model against numbers frozen before the model was
taken out of the likelihood."""

from __future__ import annotations

import math

import numpy as np
import pytest

from friction_uq.likelihood import HoopTerm, Likelihood
from friction_uq.models import ClosedFormModel
from friction_uq.record import paper_apparatus
from test_sbc import closed_form_data, record_data

#: Table 1 of physics.md (V_s = 10 m/s, nu = 0.4): f -> F_eo / F_io.
TABLE_1_RATIO = {0.01: 0.0270, 0.05: 0.1426, 0.10: 0.3056, 0.20: 0.7046, 0.50: 2.7937}


def test_ratio_is_eq_17_inverted_at_table_1_values():
    d = closed_form_data(0.05, 0.4, seed=1)
    model = ClosedFormModel(d)
    assert model.parameters.names == ("f", "nu", "hoop_gain")
    R, L = paper_apparatus().sample.radius, paper_apparatus().sample.length
    for f, table in TABLE_1_RATIO.items():
        r = float(model.ratio({"f": f, "nu": 0.4}))
        assert r == pytest.approx(table, abs=5e-5)  # half a unit of the table's last digit
        # eq. 17: f = (1 - nu) R / (2 nu L) ln(1 + F_eo / F_io)
        assert (1 - 0.4) * R / (2 * 0.4 * L) * math.log1p(r) == pytest.approx(f, rel=1e-12)


def test_model_predicts_by_name_and_without_hoop():
    d = closed_form_data(0.05, 0.4, seed=2)
    model = ClosedFormModel(d)
    vals = {"f": np.array([0.05, 0.1]), "nu": np.array([0.4, 0.3]), "hoop_gain": np.array([1.0, 0.9])}
    out = model.predict(vals)
    assert out["tube_hoop"].shape == (2, d.n)
    np.testing.assert_array_equal(out["tube_hoop"], HoopTerm(d).predict(vals["f"], vals["nu"], vals["hoop_gain"]))
    bare = ClosedFormModel(d, hoop=False)
    assert bare.parameters.names == ("f", "nu") and set(bare.predict(vals)) == {"ratio"}
    with pytest.raises(ValueError, match="built without the hoop gauge"):
        bare.hoop_reading(vals)
    with pytest.raises(ValueError, match="hoop=False but the model predicts the hoop gauge"):
        Likelihood(d, hoop=False, model=model)


#: Log-likelihoods on a closed-form record (friction_uq.synthetic, f = 0.05, nu = 0.4, g = 1, seed 3)
#: at THETA, computed with the likelihood before the closed form became a model of its own.
THETA = np.array([[0.05, 0.4, 1.0], [0.06, 0.35, 1.05], [0.04, 0.45, 0.9]])
FROZEN = {
    "level": [-13017.892139593494, -13040.568016959662, -13023.357229850677],
    "series": [9500.622072009706, -6727.6555043959725, 2636.6461866163463],
    "series_no_axial": [9135.52504197031, -11747.194237946189, 4998.550066436324],
    "force": [-13029.287677259113, -13034.72099966711, -13030.245157704394],
}


def test_likelihood_over_the_model_gives_the_numbers_of_before():
    d = record_data(0.05, 0.4, 1.0, seed=3)
    got = {
        "level": Likelihood(d, model=ClosedFormModel(d))(THETA),
        "series": Likelihood(d, hoop_mode="series", model=ClosedFormModel(d))(THETA),
        "series_no_axial": Likelihood(d, hoop_mode="series", axial_poisson=False)(THETA),
        "force": Likelihood(d, model=ClosedFormModel(d, hoop=False))(THETA[:, :2]),
    }
    for k, v in FROZEN.items():
        np.testing.assert_allclose(got[k], v, rtol=1e-10, err_msg=k)
