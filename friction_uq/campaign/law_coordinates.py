"""The coordinates a friction law's parameters are sampled in: the same posterior, a shape an ensemble
sampler can cross.

In the law's own parameters the velocity law y = d + (s - d) exp(-V / v_c) has a curved ridge: over the
tested speeds only the law's values are fixed, and as v_c grows s - d grows with it (the law turns into
a straight line in V). An affine-invariant ensemble follows a straight ridge at any tilt but not a
curved one: on the bundled campaign its autocorrelation time was 200-250 steps, so a fit of 700 kept
steps held a few independent draws, its tails (and the leave-one-test-out ELPD read from them) followed
the seed, and so did the campaign's verdict. Sampled instead in

* the law's values at the slowest and the fastest tested speed, y_lo and y_hi (for d and s; with
  v_c they give d and s back, and given v_c they are what the tests fix), and
* log r for the between-test scatter r (its half-normal prior piles density at 0),

with the Jacobian of the change added to the log density, the posterior is the same and the ridge is
nearly straight. The draws are handed back in the law's own parameters.

    y_i = d (1 - e_i) + s e_i,   e_i = exp(-V_i / v_c),   |d(y_lo, y_hi) / d(d, s)| = e_lo - e_hi
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class LawCoordinates:
    """The change of coordinates for one model's parameter tuple (``params``) and the tested speed range."""

    def __init__(self, params: Sequence[str], V: np.ndarray) -> None:
        names = list(params)
        V = np.asarray(V, float)
        self.V_lo, self.V_hi = float(np.min(V)), float(np.max(V))
        speeds = {"d", "s", "log_vc"} <= set(names) and self.V_hi - self.V_lo > 1e-6 * max(self.V_hi, 1.0)
        self._ds = (names.index("d"), names.index("s"), names.index("log_vc")) if speeds else None
        self._r = names.index("r") if "r" in names else None

    def _e(self, log_vc: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """exp(-V_lo / v_c), exp(-V_hi / v_c) and log(e_lo - e_hi), the last without cancellation."""
        inv = np.exp(-log_vc)
        e_lo, e_hi = np.exp(-self.V_lo * inv), np.exp(-self.V_hi * inv)
        log_gap = -self.V_lo * inv + np.log(-np.expm1(-(self.V_hi - self.V_lo) * inv))
        return e_lo, e_hi, log_gap

    def to_sampling(self, x: np.ndarray) -> np.ndarray:
        """Law parameters (W, k) -> sampling coordinates (W, k)."""
        z = np.array(x, float, copy=True)
        if self._ds is not None:
            i, j, k = self._ds
            e_lo, e_hi, _ = self._e(x[:, k])
            z[:, i] = x[:, i] * (1 - e_lo) + x[:, j] * e_lo
            z[:, j] = x[:, i] * (1 - e_hi) + x[:, j] * e_hi
        if self._r is not None:
            with np.errstate(divide="ignore"):
                z[:, self._r] = np.log(x[:, self._r])
        return z

    def to_law(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sampling coordinates (W, k) -> (law parameters (W, k), log |det d(law)/d(sampling)| (W,))."""
        x = np.array(z, float, copy=True)
        log_jac = np.zeros(len(z))
        if self._ds is not None:
            i, j, k = self._ds
            e_lo, e_hi, log_gap = self._e(z[:, k])
            with np.errstate(over="ignore", invalid="ignore"):
                spread = (z[:, i] - z[:, j]) * np.exp(-log_gap)  # s - d
                x[:, i] = z[:, i] - spread * e_lo
                x[:, j] = x[:, i] + spread
            log_jac -= log_gap
        if self._r is not None:
            x[:, self._r] = np.exp(z[:, self._r])
            log_jac += z[:, self._r]
        return x, log_jac
