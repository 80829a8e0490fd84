"""The sampling loop: emcee with several independent ensembles, stopping rule, checkpoints, draws."""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import emcee
import numpy as np

from ..errors import PriorError, SamplingError
from ..likelihood import Likelihood
from ..priors import Priors
from ..stats.streams import legacy_state
from ..window import StationaryData
from . import checkpoint
from .model import LogPosterior, start_ball
from .moves import BlockDEMove
from .results import ConvergenceWarning, PosteriorSamples, Progress, SamplerSettings


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


@contextlib.contextmanager
def _interrupt_between_steps() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) while emcee steps and raise KeyboardInterrupt when the block of steps ends: emcee's
    wrapper of the log-probability prints the walkers' positions and a traceback for any exception raised in
    it, KeyboardInterrupt included. Only in the main thread (elsewhere signals cannot be handled), and not where
    SIGINT is ignored (a background job of a shell: Ctrl-C is not meant for it, and catching it during the steps
    only would stop the job at some moments and not at others)."""
    if threading.current_thread() is not threading.main_thread() or signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        yield
        return
    caught: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old if old is not None else signal.default_int_handler)
    if caught:
        raise KeyboardInterrupt


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
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**64:
        raise SamplingError(f"seed must be an integer in [0, 2**64), got {seed!r}")
    if nwalkers < 4 or nwalkers % 2:
        raise SamplingError(f"nwalkers must be an even number >= 4, got {nwalkers}")
    if n_ensembles < 1 or max_steps < check_every or check_every < 10:
        raise SamplingError(
            f"need n_ensembles >= 1, check_every >= 10 and max_steps >= check_every; got {n_ensembles}, "
            f"{check_every}, {max_steps}"
        )
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
    n_all = nwalkers * n_ensembles
    seeds = np.random.SeedSequence(seed).spawn(2)
    rng_start = np.random.default_rng(seeds[1])

    fp = checkpoint.fingerprint(data, prior, names, seed, settings) if backend_path is not None else ""
    ck = (checkpoint.load(backend_path, fp, nwalkers=n_all, ndim=ndim, notify=notify)
          if backend_path is not None else None)
    move = BlockDEMove(n_ensembles)
    if ck is not None:
        backend = _memory_backend(ck, n_all, ndim)
        state = backend.get_last_sample()
        z_map = start_ball(log_post, prior, nwalkers=nwalkers, n_ensembles=1, rng=rng_start)[0]  # for the record
    else:
        backend = emcee.backends.Backend()
        z_map, ball = start_ball(log_post, prior, nwalkers=nwalkers, n_ensembles=n_ensembles, rng=rng_start)
        rs = legacy_state(np.random.default_rng(seeds[0]))
        state = emcee.State(ball.reshape(n_all, ndim), random_state=rs.get_state())
    sampler = emcee.EnsembleSampler(n_all, ndim, log_post, vectorize=True, backend=backend, moves=move)

    def save() -> None:
        checkpoint.save(backend_path, fp, checkpoint.Checkpoint(
            backend.get_chain(), backend.get_log_prob(), np.asarray(backend.accepted, float),
            backend.random_state))

    converged = False
    prev_tau: np.ndarray | None = None
    last_save = time.perf_counter()
    # a resumed run whose stored chain ends on a check point is checked before stepping, so that
    # resuming a finished run gives back the same draws instead of stepping one block further
    check_first = backend.iteration > 0 and backend.iteration % check_every == 0
    try:
        while True:
            done = backend.iteration
            target = min(max_steps, (done // check_every + 1) * check_every)
            if not check_first and target > done:
                with _interrupt_between_steps():
                    state = sampler.run_mcmc(state, target - done, progress=False, skip_initial_state_check=True)
                if backend_path is not None and time.perf_counter() - last_save >= checkpoint_seconds:
                    save()
                    last_save = time.perf_counter()
            check_first = False
            n = backend.iteration
            chains = backend.get_chain()  # (n, all walkers, ndim)
            tau = integrated_time(chains)
            if prev_tau is None:  # first check (or first after resuming): previous check from the stored chain
                prev_tau = integrated_time(chains[: n - check_every]) if n >= 2 * check_every else np.full(ndim, np.inf)
            change = float(np.max(np.abs(prev_tau - tau) / tau))
            prev_tau = tau
            tau_max = float(np.max(tau))
            acc = float(np.mean(backend.accepted) / max(n, 1))
            if progress is not None:
                progress(Progress(n, max_steps, tau_max, change, n / tau_max, acc, time.perf_counter() - t_start,
                                  settings.tau_factor, settings.tau_rtol))
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
    except KeyboardInterrupt:  # Ctrl-C: the steps made so far are kept, the next run resumes from them
        if backend_path is not None and backend.iteration > 0:
            save()
        raise
    if backend_path is not None:
        save()  # a run killed while its outputs are written resumes here without stepping

    chain = backend.get_chain()  # (n, all walkers, ndim)
    blocks = [slice(k * nwalkers, (k + 1) * nwalkers) for k in range(n_ensembles)]
    tau_all = np.array([integrated_time(chain[:, b]) for b in blocks])
    burn = int(math.ceil(settings.burn_factor * tau_max))
    if burn >= n - 1:
        burn = n // 2
    # thin to tau/2, and further so that at most max_draws draws are kept (the pointwise
    # log-likelihood of every kept draw is stored; thinned beyond tau the draws are nearly
    # independent, so ESS ~ max_draws)
    thin = max(1, int(settings.thin_factor * float(np.min(tau))),
               math.ceil((n - burn) * n_all / settings.max_draws))
    kept = chain[burn::thin]  # (nkeep, all walkers, ndim)
    z = np.stack([np.transpose(kept[:, b], (1, 0, 2)).reshape(-1, ndim) for b in blocks])  # walker-major chains
    theta = log_post.to_theta(z)
    flat = theta.reshape(-1, ndim)
    ll = np.concatenate([likelihood(flat[i:i + 8192]) for i in range(0, len(flat), 8192)]).reshape(z.shape[:2])
    lprior = prior.logpdf(flat).reshape(z.shape[:2])
    accepted = np.asarray(backend.accepted, float)
    acceptance = np.array([accepted[b].mean() / n for b in blocks])
    return PosteriorSamples(
        names=names,
        draws=likelihood.parameters.as_dict(theta),
        log_likelihood=ll,
        log_prior=lprior,
        acceptance=acceptance,
        tau=tau_all,
        n_steps=n,
        burn=burn,
        thin=thin,
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
