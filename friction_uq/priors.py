"""Prior distributions of the friction analysis, read from a TOML file per sample material.

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
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy import special, stats

from .errors import PriorError
from .plausible import MAX_TEXT_BYTES, is_name, not_regular, toml_shape_problem

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



def _priors_dir() -> Path:
    """The prior files: ``friction_uq/prior_files`` in an installed wheel, ``priors/`` in a checkout.

    The repository keeps one copy, its top-level ``priors/``; the wheel ships it as package data
    under ``friction_uq/prior_files`` (setup.py maps the folder).
    """
    here = Path(__file__).resolve().parent
    shipped = here / "prior_files"
    return shipped if shipped.is_dir() else here.parent / "priors"


#: Folder of the prior files that come with friction-uq (found from any folder).
PRIORS_DIR = _priors_dir()
#: Largest prior file read (bytes): a prior file is a few dozen lines; the limit of every text input
#: (docs/limits.md: 1 MiB).
MAX_PRIOR_BYTES = MAX_TEXT_BYTES

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
            out = out - _log_normal_mass(lo, hi, m, s)
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


def _log_normal_mass(lo: float, hi: float, mean: float, sd: float) -> float:
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


def _fail(path: Path | str, key: str, problem: str) -> PriorError:
    return PriorError(f"{path}: {key}: {problem}")


def _number(path: Path, key: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _fail(path, key, f"must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(path, key, f"must be finite, got {value!r}")
    return x


def _parameter_prior(path: Path, name: str, table: object) -> ParameterPrior:
    where = f"[{name}]"
    if not isinstance(table, dict):
        raise _fail(path, where, f"must be a table with a 'distribution' key, got {table!r}")
    if "distribution" not in table:
        raise _fail(path, where, f"missing key 'distribution'; allowed: {', '.join(DISTRIBUTIONS)}")
    dist = table["distribution"]
    if dist not in DISTRIBUTIONS:
        raise _fail(path, f"{where} distribution", f"unknown distribution {dist!r}; allowed: {', '.join(DISTRIBUTIONS)}")
    wanted = DISTRIBUTIONS[dist]
    allowed = ("distribution", "note") + wanted
    for key in table:
        if key not in allowed:
            raise _fail(path, f"{where} {key}", f"unknown key for a {dist} prior; allowed: {', '.join(allowed)}")
    missing = [k for k in wanted if k not in table]
    if missing:
        raise _fail(path, where, f"{dist} prior needs {', '.join(wanted)}; missing {', '.join(missing)}")
    note = table.get("note", "")
    if not isinstance(note, str):
        raise _fail(path, f"{where} note", f"must be a string, got {note!r}")
    params = {k: _number(path, f"{where} {k}", table[k]) for k in wanted}

    for k in ("sd", "scale", "sigma", "median"):
        if k in params and params[k] <= 0.0:
            raise _fail(path, f"{where} {k}", f"must be > 0, got {params[k]:g}")
    if "lower" in params and not params["lower"] < params["upper"]:
        raise _fail(path, f"{where} lower", f"lower ({params['lower']:g}) must be < upper ({params['upper']:g})")

    prior = ParameterPrior(name, dist, params, note)
    lo, hi = prior.support
    plo, phi = PARAMETERS[name]
    if lo < plo or hi > phi:
        fix = "give lower and upper (truncnormal or uniform)" if dist == "normal" else "narrow the bounds"
        raise _fail(
            path, where,
            f"{prior.describe()} has support [{lo:g}, {hi:g}], outside the physical range of {name} "
            f"[{plo:g}, {phi:g}]; {fix}",
        )
    if dist == "truncnormal" and _log_normal_mass(lo, hi, params["mean"], params["sd"]) < math.log(MIN_MASS):
        raise _fail(
            path, where,
            f"normal(mean={params['mean']:g}, sd={params['sd']:g}) puts no mass (< {MIN_MASS:g}) on "
            f"[{lo:g}, {hi:g}]; move the mean inside the bounds or widen sd",
        )
    plo, phi = PLAUSIBLE[name]
    mass = float(prior.frozen().cdf(phi) - prior.frozen().cdf(plo))
    if not mass >= MIN_PLAUSIBLE_MASS:
        raise _fail(path, where, f"{prior.describe()} puts {mass:.2g} of its mass on [{plo:g}, {phi:g}], where "
                    f"{name} may lie (docs/limits.md); at least {MIN_PLAUSIBLE_MASS:g} is needed: check its parameters")
    return prior


def parse_priors(doc: Mapping[str, object], *, path: Path | str = "<priors>") -> Priors:
    """Validate a parsed TOML document (see module docstring) into :class:`Priors`."""
    path = Path(path) if not isinstance(path, Path) else path
    allowed = TOP_LEVEL_KEYS + tuple(PARAMETERS)
    for key in doc:
        if key not in allowed:
            raise _fail(path, key, f"unknown key or section; allowed: {', '.join(allowed)}")
    for key in TOP_LEVEL_KEYS:
        if key in doc and not isinstance(doc[key], str):
            raise _fail(path, key, f"must be a string, got {doc[key]!r}")
    missing = [k for k in REQUIRED_PARAMETERS if k not in doc]
    if missing:
        raise _fail(path, f"[{missing[0]}]", f"missing section; required: {', '.join(REQUIRED_PARAMETERS)}")
    params = tuple(_parameter_prior(path, name, doc[name]) for name in PARAMETERS if name in doc)
    return Priors(params, str(doc.get("material", "")), str(doc.get("description", "")), str(path))


def load_priors(path: str | Path) -> Priors:
    """Read and validate a prior file.

    Raises
    ------
    PriorError
        If the file is missing, is not TOML, or breaks a rule of the module docstring; the message
        names the file, the key and the problem.
    """
    path = Path(path)
    odd = not_regular(path)
    if odd:
        raise _fail(path, "file", f"{odd}, not a prior file")
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_PRIOR_BYTES + 1)
    except OSError as exc:
        raise _fail(path, "file", f"cannot be read ({exc.strerror or exc})") from None
    if len(raw) > MAX_PRIOR_BYTES:
        raise _fail(path, "file", f"is larger than {MAX_PRIOR_BYTES} bytes, not a prior file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _fail(path, "file", f"is not UTF-8 text (byte {exc.start}: {raw[exc.start:exc.start + 1]!r}); "
                    "save it as UTF-8 TOML") from None
    if "\x00" in text:
        raise _fail(path, "file", "contains NUL characters: a binary file, not TOML")
    shape = toml_shape_problem(text)
    if shape:
        raise _fail(path, "file", f"{shape}, too deep for a prior file")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _fail(path, "file", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise _fail(path, "file", "is nested too deeply to be a prior file") from None
    return parse_priors(doc, path=path)


def check_material_name(material: str) -> str:
    """``material`` if it is a name (letters, digits, '-', '_'), else PriorError: a record's material is data,
    looked up among the prior files, never a path."""
    if not is_name(material):
        raise PriorError(f"sample material {material!r} is not a material name (letters, digits, '-' and '_' "
                         "only); name the material in the record, or pass a prior file with --priors")
    return material


def default_prior_path(material: str, *, directory: str | Path | None = None) -> Path:
    """``<directory>/<material>.toml`` (``directory`` defaults to :data:`PRIORS_DIR`, in the package).

    Raises
    ------
    PriorError
        If there is no file for ``material``; the message lists the materials that have one.
    """
    folder = Path(directory) if directory is not None else PRIORS_DIR
    check_material_name(material)
    path = folder / f"{material}.toml"
    if not path.is_file():
        known = prior_files(folder)
        listed = ", ".join(f"{m} (nu alternatives: {', '.join(a)})" if a else m for m, a in known.items())
        raise _fail(
            path, "material",
            f"no prior file for material {material!r}; materials: {listed or 'none'}; write one with "
            f"'friction-uq priors {material} --nu ESTIMATE --nu-sd UNCERTAINTY' and pass it with --priors "
            f"{material}.toml (docs/priors.md)",
        )
    return path


def record_prior_path(record_path: str | Path, material: str) -> Path:
    """The prior file of a record's sample material (:func:`default_prior_path`); a material that names none, or
    is not a name, is refused naming the record and its field ``/apparatus/sample@material``."""
    try:
        return default_prior_path(material)
    except PriorError as exc:
        raise PriorError(f"{record_path}: /apparatus/sample@material: {exc}") from None


#: Infix of a nu alternative's file name: ``<material>-nu-<label>.toml``.
ALTERNATIVE_INFIX = "-nu-"


def prior_files(directory: str | Path | None = None) -> dict[str, list[str]]:
    """Materials with a prior file in ``directory`` (default :data:`PRIORS_DIR`) -> their nu alternatives.

    ``I1.toml`` is the material I1; ``I1-nu-wide.toml`` is not a material but an alternative nu
    prior of I1, which a run compares with the default one.
    """
    folder = Path(directory) if directory is not None else PRIORS_DIR
    stems = sorted(p.stem for p in folder.glob("*.toml")) if folder.is_dir() else []
    out: dict[str, list[str]] = {s: [] for s in stems if ALTERNATIVE_INFIX not in s}
    for s in stems:
        base, sep, _ = s.partition(ALTERNATIVE_INFIX)
        if sep:
            out.setdefault(base, []).append(s)
    return out
