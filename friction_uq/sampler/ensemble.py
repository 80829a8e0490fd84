"""The sampling call: emcee with several independent ensembles, from the checked settings and the start to the kept
draws (the loop of steps and its stopping rule: :mod:`.stopping_rule`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import emcee
import numpy as np

from ..errors import PriorError, SamplingError
from ..likelihood import Likelihood
from ..priors import Priors
from ..stats.streams import legacy_state
from ..window import StationaryData
from . import checkpoint
from .log_posterior import LogPosterior, start_ball
from .moves import BlockDEMove
from .results import PosteriorSamples, Progress, SamplerSettings
from .stopping_rule import integrated_time, run_until_steady


def _memory_backend(ck: checkpoint.Checkpoint, nwalkers: int, ndim: int) -> emcee.backends.Backend:
    """An in-memory emcee backend holding a checkpoint's chain (to continue from its last step)."""
    b = emcee.backends.Backend()
    b.reset(nwalkers, ndim)
    b.grow(ck.iteration, None)
    b.chain[:] = ck.chain
    b.log_prob[:] = ck.log_prob
    b.accepted[:] = ck.accepted
    b.iteration = ck.iteration
    b.random_state = ck.random_state
    return b


def likelihood_priors(likelihood: Likelihood, priors: Priors) -> Priors:
    """The priors of the likelihood's parameters, in its order; :class:`PriorError` (naming the file and the missing
    parameter) if the prior file lacks one: checked before any work."""
    try:
        return priors.subset(likelihood.names)
    except PriorError as exc:
        raise PriorError(f"{exc} (the {'hoop' if likelihood.has_hoop else 'force'} likelihood needs "
                         f"{', '.join(likelihood.names)})") from exc


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
    checkpoint_seconds: float = 2.0,
    notify: Callable[[str], None] | None = None,
    axial_poisson: bool = True,
    likelihood: Likelihood | None = None,
) -> PosteriorSamples:
    """Sample the posterior of (f, nu[, hoop_gain]) for one stationary phase.

    Parameters
    ----------
    data : StationaryData
        The stationary phase (forces in N, hoop strain, noise estimates).
    priors : Priors
        Must define f, nu and, with the hoop term, hoop_gain.
    seed : int
        Seed of everything random (start ball and the ensembles' stream), 0 <= seed < 2**64.
    hoop : bool or None
        Use the hoop-gauge term; None: when the data have a hoop channel.
    backend_path : path or None
        Checkpoint file (:mod:`friction_uq.sampler.checkpoint`): saved at a convergence check at
        most every ``checkpoint_seconds`` and when sampling ends; an existing file of the same
        call is resumed, one of another call (or unreadable) is removed with a notice.
    progress : callable or None
        Called with a :class:`Progress` every ``check_every`` steps (e.g. :func:`stderr_progress`).
    max_steps : int
        Cap on steps per walker.
    nwalkers, n_ensembles, check_every : int
        Walkers per ensemble, independent ensembles (= chains), steps between convergence checks.
    checkpoint_seconds : float
        Least time between two checkpoints (0: at every check).
    notify : callable or None
        Receives one-line notices (a checkpoint set aside).
    axial_poisson : bool
        Include the tube's axial Poisson term in the hoop prediction.
    likelihood : Likelihood or None
        The analysis' likelihood over ``data``, built once by the caller; None: built here from
        ``hoop`` and ``axial_poisson``.

    Returns
    -------
    PosteriorSamples

    Raises
    ------
    PriorError
        If ``priors`` lacks a parameter the likelihood needs.
    SamplingError
        If the seed or a setting is out of range, or no walker start inside the prior support is
        found.
    """
    t_start = time.perf_counter()
    settings = SamplerSettings(nwalkers=nwalkers, n_ensembles=n_ensembles, max_steps=max_steps,
                               check_every=check_every, checkpoint_seconds=checkpoint_seconds)
    _check_settings(seed, settings)
    if likelihood is None:
        likelihood = Likelihood(data, hoop=hoop, axial_poisson=axial_poisson)
    elif likelihood.data is not data or (hoop is not None and bool(hoop) != likelihood.has_hoop):
        raise SamplingError(f"the likelihood given is over other data or has the hoop term "
                            f"{'on' if likelihood.has_hoop else 'off'} against hoop={hoop}")
    names = likelihood.names
    prior = likelihood_priors(likelihood, priors)
    log_post = LogPosterior(likelihood, prior)
    ndim = len(names)
    if nwalkers < 2 * ndim:
        raise SamplingError(f"nwalkers must be >= {2 * ndim} for {ndim} parameters, got {nwalkers}")
    fp = checkpoint.fingerprint(data, prior, names, seed, settings) if backend_path is not None else ""
    store = checkpoint.Store(backend_path, fp)
    backend, state, z_map = _start(log_post, prior, settings, ndim, seed, store, notify)
    sampler = emcee.EnsembleSampler(nwalkers * n_ensembles, ndim, log_post, vectorize=True, backend=backend,
                                    moves=BlockDEMove(n_ensembles))
    converged, tau = run_until_steady(sampler, state, settings, store, progress, t_start)
    draws = _kept_draws(backend.get_chain(), settings, tau, log_post)
    flat = draws.theta.reshape(-1, ndim)
    ll = np.concatenate([likelihood(flat[i:i + 8192]) for i in range(0, len(flat), 8192)]).reshape(draws.shape)
    lprior = prior.logpdf(flat).reshape(draws.shape)
    n = backend.iteration
    accepted = np.asarray(backend.accepted, float)
    acceptance = np.array([accepted[b].mean() / n for b in _blocks(settings)])
    return PosteriorSamples(
        names=names,
        draws=likelihood.parameters.as_dict(draws.theta),
        log_likelihood=ll,
        log_prior=lprior,
        acceptance=acceptance,
        tau=draws.tau,
        n_steps=n,
        burn=draws.burn,
        thin=draws.thin,
        converged=converged,
        seconds=time.perf_counter() - t_start,
        seed=int(seed),
        hoop=likelihood.has_hoop,
        nwalkers=nwalkers,
        map_estimate={n: float(v) for n, v in likelihood.parameters.as_dict(log_post.to_theta(z_map)).items()},
        prior_path=priors.path,
        prior_description=prior.describe(),
        settings=settings,
    )


def _check_settings(seed: int, settings: SamplerSettings) -> None:
    """:class:`SamplingError` for a seed or a setting out of range, before any work."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**64:
        raise SamplingError(f"seed must be an integer in [0, 2**64), got {seed!r}")
    if settings.nwalkers < 4 or settings.nwalkers % 2:
        raise SamplingError(f"nwalkers must be an even number >= 4, got {settings.nwalkers}")
    if settings.n_ensembles < 1 or settings.max_steps < settings.check_every or settings.check_every < 10:
        raise SamplingError(
            f"need n_ensembles >= 1, check_every >= 10 and max_steps >= check_every; got {settings.n_ensembles}, "
            f"{settings.check_every}, {settings.max_steps}"
        )


def _blocks(settings: SamplerSettings) -> list[slice]:
    """The walkers of each independent ensemble (one chain each) among all the sampler's walkers."""
    return [slice(k * settings.nwalkers, (k + 1) * settings.nwalkers) for k in range(settings.n_ensembles)]


def _start(log_post: LogPosterior, prior, settings: SamplerSettings, ndim: int, seed: int, store: checkpoint.Store,
           notify: Callable[[str], None] | None) -> tuple[emcee.backends.Backend, emcee.State, np.ndarray]:
    """The backend and the state to step from: a stored checkpoint of the same call resumed, else a fresh ball
    around the mode (the "start" stream of ``seed``; the ensembles' own stream is its sibling); and the mode."""
    n_all = settings.nwalkers * settings.n_ensembles
    seeds = np.random.SeedSequence(seed).spawn(2)
    rng_start = np.random.default_rng(seeds[1])
    ck = (checkpoint.load(store.path, store.fingerprint, nwalkers=n_all, ndim=ndim, notify=notify)
          if store.path is not None else None)
    if ck is not None:
        backend = _memory_backend(ck, n_all, ndim)
        z_map = start_ball(log_post, prior, nwalkers=settings.nwalkers, n_ensembles=1, rng=rng_start)[0]  # reported
        return backend, backend.get_last_sample(), z_map
    z_map, ball = start_ball(log_post, prior, nwalkers=settings.nwalkers, n_ensembles=settings.n_ensembles,
                             rng=rng_start)
    rs = legacy_state(np.random.default_rng(seeds[0]))
    return emcee.backends.Backend(), emcee.State(ball.reshape(n_all, ndim), random_state=rs.get_state()), z_map


@dataclass(frozen=True)
class _Draws:
    """The kept draws, per chain (one chain per ensemble, walker-major), and how they were kept."""

    theta: np.ndarray  # (chains, draws, ndim), the parameters' own coordinates
    tau: np.ndarray  # (chains, ndim), each ensemble's integrated time
    burn: int
    thin: int

    @property
    def shape(self) -> tuple[int, int]:
        return self.theta.shape[:2]


def _kept_draws(chain: np.ndarray, settings: SamplerSettings, tau: np.ndarray, log_post: LogPosterior) -> _Draws:
    """``tau``: each parameter's integrated time over all walkers. Burn-in of ``burn_factor`` tau dropped (half
    the chain if that is all of it), thinned to tau/2 and further so that at most ``max_draws`` draws are kept
    (the pointwise log-likelihood of every kept draw is stored; thinned beyond tau the draws are nearly
    independent, so ESS ~ max_draws)."""
    n, n_all, ndim = chain.shape
    blocks = _blocks(settings)
    tau_all = np.array([integrated_time(chain[:, b]) for b in blocks])
    burn = int(math.ceil(settings.burn_factor * float(np.max(tau))))
    if burn >= n - 1:
        burn = n // 2
    thin = max(1, int(settings.thin_factor * float(np.min(tau))),
               math.ceil((n - burn) * n_all / settings.max_draws))
    kept = chain[burn::thin]  # (nkeep, all walkers, ndim)
    z = np.stack([np.transpose(kept[:, b], (1, 0, 2)).reshape(-1, ndim) for b in blocks])  # walker-major chains
    return _Draws(log_post.to_theta(z), tau_all, burn, thin)
