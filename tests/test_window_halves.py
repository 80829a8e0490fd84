"""kappa's change across the stationary window (friction_uq.window_halves): closed forms, invariances, and
the coverage of its standard error on noise the record's own model makes."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.analysis import prepare
from friction_uq.apparatus import paper_apparatus
from friction_uq.physics.cell import force_ratio
from friction_uq.record import read_record
from friction_uq.window import StationaryData
from friction_uq.window_halves import WindowHalves, window_halves

R, L, NU = 0.005, 0.01, 0.4
N = 800
DT = 0.5e-6


def data(f_of_t: np.ndarray, *, F_io: float = 20e3, noise: float = 0.0, seed: int = 0, V: float = 8.0) -> StationaryData:
    """A window whose output forces follow eq. 5 and 13 with f(t), white noise of ``noise`` N on each force."""
    rng = np.random.default_rng(seed)
    t = np.arange(len(f_of_t)) * DT
    F_eo = F_io * force_ratio(f_of_t, NU, radius=R, length=L)
    return StationaryData(
        test_id="t", campaign="S", time=t, F_io=F_io + noise * rng.standard_normal(t.size),
        F_eo=F_eo + noise * rng.standard_normal(t.size), V=np.full(t.size, V), slip=1e-3 + V * t, sd_io=noise,
        sd_eo=noise, rho_io=0.0, rho_eo=0.0, radius=R, length=L, tube=paper_apparatus().tube,
        window=(0.0, float(t[-1])), sample_rate=1.0 / DT)


def test_a_step_in_f_between_the_halves_gives_its_log_ratio_exactly():
    f = np.r_[np.full(N // 2, 0.06), np.full(N // 2, 0.045)]
    h = window_halves(data(f))
    assert h is not None
    assert np.isclose(h.log_kappa_change, np.log(0.045 / 0.06), rtol=1e-12)
    # the halves' slip and speed: the means of each half of the window
    assert np.isclose(h.slip[1] - h.slip[0], 8.0 * DT * N / 2) and h.V == (8.0, 8.0)
    # p = tau / f (eq. 18, 20): the friction force grows faster than f (eq. 5, 13), so the half with the higher f
    # has the higher mean pressure too, by the ratio of F_eo / f
    ratio = force_ratio(np.array([0.06, 0.045]), NU, radius=R, length=L) / np.array([0.06, 0.045])
    assert h.pressure_rel[0] > 1.0 > h.pressure_rel[1]
    assert np.isclose(h.pressure_rel[0] / h.pressure_rel[1], ratio[0] / ratio[1], rtol=1e-12)


def test_constant_f_gives_no_change():
    h = window_halves(data(np.full(N, 0.05)))
    assert h is not None and abs(h.log_kappa_change) < 1e-12


@settings(max_examples=40, deadline=None)
@given(scale=st.floats(0.05, 20.0), slope=st.floats(-0.3, 0.3))
def test_a_common_gain_on_both_forces_leaves_the_change_unchanged_and_time_reversal_negates_it(scale, slope):
    f = 0.05 * (1.0 + slope * np.linspace(-0.5, 0.5, N))
    d = data(f, noise=5.0, seed=3)
    h = window_halves(d)
    scaled = window_halves(StationaryData(**{**d.__dict__, "F_io": d.F_io * scale, "F_eo": d.F_eo * scale}))
    assert h is not None and scaled is not None
    assert np.isclose(h.log_kappa_change, scaled.log_kappa_change, rtol=1e-9, atol=1e-12)
    assert np.isclose(h.sd, scaled.sd, rtol=1e-9, atol=1e-12)
    back = window_halves(StationaryData(**{**d.__dict__, "F_io": d.F_io[::-1].copy(), "F_eo": d.F_eo[::-1].copy()}))
    assert back is not None and np.isclose(back.log_kappa_change, -h.log_kappa_change, rtol=1e-9, atol=1e-12)


def test_the_standard_error_covers_the_truth_as_often_as_it_says():
    """400 windows of white noise around a constant f: the 90 % interval change +- 1.645 sd (the batch
    means' spread, 6 degrees of freedom, so a t's 1.943 is the exact 90 %) holds 0 on 90 % of them,
    and on fewer with the normal's 1.645. Tolerance: 3 binomial sd at n = 400 (0.045)."""
    changes = []
    for seed in range(400):
        h = window_halves(data(np.full(N, 0.05), noise=300.0, seed=seed))
        changes.append((h.log_kappa_change, h.sd))
    z = np.array([c / s for c, s in changes])
    assert abs(np.mean(np.abs(z) < 1.943) - 0.90) < 0.045
    assert np.mean(np.abs(z) < 1.645) < 0.90


def test_a_steady_change_does_not_widen_its_own_error():
    """The batches' spread is taken about a line: a change of 10 % across the window leaves sd that of the noise."""
    flat = window_halves(data(np.full(N, 0.05), noise=300.0, seed=11))
    sloped = window_halves(data(0.05 * (1.0 - 0.1 * np.linspace(0.0, 1.0, N)), noise=300.0, seed=11))
    assert flat is not None and sloped is not None
    assert sloped.log_kappa_change < -0.04
    assert sloped.sd == pytest.approx(flat.sd, rel=0.1)


@pytest.mark.parametrize("edit, words", [
    ({"sd": float("nan")}, "'sd' must be a finite number"),
    ({"sd": -0.1}, "sd must be >= 0"),
    ({"slip_m": [0.0, 1e-3]}, "slips, speeds and pressures > 0"),
    ({"V_m_per_s": [True, 8.0]}, "'V_m_per_s' must be a finite number"),
    ({"pressure_over_window_mean": [1.0]}, "a list of two numbers"),
    ({"log_kappa_change": "-0.1"}, "'log_kappa_change' must be a finite number"),
])
def test_a_damaged_record_of_the_change_is_refused_naming_its_key(edit, words):
    good = WindowHalves(-0.05, 0.01, (1e-3, 2e-3), (8.0, 8.1), (1.01, 0.99)).to_json()
    with pytest.raises(ValueError, match=re.escape(words)):
        WindowHalves.from_json(good | edit)
    with pytest.raises(ValueError, match="not an object"):
        WindowHalves.from_json([1, 2])


def test_too_short_a_window_or_a_batch_without_kappa_gives_none():
    assert window_halves(data(np.full(10, 0.05))) is None
    d = data(np.full(N, 0.05))
    F_eo = d.F_eo.copy()
    F_eo[:N // 8] = -2.0 * d.F_io[:N // 8]  # a ratio below -1: no kappa
    assert window_halves(StationaryData(**{**d.__dict__, "F_eo": F_eo})) is None


def test_a_record_of_constant_f_shows_no_change_beyond_its_error_and_reads_back_from_json(good_record):
    h = window_halves(prepare(read_record(good_record), window=None, dispersion=False).data)
    assert h is not None and abs(h.log_kappa_change) < 3 * h.sd + 0.005
    assert h.slip[1] > h.slip[0] > 0 and all(v > 0 for v in h.V)
    assert WindowHalves.from_json(h.to_json()) == h
