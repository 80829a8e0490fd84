"""Prior distributions of the friction analysis, read from a TOML file per sample material (read, checked and
found by :mod:`friction_uq.prior_loader`).

A prior file (``<material>.toml``; friction-uq ships those of the repository's ``priors/`` folder)
holds one table per parameter (docs/priors.md describes the format)::

    material = "I1"
    description = "one line for reports"

    [f]                      # friction coefficient, f >= 0
    distribution = "halfnormal"
    scale = 0.3

    [nu]                     # sample Poisson ratio, 0 < nu < 0.5
    distribution = "truncnormal"
    mean = 0.4
    sd = 0.03
    lower = 0.0
    upper = 0.5

    [hoop_gain]              # hoop-gauge calibration factor g > 0 (optional table)
    distribution = "lognormal"
    median = 1.0
    sigma = 0.05

Each table may also carry a ``note`` string (the justification, shown in reports).
Distributions and their parameters (all SI / dimensionless):

==============  ===============================  ==========================================
name            parameters                       density
==============  ===============================  ==========================================
``halfnormal``  ``scale``                        half-normal on [0, inf)
``normal``      ``mean``, ``sd``                 normal (only for unbounded parameters)
``truncnormal`` ``mean``, ``sd``, ``lower``,     normal truncated to [lower, upper]
                ``upper``
``uniform``     ``lower``, ``upper``             uniform on [lower, upper]
``lognormal``   ``median``, ``sigma``            log x ~ normal(log median, sigma)
==============  ===============================  ==========================================

Every problem (unknown table or key, unknown distribution, missing parameter, sd <= 0,
lower >= upper, support outside the parameter's physical range, no mass on it) is refused with
:class:`~friction_uq.errors.PriorError` naming the file, the key and the allowed values.

Densities are written out in closed form (they sit in the sampler's inner loop, where a frozen
``scipy.stats`` call costs ~30 us); random draws, quantiles and the tests' reference densities
use ``scipy.stats``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import special, stats

from .errors import PriorError

#: Physical support (lower, upper) of each parameter the analysis knows.
PARAMETERS: Mapping[str, tuple[float, float]] = {
    "f": (0.0, math.inf),
    "nu": (0.0, 0.5),
    "hoop_gain": (0.0, math.inf),
}
#: Parameters a prior file must define.
REQUIRED_PARAMETERS = ("f", "nu")
#: Top-level scalar keys allowed besides the parameter tables.
TOP_LEVEL_KEYS = ("material", "description")
#: Distribution name -> its parameter names.
DISTRIBUTIONS: Mapping[str, tuple[str, ...]] = {
    "halfnormal": ("scale",),
    "normal": ("mean", "sd"),
    "truncnormal": ("mean", "sd", "lower", "upper"),
    "uniform": ("lower", "upper"),
    "lognormal": ("median", "sigma"),
}
#: Smallest probability mass the untruncated normal may put inside [lower, upper].
MIN_MASS = 1e-9
#: Where each parameter may plausibly lie (friction coefficients above 2 are not friction), and the least
#: prior mass there: a prior with less is a slip of its parameters (a scale of 1e300), not a belief.
PLAUSIBLE: Mapping[str, tuple[float, float]] = {"f": (0.0, 2.0), "nu": (0.0, 0.5), "hoop_gain": (0.5, 2.0)}
MIN_PLAUSIBLE_MASS = 1e-3



_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)


@dataclass(frozen=True)
class ParameterPrior:
    """Prior of one scalar parameter.

    Attributes
    ----------
    name : str
        Parameter name (a key of :data:`PARAMETERS`).
    distribution : str
        A key of :data:`DISTRIBUTIONS`.
    params : Mapping[str, float]
        The distribution's parameters as written in the file.
    note : str
        Justification from the file ('' if none).
    """

    name: str
    distribution: str
    params: Mapping[str, float]
    note: str = ""

    @property
    def support(self) -> tuple[float, float]:
        """(lower, upper) of the distribution's support."""
        p, d = self.params, self.distribution
        if d in ("truncnormal", "uniform"):
            return p["lower"], p["upper"]
        if d in ("halfnormal", "lognormal"):
            return 0.0, math.inf
        return -math.inf, math.inf

    def frozen(self) -> Any:
        """The equivalent frozen ``scipy.stats`` distribution."""
        p, d = self.params, self.distribution
        if d == "halfnormal":
            return stats.halfnorm(scale=p["scale"])
        if d == "normal":
            return stats.norm(loc=p["mean"], scale=p["sd"])
        if d == "truncnormal":
            a, b = (p["lower"] - p["mean"]) / p["sd"], (p["upper"] - p["mean"]) / p["sd"]
            return stats.truncnorm(a, b, loc=p["mean"], scale=p["sd"])
        if d == "uniform":
            return stats.uniform(loc=p["lower"], scale=p["upper"] - p["lower"])
        return stats.lognorm(s=p["sigma"], scale=p["median"])

    def logpdf(self, x: np.ndarray) -> np.ndarray:
        """Log density at ``x`` (any shape), -inf outside the support. Closed forms, see module doc."""
        x = np.asarray(x, float)
        p, d = self.params, self.distribution
        if d == "halfnormal":
            s = p["scale"]
            out = -0.5 * (x / s) ** 2 - math.log(s) - _LOG_SQRT_2PI + math.log(2.0)
            return np.where(x >= 0.0, out, -np.inf)
        if d in ("normal", "truncnormal"):
            m, s = p["mean"], p["sd"]
            out = -0.5 * ((x - m) / s) ** 2 - math.log(s) - _LOG_SQRT_2PI
            if d == "normal":
                return out
            lo, hi = p["lower"], p["upper"]
            out = out - log_normal_mass(lo, hi, m, s)
            return np.where((x >= lo) & (x <= hi), out, -np.inf)
        if d == "uniform":
            lo, hi = p["lower"], p["upper"]
            return np.where((x >= lo) & (x <= hi), -math.log(hi - lo), -np.inf)
        # lognormal
        m, s = math.log(p["median"]), p["sigma"]
        with np.errstate(divide="ignore", invalid="ignore"):
            lx = np.log(np.where(x > 0.0, x, 1.0))
            out = -0.5 * ((lx - m) / s) ** 2 - math.log(s) - _LOG_SQRT_2PI - lx
        return np.where(x > 0.0, out, -np.inf)

    def rvs(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` independent draws, shape (size,)."""
        return np.asarray(self.frozen().rvs(size=size, random_state=rng), float)

    def ppf(self, q: np.ndarray) -> np.ndarray:
        """Quantile function (inverse CDF) at probabilities ``q``."""
        return np.asarray(self.frozen().ppf(q), float)

    def cdf(self, x: np.ndarray) -> np.ndarray:
        """Cumulative distribution function at ``x``."""
        return np.asarray(self.frozen().cdf(x), float)

    def describe(self) -> str:
        """One line, e.g. ``nu ~ truncnormal(mean=0.4, sd=0.03, lower=0, upper=0.5)``."""
        args = ", ".join(f"{k}={v:g}" for k, v in self.params.items())
        return f"{self.name} ~ {self.distribution}({args})"


def log_normal_mass(lo: float, hi: float, mean: float, sd: float) -> float:
    """log P(lo <= X <= hi) for X ~ normal(mean, sd), accurate in the tails."""
    a, b = (lo - mean) / sd, (hi - mean) / sd
    if a > 0.0:  # both in the upper tail: use the mirror image
        a, b = -b, -a
    # P = Phi(b) - Phi(a) = Phi(b) (1 - Phi(a)/Phi(b))
    lb, la = special.log_ndtr(b), special.log_ndtr(a)
    return float(lb + np.log1p(-np.exp(la - lb))) if la < lb else -math.inf


@dataclass(frozen=True)
class Priors:
    """Joint prior: independent :class:`ParameterPrior` s, in the order of ``names``.

    Parameter vectors are rows of an array of shape (n, ndim) with columns in ``names`` order.
    """

    parameters: tuple[ParameterPrior, ...]
    material: str = ""
    description: str = ""
    path: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def ndim(self) -> int:
        return len(self.parameters)

    def __getitem__(self, name: str) -> ParameterPrior:
        for p in self.parameters:
            if p.name == name:
                return p
        raise PriorError(
            f"{self.path or '<priors>'}: [{name}]: no prior for this parameter; the file defines "
            f"{', '.join(self.names)}"
        )

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def subset(self, names: Sequence[str]) -> Priors:
        """The priors of ``names``, in that order (PriorError names the file if one is missing)."""
        return Priors(tuple(self[n] for n in names), self.material, self.description, self.path)

    def replace(self, prior: ParameterPrior) -> Priors:
        """A copy with ``prior`` replacing the parameter of the same name."""
        params = tuple(prior if p.name == prior.name else p for p in self.parameters)
        return Priors(params, self.material, self.description, self.path)

    def logpdf(self, theta: np.ndarray) -> np.ndarray:
        """Joint log density of parameter vectors.

        Parameters
        ----------
        theta : array, shape (n, ndim) or (ndim,)
            Columns in ``names`` order.

        Returns
        -------
        array, shape (n,) (or scalar array for one vector); -inf outside the support.
        """
        theta = np.asarray(theta, float)
        if theta.shape[-1] != self.ndim:
            raise ValueError(f"theta has {theta.shape[-1]} columns, the priors {self.ndim} ({', '.join(self.names)})")
        out = np.zeros(theta.shape[:-1])
        for j, p in enumerate(self.parameters):
            out = out + p.logpdf(theta[..., j])
        return out

    def rvs(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` independent draws from the joint prior, shape (size, ndim)."""
        return np.column_stack([p.rvs(rng, size) for p in self.parameters])

    def describe(self) -> str:
        """Multi-line description for reports: source, then one line per parameter with its note."""
        head = f"priors for {self.material or '?'}" + (f" ({self.path})" if self.path else "")
        lines = [head] + ([self.description] if self.description else [])
        for p in self.parameters:
            lines.append("  " + p.describe() + (f"  -- {p.note}" if p.note else ""))
        return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Reading and validation
# ----------------------------------------------------------------------------------------------
