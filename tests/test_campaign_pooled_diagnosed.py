"""A diagnosed campaign pools f under each test's diagnosed model, the prior its draws were made under (stored
beside them by the run) divided out, and keeps the stationary pooling beside it, labelled; the report's
forest plot says which. Hand-made tests (four: below the law comparison's five, so nothing slow runs)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import stats

from friction_uq.campaigns import RecordResult
from friction_uq.campaigns.analysis import RecordPosterior, analyse_tests, read_test_posterior
from friction_uq.campaigns.flags import tally_causes
from friction_uq.campaigns.outputs import SCHEMA_VERSION, campaign_doc, summary_text, write_netcdf
from friction_uq.campaigns.pooling import StoredDraws, pool
from friction_uq.prior_loader import PRIORS_DIR, load_priors
from friction_uq.report.campaign_pages import write_campaign_report

PRIOR = str(PRIORS_DIR / "I1.toml")
#: the prior the diagnosed f's draws are made under here (a stand-in for a friction law's prior on f_effective)
MODEL_PRIOR = stats.norm(0.04, 0.01)


def _tests(*, diagnosed: bool) -> list[RecordPosterior]:
    """Four tests whose stationary f reads 0.040 (a clearance's bias) where f under the diagnosed model is 0.060
    +- 0.002 between tests; each diagnosed posterior is the measurement (sd 0.003) pulled by MODEL_PRIOR."""
    rng = np.random.default_rng(8)
    z = stats.norm.ppf((np.arange(1000) + 0.5) / 1000)
    out = []
    for k, x in enumerate(rng.normal(0.06, 0.002, 4)):
        f = 0.04 * rng.normal(1.0, 0.01) + 0.002 * z
        nu = np.full(1000, 0.4)
        t = RecordPosterior(f"A-0{k + 1}", "A", f, f * nu / (1 - nu), nu, np.full(1000, 1e8),
                            {"mean": 9.0, "sd": 0.1, "q05": 9.0, "q50": 9.0, "q95": 9.0}, PRIOR)
        if diagnosed:
            sd = 1.0 / np.sqrt(1 / 0.003**2 + 1 / MODEL_PRIOR.std() ** 2)
            t.f_model = (x / 0.003**2 + MODEL_PRIOR.mean() / MODEL_PRIOR.var()) * sd**2 + sd * z
            t.f_model_log_prior = MODEL_PRIOR.logpdf(t.f_model)
        out.append(t)
    return out


def _doc(ca):
    results = [RecordResult(path=f"{t.label}.h5", status="done", campaign=t.setup, test_id=t.label) for t in ca.tests]
    return json.loads(json.dumps(campaign_doc(results, ca, seed=1, settings={}), default=float))


@pytest.mark.slow  # a diagnosed campaign's law comparison: in the default suite it kept that suite over 10 minutes (11 s in a CI run)
def test_a_diagnosed_campaign_pools_the_diagnosed_f_and_labels_both(tmp_path):
    tests = _tests(diagnosed=True)
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    doc = _doc(ca)
    assert doc["schema_version"] == SCHEMA_VERSION == 7
    pf, ps = doc["pooled"]["f"], doc["pooled_stationary"]["f"]
    assert pf["basis"] == "diagnosed" and ps["basis"] == "stationary"
    assert doc["pooled"]["kappa"]["basis"] == "stationary"
    # the diagnosed f with its stored prior divided out: the same as pooling those draws directly
    direct = pool([StoredDraws(t.label, t.setup, t.f_model, MODEL_PRIOR.logpdf(t.f_model)) for t in tests], "f")
    assert pf["mu"]["q50"] == pytest.approx(direct.mu["q50"], abs=1e-6)
    assert pf["mu"]["q05"] < 0.06 < pf["mu"]["q95"] and 0.038 < ps["mu"]["q50"] < 0.042
    # the prior counts: left in, it pulls the pooled mean toward 0.04 by about (0.04 - 0.06) * 0.08
    kept = pool([StoredDraws(t.label, t.setup, t.f_model, np.zeros(1000)) for t in tests], "f")
    assert kept.mu["q50"] < pf["mu"]["q50"] - 0.001
    text = summary_text(doc)
    lines = [x for x in text.splitlines() if x.startswith("pooled ")]
    assert lines[0].startswith("pooled f under each test's diagnosed model (its prior on f_effective divided out): "
                               f"population mean {pf['mu']['q50']:.4g} ")
    assert lines[1].startswith(f"pooled f of the stationary analysis: population mean {ps['mu']['q50']:.4g} ")
    assert lines[2].startswith("pooled kappa of the stationary analysis")
    import xarray as xr

    with xr.open_datatree(write_netcdf(ca, tmp_path / "campaign.nc"), engine="h5netcdf") as dt:
        assert dt["pooled_f"].attrs["basis"] == "diagnosed" and dt["pooled_stationary_f"].attrs["basis"] == "stationary"
    pdf = write_campaign_report(ca, doc, tmp_path / "campaign.pdf")
    assert pdf.read_bytes()[:4] == b"%PDF"


def test_without_diagnose_the_pooled_f_is_the_stationary_one_and_says_so():
    doc = _doc(analyse_tests(_tests(diagnosed=False), tally_causes([]), seed=1))
    assert doc["pooled"]["f"]["basis"] == "stationary" and doc["pooled_stationary"] == {}
    assert 0.038 < doc["pooled"]["f"]["mu"]["q50"] < 0.042
    assert not any("diagnosed" in s for s in doc["statements"])


def test_a_test_without_the_prior_of_its_diagnosed_f_keeps_the_stationary_pooling():
    tests = _tests(diagnosed=True)
    tests[2].f_model_log_prior = None  # a record of a version that stored no prior beside the draws
    ca = analyse_tests(tests, tally_causes([]), seed=1)
    assert ca.pooled["f"].basis == "stationary" and ca.pooled_stationary == {}
    assert any("3 of 4 tests carry f under a diagnosed model" in s for s in ca.sentences)


@pytest.mark.parametrize("stored", [True, False])
def test_the_prior_of_the_diagnosed_f_is_read_from_beside_its_draws(tmp_path, stored):
    import xarray as xr

    rng = np.random.default_rng(0)
    post = {k: (("chain", "draw"), rng.normal(m, 0.01 * m, (2, 500)))
            for k, m in (("f", 0.05), ("kappa", 0.033), ("nu", 0.4), ("p_mean", 1e8))}
    f_eff = rng.normal(0.06, 0.002, (1, 1200))
    group = {"f_effective": (("chain", "draw"), f_eff)}
    if stored:
        group["log_prior_f_effective"] = (("chain", "draw"), MODEL_PRIOR.logpdf(f_eff))
    dt = xr.DataTree.from_dict({"/posterior": xr.Dataset(post),
                                "/discrepancy_velocity_friction/posterior": xr.Dataset(group)})
    dt.attrs["discrepancy_final_group"] = "discrepancy_velocity_friction"
    dt.to_netcdf(tmp_path / "A_A-01.nc", engine="h5netcdf")
    r = RecordResult(path="A-01.h5", status="done", campaign="A", test_id="A-01", prior_file=PRIOR,
                     outputs={"netcdf": "A_A-01.nc"}, summary={"V": {"mean": 9.0, "sd": 0.1}})
    t = read_test_posterior(r, tmp_path)
    assert t.f_model.size == 1000  # thinned
    if stored:
        np.testing.assert_array_equal(t.f_model_log_prior, MODEL_PRIOR.logpdf(t.f_model))
    else:
        assert t.f_model_log_prior is None
    # no cause named: the stationary f, whose prior is the prior file's f prior
    dt.attrs["discrepancy_final_group"] = ""
    dt.to_netcdf(tmp_path / "A_A-01.nc", engine="h5netcdf", mode="w")
    t = read_test_posterior(r, tmp_path)
    np.testing.assert_array_equal(t.f_model, t.f)
    np.testing.assert_allclose(t.f_model_log_prior, load_priors(PRIOR)["f"].logpdf(t.f))


def test_a_log_prior_without_density_at_a_draw_is_refused_naming_the_file(tmp_path):
    import xarray as xr

    from friction_uq.errors import FrictionUQError

    post = {k: (("chain", "draw"), np.full((1, 10), m)) for k, m in (("f", 0.05), ("kappa", 0.033), ("nu", 0.4),
                                                                     ("p_mean", 1e8))}
    group = {"f_effective": (("chain", "draw"), np.zeros((1, 10))),
             "log_prior_f_effective": (("chain", "draw"), np.full((1, 10), -np.inf))}
    dt = xr.DataTree.from_dict({"/posterior": xr.Dataset(post), "/discrepancy_pressure_friction/posterior":
                                xr.Dataset(group)})
    dt.attrs["discrepancy_final_group"] = "discrepancy_pressure_friction"
    dt.to_netcdf(tmp_path / "A_A-01.nc", engine="h5netcdf")
    r = RecordResult(path="A-01.h5", status="done", campaign="A", test_id="A-01", prior_file=PRIOR,
                     outputs={"netcdf": "A_A-01.nc"}, summary={"V": {"mean": 9.0, "sd": 0.1}})
    with pytest.raises(FrictionUQError, match="A_A-01.nc: group discrepancy_pressure_friction: the log prior"):
        read_test_posterior(r, tmp_path)
