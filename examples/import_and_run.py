"""From an oscilloscope CSV to a figure for a paper, in Python.

1. import the bundled scope export (``data/scope/A-03_scope.csv``, described by
   ``data/scope/SETUP.toml``) into a test record, as ``friction-uq import`` does;
2. run the analysis (``friction_uq.run``): the posterior of f and nu, written as JSON and netCDF;
3. open the posterior in ArviZ (``Result.datatree()`` is an ``xarray.DataTree``) for a summary table;
4. draw one figure: the joint posterior of nu and f, and the posterior of f with its 90 % interval.

    python examples/import_and_run.py [--out reports/example]

Takes about half a minute on two cores. Replace the CSV and SETUP.toml by your own to do the same
with your test (docs/import.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCOPE_CSV = ROOT / "data" / "scope" / "A-03_scope.csv"
SETUP = ROOT / "data" / "scope" / "SETUP.toml"


def main(out: Path) -> Path:
    import arviz as az
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    import friction_uq as fu

    out.mkdir(parents=True, exist_ok=True)
    imported = fu.import_scope_files([SCOPE_CSV], SETUP, out / "A-03.h5")
    print(f"imported {imported.path} ({imported.n_samples} samples at {imported.sample_rate / 1e6:g} MHz)")

    res = fu.run(imported.path, out_dir=out, pdf=False)
    f = res.f
    print(f"f = {f['q50']:.4f} (90 % interval {f['q05']:.4f} to {f['q95']:.4f}), from {f['model']}")
    for w in res.warnings:
        print(f"warning: {w}")

    dt = res.datatree()
    print(az.summary(dt, var_names=["f", "nu", "kappa"], ci_prob=0.9, ci_kind="eti", round_to="none"))

    post = dt["posterior"]
    f_draws, nu_draws = post["f"].values.ravel(), post["nu"].values.ravel()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(7.0, 2.8), layout="constrained")
    ax1.plot(nu_draws, f_draws, ".", ms=1.5, alpha=0.3, color="C0", rasterized=True)
    ax1.set(xlabel=r"Poisson ratio $\nu$", ylabel="friction coefficient $f$", title="(a) joint posterior")
    bins = np.linspace(*np.quantile(f_draws, [0.001, 0.999]), 60)
    ax2.hist(f_draws, bins=bins, density=True, color="C0", alpha=0.6)
    for q in (f["q05"], f["q95"]):
        ax2.axvline(q, color="k", lw=0.8, ls="--")
    ax2.set(xlabel="friction coefficient $f$", ylabel="density", title="(b) $f$, 90 % interval dashed")
    fig.suptitle(f"test {res.test_id}: f = {f['q50']:.3f} [{f['q05']:.3f}, {f['q95']:.3f}]", fontsize=10)
    path = out / "A-03_f_nu.pdf"
    fig.savefig(path)
    plt.close(fig)
    print(f"wrote {path}")
    return path


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("reports") / "example")
    main(ap.parse_args().out)
