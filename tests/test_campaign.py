"""Comparison across campaigns: weighted trend fits against closed forms, table, figure, refusals."""

import json

import numpy as np
import pytest

from friction_uq.campaigns import compare, comparison_table, fit_trend, load_result
from friction_uq.cli import main
from friction_uq.errors import FrictionUQError


def _result(path, campaign, test_id, kappa, sd, V, p):
    stat = lambda m, s: {"mean": m, "sd": s, "q05": m - 1.645 * s, "q50": m, "q95": m + 1.645 * s}  # noqa: E731
    doc = {"campaign": campaign, "test_id": test_id, "kappa": stat(kappa, sd), "f": stat(kappa * 1.5, sd * 1.5),
           "nu": stat(0.4, 0.03), "V": stat(V, 1e-3), "p_mean": stat(p, 1e6)}
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture
def two_campaigns(tmp_path):
    """kappa = 0.04 - 0.001 V exactly (a velocity effect, no pressure effect); B at higher pressure."""
    paths = []
    for camp, dp in (("A", 0.0), ("B", 40e6)):
        for k, V in enumerate([5.5, 7.2, 8.8, 10.7, 12.3]):
            p = 50e6 + 6e6 * V + dp
            paths.append(_result(tmp_path / f"{camp}_{k}.json", camp, f"{camp}-0{k + 1}", 0.04 - 0.001 * V, 2e-4, V, p))
    return paths


def test_joint_fit_separates_velocity_from_pressure(two_campaigns):
    c = compare(two_campaigns)
    fit = c.fits["V+p_mean"]
    assert fit.coef[1] == pytest.approx(-0.001, rel=1e-6)
    assert fit.coef[2] == pytest.approx(0.0, abs=1e-12)
    assert fit.slope_z("V") < -10
    # one campaign alone: V and p rise together, the joint fit is degenerate -> p alone fits as well
    single = [load_result(p) for p in two_campaigns[:5]]
    assert fit_trend(single, ("p_mean",)).chi2_dof == pytest.approx(0.0, abs=1e-9)


def test_weighted_fit_matches_closed_form_least_squares():
    rng = np.random.default_rng(1)
    from friction_uq.campaigns import TestResult

    V = np.linspace(5, 12, 6)
    sd = np.full(6, 3e-4)
    y = 0.035 - 0.0008 * V + rng.normal(0, 3e-4, 6)
    rs = [TestResult("A", str(i), {}, {"q50": y[i], "sd": sd[i]}, {}, {"mean": V[i]}, {"mean": 1.0}, "") for i in range(6)]
    fit = fit_trend(rs, ("V",))
    X = np.column_stack([np.ones(6), V])
    coef = np.linalg.solve(X.T @ X, X.T @ y)
    np.testing.assert_allclose(fit.coef, coef, rtol=1e-10)


def test_compare_cli_prints_table_and_writes_figure(two_campaigns, tmp_path, capsys):
    out = tmp_path / "cmp.pdf"
    assert main(["compare", *map(str, two_campaigns), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "fit kappa ~ V+p_mean" in text and "A-01" in text and "B-05" in text
    assert out.read_bytes()[:4] == b"%PDF"
    assert "one campaign" not in comparison_table(compare(two_campaigns))


def test_tests_analysed_otherwise_are_said_apart(two_campaigns):
    """A test analysed with the dispersion correction beside tests without it (or with another prior file) was
    compared silently: its kappa moves by a few per cent with the correction alone."""
    assert "analysed differently" not in comparison_table(compare(two_campaigns))  # the files say nothing: alike
    for k, path in enumerate(two_campaigns):
        doc = json.loads(path.read_text())
        doc |= {"dispersion_correction": k == 2, "hoop_term": True, "prior_file": "/x/priors/I1.toml"}
        path.write_text(json.dumps(doc))
    text = comparison_table(compare(two_campaigns))
    assert "analysed differently, the dispersion correction: A-01: off; A-02: off; A-03: on; A-04: off" in text
    assert "hoop term" not in text and "prior file" not in text
    doc = json.loads(two_campaigns[0].read_text()) | {"prior_file": "/lab/I1-mine.toml"}
    two_campaigns[0].write_text(json.dumps(doc))
    assert "the prior file: A-01: I1-mine.toml; A-02: I1.toml" in comparison_table(compare(two_campaigns))
    doc = json.loads(two_campaigns[0].read_text()) | {"prior_file": "/lab/I1.toml"}  # two files of one name
    two_campaigns[0].write_text(json.dumps(doc))
    assert "the prior file: A-01: /lab/I1.toml; A-02: /x/priors/I1.toml" in comparison_table(compare(two_campaigns))


def test_a_file_that_is_not_a_result_is_refused(tmp_path, capsys):
    bad = tmp_path / "x.json"
    bad.write_text('{"f": 1}')
    with pytest.raises(FrictionUQError, match="x.json: not a friction-uq run result: key"):
        load_result(bad)
    assert main(["compare", str(bad)]) == 2
    assert "Traceback" not in capsys.readouterr().err
