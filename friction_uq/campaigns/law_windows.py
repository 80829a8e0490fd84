"""Each test's change of kappa across its window in the laws' likelihood (:mod:`.laws`).

The data are each run's :mod:`friction_uq.window_halves`. Across a campaign a test's mean slip is nearly V
times a time the set-up fixes, so the slip law and the velocity law predict the window means alike. Each
test also gives kappa's change from the first half of its window to the second, ln(kappa_2 / kappa_1),
with its standard error s_i, and the halves' slip, speed and pressure: the sample slides 1-2 mm through a
window at a nearly constant V. Every law predicts that change, ln(y(V_2, P_2, S_2) / y(V_1, P_1, S_1))
(the set-up's offsets cancel), and each test's likelihood carries it as a second, independent term

    ln(kappa_2 / kappa_1) = pred + sqrt(s_i^2 + TREND_FLOOR^2 + (TREND_REL pred)^2) t,   t ~ Student-t(6),

TREND_FLOOR (0.005) for what the window does that no law describes and TREND_REL (0.3) for how far the
change a quasi-static law predicts is from the one a dynamic test shows: both from records of the
axisymmetric simulation (docs/campaigns.md); a Student-t with the 6 degrees of freedom of s_i (eight batch
means about a line), since s_i is itself an estimate. When a test carries no such change (a result of an
older version), or when the laws are fitted to f under each test's diagnosed model (a named cause such as a
plug friction or a clearance changes kappa across the window by itself, which the stationary change does not
separate from the wall's), the slip law is not compared and no test's likelihood has the term.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.special import gammaln

from ..window_halves import DOF
from .law_forms import law_mean

if TYPE_CHECKING:
    from .law_data import LawData

#: The model-form terms of kappa's change across a window (module docstring).
TREND_FLOOR = 0.005
TREND_REL = 0.3
#: Degrees of freedom of the change's standard error (friction_uq.window_halves.DOF)
TREND_DOF = DOF


_T_CONST = float(gammaln((TREND_DOF + 1) / 2) - gammaln(TREND_DOF / 2) - 0.5 * np.log(TREND_DOF * np.pi))


def halves_points(d: LawData, p_ref: float) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], ...]:
    """Each test's two window halves as the law's arguments: ((V, p_rel, S), (V, p_rel, S)), arrays of (n,)."""
    return tuple((d.halves[:, k, 1], (d.p * d.halves[:, k, 2] - p_ref) / p_ref, d.halves[:, k, 0]) for k in (0, 1))


def change_loglike(first: np.ndarray, second: np.ndarray, d: LawData) -> np.ndarray:
    """log p(kappa's change across test i's window | theta) from the law at the two halves (:func:`halves_points`),
    ``first`` and ``second`` (W, n): (W, n) (module docstring)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        pred = np.where((first > 0) & (second > 0), np.log(second / first), np.nan)
    scale2 = d.trend[:, 1] ** 2 + TREND_FLOOR**2 + (TREND_REL * pred) ** 2
    # Student-t log density by hand (scipy's logpdf costs more than the law's whole likelihood at these sizes)
    out = _T_CONST - 0.5 * np.log(scale2) - 0.5 * (TREND_DOF + 1) * np.log1p((d.trend[:, 0] - pred) ** 2
                                                                              / (TREND_DOF * scale2))
    return np.where(np.isfinite(pred), out, -np.inf)
