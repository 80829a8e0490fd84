"""Posterior sampling of (f, nu[, hoop_gain]) with emcee.

Modules: :mod:`.log_posterior` (parametrisation, log posterior, start ball), :mod:`.moves` (the
differential-evolution move inside independent ensembles), :mod:`.ensemble` (settings, start,
draws), :mod:`.stopping_rule` (the loop of steps and its stopping rule), :mod:`.checkpoint` (saving and resuming),
:mod:`.results` (what is returned).

Design
------
* **Parametrisation.** emcee runs in the unbounded coordinates z that the likelihood's model
  declares for its named parameters (:class:`~friction_uq.models.ParameterSet`); nothing here
  knows a column. The closed form declares z = (log f, log(nu/(1-nu)), log g): there the force
  data fix log f + log(nu/(1-nu)) = log kappa, the f-nu ridge of eq. 17 is a straight line, which
  the affine-invariant ensemble moves follow without loss (in (f, nu) it is a curve). The
  log-density in z includes the transforms' log Jacobian. Draws are returned by name.
* **Move.** Differential evolution (``emcee.moves.DEMove``): on these near-Gaussian posteriors it
  gives tau ~ 8-10 steps against 28-40 for the default stretch move at the same cost per step
  (measured on the paper's case, 32 walkers, with and without the hoop term).
* **Independent ensembles.** R-hat across the walkers of one ensemble is not an independent-chain
  diagnostic (emcee#183): ``n_ensembles`` (4) ensembles start from independent balls and never
  interact (:class:`~.moves.BlockDEMove` draws each walker's partners from its own ensemble), and
  each is one *chain* of the result, so R-hat compares independent runs. They are stepped as one
  emcee ensemble of ``n_ensembles * nwalkers`` walkers, so that one vectorised call of the
  likelihood (whose cost hardly grows up to ~128 rows) serves all of them.
* **Stopping.** Every ``check_every`` steps (absolute step counts, so a resumed run checks at the
  same steps as an uninterrupted one) the integrated autocorrelation time tau is estimated per
  parameter, with the autocorrelation averaged over the walkers of all ensembles (same target and
  kernel, so pooling only lowers the estimator's noise); the run stops when, for every parameter,
  the chain is longer than ``tau_factor`` (50) tau and tau changed by less than ``tau_rtol``
  (5 %) since the previous check. (1 % chased the estimator's own noise: on a bundled record tau moved by
  1-4 % from check to check between steps 600 and 1200 while it drifted from 9.0 to 10.1, and the run
  took twice the steps for the same ESS, 3800 of f.) At ``max_steps`` it stops anyway with a
  :class:`ConvergenceWarning` and ``converged=False`` in the result.
* **Draws.** burn-in 3 max(tau), thinning max(1, tau_min / 2), coarser where needed to keep at
  most ``max_draws`` (4000) draws. A chain's draws are its walkers' thinned sequences one after
  the other (walker-major), so autocorrelation along ``draw`` is the walkers' own and ArviZ's ESS
  is not inflated by interleaving walkers.
* **Resuming.** With ``backend_path`` the chain is sampled in memory and saved, with the random
  state, at a convergence check when ``checkpoint_seconds`` (2 s) have passed since the last save,
  and when sampling ends (:mod:`.checkpoint`; saving every step cost about half the sampling
  time). Calling again with the same path and arguments continues from the saved step: the
  result equals an uninterrupted run. A file written for other data, priors, seed or settings, or
  one that cannot be read, is removed with a one-line notice and sampling starts afresh.
* **Start.** A small Gaussian ball (a tenth of the Laplace-approximation sd) around the maximum a
  posteriori in z, every walker inside the prior support.
"""

from .ensemble import likelihood_priors, sample_posterior
from .stopping_rule import integrated_time
from .log_posterior import LogPosterior, _initial_guess, start_ball
from .moves import BlockDEMove
from .results import ConvergenceWarning, PosteriorSamples, Progress, SamplerSettings, stderr_progress

__all__ = [
    "BlockDEMove", "ConvergenceWarning", "LogPosterior", "PosteriorSamples", "Progress", "SamplerSettings",
    "_initial_guess", "integrated_time", "likelihood_priors", "sample_posterior", "start_ball", "stderr_progress",
]
