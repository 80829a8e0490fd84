"""The prior of f_effective under an extended model (what its draws were made under, stored beside them for a
campaign to divide out): exact where the model leaves f as it is, against quadrature and Monte Carlo where a
friction law replaces it, and written into each model's group of the DataTree."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from friction_uq.discrepancy import outcome
from friction_uq.discrepancy.effective_prior import EXACT_NOTE, PUSHED_NOTE, log_prior_f_effective
from friction_uq.discrepancy.extended import Variant
from friction_uq.discrepancy.mechanisms import MECHANISMS, Context
from friction_uq.prior_loader import PRIORS_DIR, load_priors

F_PRIOR = load_priors(PRIORS_DIR / "I1.toml")["f"]  # half-normal(0.3), as the run passes it
F_SCIPY = F_PRIOR.frozen()  # the same law, for the quadratures
CTX = Context(V=9.0, tau_mean=0.05 * 9e7, slip=2e-3, sigma_mean=1.35e8)  # nu 0.4: a wall pressure of 90 MPa
NU_PRIOR = load_priors(PRIORS_DIR / "I1.toml")["nu"]


def _variants(*names: str) -> tuple[Variant, ...]:
    return tuple(Variant(MECHANISMS[n]) for n in names)


def test_a_model_that_leaves_f_as_it_is_has_the_prior_files_f_prior():
    y = np.linspace(0.01, 0.3, 50)
    lp, note = log_prior_f_effective(_variants("dispersion", "clearance", "plug_friction"), CTX, F_PRIOR, y,
                                     rng=np.random.default_rng(0))
    assert note == EXACT_NOTE
    np.testing.assert_array_equal(lp, F_PRIOR.logpdf(y))


def _midpoints(prior, k: int) -> np.ndarray:
    return prior.ppf((np.arange(k) + 0.5) / k)


def test_pressure_friction_prior_matches_quadrature_over_p0_the_shape_and_nu():
    """f_effective = y = f / s, s = (1 + (p/p0)^n)^(1/n) at the window's wall pressure p = nu/(1-nu) sigma (the
    saturating wall): f = y s, so pi(y) = E_{p0,n,nu}[pi_f(y s) s], by midpoints in p0's, n's and nu's quantiles."""
    y = np.array([0.02, 0.05, 0.1, 0.2, 0.4])
    lp, note = log_prior_f_effective(_variants("pressure_friction"), CTX, F_PRIOR, y, rng=np.random.default_rng(1),
                                     nu_prior=NU_PRIOR)
    assert note == PUSHED_NOTE
    mech = MECHANISMS["pressure_friction"]
    p0 = _midpoints(mech.priors["p0"], 400)[:, None, None]
    n = _midpoints(mech.priors["n_p"], 100)[None, :, None]
    nu = NU_PRIOR.ppf((np.arange(60) + 0.5) / 60)[None, None, :]
    s = (1.0 + (CTX.wall_pressure(nu) / p0) ** n) ** (1.0 / n)
    exact = np.array([np.mean(F_SCIPY.pdf(v * s) * s) for v in y])
    np.testing.assert_allclose(np.exp(lp), exact, rtol=0.01)
    assert np.max(np.abs(lp - F_PRIOR.logpdf(y))) > 0.05  # not the f prior: dividing that out would be wrong


def test_a_law_whose_f_reads_nu_asks_for_nus_prior():
    with pytest.raises(ValueError, match="nu's prior"):
        log_prior_f_effective(_variants("pressure_friction"), CTX, F_PRIOR, np.array([0.05]),
                              rng=np.random.default_rng(0))


@pytest.mark.parametrize("seed", [0, 2])  # seed 0: one draw with w near 1 put the density 39 % off when f was pushed
def test_velocity_friction_prior_matches_quadrature(seed):
    """f_effective = (1 - e) f + e f_s, e = exp(-V / v_c), f and f_s half-normal(0.3), v_c from its
    prior: given e, the density of a sum of two scaled half-normals by quadrature over the one whose scale is
    >= 1/2."""
    y = np.array([0.01, 0.03, 0.06, 0.1, 0.2, 0.4])
    lp, note = log_prior_f_effective(_variants("clearance", "velocity_friction"), CTX, F_PRIOR, y,
                                     rng=np.random.default_rng(seed))
    assert note == PUSHED_NOTE
    mech = MECHANISMS["velocity_friction"]
    x_c = CTX.V / _midpoints(mech.priors["v_c"], 200)
    e = np.exp(-x_c).reshape(-1, 1)
    e = np.clip(e, 1e-12, 1 - 1e-12)
    x = np.linspace(0.0, 2.0, 2001)  # the other coefficient, integrated out
    fs = mech.priors["f_s"]
    exact = np.array([np.trapezoid(np.where(e < 0.5, fs.pdf(x) * F_SCIPY.pdf((v - e * x) / (1 - e)) / (1 - e),
                                            F_SCIPY.pdf(x) * fs.pdf((v - (1 - e) * x) / e) / e), x, axis=1).mean()
                      for v in y])
    np.testing.assert_allclose(np.exp(lp), exact, rtol=0.01)
    # it falls where the f prior is highest: a sum of two half-normals has no density at 0
    assert lp[0] < F_PRIOR.logpdf(0.01) - 0.1


def test_same_seed_same_bits():
    y = np.random.default_rng(3).normal(0.06, 0.01, 300)
    a, _ = log_prior_f_effective(_variants("slip_friction"), CTX, F_PRIOR, y, rng=np.random.default_rng(7))
    b, _ = log_prior_f_effective(_variants("slip_friction"), CTX, F_PRIOR, y, rng=np.random.default_rng(7))
    c, _ = log_prior_f_effective(_variants("slip_friction"), CTX, F_PRIOR, y, rng=np.random.default_rng(8))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(a, c, atol=0.02)  # another Sobol scramble: the same prior to Monte Carlo error


def _model(label: str, names: tuple[str, ...], f: np.ndarray):
    elpd = SimpleNamespace(pointwise=np.zeros(3), calibration=np.zeros(1), calibration_names=("hoop_gain",),
                           total=0.0, se=0.0)
    return SimpleNamespace(label=label, variants=_variants(*names), f_effective=f, f_from="cut posterior",
                           hoop_gain=1.0, predicted={"tube_hoop": None}, elpd=elpd,
                           fit=SimpleNamespace(draws={"f": f, "nu": np.full(f.size, 0.4)}))


def _written(dg, tmp_path):
    """The diagnosis' groups as a run writes them to its .nc, opened again."""
    import xarray as xr

    dt = xr.DataTree()
    outcome.add_to_datatree(dt, dg, F_PRIOR, NU_PRIOR)
    dt.to_netcdf(tmp_path / "d.nc", engine="h5netcdf")
    return xr.open_datatree(tmp_path / "d.nc", engine="h5netcdf")


def test_each_models_group_holds_the_log_prior_of_f_effective_beside_its_draws(tmp_path):
    rng = np.random.default_rng(0)
    base = _model("baseline", (), rng.normal(0.05, 0.002, 200))
    vel = _model("velocity_friction", ("velocity_friction",), rng.normal(0.06, 0.002, 200))
    dg = SimpleNamespace(swap_models=(), f_prior_nu=None, baseline=base, final=vel, causes=vel.variants,
                         rounds=((SimpleNamespace(fit=vel),),),
                         posterior_method="importance", context=CTX, seed=4, mixture_f=None)
    with _written(dg, tmp_path) as back:
        assert back.attrs["discrepancy_final_group"] == "discrepancy_velocity_friction"
        b = back["discrepancy_baseline/posterior"]
        np.testing.assert_allclose(b["log_prior_f_effective"].values, F_PRIOR.logpdf(b["f_effective"].values))
        assert b["log_prior_f_effective"].attrs["description"] == EXACT_NOTE
        v = back["discrepancy_velocity_friction/posterior"]
        want, _ = log_prior_f_effective(vel.variants, CTX, F_PRIOR, vel.f_effective, rng=np.random.default_rng(
            np.random.SeedSequence([4, 13, __import__("zlib").crc32(b"velocity_friction")])))
        np.testing.assert_array_equal(v["log_prior_f_effective"].values[0], want)
        assert v["log_prior_f_effective"].attrs["description"] == PUSHED_NOTE


def test_a_law_that_is_not_monotone_in_f_is_refused():
    mech = SimpleNamespace(name="odd", parameters=(), priors={}, f_effective=lambda v, c: (v["f"] - 0.2) ** 2,
                           companion=None, uses_nu=False)
    with pytest.raises(ValueError, match="decreases with f"):
        log_prior_f_effective((SimpleNamespace(mechanism=mech, label="odd"),), CTX, F_PRIOR, np.array([0.05]),
                              rng=np.random.default_rng(0))


def test_the_mixture_group_holds_each_draws_prior_from_the_model_it_came_from(tmp_path):
    """Under candidates or an unexplained misfit the f to quote is a stacking mixture: each of its draws keeps the
    log prior of f_effective under the model it was drawn from, for a campaign to divide out."""
    rng = np.random.default_rng(1)
    base = _model("baseline", (), rng.normal(0.05, 0.002, 200))
    vel = _model("velocity_friction", ("velocity_friction",), rng.normal(0.06, 0.002, 200))
    f = np.concatenate([base.f_effective[:30], vel.f_effective[:70]])
    source = np.repeat([0, 1], [30, 70])
    dg = SimpleNamespace(swap_models=(), f_prior_nu=None, baseline=base, final=base, causes=(), rounds=((SimpleNamespace(fit=vel),),),
                         ranking=(SimpleNamespace(fit=vel),), posterior_method=None, context=CTX, seed=4,
                         mixture_f=f, mixture_source=source, mixture_weights={"reference": 0.3, "velocity_friction": 0.7},
                         verdict=SimpleNamespace(kind="unexplained"))
    with _written(dg, tmp_path) as back:
        assert back.attrs["discrepancy_final_group"] == "discrepancy_mixture"
        m = back["discrepancy_mixture/posterior"]
        lp = m["log_prior_f_effective"].values[0]
        np.testing.assert_allclose(lp[:30], F_PRIOR.logpdf(f[:30]))  # the reference leaves f as it is
        assert list(m["model"].values[0][[0, -1]]) == ["reference", "velocity_friction"]
        assert np.all(np.isfinite(lp)) and not np.allclose(lp[30:], F_PRIOR.logpdf(f[30:]))


def test_the_stationary_half_of_a_mixture_keeps_the_f_prior_and_says_so(tmp_path):
    """With nothing named (candidates fitted in turn and left open: causes not empty), half the mixture's draws are
    the stationary posterior's: written as model "stationary", each with the f prior's log density (the prior the
    stationary analysis sampled under), and the group's posterior_method says that half is there."""
    rng = np.random.default_rng(3)
    base = _model("baseline", (), rng.normal(0.05, 0.002, 200))
    vel = _model("velocity_friction", ("velocity_friction",), rng.normal(0.06, 0.002, 200))
    stationary = rng.normal(0.052, 0.003, 50)
    f = np.concatenate([stationary, vel.f_effective[:50]])
    source = np.repeat([0, 1], [50, 50])
    dg = SimpleNamespace(swap_models=(), f_prior_nu=None, baseline=base, final=vel, causes=vel.variants,
                         rounds=((SimpleNamespace(fit=vel),),),
                         posterior_method="importance", context=CTX, seed=4, mixture_f=f, mixture_source=source,
                         mixture_weights={"stationary": 0.5, "velocity_friction": 0.5},
                         verdict=SimpleNamespace(kind="candidates"))
    with _written(dg, tmp_path) as back:
        m = back["discrepancy_mixture/posterior"]
        assert list(m["model"].values[0][[0, -1]]) == ["stationary", "velocity_friction"]
        np.testing.assert_allclose(m["log_prior_f_effective"].values[0][:50], F_PRIOR.logpdf(stationary))
        assert m.attrs["posterior_method"].endswith("half of it the stationary posterior's draws")


def test_the_method_of_the_f_to_quote_is_the_mixtures_where_f_is_one():
    """The JSON's f says how its draws were obtained: a mixture's members (not the final model's route alone),
    and the Pareto k it carries is named as the final model's."""
    from friction_uq.discrepancy.outcome import posterior_method_of

    rng = np.random.default_rng(3)
    vel = _model("velocity_friction", ("velocity_friction",), rng.normal(0.06, 0.002, 200))
    one = SimpleNamespace(final=vel, f_prior_nu=None, causes=vel.variants, posterior_method="importance", mixture_f=None,
                          mixture_weights={})
    assert posterior_method_of(one) == "importance"
    mixed = SimpleNamespace(final=vel, f_prior_nu=None, causes=vel.variants, posterior_method="importance",
                            mixture_f=rng.normal(0.06, 0.002, 100),
                            mixture_weights={"stationary": 0.5, "velocity_friction": 0.5})
    assert posterior_method_of(mixed) == ("stacking mixture: the final model's draws from its exact posterior where "
                                          "it is a member, the other members' normal approximations, half of it the "
                                          "stationary posterior's draws")
    candidates = SimpleNamespace(final=vel, f_prior_nu=None, causes=(), posterior_method=None, mixture_f=mixed.mixture_f,
                                 mixture_weights={"reference": 0.4, "velocity_friction": 0.6})
    assert posterior_method_of(candidates) == "stacking mixture of the candidates' normal approximations"


def test_a_mixture_member_that_drew_no_draw_is_written_without_one(tmp_path):
    """A candidate whose stacking weight is too small to draw any of the mixture's draws (bundled A-02 under
    diagnose ended in a ValueError on the empty set of its draws): the mixture is written with the others'."""
    rng = np.random.default_rng(2)
    base = _model("baseline", (), rng.normal(0.05, 0.002, 200))
    vel = _model("velocity_friction", ("velocity_friction",), rng.normal(0.06, 0.002, 200))
    slip = _model("slip_friction", ("slip_friction",), rng.normal(0.055, 0.002, 200))
    f = np.concatenate([base.f_effective[:40], vel.f_effective[:60]])
    source = np.repeat([0, 1], [40, 60])  # slip_friction (index 2) drew nothing
    dg = SimpleNamespace(swap_models=(), f_prior_nu=None, baseline=base, final=base, causes=(), rounds=((SimpleNamespace(fit=vel),
                                                                        SimpleNamespace(fit=slip)),),
                         posterior_method=None, context=CTX, seed=4, mixture_f=f, mixture_source=source,
                         mixture_weights={"reference": 0.4, "velocity_friction": 0.5999, "slip_friction": 1e-4},
                         verdict=SimpleNamespace(kind="candidates"))
    lp, _ = log_prior_f_effective(slip.variants, CTX, F_PRIOR, np.array([]), rng=np.random.default_rng(0))
    assert lp.shape == (0,)
    with _written(dg, tmp_path) as back:
        m = back["discrepancy_mixture/posterior"]
        assert m["f_effective"].shape == (1, 100)
        assert set(m["model"].values[0]) == {"reference", "velocity_friction"}
        assert np.all(np.isfinite(m["log_prior_f_effective"].values))
