"""The stopping rule of the sampling loop: emcee steps in blocks, the integrated autocorrelation time measured at
the end of each, until the chain is long enough against it and it is steady (``SamplerSettings.tau_factor``,
``tau_rtol``), or the step cap is reached."""

from __future__ import annotations

import contextlib
import signal
import threading
import time
import warnings
from collections.abc import Callable, Iterator

import emcee
import numpy as np

from .checkpoint import Store
from .results import ConvergenceWarning, Progress, SamplerSettings


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


def run_until_steady(sampler: emcee.EnsembleSampler, state: emcee.State, settings: SamplerSettings, store: Store,
                      progress: Callable[[Progress], None] | None, t_start: float) -> tuple[bool, np.ndarray]:
    """Step in blocks of ``check_every`` until the stopping rule holds (steps > tau_factor tau, tau steady within
    tau_rtol) or ``max_steps`` (a :class:`ConvergenceWarning`), checkpointing at most every
    ``checkpoint_seconds`` and at the end; Ctrl-C keeps the steps made. Returns (converged, each parameter's tau
    over all walkers at the last check, which is the chain's end)."""
    backend, every = sampler.backend, settings.check_every
    prev_tau: np.ndarray | None = None
    # a resumed run whose stored chain ends on a check point is checked before stepping, so that
    # resuming a finished run gives back the same draws instead of stepping one block further
    check_first = backend.iteration > 0 and backend.iteration % every == 0
    store.last = time.perf_counter()
    try:
        while True:
            done = backend.iteration
            target = min(settings.max_steps, (done // every + 1) * every)
            if not check_first and target > done:
                with _interrupt_between_steps():
                    state = sampler.run_mcmc(state, target - done, progress=False, skip_initial_state_check=True)
                if time.perf_counter() - store.last >= settings.checkpoint_seconds:
                    store.write(backend)
            check_first = False
            n = backend.iteration
            chains = backend.get_chain()  # (n, all walkers, ndim)
            tau = integrated_time(chains)
            if prev_tau is None:  # first check (or first after resuming): previous check from the stored chain
                prev_tau = integrated_time(chains[: n - every]) if n >= 2 * every else np.full(len(tau), np.inf)
            change = float(np.max(np.abs(prev_tau - tau) / tau))
            prev_tau = tau
            tau_max = float(np.max(tau))
            if progress is not None:
                acc = float(np.mean(backend.accepted) / max(n, 1))
                progress(Progress(n, settings.max_steps, tau_max, change, n / tau_max, acc,
                                  time.perf_counter() - t_start, settings.tau_factor, settings.tau_rtol))
            converged = n > settings.tau_factor * tau_max and change < settings.tau_rtol
            if converged:
                break
            if n >= settings.max_steps:
                warnings.warn(
                    f"sampler stopped at max_steps={settings.max_steps} before convergence: steps/tau = "
                    f"{n / tau_max:.1f} (needs > {settings.tau_factor:g}), tau change {100 * change:.1f} % (needs < "
                    f"{100 * settings.tau_rtol:g} %); raise max_steps or treat the posterior as approximate",
                    ConvergenceWarning, stacklevel=3,
                )
                break
    except KeyboardInterrupt:  # Ctrl-C: the steps made so far are kept, the next run resumes from them
        if backend.iteration > 0:
            store.write(backend)
        raise
    store.write(backend)  # a run killed while its outputs are written resumes here without stepping
    return converged, tau
