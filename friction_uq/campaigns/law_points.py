"""Where a friction law is evaluated in one fit's likelihood (:class:`~.laws.Fit`), stacked into one array.

A test's likelihood reads the law at its measured V, p (and slip S), at each of them moved by a small step (the
errors in variables' slopes, central differences) and at its window's two halves (:mod:`.law_windows`): up to
nine points a test. Evaluated point set by point set, the law's few arithmetic operations on arrays of ten tests
cost less than numpy's call overhead around them; stacked, the law is computed once per batch of draws, with the
same operations on the same numbers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .law_forms import law_mean
from .law_windows import halves_points

if TYPE_CHECKING:
    from .law_data import LawData

#: the relative step of the slopes' central differences (V's at least 1e-3 m/s, p's in units of p_ref)
STEP = 1e-3


class LawPoints:
    """The points of ``law``'s likelihood on the data ``d`` (campaign mean pressure ``p_ref``): the tests
    (``"mean"``), V, p and, for the slip law, S moved by +-:data:`STEP` (``"V+"``, ``"V-"``, ``"p+"``, ...), and the
    window's halves (``"first"``, ``"second"``) where the data read them; :meth:`evaluate` gives the law at each."""

    def __init__(self, law: str, d: LawData, p_ref: float) -> None:
        self.law = law
        p_rel = (d.p - p_ref) / p_ref
        #: the steps of the slopes (n,), (), (n,)
        self.hV, self.hp = STEP * np.maximum(d.V, 1.0), STEP
        S = d.slip
        sets = {"mean": (d.V, p_rel, S), "V+": (d.V + self.hV, p_rel, S), "V-": (d.V - self.hV, p_rel, S),
                "p+": (d.V, p_rel + self.hp, S), "p-": (d.V, p_rel - self.hp, S)}
        if law == "slip":
            if S is None:
                raise ValueError("the slip law needs each test's slip")
            self.hS = STEP * S
            sets |= {"S+": (d.V, p_rel, S + self.hS), "S-": (d.V, p_rel, S - self.hS)}
        if d.reads_window_changes:
            sets |= dict(zip(("first", "second"), halves_points(d, p_ref)))
        n = d.n
        self._slices = {key: slice(k * n, (k + 1) * n) for k, key in enumerate(sets)}
        self._V, self._p = (np.concatenate([v[i] for v in sets.values()]) for i in (0, 1))
        self._S = np.concatenate([v[2] for v in sets.values()]) if law == "slip" else None

    def evaluate(self, theta: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The law at every point set for parameter arrays of shape (W, 1): (W, n) each, by point set's key."""
        y = law_mean(self.law, theta, self._V, self._p, self._S)
        return {key: y[:, s] for key, s in self._slices.items()}
