"""Does ``diagnose`` name the hidden cause? A confusion matrix over simulated records.

Records: the project's simulator with one hidden mechanism each at a documented detectable
strength (below), f, nu, striker speed, rise time, noise levels and offsets drawn over their
ranges (as ``bench_misfit.py``), both bundled set-ups; plus clean records. Each goes through
``friction-uq run --diagnose``'s path (stationary posterior maximum, then
:func:`friction_uq.discrepancy.diagnose.diagnose`).

    python benchmarks/bench_diagnose.py [--per 8] [--clean 40] [--seed 3] [--as-run]

With ``--as-run`` each record goes through ``friction_uq.run(..., diagnose=True)`` instead (every round of
``diagnose``, and the stationary posterior's draws as half of the f to quote when no cause is named): "f covered"
is then the JSON's f, what a user of ``friction-uq run --diagnose`` reads; "given hdr" is left out.

Prints, per hidden mechanism: how often the first named cause is it (exact), how often it is
named or listed as not separable from the named one (named-or-inseparable), false alarms on clean
records, the coverage of the 90 % interval of the f to quote (the JSON's: the chosen model's posterior with
the output bars' calibration folded in, ``friction_uq.quoted``) and of that posterior's own interval (given
the bars' header values) (truth: the wall's coefficient at the window's mean sliding speed, pressure and
slip), and the time per record.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import tempfile
import time
from collections import Counter
from types import MappingProxyType

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_misfit import clean_config, with_gain  # noqa: E402

from friction_uq.analysis import prepare  # noqa: E402
from friction_uq.discrepancy.diagnose import diagnose  # noqa: E402
from friction_uq.discrepancy.diagnosed_f import quoted_of  # noqa: E402
from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.likelihood import Likelihood  # noqa: E402
from friction_uq.prior_loader import default_prior_path, load_priors  # noqa: E402
from friction_uq.record import read_record  # noqa: E402
from friction_uq.sampler import LogPosterior, start_ball  # noqa: E402
from friction_uq.simulate import simulate_to_file  # noqa: E402
from friction_uq.simulate.simulation import run_any  # noqa: E402

#: Hidden mechanism -> config edit at a detectable strength (and the truth's f at the window).
HIDDEN = {
    "plug_friction": lambda c, r: dataclasses.replace(c, plug_friction_force=float(r.uniform(200, 400)),
                                                      plug_friction_coefficient=float(r.uniform(0.01, 0.02))),
    "gauge_gain": lambda c, r: with_gain(c, "external_output_bar", float(r.choice([0.88, 1.12]))),
    "clearance": lambda c, r: dataclasses.replace(c, gap=float(r.uniform(5e-6, 12e-6)), tube_compliance=True),
    "velocity_friction": lambda c, r: dataclasses.replace(c, friction_law="velocity", friction_params=MappingProxyType(
        {"f_s": float(r.uniform(0.07, 0.09)), "f_d": float(r.uniform(0.03, 0.04)), "v_c": float(r.uniform(5, 10))})),
    "pressure_friction": lambda c, r: dataclasses.replace(c, friction_law="hyperbolic", friction_params=MappingProxyType(
        {"f0": float(r.uniform(0.07, 0.1)), "p0": float(r.uniform(5e7, 1e8))})),
    "slip_friction": lambda c, r: dataclasses.replace(c, friction_law="slip_weakening", friction_params=MappingProxyType(
        {"f_s": float(r.uniform(0.09, 0.12)), "f_d": float(r.uniform(0.04, 0.06)), "d_c": float(r.uniform(5e-4, 2e-3))})),
    "dispersion": lambda c, r: dataclasses.replace(c, dispersion=True),
    # unlubricated end faces (the PTFE sheets missing or torn: explosive on steel); with sheets (0.02-0.1)
    # the ends' share of the wall pressure is below what one record resolves (dELPD < 4 up to 0.25)
    "end_friction": lambda c, r: dataclasses.replace(c, end_friction=float(r.uniform(0.3, 0.5))),
}

#: Walls of the simulator's friction families at shapes other than the catalogue's simple laws (their n = 1): a
#: velocity law turning sharper or slower than an exponential, a shear cap (the simulator's ``pressure`` law, which
#: no finite shape of the saturating family is), an exponential slip weakening. Group -> (the family that should be
#: named, config edit); the strengths are HIDDEN's.
SHAPES = {
    "velocity_shape": ("velocity_friction", lambda c, r: dataclasses.replace(
        c, friction_law="velocity_stretched", friction_params=MappingProxyType(
            {"f_s": float(r.uniform(0.07, 0.09)), "f_d": float(r.uniform(0.03, 0.04)), "v_c": float(r.uniform(5, 10)),
             "n": float(r.choice([0.5, 2.5]))}))),
    "pressure_cap": ("pressure_friction", lambda c, r: _cap(c, float(r.uniform(0.07, 0.1)), float(r.uniform(5e7, 8e7)))),
    "slip_exponential": ("slip_friction", lambda c, r: _exponential_slip(
        c, float(r.uniform(0.09, 0.12)), float(r.uniform(0.04, 0.06)), float(r.uniform(3e-4, 1e-3)))),
}


def _cap(c, f: float, p_cap: float):
    """tau = min(f p, f p_cap): Coulomb below the wall pressure p_cap, the shear strength f p_cap above."""
    return dataclasses.replace(c, friction_law="pressure", friction_params=MappingProxyType(
        {"f": f, "tau_max": f * p_cap}))


def _exponential_slip(c, f_s: float, f_d: float, d_e: float):
    """f = f_d + (f_s - f_d) exp(-d / d_e), as the power family's long reach (n = 200, d_c = 200 d_e)."""
    return dataclasses.replace(c, friction_law="slip_power", friction_params=MappingProxyType(
        {"f_s": f_s, "f_d": f_d, "d_c": 200.0 * d_e, "n": 200.0}))


def true_f(cfg, prep) -> float:
    """The wall's coefficient at the window's mean sliding speed, pressure and slip (as f_effective)."""
    p = cfg.friction_params
    d = prep.data
    V, slip = float(np.mean(d.V)), float(np.mean(d.slip))
    law = cfg.friction_law
    if law == "coulomb":
        return p["f"]
    if law == "velocity":
        return p["f_d"] + (p["f_s"] - p["f_d"]) * math.exp(-V / p["v_c"])
    if law == "slip_weakening":
        return p["f_d"] + (p["f_s"] - p["f_d"]) * max(0.0, 1.0 - slip / p["d_c"])
    if law == "velocity_stretched":
        return p["f_d"] + (p["f_s"] - p["f_d"]) * math.exp(-((V / p["v_c"]) ** p["n"]))
    if law == "slip_power":
        return p["f_d"] + (p["f_s"] - p["f_d"]) * max(0.0, 1.0 - slip / p["d_c"]) ** p["n"]
    if law == "pressure":
        return capped_wall_f(cfg, prep.window.t0, prep.window.t1)
    if law == "hyperbolic":  # p_mean from tau_mean and the truth's f (fixed point)
        # the wall's shear from the force the external bar carries: the record reads it through its header's modulus,
        # which a bar_modulus fault sets apart from the simulated bar's (the fault's own bias is not the wall's f)
        carried = (cfg.apparatus.external_output_bar.young_modulus
                   / prep.record.apparatus.external_output_bar.young_modulus)
        tau = carried * float(np.mean(d.F_eo)) / (2 * math.pi * d.radius * d.length)
        f = p["f0"]
        for _ in range(50):
            f = p["f0"] / (1.0 + tau / f / p["p0"])
        return f
    raise ValueError(law)


def capped_wall_f(cfg, t0: float, t1: float) -> float:
    """A shear cap has no coefficient at the window's mean shear stress (that stress is below the cap however much
    of the wall sits on it): its truth is the wall's mean shear over its mean pressure in the window [t0, t1] (s),
    from the noise-free simulation of ``cfg`` (equal elements along the wall)."""
    model = run_any(cfg)
    w = (model.time >= t0) & (model.time <= t1)
    s = cfg.apparatus.sample
    wall = 2.0 * math.pi * s.radius * s.length
    return float(np.abs(model.wall_friction[w]).sum(axis=1).mean() / (wall * model.wall_pressure[w].mean()))


def analyse(path: str, priors, seed: int, max_causes: int):
    rec = read_record(path)
    prep = prepare(rec)
    lp = LogPosterior(Likelihood(prep.data, hoop=True), priors)
    z_map, _ = start_ball(lp, priors, nwalkers=8, n_ensembles=1, rng=np.random.default_rng(seed))
    th = lp.to_theta(z_map)

    def log_prior(v):
        return float(priors["f"].logpdf(np.array(v["f"])) + priors["nu"].logpdf(np.array(v["nu"])))

    # every model's f from the cut posterior, as ``run`` has it (friction_uq.discrepancy.nu_cut)
    return prep, diagnose(prep, log_prior, {"f": th[0], "nu": th[1]}, hoop=True, seed=seed, n_draws=1000,
                          max_causes=max_causes, nu_cut=True)


def analyse_as_run(path: str, out: str, seed: int):
    """``friction_uq.run(path, diagnose=True)``: the prepared record, the diagnosis and the JSON's f."""
    import friction_uq as fu

    res = fu.run(path, out_dir=out, seed=seed + 1, pdf=False, diagnose=True)
    return res.details.prepared, res.details.diagnosis, res.f


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per", type=int, default=8)
    ap.add_argument("--clean", type=int, default=40)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--max-causes", type=int, default=1,
                    help="causes searched in turn (1: the first named cause, what the study scores)")
    ap.add_argument("--only", help="comma-separated groups (clean, or hidden mechanisms) to analyse; the records "
                    "are those of the whole study (the others are drawn and skipped)")
    ap.add_argument("--as-run", action="store_true", help="through friction_uq.run(..., diagnose=True): the "
                    "JSON's f, every round (module docstring)")
    args = ap.parse_args()
    only = set(args.only.split(",")) if args.only else None
    priors = load_priors(default_prior_path("I1"))
    rng = np.random.default_rng(args.seed)
    tmp = tempfile.mkdtemp()
    jobs = [("clean", None)] * args.clean + [(m, f) for m, f in HIDDEN.items() for _ in range(args.per)]
    stats: dict[str, Counter] = {}
    secs = []
    for k, (hidden, make) in enumerate(jobs):
        cfg = clean_config(rng, "A" if k % 2 == 0 else "B")
        if make is not None:
            cfg = make(cfg, rng)
        path = os.path.join(tmp, f"r{k}.h5")
        sim_seed = int(rng.integers(2**31))
        if only is not None and hidden not in only:
            continue
        simulate_to_file(cfg, path, seed=sim_seed)
        c = stats.setdefault(hidden, Counter())
        c["n"] += 1
        t = time.perf_counter()
        try:
            if args.as_run:
                prep, dg, f_json = analyse_as_run(path, os.path.join(tmp, "out"), seed=k)
            else:
                prep, dg = analyse(path, priors, seed=k, max_causes=args.max_causes)
                f_json = None
        except FrictionUQError as exc:
            c["refused"] += 1
            print(f"{k:4d} {hidden:<18} refused: {exc}", file=sys.stderr, flush=True)
            continue
        secs.append(time.perf_counter() - t)
        named = dg.cause.mechanism.name if dg.cause else None
        c[f"named:{named}"] += 1
        if hidden == "clean":
            c["alarm"] += named is not None
        else:
            c["exact"] += named == hidden
            c["named_or_inseparable"] += named == hidden or hidden in dg.not_separable
            # the diagnosed f with the output bars' calibration: the JSON's f when a cause or candidates were found
            # (when nothing needed explaining the JSON quotes the stationary f; this is the whole-record baseline's)
            fx = quoted_of(dg) if f_json is None else f_json
            tf = true_f(cfg, prep)
            c["covered"] += fx["q05"] <= tf <= fx["q95"]
            given = dg.final.f_summary()  # the posterior's own, given the bars' header values
            c["covered_given_headers"] += given["q05"] <= tf <= given["q95"]
        fq = quoted_of(dg) if f_json is None else f_json
        print(f"{k:4d} {hidden:<18} named {named} causes {[v.label for v in dg.causes]} not_sep {list(dg.not_separable)} "
              f"f quoted {fq['q50']:.4f} [{fq['q05']:.4f}, {fq['q95']:.4f}] truth "
              f"{true_f(cfg, prep):.4f} {secs[-1]:.1f} s", file=sys.stderr, flush=True)
        os.remove(path)
    names = ["clean"] + list(HIDDEN)
    print(f"{'hidden':<18} {'n':>3} {'exact':>6} {'named/insep':>11} {'f covered':>9} {'given hdr':>9} {'alarm':>6} "
          f"{'refused':>7}  first named cause")
    for h in names:
        c = stats.get(h, Counter())
        n = max(c["n"] - c["refused"], 1)
        tally = ", ".join(f"{k.split(':', 1)[1]} {v}" for k, v in sorted(c.items()) if k.startswith("named:"))
        if h == "clean":
            print(f"{h:<18} {c['n']:>3} {'-':>6} {'-':>11} {'-':>9} {'-':>9} {c['alarm'] / n:>6.2f} {c['refused']:>7}  "
                  f"{tally}")
        else:
            print(f"{h:<18} {c['n']:>3} {c['exact'] / n:>6.2f} {c['named_or_inseparable'] / n:>11.2f} "
                  f"{c['covered'] / n:>9.2f} {c['covered_given_headers'] / n:>9.2f} {'-':>6} {c['refused']:>7}  {tally}")
    print("f covered: the f to quote (the JSON's: the output bars' calibration included); given hdr: the final "
          "model's posterior, given the bars' header values")
    eff = [h for h in HIDDEN if h in stats]  # with --only, the groups analysed
    tot = sum(stats[h]["n"] - stats[h]["refused"] for h in eff)
    if tot == 0:
        print(f"no effect record analysed; time per record median {np.median(secs):.1f} s" if secs else "no record analysed")
        return
    print(f"all effect records: exact {sum(stats[h]['exact'] for h in eff) / tot:.2f}, named or inseparable "
          f"{sum(stats[h]['named_or_inseparable'] for h in eff) / tot:.2f}, f covered "
          f"{sum(stats[h]['covered'] for h in eff) / tot:.2f}; time per record median {np.median(secs):.1f} s")


if __name__ == "__main__":
    main()
