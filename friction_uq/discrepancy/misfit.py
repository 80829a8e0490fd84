"""The misfit decision: does the fitted model miss something on a channel in a phase?

Statistic. For each channel c and phase (rise, stationary, unloading) of the whole-record
comparison (:mod:`.whole_record`), the residual is first shrunk by a model tolerance: the part of
each residual sample within the tolerated model error tol_t is forgiven,

    e'_t = e_t - clip(e_t, -tol_t, +tol_t),

tol_t from :func:`~.whole_record.tolerance_sd`: 1 % of the signal on the bar gauges (the accuracy
of a bar gauge's calibration and of the bar's E and c), 3 % on the tube hoop gauge (the fit error
of its influence function, docs/physics.md section 6), and a timing tolerance times the local slope
(the timing of a front): 0.2 us, except where :data:`CHECK_TOLERANCE` says otherwise.

Tolerance per channel and phase. Set on the 1-D simulator's records, these flagged 11 of 40 clean
records of the axisymmetric simulation (plug, sample and tube in r-z): the input bar's rise and
unloading (the plug's impact and rebound, which the 1-D model's rigid plug makes sharper) and the
internal output bar's rise (the wave through an elastic sample in r-z arrives with another front).
A timing tolerance of 0.5 us on those three fronts, the timing a gauge's position or a trigger's
skew may carry, is :data:`CHECK_TOLERANCE` (the grid search ``benchmarks/bench_check_tolerance.py``
on 40 records, seed 11, and 40 more, seed 43, which moved the input bar's rise from 0.3 to 0.5 us).

Threshold per cell. Every cell is tested at :data:`THRESHOLD` except one, which has its own, lower,
threshold (:data:`CELL_THRESHOLD`): the first half of the external output bar's rise. A force that
reaches the tube without passing through the sample (a plug rubbing on the tube) adds to F_eo in the
stationary phase exactly as wall friction does, so eq. 17 reads it as a higher f and nothing in that
phase can tell; it shows as an external force that leads the sample's, early in the rise, before the
wall friction builds. So the external bar's rise is tested as two halves in time (:data:`SPLIT_RISE`:
"early rise" and "late rise"; over the whole rise the lead is diluted by the half where the fitted,
too high, f over-predicts), and the early half at 2.5 (about the 1-2 % point of a single cell's
statistic under the noise model, chosen before the records below); the late half keeps 5 (at 2.5 it
flagged 2 of 80 clean axisymmetric records and no plug friction the early half missed). Tested at 5
with the other cells over the whole rise, the 1-D simulation's plug friction was seen mostly through
the input bar's unloading, the very front the tolerance table forgives. ``benchmarks/bench_check_cells.py``
(seeds 41, 43, 47): the early half stayed under 1.6 on 40 clean records of the 1-D simulation and 40 of
it perturbed (mesh, hoop kernel, pulse, coloured noise, a channel's timing), and went over 2.5 on 3 of
80 of the axisymmetric one; plug friction of 200-400 N + 1-2 % of F_i went over it on 40 of 40 records
of the 1-D simulation and 35 of 40 of the axisymmetric one. With the table and this threshold the check
flags 6 of those 80 clean axisymmetric records (7.5 %), where the channels' tolerances at one threshold
flagged 24, and plug friction on 40 and 36 of 40 (27 and 28 before); docs/trust.md gives the tables.

On e' two standardised figures are formed:

* the level z = mean(e') / se, se^2 the variance of an AR(1) mean (long-run variance), of the
  offset error of the pre-pulse mean and of the phase mean of the prediction over the posterior
  draws;
* the shape z = (q - n) / sqrt(2 n), q = e'^T (S + U U^T)^-1 e' with S the AR(1) noise covariance
  (lag-1 coefficient of the pre-pulse noise) and U the centred predictions of the posterior draws
  over sqrt(ndraw - 1): the posterior predictive covariance, so that what the posterior leaves
  uncertain (the rise depends on nu through the sample's confined modulus, for instance) is not
  taken for a misfit. With D the AR(1) whitening operator, w = D e' and B = D U,
  q = |w|^2 - b^T (I + B^T B)^-1 b, b = B^T w (Woodbury). Under "the model is right" q is about
  chi-square with n degrees of freedom, so the shape z is about N(0, 1) for large n.

A cell's statistic is the larger of |level z| and shape z; "misfit" when a cell's exceeds its threshold
(:func:`cell_threshold`), and the cells over theirs are named, the furthest over (statistic over
threshold) first. The record's statistic and threshold are that cell's, so that a record reads
"statistic 2.7 > 2.5" when only the external bar's early rise is over, while another cell may stand at
4.9 under its 5. The threshold 5 was set on simulated clean records (Coulomb friction, no hidden effect,
f, nu, striker speed and noise levels drawn over their ranges, both bundled set-ups) for a false
alarm rate of at most 5 %; ``benchmarks/bench_misfit.py`` measures the rate and the detection
rate of each hidden effect.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..stats.ar1 import ar1_mean_sd
from .whole_record import (
    CHANNEL_LABELS,
    phases_of,
    WholeRecord,
    compare_whole_record,
    tolerance_sd,
    whiten,
)

#: Decision threshold on the statistic (standard-normal units).
THRESHOLD = 5.0
#: The check's model tolerance where a channel's over a phase differs from its own: (channel, phase) ->
#: (relative tolerance, timing tolerance in s), set on clean records of the axisymmetric simulation (module docstring).
CHECK_TOLERANCE: dict[tuple[str, str], tuple[float, float]] = {
    ("input_bar", "rise"): (0.01, 0.5e-6),
    ("input_bar", "unloading"): (0.01, 0.5e-6),
    ("internal_output_bar", "rise"): (0.01, 0.5e-6),
}
#: The threshold of a cell where it differs from :data:`THRESHOLD`: the one place a force that bypasses the
#: sample shows (module docstring).
CELL_THRESHOLD: dict[tuple[str, str], float] = {("external_output_bar", "early rise"): 2.5}
#: Channels whose rise is tested as two halves in time, "early rise" and "late rise": a force that bypasses the
#: sample leads the wall friction, so it sits in the first half, where a test over the whole rise dilutes it.
SPLIT_RISE = ("external_output_bar",)


def cell_threshold(channel: str, phase: str) -> float:
    """The threshold of one channel over one phase: :data:`CELL_THRESHOLD`'s, else :data:`THRESHOLD`."""
    return CELL_THRESHOLD.get((channel, phase), THRESHOLD)


@dataclass(frozen=True)
class CellTest:
    """Level and shape z of one channel and phase, after the model tolerance."""

    channel: str
    phase: str
    level_z: float
    shape_z: float
    relative_level: float
    chi2_dof: float = float("nan")
    threshold: float = THRESHOLD

    @property
    def statistic(self) -> float:
        return max(abs(self.level_z), self.shape_z)

    @property
    def excess(self) -> float:
        """The statistic over the cell's threshold: a misfit above 1."""
        return self.statistic / self.threshold

    @property
    def over(self) -> bool:
        """The cell's statistic exceeds its threshold."""
        return self.statistic > self.threshold

    def to_json(self) -> dict[str, float | str]:
        return {"channel": self.channel, "phase": self.phase, "level_z": self.level_z, "shape_z": self.shape_z,
                "statistic": self.statistic, "threshold": self.threshold, "relative_level": self.relative_level,
                "chi2_dof": self.chi2_dof}


@dataclass(frozen=True)
class MisfitDecision:
    """The record's misfit statistic, the decision and the cells behind it."""

    statistic: float
    threshold: float
    cells: tuple[CellTest, ...]

    @property
    def detected(self) -> bool:
        return self.statistic > self.threshold

    @property
    def worst(self) -> CellTest | None:
        """The cell furthest over (or nearest to) its threshold."""
        return max(self.cells, key=lambda c: c.excess) if self.cells else None

    def flagged(self) -> list[CellTest]:
        """Cells over their threshold, furthest over first."""
        return sorted((c for c in self.cells if c.over), key=lambda c: -c.excess)

    def sentence(self, *, page: int | None = None) -> str:
        """One line for the summary page and the terminal; ``page``: the report's first whole-record page (two
        channels a page, in :data:`CHANNEL_LABELS`' order), from which the worst channel's page is said."""
        if not self.detected:
            n = len({c.channel for c in self.cells})
            return (f"The model reproduces all {n} gauges within their noise over the whole loading "
                    f"(misfit statistic {self.statistic:.1f} <= {self.threshold:g}).")
        w = self.worst
        assert w is not None
        drawn = [c for c in CHANNEL_LABELS if any(x.channel == c for x in self.cells)]
        where = f": see page {page + drawn.index(w.channel) // 2}" if page is not None else ""
        more = len(self.flagged()) - 1
        also = f"; {more} more channel/phase pairs over their thresholds" if more > 0 else ""
        if abs(w.level_z) >= w.shape_z:
            direction = "above" if w.relative_level > 0 else "below"
            what = (f"is {abs(w.relative_level) * 100:.1f} % {direction} the model over the {w.phase} phase "
                    f"(level z {w.level_z:+.1f}")
        else:
            what = (f"departs from the model's shape over the {w.phase} phase (chi2/dof {w.chi2_dof:.1f}, "
                    f"shape z {w.shape_z:.0f}")
        return f"The {CHANNEL_LABELS[w.channel]} gauge {what}; threshold {w.threshold:g}){also}{where}."

    def to_json(self) -> dict[str, object]:
        return {"detected": self.detected, "statistic": self.statistic, "threshold": self.threshold,
                "worst": self.worst.to_json() if self.worst else None,
                "cells": [c.to_json() for c in self.cells]}


def tolerated(resid: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """The residual less what lies within ``tol`` of zero (module docstring)."""
    return resid - np.clip(resid, -tol, tol)


def predictive_quadratic(e: np.ndarray, draws: np.ndarray, *, sd: float, rho: float) -> float:
    """e^T (S + U U^T)^-1 e for AR(1) covariance S and the draws' centred predictions U (module docstring)."""
    w = whiten(e, sd=sd, rho=rho)
    q = float(w @ w)
    if len(draws) < 2:
        return q
    U = (draws - draws.mean(axis=0)).T / math.sqrt(len(draws) - 1)  # (n, ndraw)
    B = np.column_stack([whiten(u, sd=sd, rho=rho) for u in U.T])
    b = B.T @ w
    return q - float(b @ np.linalg.solve(np.eye(B.shape[1]) + B.T @ B, b))


def check_tolerance(channel: str, phase: str) -> tuple[float | None, float | None]:
    """The check's (relative, timing) model tolerance on one channel over one phase: :data:`CHECK_TOLERANCE`
    where it was set on records the 1-D model did not make, else the channel's (``None``: those of
    :func:`~.whole_record.tolerance_sd`)."""
    return CHECK_TOLERANCE.get((channel, phase), (None, None))


def channel_tolerance(wr: WholeRecord, channel: str, *, relative: float | None = None,
                      timing: float | None = None) -> np.ndarray:
    """The tolerance over the whole channel (its 2 us filters see across the phase edges), strain."""
    fs = 1.0 / float(wr.time[1] - wr.time[0])
    return tolerance_sd(wr.measured[channel], channel, sample_rate=fs, relative=relative, timing=timing)


def cell_test(wr: WholeRecord, channel: str, phase: str, a: int, b: int, *, relative: float | None = None,
              timing: float | None = None, tolerance: np.ndarray | None = None) -> CellTest:
    """Level and shape z of ``channel`` over samples [a, b) (``phase``), with the relative tolerance ``relative``
    and the timing tolerance ``timing`` (s) (None: the channel's, :func:`~.whole_record.tolerance_sd`), or the
    channel's tolerance ``tolerance`` computed already (:func:`channel_tolerance`)."""
    resid = wr.measured[channel][a:b] - wr.predicted[channel][:, a:b].mean(axis=0)
    if tolerance is None:
        tolerance = channel_tolerance(wr, channel, relative=relative, timing=timing)
    tol = tolerance[a:b]
    nz = wr.noise[channel]
    n = b - a
    e = tolerated(resid, tol)
    draws = wr.predicted[channel][:, a:b]
    spread = float(np.var(draws.mean(axis=1), ddof=1)) if len(draws) > 1 else 0.0
    se = math.sqrt(ar1_mean_sd(nz.sd, nz.rho_long_run, n) ** 2 + nz.offset_sd**2 + spread)
    shape = (predictive_quadratic(e, draws, sd=nz.sd, rho=nz.rho) - n) / math.sqrt(2.0 * n)
    m_meas = float(np.mean(wr.measured[channel][a:b]))
    rel = float(np.mean(resid)) / m_meas if abs(m_meas) > 0 else 0.0
    w_plain = whiten(resid, sd=nz.sd, rho=nz.rho)
    return CellTest(channel, phase, float(np.mean(e)) / se, shape, rel, float(np.mean(w_plain**2)),
                    cell_threshold(channel, phase))


def phase_spans(wr: WholeRecord, channel: str) -> list[tuple[str, int, int]]:
    """(phase, first sample, end) of each phase of ``channel`` long enough to test (>= 10 samples); the rise of a
    channel of :data:`SPLIT_RISE` as its two halves in time, "early rise" and "late rise"."""
    i0, iw0, iw1, i3 = wr.phase_bounds[channel]
    spans = [(p, a, b) for p, a, b in phases_of(wr.phase_bounds[channel]) if b - a >= 10]
    if channel in SPLIT_RISE and iw0 - i0 >= 20:
        mid = (i0 + iw0) // 2
        spans = [("early rise", i0, mid), ("late rise", mid, iw0)] + [s for s in spans if s[0] != "rise"]
    return spans


def decide(wr: WholeRecord, *, threshold: float | None = None) -> MisfitDecision:
    """Misfit statistic and decision for a whole-record comparison (module docstring): each cell tested at its own
    threshold (:func:`cell_threshold`), or every cell at ``threshold`` when one is given."""
    if threshold is not None and not threshold > 0:
        raise ValueError(f"a misfit threshold must be positive, not {threshold!r}")
    cells = []
    for ch in wr.phase_bounds:
        tols: dict[tuple[float | None, float | None], np.ndarray] = {}  # one per tolerance the channel's phases use
        for phase, a, b in phase_spans(wr, ch):
            rel, tim = check_tolerance(ch, phase)
            if (rel, tim) not in tols:
                tols[(rel, tim)] = channel_tolerance(wr, ch, relative=rel, timing=tim)
            cells.append(cell_test(wr, ch, phase, a, b, tolerance=tols[(rel, tim)]))
    if threshold is not None:  # one threshold for the whole record replaces every cell's
        cells = [replace(c, threshold=threshold) for c in cells]
    worst = max(cells, key=lambda c: c.excess, default=None)
    return MisfitDecision(statistic=worst.statistic if worst else 0.0,
                          threshold=worst.threshold if worst else (threshold or THRESHOLD), cells=tuple(cells))


def misfit_detected(prep, predicted: dict[str, np.ndarray]) -> bool:
    """Whether the whole-record check flags a model's predicted gauges (channel -> (ndraw, n)) on the record of
    ``prep`` (a :class:`~friction_uq.analysis.Prepared`): the first round's misfit gate, asked again by the swap
    check of the model without a candidate (:mod:`.rival_swaps`)."""
    return decide(compare_whole_record(prep, predicted)).detected
