"""Speed and memory of the simulator: one noise-free 1.2 ms record at 5 MHz.

    python benchmarks/bench_simulate.py [--repeat N]

Prints one table row per case: median and best wall time over ``--repeat`` runs after one warm-up
run (numba compilation or cache loading, and the dispersion curve's root finding, happen there),
and the peak of Python-tracked memory (tracemalloc, numpy buffers included) during one run.
Target for the base physics: <= 20 ms on the project's 2-core machine.
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc
from dataclasses import replace
from types import MappingProxyType

from friction_uq.simulate import SimulationConfig, run_model, simulate
from friction_uq._jit import HAVE_NUMBA

BASE = SimulationConfig(duration=1.2e-3, pretrigger=80e-6, sample_rate=5e6)
CASES = {
    "base (Coulomb, 20 elements)": BASE,
    "base, dispersion on": replace(BASE, dispersion=True),
    "all options (velocity law, gap, compliant tube, plug friction)": replace(
        BASE, friction_law="velocity", friction_params=MappingProxyType({"f_s": 0.075, "f_d": 0.035, "v_c": 8.0}),
        gap=8e-6, tube_compliance=True, plug_friction_force=150.0),
    "base, 40 elements": replace(BASE, elements=40),
}


def measure(cfg: SimulationConfig, repeat: int, *, noisy: bool = False) -> tuple[float, float, float]:
    run = (lambda: simulate(cfg, seed=1)) if noisy else (lambda: run_model(cfg))
    run()  # warm-up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    tracemalloc.start()
    run()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return statistics.median(times) * 1e3, min(times) * 1e3, peak / 2**20


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    print(f"numba: {'yes' if HAVE_NUMBA else 'NO (pure Python fallback)'}; record 1.2 ms at 5 MHz = 6000 samples")
    print(f"{'case':<66} {'median ms':>10} {'best ms':>8} {'peak MiB':>9}")
    for name, cfg in CASES.items():
        med, best, peak = measure(cfg, args.repeat)
        print(f"{name:<66} {med:10.2f} {best:8.2f} {peak:9.2f}")
    med, best, peak = measure(BASE, args.repeat, noisy=True)
    print(f"{'base + measurement noise (simulate)':<66} {med:10.2f} {best:8.2f} {peak:9.2f}")


if __name__ == "__main__":
    main()
