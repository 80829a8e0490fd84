"""Naming the bar-level causes of a two-bar force-balance misfit (friction_uq.shpb diagnose).

Two parts. On hand-made two-bar records with a hidden effect (a transmitted gain error, a bar
wave speed off its stated value), the selection must name it and measure it within its posterior.
On the real LANL copper record (``../shared/data/real/lanl-hoppybar-cu/``, skipped with a reason
when absent), measured with seed 0 (blocks with Pareto k > 0.7 left out by refitting):

* nominal model (gain 200 V/V, c0 = 4975 m/s, no dispersion): chi2/dof 3403 against the
  pre-pulse noise, RMS 3351 N = 31.5 % of the peak F_2;
* step 1: wave_speed dELPD 1091 +- 191 (decisive); dispersion 41 +- 80, gauge_gain -13 +- 31
  (not decisive); fitted c = 4830 m/s [4828, 4832], reflection time 2 d / c = 157.8 us (the
  file's calibrated 156.6 us; nominal 153.2 us); after it chi2/dof 235, RMS 8.3 %;
* step 2 on top: dispersion 180 +- 172 (1 SE: improves, not decisive; chi2/dof 150, RMS
  6.6 %), gauge_gain 35 +- 28 (gamma 0.971 [0.964, 0.980]); selection stops;
* all three mechanisms: gamma = 0.9886 +- 0.0040, 197.7 V/V [196.6, 199.0]; the header's 500
  (gamma 2.5) is 379 sd away.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from friction_uq.shpb import (
    BalanceObservation,
    combine,
    diagnose_balance,
    fit_balance,
    read_lanl_raw,
)
from friction_uq.shpb.balance_diagnosis import Candidate

RECORD = (Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "real" / "lanl-hoppybar-cu"
          / "20061201_1148HE_CuOFE_273K.raw")


# ----------------------------------------------------------------------------------------------
# hand-made records with a hidden effect
# ----------------------------------------------------------------------------------------------

def _meta(rod_speed: float) -> list[tuple[str, str]]:
    meta = [("Test Loading", "Compression"), ("Sample Description", "test"), ("Initial Sample Diameter(mm)", "6"),
            ("Initial Sample Length(mm)", "3"), ("Test Temperature(\ufffdC)", "20"), ("Sample Material", "Cu")]
    for bar in ("Incident", "Transmitted"):
        meta += [(f"{bar} Bar {k}", v) for k, v in (
            ("Calibrated Gage Factor", "2.0"), ("Young's Modulus(GPa)", "110"), ("Poisson Ratio", "0.33"),
            ("Rod Sound Speed(m/s)", f"{rod_speed:.0f}"), ("Density(kg/m^3)", "4400"), ("Diameter(mm)", "10"),
            ("Strain Gage Location(mm)", "400"), ("Excitation Voltage(V)", "10"), ("Calibrated Gain", "100"))]
    return meta


def write_record(path: Path, *, gain_error: float, rod_speed: float, seed: int) -> Path:
    """Incident at sample 300, reflected and transmitted at 1900 (true 2 d / c = 160 us: c = 5000 m/s).

    The transmitted wave is read ``gain_error`` times too large; the file states ``rod_speed``.
    The specimen's force rises more slowly than the incident wave (a 60-sample ramp against 20).
    """
    n, i = 3000, np.arange(3000)
    rng = np.random.default_rng(seed)

    def trapezoid(at: int, rise: int) -> np.ndarray:
        return np.clip((i - at) / rise, 0, 1) * np.clip((at + 500 - i) / rise, 0, 1)

    inc = trapezoid(300, 20)
    tra = 0.5 * trapezoid(1900, 60)
    ref = tra - np.roll(inc, 1600)  # F_1 = F_2 at the specimen: eps_i + eps_r = eps_t
    inp = inc + ref + rng.normal(0, 2e-3, n)
    out = gain_error * tra + rng.normal(0, 2e-3, n)
    rows = [["Test Date", "1/1/2000", "Incident/Reflected Waveform", "Transmitted Waveform"]]
    rows += [["", "", "-1.0E-05", "-1.0E-05"], ["", "", "1.0E-07", "1.0E-07"]]
    rows += [["", "", f"{a:.6f}", f"{b:.6f}"] for a, b in zip(inp, out, strict=True)]
    for row, (k, v) in zip(rows[1:], _meta(rod_speed), strict=False):
        row[0], row[1] = k, v
    path.write_text("\r\n".join("\t".join(r) for r in rows) + "\r\n", encoding="utf-8")
    return path


def test_hidden_gain_and_wave_speed_are_named_and_measured(tmp_path: Path) -> None:
    # truth: gain factor 1.25, c / c0 = 5000 / 5100
    rec = read_lanl_raw(write_record(tmp_path / "hidden.raw", gain_error=1.25, rod_speed=5100.0, seed=5))
    result = diagnose_balance(BalanceObservation(rec), seed=1, n_draws=100)
    assert set(result.causes) == {"gauge_gain", "wave_speed"}
    assert "dispersion" not in result.causes
    f = result.final
    for name, truth in (("gain_factor", 1.25), ("speed_factor", 5000.0 / 5100.0)):
        s = f.summary(name)
        assert abs(s["mean"] - truth) < 4.0 * s["sd"], (name, s, truth)
    assert f.misfit.chi2_dof < 1.5  # the hidden effects explain the record down to its noise
    assert result.nominal.misfit.chi2_dof > 10.0


def test_clean_record_names_nothing(tmp_path: Path) -> None:
    rec = read_lanl_raw(write_record(tmp_path / "clean.raw", gain_error=1.0, rod_speed=5000.0, seed=6))
    result = diagnose_balance(BalanceObservation(rec), seed=2, n_draws=100)
    assert result.causes == ()
    assert result.nominal.misfit.chi2_dof < 1.5


def test_same_seed_same_bits(tmp_path: Path) -> None:
    obs = BalanceObservation(read_lanl_raw(write_record(tmp_path / "s.raw", gain_error=1.1, rod_speed=5000.0,
                                                        seed=7)))
    a, b = (fit_balance(obs, combine(["gauge_gain"]), rng=np.random.default_rng(3), n_draws=50) for _ in range(2))
    np.testing.assert_array_equal(a.draws["gain_factor"], b.draws["gain_factor"])
    assert a.elpd.total == b.elpd.total


def test_unknown_mechanism_is_refused() -> None:
    with pytest.raises(ValueError, match=r"bar mechanism\(s\) 'clearance' not understood, allowed values: "
                                         r"gauge_gain, wave_speed, dispersion"):
        combine(["wave_speed", "clearance"])


def test_decision_rule() -> None:
    def decisive(d: float, se: float) -> bool:  # a selection step's verdict on a candidate (its fit is not read)
        return Candidate("gauge_gain", None, d, se).decisive

    assert decisive(4.1, 2.0) and not decisive(4.0, 1.0) and not decisive(50.0, 25.1)


# ----------------------------------------------------------------------------------------------
# the real LANL copper record
# ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def lanl():
    if not RECORD.is_file():
        pytest.skip(f"real LANL record not found at {RECORD}: the shared data directory "
                    "(../shared/data/real/lanl-hoppybar-cu/) is not beside this repository")
    obs = BalanceObservation(read_lanl_raw(RECORD))
    return obs, diagnose_balance(obs, seed=0)


def test_lanl_nominal_model_misses(lanl) -> None:
    obs, result = lanl
    assert obs.header_gain == 200.0
    m = result.nominal.misfit
    # far beyond the noise (chi2/dof ~ 1 under "the model is right"), measured 3403 and 31.5 %
    assert m.chi2_dof > 1000.0
    assert m.relative_rms > 0.2


def test_lanl_wave_speed_is_the_named_cause(lanl) -> None:
    obs, result = lanl
    step = result.steps[0]
    assert step.added == "wave_speed" and result.causes[0] == "wave_speed"
    best = step.candidates[0]
    # decisive by the rule with room: measured 1091 +- 191 (5.7 SE); the other two within 0.6 SE of 0
    assert best.delpd > 4.0 * best.se
    assert all(not c.decisive for c in step.candidates[1:])
    ib = obs.record.input_bar
    s = best.fit.summary("speed_factor")
    # off nominal: c0 lies ~100 posterior sd away (measured 4830 m/s, sd 1.3 m/s, with the noise
    # scale fitted); > 50 asks for a speed off nominal by far more than the posterior allows
    assert (1.0 - s["mean"]) / s["sd"] > 50.0
    # the travel time found agrees with the file's own calibrated reflection time (156.6 us, an
    # independent measurement) to within the copper specimen's elastic transit time (3.2 mm at
    # ~3.8 km/s: 0.84 us), which the balance model also loads on the bars, plus the 0.1 us sample:
    # 1.5 us; the nominal 2 d / c0 is 3.4 us short of it. Measured: 157.8 us.
    t_fit = 2.0 * ib.gauge_distance / (s["mean"] * ib.wave_speed)
    t_cal = 2.0 * ib.gauge_distance / ib.timing_wave_speed
    assert abs(t_fit - t_cal) < 1.5e-6
    assert t_fit - 2.0 * ib.gauge_distance / ib.wave_speed > 3.0e-6


def test_lanl_dispersion_improves_but_is_not_decisive(lanl) -> None:
    _, result = lanl
    assert result.causes == ("wave_speed",)
    step = result.steps[1]
    assert step.added is None
    disp = next(c for c in step.candidates if c.mechanism == "dispersion")
    # dELPD 180 +- 172: positive, about one SE, short of the rule's two; chi2/dof 235 -> 150
    assert 0.0 < disp.delpd < 2.0 * disp.se
    assert disp.fit.misfit.chi2_dof < 0.75 * step.base.misfit.chi2_dof


def test_lanl_gain_is_the_header_200_not_500(lanl) -> None:
    obs, _ = lanl
    full = fit_balance(obs, combine(["gauge_gain", "wave_speed", "dispersion"]), rng=np.random.default_rng(0))
    s = full.summary("gain_factor")
    # the header's other statement (500 V/V: gamma = 2.5) is excluded by hundreds of sd (measured 378)
    assert (2.5 - s["mean"]) / s["sd"] > 100.0
    # and 200 stands within the model error still in the residual: the fitted gain (measured
    # 197.7 V/V, sd 0.8) is within the fit's residual RMS (6.6 % of the peak force) of 200
    assert abs(math.log(s["mean"])) < full.misfit.relative_rms


def test_registry_documents_each_mechanism() -> None:
    from friction_uq.shpb.balance_mechanisms import GAIN_LOG_SD, MECHANISMS, lognormal_logpdf

    assert list(MECHANISMS) == ["gauge_gain", "wave_speed", "dispersion"]
    for m in MECHANISMS.values():
        assert m.meaning and m.signature, m.name
        for p in m.parameters:
            assert p.contains(1.0) and p.name in m.prior_log_sd, (m.name, p.name)
    # the gain prior puts the header's other statement (500 against 200) at two prior sd
    assert math.log(2.5) / GAIN_LOG_SD == pytest.approx(2.0)
    drop = lognormal_logpdf(1.0, log_sd=GAIN_LOG_SD) - lognormal_logpdf(2.5, log_sd=GAIN_LOG_SD)
    assert drop == pytest.approx(2.0 + math.log(2.5))  # z^2 / 2 and the 1 / x of the density
    with pytest.raises(ValueError, match=r"bar mechanism 'dispersion' is already registered"):
        from friction_uq.shpb.balance_mechanisms import register

        register(MECHANISMS["dispersion"])
