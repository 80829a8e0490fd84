"""The prior of f_effective under an extended model, the prior its draws were made under: a campaign
that pools f under each test's diagnosed model divides it out (friction_uq.campaigns.pooling).

A model's draws are of the base f (under the prior file's f prior), nu, the sample's modulus and the
mechanisms' parameters theta (each under its own prior, :mod:`.mechanisms`), all independent;
f_effective = g(f, theta) is the wall's coefficient at the stationary window (:mod:`.extended`).

* Where every mechanism of the model leaves f as it is (all but the friction laws), f_effective = f
  and its prior is the prior file's f prior, evaluated exactly.
* Otherwise its prior is the push-forward of the joint prior through g,
  pi(y) = E_theta[ density at y of g(f, theta), f ~ pi_f ], computed conditionally on theta: g is
  nondecreasing in f (a convex combination of f and f_s, or f less tau/p0 clamped at 0), so the f
  prior's mass between two points of a fine grid (:data:`GRID`, exact from its CDF) lands evenly
  between their images. The expectation over theta is a mean over :data:`THETA_DRAWS` scrambled
  Sobol points mapped through the priors' quantile functions (seeded: same seed, same bits). The
  relative error is below 1 % (tests/test_effective_prior.py: against quadrature for the pressure
  law, against 10^6 prior draws for the velocity law).

A clamp (pressure_friction's f_effective = 0 when tau/p0 > f) puts an atom of prior mass at 0 that
the density leaves out: a draw there has density 0 (log -inf), which pooling refuses to divide by.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.stats import qmc

from .mechanisms import Context

#: Points of the f grid, from the f prior's 1e-9 to its 1 - 1e-9 quantile.
GRID = 1025
#: Sobol points (a power of two) over the mechanisms' parameters.
THETA_DRAWS = 4096
#: What the stored log prior is, as the netCDF's attribute says it.
EXACT_NOTE = "the prior file's f prior: every mechanism of this model leaves f as it is (f_effective = f)"
PUSHED_NOTE = ("the prior of f_effective implied by the prior file's f prior and the mechanisms' priors (push-forward "
               f"through f_effective, conditionally on the mechanisms' parameters, over {THETA_DRAWS} Sobol points)")


def _compose(variants: Sequence[Any], values: dict[str, Any], context: Context) -> Any:
    """g(f, theta): f through each mechanism's f_effective in the model's order (extended.Diagnoser)."""
    f = values["f"]
    for v in variants:
        f = v.mechanism.f_effective({**values, "f": f}, context)
    return f


def _theta(variants: Sequence[Any], rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Draws of every mechanism parameter of the model from its prior, (THETA_DRAWS, 1) each."""
    params = [(p.name, v.mechanism.priors[p.name]) for v in variants for p in v.mechanism.parameters]
    if not params:
        return {}
    u = qmc.Sobol(len(params), scramble=True, seed=rng).random_base2(int(np.log2(THETA_DRAWS)))
    u = np.clip(u, 1e-12, 1.0 - 1e-12)
    return {name: np.asarray(prior.ppf(u[:, j]), float)[:, None] for j, (name, prior) in enumerate(params)}


def log_prior_f_effective(variants: Sequence[Any], context: Context, f_prior: Any, y: np.ndarray, *,
                          rng: np.random.Generator) -> tuple[np.ndarray, str]:
    """log pi(y) of f_effective under a model (its ``variants``: extended.Variant) at the draws ``y``, and what
    that prior is in words (module docstring). ``f_prior``: the prior file's f prior
    (:class:`~friction_uq.priors.ParameterPrior`: its logpdf, cdf and ppf are used)."""
    y = np.asarray(y, float)
    lo, hi = (float(x) for x in f_prior.ppf([1e-9, 1.0 - 1e-9]))
    grid = np.linspace(lo, hi, GRID)
    theta = _theta(variants, rng)
    G = np.asarray(_compose(variants, {**theta, "f": grid[None, :]}, context), float)
    G = np.broadcast_to(G, (max(1, len(next(iter(theta.values()), []))), GRID))
    if np.array_equal(G, np.broadcast_to(grid, G.shape)):
        return np.asarray(f_prior.logpdf(y), float), EXACT_NOTE
    if y.size == 0:  # no draw to evaluate it at (a mixture's member whose weight drew none)
        return np.empty(y.shape), PUSHED_NOTE
    width = np.diff(G, axis=1)
    if np.any(width < -1e-12 * np.abs(G[:, 1:]).max()):
        names = "+".join(v.label for v in variants)
        raise ValueError(f"f_effective of the model {names} decreases with f for some of its prior's parameters: "
                         "its prior cannot be computed by the monotone push-forward")
    mass = np.diff(f_prior.cdf(grid))
    order = np.argsort(y.ravel())
    flat = y.ravel()[order]  # sorted: numpy's search then starts each key where the last one ended
    dens = np.zeros(flat.size)
    # every row searched at once: row k shifted by k * step keeps the flattened rows in order
    step = 2.0 * float(np.abs(G).max() + np.abs(flat).max()) + 1.0
    for a in range(0, G.shape[0], 512):
        rows = G[a:a + 512]
        k = np.arange(rows.shape[0])[:, None]
        i = np.searchsorted((rows + k * step).ravel(), (flat[None, :] + k * step).ravel(), side="right")
        i = i.reshape(rows.shape[0], flat.size) - k * GRID - 1
        ok = (i >= 0) & (i < GRID - 1)
        i = np.clip(i, 0, GRID - 2)
        wi = np.take_along_axis(width[a:a + 512], i, axis=1)
        ok &= wi > 0
        dens += np.where(ok, mass[i] / np.where(ok, wi, 1.0), 0.0).sum(axis=0)
    with np.errstate(divide="ignore"):
        out = np.empty(flat.size)
        out[order] = np.log(dens / G.shape[0])
    return out.reshape(y.shape), PUSHED_NOTE
