"""What the sampler returns and reports: settings, progress lines, posterior draws."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np


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
    tau_factor: float  # the stopping rule's steps/tau and relative tau change (SamplerSettings)
    tau_rtol: float

    @property
    def done(self) -> bool:
        """The stopping rule is met: steps > tau_factor tau and tau steady within tau_rtol."""
        return self.steps_over_tau > self.tau_factor and self.tau_change < self.tau_rtol

    def line(self) -> str:
        """A short line for a terminal: how far along what the stopping rule needs (not the step cap)."""
        if self.done:
            return (f"sampling: done at step {self.steps} (tau {self.tau_max:.1f}, steady within "
                    f"{100 * self.tau_change:.1f} %), acceptance {self.acceptance:.2f}, {self.seconds:.1f} s")
        need = min(self.max_steps, int(math.ceil(self.tau_factor * self.tau_max))) if math.isfinite(self.tau_max) \
            else self.max_steps
        share = min(1.0, self.steps / max(need, 1))
        steady = ("steady" if self.tau_change < self.tau_rtol else f"still moving {100 * self.tau_change:.0f} %"
                  if math.isfinite(self.tau_change) else "not yet measured twice")
        if self.steps >= need and need < self.max_steps:  # long enough; the rule waits for tau to settle
            return (f"sampling: {self.steps} steps, more than {self.tau_factor:g} tau ({need}); waiting for tau "
                    f"{self.tau_max:.1f} to settle (still moving {100 * self.tau_change:.1f} %, needs < "
                    f"{100 * self.tau_rtol:g} %), acceptance {self.acceptance:.2f}, {self.seconds:.1f} s")
        return (f"sampling: {100 * share:.0f} % of the steps the stopping rule needs ({self.steps} of ~{need}, "
                f"tau {self.tau_max:.1f} {steady}), acceptance {self.acceptance:.2f}, {self.seconds:.1f} s")


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
    checkpoint_seconds: float = 2.0
    tau_factor: float = 50.0
    tau_rtol: float = 0.05
    burn_factor: float = 3.0
    thin_factor: float = 0.5
    max_draws: int = 4000


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
