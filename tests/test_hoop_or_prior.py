"""The hoop gauge against nu's prior (friction_uq.hoop_or_prior): a hoop gauge read off its scale moved f by the
same factor with only a prior-data note; now f is quoted from both readings, and a campaign pools what is quoted."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from friction_uq.hoop_or_prior import HOOP_OR_PRIOR_GROUP, disagree
from friction_uq.stats.thinning import equal_parts
from friction_uq.prior_sensitivity import PriorDataConflict

ROOT = Path(__file__).resolve().parent.parent


def _conflict(flags: dict[str, str]) -> PriorDataConflict:
    names = ("f", "nu", "hoop_gain")
    diag = {n: flags.get(n, "") for n in names}
    flagged = tuple(n for n in names if diag[n] and (n == "f" or diag[n] == "prior-data conflict"))
    return PriorDataConflict({n: 0.1 for n in names}, {n: 0.1 for n in names}, diag, flagged, 0.05)


def test_the_readings_disagree_on_a_conflict_over_nu_or_when_neither_f_holds_the_others_median():
    rng = np.random.default_rng(0)
    low, high = rng.normal(0.05, 0.004, 4000), rng.normal(0.09, 0.006, 4000)
    assert disagree(_conflict({"nu": "prior-data conflict"}), low, low)  # the check's own word on nu
    assert disagree(_conflict({"f": "prior dominates the data"}), low, high)  # fitted through f: far apart
    # a squeezed f prior flags f under both readings alike: not the hoop gauge's doing
    assert not disagree(_conflict({"f": "prior dominates the data"}), low, rng.normal(0.051, 0.004, 4000))


def test_equal_parts_takes_as_many_draws_of_each():
    a, b = np.zeros(10), np.ones(7)
    both = equal_parts(a, b)
    assert both.size == 14 and both.sum() == 7


@pytest.fixture(scope="module")
def half_scale_hoop(tmp_path_factory) -> tuple[dict, Path]:
    """A-03 with its hoop gauge read at half its scale (a half bridge declared a quarter one), through run."""
    from friction_uq.record_run import run_file

    tmp = tmp_path_factory.mktemp("hoop")
    rec = tmp / "A-03.h5"
    shutil.copy(ROOT / "data" / "A" / "A-03.h5", rec)
    with h5py.File(rec, "r+") as fh:
        fh["signals/tube_hoop"][...] = fh["signals/tube_hoop"][...] * 0.5
    res = run_file(rec, out_dir=tmp / "out", seed=3, pdf=False, progress=False, table=False, notes=False,
                   whole_record=False)
    return json.loads(res.outputs["json"].read_text()), res.outputs["netcdf"]


def test_a_hoop_gauge_off_its_scale_gives_f_from_both_readings(half_scale_hoop):
    doc, _ = half_scale_hoop
    hp = doc["hoop_or_prior"]
    assert hp is not None and "nu" in hp["flagged"]
    fh, fp, f = hp["f_with_hoop"], hp["f_prior_nu_alone"], doc["f"]
    assert fh["q05"] > fp["q95"]  # the two readings exclude each other ...
    assert f["q05"] <= fp["q50"] and fh["q50"] <= f["q95"]  # ... and the f quoted holds both
    assert f["q05"] == hp["f_quoted"]["q05"] and "in equal parts" in f["source"]
    assert 0.35 < hp["hoop_scale_against_prior_nu"] < 0.6  # read at half its scale
    said = [w for w in doc["warnings"] if w.startswith("The tube's hoop gauge and the prior file disagree")]
    assert len(said) == 1 and not any(w.startswith("The prior file and the data disagree") for w in doc["warnings"])
    assert f"from {f['q05']:.4g} to {f['q95']:.4g} (90 %)" in said[0]
    assert doc["warning_kinds"][doc["warnings"].index(said[0])] == "hoop_or_prior"


def test_the_headline_of_two_readings_gives_each_and_no_median_between_them():
    """The mixture's median can sit between the readings, where neither puts weight (a hoop gauge at 0.3 times:
    0.091 between 0.045 and 0.151): the headline gives the interval and each reading's median."""
    from friction_uq.report.quote import quote_line

    fx = {"q05": 0.038, "q50": 0.070, "q95": 0.099, "mean": 0.068, "sd": 0.02}
    line = quote_line(fx, None, 2, both={"prior": 0.0453, "hoop": 0.0899})
    assert line.startswith("Headline f from 0.0380 to 0.0990 (90 %") and "0.0700" not in line
    assert "nu from the prior file alone (0.0453) and with the hoop gauge (0.0899)" in line


def test_the_campaign_pools_the_f_the_run_quotes(half_scale_hoop):
    from friction_uq.campaigns.draws import read_test_posterior

    doc, nc = half_scale_hoop
    with h5py.File(nc) as h:
        assert h[HOOP_OR_PRIOR_GROUP]["f"].shape[0] > 0
    r = SimpleNamespace(outputs={"netcdf": nc.name}, label="A-03", campaign="A", window_halves=None, warnings=[], warning_kinds=[],
                        prior_file=doc["prior_file"], summary={"V": doc["V"]}, path=str(nc))
    post = read_test_posterior(r, nc.parent)
    assert np.quantile(post.f, 0.05) < doc["hoop_or_prior"]["f_prior_nu_alone"]["q50"]
    assert np.quantile(post.f, 0.95) > doc["hoop_or_prior"]["f_with_hoop"]["q50"]
    # nu (and p_mean, which follows it) the same two readings, not the hoop gauge's alone: a campaign's pooled nu
    # moved from 0.373 to 0.337 with one test's hoop gauge at half its scale
    nu_hoop, nu_prior = doc["hoop_or_prior"]["nu_with_hoop"], doc["hoop_or_prior"]["nu_prior"]
    assert np.mean(post.nu < nu_hoop["q95"]) == pytest.approx(0.5, abs=0.05)
    assert np.mean(post.nu > nu_prior["q05"]) == pytest.approx(0.5, abs=0.1)
    assert np.all(np.isfinite(post.kappa)) and np.all(post.p_mean > 0)


def test_a_sound_hoop_gauge_is_read_alone(tmp_path):
    from friction_uq.record_run import run_file

    res = run_file(ROOT / "data" / "A" / "A-03.h5", out_dir=tmp_path, seed=3, pdf=False, progress=False, table=False,
                   notes=False, whole_record=False)
    doc = json.loads(res.outputs["json"].read_text())
    assert doc["hoop_or_prior"] is None and doc["f"]["source"] == "the stationary analysis (eq. 17 and the hoop gauge)"


def test_under_diagnose_the_warning_gives_the_diagnosed_f_quoted_with_the_priors_nu():
    from friction_uq.hoop_or_prior import HoopOrPrior

    hp = HoopOrPrior({"q05": 0.23, "q50": 0.25, "q95": 0.27}, {"q05": 0.35, "q50": 0.4, "q95": 0.45}, 0.45,
                     {"q05": 0.08, "q50": 0.09, "q95": 0.1}, {"q05": 0.036, "q50": 0.045, "q95": 0.057},
                     {"q05": 0.038, "q50": 0.07, "q95": 0.099}, {}, (("nu", "prior-data conflict"),))
    said = hp.sentence(diagnosed={"q05": 0.041, "q50": 0.06, "q95": 0.075})
    assert "`diagnose`'s models read nu through the hoop gauge as well" in said
    assert "f from the prior's nu alone in equal parts, from 0.041 to 0.075 (90 %)" in said
    assert "the f quoted holds both" in hp.sentence() and "0.038 to 0.099" in hp.sentence()


def _diagnosed(f_prior_nu=None):
    """A diagnosis that named a clearance, f 0.065 +- 0.004 with nu read through the hoop gauge."""
    from friction_uq.discrepancy.diagnosis import Diagnosis
    from friction_uq.discrepancy.extended import Variant
    from friction_uq.discrepancy.mechanisms import MECHANISMS
    from friction_uq.discrepancy.verdict import Verdict

    clearance = Variant(MECHANISMS["clearance"])
    z = np.random.default_rng(2).standard_normal(3000)
    fin = SimpleNamespace(label="clearance", variants=(clearance,), f_effective=0.065 + 0.004 * z)
    return Diagnosis(baseline=SimpleNamespace(label="baseline", variants=()), rounds=(), misfits=(),
                     causes=(clearance,), not_separable=(), separate_by=None, final=fin,
                     verdicts=(Verdict("named", (), named="clearance"),), f_prior_nu=f_prior_nu)


def test_a_diagnosed_f_reading_a_disputed_hoop_gauge_is_quoted_with_the_priors_nu_in_equal_parts():
    """A-03 with its hoop gauge at half its scale, run --diagnose: the named causes' f 0.065 [0.050, 0.076] for
    0.048, every model reading nu through the gauge. The f to quote now holds it and the stationary f from nu's
    prior alone in equal parts, each half folding in its own calibration; the headline, the warnings and the
    sentence give its interval and not the median between the two."""
    from friction_uq.discrepancy.diagnosed_f import _folded, f_draws_to_quote, headline, readings_of_nu
    from friction_uq.discrepancy.diagnosis_words import _f_said
    from friction_uq.quoted import folded_sd
    from friction_uq.record_run.warnings import _next_step
    from friction_uq.report.quote import f_to_quote, quote_line

    prior = 0.045 + 0.006 * np.random.default_rng(3).standard_normal(2000)
    alone, both = _diagnosed(), _diagnosed(prior)
    assert readings_of_nu(alone) is None and f_draws_to_quote(alone).size == 3000
    x = f_draws_to_quote(both)
    assert x.size == 4000 and np.mean(x < 0.055) == pytest.approx(0.5, abs=0.02)
    sd = _folded(both)
    assert sd.shape == x.shape and np.all(sd[2000:] == folded_sd()) and np.all(sd[:2000] == _folded(alone))
    fx, f1 = headline(both)[1], headline(alone)[1]
    assert fx["q05"] < 0.045 < 0.065 < fx["q95"] and f1["q05"] > 0.055  # alone, the truth's side is left out
    two = readings_of_nu(both)
    assert two["diagnosed"] == pytest.approx(0.065, abs=0.001) and two["prior"] == pytest.approx(0.045, abs=0.001)
    source, quoted = f_to_quote({"q05": 0.0, "q50": 0.0, "q95": 0.0}, both)
    assert quoted == fx and source.endswith("in equal parts with the stationary analysis with nu from the prior file "
                                            "alone (the hoop gauge, through which every model reads nu, and the "
                                            "prior file disagree)")
    line = quote_line({"q05": 0.0, "q50": 0.0, "q95": 0.0}, both, 2)
    assert line.startswith(f"Headline f from {fx['q05']:.4f} to {fx['q95']:.4f} (90 %") and f"{fx['q50']:.4f}" not in line
    assert f"nu read through the hoop gauge ({two['diagnosed']:.4f})" in line
    assert f"nu from the prior file alone ({two['prior']:.4f}), which disagree, in equal parts" in line
    said = _next_step(both, None)
    assert f"from {fx['q05']:.4g} to {fx['q95']:.4g} (the JSON's f, half of it with nu from the prior file alone)" \
        in said and f"{fx['q50']:.4g}" not in said, said
    assert _f_said(both, fx).startswith(f"f from {fx['q05']:.3f} to {fx['q95']:.3f} (half of it")
    assert _f_said(alone, f1) == f"f = {f1['q50']:.3f} [{f1['q05']:.3f}, {f1['q95']:.3f}]"


# long: 482 s in a CI run (three rounds of diagnose on a bundled record with nu read two ways), which with the
# tests the default suite gave to the slow ones took CI past an hour; its pieces are default tests above and below
@pytest.mark.long
@pytest.mark.slow
def test_run_diagnose_on_a_hoop_gauge_at_half_its_scale_quotes_both_readings(tmp_path):
    """The record end to end (7-8 min on 2 cores): `run --diagnose` named causes whose f, 0.065 [0.050, 0.076], read nu
    through the gauge and left out the sample's 0.048; the JSON's f now holds the stationary reading from nu's prior
    alone as well, and the one warning about the gauge gives the same interval."""
    from friction_uq.record_run import run_file

    rec = tmp_path / "A-03.h5"
    shutil.copy(ROOT / "data" / "A" / "A-03.h5", rec)
    with h5py.File(rec, "r+") as fh:
        fh["signals/tube_hoop"][...] = fh["signals/tube_hoop"][...] * 0.5
        truth = float(fh["truth"].attrs["friction_f_d"]), float(fh["truth"].attrs["friction_f_s"])
    res = run_file(rec, out_dir=tmp_path / "out", seed=1, pdf=False, progress=False, table=False, notes=False,
                   diagnose=True)
    doc = json.loads(res.outputs["json"].read_text())
    f, two, hp = doc["f"], doc["f"]["readings_of_nu"], doc["hoop_or_prior"]
    assert doc["discrepancy"]["causes"] and res.diagnosis.f_prior_nu is not None
    assert two["prior_nu_alone"] == pytest.approx(float(np.median(res.diagnosis.f_prior_nu)), rel=1e-12)
    assert f["q05"] < min(two.values()) and max(two.values()) < f["q95"]
    assert f["q05"] < hp["f_prior_nu_alone"]["q50"] and truth[0] < f["q05"] and f["q95"] < truth[1]
    said = [w for w in doc["warnings"] if w.startswith("The tube's hoop gauge and the prior file disagree")]
    assert len(said) == 1 and f"from {f['q05']:.4g} to {f['q95']:.4g} (90 %)" in said[0]
    assert doc["schema_version"] == 14


def test_a_diagnosed_campaign_pools_the_stationary_readings_of_a_test_whose_hoop_gauge_disagrees(tmp_path):
    """Its diagnosed models read nu through the disputed gauge, and the run's f mixes them with the prior's nu
    alone, a mixture whose prior the campaign cannot divide out: the stationary f of both readings is pooled in
    their place, under the prior file's f prior."""
    import xarray as xr

    from friction_uq.campaigns.draws import read_test_posterior
    from friction_uq.prior_loader import PRIORS_DIR, load_priors

    prior = str(PRIORS_DIR / "I1.toml")
    post = {k: (("chain", "draw"), np.full((1, 400), m)) for k, m in (("f", 0.09), ("kappa", 0.03), ("nu", 0.25),
                                                                      ("p_mean", 4e7))}
    both = {"f": np.r_[np.full(400, 0.09), np.full(400, 0.045)], "nu": np.r_[np.full(400, 0.25), np.full(400, 0.4)],
            "kappa": np.full(800, 0.03), "p_mean": np.full(800, 4e7)}
    model = {"f_effective": (("chain", "draw"), np.full((1, 400), 0.065)),
             "log_prior_f_effective": (("chain", "draw"), np.zeros((1, 400)))}
    dt = xr.DataTree.from_dict({"/posterior": xr.Dataset(post), "/discrepancy_clearance/posterior": xr.Dataset(model),
                                f"/{HOOP_OR_PRIOR_GROUP}": xr.Dataset({k: (("draw",), v) for k, v in both.items()})})
    dt.attrs["discrepancy_final_group"] = "discrepancy_clearance"
    dt.to_netcdf(tmp_path / "A_A-03.nc", engine="h5netcdf")
    r = SimpleNamespace(outputs={"netcdf": "A_A-03.nc"}, label="A A-03", campaign="A", window_halves=None, warnings=[], warning_kinds=[],
                        prior_file=prior, summary={"V": {"mean": 9.0, "sd": 0.1}}, path="A-03.h5")
    t = read_test_posterior(r, tmp_path)
    assert t.hoop_disagrees and set(np.unique(t.f_model)) == {0.045, 0.09}
    np.testing.assert_allclose(t.f_model_log_prior, load_priors(prior)["f"].logpdf(t.f_model))


def test_a_test_whose_hoop_gauge_disagrees_is_left_out_of_the_campaigns_nu():
    """Its nu is half the prior's, whose spread can exceed the prior's (a negative precision moved the campaign's nu),
    and half a reading the run could not trust."""
    from friction_uq.campaigns.analysis import campaign_nu
    from friction_uq.campaigns.draws import RecordPosterior

    rng = np.random.default_rng(1)

    def test(nu, sd, both=False):
        x = rng.normal(nu, sd, 2000)
        return RecordPosterior("t", "A", x, x, x, x, {"mean": 9.0, "sd": 0.1}, "p", hoop_disagrees=both)

    sound = [test(0.38, 0.01) for _ in range(3)]
    mixed = test(0.30, 0.06, both=True)
    assert campaign_nu(sound + [mixed], 0.4, 0.03) == campaign_nu(sound, 0.4, 0.03)
    assert campaign_nu([mixed], 0.4, 0.03) == (0.4, 0.03)


def test_the_campaign_reads_kappa_from_the_reading_without_the_hoop_gauge():
    """kappa does not depend on nu; a gauge at three times its scale is fitted through f and put the hoop reading's
    kappa at 0.34 against the forces' 0.030. A group of f alone (the session's first version) gives f only."""
    from friction_uq.campaigns.draws import _both_readings

    n = 500
    group = {"f": np.r_[np.full(n, 0.4), np.full(n, 0.05)], "nu": np.r_[np.full(n, 0.45), np.full(n, 0.4)],
             "kappa": np.r_[np.full(n, 0.34), np.full(n, 0.03)], "p_mean": np.full(2 * n, 8e7)}
    out = _both_readings(group)
    assert np.all(out["kappa"] == 0.03) and set(np.unique(out["f"])) == {0.05, 0.4}
    assert set(_both_readings({"f": group["f"]})) == {"f"}


def test_the_campaign_says_which_tests_hoop_gauge_disagreed():
    from friction_uq.campaigns.conclusions import CampaignAnalysis
    from friction_uq.campaigns.draws import RecordPosterior
    from friction_uq.campaigns.outputs import statements

    x = np.full(10, 0.05)
    tests = [RecordPosterior(label, "A", x, x, x, x, {"mean": 9.0, "sd": 0.1}, "p", hoop_disagrees=both)
             for label, both in (("A A-01", False), ("A A-03", True))]
    said = statements(CampaignAnalysis(tests=tests, pooled={}, tallies={}))
    assert any(s.startswith("test A A-03: the hoop gauge and the prior file disagree on nu") for s in said)
    assert not any("A A-01" in s for s in said)


def test_the_other_warnings_quote_two_readings_by_their_interval():
    """The misfit warning said "may bias f = 0.06989 [0.03827, 0.09798]": a median between the readings, where neither
    puts weight (at three times the gauge's scale it differed from the headline's in the third digit)."""
    from friction_uq.diagnostics import VariableSummary
    from friction_uq.hoop_or_prior import TwoReadings
    from friction_uq.record_run.warnings import _f_text

    one = VariableSummary(mean=0.068, sd=0.02, q05=0.03827, q50=0.06989, q95=0.09798, r_hat=1.0, ess_bulk=4000.0)
    assert _f_text(one) == "f = 0.06989 [0.03827, 0.09798]"
    assert _f_text(TwoReadings(**vars(one))) == "f (from 0.03827 to 0.09798, two readings)"


def test_with_two_readings_of_nu_the_shares_said_are_of_the_whole_f_to_quote():
    """A reviewer's case (A-03, hoop gauge at twice its scale, nothing named): the sentence said "half of it ... from
    the prior file alone" beside "the stationary analysis (50 %) and the candidates (dispersion 30 %, clearance
    20 %)", 150 % in all, and quoted the stationary f by the median between its two readings. Each member's share
    is now halved, the stationary f said by its interval, and the posterior method names the prior's half."""
    from dataclasses import replace

    from friction_uq.discrepancy.diagnosis_words import BOTH_READINGS, _f_said, _median, _percent
    from friction_uq.discrepancy.outcome import posterior_method_of

    one, two = _diagnosed(), _diagnosed(np.full(10, 0.045))
    one, two = (replace(d, posterior_method="importance") for d in (one, two))
    assert _percent(one, 0.3) == "30 %" and _percent(two, 0.3) == "15 %" and _percent(two, 0.5) == "25 %"
    fs = {"q05": 0.038, "q50": 0.071, "q95": 0.099}
    assert _f_said(one, fs, BOTH_READINGS) == "f = 0.071 [0.038, 0.099]" and _median(one, fs) == "0.071"
    assert "0.071" not in _f_said(two, fs, BOTH_READINGS) + _median(two, fs) and _median(two, fs).startswith("0.038 to 0.099")
    assert posterior_method_of(one) == "importance"
    assert posterior_method_of(two) == ("importance; in equal parts with the stationary posterior's draws with nu "
                                        "from the prior file alone")
