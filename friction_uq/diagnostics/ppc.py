"""Posterior predictive check of the force ratio F_eo/F_io over the stationary window.

The check asks whether the ratio is *stationary*: whether its 10 us-smoothed course wanders about
the window's level by more than the gauges' noise makes a replicate wander about its own. Each
replicate (a posterior draw of r, the latent force, AR(1) noise and offsets on both forces) is
centred on its own level (its mean F_eo over its mean F_io) and the band is placed on the observed
level. The level itself is what the likelihood fits; with a likelihood by levels
(:mod:`friction_uq.likelihood.force_level`) its uncertainty widens when the window wanders, and a
band that carried that uncertainty would hide the very wandering the check is for.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from ..likelihood import Likelihood
from ..sampler import PosteriorSamples
from ..window import StationaryData
from .convergence import QUANTILES


@dataclass(frozen=True)
class RatioPPC:
    """Posterior predictive of F_eo/F_io over the window, both smoothed over ``smooth`` seconds.

    Attributes
    ----------
    time : array, shape (n,)  (s)
    observed : array, shape (n,)
        Smoothed observed ratio.
    replicated : array, shape (n_draws, n)
        Smoothed ratio of replicated data (model ratio + AR(1) noise on both forces).
    q05, q50, q95 : array, shape (n,)
        Pointwise quantiles of ``replicated``, each replicate centred on its own level and the band
        placed on the observed level (module docstring).
    model_q05, model_q95 : float
        90 % interval of the noise-free model ratio r.
    coverage : float
        Fraction of times where ``observed`` lies inside [q05, q95].
    """

    time: np.ndarray
    observed: np.ndarray
    replicated: np.ndarray
    q05: np.ndarray
    q50: np.ndarray
    q95: np.ndarray
    model_q05: float
    model_q95: float
    coverage: float
    smooth: float


def _smooth_ratio(F_eo: np.ndarray, F_io: np.ndarray, width: int) -> np.ndarray:
    num = uniform_filter1d(F_eo, width, axis=-1, mode="nearest")
    den = uniform_filter1d(F_io, width, axis=-1, mode="nearest")
    return num / den


def ratio_ppc(
    samples: PosteriorSamples, data: StationaryData, *, seed: int, n_draws: int = 200, smooth: float = 10e-6,
    likelihood: Likelihood | None = None,
) -> RatioPPC:
    """Posterior predictive check of the force ratio (see :class:`RatioPPC`); ``likelihood``: the
    analysis' (its forces are replicated; None: a force-only one is built)."""
    rng = np.random.default_rng(seed)
    lk = likelihood if likelihood is not None else Likelihood(data, hoop=False)
    n_all = samples.n_chains * samples.n_draws
    idx = rng.choice(n_all, size=min(n_draws, n_all), replace=False)
    pick = lk.parameters.vector({n: samples.flat(n)[idx] for n in lk.names})
    rep = lk.simulate(pick, rng=rng, hoop=False)
    width = max(1, int(round(smooth * data.sample_rate)))
    replicated = _smooth_ratio(rep["F_eo"], rep["F_io"], width)
    F_eo, F_io = np.asarray(data.F_eo, float), np.asarray(data.F_io, float)
    observed = _smooth_ratio(F_eo, F_io, width)
    level_rep = rep["F_eo"].mean(axis=-1) / rep["F_io"].mean(axis=-1)
    q = np.quantile(replicated - level_rep[:, None], QUANTILES, axis=0) + float(F_eo.mean() / F_io.mean())
    r = lk.model.ratio(samples.draws)
    mq = np.quantile(r, [0.05, 0.95])
    inside = (observed >= q[0]) & (observed <= q[2])
    return RatioPPC(np.asarray(data.time), observed, replicated, q[0], q[1], q[2], float(mq[0]), float(mq[1]),
                    float(inside.mean()), smooth)
