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

from friction_uq.hoop_or_prior import HOOP_OR_PRIOR_GROUP, disagree, equal_parts
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
    r = SimpleNamespace(outputs={"netcdf": nc.name}, label="A-03", campaign="A", window_halves=None,
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


def test_under_diagnose_the_warning_says_the_diagnosed_f_reads_the_hoop_gauge_too():
    from friction_uq.hoop_or_prior import HoopOrPrior

    hp = HoopOrPrior({"q05": 0.23, "q50": 0.25, "q95": 0.27}, {"q05": 0.35, "q50": 0.4, "q95": 0.45}, 0.45,
                     {"q05": 0.08, "q50": 0.09, "q95": 0.1}, {"q05": 0.036, "q50": 0.045, "q95": 0.057},
                     {"q05": 0.038, "q50": 0.07, "q95": 0.099}, {}, (("nu", "prior-data conflict"),))
    said = hp.sentence(diagnosed=True)
    assert "`diagnose`'s f reads nu through the hoop gauge as well" in said and "f from 0.038 to 0.099" in said
    assert "the f quoted holds both" in hp.sentence()


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
