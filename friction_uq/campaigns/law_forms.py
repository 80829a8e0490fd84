"""The candidate friction laws of a campaign: their formulas, parameters, priors' ranges and nesting.

In units of the campaign's mean (y = kappa / kappa_bar, or f / f_bar; :mod:`.laws`):

* ``constant``:           y = a
* ``velocity``:           y = d + (s - d) exp(-V / v_c)   (the mechanism catalogue's form)
* ``pressure``:           y = d + (s - d) exp(-P / P_c)
* ``slip``:               y = d + (s - d) exp(-S / S_c)
* ``pressure+velocity``:  y = d + (s - d) exp(-V / v_c) + amp_p [exp(-P / P_c) - exp(-1 / P_c)]

with P = p / p_ref (p_ref the campaign's mean pressure) and S a test's mean slip over its window (m). Each
variable gets one shape, a monotone change between two levels over a scale, so that the formula does not
decide which variable is named.
"""

from __future__ import annotations

import numpy as np

LAWS = ("constant", "velocity", "pressure", "slip", "pressure+velocity")
#: law -> the laws it contains as a special case (constant is in all)
NESTS = {"constant": set(LAWS), "velocity": {"velocity", "pressure+velocity"},
         "pressure": {"pressure", "pressure+velocity"}, "slip": {"slip"}, "pressure+velocity": {"pressure+velocity"}}
LAW_PARAMS = {"constant": ("a",), "velocity": ("d", "s", "log_vc"), "pressure": ("d", "s", "log_pc"),
              "slip": ("d", "s", "log_sc"), "pressure+velocity": ("d", "s", "log_vc", "amp_p", "log_pc")}
LOG_VC_RANGE = (np.log(0.3), np.log(300.0))
#: log of the pressure scale P_c = p_c / p_ref (module docstring)
LOG_PC_RANGE = (np.log(1.0 / 30.0), np.log(30.0))
#: log of the slip scale S_c (m)
LOG_SC_RANGE = (np.log(0.1e-3), np.log(100e-3))


#: The laws each law holds as special cases (:func:`law_mean`): velocity's and pressure's are constant where s = d;
#: pressure+velocity is velocity where amp_p = 0 and pressure where s = d.
SPECIAL_CASES = {"velocity": ("constant",), "pressure": ("constant",), "slip": ("constant",),
                 "pressure+velocity": ("velocity", "pressure", "constant")}


def law_mean(law: str, theta: dict[str, np.ndarray], V: np.ndarray, p_rel: np.ndarray,
             slip: np.ndarray | None = None) -> np.ndarray:
    """y for parameter arrays of shape (W, 1) and data of shape (n,) (``p_rel`` = P - 1, ``slip`` in m, needed by
    the slip law only); returns (W, n)."""
    if law == "constant":
        return theta["a"] + 0.0 * V
    if law == "slip":
        if slip is None:
            raise ValueError("the slip law needs each test's slip")
        return theta["d"] + (theta["s"] - theta["d"]) * np.exp(-np.asarray(slip, float) / np.exp(theta["log_sc"]))
    P = 1.0 + p_rel
    if law == "pressure":
        return theta["d"] + (theta["s"] - theta["d"]) * np.exp(-P / np.exp(theta["log_pc"]))
    y = theta["d"] + (theta["s"] - theta["d"]) * np.exp(-V / np.exp(theta["log_vc"]))
    if law == "pressure+velocity":
        pc = np.exp(theta["log_pc"])
        y = y + theta["amp_p"] * (np.exp(-P / pc) - np.exp(-1.0 / pc))
    return y


def prior_table(params: tuple[str, ...], *, calibration_sd: float,
                free_offset_sd: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[int, float]]]:
    """The priors of a model's parameters (``laws``' docstring): each one's support (lower, upper: arrays of
    len(params)), whether its lower end belongs to it (r's does: [0, inf); every other support is open), and the
    normal priors as (index, sd), in the parameters' order. The levels are uniform on (0, 5), amp_p on (-5, 5), the
    log scales on their ranges; a set-up's calibration offset (cal_*) is N(0, calibration_sd), a free offset
    (delta, free_*) N(0, free_offset_sd), both above -1; r is half-normal(0.1)."""
    ranges = {"a": (0.0, 5.0), "d": (0.0, 5.0), "s": (0.0, 5.0), "log_vc": LOG_VC_RANGE, "log_pc": LOG_PC_RANGE,
              "log_sc": LOG_SC_RANGE, "amp_p": (-5.0, 5.0)}
    lo, hi = np.full(len(params), -np.inf), np.full(len(params), np.inf)
    closed, normal = np.zeros(len(params), bool), []
    for k, name in enumerate(params):
        if name in ranges:
            lo[k], hi[k] = ranges[name]
        elif name == "delta" or name.startswith(("free_", "cal_")):
            lo[k] = -1.0
            normal.append((k, calibration_sd if name.startswith("cal_") else free_offset_sd))
        elif name == "r":
            lo[k], closed[k] = 0.0, True
            normal.append((k, 0.1))
    return lo, hi, closed, normal
