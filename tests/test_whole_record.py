"""Whole-record comparison and the misfit decision."""

from __future__ import annotations

import math
from types import MappingProxyType

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.analysis import prepare
from friction_uq.discrepancy.check import check_whole_record
from friction_uq.discrepancy.misfit import misfit_detected, predictive_quadratic, tolerated
from friction_uq.discrepancy.whole_record import longest_sign_run, whiten
from friction_uq.likelihood import ar1_noise
from friction_uq.prior_loader import default_prior_path, load_priors
from friction_uq.record import read_record
from friction_uq.simulate import simulate_to_file
from simulated import noisy_config


@settings(max_examples=25, deadline=None)
@given(st.floats(0.0, 0.9), st.floats(1e-7, 1e-4), st.integers(0, 2**32 - 1))
def test_whitened_ar1_noise_is_unit_white_noise(rho, sd, seed):
    e = ar1_noise((4000,), sd=sd, rho=rho, rng=np.random.default_rng(seed))
    w = whiten(e, sd=sd, rho=rho)
    # mean of w^2 ~ 1 +- sqrt(2/n) = 0.022; lag-1 correlation ~ 0 +- 1/sqrt(n) = 0.016
    assert abs(np.mean(w * w) - 1.0) < 5 * math.sqrt(2 / 4000)
    assert abs(np.corrcoef(w[1:], w[:-1])[0, 1]) < 5 / math.sqrt(4000)


def test_longest_sign_run():
    assert longest_sign_run(np.array([1, 2, -1, -2, -3, 4])) == 3
    assert longest_sign_run(np.array([-1.0])) == 1
    assert longest_sign_run(np.array([1, 0, 1, 1])) == 2
    assert longest_sign_run(np.array([])) == 0


def test_predictive_quadratic_matches_the_dense_covariance():
    rng = np.random.default_rng(3)
    n, k, sd, rho = 60, 7, 2.0, 0.6
    e = rng.normal(size=n)
    draws = rng.normal(size=(k, n)) * 0.8 + np.linspace(0, 1, n)
    i = np.arange(n)
    S = sd**2 * rho ** np.abs(i[:, None] - i[None, :])
    U = (draws - draws.mean(axis=0)).T / math.sqrt(k - 1)
    dense = float(e @ np.linalg.solve(S + U @ U.T, e))
    assert predictive_quadratic(e, draws, sd=sd, rho=rho) == pytest.approx(dense, rel=1e-9)


def test_tolerance_forgives_only_what_lies_inside_it():
    r = np.array([0.5, -0.5, 2.0, -3.0])
    np.testing.assert_allclose(tolerated(r, np.ones(4)), [0.0, 0.0, 1.0, -2.0])


def _check(path, *, dispersion=False):
    rec = read_record(path)
    prep = prepare(rec, dispersion=dispersion)
    priors = load_priors(default_prior_path("I1"))
    log_prior = lambda v: float(priors.logpdf(np.array([[v["f"], v["nu"], 1.0]]))[0])  # noqa: E731
    from friction_uq.analysis import identify

    lab = identify(prep, nu=0.4)
    return check_whole_record(prep, log_prior, {"f": lab.f, "nu": 0.4}, hoop=True, seed=1)


@pytest.mark.parametrize("seed", [1, 2])
def test_clean_record_has_no_misfit(tmp_path, seed):
    path = tmp_path / "clean.h5"
    simulate_to_file(noisy_config(striker_velocity=8.0 + seed, poisson_ratio=0.41,
                             friction_params=MappingProxyType({"f": 0.06})), path, seed=seed)
    chk = _check(path)
    assert not chk.decision.detected, chk.decision.sentence()
    assert "reproduces all 4 gauges" in chk.decision.sentence()
    assert chk.fit.mode["nu"] == pytest.approx(0.41, abs=0.01)


def test_the_gate_on_a_model_s_predicted_gauges_flags_a_gauge_read_10_percent_off(tmp_path):
    """misfit_detected, which the swap check asks of the model without a candidate: the record's own gauges as the
    prediction are within the tolerance; the input bar's read 10 % low is not."""
    path = tmp_path / "clean.h5"
    simulate_to_file(noisy_config(striker_velocity=9.0, friction_params=MappingProxyType({"f": 0.06})), path, seed=3)
    prep = prepare(read_record(path))
    exact = {ch: (prep.record.strain(ch) - prep.forces.channels[ch].noise.offset)[None, :]
             for ch in prep.record.channels}
    assert not misfit_detected(prep, exact)
    assert misfit_detected(prep, exact | {"input_bar": 0.9 * exact["input_bar"]})


def test_plug_friction_is_a_misfit(tmp_path):
    path = tmp_path / "plug.h5"
    simulate_to_file(noisy_config(plug_friction_force=400.0, plug_friction_coefficient=0.02), path, seed=4)
    chk = _check(path)
    assert chk.decision.detected
    assert chk.decision.statistic > chk.decision.threshold
    # the plug's force leads the wall friction: it is seen where it leads, in the first half of the external rise
    assert ("external_output_bar", "early rise") in [(c.channel, c.phase) for c in chk.decision.flagged()]
    sentence = chk.decision.sentence()
    assert ("above" in sentence or "below" in sentence or "shape" in sentence), sentence
    # the report draws two channels a page (reflected and internal, then external and hoop): the sentence sends the
    # reader to the page of the channel it names
    worst = chk.decision.worst.channel
    page = {"input_bar": 9, "internal_output_bar": 9, "external_output_bar": 10, "tube_hoop": 10}[worst]
    assert f"see page {page}." in chk.decision.sentence(page=9), (worst, chk.decision.sentence(page=9))


def test_clearance_is_a_misfit_on_the_hoop_gauge(tmp_path):
    """A 10 um clearance delays and lowers the wall pressure: the hoop gauge reads well below the model."""
    path = tmp_path / "gap.h5"
    simulate_to_file(noisy_config(gap=10e-6, tube_compliance=True), path, seed=5)
    chk = _check(path)
    assert chk.decision.detected
    assert any(c.channel == "tube_hoop" for c in chk.decision.flagged())
    assert "see page 9." in chk.decision.sentence(page=9)  # the worst is the internal gauge's rise, on that page


def test_the_check_of_a_dispersion_corrected_analysis_has_dispersive_bars(tmp_path):
    """A record whose bars disperse: the check of an analysis with --dispersion simulates dispersive bars, as the
    analysis reads them, and misses the record by much less than the check with 1-D bars."""
    path = tmp_path / "d.h5"
    simulate_to_file(noisy_config(dispersion=True), path, seed=3)
    plain, disp = _check(path), _check(path, dispersion=True)
    assert plain.decision.detected
    assert (disp.decision.statistic / disp.decision.threshold
            < 0.5 * plain.decision.statistic / plain.decision.threshold)


def test_the_check_uses_a_cells_own_tolerance_where_one_is_set(tmp_path, monkeypatch):
    """CHECK_TOLERANCE (set on axisymmetric records) widens the tolerance of its channel and phase only: the
    worst cell of a plug-friction record drops, every other cell is the same number as before."""
    from friction_uq.discrepancy import misfit

    path = tmp_path / "plug.h5"
    simulate_to_file(noisy_config(plug_friction_force=400.0, plug_friction_coefficient=0.02), path, seed=4)
    chk = _check(path)
    before = {(c.channel, c.phase): c.statistic for c in chk.decision.cells}
    worst = max(before, key=before.get)
    monkeypatch.setitem(misfit.CHECK_TOLERANCE, worst, (0.10, 0.5e-6))
    after = {(c.channel, c.phase): c.statistic for c in misfit.decide(chk.comparison).cells}
    assert after[worst] < before[worst]
    assert {k: v for k, v in after.items() if k != worst} == {k: v for k, v in before.items() if k != worst}


def test_a_cells_own_threshold_decides_that_cell_only(tmp_path, monkeypatch):
    """CELL_THRESHOLD gives one channel and phase its own threshold: the record's decision is then that of the cell
    furthest over its own threshold, named with it; every other cell keeps the record threshold."""
    from friction_uq.discrepancy import misfit

    path = tmp_path / "clean.h5"
    simulate_to_file(noisy_config(friction_params=MappingProxyType({"f": 0.06})), path, seed=1)
    chk = _check(path)
    assert not chk.decision.detected
    cell = max(chk.decision.cells, key=lambda c: c.statistic / c.threshold)
    monkeypatch.setitem(misfit.CELL_THRESHOLD, (cell.channel, cell.phase), 0.5 * cell.statistic)
    d = misfit.decide(chk.comparison)
    assert d.detected and [(c.channel, c.phase) for c in d.flagged()] == [(cell.channel, cell.phase)]
    assert d.statistic == pytest.approx(cell.statistic) and d.threshold == pytest.approx(0.5 * cell.statistic)
    assert f"threshold {0.5 * cell.statistic:g}" in d.sentence()
    with pytest.raises(ValueError, match="threshold"):
        misfit.decide(chk.comparison, threshold=0.0)
    assert all(c.threshold == misfit.cell_threshold(c.channel, c.phase) for c in d.cells
               if (c.channel, c.phase) != (cell.channel, cell.phase))


def test_the_external_bars_rise_is_tested_as_two_halves(tmp_path):
    """SPLIT_RISE: the external output bar's rise is two cells, its halves in time, and every other channel's one."""
    from friction_uq.discrepancy import misfit

    path = tmp_path / "clean.h5"
    simulate_to_file(noisy_config(friction_params=MappingProxyType({"f": 0.06})), path, seed=2)
    wr = _check(path).comparison
    spans = {ch: misfit.phase_spans(wr, ch) for ch in wr.phase_bounds}
    ext = spans["external_output_bar"]
    assert [p for p, _, _ in ext][:2] == ["early rise", "late rise"]
    i0, iw0, _, _ = wr.phase_bounds["external_output_bar"]
    assert ext[0][1] == i0 and ext[0][2] == ext[1][1] and ext[1][2] == iw0 and abs(ext[0][2] - (i0 + iw0) / 2) <= 1
    assert all(p[0] == "rise" for ch, sp in spans.items() if ch != "external_output_bar" for p in sp[:1])
    assert misfit.cell_threshold("external_output_bar", "early rise") < misfit.THRESHOLD
    assert misfit.cell_threshold("external_output_bar", "late rise") == misfit.THRESHOLD
