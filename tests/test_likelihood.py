"""Likelihood: AR(1) algebra against dense Gaussians, effective variance against quadrature, hoop
prediction against docs/physics.md numbers and direct quadrature of eq. 20."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy import integrate, stats
from scipy.linalg import toeplitz

from friction_uq.errors import SignalError
from friction_uq.likelihood import HoopTerm, Likelihood, ar1_loglike, ar1_noise, ar1_pointwise, offset_sd
from friction_uq.physics import cell, tube
from test_sbc import closed_form_data


def ar1_cov(n: int, sd: float, rho: float) -> np.ndarray:
    return sd**2 * toeplitz(rho ** np.arange(n))


# ---------------------------------------------------------------- AR(1)


@pytest.mark.parametrize("rho", [0.0, 0.5, -0.3, 0.9])
def test_ar1_loglike_equals_dense_gaussian(rho):
    rng = np.random.default_rng(0)
    e = rng.normal(size=(3, 40))
    mine = ar1_loglike(e, 1.7, rho)
    ref = stats.multivariate_normal(np.zeros(40), ar1_cov(40, 1.7, rho)).logpdf(e)
    np.testing.assert_allclose(mine, ref, rtol=1e-10)
    np.testing.assert_allclose(ar1_pointwise(e, 1.7, rho).sum(-1), ref, rtol=1e-10)


@pytest.mark.parametrize("rho", [0.0, 0.5, -0.3])
def test_ar1_with_offset_equals_dense_gaussian_with_rank_one_term(rho):
    rng = np.random.default_rng(1)
    e = rng.normal(size=(3, 40)) + 0.8
    cov = ar1_cov(40, 1.7, rho) + 0.6**2
    ref = stats.multivariate_normal(np.zeros(40), cov).logpdf(e)
    np.testing.assert_allclose(ar1_loglike(e, 1.7, rho, 0.6), ref, rtol=1e-10)
    np.testing.assert_allclose(ar1_pointwise(e, 1.7, rho, 0.6).sum(-1), ref, rtol=1e-10)
    # per-row offsets, one of them zero
    off = np.array([0.6, 0.0, 0.2])
    rows = [stats.multivariate_normal(np.zeros(40), ar1_cov(40, 1.7, rho) + o**2).logpdf(e[i]) for i, o in enumerate(off)]
    np.testing.assert_allclose(ar1_pointwise(e, 1.7, rho, off).sum(-1), rows, rtol=1e-10)


def test_offset_sd_is_sd_of_an_ar1_mean():
    """Against the dense covariance: Var(mean) = 1' S 1 / n^2 -> the large-n AR(1) form within 1/n."""
    n, sd, rho = 2000, 2.0, 0.5
    exact = math.sqrt(ar1_cov(n, sd, rho).sum()) / n
    assert offset_sd(sd, rho, n) == pytest.approx(exact, rel=2.0 / n * (1 + rho) / (1 - rho))


def test_ar1_noise_has_requested_sd_and_lag1():
    x = ar1_noise((200, 500), sd=3.0, rho=0.6, rng=np.random.default_rng(1))
    # 1e5 samples, effective ~ n (1-rho)/(1+rho): sd of the estimates ~ 1e-2 relative
    assert np.std(x) == pytest.approx(3.0, rel=0.03)
    lag1 = np.mean(x[:, 1:] * x[:, :-1]) / np.mean(x * x)
    assert lag1 == pytest.approx(0.6, abs=0.02)
    np.testing.assert_array_equal(x, ar1_noise((200, 500), sd=3.0, rho=0.6, rng=np.random.default_rng(1)))


# ---------------------------------------------------------------- force term


def test_force_term_sufficient_statistics_equal_explicit_residuals():
    d = closed_form_data(0.1, 0.35, seed=2, hoop=False, rho=(0.3, 0.7, 0.5))
    lk = Likelihood(d, hoop=False, force_mode="series")
    r = np.array([0.0, 0.1, lk.force.r0, 0.5, 2.0])
    sd, rho = lk.force.noise(r)
    ref = ar1_loglike(lk.force.residuals(r), sd, rho)
    np.testing.assert_allclose(lk.force.loglike(r), ref, rtol=1e-11)


def test_effective_variance_is_exact_marginal_over_true_force():
    """One sample, white noise: L(r) = integral N(F_io; x, sd_io^2) N(F_eo; r x, sd_eo^2) dx (flat prior on x)."""
    d = closed_form_data(0.05, 0.4, seed=3, hoop=False, n=8, rho=(0.0, 0.0, 0.0))
    d = replace(d, sd_io=300.0)  # make F_io's noise matter
    lk = Likelihood(d, hoop=False, force_mode="series")
    for r in (0.05, 0.1426, 0.4):
        F_io, F_eo = d.F_io[0], d.F_eo[0]
        integrand = lambda x: stats.norm.pdf(F_io, x, d.sd_io) * stats.norm.pdf(F_eo, r * x, d.sd_eo)  # noqa: E731
        ref, _ = integrate.quad(integrand, F_io - 20 * d.sd_io, F_io + 20 * d.sd_io, epsabs=0, epsrel=1e-11)
        assert lk.force.pointwise(np.array(r))[0] == pytest.approx(math.log(ref), rel=1e-9)


def test_equal_rho_force_likelihood_is_exact_dense_marginal():
    """rho_io = rho_eo: u = e_eo - r e_io is exactly AR(1) with covariance sd_eo^2 R + r^2 sd_io^2 R."""
    d = closed_form_data(0.05, 0.4, seed=4, hoop=False, n=60, rho=(0.6, 0.6, 0.5))
    lk = Likelihood(d, hoop=False, force_mode="series")
    for r in (0.1, 0.3):
        cov = ar1_cov(60, d.sd_eo, 0.6) + r**2 * ar1_cov(60, d.sd_io, 0.6)
        ref = stats.multivariate_normal(np.zeros(60), cov).logpdf(d.F_eo - r * d.F_io)
        assert lk.force.loglike(np.array(r)) == pytest.approx(ref, rel=1e-10)


def test_force_term_with_offset_errors_is_exact_dense_marginal():
    """Offsets delta_io, delta_eo: u's covariance gains (sd_off_eo^2 + r^2 sd_off_io^2) 1 1'."""
    d = closed_form_data(0.05, 0.4, seed=4, hoop=False, n=60, rho=(0.6, 0.6, 0.5), n_baseline=50)
    assert d.sd_offset_eo > 0
    lk = Likelihood(d, hoop=False, force_mode="series")
    for r in (0.1, 0.3):
        cov = ar1_cov(60, d.sd_eo, 0.6) + r**2 * ar1_cov(60, d.sd_io, 0.6) + d.sd_offset_eo**2 + r**2 * d.sd_offset_io**2
        ref = stats.multivariate_normal(np.zeros(60), cov).logpdf(d.F_eo - r * d.F_io)
        assert lk.force.loglike(np.array(r)) == pytest.approx(ref, rel=1e-10)
        assert lk.force.pointwise(np.array(r)).sum() == pytest.approx(ref, rel=1e-10)


def test_hoop_term_with_offset_error():
    d = closed_form_data(0.05, 0.4, 0.97, seed=8, n_baseline=300)
    h = HoopTerm(d, mode="series")
    assert h.offset == pytest.approx(offset_sd(d.sd_hoop, d.rho_hoop, 300))
    theta = np.array([[0.05, 0.4, 0.97], [0.06, 0.35, 1.05]])
    ref = ar1_loglike(d.hoop - h.predict(*theta.T), h.sd, h.rho, h.offset)
    np.testing.assert_allclose(h.loglike(*theta.T), ref, rtol=1e-9)
    np.testing.assert_allclose(h.pointwise(*theta.T).sum(-1), ref, rtol=1e-9)


def test_unequal_rho_uses_variance_weighted_lag1():
    d = closed_form_data(0.05, 0.4, seed=5, hoop=False, rho=(0.2, 0.8, 0.5))
    lk = Likelihood(d, hoop=False, force_mode="series")
    r = 0.3
    sd, rho = lk.force.noise(np.array(r))
    a, b = d.sd_eo**2, r**2 * d.sd_io**2
    assert sd**2 == pytest.approx(a + b)
    assert rho == pytest.approx((0.8 * a + 0.2 * b) / (a + b))


def test_vectorised_call_equals_row_calls_and_pointwise_sums():
    d = closed_form_data(0.05, 0.4, 1.02, seed=6)
    lk = Likelihood(d, hoop_mode="series", force_mode="series")
    assert lk.names == ("f", "nu", "hoop_gain")
    theta = np.column_stack([np.linspace(0.03, 0.08, 7), np.linspace(0.3, 0.45, 7), np.linspace(0.9, 1.1, 7)])
    full = lk(theta)
    assert full.shape == (7,)
    np.testing.assert_allclose(full, [lk(t[None])[0] for t in theta], rtol=1e-12)
    pw = lk.pointwise(theta)
    assert pw["F_eo"].shape == (7, d.n) and pw["hoop"].shape == (7, d.n)
    np.testing.assert_allclose(pw["F_eo"].sum(-1) + pw["hoop"].sum(-1), full, rtol=1e-9)
    seg = lk.pointwise(theta, segment=50)
    assert seg["F_eo"].shape == (7, math.ceil(d.n / 50))
    np.testing.assert_allclose(seg["F_eo"].sum(-1) + seg["hoop"].sum(-1), full, rtol=1e-9)


def test_likelihood_peaks_at_true_kappa():
    """Profile over kappa: the maximum lies within 3 standard errors of the truth."""
    d = closed_form_data(0.05, 0.4, seed=7, hoop=False)
    lk = Likelihood(d, hoop=False, force_mode="series")
    kap = np.linspace(0.030, 0.037, 2001)
    theta = np.column_stack([kap / cell.lateral_ratio(0.4), np.full_like(kap, 0.4)])
    ll = lk(theta)
    w = np.exp(ll - ll.max())
    mean = np.sum(w * kap) / w.sum()
    sd = math.sqrt(np.sum(w * (kap - mean) ** 2) / w.sum())
    assert abs(mean - float(cell.kappa(0.05, 0.4))) < 3 * sd


# ---------------------------------------------------------------- hoop term


def _hoop_data(f, nu, z_gauge, *, width=0.0):
    """Noise-free data whose gauge sits at z_gauge (m from the sample middle) at every sample."""
    d = closed_form_data(f, nu, seed=0, strain_sd=(1e-12, 1e-12, 2e-6), n=len(z_gauge))
    tb = replace(d.tube, gauge_width=width)
    return replace(d, tube=tb, slip=tb.gauge_offset - np.asarray(z_gauge))


def test_uniform_pressure_band_matches_physics_md_numbers():
    """f -> 0: uniform p over a 10 mm band reads 0.77, 0.52, 0.14, ~0 of Lame at 0, 5, 10, 15 mm (docs/physics.md 6).

    Those are the exact axisymmetric solution's values; the kernel reproduces it within 2.4 % of the
    peak (docs/physics.md), which is the tolerance. Against the kernel's closed-form band integral
    (physics.tube.band_response) the 16-node Gauss-Legendre quadrature agrees to 2e-5 (K has a kink in its 2nd derivative).
    """
    z = np.array([0.0, 5e-3, 10e-3, 15e-3, -5e-3] + [0.0] * 8)
    d = _hoop_data(1e-9, 0.4, z)
    h = HoopTerm(d, axial_poisson=False, knot_step=0.0)
    p = float(cell.lateral_ratio(0.4)) * np.mean(d.F_io) / (math.pi * d.radius**2)
    ratio = h.predict(1e-9, 0.4, 1.0)[0][:5] / (-d.tube.lame_hoop_strain_per_pressure * p)
    np.testing.assert_allclose(ratio, [0.77, 0.52, 0.14, 0.0, 0.52], atol=0.024 * 0.77)
    np.testing.assert_allclose(ratio, tube.band_response(z[:5], band_length=d.length), atol=2e-5)
    # compression-positive convention: swelling reads negative (the kernel dips below 0 beyond ~13 mm)
    assert np.all(h.predict(1e-9, 0.4, 1.0)[0][np.abs(z) <= 10e-3] < 0)


@pytest.mark.parametrize(("f", "nu", "width"), [(0.05, 0.4, 0.0), (0.3, 0.3, 0.0), (0.3, 0.3, 2e-3)])
def test_hoop_prediction_equals_quadrature_of_eq20(f, nu, width):
    """Independent path: p(z) from eq. 20 (p_mean = F_eo/(2 pi R L f)) times K, integrated by scipy quad."""
    z = np.linspace(-8e-3, 8e-3, 17)
    d = _hoop_data(f, nu, z, width=width)
    h = HoopTerm(d, axial_poisson=False, knot_step=0.0, gauge_averaging=width > 0)
    R, L = d.radius, d.length
    p_mean = np.mean(d.F_eo) / (2 * math.pi * R * L * f)

    def kern(x):
        if width == 0.0:
            return float(tube.hoop_kernel(x))
        return integrate.quad(lambda y: float(tube.hoop_kernel(y)), x - width / 2, x + width / 2, epsabs=1e-12)[0] / width

    ref = []
    for zg in z:
        val, _ = integrate.quad(
            lambda s: float(cell.pressure_profile(s + L / 2, p_mean=p_mean, f=f, nu=nu, radius=R, length=L)) * kern(zg - s),
            -L / 2, L / 2, points=[zg] if abs(zg) < L / 2 else None, epsabs=1e-3, epsrel=1e-10, limit=200,
        )
        ref.append(-d.tube.lame_hoop_strain_per_pressure * val)
    ref = np.array(ref)
    np.testing.assert_allclose(h.predict(f, nu, 1.0)[0], ref, atol=1e-4 * np.abs(ref).max())


def test_axial_poisson_term_beyond_the_output_face():
    """Gauge on the output side of the sample: the tube carries F_eo, hoop += nu_t F_eo / (E_t A_t)."""
    z = np.array([12e-3, -12e-3] + [0.0] * 8)
    d = _hoop_data(0.2, 0.4, z)
    on = HoopTerm(d, axial_poisson=True, knot_step=0.0).predict(0.2, 0.4, 1.0)[0]
    off = HoopTerm(d, axial_poisson=False, knot_step=0.0).predict(0.2, 0.4, 1.0)[0]
    tb = d.tube
    expected = tb.poisson_ratio * np.mean(d.F_eo) / (tb.young_modulus * tb.area)
    assert off[0] - on[0] == pytest.approx(expected, rel=1e-9)  # swelling: more negative
    assert on[1] == pytest.approx(off[1], abs=1e-15)  # input side carries no axial load
    # docs/physics.md: ~ +19 microstrain for 5 kN
    assert expected * 5000.0 / np.mean(d.F_eo) == pytest.approx(19e-6, abs=1e-6)


def test_hoop_quadratic_form_equals_explicit_residuals():
    d = closed_form_data(0.05, 0.4, 0.97, seed=8)
    h = HoopTerm(d, mode="series")
    theta = np.array([[0.05, 0.4, 0.97], [0.06, 0.35, 1.05], [0.04, 0.45, 0.9]])
    ref = ar1_loglike(d.hoop - h.predict(*theta.T), h.sd, h.rho)
    np.testing.assert_allclose(h.loglike(*theta.T), ref, rtol=1e-9)


def test_knot_interpolation_error_is_far_below_noise():
    d = closed_form_data(0.3, 0.4, seed=9)
    exact = HoopTerm(d, knot_step=0.0, n_nodes=64).predict(0.3, 0.4, 1.0)
    fast = HoopTerm(d).predict(0.3, 0.4, 1.0)
    assert np.max(np.abs(fast - exact)) < 0.1 * d.sd_hoop


def test_simulate_is_seeded_and_has_the_model_noise():
    d = closed_form_data(0.05, 0.4, seed=10)
    lk = Likelihood(d, force_mode="series")
    theta = np.tile([0.05, 0.4, 1.0], (400, 1))
    a = lk.simulate(theta, rng=np.random.default_rng(3))
    np.testing.assert_array_equal(a["F_eo"], lk.simulate(theta, rng=np.random.default_rng(3))["F_eo"])
    r = float(lk.ratio(theta[:1])[0])
    u = a["F_eo"] - r * a["F_io"]
    sd_u, _ = lk.force.noise(np.array(r))
    assert np.std(u) == pytest.approx(float(sd_u), rel=0.03)
    assert np.std(a["hoop"] - lk.hoop.predict(0.05, 0.4, 1.0)) == pytest.approx(d.sd_hoop, rel=0.03)


# ---------------------------------------------------------------- refusals


def test_hoop_requested_without_channel_is_refused():
    d = closed_form_data(0.05, 0.4, seed=11, hoop=False)
    assert Likelihood(d).names == ("f", "nu")  # hoop=None: off without a channel
    with pytest.raises(SignalError, match="hoop term requested but the data have no tube_hoop channel"):
        Likelihood(d, hoop=True)


def test_bad_data_are_refused():
    d = closed_form_data(0.05, 0.4, seed=12, hoop=False)
    with pytest.raises(SignalError, match="4 samples, at least 8 are needed"):
        Likelihood(replace(d, time=d.time[:4], F_io=d.F_io[:4], F_eo=d.F_eo[:4], slip=d.slip[:4]))
    with pytest.raises(SignalError, match=r"AR\(1\) coefficient rho_io must lie in \(-1, 1\), got 1.0"):
        Likelihood(replace(d, rho_io=1.0))
    with pytest.raises(SignalError, match="noise sd_eo must be a positive number, got 0.0"):
        Likelihood(replace(d, sd_eo=0.0))
    bad = d.F_eo.copy()
    bad[3] = np.nan
    with pytest.raises(SignalError, match="F_eo has non-finite values"):
        Likelihood(replace(d, F_eo=bad))


def test_hoop_prediction_matches_whole_closed_form_record(tmp_path):
    """Cross-check with friction_uq.synthetic's independent hoop model, through the whole pipeline
    (record -> forces -> window -> slip): at the true parameters the prediction follows the
    noise-free hoop strain within the noise of the smoothed F_io it is built on."""
    from friction_uq.analysis import prepare
    from friction_uq.record import paper_apparatus, read_record
    from friction_uq.synthetic import ClosedFormTest, closed_form_strains, write_closed_form_record

    test = ClosedFormTest(f=0.3, nu=0.4)
    d = prepare(read_record(write_closed_form_record(tmp_path / "r.h5", test, seed=5))).data
    t, strains, _ = closed_form_strains(test, paper_apparatus())
    truth = strains["tube_hoop"][np.searchsorted(t, d.time)]
    pred = HoopTerm(d, knot_step=0.0).predict(0.3, 0.4, 1.0)[0]
    # relative sd of F_io averaged over 10 us (50 samples) of AR(1) noise, times 4
    rel = 4 * offset_sd(d.sd_io, d.rho_io, 50) / np.mean(d.F_io)
    assert np.max(np.abs(pred - truth)) < rel * np.max(np.abs(truth)) + 0.05 * d.sd_hoop


def test_level_hoop_term_is_one_gaussian_observation_with_model_discrepancy():
    """Default hoop term: window mean vs model mean, sd^2 = noise of the mean + offset^2 + (3 % of model)^2."""
    d = closed_form_data(0.05, 0.4, 1.0, seed=9, n_baseline=400)
    h = HoopTerm(d)
    assert h.mode == "level"
    theta = np.array([[0.05, 0.4, 1.0], [0.05, 0.3, 1.1]])
    mean_pred = h.predict(*theta.T).mean(axis=1)
    tau = (1 + d.rho_hoop) / (1 - d.rho_hoop)
    sd = np.sqrt(d.sd_hoop**2 * tau / d.n + d.sd_offset_hoop**2 + (0.03 * mean_pred) ** 2)
    ref = -0.5 * np.log(2 * np.pi) - np.log(sd) - 0.5 * ((d.hoop.mean() - mean_pred) / sd) ** 2
    np.testing.assert_allclose(h.loglike(*theta.T), ref, rtol=1e-9)
    lk = Likelihood(d)
    pw = lk.pointwise(theta, segment=50)
    assert pw["hoop"].shape == (2, 1)
    np.testing.assert_allclose(pw["F_eo"].sum(-1) + pw["hoop"].sum(-1), lk(theta), rtol=1e-9)
    with pytest.raises(ValueError, match="hoop mode 'shape' is not understood, allowed values: level, series"):
        HoopTerm(d, mode="shape")
