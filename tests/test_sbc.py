"""Simulation-based calibration: 90 % credible intervals of kappa and f must cover the truth ~90 %.

Synthetic stationary phases are built from the closed forms of docs/physics.md section 4 (eq. 15-16 at
V_s = 10 m/s with the paper's bars: F_io, F_eo = (e - 1) F_io, V, slip = V t) and the model's own
noise: AR(1) on each force (strain sd 3e-6 -> sd_io = A E sd = 17 N on the aluminium bar, 338 N on
the steel tube bar; rho 0.5) and, with the hoop term, on the hoop gauge (sd 2e-6, rho 0.5). The
true (f, nu, g) are drawn from the default I1 prior.

The slow study also runs through whole records: closed-form HDF5 records of
:mod:`friction_uq.synthetic` (trapezoidal waves, white + AR(1) noise with offsets, hoop gain applied
as the ``tube_hoop`` channel gain) read back and processed by :func:`friction_uq.analysis.prepare`
(forces, automatic stationary window, noise estimated on the pre-pulse segments). There the noise
model is not the likelihood's own (white + AR(1) against AR(1)), so it tests the honesty of the
whole chain.

Both draw the ratio's model-form error the likelihood allows for (a relative sd of
``RATIO_MODEL_FORM`` on eq. 17's ratio, friction_uq.likelihood.force_level): the phases through the
likelihood's generative model, the records through ``ClosedFormTest.ratio_error``.

The gate of the default suite uses a 99 % binomial band (few replicas: a 95 % band fails by chance
one seed in twenty, libraries.md); the full study (>= 100 replicas, a family-wise 95 % band over its
8 assertions) is marked slow and is also ``benchmarks/bench_sbc.py``.

``closed_form_data`` here is the synthetic-data builder shared by the other test modules of the
likelihood, sampler and diagnostics.
"""

from __future__ import annotations

import os
import tempfile
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace

import numpy as np
import pytest
from scipy import stats

from friction_uq.likelihood import RATIO_MODEL_FORM, Likelihood, offset_sd
from friction_uq.physics import cell, design
from friction_uq.prior_loader import default_prior_path, load_priors
from friction_uq.record import paper_apparatus
from friction_uq.sampler import sample_posterior
from friction_uq.window import StationaryData

#: Strain noise of the gauges (internal bar, external bar, hoop) and their AR(1) coefficients.
STRAIN_SD = (3e-6, 3e-6, 2e-6)
RHO = (0.5, 0.5, 0.5)


def closed_form_data(
    f: float, nu: float, gain: float = 1.0, *, seed: int, n: int = 1500, sample_rate: float = 5e6,
    hoop: bool = True, strain_sd: tuple[float, float, float] = STRAIN_SD, rho: tuple[float, float, float] = RHO,
    t_start: float = 100e-6, striker_velocity: float = 10.0, axial_poisson: bool = True,
    n_baseline: int | None = None, model_form: float = 0.0,
) -> StationaryData:
    """A stationary phase of the paper's set-up with true (f, nu, g) and AR(1) noise (SI units).

    Levels from eq. 15-16 (:mod:`friction_uq.physics.design`), slip = V t from the start of loading
    (``t_start`` before the first sample), noise and hoop reading from the likelihood's generative
    model (:meth:`friction_uq.likelihood.Likelihood.simulate`). With ``n_baseline``, each channel
    also gets the offset error of a baseline removed with the mean of ``n_baseline`` noise samples
    (the ``sd_offset_*`` fields). With ``model_form``, the phase's ratio departs from eq. 17's by a relative
    error drawn from N(0, model_form^2) (the likelihood's model-form term; 0: the levels are eq. 15-16's).
    """
    app = paper_apparatus()
    io, eo = app.internal_output_bar, app.external_output_bar
    R, L = app.sample.radius, app.sample.length
    kw = dict(striker_velocity=striker_velocity, z_input=app.input_bar.impedance, z_internal=io.impedance,
              radius=R, length=L)
    F_io = float(design.stationary_internal_force(f, nu, **kw))
    F_eo = float(design.stationary_external_force(f, nu, **kw))
    V = float(design.stationary_sliding_velocity(f, nu, z_external=eo.impedance, **kw))
    t = t_start + np.arange(n) / sample_rate
    sd_io, sd_eo = io.area * io.young_modulus * strain_sd[0], eo.area * eo.young_modulus * strain_sd[1]
    extra = {}
    if n_baseline is not None:
        extra = {"sd_offset_io": offset_sd(sd_io, rho[0], n_baseline), "sd_offset_eo": offset_sd(sd_eo, rho[1], n_baseline),
                 "sd_offset_hoop": offset_sd(strain_sd[2], rho[2], n_baseline) if hoop else 0.0}
    template = StationaryData(
        test_id="synthetic", campaign="S", time=t, F_io=np.full(n, F_io), F_eo=np.full(n, F_eo), V=np.full(n, V),
        slip=V * t, sd_io=sd_io, sd_eo=sd_eo,
        rho_io=rho[0], rho_eo=rho[1], radius=R, length=L, tube=app.tube, window=(float(t[0]), float(t[-1])),
        sample_rate=sample_rate, hoop=np.zeros(n) if hoop else None, sd_hoop=strain_sd[2] if hoop else None,
        rho_hoop=rho[2] if hoop else None, striker_velocity=striker_velocity, **extra,
    )
    lk = Likelihood(template, hoop=hoop, axial_poisson=axial_poisson, ratio_model_form=model_form)
    theta = np.array([[f, nu] + ([gain] if hoop else [])])
    rep = lk.simulate(theta, rng=np.random.default_rng(seed))
    return replace(template, F_io=rep["F_io"][0], F_eo=rep["F_eo"][0], hoop=rep["hoop"][0] if hoop else None)


@dataclass(frozen=True)
class Replica:
    """Truth and 90 % intervals of one SBC replica."""

    f: float
    nu: float
    kappa: float
    f_interval: tuple[float, float]
    kappa_interval: tuple[float, float]
    converged: bool

    @property
    def covers_f(self) -> bool:
        return self.f_interval[0] <= self.f <= self.f_interval[1]

    @property
    def covers_kappa(self) -> bool:
        return self.kappa_interval[0] <= self.kappa <= self.kappa_interval[1]


def record_data(f: float, nu: float, gain: float, *, seed: int, model_form: float = 0.0) -> StationaryData:
    """Stationary data of a whole closed-form record (friction_uq.synthetic -> record -> analysis.prepare);
    noise, its effective AR(1) coefficient and the offset-error sds come from the pre-pulse segments. With
    ``model_form``, the record's ratio departs from eq. 17's by a relative error drawn from N(0, model_form^2)
    (the likelihood's model-form term, drawn from its own stream of ``seed``)."""
    from friction_uq.analysis import prepare
    from friction_uq.record import read_record
    from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

    error = model_form * float(np.random.default_rng([seed, 17]).standard_normal()) if model_form else 0.0
    with tempfile.TemporaryDirectory() as tmp:
        path = write_closed_form_record(
            os.path.join(tmp, "r.h5"), ClosedFormTest(f=f, nu=nu, gains={"tube_hoop": gain}, ratio_error=error),
            seed=seed,
        )
        prep = prepare(read_record(path))
    return prep.data


def run_replica(args: tuple[int, bool, int, str]) -> Replica:
    """One replica: truth from the default prior (seeded by ``seed``), data, posterior, intervals.

    ``source`` is "closed-form" (:func:`closed_form_data`) or "records" (:func:`record_data`).
    """
    seed, hoop, n_ensembles, source = args
    priors = load_priors(default_prior_path("I1"))
    rng = np.random.default_rng(seed)
    truth = priors.subset(("f", "nu", "hoop_gain")).rvs(rng, 1)[0]
    f, nu, g = map(float, truth)
    if source == "records":
        data = record_data(f, nu, g, seed=seed + 1_000_000, model_form=RATIO_MODEL_FORM)
    else:
        data = closed_form_data(f, nu, g, seed=seed + 1_000_000, hoop=hoop, n_baseline=2000,
                                model_form=RATIO_MODEL_FORM)
    s = sample_posterior(data, priors, seed=seed, hoop=hoop, n_ensembles=n_ensembles)
    fd = s.flat("f")
    kd = fd * cell.lateral_ratio(s.flat("nu"))
    fq = np.quantile(fd, [0.05, 0.95])
    kq = np.quantile(kd, [0.05, 0.95])
    return Replica(f, nu, float(cell.kappa(f, nu)), (float(fq[0]), float(fq[1])), (float(kq[0]), float(kq[1])),
                   s.converged)


def run_sbc(
    n: int, *, seed: int, hoop: bool, n_ensembles: int = 1, workers: int | None = None, source: str = "closed-form",
) -> list[Replica]:
    """``n`` replicas with seeds seed, seed+1, ... (in parallel processes; results do not depend on it)."""
    args = [(seed + i, hoop, n_ensembles, source) for i in range(n)]
    workers = workers or min(2, os.cpu_count() or 1)
    if workers == 1:
        return [run_replica(a) for a in args]
    with ProcessPoolExecutor(max_workers=workers) as ex:
        return list(ex.map(run_replica, args))


def binomial_band(n: int, p: float, level: float) -> tuple[float, float]:
    """Central ``level`` band of the observed rate k/n when k ~ Binomial(n, p)."""
    lo = stats.binom.ppf((1.0 - level) / 2.0, n, p) / n
    hi = stats.binom.ppf(1.0 - (1.0 - level) / 2.0, n, p) / n
    return float(lo), float(hi)


def coverage(replicas: list[Replica]) -> tuple[float, float]:
    """Coverage rates (kappa, f) of the 90 % intervals."""
    return (float(np.mean([r.covers_kappa for r in replicas])), float(np.mean([r.covers_f for r in replicas])))


# ----------------------------------------------------------------------------------------------


def test_closed_form_data_reproduces_table1_levels():
    """The builder's noise-free levels are those of docs/physics.md Table 1 (f = 0.05: 10097 N, 1440 N)."""
    d = closed_form_data(0.05, 0.4, seed=0, strain_sd=(1e-12, 1e-12, 1e-12))
    assert np.mean(d.F_io) == pytest.approx(10097, abs=0.5)
    assert np.mean(d.F_eo) == pytest.approx(1440, abs=0.5)
    assert d.V[0] == pytest.approx(8.926, abs=5e-4)


def test_sbc_coverage_gate():
    """40 replicas each without and with the hoop term: coverage of kappa and f in the 99 % band."""
    n = 40
    lo, hi = binomial_band(n, 0.9, 0.99)
    for hoop, seed in ((False, 1000), (True, 5000)):
        reps = run_sbc(n, seed=seed, hoop=hoop)
        ck, cf = coverage(reps)
        assert all(r.converged for r in reps)
        assert lo <= ck <= hi, f"hoop={hoop}: kappa coverage {ck:.3f} outside the 99 % band [{lo:.3f}, {hi:.3f}]"
        assert lo <= cf <= hi, f"hoop={hoop}: f coverage {cf:.3f} outside the 99 % band [{lo:.3f}, {hi:.3f}]"


#: The full study makes 8 coverage assertions (kappa and f, with and without the hoop term, closed-form
#: stationary phases and whole records): each is held to the binomial band of a family-wise 95 %
#: (Bonferroni), so that a correct sampler fails the study by chance one run in twenty, not one in
#: three as with a 95 % band per assertion. (Kappa with the hoop term on closed-form phases, seeds
#: 20000-20199, covers 171/200 with the sampler before its parameters were addressed by name and
#: 170/200 after: the same statistics, other bits, on the edge of a per-assertion 95 % band.)
FULL_STUDY_LEVEL = 1.0 - 0.05 / 8


#: Kappa with the hoop term on whole closed-form records over-covered a little (0.960 against the band's
#: 0.955) while the records carried neither the hoop level's 3 % discrepancy nor the ratio's model-form
#: error the likelihood allows for; with the records drawing the ratio's term (record_data) it is inside.
@pytest.mark.slow
@pytest.mark.parametrize("hoop, source", [(False, "closed-form"), (True, "closed-form"), (False, "records"),
                                          (True, "records")])
def test_sbc_coverage_full(hoop, source):
    """200 replicas: coverage of kappa and f inside the binomial band (family-wise 95 %) around 90 %."""
    n = 200
    lo, hi = binomial_band(n, 0.9, FULL_STUDY_LEVEL)
    reps = run_sbc(n, seed=(20_000 if hoop else 10_000) + (50_000 if source == "records" else 0), hoop=hoop,
                   source=source)
    ck, cf = coverage(reps)
    assert lo <= ck <= hi, f"kappa coverage {ck:.3f} outside [{lo:.3f}, {hi:.3f}]"
    assert lo <= cf <= hi, f"f coverage {cf:.3f} outside [{lo:.3f}, {hi:.3f}]"
