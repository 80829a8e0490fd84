"""Stacking weights of competing models, and the rule that reads a verdict from them.

A comparison of models by the sum of their leave-one-out log predictive densities (dELPD +- SE)
answers "is A better than B?", one pair at a time, and its verdict flips when a difference sits near
the threshold. Stacking (Yao, Vehtari, Simpson, Gelman 2018, Bayesian Analysis 13:917) answers "which
mixture of the models predicts a left-out point best?": the weights w maximise
sum_i log sum_k w_k exp(elpd_ik) over the simplex. A model that predicts no point better than the
others gets no weight, whatever its count of parameters; two models that predict alike share it.
ArviZ's ``compare`` computes them.

With a handful of points (a campaign of ten tests) stacking is sure of itself: a model 1.4 +- 1.0
nats ahead can take all the weight, and which one does follows the Monte Carlo noise of the
leave-one-out densities. :func:`stacking_weights` therefore averages the stacking weights over
Bayesian-bootstrap replicates of the points (Dirichlet(1, ..., 1) weights on the points; Rubin 1981; each replicate solved by EM,
as ArviZ's BB-pseudo-BMA does for pseudo-BMA weights; Yao et al. 2018, section 3.4): models whose
difference is within its uncertainty share the weight, and a verdict read from it does not flip
with the sampler's seed. The unweighted optimum is ArviZ's (a test checks the two agree).

:class:`WeightRule` reads the verdict: the smallest set of models that carries at least ``mass`` of
the weight is what the data support (one model: it is named; several: they are not separated); a
model with less than ``little`` of the weight is one the data speak against.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .decision import RULE, DecisionRule


def _elpd_data(pointwise: np.ndarray, n_samples: int):
    import xarray as xr
    from arviz_stats.utils import ELPDData

    pw = np.asarray(pointwise, float)
    n = pw.size
    return ELPDData(elpd=float(pw.sum()), se=float(np.sqrt(n * np.var(pw))), p=0.0, n_samples=n_samples,
                    n_data_points=n, scale="log", warning=False, good_k=0.7,
                    elpd_i=xr.DataArray(pw, dims=["point"]), pareto_k=xr.DataArray(np.zeros(n), dims=["point"]))


def arviz_stacking(pointwise: Mapping[str, np.ndarray], *, n_samples: int = 1000) -> dict[str, float]:
    """ArviZ's stacking weights (``compare``, method "stacking") of the pointwise log predictive densities."""
    import arviz as az

    table = az.compare({k: _elpd_data(v, n_samples) for k, v in pointwise.items()}, method="stacking")
    return {k: float(table.loc[k, "weight"]) for k in pointwise}


def _stack(lpd: np.ndarray, point_weights: np.ndarray, *, tol: float = 1e-6, max_iter: int = 5000) -> np.ndarray:
    """argmax over the simplex of sum_i a_i log sum_k w_k exp(lpd_ik), for each row of ``point_weights``
    (B, n) at once: (B, K). The objective is concave in w and the EM update of mixture weights,
    w_k <- sum_i a_i r_ik / sum_i a_i with r_ik = w_k p_ik / sum_j w_j p_ij, climbs it monotonically to the
    optimum (Dempster, Laird, Rubin 1977)."""
    dens = np.exp(lpd - lpd.max(axis=1, keepdims=True))  # (n, K); a per-point factor changes no weight
    a = np.atleast_2d(point_weights)  # (B, n)
    w = np.full((a.shape[0], lpd.shape[1]), 1.0 / lpd.shape[1])
    for _ in range(max_iter):
        mix = w[:, None, :] * dens[None, :, :]  # (B, n, K)
        r = mix / mix.sum(axis=2, keepdims=True)
        new = np.einsum("bn,bnk->bk", a, r) / a.sum(axis=1, keepdims=True)
        if np.max(np.abs(new - w)) < tol:
            return new
        w = new
    return w


def stacking_weights(pointwise: Mapping[str, np.ndarray], *, bootstrap: int = 200, seed: int = 0) -> dict[str, float]:
    """Stacking weights averaged over ``bootstrap`` Bayesian-bootstrap replicates of the points (module
    docstring); ``bootstrap=0``: the plain stacking weights. The points are each model's pointwise
    leave-one-out log predictive densities (the same points, in the same order, for every model)."""
    names = list(pointwise)
    if len(names) == 1:
        return {names[0]: 1.0}
    lpd = np.column_stack([np.asarray(pointwise[k], float) for k in names])
    n = lpd.shape[0]
    if bootstrap <= 0:
        w = _stack(lpd, np.ones(n))[0]
    else:
        rng = np.random.default_rng(seed)
        w = _stack(lpd, n * rng.dirichlet(np.ones(n), size=bootstrap)).mean(axis=0)
    return {k: float(v) for k, v in zip(names, w)}


@dataclass(frozen=True)
class WeightRule:
    """What a set of stacking weights supports (module docstring)."""

    #: the share of the weight the supported set must carry
    mass: float = 0.9
    #: below this a model is one the data speak against
    little: float = 0.1

    def supported(self, weights: Mapping[str, float]) -> list[str]:
        """The fewest models, heaviest first, whose weights add up to at least ``mass``."""
        out, total = [], 0.0
        for name, w in sorted(weights.items(), key=lambda kv: -kv[1]):
            out.append(name)
            total += w
            if total >= self.mass - 1e-9:
                break
        return out

    def against(self, weights: Mapping[str, float]) -> list[str]:
        """The models with less than ``little`` of the weight."""
        return [k for k, w in weights.items() if w < self.little]

    def ruled_out(self, weight: float, d_elpd: float, d_se: float, *, n: int | None = None,
                  d_rest: float | None = None, rule: DecisionRule = RULE) -> bool:
        """Whether a model ``d_elpd`` +- ``d_se`` behind the best (over ``n`` paired points) is ruled out:
        decisively behind (``rule``); or more than ``rule.min_delpd`` behind even with the point that favours the
        best most left out (``d_rest``), while it and the models that predict alike with it (within
        ``min_delpd`` of its ELPD, themselves more than ``min_delpd`` behind the best) carry less than
        ``little`` of the weight (``weight``: their sum, which the caller forms).

        The paired SE treats the points as exchangeable draws. A campaign's tests are a design: the evidence
        against a law sits in the tests that reach where the laws part (the fastest, the longest slip), so over
        six tests the SE can be as large as the difference although the tests point the same way (slip-weakening
        walls: constant 17-27 +- 7-13 behind, weight 0.00). The second route asks instead that the difference
        not hang on one point (one bad record would otherwise decide it) and that stacking, averaged over
        Bayesian-bootstrap reweightings of the points, find no use for the model or its alike ones. Without
        ``d_rest`` (a result stored before it was recorded) only the first route is open. Below ``min_delpd`` the
        weight never rules a model out: among models that predict alike, which one stacking favours follows
        the sampler's bits.

        >>> r = WeightRule()
        >>> r.ruled_out(0.0, 21.7, 11.0, n=6, d_rest=13.0), r.ruled_out(0.2, 21.7, 11.0, n=6, d_rest=13.0)
        (True, False)
        >>> r.ruled_out(0.0, 21.7, 11.0, n=6, d_rest=2.0), r.ruled_out(0.0, 21.7, 11.0, n=6)
        (False, False)
        >>> r.ruled_out(0.5, 12.0, 1.0, n=6), r.ruled_out(0.0, 3.5, 0.5, n=6, d_rest=3.5)
        (True, False)
        """
        if rule.decisive(d_elpd, d_se, n=n):
            return True
        return d_rest is not None and weight < self.little and min(d_elpd, d_rest) > rule.min_delpd

    def alike_weight(self, weights: Mapping[str, float], behind: Mapping[str, float], name: str, *,
                     rule: DecisionRule = RULE) -> float:
        """The weight :meth:`ruled_out` reads for model ``name``: its own and that of every model that predicts
        alike with it (``behind``: each model's ELPD behind the best; alike: within ``rule.min_delpd`` of
        ``name``'s) and is itself more than ``rule.min_delpd`` behind the best. Twins split the weight stacking
        would give one of them, so each alone may look light; a model close to the best lends none to a far one.

        >>> b = {"best": 0.0, "close": 3.0, "a": 20.0, "a2": 21.0, "far": 30.0}
        >>> w = {"best": 0.57, "close": 0.3, "a": 0.06, "a2": 0.06, "far": 0.01}
        >>> round(WeightRule().alike_weight(w, b, "a"), 2), round(WeightRule().alike_weight(w, b, "far"), 2)
        (0.12, 0.01)
        """
        me = behind[name]
        return float(sum(weights.get(o, 0.0) for o, d in behind.items()
                         if abs(d - me) <= rule.min_delpd and d > rule.min_delpd))
