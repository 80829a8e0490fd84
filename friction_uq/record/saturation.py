"""A run of equal samples at a channel's peak: a saturated amplifier or digitiser, or a plateau on one code.

A channel that saturates sits on one value, its rail, for as long as the signal would exceed it.
A plateau read by a coarse digitiser (an 8-bit scope) also sits on one value, a digitiser code,
when the noise is smaller than one code: the record does not say where the digitiser's range
ends, so a run of equal samples tells a rail from a code only through the noise, resolved by the
pre-trigger when it spans three codes or more (:func:`noise_sd`). A noise of sd sigma on codes q wide keeps a sample in its code with probability at most

    p = erf(q / (2 sqrt(2) sigma))      (the code centred on the noise's mean),

so a run of L equal samples anywhere among n is the noise's doing with probability at most about
n p^(L - 1) (white noise). A run is **saturated** when that chance is below :data:`RUN_ALPHA`
and the run is at least :data:`~friction_uq.record.contract.CLIP_RUN` long; a shorter one at
least ``CLIP_RUN`` long is **undecided** (a plateau or a rail, the noise cannot tell): the reader
refuses the first, the analysis warns of the second (:func:`flat_runs`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import erf

from .contract import CLIP_RUN

#: Chance, at most, that the noise alone leaves a run of equal samples as long as one called saturated.
RUN_ALPHA = 1e-3
#: Fraction of the record, at least 32 samples, read at its start for the noise (the pre-trigger).
HEAD_FRACTION = 0.02


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


def run_needed(noise_sd: float, step: float, n: int) -> float:
    """Least run of equal samples that white noise of sd ``noise_sd`` on codes ``step`` wide leaves among ``n``
    samples with a chance below :data:`RUN_ALPHA` (never below ``CLIP_RUN``; inf when one code holds the noise)."""
    if step <= 0.0:
        return float(CLIP_RUN)
    if noise_sd <= 0.0:
        return math.inf
    p = float(erf(step / (2.0 * math.sqrt(2.0) * noise_sd)))
    if p >= 1.0:
        return math.inf
    return max(float(CLIP_RUN), 1.0 + math.ceil(math.log(RUN_ALPHA / max(n, 1)) / math.log(p)))


def longest_run(mask: np.ndarray) -> int:
    if not mask.any():
        return 0
    padded = np.concatenate(([0], mask.astype(np.int8), [0]))
    edges = np.flatnonzero(np.diff(padded))
    return int((edges[1::2] - edges[0::2]).max())


def flat_run(x: np.ndarray) -> FlatRun | None:
    """The longest run of at least ``CLIP_RUN`` equal samples at the extreme the pulse reaches, or None.

    None too for a channel whose pre-trigger is noise-free (a synthetic record): there a plateau is
    exactly flat and nothing tells a rail from it.
    """
    x = np.asarray(x, dtype=float)
    head = x[: max(32, int(HEAD_FRACTION * x.size))]
    if x.size == 0 or np.ptp(head) == 0.0:
        return None
    median = float(np.median(x))
    swing = float(np.max(np.abs(x - median)))
    found = None
    for extreme, side in ((float(x.max()), "maximum"), (float(x.min()), "minimum")):
        if abs(extreme - median) < 0.5 * swing:
            continue  # the extreme of the side the pulse does not reach: baseline noise
        run = longest_run(x == extreme)
        if run >= CLIP_RUN and (found is None or run > found.run):
            step = digitiser_step(x)
            sd = noise_sd(head, step)
            found = FlatRun(run, extreme, side, step, sd / step if step > 0 else math.inf,
                            run_needed(sd, step, x.size))
    return found


def noise_sd(head: np.ndarray, step: float) -> float:
    """The noise's sd from the pre-trigger, less the digitiser's rounding (Sheppard's correction, s^2 - q^2 / 12);
    0 when the pre-trigger holds two values or fewer (a noise below one code, toggling one code boundary or none:
    its sd is not resolved)."""
    if np.unique(head).size <= 2:
        return 0.0
    return math.sqrt(max(float(np.var(head)) - step**2 / 12.0, 0.0))
