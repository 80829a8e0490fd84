"""Records for calibrating ``diagnose``'s verdict on what the 1-D likelihood did not make, and the first
round of ``diagnose`` on each, stored so that a naming rule can be evaluated without fitting again.

Groups (f, nu, striker speed, rise time and noise drawn as in ``bench_misfit.py``, both bundled set-ups):

* ``clean_axisymmetric``: the clean test in the axisymmetric simulation (plug, sample and tube in r-z);
* ``clean_perturbed``: the clean test in the 1-D simulation perturbed in a way no mechanism of the catalogue
  describes, one of: another mesh (8 or 60 sample elements), the hoop gauge's influence kernel 20 % off
  (its decay rate) or without its axial term, an incident pulse rising in 8-40 us, gauge noise coloured up to a
  lag-1 coefficient of 0.995, one channel's timing shifted by up to +-0.5 us (a gauge's position or a
  trigger's skew);
* one group per hidden mechanism of ``bench_diagnose.HIDDEN`` (1-D, at its documented strength), and
  ``axisymmetric_<mechanism>`` for those the axisymmetric simulation also has (plug friction, clearance, the
  friction laws);
* one group per measurement-chain fault (:data:`CHAIN_FAULTS`), made on the recorded strains of the 1-D
  simulation: ``channel_timing`` (one output gauge read 3-5 us late or early: a pure delay, made by the
  same linear interpolation as the model's), and, with shapes the catalogue's models do not share,
  ``bandwidth`` (one output gauge through a second-order Butterworth low-pass at
  50-80 kHz, not the model's first-order one) and ``zero_drift`` (one gauge's zero creeping 10-25
  microstrain over the record along an exponential, not the model's straight line), ``bar_modulus`` (one
  output bar's modulus 5-8 % off the header the record carries, its wave speed with it: the test simulated
  with the true bar, the record written with the header's); and the same four on records of the axisymmetric
  simulation (``axisymmetric_<fault>``);
* the friction families at other shapes than the catalogue's simple laws (``bench_diagnose.SHAPES``: a velocity
  law turning sharper or slower than an exponential, a shear cap, an exponential slip weakening), in both
  simulations (``axisymmetric_<shape>``), drawn after every other group so that those draw as before.

For each record: ``diagnose``'s first round (the baseline against every extended model), written as one
``.npz`` per record: each model's pointwise block ELPD and calibration terms, its draws of f_effective and its
mode (f, nu and the mechanism's parameters), the misfit decision's flagged cells, and the truth (f at the window,
nu).

    python benchmarks/verdict_records.py OUT_DIR [--clean 20] [--per 4] [--seed 17] [--only GROUP,...]
        [--max-causes 1 | --as-run]

Each record's line ends with its time, and diagnose's own (the simulation not counted); the last line, their
median. Under ``--as-run`` the line also gives the JSON's f (the f a user reads) and whether its 90 % interval
holds the truth. ``--as-run`` takes every round through ``friction_uq.run`` (the stationary analysis, the whole-record check
and the exact posterior included): the time a user of ``friction-uq diagnose`` waits, without the PDF.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import tempfile
import time
from types import MappingProxyType

import numpy as np
from scipy import signal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_diagnose import HIDDEN, SHAPES, analyse, analyse_as_run, true_f  # noqa: E402
from bench_misfit import clean_config  # noqa: E402
from bench_trust import write_strains  # noqa: E402

from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.prior_loader import default_prior_path, load_priors  # noqa: E402
from friction_uq.simulate import simulate  # noqa: E402

#: The mechanisms the axisymmetric simulation also has.
AXISYMMETRIC_MECHANISMS = ("plug_friction", "clearance", "velocity_friction", "pressure_friction", "slip_friction")


def _axisymmetric(c):
    return dataclasses.replace(c, model=dataclasses.replace(c.model, fidelity="axisymmetric"))


def _perturbation(c, r: np.random.Generator) -> tuple[object, str | None, str]:
    """One perturbation no mechanism describes: (config, channel to shift or None, what it is)."""
    kind = str(r.choice(["mesh", "kernel", "pulse", "coloured", "timing"]))
    if kind == "mesh":
        n = int(r.choice([8, 60]))
        return dataclasses.replace(c, elements=n), None, f"mesh {n} elements"
    if kind == "kernel":
        if r.random() < 0.5:
            return dataclasses.replace(c, hoop_axial_term=False), None, "hoop kernel without its axial term"
        k = float(r.choice([0.8, 1.2]))
        return dataclasses.replace(c, hoop_beta=c.hoop_beta * k), None, f"hoop kernel decay x{k:g}"
    if kind == "pulse":
        tr = float(r.uniform(8e-6, 40e-6))
        return dataclasses.replace(c, rise_time=tr), None, f"rise time {tr * 1e6:.0f} us"
    if kind == "coloured":
        a = float(r.uniform(0.9, 0.995))
        ch = {k: dataclasses.replace(s, ar1=s.ar1 * float(r.uniform(1.0, 2.0)), ar1_coef=a) for k, s in c.channels.items()}
        return dataclasses.replace(c, channels=MappingProxyType(ch)), None, f"noise lag-1 {a:.3f}"
    ch = str(r.choice(["input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"]))
    return c, ch, f"{ch} timing {float(r.uniform(-0.5, 0.5)):+.2f} us"


OUTPUT_GAUGES = ("internal_output_bar", "external_output_bar", "tube_hoop")


def _timing(c, r: np.random.Generator):
    ch = str(r.choice(OUTPUT_GAUGES))
    dt = float(r.uniform(3e-6, 5e-6) * r.choice([-1, 1]))
    return c, _shifted(ch, dt), f"{ch} timing {dt * 1e6:+.2f} us"


def _bandwidth(c, r: np.random.Generator):
    ch = str(r.choice(OUTPUT_GAUGES))
    fc = float(r.uniform(50e3, 80e3))

    def edit(t, noisy):
        noisy[ch] = signal.sosfilt(signal.butter(2, fc, fs=1.0 / (t[1] - t[0]), output="sos"), noisy[ch])
    return c, edit, f"{ch} through a 2nd-order low-pass at {fc / 1e3:.0f} kHz"


def _drift(c, r: np.random.Generator):
    ch = str(r.choice(("input_bar", *OUTPUT_GAUGES)))
    amp = float(r.uniform(10e-6, 25e-6) * r.choice([-1, 1]))

    def edit(t, noisy):
        u = (t - t[0]) / (t[-1] - t[0])
        noisy[ch] = noisy[ch] + amp * (1.0 - np.exp(-2.0 * u)) / (1.0 - np.exp(-2.0))
    return c, edit, f"{ch} zero creeps {amp * 1e6:+.0f} ue"


def _bar_modulus(c, r: np.random.Generator):
    name = str(r.choice(["internal_output_bar", "external_output_bar"]))
    k = float(r.uniform(1.05, 1.08) ** r.choice([-1, 1]))
    bar = getattr(c.apparatus, name)
    true = dataclasses.replace(bar, young_modulus=bar.young_modulus * k, wave_speed=bar.wave_speed * k ** 0.5)
    return (dataclasses.replace(c, apparatus=dataclasses.replace(c.apparatus, **{name: true})), None,
            f"{name} modulus x{k:.3f} of its header's")


#: Measurement-chain faults: group (the mechanism's name) -> maker of (the configuration simulated, an edit of the
#: recorded strains or None, a note); the record carries the clean configuration's header
CHAIN_FAULTS = {"channel_timing": _timing, "bandwidth": _bandwidth, "zero_drift": _drift, "bar_modulus": _bar_modulus}


def _shifted(ch: str, dt: float):
    def edit(t, noisy):  # the channel read dt later (or earlier) than its neighbours
        noisy[ch] = np.interp(t - dt, t, noisy[ch])
    return edit


def groups() -> list[str]:
    return (["clean_axisymmetric", "clean_perturbed"] + list(HIDDEN)
            + [f"axisymmetric_{m}" for m in AXISYMMETRIC_MECHANISMS] + list(CHAIN_FAULTS)
            + [f"axisymmetric_{m}" for m in CHAIN_FAULTS]
            + list(SHAPES) + [f"axisymmetric_{m}" for m in SHAPES])  # last: the groups before draw as they did


def make(group: str, k: int, r: np.random.Generator):
    """The configuration of record ``k`` of ``group``, an edit of its recorded strains (``edit(time, noisy)``,
    or None), a note and the apparatus its header carries (None: the configuration's)."""
    cfg = clean_config(r, "A" if k % 2 == 0 else "B")
    edit, note, header = None, "", None
    if group == "clean":  # the 1-D simulation as drawn: the likelihood's own family
        note = "1-D"
    elif group == "clean_axisymmetric":
        cfg, note = _axisymmetric(cfg), "axisymmetric"
    elif group == "clean_perturbed":
        cfg, ch, note = _perturbation(cfg, r)
        if ch is not None:
            edit = _shifted(ch, float(note.split("timing ")[1].split(" us")[0]) * 1e-6)
    elif group.removeprefix("axisymmetric_") in CHAIN_FAULTS:
        header = cfg.apparatus
        cfg, edit, note = CHAIN_FAULTS[group.removeprefix("axisymmetric_")](cfg, r)
        if group.startswith("axisymmetric_"):
            cfg, note = _axisymmetric(cfg), f"axisymmetric, {note}"
    else:
        mech = group.removeprefix("axisymmetric_")
        cfg = SHAPES[mech][1](cfg, r) if mech in SHAPES else HIDDEN[mech](cfg, r)
        note = mech
        if group.startswith("axisymmetric_"):
            cfg, note = _axisymmetric(cfg), f"axisymmetric {mech}"
    return cfg, edit, note, header


def write(cfg, path: str, seed: int, edit, header=None) -> object:
    sim = simulate(cfg, seed=seed)
    noisy = dict(sim.noisy)
    if edit is not None:
        edit(sim.time, noisy)
    if header is not None:
        cfg = dataclasses.replace(cfg, apparatus=header)
    write_strains(cfg, path, sim, noisy, campaign="V")
    return sim


def dump(out: str, name: str, group: str, note: str, cfg, prep, dg) -> None:
    """Round 1 of ``dg`` (a Diagnosis) as ``out/name.npz`` (module docstring)."""
    base = dg.baseline
    arrays = {"base_pointwise": base.elpd.pointwise, "base_calibration": base.elpd.calibration,
              "base_calibration_mean": base.elpd.calibration_mean, "base_calibration_var": base.elpd.calibration_var,
              "base_f": base.f_effective[:400]}
    models = []
    for i, rk in enumerate(dg.rounds[0]):
        e = rk.fit.elpd
        arrays |= {f"m{i}_pointwise": e.pointwise, f"m{i}_calibration": e.calibration,
                   f"m{i}_calibration_mean": e.calibration_mean, f"m{i}_calibration_var": e.calibration_var,
                   f"m{i}_f": rk.fit.f_effective[:400]}
        v = rk.fit.variants[-1]
        models.append({"label": rk.fit.label, "mechanism": v.mechanism.name, "channel": v.channel,
                       "calibration_names": list(e.calibration_names), "delpd": rk.delpd, "se": rk.se,
                       "mode": {k: float(x) for k, x in rk.fit.fit.mode.items()}})
    m = dg.misfits[0]
    meta = {"group": group, "note": note, "truth_f": true_f(cfg, prep), "truth_nu": cfg.poisson_ratio,
            "misfit": bool(m.detected), "base_mode": {k: float(x) for k, x in base.fit.mode.items()},
            "flagged": [[c.channel, c.phase, c.statistic, c.threshold] for c in m.flagged()],
            "base_calibration_names": list(base.elpd.calibration_names), "models": models,
            "named_now": dg.cause.mechanism.name if dg.cause else None}
    np.savez_compressed(os.path.join(out, f"{name}.npz"), meta=json.dumps(meta), **arrays)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--clean", type=int, default=20, help="records of each clean group")
    ap.add_argument("--per", type=int, default=4, help="records of each mechanism group")
    ap.add_argument("--seed", type=int, default=17)
    ap.add_argument("--only", help="comma-separated groups")
    rounds = ap.add_mutually_exclusive_group()
    rounds.add_argument("--max-causes", type=int, default=1,
                    help="rounds of diagnose (1: the first round, what is stored; 4: every round, as friction-uq "
                    "diagnose runs, to time it)")
    rounds.add_argument("--as-run", action="store_true", help="through friction_uq.run(..., diagnose=True), every round: "
                    "the stationary analysis and the whole-record check included, as friction-uq diagnose times")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    only = set(a.only.split(",")) if a.only else None
    priors = load_priors(default_prior_path("I1"))
    rng = np.random.default_rng(a.seed)
    tmp = tempfile.mkdtemp()
    jobs = [(g, k) for g in groups() for k in range(a.clean if g.startswith("clean") else a.per)]
    seconds = []  # diagnose's own time per record (the simulation not counted)
    for g, k in jobs:
        cfg, edit, note, header = make(g, k, rng)
        sim_seed = int(rng.integers(2**31))
        name = f"{g}-{k}"
        if (only is not None and g not in only) or os.path.exists(os.path.join(a.out, f"{name}.npz")):
            continue
        path = os.path.join(tmp, f"{name}.h5")
        t = time.perf_counter()
        try:
            write(cfg, path, sim_seed, edit, header)
            t_fit = time.perf_counter()
            if a.as_run:
                prep, dg, f_json = analyse_as_run(path, os.path.join(tmp, name), seed=k)
            else:
                prep, dg = analyse(path, priors, seed=k, max_causes=a.max_causes)
                f_json = None
        except FrictionUQError as exc:
            print(f"{name}: refused: {exc}", flush=True)
            continue
        seconds.append(time.perf_counter() - t_fit)
        dump(a.out, name, g, note, cfg, prep, dg)
        os.remove(path)
        causes = [v.mechanism.name for v in dg.named_causes]
        rounds = [v.kind for v in dg.verdicts]
        quoted = ""
        if f_json is not None:  # the JSON's f against the truth: whether the f a user reads holds it
            tf = true_f(cfg, prep)
            held = "held" if f_json["q05"] <= tf <= f_json["q95"] else "MISSED"
            quoted = f"f {f_json['q50']:.4f} [{f_json['q05']:.4f}, {f_json['q95']:.4f}] truth {tf:.4f} {held}, "
        print(f"{name} ({note}): misfit {dg.misfits[0].detected}, named {causes or None}, rounds {rounds}, {quoted}"
              f"{time.perf_counter() - t:.0f} s ({seconds[-1]:.0f} s diagnose)", flush=True)
    if seconds:
        how = "every round, as run" if a.as_run else f"{a.max_causes} round(s) at most"
        print(f"diagnose, {how}: median {np.median(seconds):.1f} s a record, range "
              f"{min(seconds):.0f}-{max(seconds):.0f} s, {len(seconds)} records")


if __name__ == "__main__":
    main()
