"""Is an ELPD difference spread over the data, or carried by a few points? The paired difference with the
points that favour the first model most left out.

A difference of summed pointwise log predictive densities, and its standard error sqrt(n) sd(d_i), treat
the points as exchangeable. When a model improves a few points enormously (a front a little early, a
level a little off over a short phase) the sum is large, the standard error underestimates how much the
sum would change with other data, and the verdict rests on those few points. Two simulators of the same
test differ exactly there (the fronts' timing, the plug's impact), so a mechanism with a flexible
transient can collect thousands of nats from a few blocks of a record that has nothing of it.

:func:`trimmed_difference` leaves out the ``drop`` points with the largest differences in favour of the
first model and recomputes the sum and its standard error on the rest. Evidence that survives this is
spread over the record; evidence that does not is a few points' (a reviewer's "leave out the blocks that
favour it most": a jackknife of the most influential points, Vehtari, Gelman and Gabry 2017, section 4,
on heavy-tailed pointwise differences).
"""

from __future__ import annotations

import math

import numpy as np


def points_to_drop(n: int, fraction: float) -> int:
    """How many of ``n`` points a trimmed comparison leaves out: ``ceil(fraction n)``, at least 1 when
    ``fraction`` > 0, and never so many that fewer than 2 remain."""
    if fraction <= 0.0 or n < 3:
        return 0
    return int(min(n - 2, max(1, math.ceil(fraction * n))))


def trimmed_difference(a: np.ndarray, b: np.ndarray, *, drop: int) -> tuple[float, float]:
    """sum(a - b) and its standard error (sqrt(n) sd, ddof 1) over the points left once the ``drop`` with the
    largest a - b are left out (module docstring). ``drop`` 0: the plain paired difference."""
    d = np.asarray(a, float) - np.asarray(b, float)
    if d.ndim != 1 or d.size < drop + 2:
        raise ValueError(f"trimmed_difference needs at least {drop + 2} paired points, has {d.size}")
    if drop > 0:
        d = np.partition(d, d.size - drop)[: d.size - drop]
    return float(d.sum()), float(math.sqrt(d.size) * np.std(d, ddof=1))
