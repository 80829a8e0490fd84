"""A run of equal samples at a channel's peak: a saturated amplifier or digitiser, or a plateau on one code.

A channel that saturates sits on one value, its rail, for as long as the signal would exceed it.
A plateau read by a coarse digitiser (an 8-bit scope) also sits on one value, a digitiser code,
when the noise is smaller than one code: the record does not say where the digitiser's range
ends, so a run of equal samples tells a rail from a code only through the noise, as the
pre-trigger shows it (its first 2 %, spikes left out, cut where the pulse's front begins). The
chance p that the noise keeps a sample on its code is taken as the larger of

* erf(q / (2 sqrt(2) sigma)), white noise of sd sigma (the pre-trigger's, less the rounding:
  Sheppard's correction, or at least what its samples off the commonest code say) on codes q wide,
  its mean at a code's centre (where runs are likeliest);
* the pre-trigger's own share of neighbouring samples on one code, at its 95 % upper bound
  (coloured noise stays longer than white noise of its sd);

and a run of L equal samples anywhere among n is the noise's doing with a chance of about
n p^(L - 1). A run is **saturated** when that chance is below :data:`RUN_ALPHA` and the run is at
least :data:`~friction_uq.record.contract.CLIP_RUN` long; a shorter one at least ``CLIP_RUN``
long is **undecided** (a plateau or a rail, the noise cannot tell), and so is every run of a
channel whose pre-trigger holds two values or fewer (its noise not resolved): the reader refuses
the first, the analysis warns of the second (:func:`friction_uq.gauge_check.flat_run_findings`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats
from scipy.special import erf

from ..stats.robust import despiked, longest_true_run, median_and_sd, padding, quantisation_step
from .contract import CLIP_RUN, HEAD_FRACTION, MIN_HEAD_SAMPLES

#: Chance, at most, that the noise alone leaves a run of equal samples as long as one called saturated.
RUN_ALPHA = 1e-3
@dataclass(frozen=True)
class FlatRun:
    """The longest run of equal samples at a channel's peak value, and what its noise makes of it."""

    run: int  # samples
    value: float  # the value they sit at (the channel's units)
    side: str  # "maximum" or "minimum"
    step: float  # the digitiser's step, from the gaps between the channel's distinct values
    noise_steps: float  # the pre-trigger noise's sd in steps
    needed: float  # run length the noise makes with a chance below RUN_ALPHA (inf: the noise cannot tell)

    @property
    def saturated(self) -> bool:
        return self.run >= self.needed


def digitiser_step(x: np.ndarray) -> float:
    """The channel's step: the median gap between its neighbouring distinct values (0 with one value)."""
    gaps = np.diff(np.unique(x))
    gaps = gaps[gaps > 0]
    return float(np.median(gaps)) if gaps.size else 0.0


def run_needed(stay: float, n: int) -> float:
    """Least run of equal samples that a noise keeping a sample on its code with chance ``stay`` leaves among ``n``
    samples with a chance below :data:`RUN_ALPHA` (never below ``CLIP_RUN``; inf when it never leaves)."""
    if stay >= 1.0:
        return math.inf
    if stay <= 0.0:
        return float(CLIP_RUN)
    return max(float(CLIP_RUN), 1.0 + math.ceil(math.log(RUN_ALPHA / max(n, 1)) / math.log(stay)))


def stay_chance(head: np.ndarray, step: float) -> float:
    """The chance that the pre-trigger's noise keeps a sample on its code (module docstring); 1 when its noise is
    not resolved (two values or fewer), 0 when the channel is not quantised (``step`` 0)."""
    if step <= 0.0:
        return 0.0
    if np.unique(head).size <= 2:
        return 1.0
    sd = resolved_sd(head, step)
    white = float(erf(step / (2.0 * math.sqrt(2.0) * sd))) if sd > 0.0 else 1.0
    same = int(np.count_nonzero(head[1:] == head[:-1]))
    seen = float(stats.beta.ppf(0.95, same + 1, head.size - 1 - same + 1))
    return max(white, seen)


def resolved_sd(head: np.ndarray, step: float) -> float:
    """The pre-trigger noise's sd as the run test takes it: the larger of the rounding-corrected sd
    (:func:`noise_sd`) and the least sd that leaves as many samples off the commonest code (at its 5 % lower
    bound; the noise's mean at the code's centre): a noise well below one code has a corrected sd of 0, though
    the samples it moves off the code say how large it is."""
    if step <= 0.0:
        return noise_sd(head, step)
    _, counts = np.unique(head, return_counts=True)
    off = int(head.size - counts.max())
    floor = 0.0
    if off > 0:
        p_low = float(stats.beta.ppf(0.05, off, head.size - off + 1))
        floor = step / (2.0 * float(stats.norm.isf(p_low / 2.0)))
    return max(noise_sd(head, step), floor)


def pre_trigger(x: np.ndarray) -> np.ndarray:
    """The channel's first :data:`HEAD_FRACTION` (at least :data:`MIN_HEAD_SAMPLES`) after its padding (an unfilled
    pre-trigger: :func:`friction_uq.stats.robust.padding`), spikes left out, cut where it first departs from its
    first samples' median by a tenth of the channel's swing (a pulse's front in it)."""
    lead = padding(x)
    x = x[lead:]
    n0 = min(x.size, max(MIN_HEAD_SAMPLES, int(HEAD_FRACTION * x.size)))
    med, _ = median_and_sd(x[:MIN_HEAD_SAMPLES])
    swing = float(np.max(np.abs(x - med)))
    off = np.flatnonzero(np.abs(x[:n0] - med) > 0.1 * swing)
    head = x[: max(MIN_HEAD_SAMPLES, int(off[0]) if off.size else n0)]
    return despiked(head, step=quantisation_step(x))


def flat_run(x: np.ndarray) -> FlatRun | None:
    """The longest run of at least ``CLIP_RUN`` equal samples at the extreme the pulse reaches, or None.

    None too for a channel whose pre-trigger is noise-free (a synthetic record): there a plateau is
    exactly flat and nothing tells a rail from it.
    """
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return None
    head = pre_trigger(x)
    if np.ptp(head) == 0.0:
        return None
    median = float(np.median(x))
    swing = float(np.max(np.abs(x - median)))
    found = None
    for extreme, side in ((float(x.max()), "maximum"), (float(x.min()), "minimum")):
        if abs(extreme - median) < 0.5 * swing:
            continue  # the extreme of the side the pulse does not reach: baseline noise
        start, stop = longest_true_run(x == extreme)
        run = stop - start
        if run >= CLIP_RUN and (found is None or run > found.run):
            step = digitiser_step(x)
            sd = resolved_sd(head, step) if np.unique(head).size > 2 else 0.0
            found = FlatRun(run, extreme, side, step, sd / step if step > 0 else math.inf,
                            run_needed(stay_chance(head, step), x.size))
    return found


def noise_sd(head: np.ndarray, step: float) -> float:
    """The noise's sd from the pre-trigger, less the digitiser's rounding (Sheppard's correction, s^2 - q^2 / 12);
    0 when the pre-trigger holds two values or fewer (a noise below one code, toggling one code boundary or none:
    its sd is not resolved)."""
    if np.unique(head).size <= 2:
        return 0.0
    return math.sqrt(max(float(np.var(head)) - step**2 / 12.0, 0.0))
