"""Posterior sampling of (f, nu[, hoop_gain]) with emcee.

Design
------
* **Parametrisation.** emcee runs in z = (log f, log(nu/(1-nu)), log g). There the force data fix
  log f + log(nu/(1-nu)) = log kappa: the f-nu ridge of eq. 17 is a straight line, which the
  affine-invariant ensemble moves follow without loss (in (f, nu) it is a curve). The log-density
  in z includes the Jacobian log f + log(nu (1-nu)) + log g. Draws are returned in (f, nu, g).
* **Move.** Differential evolution (``emcee.moves.DEMove``): on these near-Gaussian posteriors it
  gives tau ~ 8-10 steps against 28-40 for the default stretch move at the same cost per step
  (measured on the paper's case, 32 walkers, with and without the hoop term).
* **Independent ensembles.** R-hat across the walkers of one ensemble is not an independent-chain
  diagnostic (emcee#183): ``n_ensembles`` (4) ensembles start from independent balls with
  independent random streams (``np.random.SeedSequence(seed).spawn``), and each is one *chain*
  of the result, so R-hat compares independent runs.
* **Stopping.** Every ``check_every`` steps (absolute step counts, so a resumed run checks at the
  same steps as an uninterrupted one) the integrated autocorrelation time tau is estimated per
  parameter, with the autocorrelation averaged over the walkers of all ensembles (same target and
  kernel, so pooling only lowers the estimator's noise); the run stops when, for every parameter,
  the chain is longer than ``tau_factor`` (50) tau and tau changed by less than ``tau_rtol``
  (1 %) since the previous check. At ``max_steps`` it stops anyway with a
  :class:`ConvergenceWarning` and ``converged=False`` in the result.
* **Draws.** burn-in 3 max(tau), thinning max(1, tau_min / 2). A chain's draws are its walkers'
  thinned sequences one after the other (walker-major), so autocorrelation along ``draw`` is the
  walkers' own and ArviZ's ESS is not inflated by interleaving walkers.
* **Resuming.** With ``backend_path`` every step is saved (emcee ``HDFBackend``, one group per
  ensemble, the random state included). Calling again with the same path and arguments continues
  each ensemble from ``get_last_sample()`` toward the target: the result equals an uninterrupted
  run. A file written for other data, priors or settings is refused.
* **Start.** A small Gaussian ball (a tenth of the Laplace-approximation sd) around the maximum a
  posteriori in z, every walker inside the prior support.
"""

from __future__ import annotations

import hashlib
import math
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import emcee
import h5py
import numpy as np
from scipy import optimize

from .errors import PriorError, SamplingError
from .likelihood import Likelihood
from .physics import cell
from .priors import Priors
from .window import StationaryData


class ConvergenceWarning(UserWarning):
    """The sampler stopped at ``max_steps`` before the convergence criterion was met."""


@dataclass(frozen=True)
class Progress:
    """What a progress callback receives at each check (every ``check_every`` steps)."""

    steps: int
    max_steps: int
    tau_max: float
    tau_change: float
    steps_over_tau: float
    acceptance: float
    seconds: float

    def line(self) -> str:
        """A short line for a terminal."""
        return (
            f"sampling: step {self.steps}/{self.max_steps}, tau {self.tau_max:.1f} "
            f"(steps/tau {self.steps_over_tau:.0f}, needs 50; change {100 * self.tau_change:.1f} %, needs < 1 %), "
            f"acceptance {self.acceptance:.2f}, {self.seconds:.1f} s"
        )


def stderr_progress(info: Progress) -> None:
    """Progress callback printing :meth:`Progress.line` to stderr."""
    print(info.line(), file=sys.stderr, flush=True)


@dataclass(frozen=True)
class SamplerSettings:
    """Sampler settings (see the module docstring)."""

    nwalkers: int = 32
    n_ensembles: int = 4
    max_steps: int = 20000
    check_every: int = 100
    tau_factor: float = 50.0
    tau_rtol: float = 0.01
    burn_factor: float = 3.0
    thin_factor: float = 0.5


@dataclass(frozen=True)
class PosteriorSamples:
    """Posterior draws and run statistics.

    Attributes
    ----------
    names : tuple of str
        Sampled parameters, e.g. ("f", "nu", "hoop_gain").
    draws : dict of str to array, shape (chain, draw)
        Draws of each parameter (chain = independent ensemble).
    log_likelihood, log_prior : array, shape (chain, draw)
        Per draw (log_prior in (f, nu, g), without the sampler's Jacobian).
    acceptance : array, shape (chain,)
        Mean acceptance fraction of each ensemble.
    tau : array, shape (chain, ndim)
        Integrated autocorrelation time (steps) per ensemble and parameter, in the sampler's z
        (the stopping rule uses the estimate pooled over ensembles).
    n_steps, burn, thin : int
        Steps per walker, discarded burn-in, thinning.
    converged : bool
        Whether the stopping criterion was met before ``max_steps``.
    seconds : float
        Wall time of the whole call (s).
    """

    names: tuple[str, ...]
    draws: dict[str, np.ndarray]
    log_likelihood: np.ndarray
    log_prior: np.ndarray
    acceptance: np.ndarray
    tau: np.ndarray
    n_steps: int
    burn: int
    thin: int
    converged: bool
    seconds: float
    seed: int
    hoop: bool
    nwalkers: int
    map_estimate: dict[str, float]
    prior_path: str = ""
    prior_description: str = ""
    settings: SamplerSettings = field(default_factory=SamplerSettings)

    @property
    def n_chains(self) -> int:
        return self.log_likelihood.shape[0]

    @property
    def n_draws(self) -> int:
        return self.log_likelihood.shape[1]

    def array(self) -> np.ndarray:
        """All draws, shape (chain, draw, ndim), columns in ``names`` order."""
        return np.stack([self.draws[n] for n in self.names], axis=-1)

    def flat(self, name: str) -> np.ndarray:
        """Draws of ``name`` pooled over chains, shape (chain * draw,)."""
        return self.draws[name].reshape(-1)


# ----------------------------------------------------------------------------------------------
# Parametrisation
# ----------------------------------------------------------------------------------------------


def to_theta(z: np.ndarray) -> np.ndarray:
    """(log f, log(nu/(1-nu)), log g) -> (f, nu, g), row-wise (any number of columns >= 2)."""
    z = np.asarray(z, float)
    theta = np.exp(z)
    theta[..., 1] = 1.0 / (1.0 + np.exp(-z[..., 1]))
    return theta


def to_z(theta: np.ndarray) -> np.ndarray:
    """Inverse of :func:`to_theta`."""
    theta = np.asarray(theta, float)
    with np.errstate(divide="ignore"):
        z = np.log(theta)
        z[..., 1] = np.log(theta[..., 1] / (1.0 - theta[..., 1]))
    return z


def _log_jacobian(theta: np.ndarray) -> np.ndarray:
    """log |d theta / d z| = log f + log(nu (1 - nu)) [+ log g]."""
    out = np.log(theta[..., 0]) + np.log(theta[..., 1] * (1.0 - theta[..., 1]))
    if theta.shape[-1] > 2:
        out = out + np.sum(np.log(theta[..., 2:]), axis=-1)
    return out


class LogPosterior:
    """Vectorised log posterior density in z (emcee's ``log_prob_fn`` with ``vectorize=True``)."""

    def __init__(self, likelihood: Likelihood, priors: Priors) -> None:
        self.likelihood = likelihood
        self.priors = priors

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """z: shape (nwalkers, ndim) -> shape (nwalkers,); -inf outside the prior support."""
        z = np.atleast_2d(np.asarray(z, float))
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            theta = to_theta(z)
            lp = self.priors.logpdf(theta) + _log_jacobian(theta)
        ok = np.isfinite(lp)
        out = np.full(len(z), -np.inf)
        if ok.any():
            ll = self.likelihood(theta[ok])
            out[ok] = np.where(np.isfinite(ll), lp[ok] + ll, -np.inf)
        return out


# ----------------------------------------------------------------------------------------------
# Start
# ----------------------------------------------------------------------------------------------


def _initial_guess(likelihood: Likelihood, priors: Priors) -> np.ndarray:
    """Parameter vector from the least-squares force ratio and the prior medians (f, nu, g)."""
    d = likelihood.data
    nu = float(priors["nu"].ppf(0.5))
    r0 = likelihood.force.r0
    sd_r = math.hypot(d.sd_eo, r0 * d.sd_io) / (abs(float(np.mean(d.F_io))) * math.sqrt(d.n))
    r = max(r0, 3.0 * sd_r, 1e-6)
    f = float(math.log1p(r) / cell.beta(nu, radius=d.radius, length=d.length))
    theta = [f, nu] + ([float(priors["hoop_gain"].ppf(0.5))] if len(priors.names) > 2 else [])
    return np.array(theta)


def _hessian(fun: Callable[[np.ndarray], np.ndarray], z: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """Central-difference Hessian of a vectorised function at z (all stencil points in one call)."""
    k = len(z)
    eye = np.eye(k) * h
    pts = [z]
    for i in range(k):
        for j in range(i, k):
            pts += [z + eye[i] + eye[j], z + eye[i] - eye[j], z - eye[i] + eye[j], z - eye[i] - eye[j]]
    vals = fun(np.array(pts))
    H = np.full((k, k), np.nan)
    if not np.all(np.isfinite(vals)):  # optimum on a prior bound: no Hessian
        return H
    m = 1
    for i in range(k):
        for j in range(i, k):
            pp, pm, mp, mm = vals[m:m + 4]
            H[i, j] = H[j, i] = (pp - pm - mp + mm) / (4.0 * h * h)
            m += 4
    return H


def start_ball(
    log_post: LogPosterior, priors: Priors, *, nwalkers: int, n_ensembles: int, rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Maximum a posteriori in z and starting positions, shape (n_ensembles, nwalkers, ndim).

    The ball's sd is a tenth of the Laplace approximation's (inverse Hessian at the optimum);
    walkers falling outside the prior support are redrawn.
    """
    z0 = to_z(_initial_guess(log_post.likelihood, priors))
    if not np.isfinite(log_post(z0)[0]):
        raise SamplingError(
            f"the starting point {dict(zip(priors.names, to_theta(z0)))} has zero prior or likelihood; "
            "check the priors against the data"
        )
    res = optimize.minimize(lambda z: -float(log_post(z)[0]), z0, method="Nelder-Mead",
                            options={"xatol": 1e-7, "fatol": 1e-7, "maxiter": 4000})
    z_map = res.x if np.isfinite(res.fun) and res.fun <= -float(log_post(z0)[0]) else z0
    H = _hessian(log_post, z_map)
    try:
        cov = np.linalg.inv(-H)
        chol = np.linalg.cholesky(0.5 * (cov + cov.T))
    except np.linalg.LinAlgError:
        chol = np.eye(len(z_map)) * 1e-3
    if not np.all(np.isfinite(chol)):
        chol = np.eye(len(z_map)) * 1e-3
    out = np.empty((n_ensembles, nwalkers, len(z_map)))
    for k in range(n_ensembles):
        todo = np.ones(nwalkers, bool)
        for _ in range(100):
            out[k, todo] = z_map + 0.1 * rng.standard_normal((int(todo.sum()), len(z_map))) @ chol.T
            todo = ~np.isfinite(log_post(out[k]))
            if not todo.any():
                break
        else:
            raise SamplingError("could not place the walkers inside the prior support around the MAP")
    return z_map, out


# ----------------------------------------------------------------------------------------------
# Backend
# ----------------------------------------------------------------------------------------------


def _fingerprint(data: StationaryData, priors: Priors, names: tuple[str, ...], seed: int, settings: SamplerSettings) -> str:
    h = hashlib.sha256()
    for arr in (data.F_io, data.F_eo, data.slip) + ((data.hoop,) if data.hoop is not None else ()):
        h.update(np.ascontiguousarray(arr, float).tobytes())
    h.update(repr((data.sd_io, data.sd_eo, data.rho_io, data.rho_eo, data.sd_hoop, data.rho_hoop)).encode())
    h.update(priors.describe().encode())
    h.update(repr((names, seed, settings.nwalkers, settings.n_ensembles, settings.check_every)).encode())
    return h.hexdigest()


def _open_backends(path: Path, fingerprint: str, n_ensembles: int) -> list[emcee.backends.HDFBackend]:
    path = Path(path)
    if path.exists():
        try:
            with h5py.File(path, "r") as fh:
                stored = fh.attrs.get("friction_uq_fingerprint")
        except OSError as exc:
            raise SamplingError(f"{path}: cannot read the sampler backend ({exc})") from exc
        if stored != fingerprint:
            raise SamplingError(
                f"{path}: this sampler backend was written for other data, priors, seed or settings; "
                "delete it or choose another --backend path"
            )
    else:
        path.parent.mkdir(parents=True, exist_ok=True)
        with h5py.File(path, "w") as fh:
            fh.attrs["friction_uq_fingerprint"] = fingerprint
            fh.attrs["friction_uq_version"] = _version()
    return [emcee.backends.HDFBackend(str(path), name=f"ensemble_{k}") for k in range(n_ensembles)]


def _version() -> str:
    from . import __version__

    return __version__


# ----------------------------------------------------------------------------------------------
# Sampling
# ----------------------------------------------------------------------------------------------


def integrated_time(chain: np.ndarray, *, c: float = 5.0) -> np.ndarray:
    """Walker-averaged integrated autocorrelation time (steps) per parameter.

    Same estimator as ``emcee.autocorr.integrated_time`` (Goodman-Weare/Sokal: autocorrelation
    averaged over walkers, Sokal's automatic window, smallest M with M >= c tau(M)), with one FFT
    over all walkers and parameters instead of one per walker.

    Parameters
    ----------
    chain : array, shape (nsteps, nwalkers, ndim)

    Returns
    -------
    array, shape (ndim,)
    """
    x = np.asarray(chain, float)
    n = x.shape[0]
    nfft = 1 << (2 * n - 1).bit_length()
    x = x - x.mean(axis=0)
    fx = np.fft.rfft(x, n=nfft, axis=0)
    acf = np.fft.irfft(fx * np.conj(fx), n=nfft, axis=0)[:n]
    with np.errstate(invalid="ignore", divide="ignore"):
        acf = acf / acf[0]
    acf = np.nanmean(acf, axis=1)  # (n, ndim)
    taus = 2.0 * np.cumsum(acf, axis=0) - 1.0
    m = np.arange(n)[:, None]
    ok = m >= c * taus
    window = np.where(ok.any(axis=0), np.argmax(ok, axis=0), n - 1)
    return taus[window, np.arange(x.shape[2])]


def sample_posterior(
    data: StationaryData,
    priors: Priors,
    *,
    seed: int,
    hoop: bool | None = None,
    backend_path: str | Path | None = None,
    progress: Callable[[Progress], None] | None = None,
    max_steps: int = 20000,
    nwalkers: int = 32,
    n_ensembles: int = 4,
    check_every: int = 100,
    axial_poisson: bool = True,
) -> PosteriorSamples:
    """Sample the posterior of (f, nu[, hoop_gain]) for one stationary phase.

    Parameters
    ----------
    data : StationaryData
        The stationary phase (forces in N, hoop strain, noise estimates).
    priors : Priors
        Must define f, nu and, with the hoop term, hoop_gain.
    seed : int
        Seed of everything random (start ball and each ensemble's stream).
    hoop : bool or None
        Use the hoop-gauge term; None: when the data have a hoop channel.
    backend_path : path or None
        emcee HDF5 backend; an existing file from the same call is resumed.
    progress : callable or None
        Called with a :class:`Progress` every ``check_every`` steps (e.g. :func:`stderr_progress`).
    max_steps : int
        Cap on steps per walker.
    nwalkers, n_ensembles, check_every : int
        Walkers per ensemble, independent ensembles (= chains), steps between convergence checks.
    axial_poisson : bool
        Include the tube's axial Poisson term in the hoop prediction.

    Returns
    -------
    PosteriorSamples

    Raises
    ------
    PriorError
        If ``priors`` lacks a parameter the likelihood needs.
    SamplingError
        If no walker start inside the prior support is found, or the backend file belongs to
        another run.
    """
    t_start = time.perf_counter()
    settings = SamplerSettings(nwalkers=nwalkers, n_ensembles=n_ensembles, max_steps=max_steps, check_every=check_every)
    if nwalkers < 4 or nwalkers % 2:
        raise SamplingError(f"nwalkers must be an even number >= 4, got {nwalkers}")
    if n_ensembles < 1 or max_steps < check_every or check_every < 10:
        raise SamplingError(
            f"need n_ensembles >= 1, check_every >= 10 and max_steps >= check_every; got {n_ensembles}, "
            f"{check_every}, {max_steps}"
        )
    likelihood = Likelihood(data, hoop=hoop, axial_poisson=axial_poisson)
    names = likelihood.names
    try:
        prior = priors.subset(names)
    except PriorError as exc:
        raise PriorError(f"{exc} (the {'hoop' if likelihood.has_hoop else 'force'} likelihood needs {', '.join(names)})") from exc
    log_post = LogPosterior(likelihood, prior)
    ndim = len(names)
    seeds = np.random.SeedSequence(seed).spawn(n_ensembles + 1)
    rng_start = np.random.default_rng(seeds[-1])

    if backend_path is not None:
        backends = _open_backends(Path(backend_path), _fingerprint(data, prior, names, seed, settings), n_ensembles)
    else:
        backends = [emcee.backends.Backend() for _ in range(n_ensembles)]
    samplers = [
        emcee.EnsembleSampler(nwalkers, ndim, log_post, vectorize=True, backend=b, moves=emcee.moves.DEMove())
        for b in backends
    ]

    z_map = None
    states: list[emcee.State] = []
    for k, s in enumerate(samplers):
        it = s.backend.iteration if backend_path is not None and s.backend.initialized else 0
        if it > 0:
            states.append(s.backend.get_last_sample())
            continue
        if z_map is None:
            z_map, ball = start_ball(log_post, prior, nwalkers=nwalkers, n_ensembles=n_ensembles, rng=rng_start)
        if backend_path is not None:
            s.backend.reset(nwalkers, ndim)
        rs = np.random.RandomState(np.random.default_rng(seeds[k]).integers(2**31))
        states.append(emcee.State(ball[k], random_state=rs.get_state()))
    if z_map is None:  # everything resumed: MAP only for the record
        z_map = start_ball(log_post, prior, nwalkers=nwalkers, n_ensembles=1, rng=rng_start)[0]

    converged = False
    prev_tau: np.ndarray | None = None
    # a resumed run whose stored chains end on a check point is checked before stepping, so that
    # resuming a finished run gives back the same draws instead of stepping one block further
    done0 = [s.backend.iteration for s in samplers]
    check_first = min(done0) > 0 and len(set(done0)) == 1 and done0[0] % check_every == 0
    while True:
        for k, s in enumerate(samplers):
            if check_first:
                break
            done = s.backend.iteration
            target = min(max_steps, (done // check_every + 1) * check_every)
            if target > done:
                states[k] = s.run_mcmc(states[k], target - done, progress=False, skip_initial_state_check=True)
        check_first = False
        n = min(s.backend.iteration for s in samplers)
        chains = np.concatenate([s.backend.get_chain()[:n] for s in samplers], axis=1)  # all walkers
        tau = integrated_time(chains)
        if prev_tau is None:  # first check (or first after resuming): previous check from the stored chain
            prev_tau = integrated_time(chains[: n - check_every]) if n >= 2 * check_every else np.full(ndim, np.inf)
        change = float(np.max(np.abs(prev_tau - tau) / tau))
        prev_tau = tau
        tau_max = float(np.max(tau))
        acc = float(np.mean([np.mean(s.backend.accepted) / max(s.backend.iteration, 1) for s in samplers]))
        if progress is not None:
            progress(Progress(n, max_steps, tau_max, change, n / tau_max, acc, time.perf_counter() - t_start))
        if n > settings.tau_factor * tau_max and change < settings.tau_rtol:
            converged = True
            break
        if n >= max_steps:
            warnings.warn(
                f"sampler stopped at max_steps={max_steps} before convergence: steps/tau = {n / tau_max:.1f} "
                f"(needs > {settings.tau_factor:g}), tau change {100 * change:.1f} % (needs < "
                f"{100 * settings.tau_rtol:g} %); raise max_steps or treat the posterior as approximate",
                ConvergenceWarning, stacklevel=2,
            )
            break

    taus = [integrated_time(s.backend.get_chain()[:n]) for s in samplers]
    tau_all = np.array(taus)
    burn = int(math.ceil(settings.burn_factor * tau_max))
    thin = max(1, int(settings.thin_factor * float(np.min(tau))))
    if burn >= n - 1:
        burn = n // 2
    zs = []
    for s in samplers:
        c = s.backend.get_chain()[:n][burn::thin]  # (nkeep, nwalkers, ndim)
        zs.append(np.transpose(c, (1, 0, 2)).reshape(-1, ndim))  # walker-major
    z = np.stack(zs)  # (chain, draw, ndim)
    theta = to_theta(z)
    flat = theta.reshape(-1, ndim)
    ll = np.concatenate([likelihood(flat[i:i + 8192]) for i in range(0, len(flat), 8192)]).reshape(z.shape[:2])
    lprior = prior.logpdf(flat).reshape(z.shape[:2])
    acceptance = np.array([np.asarray(s.backend.accepted)[:].mean() / s.backend.iteration for s in samplers])
    return PosteriorSamples(
        names=names,
        draws={nm: theta[..., i] for i, nm in enumerate(names)},
        log_likelihood=ll,
        log_prior=lprior,
        acceptance=acceptance,
        tau=tau_all,
        n_steps=n,
        burn=burn,
        thin=thin,
        converged=converged,
        seconds=time.perf_counter() - t_start,
        seed=seed,
        hoop=likelihood.has_hoop,
        nwalkers=nwalkers,
        map_estimate=dict(zip(names, map(float, to_theta(z_map)))),
        prior_path=priors.path,
        prior_description=prior.describe(),
        settings=settings,
    )
