"""How long a friction law's emcee chain runs (:class:`~.laws.Fit`): on from its first length until the part kept
is :data:`TAU_MULTIPLE` autocorrelation times long, up to :data:`MAX_STEPS` (docs/campaigns.md, "Sampling the
laws")."""

from __future__ import annotations

import warnings

import numpy as np

from ..sampler import integrated_time

#: A law fit's chain runs on until its kept part is this many autocorrelation times long: emcee's own
#: criterion for a reliable estimate of the time itself (its ``tol``). Measured on the bundled campaign
#: (docs/validation.md): pressure+velocity's time is 170-210 steps where a chain of 1000 steps estimated 40-60,
#: and its leave-one-test-out ELPD moved with the fit's seed by 0.55 (sd) at 1000 steps, 0.15 at 2500 and 0.03
#: at 5000, enough at 1000 to move a set-up's flag across its 4-nat line.
TAU_MULTIPLE = 50
#: steps added at a time, and the longest chain: the cost's bound (most laws reach it: 14-35 times their time;
#: at 4000 the flag's dELPD still moved by 0.2 between fit seeds, at 6000 by 0.1)
STEP_BLOCK = 1000
MAX_STEPS = 6000
#: the steps discarded: at least the caller's burn-in, and this many autocorrelation times (the start
#: forgotten: the walkers begin in a small ball at the mode)
BURN_TAUS = 5
#: most draws kept from a chain (thinned evenly, at least every THIN-th step): PSIS-LOO's own error falls with
#: the draws (thinned to 4480, an 8000-step chain's ELPD moved by 0.25), so at MAX_STEPS none is thinned further
KEPT_DRAWS = 40000
THIN = 5


def max_autocorr_time(chain: np.ndarray) -> float:
    """The largest integrated autocorrelation time (steps) over the parameters of an emcee chain (steps,
    walkers, parameters), by the package's estimator (:func:`friction_uq.sampler.integrated_time`, emcee's),
    without a length check (the caller decides what is long enough); a parameter that never moves is left out;
    NaN for a chain too short to estimate it."""
    if len(chain) < 2:
        return float("nan")
    with warnings.catch_warnings():  # a still parameter: its autocorrelation is 0/0 in every walker
        warnings.simplefilter("ignore", RuntimeWarning)
        tau = integrated_time(chain)
    return float(np.nanmax(tau)) if np.isfinite(tau).any() else float("nan")


def chain_length_needed(tau: float, burn: int) -> tuple[int, int]:
    """The chain's length and discard for an autocorrelation time ``tau``: ``burn`` or :data:`BURN_TAUS` tau
    discarded, then :data:`TAU_MULTIPLE` tau kept; a time not estimated (NaN) asks for nothing more.

    >>> chain_length_needed(20.0, 300), chain_length_needed(100.0, 300)
    ((1300, 300), (5500, 500))
    """
    if not np.isfinite(tau):
        return 0, burn
    discard = max(burn, int(np.ceil(BURN_TAUS * tau)))
    return discard + int(np.ceil(TAU_MULTIPLE * tau)), discard
