"""ESS per second of f: the package's sampler (emcee, differential evolution, 4 independent
ensembles) against NUTS (NumPyro) on the same likelihood, side by side in one run.

Target (issue 7): >= 3x NUTS's ESS/s of f. Both sample the same log density: the package's
``LogPosterior`` (the likelihood of :mod:`friction_uq.likelihood` with the prior file's priors) in
the same unconstrained coordinates z = (log f, logit nu, log g). The likelihood is numpy code
(AR(1) noise, offsets, the hoop kernel) with no automatic derivative, so NUTS gets it through
``jax.pure_callback`` with a central-difference gradient (all 2 ndim + 1 points in one vectorised
call, step 1e-5 in z); NUTS (dense mass matrix: the force data leave a narrow f-nu ridge) runs 4
chains one after the other, 500 warm-up and 1000 draws each. Times are whole runs (warm-up / burn-in included, NUTS's compilation excluded by a first short
run); ESS is arviz_stats' bulk ESS of f over all chains.

Needs the optional extra: ``pip install -e '.[bench]'`` (numpyro, jax).

    python benchmarks/bench_nuts.py [RECORD] [--no-hoop] [--seed 1]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "data" / "A" / "A-03.h5"


def nuts_run(log_post, z0: np.ndarray, *, seed: int, chains: int = 4, warmup: int = 500, draws: int = 1000):
    """NUTS on ``log_post`` (vectorised numpy log density in z); returns (z draws (chain, draw, ndim), seconds)."""
    import jax
    import jax.numpy as jnp
    from numpyro.infer import MCMC, NUTS

    jax.config.update("jax_enable_x64", True)
    ndim = len(z0)
    h = 1e-5
    offsets = np.vstack([np.zeros(ndim), np.repeat(np.eye(ndim), 2, axis=0) * np.tile([h, -h], ndim)[:, None]])

    def value_and_grad(z):
        z = np.asarray(z, float)
        v = log_post(z[None, :] + offsets)
        if not np.isfinite(v[0]):
            return np.float64(np.inf), np.zeros(ndim)
        grad = (v[1::2] - v[2::2]) / (2 * h)
        return np.float64(-v[0]), np.where(np.isfinite(grad), -grad, 0.0)

    shapes = (jax.ShapeDtypeStruct((), jnp.float64), jax.ShapeDtypeStruct((ndim,), jnp.float64))

    def callback(z):
        return jax.pure_callback(value_and_grad, shapes, z, vmap_method="sequential")

    @jax.custom_jvp
    def potential(z):
        return callback(z)[0]

    @potential.defjvp
    def potential_jvp(primals, tangents):
        (z,), (t,) = primals, tangents
        v, g = callback(z)
        return v, jnp.dot(g, t)

    def run(n_warm, n_draw, key):
        mcmc = MCMC(NUTS(potential_fn=potential, dense_mass=True), num_warmup=n_warm, num_samples=n_draw, num_chains=chains,
                    chain_method="sequential", progress_bar=False)
        init = jnp.asarray(np.tile(z0, (chains, 1)) + 1e-3 * np.random.default_rng(seed).standard_normal((chains, ndim)))
        mcmc.run(key, init_params=init)
        return mcmc

    run(5, 5, jax.random.PRNGKey(seed + 1))  # compile
    t0 = time.perf_counter()
    mcmc = run(warmup, draws, jax.random.PRNGKey(seed))
    seconds = time.perf_counter() - t0
    z = np.asarray(mcmc.get_samples(group_by_chain=True))
    return z, seconds


def ess_bulk(x: np.ndarray) -> float:
    """Bulk ESS (arviz_stats) of draws shaped (chain, draw)."""
    from arviz_stats.base import array_stats

    return float(array_stats.ess(np.asarray(x, float), chain_axis=0, draw_axis=1, method="bulk"))


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("record", nargs="?", type=Path, default=DEFAULT)
    ap.add_argument("--no-hoop", action="store_true")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args(argv)
    try:
        import numpyro  # noqa: F401  (the optional extra)
    except ImportError:
        print("NUTS comparison needs the optional extra: pip install -e '.[bench]' (numpyro, jax)")
        return 1

    from friction_uq.analysis import prepare
    from friction_uq.likelihood import Likelihood
    from friction_uq.prior_loader import default_prior_path, load_priors
    from friction_uq.record import read_record
    from friction_uq.sampler import LogPosterior, sample_posterior, start_ball

    rec = read_record(a.record)
    prep = prepare(rec)
    priors = load_priors(default_prior_path(rec.apparatus.sample.material))
    hoop = not a.no_hoop and prep.data.hoop is not None

    t0 = time.perf_counter()
    ours = sample_posterior(prep.data, priors, seed=a.seed, hoop=hoop)
    ours_s = time.perf_counter() - t0
    ours_ess = ess_bulk(ours.draws["f"])

    lk = Likelihood(prep.data, hoop=hoop)
    log_post = LogPosterior(lk, priors.subset(lk.names))
    z_map, _ = start_ball(log_post, priors.subset(lk.names), nwalkers=8, n_ensembles=1,
                          rng=np.random.default_rng(a.seed))
    z, nuts_s = nuts_run(log_post, z_map, seed=a.seed)
    f_nuts = lk.parameters.as_dict(log_post.to_theta(z))["f"]
    nuts_ess = ess_bulk(f_nuts)

    print(f"{rec.campaign} {rec.test_id}, hoop term {'on' if hoop else 'off'}, parameters {', '.join(lk.names)}")
    print(f"{'sampler':<44} {'seconds':>8} {'draws':>7} {'ESS f':>7} {'ESS/s f':>8} {'f q50':>8} {'f sd':>8}")
    for name, s, n, e, f in (
        (f"emcee DE, {ours.n_chains} ensembles x {ours.nwalkers} walkers", ours_s, ours.n_chains * ours.n_draws,
         ours_ess, ours.draws["f"]),
        ("NUTS (NumPyro), 4 chains, finite-diff. grad.", nuts_s, f_nuts.size, nuts_ess, f_nuts),
    ):
        print(f"{name:<44} {s:>8.2f} {n:>7d} {e:>7.0f} {e / s:>8.0f} {np.median(f):>8.4f} {np.std(f):>8.4f}")
    ratio = (ours_ess / ours_s) / (nuts_ess / nuts_s)
    print(f"ESS/s of f, emcee / NUTS: {ratio:.1f}x (target >= 3x)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
