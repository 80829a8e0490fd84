"""The package's one AR(1) noise generator: stationary statistics and the order of its draws."""

from __future__ import annotations

import numpy as np
import pytest

from friction_uq.noise import ar1_noise, white_and_ar1_noise


@pytest.mark.parametrize("start", ["extra_draw", "first_draw"])
def test_ar1_noise_is_stationary_with_the_requested_sd_and_lag1(start: str) -> None:
    x = ar1_noise((400, 500), sd=2.0, rho=0.7, rng=np.random.default_rng(5), start=start)
    # 2e5 samples, effective ~ n (1 - rho)/(1 + rho) ~ 3.5e4: relative sd of the estimates ~ 0.5 %
    assert np.std(x) == pytest.approx(2.0, rel=0.03)
    assert np.mean(x[:, 1:] * x[:, :-1]) / np.mean(x * x) == pytest.approx(0.7, abs=0.02)
    # the start is stationary: the first sample has the marginal sd (400 series: 3.5 % relative sd)
    assert np.std(x[:, 0]) == pytest.approx(2.0, rel=0.15)


@pytest.mark.parametrize("start", ["extra_draw", "first_draw"])
def test_same_seed_same_bits(start: str) -> None:
    a = ar1_noise(1000, sd=1e-6, rho=0.5, rng=np.random.default_rng(3), start=start)
    b = ar1_noise(1000, sd=1e-6, rho=0.5, rng=np.random.default_rng(3), start=start)
    np.testing.assert_array_equal(a, b)


def test_order_of_the_draws() -> None:
    """The documented order: "first_draw" starts from the first normal, "extra_draw" from the (n+1)-th."""
    n, sd, rho = 50, 3.0, 0.4
    z = np.random.default_rng(8).standard_normal(n + 1)
    first = ar1_noise(n, sd=sd, rho=rho, rng=np.random.default_rng(8), start="first_draw")
    extra = ar1_noise(n, sd=sd, rho=rho, rng=np.random.default_rng(8))
    assert first[0] == pytest.approx(sd * z[0], rel=1e-15)
    assert extra[0] == pytest.approx(sd * z[n], rel=1e-15)
    innovation = sd * np.sqrt(1.0 - rho**2) * z[1]
    assert first[1] == pytest.approx(rho * first[0] + innovation, rel=1e-14)
    assert extra[1] == pytest.approx(rho * extra[0] + innovation, rel=1e-14)


def test_white_part_takes_its_fraction_of_the_variance() -> None:
    x = white_and_ar1_noise(200_000, sd=2.0, rho=0.8, white_fraction=0.25, rng=np.random.default_rng(2))
    assert np.std(x) == pytest.approx(2.0, rel=0.03)
    # lag-1 correlation of the mixture: (1 - white_fraction) rho = 0.6
    assert np.mean(x[1:] * x[:-1]) / np.mean(x * x) == pytest.approx(0.6, abs=0.02)


def test_unknown_start_is_refused() -> None:
    with pytest.raises(ValueError, match="start 'middle' is not understood"):
        ar1_noise(10, sd=1.0, rho=0.5, rng=np.random.default_rng(0), start="middle")  # type: ignore[arg-type]
