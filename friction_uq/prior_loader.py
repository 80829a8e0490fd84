"""Prior files: read and check one (:func:`load_priors`, every problem a PriorError naming the file and the
key), and find a material's (:func:`default_prior_path`, :func:`record_prior_path`) and its nu alternatives
(:func:`prior_files`) among those friction-uq ships (:data:`PRIORS_DIR`). The distributions themselves are
:mod:`friction_uq.priors`' (docs/priors.md describes the format)."""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from pathlib import Path

from .errors import PriorError
from .plausible import MAX_TEXT_BYTES, NotText, is_name, text_of, toml_shape_problem
from .priors import (DISTRIBUTIONS, MIN_MASS, MIN_PLAUSIBLE_MASS, PARAMETERS, PLAUSIBLE, REQUIRED_PARAMETERS,
                     TOP_LEVEL_KEYS, ParameterPrior, Priors, log_normal_mass)


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
    if dist == "truncnormal" and log_normal_mass(lo, hi, params["mean"], params["sd"]) < math.log(MIN_MASS):
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
    try:
        text = text_of(path, "prior file", MAX_PRIOR_BYTES)
    except NotText as why:
        raise _fail(path, "file", str(why)) from None
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
