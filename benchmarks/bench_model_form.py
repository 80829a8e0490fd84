"""How far eq. 17's closed form is from a model it did not make: the model-form error of the force ratio.

The stationary analysis reads kappa = f nu/(1 - nu) from the level ratio F_eo/F_io through eq. 17
(``r = exp(2 kappa L / R) - 1``), a 1-D closed form: uniform stresses over the section, the lateral
ratio nu/(1 - nu) everywhere. The axisymmetric simulation (plug, sample and tube in r-z,
docs/axisymmetric.md) has none of these assumptions; the ratio it makes differs from the closed
form's by a few per cent, more than the noise's standard error of a window mean (0.3-0.5 %).

This script draws clean tests (both bundled set-ups; f, nu, striker speed, rise time and gauge noise
over the ranges of ``bench_misfit.clean_config``), simulates each in 1-D and in the axisymmetric
simulation, finds the window as ``run`` does, and prints per record the relative error of the
window's level ratio against the closed form's ratio at the true kappa, and of kappa read back
through eq. 17. The root mean square of the axisymmetric records' ratio error is the model-form
term's standard deviation (:data:`friction_uq.likelihood.force_level.RATIO_MODEL_FORM`); the 1-D
records show what the noise and the window alone give.

The seed (11) is not the trust study's (5), whose axisymmetric group then checks the term on
records it was not set on.

    python benchmarks/bench_model_form.py [--n 40] [--seed 11]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_misfit import clean_config  # noqa: E402
from bench_trust import _axisymmetric, make_record  # noqa: E402

from friction_uq.analysis import prepare  # noqa: E402
from friction_uq.errors import FrictionUQError  # noqa: E402
from friction_uq.likelihood.force_level import LevelForceTerm  # noqa: E402
from friction_uq.physics import cell  # noqa: E402
from friction_uq.record import read_record  # noqa: E402


def ratio_error(path: str, f: float, nu: float) -> tuple[float, float, float]:
    """(relative error of the level ratio, of kappa through eq. 17, the ratio's noise standard error relative
    to it) of one record against the closed form at the true f and nu."""
    d = prepare(read_record(path)).data
    term = LevelForceTerm(d)
    r_true = float(cell.force_ratio(f, nu, radius=d.radius, length=d.length))
    k_hat = float(cell.kappa_from_ratio(term.r0, radius=d.radius, length=d.length))
    se = float(term.scale(term.r0)) / term.mean_io / term.r0
    return term.r0 / r_true - 1.0, k_hat / float(cell.kappa(f, nu)) - 1.0, se


def study(n: int, seed: int) -> dict[str, list[tuple[float, float, float]]]:
    rng = np.random.default_rng(seed)
    out: dict[str, list[tuple[float, float, float]]] = {"1-D": [], "axisymmetric": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(n):
            cfg = clean_config(rng, "A" if k % 2 == 0 else "B")
            f, nu = float(cfg.friction_params["f"]), float(cfg.poisson_ratio)
            line = [f"{k:3d} set-up {'AB'[k % 2]} f {f:.3f} nu {nu:.3f} V {cfg.striker_velocity:5.1f} m/s"]
            for label, c in (("1-D", cfg), ("axisymmetric", _axisymmetric(cfg, rng))):
                path = os.path.join(tmp, f"r{k}.h5")
                t = time.perf_counter()
                make_record(c, path, int(rng.integers(2**31)), None, rng)
                try:
                    e = ratio_error(path, f, nu)
                except FrictionUQError as exc:
                    line.append(f"{label}: refused ({exc})")
                    continue
                out[label].append(e)
                line.append(f"{label}: ratio {100 * e[0]:+5.2f} % kappa {100 * e[1]:+5.2f} % (se {100 * e[2]:.2f} %, "
                            f"{time.perf_counter() - t:.1f} s)")
            print("; ".join(line), flush=True)
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--seed", type=int, default=11)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = study(a.n, a.seed)
    print(f"\n{'simulation':<13} {'records':>7} {'ratio error: mean':>18} {'sd':>6} {'rms':>6} {'|e| 90 %':>9} "
          f"{'max |e|':>8} {'kappa error: mean':>18} {'noise se (median)':>18}")
    for label, rows in res.items():
        if not rows:
            continue
        e = np.array(rows)
        rms = math.sqrt(float(np.mean(e[:, 0] ** 2)))
        print(f"{label:<13} {len(e):>7} {100 * e[:, 0].mean():>17.2f}% {100 * e[:, 0].std(ddof=1):>5.2f}% "
              f"{100 * rms:>5.2f}% {100 * np.quantile(np.abs(e[:, 0]), 0.9):>8.2f}% {100 * np.abs(e[:, 0]).max():>7.2f}% "
              f"{100 * e[:, 1].mean():>17.2f}% {100 * np.median(e[:, 2]):>17.2f}%")
    print(f"\nseed {a.seed}, {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
