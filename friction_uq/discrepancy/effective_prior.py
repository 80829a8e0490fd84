"""The prior of f_effective under an extended model, the prior its draws were made under: a campaign
that pools f under each test's diagnosed model divides it out (friction_uq.campaigns.pooling).

A model's draws are of the base f (under the prior file's f prior), nu, the sample's modulus and the
mechanisms' parameters theta (each under its own prior, :mod:`.mechanisms`), all independent;
f_effective = g(f, theta) is the wall's coefficient at the stationary window (:mod:`.extended`).

* Where every mechanism of the model leaves f as it is (all but the friction laws), f_effective = f
  and its prior is the prior file's f prior, evaluated exactly.
* Otherwise its prior is the push-forward of the joint prior through g,
  pi(y) = E_theta[ density at y of g(f, theta), f ~ pi_f ], computed conditionally on theta: g is
  nondecreasing in f (a convex combination of f and f_s, or f times the saturating wall's factor at the
  window's wall pressure, which reads nu: nu is then drawn from the prior file's nu prior too), so the f
  prior's mass between two points of a fine grid (:data:`GRID`, exact from its CDF) lands evenly
  between their images. The expectation over theta is a mean over :data:`THETA_DRAWS` scrambled
  Sobol points mapped through the priors' quantile functions (seeded: same seed, same bits). Where the
  law mixes f with a coefficient of its own (velocity, slip: (1 - w) f + w f_s), a draw whose w > 1/2
  pushes f_s's grid with f drawn instead: pushing f there squeezes its grid into a spike (one such draw
  put the velocity law's density 39 % off at one point). The relative error is below 1 %
  (tests/test_effective_prior.py: against quadrature for the pressure and the velocity laws).

A law whose f_effective can be 0 for a whole range of f would put an atom of prior mass at 0 that the density leaves
out: a draw there has density 0 (log -inf), which pooling refuses to divide by. (No law of the catalogue does now.)
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


def _companion(variants: Sequence[Any]) -> str | None:
    """The coefficient a friction law of the model mixes f with (``Mechanism.companion``), or None."""
    return next((v.mechanism.companion for v in variants if v.mechanism.companion), None)


def _theta(variants: Sequence[Any], rng: np.random.Generator, f_prior: Any, nu_prior: Any) -> dict[str, np.ndarray]:
    """Draws of every mechanism parameter of the model from its prior, (THETA_DRAWS, 1) each; with a companion
    coefficient, a draw of f too (as ``"f"``: the rows that push the companion hold f fixed); where a mechanism's
    f_effective reads nu, nu from its prior."""
    params = [(p.name, v.mechanism.priors[p.name]) for v in variants for p in v.mechanism.parameters]
    if not params:
        return {}
    if _companion(variants):
        params.append(("f", f_prior))
    if any(v.mechanism.uses_nu for v in variants):
        if nu_prior is None:
            raise ValueError("the prior of f_effective under a model whose f_effective reads nu needs nu's prior")
        params.append(("nu", nu_prior))
    u = qmc.Sobol(len(params), scramble=True, seed=rng).random_base2(int(np.log2(THETA_DRAWS)))
    u = np.clip(u, 1e-12, 1.0 - 1e-12)
    return {name: np.asarray(prior.ppf(u[:, j]), float)[:, None] for j, (name, prior) in enumerate(params)}


def _pushed_rows(variants: Sequence[Any], theta: dict[str, np.ndarray], context: Context, f_prior: Any,
                 companion: str | None, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Each theta draw's image of a fine grid of f (row k: g(grid, theta_k)) and the prior mass between the grid's
    points. With a companion c (f_effective = (1 - w) f + w c), a row where w > 1/2 pushes a grid of c instead, f
    held at its draw: its image is then the wider one, where f's would be squeezed into a spike of width (1 - w) x
    the grid's, whose Monte Carlo average converges slowly. Which is pushed depends on theta's other parameters
    only (the width of a grid's image), so the mean stays the push-forward's."""
    grid = np.linspace(lo, hi, GRID)
    others = {k: x for k, x in theta.items() if k != "f"}
    G = np.asarray(_compose(variants, {**others, "f": grid[None, :]}, context), float)
    G = np.broadcast_to(G, (max(1, len(next(iter(theta.values()), []))), GRID))
    mass = np.broadcast_to(np.diff(f_prior.cdf(grid)), (G.shape[0], GRID - 1))
    if companion is None:
        return G, mass
    prior_c = next(v.mechanism.priors[companion] for v in variants if v.mechanism.companion == companion)
    grid_c = np.linspace(*(float(x) for x in prior_c.ppf([1e-9, 1.0 - 1e-9])), GRID)
    Gc = np.asarray(_compose(variants, {**theta, companion: grid_c[None, :]}, context), float)
    swap = (Gc[:, -1] - Gc[:, 0] > G[:, -1] - G[:, 0])[:, None]
    return np.where(swap, Gc, G), np.where(swap, np.diff(prior_c.cdf(grid_c))[None, :], mass)


def log_prior_f_effective(variants: Sequence[Any], context: Context, f_prior: Any, y: np.ndarray, *,
                          rng: np.random.Generator, nu_prior: Any = None) -> tuple[np.ndarray, str]:
    """log pi(y) of f_effective under a model (its ``variants``: extended.Variant) at the draws ``y``, and what
    that prior is in words (module docstring). ``f_prior``, ``nu_prior``: the prior file's f and nu priors
    (:class:`~friction_uq.priors.ParameterPrior`: logpdf, cdf and ppf; nu's is needed only where a mechanism's
    f_effective reads nu, the pressure family's)."""
    y = np.asarray(y, float)
    lo, hi = (float(x) for x in f_prior.ppf([1e-9, 1.0 - 1e-9]))
    theta, companion = _theta(variants, rng, f_prior, nu_prior), _companion(variants)
    G, mass = _pushed_rows(variants, theta, context, f_prior, companion, lo, hi)
    if companion is None and np.array_equal(G, np.broadcast_to(np.linspace(lo, hi, GRID), G.shape)):
        return np.asarray(f_prior.logpdf(y), float), EXACT_NOTE
    if y.size == 0:  # no draw to evaluate it at (a mixture's member whose weight drew none)
        return np.empty(y.shape), PUSHED_NOTE
    width = np.diff(G, axis=1)
    if np.any(width < -1e-12 * np.abs(G[:, 1:]).max()):
        names = "+".join(v.label for v in variants)
        raise ValueError(f"f_effective of the model {names} decreases with f for some of its prior's parameters: "
                         "its prior cannot be computed by the monotone push-forward")
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
        mi = np.take_along_axis(mass[a:a + 512], i, axis=1)
        ok &= wi > 0
        dens += np.where(ok, mi / np.where(ok, wi, 1.0), 0.0).sum(axis=0)
    with np.errstate(divide="ignore"):
        out = np.empty(flat.size)
        out[order] = np.log(dens / G.shape[0])
    return out.reshape(y.shape), PUSHED_NOTE
