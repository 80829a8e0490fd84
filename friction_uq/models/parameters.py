"""Named model parameters: one type for the priors, the sampler's transforms, the outputs and the report.

A forward model declares its parameters as :class:`Parameter` objects; everything downstream
addresses a parameter by its name (never by a column position): a parameter vector is turned into
a mapping with :meth:`ParameterSet.as_dict` and back with :meth:`ParameterSet.vector`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Parameter:
    """One physical parameter of a forward model.

    Attributes
    ----------
    name : str
        Identifier used in priors, outputs and reports (``f``, ``nu``, ``gap``, ...).
    unit : str
        SI unit, ``"-"`` for a dimensionless number.
    low, high : float
        Physical support (open interval); the sampler's transform maps it to the real line.
    meaning : str
        One line for the report.
    transform : {"auto", "log", "logodds"}
        The map to the real line used by samplers and mode searches: "auto" from the support (log
        for a half-line, logit for an interval); "log": log(value - low) whatever the upper bound;
        "logodds": log(value / (1 - value)) (support inside [0, 1]). A model picks the coordinates in
        which its posterior is simplest (the closed form: log f + log(nu/(1-nu)) = log kappa, eq. 17,
        a straight ridge); values mapped back beyond the support are the prior's to reject.
    scale : float
        For a parameter on the whole real line, the size it varies by (a channel's delay: 1e-6 s): its
        unbounded coordinate is value / scale, so that mode searches and finite differences, which work
        in that coordinate, step by numbers of order one whatever the unit.
    """

    name: str
    unit: str
    low: float
    high: float
    meaning: str
    transform: str = "auto"
    scale: float = 1.0

    def __post_init__(self) -> None:
        if not self.low < self.high:
            raise ValueError(f"parameter {self.name}: empty support [{self.low}, {self.high}]")
        if self.transform not in ("auto", "log", "logodds"):
            raise ValueError(f"parameter {self.name}: unknown transform {self.transform!r}")
        if self.transform == "log" and math.isinf(self.low):
            raise ValueError(f"parameter {self.name}: a log transform needs a finite lower bound")
        if self.transform == "logodds" and not (0.0 <= self.low and self.high <= 1.0):
            raise ValueError(f"parameter {self.name}: a log-odds transform needs a support inside [0, 1]")
        if not self.scale > 0.0 or (self.scale != 1.0 and not (math.isinf(self.low) and math.isinf(self.high))):
            raise ValueError(f"parameter {self.name}: a scale (> 0) is for a parameter on the whole real line")

    def nearest_inside(self, value: float, margin: float = 1e-3) -> float:
        """``value`` where it lies strictly inside the support; on a bounded support, a value on or beyond a bound is
        moved to ``margin`` of the width inside it: a start for a mode search taken from another model, whose
        support can be wider (the closed form's nu reaches 0.5, the simulator's 0.49), then maps to a finite
        coordinate. (A half-line has no width to step in by: its value is returned as given.)"""
        v = float(value)
        if self.low < v < self.high or not math.isfinite(self.high - self.low):
            return v
        width = self.high - self.low
        return float(np.clip(v, self.low + margin * width, self.high - margin * width))

    def contains(self, value: np.ndarray | float) -> np.ndarray:
        """True where ``value`` lies strictly inside the support."""
        v = np.asarray(value, float)
        return (v > self.low) & (v < self.high)

    def to_unbounded(self, value: np.ndarray | float) -> np.ndarray:
        """Map the support to the real line (log for a half-line, logit for an interval)."""
        v = np.asarray(value, float)
        if self.transform == "logodds":
            return np.log(v) - np.log1p(-v)
        if math.isinf(self.high) and math.isinf(self.low):
            return v / self.scale
        if math.isinf(self.high) or self.transform == "log":
            return np.log(v - self.low)
        if math.isinf(self.low):
            return -np.log(self.high - v)
        u = (v - self.low) / (self.high - self.low)
        return np.log(u) - np.log1p(-u)

    def from_unbounded(self, z: np.ndarray | float) -> np.ndarray:
        """Inverse of :meth:`to_unbounded`."""
        z = np.asarray(z, float)
        if self.transform == "logodds":
            return 1.0 / (1.0 + np.exp(-z))
        if math.isinf(self.high) and math.isinf(self.low):
            return z * self.scale
        if math.isinf(self.high) or self.transform == "log":
            return self.low + np.exp(z)
        if math.isinf(self.low):
            return self.high - np.exp(-z)
        return self.low + (self.high - self.low) / (1.0 + np.exp(-z))

    def log_jacobian(self, z: np.ndarray | float) -> np.ndarray:
        """log |d value / d z| of :meth:`from_unbounded`."""
        z = np.asarray(z, float)
        if self.transform == "logodds":
            return -np.logaddexp(0.0, -z) - np.logaddexp(0.0, z)
        if math.isinf(self.high) and math.isinf(self.low):
            return np.full_like(z, math.log(self.scale))
        if self.transform == "log":
            return z
        if math.isinf(self.high) or math.isinf(self.low):
            return z if math.isinf(self.high) else -z
        return math.log(self.high - self.low) - np.logaddexp(0.0, -z) - np.logaddexp(0.0, z)

    def gaussian_stand_in(self, prior) -> tuple[float, float]:
        """(centre, sd) in the unbounded coordinate of a Gaussian standing in for ``prior`` (anything with
        ``ppf``): its median and half the distance between its 16 % and 84 % quantiles."""
        lo, mid, hi = (float(self.to_unbounded(prior.ppf(q))) for q in (0.16, 0.5, 0.84))
        return mid, max(0.5 * (hi - lo), 1e-3)

    def to_json(self) -> dict[str, object]:
        return {"name": self.name, "unit": self.unit, "low": self.low, "high": self.high, "meaning": self.meaning,
                "transform": self.transform}


def summarize_draws(v: np.ndarray) -> dict[str, float]:
    """mean, sd, q05, q50, q95 of draws (the summary every output uses)."""
    v = np.asarray(v, float)
    q = np.quantile(v, [0.05, 0.5, 0.95])
    return {"mean": float(np.mean(v)), "sd": float(np.std(v, ddof=1)), "q05": float(q[0]), "q50": float(q[1]),
            "q95": float(q[2])}


def effective_sample_size(weights: np.ndarray) -> float:
    """Kish's effective sample size of weighted draws, (sum w)^2 / sum w^2 (weights need not be normalised)."""
    w = np.asarray(weights, float)
    return float(w.sum() ** 2 / np.sum(w * w))


class ParameterSet:
    """An ordered set of :class:`Parameter` with lookup by name."""

    def __init__(self, parameters: Iterable[Parameter]) -> None:
        self._params = tuple(parameters)
        names = [p.name for p in self._params]
        if len(set(names)) != len(names):
            raise ValueError(f"parameter names must be unique, got {names}")
        self._index = {p.name: i for i, p in enumerate(self._params)}

    def __iter__(self) -> Iterator[Parameter]:
        return iter(self._params)

    def __len__(self) -> int:
        return len(self._params)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def __getitem__(self, name: str) -> Parameter:
        return self._params[self._index[name]]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self._params)

    def __add__(self, other: Iterable[Parameter]) -> ParameterSet:
        return ParameterSet((*self._params, *other))

    def as_dict(self, theta: np.ndarray) -> dict[str, np.ndarray]:
        """Columns of ``theta`` (shape (..., len(self))) by name."""
        return dict(zip(self.names, self._columns(np.asarray(theta, float))))

    def to_unbounded(self, theta: np.ndarray) -> np.ndarray:
        """Parameter vectors (last axis in this set's order) -> unbounded coordinates, each parameter by its
        own transform (:meth:`Parameter.to_unbounded`)."""
        theta = np.asarray(theta, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.stack([p.to_unbounded(v) for p, v in zip(self._params, self._columns(theta))], axis=-1)

    def from_unbounded(self, z: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`to_unbounded`."""
        z = np.asarray(z, float)
        with np.errstate(over="ignore"):
            return np.stack([p.from_unbounded(v) for p, v in zip(self._params, self._columns(z))], axis=-1)

    def log_jacobian(self, z: np.ndarray) -> np.ndarray:
        """log |d theta / d z| of :meth:`from_unbounded` (a sum over the parameters: the map is diagonal)."""
        z = np.asarray(z, float)
        return sum(p.log_jacobian(v) for p, v in zip(self._params, self._columns(z)))

    def _columns(self, a: np.ndarray) -> list[np.ndarray]:
        if a.shape[-1] != len(self):
            raise ValueError(f"parameter vectors have {a.shape[-1]} entries, the model has {len(self)}: {self.names}")
        return [a[..., i] for i in range(len(self))]

    def vector(self, values: Mapping[str, np.ndarray | float]) -> np.ndarray:
        """Stack named values into vectors (last axis in this set's order)."""
        missing = [n for n in self.names if n not in values]
        if missing:
            raise KeyError(f"missing parameter(s) {', '.join(missing)}")
        return np.stack([np.asarray(values[n], float) for n in self.names], axis=-1)


#: The baseline's parameters (eq. 17 and the hoop gauge).
F = Parameter("f", "-", 0.0, 2.0, "Coulomb friction coefficient of the sample on the tube wall")
NU = Parameter("nu", "-", 0.0, 0.5, "Poisson ratio of the sample")
HOOP_GAIN = Parameter("hoop_gain", "-", 0.0, 10.0, "calibration factor of the tube hoop gauge")
