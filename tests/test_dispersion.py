"""Tests of friction_uq.dispersion: Pochhammer-Chree first mode, phase velocity, wave transport.

Reference values come from docs/physics.md section 7 (table, Rayleigh-Love statement, cut-off
f a / c0 = 0.2619, "about five times earlier in frequency") and from closed-form formulas
(Rayleigh-Love, thin-shell membrane theory, analytic shifted Gaussian), never from the module's
own output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from friction_uq import dispersion as disp

# docs/physics.md section 7: c/c0 of the first longitudinal mode of a solid bar against d/Lambda.
D_OVER_LAMBDA = (0.2, 0.4, 0.6, 0.8, 1.0, 1.5, 2.0)
TABLE = {
    0.29: (0.9911, 0.9564, 0.8730, 0.7656, 0.6893, 0.6088, 0.5861),
    0.33: (0.9887, 0.9470, 0.8598, 0.7575, 0.6846, 0.6057, 0.5827),
}
TABLE_CASES = [(nu, dl, ref) for nu, refs in TABLE.items() for dl, ref in zip(D_OVER_LAMBDA, refs, strict=True)]

# docs/physics.md section 1 (striker and input bar, steel) and the round-trip set-up of the brief.
STEEL_C0 = 4555.0
STEEL_D = 0.02
NU = 0.29
DT = 2e-7


def rayleigh_love(d_over_lambda: float, nu: float) -> float:
    """c/c0 ~ 1 - nu^2 pi^2 (a/Lambda)^2 (docs/physics.md section 7)."""
    return 1.0 - nu**2 * math.pi**2 * (d_over_lambda / 2.0) ** 2


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def smooth_trapezoid(t: np.ndarray, *, start: float, rise: float, plateau: float) -> np.ndarray:
    """Unit trapezoid with raised-cosine rise and fall (s)."""
    u = np.zeros_like(t)
    a = (t - start) / rise
    up = (a > 0.0) & (a < 1.0)
    u[up] = 0.5 * (1.0 - np.cos(np.pi * a[up]))
    u[(t - start >= rise) & (t - start <= rise + plateau)] = 1.0
    b = (t - start - rise - plateau) / rise
    down = (b > 0.0) & (b < 1.0)
    u[down] = 0.5 * (1.0 + np.cos(np.pi * b[down]))
    return u


def gaussian(n: int, centre: float, sigma: float) -> np.ndarray:
    k = np.arange(n, dtype=float)
    return np.exp(-0.5 * ((k - centre) / sigma) ** 2)


# ---------------------------------------------------------------------------------------------
# Pochhammer-Chree first mode
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("nu", "d_over_lambda", "reference"), TABLE_CASES)
def test_pochhammer_reproduces_physics_table(nu: float, d_over_lambda: float, reference: float) -> None:
    assert float(disp.pochhammer_phase_velocity_ratio(d_over_lambda, nu)) == pytest.approx(reference, rel=1e-3)


@pytest.mark.parametrize("nu", sorted(TABLE))
def test_pochhammer_vectorised_matches_table_rows(nu: float) -> None:
    got = disp.pochhammer_phase_velocity_ratio(np.array(D_OVER_LAMBDA), nu)
    assert got.shape == (len(D_OVER_LAMBDA),)
    np.testing.assert_allclose(got, TABLE[nu], rtol=1e-3)
    # same values in any order and shape
    shuffled = np.array([[2.0, 0.2], [0.6, 0.0]])
    got2 = disp.pochhammer_phase_velocity_ratio(shuffled, nu)
    assert got2.shape == (2, 2)
    assert got2[1, 1] == 1.0
    np.testing.assert_allclose(got2[0], [TABLE[nu][6], TABLE[nu][0]], rtol=1e-3)


def test_rayleigh_love_close_at_low_d_over_lambda() -> None:
    exact = float(disp.pochhammer_phase_velocity_ratio(0.2, 0.29))
    assert abs(rayleigh_love(0.2, 0.29) / exact - 1.0) <= 6e-4  # "within 0.06 % at d/Lambda = 0.2"
    exact = float(disp.pochhammer_phase_velocity_ratio(0.4, 0.29))
    err = rayleigh_love(0.4, 0.29) / exact - 1.0
    assert 0.005 < err < 0.015  # "~1 % at 0.4", Love too fast


@pytest.mark.parametrize("nu", [0.2, 0.29, 0.33, 0.45])
def test_rayleigh_love_is_the_low_frequency_limit(nu: float) -> None:
    # the error of Rayleigh-Love is O((d/Lambda)^4): tiny at d/Lambda = 0.02
    exact = float(disp.pochhammer_phase_velocity_ratio(0.02, nu))
    assert exact < 1.0
    assert exact == pytest.approx(rayleigh_love(0.02, nu), rel=1e-7)


def test_first_mode_cutoff_matches_physics_md() -> None:
    f_c = disp.first_mode_cutoff(c0=STEEL_C0, diameter=STEEL_D, nu=0.29)
    assert f_c * (STEEL_D / 2.0) / STEEL_C0 == pytest.approx(0.2619, rel=1e-3)


@pytest.mark.parametrize("nu", sorted(TABLE))
def test_curve_is_cached_read_only_and_invertible(nu: float) -> None:
    dl, ratio = disp.phase_velocity_curve(nu)
    again = disp.phase_velocity_curve(nu + 1e-9)  # same key after rounding
    assert again[0] is dl and again[1] is ratio
    assert not dl.flags.writeable and not ratio.flags.writeable
    assert dl[0] == 0.0 and ratio[0] == 1.0
    assert dl[-1] == pytest.approx(2.5)
    assert np.all(np.diff(dl * ratio) > 0.0)  # f d / c0 increases: interpolation in frequency is valid
    np.testing.assert_allclose(np.interp(D_OVER_LAMBDA, dl, ratio), TABLE[nu], rtol=1e-3)


# ---------------------------------------------------------------------------------------------
# phase velocity against frequency
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("nu", sorted(TABLE))
def test_phase_velocity_solid_converts_wavelength_to_frequency(nu: float) -> None:
    c0, d = 5000.0, 0.025
    ratio = np.array(TABLE[nu])
    # Lambda = c_p / f, so the table point (d/Lambda, c/c0) sits at f = (d/Lambda)(c/c0) c0 / d
    f = np.array(D_OVER_LAMBDA) * ratio * c0 / d
    np.testing.assert_allclose(disp.phase_velocity(f, c0=c0, diameter=d, nu=nu), ratio * c0, rtol=1e-3)


@pytest.mark.parametrize("inner", [0.0, 0.03])
def test_phase_velocity_at_zero_frequency_is_c0(inner: float) -> None:
    got = disp.phase_velocity(np.zeros(3), c0=5162.0, diameter=0.04, nu=0.29, inner_diameter=inner)
    np.testing.assert_array_equal(got, 5162.0)


def test_hollow_phase_velocity_decreases_with_frequency() -> None:
    kw = dict(c0=5162.0, diameter=0.04, inner_diameter=0.03, nu=0.29)
    f_c = disp.first_mode_cutoff(**kw)
    f = np.linspace(0.0, f_c, 200)
    cp = disp.phase_velocity(f, **kw)
    assert np.all(np.diff(cp) < 0.0)
    beyond = disp.phase_velocity(np.array([f_c, 2 * f_c, 10 * f_c]), **kw)
    np.testing.assert_allclose(beyond, beyond[0], rtol=1e-12)  # clipped at its validity


def test_hollow_bar_disperses_earlier_than_the_10_mm_bar() -> None:
    # docs/physics.md sections 1 and 7: external output bar 40/30 mm steel, internal output bar 10 mm aluminium
    hollow = dict(c0=5162.0, diameter=0.04, inner_diameter=0.03, nu=0.29)
    solid = dict(c0=5092.0, diameter=0.01, nu=0.33)
    f = np.linspace(5e3, disp.first_mode_cutoff(**hollow), 20)
    ratio_hollow = disp.phase_velocity(f, **hollow) / hollow["c0"]
    ratio_solid = disp.phase_velocity(f, **solid) / solid["c0"]
    assert np.all(ratio_hollow < ratio_solid)


def test_hollow_bar_disperses_about_five_times_earlier_in_frequency() -> None:
    # same material for both bars so that only the geometry differs; compare where c/c0 = 0.995
    c0, nu, level = 5000.0, 0.29, 0.995
    f = np.linspace(0.0, 150e3, 300001)
    hollow = disp.phase_velocity(f, c0=c0, diameter=0.04, inner_diameter=0.03, nu=nu) / c0
    solid = disp.phase_velocity(f, c0=c0, diameter=0.01, nu=nu) / c0
    f_hollow = f[np.argmax(hollow < level)]
    f_solid = f[np.argmax(solid < level)]
    assert 4.5 < f_solid / f_hollow < 5.5


def test_hollow_love_estimate_agrees_with_thin_shell_theory_below_cutoff() -> None:
    # Axisymmetric membrane shell (mean radius R): c^2/c0^2 = (1 - W^2 - nu^2) / ((1 - W^2)(1 - nu^2)),
    # W^2 = (f / f_ring)^2 (1 - nu^2), f_ring = c0 / (2 pi R). Independent of Love's theory.
    c0, nu, r_i, r_o = 5162.0, 0.29, 0.015, 0.02
    f_ring = c0 / (2.0 * math.pi * 0.5 * (r_i + r_o))
    f_c = disp.first_mode_cutoff(c0=c0, diameter=2 * r_o, inner_diameter=2 * r_i, nu=nu)
    assert f_c <= 0.6 * f_ring * (1 + 1e-12)
    f = np.linspace(1e3, f_c, 50)
    w2 = (f / f_ring) ** 2 * (1.0 - nu**2)
    shell = np.sqrt((1.0 - w2 - nu**2) / ((1.0 - w2) * (1.0 - nu**2)))
    love = disp.phase_velocity(f, c0=c0, diameter=2 * r_o, inner_diameter=2 * r_i, nu=nu) / c0
    np.testing.assert_allclose(love, shell, rtol=1e-2)


# ---------------------------------------------------------------------------------------------
# transport
# ---------------------------------------------------------------------------------------------


def test_dispersion_forward_then_back_recovers_the_pulse() -> None:
    n = 8000  # 1.6 ms: room for the 439 us transit and the dispersive tail
    t = np.arange(n) * DT
    pulse = smooth_trapezoid(t, start=100e-6, rise=10e-6, plateau=100e-6)
    bar = dict(sample_interval=DT, c0=STEEL_C0, diameter=STEEL_D, nu=NU, dispersive=True)
    forward = disp.propagate(pulse, distance=2.0, **bar)
    back = disp.propagate(forward, distance=-2.0, **bar)
    assert rms(back - pulse) / rms(pulse) < 0.01
    # the dispersed wave is clearly not a delayed copy of the pulse
    delayed = disp.propagate(pulse, sample_interval=DT, distance=2.0, c0=STEEL_C0)
    assert rms(forward - delayed) / rms(pulse) > 0.05
    # ... but it arrives on time: half-height crossing of the front within a few microseconds
    front = t[np.argmax(forward > 0.5)]
    assert front == pytest.approx(100e-6 + 5e-6 + 2.0 / STEEL_C0, abs=3e-6)


def test_dispersion_removes_content_beyond_cutoff() -> None:
    n = 4096
    noise = np.random.default_rng(1).standard_normal(n) * np.hanning(n)  # zero at both ends
    out = disp.propagate(noise, sample_interval=DT, distance=0.0, c0=STEEL_C0, diameter=STEEL_D, nu=NU, dispersive=True)
    f_c = disp.first_mode_cutoff(c0=STEEL_C0, diameter=STEEL_D, nu=NU)
    spectrum = np.abs(np.fft.rfft(out, n=8 * n))
    f = np.fft.rfftfreq(8 * n, d=DT)
    # zero padding the record spreads the cut only by leakage, far below the in-band level
    assert spectrum[f > 1.5 * f_c].max() < 1e-2 * spectrum[f < 0.5 * f_c].mean()


def test_non_dispersive_propagate_is_the_delay() -> None:
    x = gaussian(600, 150.0, 6.0)
    a = disp.propagate(x, sample_interval=DT, distance=0.37, c0=STEEL_C0)
    b = disp.delay(x, sample_interval=DT, delay=0.37 / STEEL_C0)
    np.testing.assert_allclose(a, b, atol=1e-13)
    expected = gaussian(600, 150.0 + 0.37 / STEEL_C0 / DT, 6.0)
    np.testing.assert_allclose(a, expected, atol=1e-6)


def test_fractional_delay_matches_shifted_gaussian() -> None:
    n, centre, sigma, shift = 400, 150.0, 8.0, 3.37
    x = gaussian(n, centre, sigma)
    out = disp.delay(x, sample_interval=DT, delay=shift * DT)
    expected = gaussian(n, centre + shift, sigma)
    assert np.max(np.abs(out - expected)) < 1e-6 * np.max(expected)
    back = disp.delay(out, sample_interval=DT, delay=-shift * DT)
    np.testing.assert_allclose(back, x, atol=1e-12)


def test_output_is_float64_with_input_shape() -> None:
    x = np.array([0, 0, 3, 5, 2, 0, 0, 0], dtype=np.int32)
    for out in (
        disp.delay(x, sample_interval=1e-6, delay=0.4e-6),
        disp.propagate(x, sample_interval=1e-6, distance=0.5, c0=5000.0),
        disp.propagate(x, sample_interval=1e-6, distance=0.5, c0=5000.0, diameter=0.02, nu=0.3, dispersive=True),
        disp.propagate(x.astype(np.float32), sample_interval=1e-6, distance=-0.5, c0=5000.0, pad_factor=3.5),
    ):
        assert out.dtype == np.float64 and out.shape == x.shape
    stacked = np.vstack([x, 2 * x]).astype(float)
    out2 = disp.propagate(stacked, sample_interval=1e-6, distance=0.5, c0=5000.0)
    np.testing.assert_allclose(out2[1], 2 * out2[0], atol=1e-12)


# ---------------------------------------------------------------------------------------------
# properties
# ---------------------------------------------------------------------------------------------

finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)
signals = st.integers(min_value=4, max_value=300).flatmap(lambda n: st.tuples(arrays(np.float64, n, elements=finite), arrays(np.float64, n, elements=finite)))


@settings(max_examples=40, deadline=None)
@given(
    pair=signals,
    a=st.floats(min_value=-10, max_value=10),
    b=st.floats(min_value=-10, max_value=10),
    distance=st.floats(min_value=-3.0, max_value=3.0),
    dispersive=st.booleans(),
)
def test_propagate_is_linear(pair: tuple[np.ndarray, np.ndarray], a: float, b: float, distance: float, dispersive: bool) -> None:
    x, y = pair
    kw = dict(sample_interval=1e-6, distance=distance, c0=5000.0, diameter=0.02, nu=0.3, dispersive=dispersive)
    lhs = disp.propagate(a * x + b * y, **kw)
    rhs = a * disp.propagate(x, **kw) + b * disp.propagate(y, **kw)
    scale = 1.0 + np.max(np.abs(a * x)) + np.max(np.abs(b * y))
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-11 * scale * len(x))


@settings(max_examples=40, deadline=None)
@given(data=st.data(), x=st.integers(min_value=2, max_value=300).flatmap(lambda n: arrays(np.float64, n, elements=finite)))
def test_integer_delay_is_a_shift_with_zeros(data: st.DataObject, x: np.ndarray) -> None:
    n = len(x)
    k = data.draw(st.integers(min_value=-(n - 1), max_value=n - 1))
    dt = 2e-7
    out = disp.delay(x, sample_interval=dt, delay=k * dt)
    expected = np.zeros(n)
    if k >= 0:
        expected[k:] = x[: n - k]
    else:
        expected[: n + k] = x[-k:]
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-11 * (1.0 + np.max(np.abs(x))) * n)


@settings(max_examples=40, deadline=None)
@given(
    sigma=st.floats(min_value=3.0, max_value=10.0),
    amplitudes=st.lists(st.floats(min_value=-5.0, max_value=5.0), min_size=1, max_size=3),
    d1=st.floats(min_value=-60.0, max_value=60.0),
    d2=st.floats(min_value=-60.0, max_value=60.0),
)
def test_delays_compose(sigma: float, amplitudes: list[float], d1: float, d2: float) -> None:
    n, dt = 512, 1e-6
    x = sum(a * gaussian(n, 236.0 + 20.0 * i, sigma) for i, a in enumerate(amplitudes))
    twice = disp.delay(disp.delay(x, sample_interval=dt, delay=d1 * dt), sample_interval=dt, delay=d2 * dt)
    once = disp.delay(x, sample_interval=dt, delay=(d1 + d2) * dt)
    np.testing.assert_allclose(twice, once, rtol=0, atol=1e-8 * (1.0 + max(abs(a) for a in amplitudes)))


# ---------------------------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: disp.pochhammer_phase_velocity_ratio(0.5, 0.5), "nu"),
        (lambda: disp.pochhammer_phase_velocity_ratio(0.5, -0.1), "nu"),
        (lambda: disp.pochhammer_phase_velocity_ratio(-0.1, 0.3), "d_over_lambda"),
        (lambda: disp.pochhammer_phase_velocity_ratio(np.nan, 0.3), "d_over_lambda"),
        (lambda: disp.phase_velocity_curve(0.3, n=3), "n must"),
        (lambda: disp.phase_velocity([-1.0], c0=5000.0, diameter=0.02, nu=0.3), "frequency"),
        (lambda: disp.phase_velocity([1.0], c0=0.0, diameter=0.02, nu=0.3), "c0"),
        (lambda: disp.phase_velocity([1.0], c0=5000.0, diameter=0.02, nu=0.3, inner_diameter=0.02), "inner_diameter"),
        (lambda: disp.first_mode_cutoff(c0=5000.0, diameter=-0.02, nu=0.3), "diameter"),
        (lambda: disp.propagate([0.0, 1.0], sample_interval=1e-6, distance=1.0, c0=5000.0, dispersive=True), "diameter"),
        (lambda: disp.propagate([0.0, 1.0], sample_interval=1e-6, distance=1.0, c0=5000.0, pad_factor=0.5), "pad_factor"),
        (lambda: disp.propagate([], sample_interval=1e-6, distance=1.0, c0=5000.0), "at least one sample"),
        (lambda: disp.propagate([0.0, np.inf], sample_interval=1e-6, distance=1.0, c0=5000.0), "finite"),
        (lambda: disp.delay([0.0, 1.0], sample_interval=0.0, delay=1e-6), "sample_interval"),
        (lambda: disp.delay([0.0, 1.0], sample_interval=1e-6, delay=np.nan), "delay"),
    ],
)
def test_bad_input_raises_value_error(call, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        call()
