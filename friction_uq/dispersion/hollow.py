"""The hollow bar's first mode: Love's estimate of its phase velocity and its cut-off.

An approximation valid well below the tube's ring frequency c0 / (2 pi r_m); used for the
external output bar (docs/physics.md section 7).
"""

from __future__ import annotations

import math

import numpy as np

from .pochhammer import CUTOFF_D_OVER_LAMBDA

#: Fraction of a hollow bar's ring frequency c0 / (2 pi r_m) above which its Love estimate is not
#: trusted (see ``first_mode_cutoff``).
RING_FREQUENCY_FRACTION = 0.6


def love_hollow_ratio(frequency: np.ndarray, *, c0: float, mean_square_radius: float, nu: float) -> np.ndarray:
    """Self-consistent Love estimate s = c/c0 with s = 1 - nu^2 pi^2 (r_i^2 + r_o^2) f^2 / (s c0)^2.

    s solves s^3 - s^2 + B = 0 with B = nu^2 pi^2 (r_i^2 + r_o^2) f^2 / c0^2. A root in (2/3, 1]
    exists for B <= 4/27; Newton from s = 1 converges monotonically to it (the cubic is convex and
    increasing there). The callers clip the frequency well before that (s >= 0.77 at the clip).
    """
    b = (nu * math.pi) ** 2 * mean_square_radius * (np.asarray(frequency, dtype=float) / c0) ** 2
    if np.any(b > 4.0 / 27.0):  # pragma: no cover - guarded by the callers' clip
        raise ValueError(f"Love estimate has no real phase velocity for B = {float(np.max(b))!r} > 4/27")
    s = np.ones_like(b)
    for _ in range(60):
        step = (s**3 - s**2 + b) / (3.0 * s**2 - 2.0 * s)
        s = s - step
        if np.all(np.abs(step) <= 1e-15):
            break
    return s


def hollow_cutoff(*, c0: float, outer_radius: float, inner_radius: float, nu: float) -> float:
    """Cut-off of the hollow bar's Love estimate (Hz): the lower of the d/Lambda rule and the ring bound."""
    mean_square_radius = inner_radius**2 + outer_radius**2
    ratio_cut = 1.0 - (nu * math.pi * CUTOFF_D_OVER_LAMBDA / 2.0) ** 2
    f_love = CUTOFF_D_OVER_LAMBDA * ratio_cut * c0 / (2.0 * math.sqrt(mean_square_radius))
    f_ring = c0 / (2.0 * math.pi * 0.5 * (inner_radius + outer_radius))
    return min(f_love, RING_FREQUENCY_FRACTION * f_ring)
