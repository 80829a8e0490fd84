"""How eq. 17's kappa changes across the stationary window: its two halves, for the campaign's slip law.

Across a campaign, a test's window-mean slip is nearly its sliding speed times a time the set-up fixes (the
window starts and lasts about as long at every speed), so a law in the slip and a law in V predict the
window means alike. What separates them is inside each test: the sample slides 1-2 mm through the window at
a nearly constant V. If f weakens with slip, kappa falls from the first half of the window to the second;
if it depends on V or on the pressure, it changes only as much as they do.

Per test, from the stationary data (:class:`~friction_uq.window.StationaryData`):

* ``log_kappa_change`` = ln(kappa_late / kappa_early), kappa of each half from the half's mean forces by
  eq. 17 (``kappa_from_ratio``; nu cancels, and so do the bars' calibrations and any set-up offset);
* its standard error ``sd`` from batch means: the window cut into :data:`BATCHES` contiguous batches, ln kappa
  of each, the spread of the batches about their half's mean pooled over both halves (2 (B/2 - 1) degrees of
  freedom): sd^2 = s^2 / (B/2) x 2. The spread inside a half includes whatever the record does that the
  model does not describe, so such fluctuations widen sd rather than move the change;
* each half's mean slip (eq. 7 integrated from the start of loading, m) and sliding speed (m/s), and its mean
  wall pressure relative to the window's: p = tau_mean / f (eq. 18, 20) with f of the half proportional to
  its kappa, so p_half / p_window = (F_eo,half / F_eo,window) / (kappa_half / kappa_window).

None when a batch's forces give no kappa (a ratio at or below -1, too few samples).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .physics.cell import kappa_from_ratio
from .window import StationaryData

#: Batches the window is cut into for the change's standard error (half of them in each half).
BATCHES = 8


@dataclass(frozen=True)
class WindowHalves:
    """kappa's change across the window and the two halves' slip, speed and relative pressure (SI units)."""

    log_kappa_change: float
    sd: float
    slip: tuple[float, float]
    V: tuple[float, float]
    pressure_rel: tuple[float, float]

    @property
    def mean_slip(self) -> float:
        """The window's mean slip (m): the mean of the halves' (they have the same length to one sample)."""
        return 0.5 * (self.slip[0] + self.slip[1])

    def to_json(self) -> dict[str, Any]:
        return {"log_kappa_change": self.log_kappa_change, "sd": self.sd, "slip_m": list(self.slip),
                "V_m_per_s": list(self.V), "pressure_over_window_mean": list(self.pressure_rel)}

    @classmethod
    def from_json(cls, doc: dict[str, Any]) -> WindowHalves:
        return cls(float(doc["log_kappa_change"]), float(doc["sd"]), _pair(doc["slip_m"]), _pair(doc["V_m_per_s"]),
                   _pair(doc["pressure_over_window_mean"]))


def _pair(x: Any) -> tuple[float, float]:
    a, b = (float(v) for v in x)
    return a, b


def _log_kappa(F_eo: np.ndarray, F_io: np.ndarray, data: StationaryData) -> float:
    with np.errstate(invalid="ignore", divide="ignore"):
        k = kappa_from_ratio(np.mean(F_eo) / np.mean(F_io), radius=data.radius, length=data.length)
        return float(np.log(k))


def window_halves(data: StationaryData) -> WindowHalves | None:
    """kappa's change from the first half of the window to the second, with its standard error (module docstring)."""
    n = data.n
    m = n // BATCHES
    if m < 2:
        return None
    batches = np.array([_log_kappa(data.F_eo[b * m:(b + 1) * m], data.F_io[b * m:(b + 1) * m], data)
                        for b in range(BATCHES)])
    h = n // 2
    halves = [slice(0, h), slice(h, n)]
    logk = np.array([_log_kappa(data.F_eo[s], data.F_io[s], data) for s in halves])
    if not (np.all(np.isfinite(batches)) and np.all(np.isfinite(logk))):
        return None
    per = BATCHES // 2
    first, second = batches[:per], batches[per:]
    pooled = (np.sum((first - first.mean()) ** 2) + np.sum((second - second.mean()) ** 2)) / (2 * (per - 1))
    sd = float(np.sqrt(2.0 * pooled / per))
    kappa_rel = np.exp(logk - np.log(np.mean(np.exp(logk))))
    F_rel = np.array([np.mean(data.F_eo[s]) for s in halves]) / np.mean(data.F_eo)
    p_rel = F_rel / kappa_rel
    return WindowHalves(float(logk[1] - logk[0]), sd, _pair([np.mean(data.slip[s]) for s in halves]),
                        _pair([np.mean(data.V[s]) for s in halves]), _pair(p_rel))
