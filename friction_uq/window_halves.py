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
  of each, and the spread of the batches about a straight line through them (B - 2 degrees of freedom,
  :data:`DOF`): sd^2 = 2 s^2 / (B/2), the variance of the difference of two means of B/2 batches. About a
  line, not about each half's mean, so that a steady change across the window (the signal) does not widen its
  own error; a fluctuation the model does not describe does, rather than move the change. With B - 2 degrees
  of freedom, change / sd is Student-t (the campaign's likelihood uses it);
* each half's mean slip (eq. 7 integrated from the start of loading, m) and sliding speed (m/s), and its mean
  wall pressure relative to the window's: p = tau_mean / f (eq. 18, 20) with f of the half proportional to
  its kappa, so p_half / p_window = (F_eo,half / F_eo,window) / (kappa_half / kappa_window).

None when a batch's forces give no kappa (a ratio at or below -1, too few samples) or the sample does not slide
forward through the window (a mean slip or speed of a half at or below 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .physics.cell import kappa_from_ratio
from .window import StationaryData

#: Batches the window is cut into for the change's standard error (half of them in each half).
BATCHES = 8
#: Degrees of freedom of that standard error (the batches' spread about a line).
DOF = BATCHES - 2


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
    def from_json(cls, doc: Any) -> WindowHalves:
        """Read back from a JSON object; ValueError naming the key for anything a run could not have written."""
        if not isinstance(doc, dict):
            raise ValueError(f"is a JSON {type(doc).__name__}, not an object")
        out = cls(_number(doc, "log_kappa_change"), _number(doc, "sd"), _pair(doc, "slip_m"), _pair(doc, "V_m_per_s"),
                  _pair(doc, "pressure_over_window_mean"))
        if out.sd < 0 or min(out.slip + out.V + out.pressure_rel) <= 0:
            raise ValueError("sd must be >= 0 and the slips, speeds and pressures > 0")
        return out


def _number(doc: dict[str, Any], key: str) -> float:
    v = doc.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise ValueError(f"key {key!r} must be a finite number")
    return float(v)


def _pair(doc: dict[str, Any], key: str) -> tuple[float, float]:
    v = doc.get(key)
    if not isinstance(v, list) or len(v) != 2:
        raise ValueError(f"key {key!r} must be a list of two numbers")
    a, b = (_number({key: x}, key) for x in v)
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
    idx = np.arange(BATCHES, dtype=float)
    residual = batches - np.polyval(np.polyfit(idx, batches, 1), idx)
    s2 = float(np.sum(residual**2)) / DOF
    sd = float(np.sqrt(2.0 * s2 / (BATCHES // 2)))
    kappa_rel = np.exp(logk - np.log(np.mean(np.exp(logk))))
    F_rel = np.array([np.mean(data.F_eo[s]) for s in halves]) / np.mean(data.F_eo)
    slip = np.array([np.mean(data.slip[s]) for s in halves])
    V = np.array([np.mean(data.V[s]) for s in halves])
    if min(*slip, *V) <= 0:
        return None
    p_rel = F_rel / kappa_rel
    return WindowHalves(float(logk[1] - logk[0]), sd, (float(slip[0]), float(slip[1])), (float(V[0]), float(V[1])),
                        (float(p_rel[0]), float(p_rel[1])))
