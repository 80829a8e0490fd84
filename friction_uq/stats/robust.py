"""Robust statistics of a baseline: its median and scale, and its spikes left out.

A pre-pulse baseline is Gaussian noise (white or coloured) plus, in a laboratory, the odd spike of
pick-up (a trigger, a valve, a relay): a sample far from its neighbours. A spike is told from the
noise by its distance from the running median of its neighbours, in units of a robust scale of
those distances. The residuals that are exactly zero (the sample *is* its window's median: one in
``width`` of continuous data, most of data quantised more coarsely than its noise) are left out of
that scale, or they would shrink it to nothing and make the noise look like spikes.
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.ndimage import median_filter

#: Normal sd per median absolute deviation.
MAD_SD = 1.4826
#: Width (samples) of the running median through which spikes are seen: a spike of up to half as many samples (less
#: one) is passed over, a monotone front is kept as it is.
SPIKE_FILTER = 7
#: A baseline sample further than this many robust sd from its running median is a spike, not noise.
SPIKE_SIGMAS = 8.0


def median_and_sd(x: np.ndarray) -> tuple[float, float]:
    """Median and median absolute deviation (as a normal sd) of ``x``."""
    x = np.asarray(x, dtype=float)
    med = float(np.median(x))
    return med, MAD_SD * float(np.median(np.abs(x - med)))


def running_median(x: np.ndarray, width: int) -> np.ndarray:
    """Centred running median over ``width`` samples (the ends repeat the edge sample); ``x`` if shorter."""
    x = np.asarray(x, dtype=float)
    return median_filter(x, width, mode="nearest") if x.size >= width else x


def despiked(seg: np.ndarray, *, width: int = SPIKE_FILTER, sigmas: float = SPIKE_SIGMAS,
             step: float = 0.0) -> np.ndarray:
    """``seg`` with its spikes (samples more than ``sigmas`` robust sd from their running median of ``width``)
    replaced by that median; ``seg`` itself when it has none.

    ``step``: the digitiser's step when the channel is quantised (0: not known). A baseline quantised more coarsely
    than its noise sits on one code but for a few samples; when fewer than ``2 width`` samples leave their running
    median, they may all be a spike's, and the scale is then at most one step (a sample one code off its neighbours is
    noise, one 12 codes off is not), not the spike's own size.
    """
    seg = np.asarray(seg, dtype=float)
    if seg.size < width:
        return seg
    running = running_median(seg, width)
    r = seg - running
    moved = np.abs(r[r != 0.0])
    if moved.size == 0:
        return seg
    scale = float(np.median(moved))
    if step > 0.0 and moved.size < 2 * width:
        scale = min(scale, step)
    spikes = np.abs(r) > sigmas * MAD_SD * scale
    return np.where(spikes, running, seg) if spikes.any() else seg


#: Share of a channel's gaps between neighbouring distinct values that must be whole multiples of the smallest for
#: the channel to be read as quantised (continuous data: about a tenth by chance).
LATTICE_SHARE = 0.9
#: How far from a whole multiple a gap may be (in steps): float32 storage rounds a value 2**15 steps from 0 by 0.002.
LATTICE_SLACK = 0.02


def quantisation_step(x: np.ndarray) -> float:
    """The step of the lattice a channel's values sit on (a digitiser's code, scaled to strain), or 0 when they sit on
    none (continuous, resampled or filtered data).

    The step is the mean of the gaps between neighbouring distinct values that are within :data:`LATTICE_SLACK` of
    the smallest gap, and the values are on a lattice when :data:`LATTICE_SHARE` of all gaps are whole multiples of it.
    The median gap overstates the step of a resolved channel several times: a wave crosses many codes in few samples,
    and most distinct values are its.
    """
    v = np.unique(np.asarray(x, dtype=float))
    v = v[np.isfinite(v)]
    if v.size < 3:
        return 0.0
    gaps = np.diff(v)
    unit = gaps[gaps <= gaps.min() * (1.0 + LATTICE_SLACK)]
    step = float(unit.mean())
    k = gaps / step
    on = np.abs(k - np.round(k)) <= LATTICE_SLACK
    return step if float(on.mean()) >= LATTICE_SHARE else 0.0


#: Fewest leading samples, all equal to the first, that can be padding rather than a baseline on one code.
PADDING_MIN = 8
#: Samples after the padding that must look like noise.
PADDING_CHECK = 32


def padding(x: np.ndarray) -> int:
    """Samples at the start that all repeat the first exactly (a zero-padded export, an unfilled pre-trigger buffer):
    at least :data:`PADDING_MIN` of them, followed by :data:`PADDING_CHECK` samples of noise (their steps changing
    sign 4 times or more: a noise-free record's constant baseline runs into its pulse's monotone front), and more
    of them than that noise leaves on one value by chance (a baseline quantised more coarsely than its noise sits
    on one code for a while): its chance of two equal neighbours, at its 95 % upper bound, to the power of the
    run, below 1e-3; else 0."""
    x = np.asarray(x)
    moved = np.flatnonzero(x != x[0]) if x.size else np.array([], int)
    k = int(moved[0]) if moved.size else 0
    if k < PADDING_MIN:
        return 0
    after = x[k:k + PADDING_CHECK]
    steps = np.diff(after)
    if after.size < PADDING_CHECK or int(np.count_nonzero(np.diff(np.sign(steps[steps != 0])))) < 4:
        return 0
    same = int(np.count_nonzero(steps == 0))
    stay = float(stats.beta.ppf(0.95, same + 1, steps.size - same + 1))
    return k if (k - 1) * np.log(stay) < np.log(1e-3) else 0


def longest_true_run(mask: np.ndarray) -> tuple[int, int]:
    """(start, stop) of the longest run of True in ``mask`` ((0, 0) when there is none)."""
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        return 0, 0
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    starts, stops = edges[0::2], edges[1::2]
    k = int(np.argmax(stops - starts))
    return int(starts[k]), int(stops[k])
