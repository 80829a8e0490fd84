"""Benchmark of the main job: ``friction-uq run`` on a bundled record, end to end with the PDF.

Target (issue 7): <= 5 s wall per record with the PDF on 2 cores, median of 5 runs of the
command as a user starts it (a new process each time, imports included). Prints

1. the command's wall and CPU time (user + sys of the process) for each of the ``--repeat`` runs
   and their median;
2. the breakdown of one in-process run, in this process's order: imports, signals (read, forces,
   window), sampling, the DataTree (pointwise log-likelihood, ESS, R-hat), sensitivity (nu priors by
   PSIS reweighting, prior-data conflict), analysis (the lab's identification), pdf (the posterior's
   pages, then the summary page and the merge), whole_record (what is left to wait of the other
   core's work: the simulator fitted to every gauge, the misfit decision, the record's and the
   check's pages), outputs (netCDF, JSON, renames);
3. ESS of f (bulk and tail; must be >= 2000), ESS per second of sampling, steps, R-hat max.

Beside each run of the command, and taken in turn with it so that both see the same load, a new
interpreter imports the scientific stack the command uses (numpy, scipy, h5py, emcee, arviz,
matplotlib, numba, dask.distributed) and nothing else. The ratio of the two medians is the
target (<= 2.0 with the PDF): it measures what the run adds to the libraries' own start-up, and
holds on a loaded machine where wall times do not.

On a shared machine wall times are noisy: quote CPU time beside them.

    python benchmarks/bench_run.py [RECORD] [--repeat 3] [--no-pdf]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "data" / "A" / "A-03.h5"


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


#: The scientific stack ``run`` uses: importing it in a bare interpreter is the ratio's denominator.
STACK = "import numpy, scipy, scipy.stats, h5py, emcee, arviz, matplotlib.pyplot, numba, dask.distributed"


def stack_import_time() -> tuple[float, float]:
    """(wall, cpu) of a new interpreter that imports :data:`STACK` and exits."""
    c0, t0 = _cpu_children(), time.perf_counter()
    subprocess.run([sys.executable, "-c", STACK], check=True, capture_output=True)
    return time.perf_counter() - t0, _cpu_children() - c0


def command_times(record: Path, repeat: int, pdf: bool) -> list[tuple[float, float, float]]:
    """(wall, cpu, stack import wall) of ``friction-uq run RECORD`` in a new process, ``repeat`` times, each
    beside a bare import of the stack."""
    rows = []
    for k in range(repeat):
        stack, _ = stack_import_time()
        with tempfile.TemporaryDirectory() as out:
            cmd = [sys.executable, "-m", "friction_uq.cli", "run", str(record), "--out", out, "--quiet", "--seed", "1"]
            if not pdf:
                cmd.append("--no-pdf")
            c0, t0 = _cpu_children(), time.perf_counter()
            r = subprocess.run(cmd, capture_output=True, text=True)
            wall, cpu = time.perf_counter() - t0, _cpu_children() - c0
            if r.returncode != 0:
                raise SystemExit(r.stderr)
            rows.append((wall, cpu, stack))
            print(f"run {k + 1}: wall {wall:5.2f} s, cpu {cpu:5.2f} s; importing the stack alone {stack:5.2f} s "
                  f"(ratio {wall / stack:.2f})", flush=True)
    return rows


def breakdown(record: Path, pdf: bool) -> None:
    """Stage times of one in-process run, in a new process (so imports are measured cold)."""
    code = f"""
import time, tempfile
t0 = time.perf_counter()
from friction_uq.record_run import run_file
{'import friction_uq.report.pdf' if pdf else ''}
imports = time.perf_counter() - t0
import arviz_stats, xarray as xr
with tempfile.TemporaryDirectory() as out:
    res = run_file({str(record)!r}, out_dir=out, seed=1, pdf={pdf}, progress=False, table=False, notes=False)
    dt = xr.open_datatree(res.outputs["netcdf"], engine="h5netcdf")
    bulk = float(arviz_stats.ess(dt, var_names=["f"], method="bulk")["f"].values)
    tail = float(arviz_stats.ess(dt, var_names=["f"], method="tail")["f"].values)
st = dict(imports=imports, **res.stages)
print()
print("stage        seconds")
for k in ("imports", "signals", "sampling", "datatree", "sensitivity", "analysis", "whole_record", "outputs", "pdf"):
    print(f"{{k:<12}} {{st.get(k, 0.0):7.2f}}")
print(f"{{'sum':<12}} {{sum(st.values()):7.2f}}")
print()
s = res.samples
print(f"steps {{s.n_steps}} x {{s.nwalkers}} walkers x {{s.n_chains}} ensembles, tau max {{s.tau.max():.1f}}, "
      f"draws {{s.n_chains * s.n_draws}}; ESS of f: bulk {{bulk:.0f}}, tail {{tail:.0f}} (needs >= 2000); "
      f"{{bulk / s.seconds:.0f}} ESS/s of sampling; R-hat max {{res.convergence.r_hat_max:.4f}}")
print("nu priors: " + ", ".join(f"{{k}} {{v.method}} (k {{v.pareto_k:.2f}})" for k, v in res.sensitivity.items()))
"""
    # as the command runs: one BLAS thread per process (friction_uq.cli.console)
    from friction_uq.cli import BLAS_THREADS

    env = {**os.environ, **{v: os.environ.get(v, "1") for v in BLAS_THREADS}}
    subprocess.run([sys.executable, "-c", code], check=True, env=env)


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("record", nargs="?", type=Path, default=DEFAULT)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-pdf", action="store_true")
    a = ap.parse_args(argv)
    pdf = not a.no_pdf
    print(f"friction-uq run {a.record.name}{'' if pdf else ' --no-pdf'}: {a.repeat} runs, each a new process")
    rows = command_times(a.record, a.repeat, pdf)
    wall, cpu, stack = (statistics.median(r[i] for r in rows) for i in range(3))
    print(f"median: wall {wall:.2f} s, cpu {cpu:.2f} s; the stack's import alone {stack:.2f} s; "
          f"ratio {wall / stack:.2f} (target with the PDF: <= 2.0)")
    breakdown(a.record, pdf)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
