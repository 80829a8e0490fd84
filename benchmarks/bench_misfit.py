"""Calibration of the misfit decision: false alarms on clean records, detection of hidden effects.

Clean records: the project's simulator with Coulomb friction and no hidden effect; f, nu, striker
speed, rise time, noise levels and offsets drawn over their ranges; both bundled set-ups (A: the
paper's, B: titanium internal bar, hoop gauge 5 % low as in campaign B). Each record goes through
the same path as ``friction-uq run``: stationary-phase posterior (its maximum here, to keep the
study short), whole-record fit of the simulator driven by the measured incident wave, comparison,
decision. Effect records add one hidden effect at two strengths.

    python benchmarks/bench_misfit.py [--clean 200] [--effect 20] [--seed 1]

Prints the false-alarm rate with its 95 % binomial (Clopper-Pearson) interval and a table of
detection rates.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
from types import MappingProxyType

import numpy as np
from scipy import stats

from friction_uq.analysis import prepare
from friction_uq.discrepancy.check import check_whole_record
from friction_uq.discrepancy.diagnosis_words import HOOP_GAIN_FINDING
from friction_uq.errors import FrictionUQError
from friction_uq.likelihood import Likelihood
from friction_uq.prior_loader import default_prior_path, load_priors
from friction_uq.record import read_record
from friction_uq.sampler import LogPosterior, start_ball
from friction_uq.simulate import load_config, simulate_to_file

HERE = os.path.dirname(os.path.abspath(__file__))
SETUPS = {k: load_config(os.path.join(HERE, "..", "data", "configs", f"{k}-03.toml")) for k in ("A", "B")}


def clean_config(rng: np.random.Generator, setup: str):
    cfg = SETUPS[setup]
    chans = {}
    for k, c in cfg.channels.items():
        s = rng.uniform(0.6, 1.6)
        chans[k] = dataclasses.replace(c, white=c.white * s, ar1=c.ar1 * s, offset=float(rng.normal(0, 5e-6)))
    return dataclasses.replace(
        cfg, friction_law="coulomb", friction_params=MappingProxyType({"f": float(rng.uniform(0.02, 0.12))}),
        poisson_ratio=float(np.clip(rng.normal(0.4, 0.03), 0.3, 0.48)), striker_velocity=float(rng.uniform(6, 15)),
        rise_time=float(rng.uniform(15e-6, 25e-6)), gap=0.0, tube_compliance=False, dispersion=False,
        plug_friction_force=0.0, plug_friction_coefficient=0.0, channels=MappingProxyType(chans))


def with_gain(cfg, channel: str, gain: float):
    c = dict(cfg.channels)
    c[channel] = dataclasses.replace(c[channel], gain=gain)
    return dataclasses.replace(cfg, channels=MappingProxyType(c))


EFFECTS = {
    "plug friction 150 N + 1 % F_i": lambda c: dataclasses.replace(c, plug_friction_force=150.0, plug_friction_coefficient=0.01),
    "plug friction 300 N + 2 % F_i": lambda c: dataclasses.replace(c, plug_friction_force=300.0, plug_friction_coefficient=0.02),
    "external gauge gain 1.05": lambda c: with_gain(c, "external_output_bar", 1.05),
    "external gauge gain 1.15": lambda c: with_gain(c, "external_output_bar", 1.15),
    "internal gauge gain 0.97": lambda c: with_gain(c, "internal_output_bar", 0.97),
    "internal gauge gain 0.90": lambda c: with_gain(c, "internal_output_bar", 0.90),
    "clearance 4 um + compliance": lambda c: dataclasses.replace(c, gap=4e-6, tube_compliance=True),
    "clearance 10 um + compliance": lambda c: dataclasses.replace(c, gap=10e-6, tube_compliance=True),
    "velocity weakening 0.06->0.04": lambda c: dataclasses.replace(c, friction_law="velocity", friction_params=MappingProxyType({"f_s": 0.06, "f_d": 0.04, "v_c": 8.0})),
    "velocity weakening 0.075->0.035": lambda c: dataclasses.replace(c, friction_law="velocity", friction_params=MappingProxyType({"f_s": 0.075, "f_d": 0.035, "v_c": 8.0})),
    "slip weakening 0.07->0.05, 1 mm": lambda c: dataclasses.replace(c, friction_law="slip_weakening", friction_params=MappingProxyType({"f_s": 0.07, "f_d": 0.05, "d_c": 1e-3})),
    "slip weakening 0.10->0.05, 1 mm": lambda c: dataclasses.replace(c, friction_law="slip_weakening", friction_params=MappingProxyType({"f_s": 0.10, "f_d": 0.05, "d_c": 1e-3})),
    "pressure cap tau_max 4 MPa": lambda c: dataclasses.replace(c, friction_law="pressure", friction_params=MappingProxyType({"f": 0.08, "tau_max": 4e6})),
    "pressure cap tau_max 2.5 MPa": lambda c: dataclasses.replace(c, friction_law="pressure", friction_params=MappingProxyType({"f": 0.08, "tau_max": 2.5e6})),
    "dispersion (all bars)": lambda c: dataclasses.replace(c, dispersion=True),
}


def analyse(path: str, priors, seed: int):
    rec = read_record(path)
    prep = prepare(rec)
    lp = LogPosterior(Likelihood(prep.data, hoop=True), priors)
    z_map, _ = start_ball(lp, priors, nwalkers=8, n_ensembles=1, rng=np.random.default_rng(seed))
    th = lp.to_theta(z_map)
    log_prior = lambda v: float(priors.logpdf(np.array([[v["f"], v["nu"], th[2]]]))[0])  # noqa: E731
    return check_whole_record(prep, log_prior, {"f": th[0], "nu": th[1]}, hoop=True, seed=seed)


def rate_line(label: str, hits: int, n: int, refused: int = 0) -> str:
    lo, hi = stats.binomtest(hits, n).proportion_ci(0.95, method="exact")
    return f"{label:<36} {n:>5} {hits:>5} {refused:>7} {hits / n:>7.3f}  [{lo:.3f}, {hi:.3f}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clean", type=int, default=200)
    ap.add_argument("--effect", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    priors = load_priors(default_prior_path("I1"))
    rng = np.random.default_rng(args.seed)
    tmp = tempfile.mkdtemp()
    rows, secs, worst_clean = [], [], []
    hoop: dict[str, list[float]] = {}
    header = (f"{'records':<36} {'n':>5} {'flag':>5} {'refused':>7} {'rate':>7}  95 % interval "
              "(flag: misfit detected, or refused: no stationary phase)")
    k = 0
    hits = 0
    for i in range(args.clean):
        cfg = clean_config(rng, "A" if i % 2 == 0 else "B")
        p = os.path.join(tmp, f"r{k}.h5"); k += 1
        simulate_to_file(cfg, p, seed=int(rng.integers(2**31)))
        t = time.perf_counter()
        chk = analyse(p, priors, seed=i)
        secs.append(time.perf_counter() - t)
        hits += chk.decision.detected
        worst_clean.append(chk.decision.statistic / chk.decision.threshold)
        hoop.setdefault("A" if i % 2 == 0 else "B", []).append(chk.hoop_gain)
        os.remove(p)
    rows.append(rate_line("clean (false alarms)", hits, args.clean))
    print(rows[-1], file=sys.stderr, flush=True)
    for label, make in EFFECTS.items():
        hits = refused = 0
        for i in range(args.effect):
            cfg = make(clean_config(rng, "A" if i % 2 == 0 else "B"))
            p = os.path.join(tmp, f"r{k}.h5"); k += 1
            simulate_to_file(cfg, p, seed=int(rng.integers(2**31)))
            try:
                hits += analyse(p, priors, seed=1000 + i).decision.detected
            except FrictionUQError:
                refused += 1
                hits += 1
            os.remove(p)
        rows.append(rate_line(label, hits, args.effect, refused))
        print(rows[-1], file=sys.stderr, flush=True)
    q = np.quantile(worst_clean, [0.5, 0.9, 0.95, 0.99]) if worst_clean else [np.nan] * 4
    print(header)
    print("\n".join(rows))
    print(f"clean records, the furthest cell's statistic over its threshold, quantiles 50/90/95/99 %: {q[0]:.2f} "
          f"{q[1]:.2f} {q[2]:.2f} {q[3]:.2f} (misfit above 1)")
    for setup, g in sorted(hoop.items()):
        g = np.array(g)
        q = np.quantile(g, [0.05, 0.5, 0.95])
        print(f"hoop gauge factor, clean set-up {setup} (true {SETUPS[setup].channels['tube_hoop'].gain:.2f}): "
              f"5/50/95 % {q[0]:.3f} {q[1]:.3f} {q[2]:.3f}; |g - 1| > {HOOP_GAIN_FINDING:.0%} (reported) in "
              f"{np.mean(np.abs(g - 1.0) > HOOP_GAIN_FINDING):.0%} of {len(g)}")
    if secs:
        print(f"whole-record check per record: median {np.median(secs):.2f} s, max {np.max(secs):.2f} s")


if __name__ == "__main__":
    main()
