"""The closed form as a forward model (friction_uq.models.closed_form): ratio against eq. 17 and
Table 1 of docs/physics.md; the likelihood over the model against numbers frozen before the model was
taken out of the likelihood."""

from __future__ import annotations

import math

import numpy as np
import pytest

from friction_uq.likelihood import HoopTerm, Likelihood
from friction_uq.models import ClosedFormModel
from friction_uq.record import paper_apparatus
from test_sbc import closed_form_data, record_data

#: Table 1 of docs/physics.md (V_s = 10 m/s, nu = 0.4): f -> F_eo / F_io.
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
#: at THETA, computed with the likelihood before the closed form became a model of its own. The hoop
#: values were recomputed (with the same likelihood code) when the synthetic record's hoop strain
#: became the closed form's own prediction instead of a trapezoid rule (a 1e-6 relative change of
#: the data); the force values, which that does not touch, are the original ones. They are of the
#: sample-by-sample force term (force_mode="series"), the default before the ratio was read from
#: the window's levels. All four were recomputed (the likelihood code unchanged: the old data still give the old
#: values) when a pulse's front and peak came to be found through a running median: the external bar's 50 % crossing
#: had been a noise sample's, its pre-pulse segment now ends 12 samples earlier, the input bar's one later (their
#: noise sds 2e-4 and 1.4e-3 relative apart). Recomputed again (the likelihood code unchanged) when the front's 50 %
#: crossing came to be interpolated between two samples that straddle it: it had been extrapolated from two samples
#: both past it where the external bar's slow, noisy front was past half its peak when its search began.
THETA = np.array([[0.05, 0.4, 1.0], [0.06, 0.35, 1.05], [0.04, 0.45, 0.9]])
FROZEN = {
    "level": [-13017.388951111066, -13039.947488359214, -13022.76161212877],
    "series": [9501.094947345762, -6735.043373668865, 2642.4508139152167],
    "series_no_axial": [9134.864339590269, -11755.729182446517, 5003.3529422420015],
    "force": [-13028.784466106918, -13034.091870794051, -13029.652890352083],
}


def test_likelihood_over_the_model_gives_the_numbers_of_before():
    d = record_data(0.05, 0.4, 1.0, seed=3)
    got = {
        "level": Likelihood(d, model=ClosedFormModel(d), force_mode="series")(THETA),
        "series": Likelihood(d, hoop_mode="series", model=ClosedFormModel(d), force_mode="series")(THETA),
        "series_no_axial": Likelihood(d, hoop_mode="series", axial_poisson=False, force_mode="series")(THETA),
        "force": Likelihood(d, model=ClosedFormModel(d, hoop=False), force_mode="series")(THETA[:, :2]),
    }
    for k, v in FROZEN.items():
        np.testing.assert_allclose(got[k], v, rtol=1e-10, err_msg=k)


@pytest.mark.parametrize("f, nu", [(0.05, 0.4), (0.3, 0.35)])
def test_hoop_prediction_matches_an_independent_trapezoid_quadrature(f, nu):
    """The closed form's hoop reading (Gauss-Legendre over the sample, exponential profile from eq. 11-13)
    against a trapezoid rule over eq. 20's pressure profile (physics.cell.pressure_profile) times the
    gauge-averaged tube kernel, plus the tube's axial Poisson term, at slips across the gauge."""
    from types import SimpleNamespace

    from friction_uq.models.closed_form import HoopPrediction
    from friction_uq.physics import cell, tube

    a = paper_apparatus()
    tb, R, L = a.tube, a.sample.radius, a.sample.length
    n = 40
    slip = np.linspace(0.0, 12e-3, n)
    F_io = np.full(n, 20e3)
    hist = SimpleNamespace(tube=tb, radius=R, length=L, n=n, sample_rate=5e6, F_io=F_io, slip=slip)
    got = HoopPrediction(hist, smooth=0.0, knot_step=0.0).predict(f, nu, 1.0)[0]

    fb = f * float(cell.beta(nu, radius=R, length=L))
    F_eo = F_io * np.expm1(fb)
    p_mean = F_eo / (2 * math.pi * R * L * f)
    s = np.linspace(-L / 2, L / 2, 2001)
    shape = cell.pressure_profile(s + L / 2, p_mean=1.0, f=f, nu=nu, radius=R, length=L)
    z_g = tb.gauge_offset - slip
    kern = tube.band_response(z_g[:, None] - s[None, :], band_length=tb.gauge_width,
                              beta=tube.BETA_EFF_PAPER_TUBE) / tb.gauge_width
    seen = np.trapezoid(shape[None, :] * kern, s, axis=1)
    z_in = np.clip(z_g + L / 2, 0.0, L)
    N = F_io * (np.exp(fb) - np.exp(fb * (L - z_in) / L))
    ref = -(tb.lame_hoop_strain_per_pressure * p_mean * seen + tb.poisson_ratio * N / (tb.young_modulus * tb.area))
    np.testing.assert_allclose(got, ref, rtol=2e-3, atol=1e-3 * np.max(np.abs(ref)))


@pytest.mark.parametrize("axial", [True, False])
def test_weighted_hoop_prediction_is_the_knot_prediction_contracted(axial):
    """The level likelihood's window mean of the hoop reading, computed without the knot values
    (HoopPrediction.predict_weighted), equals the knot values times the weights, over f up to 0.5
    and nu across (0.05, 0.49), gains either side of 1."""
    from friction_uq.models.closed_form import HoopPrediction

    d = record_data(0.05, 0.4, 1.0, seed=3)
    hp = HoopPrediction(d, axial_poisson=axial)
    rng = np.random.default_rng(7)
    f, nu, g = rng.uniform(0.0, 0.5, 200), rng.uniform(0.05, 0.49, 200), rng.uniform(0.7, 1.3, 200)
    w = rng.uniform(0.0, 1.0, len(hp.knots))
    ref = hp.predict_knots(f, nu, g) @ w
    np.testing.assert_allclose(hp.predict_weighted(f, nu, g, w), ref, rtol=1e-12, atol=1e-14 * np.max(np.abs(ref)))
