"""Hierarchical pooling of a campaign from each test's stored posterior draws.

Population model: theta_i ~ Normal(mu, sigma) across tests (theta = f or kappa). Each test's
draws were made under its own prior pi(theta), so the hyper-likelihood of the campaign is (as
bilby's hyper-parameter likelihood)

    log L(mu, sigma) = sum_i log mean_j [ N(theta_ij; mu, sigma) / pi(theta_ij) ].

The hyper-posterior is evaluated on a grid (flat prior on mu, uniform on sigma over [0, sigma_max];
a uniform prior on the scale is the usual weakly informative choice for a handful to hundreds of
groups). The Monte Carlo estimate of each term is noisy when few draws carry weight (a population
narrower than the per-test posteriors): each test's effective sample size and the variance of the
log-likelihood estimate, sum_i Var(w_i) / (n_i mean(w_i)^2), are reported, and the pooling is
refused when that variance, averaged over the hyper-posterior, exceeds 1 (as gwpopulation does).

The prior of f is the test's prior file; kappa = f nu/(1-nu) has an implied prior, computed
exactly by quadrature over nu: pi(kappa) = int pi_f(kappa (1-nu)/nu) (1-nu)/nu pi_nu(nu) dnu. f under
a test's diagnosed model (``basis`` "diagnosed") was drawn under that model's prior on f_effective,
which the run stores beside the draws (friction_uq.discrepancy.effective_prior) and the campaign
reads back.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.special import logsumexp

from ..models.parameters import effective_sample_size
from ..priors import Priors
from ..stats.thinning import evenly_spaced

MAX_MC_VARIANCE = 1.0
DRAWS_PER_TEST = 1000


@dataclass(frozen=True)
class StoredDraws:
    """One test's posterior draws of a quantity and the log density of its sampling prior at them."""

    label: str
    setup: str
    draws: np.ndarray
    log_prior: np.ndarray


@dataclass(frozen=True)
class Pooled:
    """Population mean and between-test scatter of one quantity, or the reason it was refused."""

    variable: str
    tests: list[str]
    mu: dict[str, float] = field(default_factory=dict)
    sigma: dict[str, float] = field(default_factory=dict)
    ess: dict[str, float] = field(default_factory=dict)
    mc_variance: float = float("nan")
    refused: str | None = None
    grid_mu: np.ndarray | None = None
    grid_sigma: np.ndarray | None = None
    log_post: np.ndarray | None = None
    #: whose draws were pooled: "stationary" (the stationary analysis') or "diagnosed" (f under each test's
    #: diagnosed model)
    basis: str = "stationary"

    def to_json(self) -> dict[str, object]:
        return {"variable": self.variable, "basis": self.basis, "tests": self.tests, "mu": self.mu, "sigma": self.sigma,
                "ess_per_test": self.ess, "mc_variance_log_likelihood": self.mc_variance, "refused": self.refused}


def implied_kappa_log_prior(kappa: np.ndarray, priors: Priors, *, n_nu: int = 801) -> np.ndarray:
    """log pi(kappa) for kappa = f nu/(1-nu) with f and nu independent under ``priors`` (quadrature over nu)."""
    nu_prior, f_prior = priors["nu"], priors["f"]
    lo, hi = (float(x) for x in nu_prior.ppf(np.array([1e-7, 1 - 1e-7])))
    nu = np.linspace(lo, hi, n_nu)
    jac = (1.0 - nu) / nu
    log_w = nu_prior.logpdf(nu) + np.log(jac) + np.log(np.gradient(nu))
    k = np.asarray(kappa, float)
    out = np.empty(k.shape)
    for i in range(0, k.size, 2000):
        kk = k.ravel()[i:i + 2000]
        out.ravel()[i:i + 2000] = logsumexp(f_prior.logpdf(kk[:, None] * jac[None, :]) + log_w[None, :], axis=1)
    return out


def thin(x: np.ndarray, n: int = DRAWS_PER_TEST) -> np.ndarray:
    """At most n draws, evenly spaced (deterministic: :func:`friction_uq.stats.thinning.evenly_spaced`)."""
    return evenly_spaced(x, n)


def strata(x: np.ndarray, n: int) -> np.ndarray:
    """Indices of ``n`` draws of ``x`` that stand for its distribution: the order statistics at ranks
    (j + 1/2) / n, j = 0 .. n-1 (all of them when there are at most ``n``). A mean over them is a
    stratified estimate of an expectation under the draws (error O(1/n) for a smooth integrand, against
    O(1/sqrt(n)) for n draws taken at random or evenly along the chain), so a test's likelihood read
    from them moves little with the sampler's bits."""
    x = np.asarray(x, float).ravel()
    if x.size <= n:
        return np.arange(x.size)
    order = np.argsort(x, kind="stable")
    return order[((np.arange(n) + 0.5) * x.size / n).astype(int)]


def _quantiles(values: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    order = np.argsort(values)
    v, w = values[order], weights[order]
    c = np.cumsum(w) / np.sum(w)
    q = np.interp([0.05, 0.5, 0.95], c, v)
    mean = float(np.sum(v * w) / np.sum(w))
    return {"mean": mean, "q05": float(q[0]), "q50": float(q[1]), "q95": float(q[2]),
            "sd": float(np.sqrt(np.sum(w * (v - mean) ** 2) / np.sum(w)))}


def pool(tests: Sequence[StoredDraws], variable: str, *, n_mu: int = 81, n_sigma: int = 60,
         basis: str = "stationary") -> Pooled:
    """Hyper-posterior of (mu, sigma) on a grid; refused (with the reason) where the estimate is too noisy.
    ``basis`` says whose draws these are (:attr:`Pooled.basis`).

    The grid of mu first spans the tests' medians +- 2 of their largest sd; where mu's marginal posterior
    still has mass at its ends (a wide scatter among few tests: mu's posterior sd runs to sigma / sqrt(N)),
    it is widened (:func:`mu_grid`) until it holds the posterior to :data:`MU_EDGE_MASS`, or the pooling is
    refused."""
    labels = [t.label for t in tests]
    if len(tests) < 2:
        return Pooled(variable, labels, refused=f"pooling {variable} needs at least 2 analysed tests, "
                      f"{len(tests)} given", basis=basis)
    med = np.array([np.median(t.draws) for t in tests])
    sds = np.array([np.std(t.draws) for t in tests])
    span = float(np.ptp(med) + 4 * np.max(sds))
    sigma = np.linspace(span / n_sigma, span, n_sigma)
    for widen in range(MU_WIDENINGS + 1):
        mu = mu_grid(med, sds, n_mu, widen)
        log_l, var = _hyper_log_likelihood(tests, mu, sigma)
        edge = mu_edge_mass(np.exp(log_l - logsumexp(log_l)).sum(axis=0))
        if edge <= MU_EDGE_MASS:
            break
    log_post = log_l - logsumexp(log_l)
    p = np.exp(log_post)
    mc_var = float(np.sum(p * var))
    i_s, i_m = np.unravel_index(np.argmax(log_post), log_post.shape)
    ess = {}
    for t in tests:
        log_w = -0.5 * ((t.draws - mu[i_m]) / sigma[i_s]) ** 2 - t.log_prior
        w = np.exp(log_w - log_w.max())
        ess[t.label] = effective_sample_size(w)
    mu_q = _quantiles(mu, p.sum(axis=0))
    sigma_q = _quantiles(sigma, p.sum(axis=1))
    refused = None
    if mc_var > MAX_MC_VARIANCE:
        worst = min(ess, key=ess.get)
        refused = (f"pooling {variable} refused: the Monte Carlo variance of the hyper-log-likelihood is {mc_var:.2f} "
                   f"(> {MAX_MC_VARIANCE:g}); too few draws carry weight (smallest effective sample size "
                   f"{ess[worst]:.0f}, test {worst}): the population is narrower than the per-test posteriors, "
                   "store more draws or pool a quantity the tests measure less precisely")
    elif edge > MU_EDGE_MASS:
        refused = (f"pooling {variable} refused: the population mean's posterior runs to the edge of its grid "
                   f"([{mu[0]:.3g}, {mu[-1]:.3g}], {2 ** MU_WIDENINGS} times the tests' spread); the tests scatter "
                   "too widely for their number to place it")
    elif sigma_q["q95"] > 0.95 * sigma[-1]:
        refused = (f"pooling {variable} refused: the between-test scatter runs to the edge of its grid "
                   f"({sigma[-1]:.3g}); the tests disagree too much for one normal population")
    return Pooled(variable, labels, mu_q, sigma_q, ess, mc_var, refused, mu, sigma, log_post, basis)

#: Largest posterior mass of mu allowed in the outer 2.5 % of its grid at either end: a numerical tolerance of
#: the quadrature, not a statistical threshold. On 400 random campaigns (2-8 tests of normal posteriors, sd
#: 0.002-0.03, scatter 0-0.06, the closed-form hyper-likelihood on a wide grid) a grid within it left at most
#: 7e-4 of mu's posterior outside (9e-3 at 1e-3); the first grid was within it on 51 of the 400.
MU_EDGE_MASS = 1e-4
#: Times the grid of mu is doubled in width before the pooling is refused.
MU_WIDENINGS = 3


def mu_grid(med: np.ndarray, sds: np.ndarray, n_mu: int, widen: int) -> np.ndarray:
    """The grid of mu: the medians' range +- 2 of the largest sd (``widen`` 0), its width doubled ``widen``
    times about the same centre with the spacing kept, (n_mu - 1) 2^widen + 1 points."""
    lo, hi = med.min() - 2 * sds.max(), med.max() + 2 * sds.max()
    if widen == 0:
        return np.linspace(lo, hi, n_mu)
    extra = (2 ** widen - 1) * (hi - lo) / 2
    return np.linspace(lo - extra, hi + extra, (n_mu - 1) * 2 ** widen + 1)


def mu_edge_mass(p_mu: np.ndarray) -> float:
    """The larger of the masses of mu's marginal posterior (on its grid) in the outer 2.5 % of the grid at
    either end."""
    k = max(1, len(p_mu) // 40)
    return float(max(p_mu[:k].sum(), p_mu[-k:].sum()) / p_mu.sum())


def _hyper_log_likelihood(tests: Sequence[StoredDraws], mu: np.ndarray,
                          sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """log L(mu, sigma) on the grid (module docstring) and the Monte Carlo variance of its estimate."""
    n_sigma, n_mu = len(sigma), len(mu)
    rows = max(1, 810 // n_mu)  # chunks keep the (sigma, mu, draw) array near 10 MB
    log_l = np.zeros((n_sigma, n_mu))
    var = np.zeros((n_sigma, n_mu))
    for t in tests:
        n = t.draws.size
        for a in range(0, n_sigma, rows):
            sg = sigma[a:a + rows, None, None]
            log_w = (-0.5 * ((t.draws[None, None, :] - mu[None, :, None]) / sg) ** 2 - np.log(sg)
                     - 0.5 * np.log(2 * np.pi) - t.log_prior[None, None, :])
            top = log_w.max(axis=2)
            w = np.exp(log_w - top[..., None])
            s1, s2 = w.sum(axis=2), np.einsum("ijk,ijk->ij", w, w)
            log_l[a:a + rows] += top + np.log(s1) - np.log(n)
            # Var of log(mean w) ~ Var(w) / (n mean(w)^2) = (n sum w^2 / (sum w)^2 - 1) / n
            var[a:a + rows] += (n * s2 / s1**2 - 1.0) / n
    return log_l, var
