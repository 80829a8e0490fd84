"""Friction laws across tests and set-ups: joint fit, leave-one-test-out ELPD, the best-supported law.

Each test gives kappa = f nu/(1-nu) (what its forces fix, to < 1 %: a normal approximation of its
draws), its sliding velocity V and mean wall pressure p (measured, with their sd). The sample is
one material, so nu is shared: a law for f is a law for kappa up to the factor nu/(1-nu), and the
laws are fitted to kappa (in units of the campaign's mean kappa, y = kappa / kappa_bar). When
every test was diagnosed, the laws are fitted to f under each test's diagnosed model instead
(``LawData.basis = "f"``; y = f / f_bar), which the mechanism found (a clearance, a plug
friction) no longer biases:

* ``constant``:           y = a
* ``velocity``:           y = d + (s - d) exp(-V / v_c)   (the mechanism catalogue's form)
* ``pressure``:           y = d + (s - d) exp(-P / P_c)
* ``slip``:               y = d + (s - d) exp(-S / S_c)
* ``pressure+velocity``:  y = d + (s - d) exp(-V / v_c) + amp_p [exp(-P / P_c) - exp(-1 / P_c)]

with P = p / p_ref, p_ref the campaign's mean pressure, and S the test's mean slip over its window (eq. 7
integrated from the start of loading). The pressure and the velocity terms have one shape, a
monotone change between two levels over a scale (rising or falling, nearly straight when the scale is long,
saturating when it is short), so that the law's formula does not decide which variable is named: a pressure law
of one straight line (y = a (1 + c (P - 1)), before the nineteenth session) was 8 % off a hyperbolic wall over
the pressures of three set-ups (50-280 MPa), a misfit the velocity term of pressure+velocity then took up. Every set-up but the first carries a calibration offset
(1 + cal_s) with a normal prior of sd :data:`CALIBRATION_SD`: what the bars' and gauges' calibrations
allow (below), not a free parameter, so that a law cannot fit a difference between set-ups (which
is what a second internal output bar is there to measure, eq. 15-16) by an offset. A model used to
*flag* a set-up also carries a free multiplicative offset (1 + delta) on one set-up (delta ~
N(0, 0.3)): a set-up that departs from the shared law by more than its calibration allows is a
finding for ``diagnose`` to explain, never part of a law.

Calibration (:data:`CALIBRATION_SD` = 3 %): kappa is read from F_eo/F_io, two bars' forces, each
E A epsilon: a bar's modulus (~1 %), its section (~1 %: 0.5 % on a diameter) and its gauge's
calibration (~1 %) on each of the two bars, sqrt(6) x 1 % = 2.4 %, rounded up to 3 % for the
wave speeds and the gauges' positions. A test's y is uncertain by
its own posterior, by the measured V and p through the law's slopes (errors in variables,
linearised: (dy/dV sd_V)^2 + (dy/dp sd_p)^2), and by a between-test scatter r (relative,
half-normal(0.1) prior) that the per-test posteriors do not explain. Given the test's stored draws
(``LawData.draws``), its likelihood is their kernel density convolved with that normal spread,
each draw divided by its prior (bilby's hyper-likelihood from stored samples; :mod:`.kernels`).
It keeps the shape of a skewed posterior, which a normal of the draws' mean and sd does not: the
long upper tail of a test whose f is weakly fixed would pull that mean up and inflate that sd.
Without draws the test's likelihood is the normal N(y; law, sqrt(sd_y^2 + law_var)).
Priors: a, d, s uniform on (0, 5); v_c log-uniform on (0.3, 300) m/s; P_c log-uniform on (1/30, 30) (in
units of p_ref: about the span of v_c's range over the tested speeds); amp_p uniform on (-5, 5), as s - d; the law
positive at every test; cal_s ~ N(0, 0.03); delta ~ N(0, 0.3).

**Inside each test**: every law's likelihood also reads each test's change of kappa across its
window, which separates a slip law from a velocity law (:mod:`.law_windows`).
Priors: S_c log-uniform on (0.1, 100) mm (the tested slips are 0.5-4 mm).

Sampled with emcee (:mod:`.law_coordinates`), the chain run on to ``TAU_MULTIPLE`` autocorrelation times
(up to ``MAX_STEPS``, :mod:`.law_chain`); leave-one-test-out ELPD in :mod:`.law_loo`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..stats import RULE, paired_difference
from ..stats.trimmed import trimmed_difference
from ..stats.streams import legacy_state
from .kernels import log_kernel_mixture
from . import law_chain
from .law_chain import KEPT_DRAWS, STEP_BLOCK, THIN, chain_length_needed, max_autocorr_time
from .law_coordinates import LawCoordinates
from .law_data import BASES, LawData
from .law_forms import (LAW_PARAMS, LAWS, LOG_PC_RANGE, LOG_SC_RANGE, LOG_VC_RANGE, NESTS, SPECIAL_CASES,
                        law_mean, prior_table)
from .law_points import LawPoints
from .law_windows import TREND_DOF, TREND_FLOOR, TREND_REL, change_loglike

#: What the campaign's law modules give, from here (the laws' forms, data and window term live beside)
__all__ = ["BASES", "CALIBRATION_SD", "FREE_OFFSET_SD", "LAWS", "LAW_PARAMS", "LOG_PC_RANGE", "LOG_SC_RANGE",
           "LOG_VC_RANGE", "NESTS", "SPECIAL_CASES", "TREND_DOF", "TREND_FLOOR", "TREND_REL", "Elpd", "Fit", "LawData",
           "Model", "best_law", "law_mean", "rank"]

#: Prior sd of a set-up's calibration offset (module docstring).
CALIBRATION_SD = 0.03
#: Prior sd of a free set-up offset (flag models only).
FREE_OFFSET_SD = 0.3


@dataclass(frozen=True)
class Model:
    """A law, with calibration offsets on the set-ups ``calibrated`` and optionally a free offset on one
    set-up (``offset_setup``; module docstring)."""

    law: str
    offset_setup: str | None = None
    calibrated: tuple[str, ...] = ()
    #: set-ups flagged already: their level is left out of the law (a free offset, ``free_<set-up>``)
    freed: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        free = self.freed + ((self.offset_setup,) if self.offset_setup else ())
        return self.law + "".join(f" + offset {s}" for s in free)

    @property
    def cal_setups(self) -> tuple[str, ...]:
        """The set-ups with a calibration offset (a set-up with a free offset needs none)."""
        return tuple(s for s in self.calibrated if s != self.offset_setup and s not in self.freed)

    @property
    def params(self) -> tuple[str, ...]:
        return (LAW_PARAMS[self.law] + tuple(f"cal_{s}" for s in self.cal_setups)
                + tuple(f"free_{s}" for s in self.freed) + (("delta",) if self.offset_setup else ()) + ("r",))

    def setup_scale(self, theta: dict[str, np.ndarray], setups: Sequence[str]) -> np.ndarray | float:
        """(1 + cal_s)(1 + free_s)(1 + delta) of each test's set-up: (W, n), or 1.0 without offsets."""
        scale: np.ndarray | float = 1.0
        for s in self.cal_setups + self.freed:
            on = np.array([x == s for x in setups])
            key = f"cal_{s}" if s in self.cal_setups else f"free_{s}"
            scale = scale * np.where(on[None, :], 1.0 + theta[key], 1.0)
        if self.offset_setup is not None:
            on = np.array([x == self.offset_setup for x in setups])
            scale = scale * np.where(on[None, :], 1.0 + theta["delta"], 1.0)
        return scale


class Fit:
    """Posterior draws of one model on one data set, and its pointwise log-likelihood function."""

    def __init__(self, model: Model, data: LawData, *, kbar: float, p_ref: float, seed: int,
                 nwalkers: int = 32, nsteps: int = 1000, burn: int = 300, start: np.ndarray | None = None,
                 max_steps: int | None = None) -> None:
        """``start``: the walkers' first positions (nwalkers, parameters), e.g. draws of the model on more
        data; without it a random search from a fixed guess finds a start near the mode. ``nsteps``: the chain's
        first length, run on to ``law_chain.TAU_MULTIPLE`` autocorrelation times up to ``max_steps`` (None:
        ``law_chain.MAX_STEPS``; :func:`~.law_chain.chain_length_needed`)."""
        self.model, self.data, self.kbar, self.p_ref = model, data, kbar, p_ref
        self._kernels = data.kernels(kbar)
        self._points = LawPoints(model.law, data, p_ref)
        self._prior = prior_table(model.params, calibration_sd=CALIBRATION_SD, free_offset_sd=FREE_OFFSET_SD)
        #: the chain's steps, the steps discarded, and the largest autocorrelation time estimated (steps)
        self.steps, self.discarded, self.tau = 0, 0, float("nan")
        cap = law_chain.MAX_STEPS if max_steps is None else max_steps
        self.draws = self._sample(seed, nwalkers, (nsteps, max(nsteps, cap)), burn, start)

    def _theta(self, x: np.ndarray) -> dict[str, np.ndarray]:
        return {name: x[:, k:k + 1] for k, name in enumerate(self.model.params)}

    def pointwise(self, x: np.ndarray, data: LawData | None = None, *, chunk: int = 512) -> np.ndarray:
        """log p(test_i | theta) for draws x (W, k): (W, n), on the fitted data or on ``data``, ``chunk`` draws at a
        time."""
        if data is None:
            d, kernels, points = self.data, self._kernels, self._points
        else:
            d, kernels, points = data, data.kernels(self.kbar), LawPoints(self.model.law, data, self.p_ref)
        out = []
        for i in range(0, len(x), chunk):
            th = self._theta(x[i:i + chunk])
            out.append(self._loglike(th, d, kernels, points, points.evaluate(th)))
        return np.vstack(out) if out else np.zeros((0, d.n))

    def _loglike(self, th: dict[str, np.ndarray], d: LawData, kernels: tuple | None, points: LawPoints,
                 at: dict[str, np.ndarray]) -> np.ndarray:
        """log p(test_i | theta) on ``d`` from the law at the likelihood's points, ``at = points.evaluate(th)``
        (:class:`~.law_points.LawPoints`): (W, n)."""
        mean = at["mean"]
        # errors in variables: the measured V and p, and the slip (V integrated: V's relative error)
        dV = (at["V+"] - at["V-"]) / (2 * points.hV)
        dp = (at["p+"] - at["p-"]) / (2 * points.hp)
        var_x = (dV * d.V_sd) ** 2 + (dp * d.p_sd / self.p_ref) ** 2
        if "S+" in at:
            dS = (at["S+"] - at["S-"]) / (2 * points.hS)
            var_x = var_x + (dS * d.slip * d.V_sd / np.maximum(d.V, 1e-9)) ** 2
        if self.model.offset_setup is not None or self.model.cal_setups or self.model.freed:
            scale = self.model.setup_scale(th, d.setups)
            mean, var_x = mean * scale, var_x * scale**2
        var = var_x + (th["r"] * mean) ** 2
        if kernels is None:
            var = var + (d.kappa_sd / self.kbar) ** 2
            out = -0.5 * (d.kappa / self.kbar - mean) ** 2 / var - 0.5 * np.log(2 * np.pi * var)
        else:
            yj, logw, h2 = kernels
            out = log_kernel_mixture(np.ascontiguousarray(mean, dtype=float), np.ascontiguousarray(var + h2[None, :]),
                                     yj, logw)
        return out + change_loglike(at["first"], at["second"], d) if d.reads_window_changes else out

    def log_prior(self, x: np.ndarray) -> np.ndarray:
        """The log prior density of draws x (W, k) up to a constant (module docstring): every support in one test,
        then the normal priors' terms in the parameters' order."""
        lo, hi, closed, normal = self._prior
        inside = np.where(closed, x >= lo, x > lo) & (x < hi)
        lp = np.where(np.all(inside, axis=1), 0.0, -np.inf)
        for k, sd in normal:
            lp += -0.5 * (x[:, k] / sd) ** 2
        return lp

    def _log_prob(self, x: np.ndarray) -> np.ndarray:
        lp = self.log_prior(x)
        ok = np.isfinite(lp)
        out = np.full(len(x), -np.inf)
        if ok.any():
            th = self._theta(x[ok])
            at = self._points.evaluate(th)
            ll = self._loglike(th, self.data, self._kernels, self._points, at).sum(axis=1)
            if self.model.law == "pressure+velocity":  # the only law whose terms can take it below 0 at a test
                positive = np.all(at["mean"] > 0, axis=1)
                if self.data.reads_window_changes:  # and within each window
                    positive &= np.all(at["first"] > 0, axis=1) & np.all(at["second"] > 0, axis=1)
                ll = np.where(positive, ll, -np.inf)
            out[ok] = lp[ok] + ll
        return out

    def _start(self, rng: np.random.Generator, nwalkers: int) -> np.ndarray:
        guess = {"a": 1.0, "d": 0.8, "s": 1.3, "log_vc": np.log(8.0), "log_pc": 0.0, "log_sc": np.log(2e-3),
                 "amp_p": 0.0, "delta": 0.0, "r": 0.02}
        x0 = np.array([guess.get(p, 0.0) for p in self.model.params])
        best = x0
        # a few rounds of random search from the guess: a start inside the support, near the mode
        for width in (0.3, 0.1, 0.03, 0.01):
            cand = best + width * rng.standard_normal((400, x0.size)) * np.maximum(np.abs(best), 0.05)
            lp = self._log_prob(np.vstack([best[None, :], cand]))
            best = np.vstack([best[None, :], cand])[int(np.argmax(lp))]
        ball = best + 1e-3 * rng.standard_normal((nwalkers, x0.size)) * np.maximum(np.abs(best), 0.01)
        ball[:, -1] = np.abs(ball[:, -1])
        return ball

    def _sample(self, seed: int, nwalkers: int, steps: tuple[int, int], burn: int,
                start: np.ndarray | None) -> np.ndarray:
        """Draws in the law's parameters, sampled in :class:`~.law_coordinates.LawCoordinates` (the same
        posterior, with the change's Jacobian; a shape the ensemble crosses in a few tens of steps), the chain
        run on in blocks of :data:`STEP_BLOCK` from ``steps[0]`` until it is long enough
        (:func:`chain_length_needed`) or ``steps[1]`` long; about :data:`KEPT_DRAWS` draws kept, evenly thinned."""
        import emcee

        rng = np.random.default_rng(seed)
        start = self._start(rng, nwalkers) if start is None else np.asarray(start, float)
        coords = LawCoordinates(self.model.params, self.data.V, self.data.p / self.p_ref, self.data.slip)

        def log_prob(z: np.ndarray) -> np.ndarray:
            x, log_jac = coords.to_law(z)
            ok = np.all(np.isfinite(x), axis=1)
            out = np.full(len(z), -np.inf)
            if ok.any():
                out[ok] = self._log_prob(x[ok]) + log_jac[ok]
            return out

        sampler = emcee.EnsembleSampler(nwalkers, start.shape[1], log_prob, vectorize=True)
        state = emcee.State(coords.to_sampling(start), random_state=legacy_state(rng).get_state())
        state = sampler.run_mcmc(state, steps[0])
        while True:
            chain = sampler.get_chain()
            self.tau = max_autocorr_time(chain[burn:])
            needed, discard = chain_length_needed(self.tau, burn)
            if len(chain) >= min(needed, steps[1]):
                break
            state = sampler.run_mcmc(state, min(STEP_BLOCK, steps[1] - len(chain)))
        self.steps, self.discarded = len(chain), min(discard, len(chain) - 1)
        kept = chain[self.discarded:]
        thin = max(THIN, (kept.shape[0] * nwalkers) // KEPT_DRAWS)
        # thinned from the last step back, so that the last walkers (where a leave-one-out refit starts) are kept
        return coords.to_law(kept[::-1][::thin][::-1].reshape(-1, kept.shape[2]))[0]


@dataclass(frozen=True)
class Elpd:
    model: str
    elpd: float
    se: float
    pointwise: np.ndarray
    pareto_k: np.ndarray
    refits: int


def rank(elpds: Sequence[Elpd]) -> list[dict[str, float | str]]:
    """Models by ELPD, each with dELPD and SE against the top one, and ``d_elpd_rest``: dELPD with the one test
    that favours the top model most left out (:func:`friction_uq.stats.trimmed.trimmed_difference`, as
    ``diagnose`` asks of a cause's evidence; read by :meth:`friction_uq.stats.WeightRule.ruled_out`; None with
    fewer than 3 tests), the test's index in ``rest_without_test`` (in the order of the tests' pointwise densities,
    ``LawData.labels``; None for the top model and with fewer than 3 tests)."""
    order = sorted(elpds, key=lambda e: -e.elpd)
    top = order[0]
    out = []
    for e in order:
        d, se = paired_difference(top.pointwise, e.pointwise)
        few, first = e.pointwise.size < 3, e is top
        worst = None if first or few else int(np.argmax(top.pointwise - e.pointwise))
        rest = None if few else 0.0 if first else trimmed_difference(top.pointwise, e.pointwise, drop=1)[0]
        out.append({"model": e.model, "elpd": e.elpd, "se": e.se, "d_elpd": d, "d_se": se, "d_elpd_rest": rest,
                    "rest_without_test": worst,
                    "n_tests": int(e.pointwise.size), "pareto_k_max": float(np.max(e.pareto_k)), "refits": e.refits})
    return out


def best_law(ranking: Sequence[dict], laws: Sequence[str]) -> str | None:
    """The simplest law that every law not decisively worse than the top contains; None if there is none."""
    contenders = [r["model"] for r in ranking if not RULE.decisive(r["d_elpd"], r["d_se"], n=r.get("n_tests"))]
    contenders = [m for m in contenders if m in laws]
    for law in sorted(contenders, key=lambda m: len(LAW_PARAMS[m])):
        if all(other in NESTS[law] for other in contenders):
            return law
    return None
