"""The f to quote: a posterior's draws of f with the output bars' calibration folded in.

Every model of a record (the stationary analysis, the whole-record fits of ``diagnose``) reads the two output
forces through their bars' header values (modulus, section, gauge factor), as eq. 2-4 say, and none of them can
tell a few per cent on one bar's calibration from a few per cent on f: eq. 17's ratio F_eo / F_io scales with
the two calibrations, and f with the ratio. The posteriors are therefore conditional on the headers, and so are
the draws the campaign pools (it has its own calibration offset for every set-up but the first, shared by that
set-up's tests). The f a person or a script quotes carries that uncertainty as well: f times an independent
factor G, ln G ~ N(0, s^2). Each output bar's force is uncertain by
:data:`~friction_uq.physics.bars.BAR_FORCE_CALIBRATION_SD` (1.73 %: three 1 % terms); s^2 sums, over the two
bars, what of that the model's likelihood does not carry already: the stationary analysis carries none (s =
2.45 %), the whole-record fits of ``diagnose`` a 1 % gain on each output gauge (s = 2.0 %); a model with a
bar's own calibration fault fitted (a gauge's gain, the bars' moduli) reads f partly against the input bar,
whose calibration none carries, and folds in the whole budget. On a
``diagnose`` interval of +-2 % this nearly doubles the width; on the stationary analysis', which nu's
uncertainty sets at +-10 %, it adds little.

**The whole-record models' form.** The stationary analysis carries the closed form's model-form error in its
likelihood (:data:`~friction_uq.likelihood.force_level.RATIO_MODEL_FORM`, 2.5 %: the rms of eq. 17's level
ratio against 40 clean records of the axisymmetric simulation). The whole-record fits of ``diagnose`` read f
through the 1-D simulation of the test, which shares that error (it and eq. 13 put the cell's F_eo 2.3 % high,
docs/axisymmetric.md), but their likelihood has no such term: a 1 % tolerance per sample forgives the
fronts, not a level that is off by the same fraction over the whole window. Their f carries
:data:`WHOLE_RECORD_MODEL_FORM` in quadrature beside the calibration. It is a floor, not the whole of their
form's error: on clean axisymmetric records the whole-record fit reads nu from the hoop gauge's course, whose
shape two simulators of the cell do not share, and its f errs by more (docs/trust.md).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .likelihood.force_level import RATIO_MODEL_FORM
from .physics.bars import BAR_FORCE_CALIBRATION_SD
from .stats.factor import times_lognormal_factor

#: The two bars whose forces make eq. 17's ratio.
OUTPUT_BARS = ("internal_output_bar", "external_output_bar")
#: The model-form sd folded into the f of a whole-record model (module docstring): the stationary likelihood's own.
WHOLE_RECORD_MODEL_FORM = RATIO_MODEL_FORM


def folded_sd(carried: Mapping[str, float] | None = None, model_form: float = 0.0) -> float:
    """The log sd folded into f: over the two output bars, the bar's calibration sd less, in quadrature, what the
    model's likelihood already carries of it (``carried``: bar -> sd; absent: none; at least the bar's whole
    term: nothing left of it), and ``model_form`` in quadrature beside it (:data:`WHOLE_RECORD_MODEL_FORM` for a
    whole-record model; 0 for the stationary analysis, whose likelihood carries its own)."""
    carried = carried or {}
    left = sum(max(0.0, BAR_FORCE_CALIBRATION_SD ** 2 - float(carried.get(bar, 0.0)) ** 2) for bar in OUTPUT_BARS)
    return float(np.sqrt(left + model_form ** 2))


def quoted_summary(f_draws: np.ndarray, log_sd: float | np.ndarray | None = None) -> dict[str, float]:
    """mean, sd, q05, q50, q95 of f with the output bars' calibration (module docstring): ``log_sd`` the sd folded
    in, one number or one per draw (:func:`folded_sd`; default: the stationary analysis', the whole budget)."""
    return times_lognormal_factor(f_draws, folded_sd() if log_sd is None else log_sd)
