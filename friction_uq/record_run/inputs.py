"""What a run decides from the record and the prior files before and beside sampling: whether the
hoop gauge can enter the likelihood, the sliding speed's summary, the alternative nu priors."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
from scipy import stats

from ..analysis import Prepared
from ..diagnostics import VariableSummary
from ..gauge_check import hoop_findings
from ..priors import Priors
from ..prior_loader import PRIORS_DIR, load_priors


def sliding_velocity_summary(p: Prepared) -> VariableSummary:
    """V over the window: mean and its standard error, normal quantiles.

    V = V_io - V_eo (eq. 7) is measured, not a model parameter; its uncertainty is the noise of
    the two output gauges averaged over the window (effective AR(1) sample size) plus the error
    of the offsets removed from them (pre-pulse estimates).
    """
    app = p.record.apparatus
    ch = p.forces.channels
    io, eo = app.internal_output_bar, app.external_output_bar
    n_io, n_eo = ch["internal_output_bar"].noise, ch["external_output_bar"].noise
    v = np.asarray(p.data.V, float)
    sd = math.hypot(n_io.window_mean_sd(len(v), scale=io.wave_speed), n_eo.window_mean_sd(len(v), scale=eo.wave_speed))
    m = float(np.mean(v))
    q = stats.norm.ppf([0.05, 0.5, 0.95], loc=m, scale=sd)
    return VariableSummary(m, sd, float(q[0]), float(q[1]), float(q[2]), float("nan"), float("nan"))



def alternative_nu_priors(default_path: Path, priors: Priors) -> dict[str, Priors]:
    """The priors used and the nu alternatives ``<material>-nu-*.toml``.

    Alternatives are looked up beside the prior file used, then among the files shipped in the
    package (:data:`~friction_uq.priors.PRIORS_DIR`; a label found beside the file wins). Each
    keeps the used f (and hoop gain) prior and swaps nu only, so the posteriors of f differ by the
    nu prior alone. A material without alternatives gets none (the report then shows f under the
    one prior used).
    """
    out: dict[str, Priors] = {"default": priors}
    material = priors.material or Path(default_path).stem
    used = Path(default_path).resolve()
    for folder in dict.fromkeys([Path(default_path).resolve().parent, PRIORS_DIR]):
        for alt in sorted(folder.glob(f"{material}-nu-*.toml")):
            label = alt.stem.removeprefix(f"{material}-")
            if alt.resolve() == used or label in out:
                continue
            other = load_priors(alt)
            out[label] = dataclasses.replace(priors.replace(other["nu"]), path=str(alt), description=other.description)
    return out



def hoop_unusable(p: Prepared) -> str | None:
    """Why the hoop gauge cannot enter the likelihood for this record, or None if it can:
    :func:`hoop_fault` (a reversed gauge, another tube) or :func:`hoop_silence` (no pulse, no swelling)."""
    return hoop_fault(p) or hoop_silence(p)


def hoop_fault(p: Prepared) -> str | None:
    """A hoop gauge that reads something other than this model's: the tube contracting through the loading
    (reversed: :func:`~friction_uq.gauge_check.hoop_findings`), or a tube other than the one the influence function
    was fitted to (bore 10 mm, outer 24 mm, nu_t 0.29; docs/physics.md section 6: the kernel would be wrong)."""
    t = p.record.apparatus.tube
    if not (abs(t.inner_diameter - 0.010) < 1e-6 and abs(t.outer_diameter - 0.024) < 1e-6
            and abs(t.poisson_ratio - 0.29) < 1e-3):
        return (f"the tube influence function is fitted to a 10/24 mm tube with nu_t = 0.29, this record's tube is "
                f"{t.inner_diameter * 1e3:g}/{t.outer_diameter * 1e3:g} mm with nu_t = {t.poisson_ratio:g}")
    info = p.forces.channels["tube_hoop"]
    for finding in hoop_findings(p.forces, p.record.apparatus, info.noise.sd):
        if finding.kind == "reversed":  # a reversed gauge's pulse is not "no pulse": say what it is
            return finding.sentence
    return None


def hoop_silence(p: Prepared) -> str | None:
    """Why the hoop gauge reads nothing a swelling tube makes (no pulse above its noise, or no swelling over the
    window), or None. A dead bridge and a sample that hardly swells (nu near 0) read alike."""
    info = p.forces.channels["tube_hoop"]
    if not info.detected:
        return "tube_hoop shows no pulse above its noise (a dead or disconnected gauge?)"
    se = info.noise.window_mean_sd(p.data.n)
    mean = float(np.mean(p.data.hoop))
    if not mean < -3.0 * se:  # compression positive: a swelling tube reads negative
        return (f"tube_hoop shows no swelling over the window (mean {mean * 1e6:+.2f} microstrain, standard "
                f"error {se * 1e6:.2f})")
    return None
