"""The per-test points a campaign's laws are fitted to (:mod:`.laws`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels import draw_kernels
from .law_forms import LAWS

#: What the laws are fitted to, in words (``LawData.basis``).
BASES = {"kappa": "kappa = f nu/(1-nu) of the stationary phase, converted with the campaign's nu",
         "f": "f under each test's diagnosed model"}


@dataclass(frozen=True)
class LawData:
    """Per-test points of a campaign (SI units)."""

    labels: list[str]
    setups: list[str]
    kappa: np.ndarray
    kappa_sd: np.ndarray
    V: np.ndarray
    V_sd: np.ndarray
    p: np.ndarray
    p_sd: np.ndarray
    #: what ``kappa`` holds: "kappa" (f nu/(1-nu) of the stationary phase) or "f" (f itself, under
    #: each test's diagnosed model); :data:`BASES` says it in words
    basis: str = "kappa"
    #: each test's posterior draws of the same quantity (thinned), and the log prior density they were
    #: drawn under; None: the tests are summarised by ``kappa`` and ``kappa_sd`` alone
    draws: tuple[np.ndarray, ...] | None = None
    draws_log_prior: tuple[np.ndarray, ...] | None = None
    #: each test's mean slip over its window (m); None: the tests carry no slip (the slip law is not compared)
    slip: np.ndarray | None = None
    #: kappa's change across each window, ln(kappa_2 / kappa_1), and its standard error: (n, 2)
    trend: np.ndarray | None = None
    #: each window half's slip (m), speed (m/s) and pressure over the test's mean: (n, 2, 3)
    halves: np.ndarray | None = None

    @property
    def n(self) -> int:
        return len(self.labels)

    @property
    def meaning(self) -> str:
        """What the laws were fitted to, in words."""
        return BASES[self.basis]

    def to_f(self, nu: float | np.ndarray) -> float | np.ndarray:
        """Factor from the data's unit to f: (1-nu)/nu for kappa, 1 for f."""
        return (1.0 - nu) / nu if self.basis == "kappa" else 1.0 + 0.0 * nu

    def select(self, keep: np.ndarray) -> LawData:
        """The tests where ``keep`` (a boolean mask) is true."""
        idx = np.flatnonzero(keep)

        def pick(seq: tuple[np.ndarray, ...] | None) -> tuple[np.ndarray, ...] | None:
            return None if seq is None else tuple(seq[i] for i in idx)

        return LawData([self.labels[i] for i in idx], [self.setups[i] for i in idx],
                       *(getattr(self, f)[idx] for f in ("kappa", "kappa_sd", "V", "V_sd", "p", "p_sd")),
                       basis=self.basis, draws=pick(self.draws), draws_log_prior=pick(self.draws_log_prior),
                       **{f: None if getattr(self, f) is None else getattr(self, f)[idx]
                          for f in ("slip", "trend", "halves")})

    @property
    def laws(self) -> tuple[str, ...]:
        """The laws these data can compare: the slip law only where every test carries its slip and window change."""
        return LAWS if self.reads_window_changes else tuple(x for x in LAWS if x != "slip")

    @property
    def reads_window_changes(self) -> bool:
        """Whether each test's change across its window enters the laws' likelihood (module docstring)."""
        return self.slip is not None and self.trend is not None and self.basis == "kappa"

    def drop(self, i: int) -> LawData:
        return self.select(np.arange(self.n) != i)

    def slip_at(self, setup: str, V: np.ndarray | float) -> np.ndarray | None:
        """A test's mean slip over its window at speed ``V`` on ``setup`` (m): V times the set-up's median S / V
        (the window's place in the test is the set-up's); None without slips."""
        if self.slip is None:
            return None
        on = np.array([s == setup for s in self.setups])
        ratio = np.median((self.slip / self.V)[on]) if on.any() else np.median(self.slip / self.V)
        return np.asarray(V, float) * ratio

    def kernels(self, scale: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The tests' draws over ``scale`` (n, J; padded where a test has fewer; shrunk, see above), their
        normalised log weights 1/prior (n, J; -inf on padding) and squared kernel bandwidths (n,; Scott's rule, scipy's
        ``gaussian_kde``); None without draws."""
        if self.draws is None:
            return None
        return draw_kernels(self.draws, self.draws_log_prior, scale)
