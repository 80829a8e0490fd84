"""The coordinates a friction law's parameters are sampled in: the same posterior, a shape an ensemble
sampler can cross.

In the law's own parameters the velocity law y = d + (s - d) exp(-V / v_c) has a curved ridge: over the
tested speeds only the law's values are fixed, and as v_c grows s - d grows with it (the law turns into
a straight line in V). An affine-invariant ensemble follows a straight ridge at any tilt but not a
curved one: on the bundled campaign its autocorrelation time was 200-250 steps, so a fit of 700 kept
steps held a few independent draws, its tails (and the leave-one-test-out ELPD read from them) followed
the seed, and so did the campaign's verdict. The pressure law y = d + (s - d) exp(-P / P_c) (P the wall
pressure over the campaign's mean) and the pressure term of pressure+velocity, amp_p (exp(-P / P_c) -
exp(-1 / P_c)), have the same ridge in P. Sampled instead in

* the law's values at the lowest and the highest tested speed (or pressure), y_lo and y_hi (for d and s;
  with the scale v_c or P_c they give d and s back, and given it they are what the tests fix),
* for the pressure term's amplitude, the change it makes over the tested pressures, amp_p (e_lo - e_hi), and
* log r for the between-test scatter r (its half-normal prior piles density at 0),

with the Jacobian of the change added to the log density, the posterior is the same and the ridge is
nearly straight. The draws are handed back in the law's own parameters.

    y_i = d (1 - e_i) + s e_i,   e_i = exp(-x_i / x_c),   |d(y_lo, y_hi) / d(d, s)| = e_lo - e_hi
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def _spread(x: np.ndarray | None) -> tuple[float, float] | None:
    """(lowest, highest) of the tested values, or None where they do not spread (one speed, no pressures)."""
    if x is None or np.size(x) == 0:
        return None
    lo, hi = float(np.min(x)), float(np.max(x))
    return (lo, hi) if hi - lo > 1e-6 * max(abs(hi), 1.0) else None


def _e(log_c: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """exp(-lo / x_c), exp(-hi / x_c) and log(e_lo - e_hi), the last without cancellation."""
    inv = np.exp(-log_c)
    e_lo, e_hi = np.exp(-lo * inv), np.exp(-hi * inv)
    log_gap = -lo * inv + np.log(-np.expm1(-(hi - lo) * inv))
    return e_lo, e_hi, log_gap


class LawCoordinates:
    """The change of coordinates for one model's parameter tuple (``params``), the tested speeds ``V``, the
    tested pressures over the campaign's mean, ``P`` (None: no pressure term is changed) and the tests' mean
    slips ``S`` (m; None: no slip law)."""

    def __init__(self, params: Sequence[str], V: np.ndarray, P: np.ndarray | None = None,
                 S: np.ndarray | None = None) -> None:
        names = list(params)
        v_range, p_range = _spread(np.asarray(V, float)), _spread(None if P is None else np.asarray(P, float))
        s_range = _spread(None if S is None else np.asarray(S, float))
        #: (index of d, of s, of the log scale, lowest and highest tested value): d and s to y_lo and y_hi
        self._pairs: list[tuple[int, int, int, float, float]] = []
        #: (index of the amplitude, of the log scale, lowest and highest tested value)
        self._amps: list[tuple[int, int, float, float]] = []
        if {"d", "s", "log_vc"} <= set(names) and v_range:
            self._pairs.append((names.index("d"), names.index("s"), names.index("log_vc"), *v_range))
        elif {"d", "s", "log_pc"} <= set(names) and "log_vc" not in names and p_range:  # the pressure law
            self._pairs.append((names.index("d"), names.index("s"), names.index("log_pc"), *p_range))
        elif {"d", "s", "log_sc"} <= set(names) and s_range:  # the slip law
            self._pairs.append((names.index("d"), names.index("s"), names.index("log_sc"), *s_range))
        if {"amp_p", "log_pc"} <= set(names) and p_range:
            self._amps.append((names.index("amp_p"), names.index("log_pc"), *p_range))
        self._r = names.index("r") if "r" in names else None

    def to_sampling(self, x: np.ndarray) -> np.ndarray:
        """Law parameters (W, k) -> sampling coordinates (W, k)."""
        z = np.array(x, float, copy=True)
        for i, j, k, lo, hi in self._pairs:
            e_lo, e_hi, _ = _e(x[:, k], lo, hi)
            z[:, i] = x[:, i] * (1 - e_lo) + x[:, j] * e_lo
            z[:, j] = x[:, i] * (1 - e_hi) + x[:, j] * e_hi
        for i, k, lo, hi in self._amps:
            z[:, i] = x[:, i] * np.exp(_e(x[:, k], lo, hi)[2])
        if self._r is not None:
            with np.errstate(divide="ignore"):
                z[:, self._r] = np.log(x[:, self._r])
        return z

    def to_law(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sampling coordinates (W, k) -> (law parameters (W, k), log |det d(law)/d(sampling)| (W,))."""
        x = np.array(z, float, copy=True)
        log_jac = np.zeros(len(z))
        for i, j, k, lo, hi in self._pairs:
            e_lo, e_hi, log_gap = _e(z[:, k], lo, hi)
            with np.errstate(over="ignore", invalid="ignore"):
                spread = (z[:, i] - z[:, j]) * np.exp(-log_gap)  # s - d
                x[:, i] = z[:, i] - spread * e_lo
                x[:, j] = x[:, i] + spread
            log_jac -= log_gap
        for i, k, lo, hi in self._amps:
            log_gap = _e(z[:, k], lo, hi)[2]
            with np.errstate(over="ignore", invalid="ignore"):
                x[:, i] = z[:, i] * np.exp(-log_gap)
            log_jac -= log_gap
        if self._r is not None:
            x[:, self._r] = np.exp(z[:, self._r])
            log_jac += z[:, self._r]
        return x, log_jac
