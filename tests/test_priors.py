"""Prior files: loading, closed-form densities against scipy.stats, draws, and every refusal."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from friction_uq.errors import PriorError
from friction_uq.priors import ParameterPrior
from friction_uq.prior_loader import PRIORS_DIR, default_prior_path, load_priors

GOOD = """
material = "X"
[f]
distribution = "halfnormal"
scale = 0.3
[nu]
distribution = "truncnormal"
mean = 0.4
sd = 0.03
lower = 0.0
upper = 0.5
"""


def write(tmp_path: Path, text: str, name: str = "X.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# ---------------------------------------------------------------- shipped files


@pytest.mark.parametrize("material", ["I1", "I1-nu-wide", "I1-nu-tight"])
def test_shipped_files_load_with_all_parameters(material):
    pri = load_priors(default_prior_path(material))
    assert pri.names == ("f", "nu", "hoop_gain")
    assert pri.material == "I1"
    lo, hi = pri["nu"].support
    assert 0.0 <= lo < hi <= 0.5


def test_default_nu_prior_is_about_0_4_within_a_few_hundredths():
    nu = load_priors(default_prior_path("I1"))["nu"]
    q = nu.ppf(np.array([0.05, 0.5, 0.95]))
    assert q[1] == pytest.approx(0.4, abs=1e-3)  # truncation at 0.5 (3.3 sd) moves it by 2e-5
    assert 0.02 <= (q[2] - q[0]) / (2 * 1.645) <= 0.05  # "estimated": sd of a few hundredths


def test_default_f_prior_covers_literature_range():
    """Literature values 0.05-0.5 (docs/physics.md section 4) all keep substantial prior mass."""
    f = load_priors(default_prior_path("I1"))["f"]
    assert f.ppf(np.array([0.5]))[0] == pytest.approx(0.3 * stats.halfnorm.ppf(0.5), rel=1e-12)
    assert float(f.frozen().cdf(0.05)) < 0.2 and float(f.frozen().sf(0.5)) > 0.05


def test_alternatives_differ_from_default_only_in_nu():
    d = load_priors(default_prior_path("I1"))
    for alt in ("I1-nu-wide", "I1-nu-tight"):
        a = load_priors(default_prior_path(alt))
        assert a["f"] == d["f"] and a["hoop_gain"] == d["hoop_gain"]
        assert a["nu"] != d["nu"]
    wide = load_priors(default_prior_path("I1-nu-wide"))["nu"]
    assert (wide.distribution, wide.support) == ("uniform", (0.2, 0.45))


def test_description_names_every_parameter_and_file():
    pri = load_priors(default_prior_path("I1"))
    text = pri.describe()
    assert "I1.toml" in text
    for line in ("f ~ halfnormal(scale=0.3)", "nu ~ truncnormal(mean=0.4, sd=0.03, lower=0, upper=0.5)",
                 "hoop_gain ~ lognormal(median=1, sigma=0.05)"):
        assert line in text


# ---------------------------------------------------------------- densities and draws


CASES = [
    ParameterPrior("f", "halfnormal", {"scale": 0.3}),
    ParameterPrior("f", "uniform", {"lower": 0.0, "upper": 1.0}),
    ParameterPrior("nu", "truncnormal", {"mean": 0.4, "sd": 0.03, "lower": 0.0, "upper": 0.5}),
    ParameterPrior("nu", "truncnormal", {"mean": 0.7, "sd": 0.05, "lower": 0.2, "upper": 0.5}),  # tail mass
    ParameterPrior("nu", "uniform", {"lower": 0.2, "upper": 0.45}),
    ParameterPrior("hoop_gain", "lognormal", {"median": 1.0, "sigma": 0.05}),
    ParameterPrior("x", "normal", {"mean": 1.0, "sd": 2.0}),
]


@pytest.mark.parametrize("prior", CASES, ids=lambda p: f"{p.name}-{p.distribution}")
def test_closed_form_logpdf_matches_scipy(prior):
    ref = prior.frozen()
    lo, hi = prior.support
    x = np.linspace(max(lo, -5.0) - 0.1, min(hi, 5.0) + 0.1, 401)
    mine = prior.logpdf(x)
    with np.errstate(divide="ignore"):
        theirs = ref.logpdf(x)
    inside = np.isfinite(theirs)
    assert np.array_equal(np.isfinite(mine), inside)
    np.testing.assert_allclose(mine[inside], theirs[inside], rtol=1e-10, atol=1e-10)


def test_joint_logpdf_is_vectorised_sum():
    pri = load_priors(default_prior_path("I1"))
    theta = pri.rvs(np.random.default_rng(1), 50)
    joint = pri.logpdf(theta)
    assert joint.shape == (50,)
    ref = sum(pri[n].frozen().logpdf(theta[:, i]) for i, n in enumerate(pri.names))
    np.testing.assert_allclose(joint, ref, rtol=1e-12)
    outside = theta.copy()
    outside[0, 1] = 0.55
    assert pri.logpdf(outside)[0] == -np.inf


def test_draws_are_seeded_and_follow_the_distribution():
    pri = load_priors(default_prior_path("I1"))
    a = pri.rvs(np.random.default_rng(7), 4000)
    b = pri.rvs(np.random.default_rng(7), 4000)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, pri.rvs(np.random.default_rng(8), 4000))
    # each marginal: KS test at 0.1 % (fails by chance once in a thousand seeds)
    for i, name in enumerate(pri.names):
        assert stats.kstest(a[:, i], pri[name].frozen().cdf).pvalue > 1e-3


# ---------------------------------------------------------------- refusals


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda t: t + '\n[friction]\ndistribution = "uniform"\n', r"X\.toml: friction: unknown key or section; allowed: material, description, f, nu, hoop_gain"),
        (lambda t: t.replace("scale = 0.3", "scael = 0.3"), r"\[f\] scael: unknown key for a halfnormal prior; allowed: distribution, note, scale"),
        (lambda t: t.replace('"halfnormal"', '"gamma"'), r"\[f\] distribution: unknown distribution 'gamma'; allowed: halfnormal, normal, truncnormal, uniform, lognormal"),
        (lambda t: t.replace("upper = 0.5\n", ""), r"\[nu\]: truncnormal prior needs mean, sd, lower, upper; missing upper"),
        (lambda t: t.replace("sd = 0.03", "sd = 0.0"), r"\[nu\] sd: must be > 0, got 0"),
        (lambda t: t.replace("scale = 0.3", "scale = -1"), r"\[f\] scale: must be > 0, got -1"),
        (lambda t: t.replace("lower = 0.0", "lower = 0.5"), r"\[nu\] lower: lower \(0.5\) must be < upper \(0.5\)"),
        (lambda t: t.replace("upper = 0.5", "upper = 0.6"), r"\[nu\]: .*support \[0, 0.6\], outside the physical range of nu \[0, 0.5\]"),
        (lambda t: t.replace('"truncnormal"', '"normal"').replace("lower = 0.0\n", "").replace("upper = 0.5\n", ""),
         r"\[nu\]: nu ~ normal\(mean=0.4, sd=0.03\) has support \[-inf, inf\].*give lower and upper"),
        (lambda t: t.replace("mean = 0.4", "mean = 5.0"), r"\[nu\]: normal\(mean=5, sd=0.03\) puts no mass .* on \[0, 0.5\]"),
        (lambda t: t.replace("sd = 0.03", 'sd = "wide"'), r"\[nu\] sd: must be a number, got 'wide'"),
        (lambda t: t.replace("[f]\n", "[f]\nnote = 3\n"), r"\[f\] note: must be a string"),
        (lambda t: t.replace('distribution = "halfnormal"\nscale = 0.3\n', 'scale = 0.3\n'), r"\[f\]: missing key 'distribution'; allowed: halfnormal"),
        (lambda t: t.split("[nu]")[0], r"\[nu\]: missing section; required: f, nu"),
        (lambda t: t + "\nuniform = [", r"X\.toml: file: not valid TOML"),
    ],
)
def test_bad_files_are_refused_naming_file_key_and_problem(tmp_path, edit, match):
    path = write(tmp_path, edit(GOOD))
    with pytest.raises(PriorError, match=match):
        load_priors(path)


def test_missing_file_is_refused(tmp_path):
    with pytest.raises(PriorError, match=r"nope\.toml: file: cannot be read"):
        load_priors(tmp_path / "nope.toml")


def test_default_prior_path_lists_available_materials(tmp_path):
    write(tmp_path, GOOD, "A.toml")
    write(tmp_path, GOOD, "B.toml")
    assert default_prior_path("A", directory=tmp_path) == tmp_path / "A.toml"
    with pytest.raises(PriorError, match=r"no prior file for material 'PBX9501'; materials: A, B; write one with 'friction-uq priors PBX9501"):
        default_prior_path("PBX9501", directory=tmp_path)
    assert default_prior_path("I1") == PRIORS_DIR / "I1.toml"


def test_subset_without_hoop_gain_names_the_file(tmp_path):
    pri = load_priors(write(tmp_path, GOOD))
    assert pri.subset(["nu", "f"]).names == ("nu", "f")
    with pytest.raises(PriorError, match=r"X\.toml: \[hoop_gain\]: no prior for this parameter; the file defines f, nu"):
        pri.subset(["f", "nu", "hoop_gain"])


def test_truncated_tail_prior_has_finite_normalisation():
    """A truncated normal whose mean lies outside the bounds still normalises (tail-safe mass)."""
    p = ParameterPrior("nu", "truncnormal", {"mean": 0.8, "sd": 0.05, "lower": 0.3, "upper": 0.5})
    x = np.linspace(0.3, 0.5, 20001)
    assert np.trapezoid(np.exp(p.logpdf(x)), x) == pytest.approx(1.0, rel=1e-6)
    assert math.isfinite(float(p.logpdf(np.array([0.4]))[0]))
