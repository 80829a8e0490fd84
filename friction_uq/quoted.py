"""The f to quote: a posterior's draws of f with the output bars' calibration folded in.

Every model of a record (the stationary analysis, the whole-record fits of ``diagnose``) reads the two output
forces through their bars' header values (modulus, section, gauge factor), as eq. 2-4 say, and none of them can
tell a few per cent on one bar's calibration from a few per cent on f: eq. 17's ratio F_eo / F_io scales with
the two calibrations, and f with the ratio. The posteriors are therefore conditional on the headers, and so are
the draws the campaign pools (it has its own calibration offset per set-up, shared by that set-up's tests). The
f a person or a script quotes carries that uncertainty as well: f times an independent factor G, ln G ~ N(0,
s^2), s = :data:`~friction_uq.physics.bars.FORCE_RATIO_CALIBRATION_SD` (2.45 %: three 1 % terms on each of the
two bars), less what the model's likelihood already marginalises (the whole-record fits of ``diagnose``: a 1 %
gain on each output bar gauge, which leaves 2.0 % to fold in). On a ``diagnose`` interval of +-2 % this nearly
doubles the width; on the stationary analysis', which nu's uncertainty sets at +-10 %, it adds little.
"""

from __future__ import annotations

import numpy as np

from .physics.bars import FORCE_RATIO_CALIBRATION_SD
from .stats.factor import times_lognormal_factor


def folded_sd(marginalised_sd: float = 0.0) -> float:
    """The log sd folded into f: the ratio's calibration sd less, in quadrature, ``marginalised_sd`` (the part the
    model's likelihood already carries: the whole-record fits marginalise a 1 % gain on each output bar gauge,
    sqrt(2) x 1 % on the ratio)."""
    left = FORCE_RATIO_CALIBRATION_SD ** 2 - marginalised_sd ** 2
    if left < 0:
        raise ValueError(f"the likelihood's calibration sd {marginalised_sd:g} exceeds the budget "
                         f"{FORCE_RATIO_CALIBRATION_SD:g}")
    return float(np.sqrt(left))


def quoted_summary(f_draws: np.ndarray, *, marginalised_sd: float = 0.0) -> dict[str, float]:
    """mean, sd, q05, q50, q95 of f with the output bars' calibration (module docstring; :func:`folded_sd`)."""
    return times_lognormal_factor(f_draws, folded_sd(marginalised_sd))
